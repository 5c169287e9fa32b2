"""A plan on a slope in its ROS 2 bag (snakehead.app.ros_bag): the ground frame on /tf as ``world`` -> ``ground``,
the root and the targets under it, the markers in ``ground`` with the tilted ground plane.

Read back with rosbags (as tests/app/test_ros_bag.py reads a bag) and checked against poses computed here: the
world pose of the head is ``G @ robot.frame(q, head_tip, base)``, G the ground frame's pose; the tf chain
world -> ground -> root composed with pinocchio's FK of the URDF at /joint_states is that pose; the ground plane's
marker has the slope's normal (``plane_normal_deg``) and lies on the plane. A flat plan's bag has no ``ground``
frame (tests/app/test_ros_bag.py checks it is the bag written before slopes).
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_ros_bag import matrix, pinocchio_head, read_bag, stamp_ns, synthetic_plan

import snakehead
from snakehead import BasePlacement, SnakeRobot
from snakehead.app import ros_bag, ros_messages
from snakehead.model.placement import GroundFrame
from snakehead.terrain.surfaces import plane_normal_deg

TARGET = ((0.1, 0.5, 0.35), (0.0, 1.0, 0.0))
ROLL_DEG, PITCH_DEG = -6.0, 10.0
PLANE_POINT = np.array([0.2, -0.1, 0.05])


def normal() -> np.ndarray:
    """The slope's upward unit normal in the world: Ry(pitch) Rx(roll) e_z."""
    return Rotation.from_euler("YX", [PITCH_DEG, ROLL_DEG], degrees=True).as_matrix() @ np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def ground() -> GroundFrame:
    g = GroundFrame.of_plane(plane_normal_deg(ROLL_DEG, PITCH_DEG), PLANE_POINT)
    np.testing.assert_allclose(g.matrix[:3, 2], normal(), atol=1e-12)
    assert abs(normal() @ (g.matrix[:3, 3] - PLANE_POINT)) < 1e-12
    return g


@pytest.fixture(scope="module")
def plan(ground):
    p = snakehead.plan([TARGET], base=BasePlacement(-0.05, 0.03, -0.2, ground=ground))
    assert p.success, p.failure
    return p


@pytest.fixture(scope="module")
def topics(plan, tmp_path_factory):
    return read_bag(ros_bag.write_plan_bag(plan, tmp_path_factory.mktemp("slope") / "slope.mcap"))


def tf_tree(messages) -> dict[str, list[tuple[int, str, np.ndarray]]]:
    """child frame -> [(stamp ns, parent, pose in the parent)] from /tf."""
    out: dict[str, list] = {}
    for log_time, msg in messages:
        for tr in msg.transforms:
            assert stamp_ns(tr.header) == log_time
            out.setdefault(tr.child_frame_id, []).append((log_time, tr.header.frame_id, matrix(tr.transform)))
    return out


def world_pose(tree, frame: str, k: int) -> np.ndarray:
    """The world pose of ``frame`` at its k-th stamp, composed along the tree's parents."""
    T = np.eye(4)
    while frame != ros_bag.WORLD_FRAME:
        _, parent, P = tree[frame][k]
        T = P @ T
        frame = parent
    return T


def test_tf_holds_the_ground_frame_and_the_chain_to_the_head(plan, ground, topics):
    robot = plan.robot
    tree = tf_tree(topics["/tf"])
    assert set(tree) == {ros_bag.GROUND_FRAME, robot.description_root, "target/target"}
    assert {p for _, p, _ in tree[ros_bag.GROUND_FRAME]} == {ros_bag.WORLD_FRAME}
    assert {p for _, p, _ in tree[robot.description_root]} == {ros_bag.GROUND_FRAME}
    assert {p for _, p, _ in tree["target/target"]} == {ros_bag.GROUND_FRAME}
    for _, _, G in tree[ros_bag.GROUND_FRAME]:  # the same at every stamp: the slope's frame
        np.testing.assert_allclose(G, ground.matrix, atol=1e-12)
        np.testing.assert_allclose(G[:3, 2], normal(), atol=1e-12)
    # the target's world pose: its position turned by the ground frame, its x-axis the direction turned
    T = world_pose(tree, "target/target", 0)
    G = ground.matrix
    np.testing.assert_allclose(T[:3, 3], G[:3, :3] @ TARGET[0] + G[:3, 3], atol=1e-12)
    np.testing.assert_allclose(T[:3, 0], G[:3, :3] @ TARGET[1], atol=1e-12)
    # world -> ground -> URDF root (/tf), then pinocchio's FK of /robot_description at /joint_states: the head's
    # world pose
    urdf = topics["/robot_description"][0][1].data
    states = topics["/joint_states"]
    stamps = [s for s, _, _ in tree[robot.description_root]]
    tip = robot.user_frames["head_tip"]
    for k in np.linspace(0, len(states) - 1, 8).astype(int):
        stamp, js = states[k]
        j = int(np.searchsorted(stamps, stamp, side="right")) - 1
        head = world_pose(tree, robot.description_root, j) @ pinocchio_head(urdf, tip, js.name, js.position)
        np.testing.assert_allclose(head, G @ robot.frame(plan.q[k], tip, plan.base), atol=1e-9)
    head = world_pose(tree, robot.description_root, len(stamps) - 1) @ pinocchio_head(
        urdf, tip, states[-1][1].name, states[-1][1].position)
    np.testing.assert_allclose(head[:3, 3], G[:3, :3] @ TARGET[0] + G[:3, 3], atol=1e-4)  # at the target


def test_markers_are_in_the_ground_frame_with_the_tilted_plane(plan, ground, topics):
    messages = topics["/snakehead/markers"]
    assert all(m.header.frame_id == ros_bag.GROUND_FRAME for _, msg in messages for m in msg.markers)
    static = [msg for _, msg in messages if msg.markers[0].ns == "targets"]
    (plane,) = [m for m in static[0].markers if m.ns == "ground_plane"]
    assert plane.type == ros_messages.CUBE and plane.scale.z == ros_bag.GROUND_PLANE_THICKNESS
    G = ground.matrix
    P = np.eye(4)
    o = plane.pose.orientation
    P[:3, :3] = Rotation.from_quat([o.x, o.y, o.z, o.w]).as_matrix()
    P[:3, 3] = [plane.pose.position.x, plane.pose.position.y, plane.pose.position.z]
    W = G @ P  # the plane's world pose, through the bag's own world -> ground
    np.testing.assert_allclose(W[:3, 2], normal(), atol=1e-12)  # its thin axis is the slope's normal
    assert (W[:3, 3] - PLANE_POINT) @ normal() == pytest.approx(-ros_bag.GROUND_PLANE_THICKNESS / 2, abs=1e-12)
    # it spans the body: the root's ground-frame x, y inside it
    root = plan.robot.root_pose(plan.base)[:3, 3]
    assert abs(root[0] - P[0, 3]) < plane.scale.x / 2 and abs(root[1] - P[1, 3]) < plane.scale.y / 2
    # the support polygon and the ZMP lie on the slope (GROUND_MARK_Z above it) once in the world
    ground_msgs = [msg for _, msg in messages if msg.markers[0].ns == "support_polygon"]
    assert ground_msgs
    for msg in ground_msgs[:: max(1, len(ground_msgs) // 5)]:
        polygon, zmp = msg.markers
        ring = np.array([[p.x, p.y, p.z] for p in polygon.points]) @ G[:3, :3].T + G[:3, 3]
        np.testing.assert_allclose((ring - PLANE_POINT) @ normal(), ros_bag.GROUND_MARK_Z, atol=1e-12)
        z = np.array([zmp.pose.position.x, zmp.pose.position.y, zmp.pose.position.z]) @ G[:3, :3].T + G[:3, 3]
        assert (z - PLANE_POINT) @ normal() == pytest.approx(ros_bag.GROUND_MARK_Z, abs=1e-12)
    # the target's arrow ends at the target, in the ground frame
    arrow = static[0].markers[0]
    o = arrow.pose.orientation
    end = np.array([arrow.pose.position.x, arrow.pose.position.y, arrow.pose.position.z]) + \
        Rotation.from_quat([o.x, o.y, o.z, o.w]).as_matrix()[:, 0] * arrow.scale.x
    np.testing.assert_allclose(end, TARGET[0], atol=1e-12)


def test_a_flat_plan_has_no_ground_frame(tmp_path):
    robot = SnakeRobot.default()
    fake = synthetic_plan(robot, BasePlacement(0.1, 0.2, 0.3), n=20)
    topics = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "flat.mcap"))
    tree = tf_tree(topics["/tf"])
    assert set(tree) == {robot.description_root}
    assert all(m.header.frame_id == ros_bag.WORLD_FRAME for _, msg in topics["/snakehead/markers"]
               for m in msg.markers)
    np.testing.assert_allclose(tree[robot.description_root][0][2], robot.root_pose(fake.base), atol=1e-12)


def test_a_synthetic_slope_plan_of_another_robot(ground, tmp_path):
    """The SEA-snake style robot (its URDF root is not its body frame) on the slope: the chain still ends at the
    head's world pose."""
    from snakehead.samples.published import write_robot

    robot = SnakeRobot.from_file(write_robot("sea", tmp_path))
    base = BasePlacement(-0.2, 0.5, -2.0, ground=ground)
    fake = synthetic_plan(robot, base, seed=3, targets=[SimpleNamespace(name="t", position=np.array([0.1, 0.2, 0.3]),
                                                                        direction=np.array([0.0, 0.0, 1.0]))])
    topics = read_bag(ros_bag.write_plan_bag(fake, tmp_path / "sea.mcap"))
    tree = tf_tree(topics["/tf"])
    urdf = topics["/robot_description"][0][1].data
    tip = robot.user_frames["head_tip"]
    stamps = [s for s, _, _ in tree[robot.description_root]]
    for k in range(0, 50, 9):
        stamp, js = topics["/joint_states"][k]
        j = int(np.searchsorted(stamps, stamp, side="right")) - 1
        head = world_pose(tree, robot.description_root, j) @ pinocchio_head(urdf, tip, js.name, js.position)
        np.testing.assert_allclose(head, ground.matrix @ robot.frame(fake.q[k], tip, base), atol=1e-9)
