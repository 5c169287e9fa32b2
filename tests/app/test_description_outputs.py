"""Every file snakehead writes for a robot holds the description's joint angles and names (issue 34 item 3), and the
ROS bag shows the description's own tree (item 2): /robot_description is the user's URDF as written, /joint_states
names every movable joint of it, /tf places its own root link.

Robots from ``snakehead.samples.published.write_robot``: "cad" (a [home] table: the planner's zero is not the
description's), "reu_reversed" (the URDF's tree starts at the head: its root link moves with the joints), "wheeled"
(passive wheels held by the planner) and the default robot (nothing rewritten). The plans are synthetic (random
joints within the limits every 2 ms): the writers are called directly. The bag is read back with rosbags and its
kinematics checked with pinocchio on ``robot.description_text`` alone, independently of snakehead's internal URDF.
"""
from __future__ import annotations

import csv
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from test_ros_bag import read_bag

from snakehead import BasePlacement, SnakeRobot
from snakehead.app import ros_bag
from snakehead.app.report import write_trajectory_csv
from snakehead.samples.published import write_robot

pin = pytest.importorskip("pinocchio")
pytest.importorskip("rosbags")

BASE = BasePlacement(0.3, -0.2, 0.7)


@pytest.fixture(scope="module")
def robots(tmp_path_factory) -> dict[str, SnakeRobot]:
    folder = tmp_path_factory.mktemp("robots")
    out = {style: SnakeRobot.from_file(write_robot(style, folder / style))
           for style in ("cad", "reu_reversed", "wheeled")}
    out["default"] = SnakeRobot.default()
    return out


def synthetic_plan(robot: SnakeRobot, n: int = 200, seed: int = 0) -> SimpleNamespace:
    """What the writers read of a plan: random joints within the limits every 2 ms, at :data:`BASE`."""
    rng = np.random.default_rng(seed)
    t = 0.002 * np.arange(n)
    q = rng.uniform(robot.lower, robot.upper, (n, robot.n_joints))
    return SimpleNamespace(name="synthetic", robot=robot, base=BASE, t=t, q=q, qd=np.gradient(q, t, axis=0),
                           targets=[], obstacles=[], scene=None, stability=SimpleNamespace(zmp=np.zeros((n, 2))))


def tf_matrix(transform) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    r, p = transform.rotation, transform.translation
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix()
    T[:3, 3] = [p.x, p.y, p.z]
    return T


def tf_of(topics: dict, child: str) -> dict[int, np.ndarray]:
    """stamp ns -> world pose of ``child`` on /tf (every parent is the world)."""
    out = {}
    for log_time, msg in topics["/tf"]:
        for tr in msg.transforms:
            assert tr.header.frame_id == ros_bag.WORLD_FRAME
            if tr.child_frame_id == child:
                out[log_time] = tf_matrix(tr.transform)
    return out


def description_joints(text: str) -> list[str]:
    """The movable joints of a URDF that mimic none (what robot_state_publisher needs on /joint_states)."""
    return [j.get("name", "") for j in ET.fromstring(text).findall("joint")
            if j.get("type") in ("revolute", "continuous", "prismatic") and j.find("mimic") is None]


def pinocchio_frame(model, names, positions, frame: str) -> np.ndarray:
    """The pose (4, 4) of ``frame`` in the URDF's root link by pinocchio, every joint of the model set from
    (names, positions) (each must be there)."""
    data = model.createData()
    q = pin.neutral(model)
    given = dict(zip(names, positions))
    for joint_id in range(1, model.njoints):
        name = model.names[joint_id]
        assert name in given, f"joint {name!r} of the description is not on /joint_states"
        joint = model.joints[joint_id]
        if joint.nq == 2:  # a continuous joint: (cos, sin)
            q[joint.idx_q:joint.idx_q + 2] = np.cos(given[name]), np.sin(given[name])
        else:
            q[joint.idx_q] = given[name]
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(frame)].homogeneous


def check_bag_kinematics(robot: SnakeRobot, plan: SimpleNamespace, topics: dict) -> int:
    """At every /tf stamp: world -> the description's root (/tf) composed with pinocchio's forward kinematics of
    /robot_description at /joint_states puts the description's head tip frame where snakehead puts it (1e-9 m);
    returns how many stamps were checked."""
    (_, description), = topics["/robot_description"]
    model = pin.buildModelFromXML(description.data)
    states = {log: m for log, m in topics["/joint_states"]}
    stamps = np.round((plan.t - plan.t[0]) * 1e9).astype(np.int64).tolist()
    roots = tf_of(topics, robot.description_root)
    tip = robot.user_frames["head_tip"]
    for stamp, T in roots.items():
        k = stamps.index(stamp)
        js = states[stamp]
        head = T @ pinocchio_frame(model, js.name, js.position, tip)
        np.testing.assert_allclose(head, robot.frame(plan.q[k], tip, plan.base), atol=1e-9)
        np.testing.assert_allclose(head[:3, 3], robot.head_pose(plan.q[k], plan.base)[:3, 3], atol=1e-9)
    return len(roots)


# ------------------------------------------------------------------------------------------------
# the description's angles in every file: a robot with a home pose
# ------------------------------------------------------------------------------------------------
def test_the_cad_robot_has_a_home_pose(robots):
    robot = robots["cad"]
    assert np.abs(robot.joint_offsets.home).max() > 0.01  # what the tests below rely on


def test_the_csv_holds_the_description_angles(robots, tmp_path):
    robot = robots["cad"]
    plan = synthetic_plan(robot)
    path = write_trajectory_csv(plan, tmp_path / "t.csv", robot.joint_names)
    with open(path) as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time_s"] + [f"{name}_rad" for name in robot.joint_names]
    angles = np.array(rows[1:], float)[:, 1:]
    np.testing.assert_allclose(angles, robot.description_angles(plan.q), atol=6e-8)
    np.testing.assert_allclose(angles - plan.q, np.broadcast_to(robot.joint_offsets.home, plan.q.shape), atol=6e-8)


def test_the_joint_trajectory_yaml_holds_the_description_angles(robots, tmp_path):
    robot = robots["cad"]
    plan = synthetic_plan(robot, n=20)
    msg = yaml.safe_load(ros_bag.write_joint_trajectory(plan, tmp_path / "t.yaml").read_text())
    assert msg["joint_names"] == robot.joint_names
    positions = np.array([p["positions"] for p in msg["points"]])
    np.testing.assert_array_equal(positions, robot.description_angles(plan.q))
    assert np.abs(positions - plan.q).max() > 0.01
    np.testing.assert_array_equal(np.array([p["velocities"] for p in msg["points"]]), plan.qd)


def test_the_bag_of_a_robot_with_a_home_pose(robots, tmp_path):
    """/joint_states in the description's angles (velocities the plan's), and pinocchio on the description's own
    URDF at those angles puts the head where the plan does."""
    robot = robots["cad"]
    plan = synthetic_plan(robot, seed=1)
    topics = read_bag(ros_bag.write_plan_bag(plan, tmp_path / "cad.mcap"))
    assert topics["/robot_description"][0][1].data == robot.description_text
    states = topics["/joint_states"]
    n = robot.n_joints
    assert all(list(m.name)[:n] == robot.joint_names for _, m in states)
    np.testing.assert_array_equal([m.position[:n] for _, m in states], robot.description_angles(plan.q))
    np.testing.assert_array_equal([m.velocity[:n] for _, m in states], plan.qd)
    assert check_bag_kinematics(robot, plan, topics) >= 5


def test_the_loop_report_gives_its_start_in_description_angles(robots):
    from snakehead.closed_loop.loop import LoopRun

    robot = robots["cad"]
    q_start = np.zeros(robot.n_joints)  # the body straight: the description's home
    run = LoopRun(robot=robot, scene=SimpleNamespace(obstacles=[], targets=[]), start=BASE, believed_start=BASE,
                  q_start=q_start, phases=[], fixes=[], plan=None, head=None, metrics=None, head_t0_s=0.0,
                  corrections=0, planning_time_s=0.0, notes=[], failure="not run")
    np.testing.assert_array_equal(run.report()["start"]["q_rad"], robot.joint_offsets.home)


# ------------------------------------------------------------------------------------------------
# the bag on the description's own tree
# ------------------------------------------------------------------------------------------------
def test_the_bag_of_a_tree_written_from_the_head(robots, tmp_path):
    """reu_reversed: the URDF's root is at the head, the body's root the tail. /robot_description is the URDF as
    written (not the re-rooted one), /tf places its root (which moves with the joints) so that pinocchio on it puts
    the head tip where snakehead does."""
    robot = robots["reu_reversed"]
    assert robot.description_root != robot.parts.root
    assert robot.description_text != robot.urdf_text
    plan = synthetic_plan(robot, seed=2)
    topics = read_bag(ros_bag.write_plan_bag(plan, tmp_path / "reu.mcap"))
    assert topics["/robot_description"][0][1].data == robot.description_text
    assert set(topics["/joint_states"][0][1].name) == set(description_joints(robot.description_text))
    roots = list(tf_of(topics, robot.description_root).values())
    assert np.abs(roots[0][:3, 3] - roots[-1][:3, 3]).max() > 0.01  # the head end moves with the joints
    assert check_bag_kinematics(robot, plan, topics) >= 5


def test_description_root_pose_along_a_motion(robots):
    """One pose or many: description_root_pose is the description root's frame on the body (reu_reversed: on it)."""
    robot = robots["reu_reversed"]
    plan = synthetic_plan(robot, n=6, seed=4)
    roots = np.array([robot.root_pose(BasePlacement(0.1 * k, 0.0, 0.2 * k)) for k in range(6)])
    many = robot.description_root_pose(roots, plan.q)
    for k in range(6):
        one = robot.description_root_pose(roots[k], plan.q[k])
        np.testing.assert_allclose(many[k], one, atol=1e-12)
        np.testing.assert_allclose(one, roots[k] @ robot.body.fk_all(plan.q[k])[robot.link_index(
            robot.description_root)], atol=1e-12)


def test_a_loop_bag_of_a_tree_written_from_the_head(robots, tmp_path):
    """A closed loop's bag (a ground phase only, the root frame moving): /tf places the description's root where
    the simulated root frame and joints put it, /joint_states the description's joints."""
    from snakehead.closed_loop.loop import LoopRun, Phase

    robot = robots["reu_reversed"]
    plan = synthetic_plan(robot, n=120, seed=6)
    roots = np.array([robot.root_pose(BasePlacement(0.3 + 0.5 * t, -0.2, 0.7 + t)) for t in plan.t])
    ground = SimpleNamespace(name="sidewinding", t=plan.t, q=plan.q, root_truth=roots, root_estimate=None)
    run = LoopRun(robot=robot, scene=SimpleNamespace(obstacles=[], targets=[]), start=BASE, believed_start=BASE,
                  q_start=plan.q[0], phases=[Phase("sidewinding", "gait", 0.0, float(plan.t[-1]), None, run=ground)],
                  fixes=[], plan=None, head=None, metrics=None, head_t0_s=0.0, corrections=0, planning_time_s=0.0,
                  notes=[], failure="no plan")
    topics = read_bag(ros_bag.write_loop_bag(run, tmp_path / "loop.mcap"))
    assert topics["/robot_description"][0][1].data == robot.description_text
    (_, description), = topics["/robot_description"]
    model = pin.buildModelFromXML(description.data)
    states = {log: m for log, m in topics["/joint_states"]}
    stamps = np.round(plan.t * 1e9).astype(np.int64).tolist()
    tip = robot.user_frames["head_tip"]
    placed = tf_of(topics, robot.description_root)
    assert len(placed) >= 3
    for stamp, T in placed.items():
        k = stamps.index(stamp)
        head = T @ pinocchio_frame(model, states[stamp].name, states[stamp].position, tip)
        np.testing.assert_allclose(head, roots[k] @ robot.body.fk_all(plan.q[k])[robot.link_index(tip)], atol=1e-9)


def test_the_bag_of_a_snake_with_passive_wheels(robots, tmp_path):
    """wheeled: the wheels' joints (held by the planner) are on /joint_states at their held values, so that
    robot_state_publisher places every link; the head where the plan puts it."""
    robot = robots["wheeled"]
    held = {name: value for name, value, _ in robot.tree_changes.held_joints}
    assert held and not set(held) & set(robot.joint_names)
    plan = synthetic_plan(robot, seed=3)
    topics = read_bag(ros_bag.write_plan_bag(plan, tmp_path / "wheeled.mcap"))
    assert topics["/robot_description"][0][1].data == robot.description_text
    for _, m in topics["/joint_states"][:3]:
        assert list(m.name) == robot.joint_names + [j for j in description_joints(robot.description_text)
                                                    if j not in robot.joint_names]
        values = dict(zip(m.name, m.position))
        assert all(values[name] == value for name, value in held.items())
        assert all(v == 0.0 for v in m.velocity[robot.n_joints:])
    assert check_bag_kinematics(robot, plan, topics) >= 5


def test_the_default_robot_is_unchanged(robots, tmp_path):
    """Nothing rewritten: the description is the file, its angles the plan's, its root the body's root."""
    robot = robots["default"]
    assert robot.description_text == robot.urdf_text and robot.description_root == robot.parts.root
    plan = synthetic_plan(robot, n=60, seed=5)
    topics = read_bag(ros_bag.write_plan_bag(plan, tmp_path / "default.mcap"))
    assert topics["/robot_description"][0][1].data == Path(robot.urdf).read_text()
    np.testing.assert_array_equal([m.position for _, m in topics["/joint_states"]], plan.q)
    for T in tf_of(topics, robot.description_root).values():
        np.testing.assert_array_equal(T[:3, 3], robot.root_pose(BASE)[:3, 3])
    assert check_bag_kinematics(robot, plan, topics) >= 2
