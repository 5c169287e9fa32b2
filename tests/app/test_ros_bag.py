"""ROS 2 bags without ROS (snakehead.app.ros_bag): NAME.mcap read back with an independent reader (rosbags' AnyReader,
which parses the bag's own schemas) against the CSV the pipeline writes beside it, and with a second decoder
(mcap-ros2-support's); the URDF on /robot_description with /tf and /joint_states put through pinocchio's forward
kinematics against the plan's head; the markers; the JointTrajectory YAML; a closed loop's bag (on a loop run made
from a plan: running the loop in MuJoCo takes minutes); and ``snakehead plan`` writing and listing both files.

One target is planned once for the module (a few seconds); the writers are called directly.
"""
from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from snakehead import BasePlacement, SnakeRobot
from snakehead.app import ros_bag, ros_messages
from snakehead.app.report import write_trajectory_csv

TARGET = ((0.1, 0.5, 0.35), (0.0, 1.0, 0.0))


# ------------------------------------------------------------------------------------------------
# reading a bag back
# ------------------------------------------------------------------------------------------------
def read_bag(path: Path) -> dict[str, list]:
    """topic -> [(log time ns, message)] with rosbags (the bag's schemas registered from the file itself)."""
    from rosbags.highlevel import AnyReader

    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for conn, log_time, raw in reader.messages():
            out.setdefault(conn.topic, []).append((log_time, reader.deserialize(raw, conn.msgtype)))
    return out


def read_with_mcap_ros2(path: Path) -> dict[str, list]:
    """topic -> [decoded message] with mcap-ros2-support's decoder (another CDR implementation)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    out: dict[str, list] = {}
    with open(path, "rb") as f:
        for _, channel, _, msg in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
            out.setdefault(channel.topic, []).append(msg)
    return out


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], float)


def stamp_ns(header) -> int:
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


def matrix(transform) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    r, p = transform.rotation, transform.translation
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix()
    T[:3, 3] = [p.x, p.y, p.z]
    return T


def tf_frames(messages) -> dict[str, list[tuple[int, np.ndarray]]]:
    """child frame -> [(stamp ns, world pose)] from /tf (every parent is the world)."""
    out: dict[str, list] = {}
    for log_time, msg in messages:
        for tr in msg.transforms:
            assert tr.header.frame_id == ros_bag.WORLD_FRAME and stamp_ns(tr.header) == log_time
            out.setdefault(tr.child_frame_id, []).append((log_time, matrix(tr.transform)))
    return out


def synthetic_plan(robot: SnakeRobot, base: BasePlacement, n: int = 50, seed: int = 0, **extra) -> SimpleNamespace:
    """What the bag writer reads of a plan, for a robot that is not planned here: random joints within the limits
    every 2 ms."""
    rng = np.random.default_rng(seed)
    t = 0.002 * np.arange(n)
    q = rng.uniform(robot.lower, robot.upper, (n, robot.n_joints))
    fields = dict(name="synthetic", robot=robot, base=base, t=t, q=q, qd=np.gradient(q, t, axis=0), targets=[],
                  obstacles=[], scene=None, stability=SimpleNamespace(zmp=np.zeros((n, 2))))
    return SimpleNamespace(**{**fields, **extra})


# ------------------------------------------------------------------------------------------------
# one plan, its CSV, its bag
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def plan():
    import snakehead

    p = snakehead.plan([TARGET])
    assert p.success, p.failure
    return p


@pytest.fixture(scope="module")
def written(plan, tmp_path_factory):
    out = tmp_path_factory.mktemp("bag")
    csv_path = write_trajectory_csv(plan, out / "target_trajectory.csv", plan.robot.joint_names)
    bag = ros_bag.write_plan_bag(plan, out / "target.mcap")
    return SimpleNamespace(csv=csv_path, bag=bag, topics=read_bag(bag))


def test_the_bag_holds_its_topics_with_their_types(written):
    from rosbags.highlevel import AnyReader

    with AnyReader([written.bag]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
    assert types == {"/joint_states": "sensor_msgs/msg/JointState", "/tf": "tf2_msgs/msg/TFMessage",
                     "/robot_description": "std_msgs/msg/String",
                     "/snakehead/markers": "visualization_msgs/msg/MarkerArray"}
    from mcap.reader import make_reader

    with open(written.bag, "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        assert all("offered_qos_profiles" in c.metadata for c in summary.channels.values())


def test_every_joint_state_is_the_csv(plan, written):
    """The target: every /joint_states sample equal to the CSV to 1e-6 (names, stamps, positions), velocities the
    plan's."""
    header, rows = read_csv(written.csv)
    states = written.topics["/joint_states"]
    assert len(states) == len(rows) == len(plan.t)
    names = [h.removesuffix("_rad") for h in header[1:]]
    stamps = np.array([stamp_ns(m.header) for _, m in states])
    assert np.array_equal(stamps, [log for log, _ in states])  # log time = header stamp
    np.testing.assert_allclose(stamps * 1e-9, rows[:, 0] - rows[0, 0], atol=1e-6)
    assert stamps[0] == 0 and np.all(np.diff(stamps) > 0)
    for (_, m), row, qd in zip(states, rows, plan.qd):
        assert list(m.name) == names and m.header.frame_id == ""
        np.testing.assert_allclose(m.position, row[1:], atol=1e-6)
        np.testing.assert_array_equal(m.velocity, qd)
        assert len(m.effort) == 0
    np.testing.assert_array_equal(np.array([m.position for _, m in states]), plan.q)  # exactly the plan's


def test_a_second_decoder_reads_the_same(written):
    """mcap-ros2-support's decoder (its own CDR reader and schema parser) agrees with rosbags on every message."""
    other = read_with_mcap_ros2(written.bag)
    assert {k: len(v) for k, v in other.items()} == {k: len(v) for k, v in written.topics.items()}
    for a, (_, b) in zip(other["/joint_states"], written.topics["/joint_states"]):
        assert list(a.name) == list(b.name) and stamp_ns(a.header) == stamp_ns(b.header)
        assert list(a.position) == b.position.tolist() and list(a.velocity) == b.velocity.tolist()
    for a, (_, b) in zip(other["/tf"], written.topics["/tf"]):
        assert [t.child_frame_id for t in a.transforms] == [t.child_frame_id for t in b.transforms]
        assert [t.transform.rotation.w for t in a.transforms] == [t.transform.rotation.w for t in b.transforms]
    assert other["/robot_description"][0].data == written.topics["/robot_description"][0][1].data
    for a, (_, b) in zip(other["/snakehead/markers"], written.topics["/snakehead/markers"]):
        assert [(m.ns, m.id, m.type, len(m.points)) for m in a.markers] == \
               [(m.ns, m.id, m.type, len(m.points)) for m in b.markers]


def test_schemas_are_the_ros2_definitions():
    """The schema text of every type is what rosbags' Humble type store generates from ROS 2's own .msg files;
    Jazzy's has the same fields (its Marker adds a constant, ARROW_STRIP, which is not on the wire)."""
    from rosbags.typesys import Stores, get_typestore

    def fields(text: str) -> list[str]:
        return [line for line in text.strip().splitlines() if "=" not in line.split("#")[0].split()[-1]]

    humble, jazzy = get_typestore(Stores.ROS2_HUMBLE), get_typestore(Stores.ROS2_JAZZY)
    for kind in set(ros_bag.TOPIC_TYPES.values()):
        ours = ros_messages.schema_text(kind)
        assert ours.strip() == humble.generate_msgdef(kind, ros_version=2)[0].strip(), kind
        assert fields(ours) == fields(jazzy.generate_msgdef(kind, ros_version=2)[0]), kind


def test_robot_description_is_the_urdf(plan, written):
    (log_time, msg), = written.topics["/robot_description"]
    assert log_time == 0
    assert msg.data == plan.robot.description_text == plan.robot.urdf_text  # the default robot: nothing rewritten
    assert msg.data == Path(plan.robot.urdf).read_text()  # its file as it is


def test_tf_places_the_root_and_the_targets(plan, written):
    robot = plan.robot
    frames = tf_frames(written.topics["/tf"])
    assert set(frames) == {robot.description_root, "target/target"}
    t = plan.t - plan.t[0]
    expected = np.round(t[ros_bag.samples_every(plan.t, ros_bag.TF_PERIOD)] * 1e9)
    for child, poses in frames.items():
        assert [s for s, _ in poses] == expected.tolist()
    assert np.allclose(np.diff(expected)[:-1], ros_bag.TF_PERIOD * 1e9, atol=2e6)  # 20 Hz, the last sample too
    for _, T in frames[robot.description_root]:
        np.testing.assert_allclose(T, robot.root_pose(plan.base), atol=1e-12)
    tg = plan.targets[0]
    for _, T in frames["target/target"]:
        np.testing.assert_allclose(T[:3, 3], tg.position, atol=1e-12)
        np.testing.assert_allclose(T[:3, 0], tg.direction / np.linalg.norm(tg.direction), atol=1e-12)


def pinocchio_head(urdf: str, frame: str, names, positions) -> np.ndarray:
    """The pose (4, 4) of ``frame`` in the URDF's root link by pinocchio, at the named joint positions."""
    import pinocchio as pin

    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    q = pin.neutral(model)
    for name, value in zip(names, positions):
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(frame)].homogeneous


def check_head_through_the_bag(topics, robot: SnakeRobot, q: np.ndarray, base: BasePlacement, samples) -> None:
    """world -> URDF root (/tf) composed with pinocchio's FK of /robot_description at /joint_states is the plan's
    head pose (snakehead's FK of the same joints): the head tip frame as the description names it (the one the
    planner reads may be its aligned twin, which only snakehead's internal URDF has)."""
    urdf = topics["/robot_description"][0][1].data
    root = tf_frames(topics["/tf"])[robot.description_root]
    states = topics["/joint_states"]
    tip = robot.user_frames["head_tip"]
    for k in samples:
        stamp, js = states[k]
        T = root[int(np.searchsorted([s for s, _ in root], stamp, side="right")) - 1][1]  # the base does not move
        head = T @ pinocchio_head(urdf, tip, js.name, js.position)
        np.testing.assert_allclose(head, robot.frame(q[k], tip, base), atol=1e-9)
        np.testing.assert_allclose(head[:3, 3], robot.head_pose(q[k], base)[:3, 3], atol=1e-9)


def test_the_bag_puts_the_head_where_the_plan_does(plan, written):
    check_head_through_the_bag(written.topics, plan.robot, plan.q, plan.base,
                               np.linspace(0, len(plan.t) - 1, 12).astype(int))
    # and at the end, at the target
    head = plan.robot.head_pose(plan.q[-1], plan.base)
    np.testing.assert_allclose(head[:3, 3], TARGET[0], atol=1e-4)


def test_a_robot_whose_urdf_root_is_above_its_root_frame(tmp_path):
    """A dummy root link above link_0, rotated and shifted (the robot's root frame stays link_0): /tf places the
    URDF's root so that RViz draws the robot where snakehead plans it."""
    robot0 = SnakeRobot.default()
    text = robot0.urdf_text.replace(
        "<link name=\"link_0\"",
        "<link name=\"dummy_root\"/><joint name=\"dummy_to_tail\" type=\"fixed\"><parent link=\"dummy_root\"/>"
        "<child link=\"link_0\"/><origin xyz=\"0.3 -0.1 0.05\" rpy=\"0.2 -0.4 1.1\"/></joint><link name=\"link_0\"", 1)
    robot = SnakeRobot.from_urdf(text, base_end="base_end", neck_end="neck_end", head_tip="head_tip", root="link_0")
    assert robot.description_root == "dummy_root" != robot.parts.root
    base = BasePlacement(0.4, -0.3, 0.8)
    fake = synthetic_plan(robot, base)
    topics = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "dummy.mcap"))
    check_head_through_the_bag(topics, robot, fake.q, base, range(0, 50, 7))


def test_a_robot_whose_body_frame_is_not_its_root_frame(tmp_path):
    """The SEA-snake style: a link-less dummy root turned by -90 deg, modules along z, its own joint names."""
    from snakehead.samples.published import write_robot

    robot = SnakeRobot.from_file(write_robot("sea", tmp_path))
    assert not np.allclose(robot.body_in_root, np.eye(4))
    base = BasePlacement(-0.2, 0.5, -2.0)
    fake = synthetic_plan(robot, base, seed=3)
    topics = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "sea.mcap"))
    assert list(topics["/joint_states"][0][1].name)[:robot.n_joints] == robot.joint_names
    check_head_through_the_bag(topics, robot, fake.q, base, range(0, 50, 9))


def test_joints_off_the_body_are_held_at_zero(tmp_path):
    """A movable joint off the body (a camera's pan on the head) is named after the body's, at 0, so that
    robot_state_publisher places its link; a mimic joint is left to robot_state_publisher."""
    robot0 = SnakeRobot.default()
    extra = ("<link name=\"camera\"/><joint name=\"camera_pan\" type=\"continuous\"><parent link=\"link_16\"/>"
             "<child link=\"camera\"/><axis xyz=\"0 0 1\"/></joint>"
             "<link name=\"lens\"/><joint name=\"lens_tilt\" type=\"revolute\"><parent link=\"camera\"/>"
             "<child link=\"lens\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
             "velocity=\"1\"/><mimic joint=\"camera_pan\"/></joint></robot>")
    robot = SnakeRobot.from_urdf(robot0.urdf_text.replace("</robot>", extra), base_end="base_end",
                                 neck_end="neck_end", head_tip="head_tip")
    assert ros_bag.joint_names(robot) == robot.joint_names + ["camera_pan"]
    fake = synthetic_plan(robot, BasePlacement(), n=5)
    states = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "camera.mcap"))["/joint_states"]
    for (_, m), q, qd in zip(states, fake.q, fake.qd):
        assert list(m.name) == robot.joint_names + ["camera_pan"]
        assert m.position.tolist() == q.tolist() + [0.0] and m.velocity.tolist() == qd.tolist() + [0.0]


def test_markers(plan, written):
    messages = written.topics["/snakehead/markers"]
    static = [(s, m) for s, m in messages if m.markers[0].ns == "targets"]
    ground = [(s, m) for s, m in messages if m.markers[0].ns == "support_polygon"]
    assert len(static) + len(ground) == len(messages)
    duration = plan.t[-1] - plan.t[0]
    assert [s for s, _ in static] == [round(k * 1e9) for k in np.arange(0, duration + 1e-9, 1.0)]
    _, first = static[0]
    kinds = [(m.ns, m.type) for m in first.markers]
    assert kinds == [("targets", ros_messages.ARROW), ("targets", ros_messages.SPHERE),
                     ("target_names", ros_messages.TEXT_VIEW_FACING)]
    assert first.markers[2].text == "target" and all(m.header.frame_id == "world" for m in first.markers)
    arrow = first.markers[0]
    tip = np.array([arrow.pose.position.x, arrow.pose.position.y, arrow.pose.position.z]) + [0, arrow.scale.x, 0]
    np.testing.assert_allclose(tip, TARGET[0], atol=1e-12)  # it ends at the target, along +y
    idx = ros_bag.samples_every(plan.t, ros_bag.MARKER_PERIOD)
    assert len(ground) == len(idx)
    for (s, m), k in zip(ground, idx):
        polygon, zmp = m.markers
        assert s == stamp_ns(polygon.header) == round((plan.t[k] - plan.t[0]) * 1e9)
        ring = np.array([[p.x, p.y, p.z] for p in polygon.points])
        assert polygon.type == ros_messages.LINE_STRIP and polygon.action == 0 and len(ring) >= 4
        np.testing.assert_array_equal(ring[0], ring[-1])
        assert np.all(ring[:, 2] == ros_bag.GROUND_MARK_Z)
        assert (zmp.ns, zmp.type, zmp.action) == ("zmp", ros_messages.SPHERE, 0)
        np.testing.assert_allclose([zmp.pose.position.x, zmp.pose.position.y], plan.stability.zmp[k], atol=1e-12)


def test_obstacle_markers(tmp_path):
    from snakehead.geometry.obstacles import BoxObstacle, WallWithHole

    robot = SnakeRobot.default()
    box = BoxObstacle.from_yaw((0.5, 0.2, 0.1), (0.2, 0.1, 0.2), yaw=0.3)
    wall = WallWithHole.standing((0.0, 0.8, 0.3), (0.0, 1.0, 0.0), (0.6, 0.5, 0.02), 0.1)
    fake = synthetic_plan(robot, BasePlacement(), obstacles=[box, wall])
    topics = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "obstacles.mcap"))
    cube, triangles = [m for m in topics["/snakehead/markers"][0][1].markers if m.ns == "obstacles"]
    assert cube.type == ros_messages.CUBE and triangles.type == ros_messages.TRIANGLE_LIST
    np.testing.assert_allclose([cube.scale.x, cube.scale.y, cube.scale.z], box.size)
    np.testing.assert_allclose([cube.pose.position.x, cube.pose.position.y, cube.pose.position.z], box.centre)
    assert cube.pose.orientation.z == pytest.approx(np.sin(0.15))
    points = np.array([[p.x, p.y, p.z] for p in triangles.points])
    assert len(points) % 3 == 0 and len(points) > 3 * 32 * 8  # the 32 pieces around the hole, closed
    np.testing.assert_allclose(wall.distance_to_points(points), 0.0, atol=1e-9)  # every vertex on the wall


def test_frame_names():
    assert ros_bag.frame_name("sphere 1") == "sphere_1"
    assert ros_bag.frame_name("a/b:c--d") == "a_b_c_d"
    assert ros_bag.frame_name("  ") == "unnamed"
    targets = [SimpleNamespace(name=n, position=(0, 0, 0.3), direction=(1, 0, 0)) for n in ("a b", "a_b", "x")]
    assert [f for f, _ in ros_bag.target_frames(targets)] == ["target/a_b", "target/a_b_2", "target/x"]


# ------------------------------------------------------------------------------------------------
# the JointTrajectory for controllers
# ------------------------------------------------------------------------------------------------
def test_joint_trajectory_yaml(plan, tmp_path):
    """The YAML parses (PyYAML, as ``ros2 topic pub`` reads it) into the message's fields: the plan's positions and
    velocities exactly, as floats, and its times. A stretch of the plan: PyYAML takes seconds for the whole."""
    n = 400
    part = SimpleNamespace(name="target", robot=plan.robot, t=plan.t[:n], q=plan.q[:n], qd=plan.qd[:n])
    part.q = part.q.copy()
    part.q[1, :3] = [1e-5, 1e16, -2.0]  # numbers Python writes without a "."
    msg = yaml.safe_load(ros_bag.write_joint_trajectory(part, tmp_path / "target.yaml").read_text())
    assert set(msg) == {"header", "joint_names", "points"}
    assert msg["joint_names"] == plan.robot.joint_names
    assert msg["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert len(msg["points"]) == n
    for k, point in enumerate(msg["points"]):
        assert all(type(v) is float for v in point["positions"] + point["velocities"])
        assert point["positions"] == part.q[k].tolist() and point["velocities"] == part.qd[k].tolist()
        stamp = point["time_from_start"]
        assert stamp["sec"] * 10**9 + stamp["nanosec"] == round((part.t[k] - part.t[0]) * 1e9)
        assert point["accelerations"] == [] and point["effort"] == []
    # the whole plan: a point per sample, at the control period
    whole = ros_bag.write_joint_trajectory(plan, tmp_path / "whole.yaml").read_text().splitlines()
    assert sum(line.startswith("  - positions: [") for line in whole) == len(plan.t)
    assert "every 2 ms" in whole[0]


# ------------------------------------------------------------------------------------------------
# a closed loop's bag
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def loop_run(plan):
    """A LoopRun as ClosedLoop.run returns it, made from the plan: one ground phase of 1 s recorded every 10 ms
    (the tail sliding 0.2 m along x into the plan's placement, dead reckoning 1 cm off), then the head phases
    'simulated' as the plan offset by 1 mrad and the ZMP by 1 mm."""
    from snakehead.closed_loop.loop import LoopRun, Phase, head_phases

    robot = plan.robot
    t = 0.01 * np.arange(101)
    q = np.linspace(np.zeros(robot.n_joints), plan.q[0], len(t))
    root = np.repeat(robot.root_pose(plan.base)[None], len(t), axis=0)
    root[:, 0, 3] += np.linspace(-0.2, 0.0, len(t))
    estimate = root.copy()
    estimate[:, 1, 3] += 0.01
    ground = SimpleNamespace(t=t, q=q, root_truth=root, root_estimate=estimate)
    head = SimpleNamespace(t=plan.t.copy(), q=plan.q + 1e-3, qdot=plan.qd.copy(), zmp=plan.stability.zmp + 1e-3,
                           root_pose=np.repeat(robot.root_pose(plan.base)[None], len(plan.t), axis=0))
    t0 = float(t[-1]) + 0.002
    phases = [Phase("sidewinding", "gait", 0.0, float(t[-1]), None, run=ground)] + head_phases(plan, t0)
    return LoopRun(robot=robot, scene=plan.scene, start=BasePlacement(-0.2, 0.0, 0.0), believed_start=plan.base,
                   q_start=np.zeros(robot.n_joints), phases=phases, fixes=[], plan=plan, head=head, metrics=None,
                   head_t0_s=t0, corrections=0, planning_time_s=0.0, notes=[], failure=None)


def test_loop_bag(loop_run, written, tmp_path):
    run, plan = loop_run, loop_run.plan
    topics = read_bag(ros_bag.write_loop_bag(run, tmp_path / "loop.mcap"))
    t, roots, q = run.timeline()
    # /joint_states: the whole sequence as simulated
    states = topics["/joint_states"]
    assert len(states) == len(t)
    np.testing.assert_array_equal([m.position for _, m in states], q)
    np.testing.assert_allclose([s * 1e-9 for s, _ in states], t, atol=1e-9)
    np.testing.assert_array_equal([m.velocity for _, m in states][len(run.ground_runs[0].t):], run.head.qdot)
    # the head phases' plan beside, on the loop's clock: the CSV's samples
    header, rows = read_csv(written.csv)
    planned = topics["/snakehead/planned_joint_states"]
    assert len(planned) == len(rows)
    np.testing.assert_allclose([m.position for _, m in planned], rows[:, 1:], atol=1e-6)
    np.testing.assert_allclose([s * 1e-9 for s, _ in planned], run.head_t0_s + rows[:, 0] - rows[0, 0], atol=1e-6)
    # /tf: the robot where it truly is, the body frame true and estimated, the target
    frames = tf_frames(topics["/tf"])
    robot = run.robot
    assert set(frames) == {robot.description_root, "base_true", "base_estimate", "target/target"}
    at = {round(ti * 1e9): k for k, ti in enumerate(t)}
    for stamp, T in frames["base_true"]:
        np.testing.assert_allclose(T, roots[at[stamp]] @ robot.body_in_root, atol=1e-12)
    for stamp, T in frames["base_estimate"]:
        k = at[stamp]
        expected = run.ground_runs[0].root_estimate[k] if k < 101 else robot.root_pose(plan.base)
        np.testing.assert_allclose(T, expected @ robot.body_in_root, atol=1e-12)
    assert len(frames["base_estimate"]) == len(frames["base_true"])
    first_estimate = frames["base_estimate"][0][1][:3, 3] - frames["base_true"][0][1][:3, 3]
    np.testing.assert_allclose(first_estimate, [0, 0.01, 0], atol=1e-12)
    # markers: the simulated ZMP beside the planned one in the head phases only
    ground = [(s, m) for s, m in topics["/snakehead/markers"] if m.markers[0].ns == "support_polygon"]
    assert ground and min(s for s, _ in ground) == round(run.head_t0_s * 1e9)
    for _, m in ground:
        assert [k.ns for k in m.markers] == ["support_polygon", "zmp", "zmp_simulated"]


def test_a_loop_that_never_reached_the_head_phases(loop_run, tmp_path):
    import dataclasses

    run = dataclasses.replace(loop_run, phases=loop_run.phases[:1], plan=None, head=None, failure="no plan")
    topics = read_bag(ros_bag.write_loop_bag(run, tmp_path / "failed.mcap"))
    assert "/snakehead/planned_joint_states" not in topics
    assert len(topics["/joint_states"]) == len(run.ground_runs[0].t)
    assert "target/target" in tf_frames(topics["/tf"])  # the scene's target, still shown


# ------------------------------------------------------------------------------------------------
# the command line
# ------------------------------------------------------------------------------------------------
def test_snakehead_plan_writes_and_lists_the_bag(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--position", *map(str, TARGET[0]),
                           "--direction", *map(str, TARGET[1]), "--out", str(out), "--no-sim", "--fast"],
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads((out / "report.json").read_text())
    files = report["scenarios"]["target"]["files"]
    assert "target.mcap" in files and "target_joint_trajectory.yaml" in files
    summary = (out / "summary.md").read_text()
    assert "`target.mcap`" in summary and "`target_joint_trajectory.yaml`" in summary
    assert "target: ROS 2 bag and joint trajectory" in proc.stderr and "target.mcap" in proc.stderr
    header, rows = read_csv(out / "target_trajectory.csv")
    states = read_bag(out / "target.mcap")["/joint_states"]
    assert len(states) == len(rows)
    np.testing.assert_allclose([m.position for _, m in states], rows[:, 1:], atol=1e-6)


def test_the_pipeline_writes_a_loops_bag(loop_run, tmp_path):
    """What ``snakehead plan --start`` writes beside the loop's CSV (run_loop_scene's files): the loop's bag and the
    head phases' trajectory; nothing for a loop that failed before its first phase."""
    import dataclasses

    from snakehead.app.pipeline import Progress
    from snakehead.app.scene_outputs import write_ros_outputs

    files = write_ros_outputs("loop", tmp_path, Progress(quiet=True), loop_run.plan, loop_run)
    assert files == ["loop.mcap", "loop_joint_trajectory.yaml"]
    assert "/snakehead/planned_joint_states" in read_bag(tmp_path / "loop.mcap")
    nothing = dataclasses.replace(loop_run, phases=[], plan=None, head=None, failure="no plan reaches the targets")
    assert write_ros_outputs("none", tmp_path, Progress(quiet=True), None, nothing) == []
    assert not (tmp_path / "none.mcap").exists()


def test_the_yamls_float_rows_read_back_exactly() -> None:
    """The rows of floats (written from the list's repr at once) are each float's shortest repr with the "." YAML
    1.1 needs before an exponent, and read back bit for bit by PyYAML; the same text as float by float."""
    rng = np.random.default_rng(0)
    row = np.r_[rng.standard_normal(500) * 10.0 ** rng.integers(-30, 30, 500), 1e-5, -1e-5, 1e16, -3e20, 0.0, -0.0,
                1.0, 5e-324, 1.7976931348623157e308, 123456789012345678.0]
    text = ros_bag.yaml_floats(row)
    assert text == ", ".join(map(ros_bag.yaml_float, row.tolist()))
    back = yaml.safe_load(f"[{text}]")
    assert all(isinstance(x, float) for x in back)
    np.testing.assert_array_equal(np.array(back), row)
    assert "1.0e-05" in text and "-3.0e+20" in text


def test_the_trajectory_csv_is_csvs_row_by_row(tmp_path: Path) -> None:
    """The CSV (rows formatted a block at a time) is what the csv module writes row by row: time to 1 us, angles to
    1e-7 rad, "\\r\\n" line ends, over more rows than one block."""
    from snakehead.app import report

    rng = np.random.default_rng(1)
    n_rows = report.CSV_BLOCK_ROWS + 7
    plan = SimpleNamespace(t=np.arange(n_rows) * 0.002, q=rng.standard_normal((n_rows, 3)) * [1.0, 1e-8, -0.0])
    names = ["a", "b,c", 'd"e']
    path = write_trajectory_csv(plan, tmp_path / "t.csv", names)
    reference = tmp_path / "ref.csv"
    with open(reference, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s"] + [f"{n}_rad" for n in names])
        for when, row in zip(plan.t, plan.q):
            w.writerow([f"{when:.6f}"] + [f"{v:.7f}" for v in row])
    assert path.read_bytes() == reference.read_bytes()
