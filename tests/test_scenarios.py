"""The paper's scenarios (Section 4) on the default robot: kinematic success and every check."""
import numpy as np
import pytest

from snakehead import SnakeRobot, trajectory as tr
from snakehead import scenarios as sc
from snakehead.controller import HeadController


@pytest.fixture(scope="module")
def controller():
    return HeadController(SnakeRobot.default(), method="free_roll", seed=0)


@pytest.fixture(scope="module")
def spheres(controller):
    return sc.catch_spheres(controller)


@pytest.fixture(scope="module")
def hole(controller):
    return sc.through_hole(controller)


def check(result, robot):
    assert result.targets, "no targets"
    for tg in result.targets:
        assert tg.solution.success, tg.solution.message
        # independent: whole-body FK of the planned joints at the target's time
        k = int(np.argmin(np.abs(result.t - tg.time)))
        T = robot.head_pose(result.q[k], result.base)
        assert np.linalg.norm(T[:3, 3] - tg.position) <= 1e-4
        assert np.degrees(np.arccos(np.clip(T[:3, 0] @ tg.direction, -1, 1))) <= 0.05
    assert result.stability.inside.all(), f"ZMP outside at t = {result.t[result.stability.argmin]:.3f} s"
    below = tr.below_ground(robot, result.q, result.base)
    assert not below.any()
    assert np.all(np.diff(result.t) > 0) and result.q.shape == (len(result.t), 16)
    assert np.all(result.q >= robot.lower - 1e-9) and np.all(result.q <= robot.upper + 1e-9)
    assert result.success


def test_spheres(spheres, controller):
    check(spheres, controller.robot)
    names = [t.name for t in spheres.targets]
    assert names == ["sphere 1", "sphere 2"]


def test_hole(hole, controller):
    check(hole, controller.robot)
    assert hole.obstacle_distance is not None and hole.obstacle_distance.min() > 0  # no link touches the wall
    # The head link is through: the head tip beyond the wall's far face, on the hole's axis.
    last = controller.robot.head_pose(hole.q[-1], hole.base)
    assert last[1, 3] > sc.HOLE_CENTRE[1] + sc.WALL_SIZE[2] / 2
    assert np.linalg.norm(last[[0, 2], 3] - sc.HOLE_CENTRE[[0, 2]]) < 1e-4
    # nothing but the head link crosses the wall's near face
    F = controller.robot.frames_many(hole.q, hole.base)
    head_link = controller.robot.body.model.joint_child_links[-1]
    near = sc.HOLE_CENTRE[1] - sc.WALL_SIZE[2] / 2
    assert F[:, :head_link + 1, 1, 3].max() < near  # every joint up to the head link's stays in front


def test_bad_parameters(controller):
    with pytest.raises(ValueError, match="speed"):
        sc.catch_spheres(controller, speed=0.0)
    with pytest.raises(ValueError, match="step"):
        sc.through_hole(controller, step=-0.01)


def test_wall_stands_on_the_ground():
    wall = sc.hole_wall()
    R = wall.rotation
    centre = wall.centre + R[:, :2] @ wall.hole_offset  # the wall's own centre
    corners = np.array([centre + R @ (np.array([sx, sy, sz]) * wall.size / 2)
                        for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    assert corners[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    assert corners[:, 2].max() == pytest.approx(sc.WALL_SIZE[1])
    # the hole's centre is in the wall and free; a point of the wall just outside the hole's rim is solid
    assert wall.distance_to_points(sc.HOLE_CENTRE[None])[0] == pytest.approx(sc.HOLE_DIAMETER / 2)
    assert wall.distance_to_points((sc.HOLE_CENTRE + [0, 0, -0.05])[None])[0] == 0.0
