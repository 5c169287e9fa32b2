"""The paper's scenarios (Section 4) from their scene files, planned by snakehead.plan on the default robot:
kinematic success and every check by independent computations."""
import numpy as np
import pytest

import snakehead
from snakehead import SnakeRobot
from snakehead._errors import Infeasible, InputError
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.margins import DETOUR_MARGIN
from snakehead.planning import start_state
from snakehead.planning.plan_cache import plan_cache_of
from snakehead.scenes import paper_scene
from snakehead.solve.head_controller import HeadController

HOLE = paper_scene("hole")
WALL = HOLE.obstacles[0]
HOLE_CENTRE = WALL.centre
WALL_SIZE = WALL.size


@pytest.fixture(scope="module")
def controller():
    return HeadController(SnakeRobot.default(), method="free_roll", seed=0)


@pytest.fixture(scope="module")
def spheres(controller):
    return snakehead.plan(paper_scene("spheres"), controller=controller)


@pytest.fixture(scope="module")
def hole(controller):
    return snakehead.plan(HOLE, controller=controller)


def check(result, robot):
    assert result.targets, "no targets"
    for tg in result.targets:
        assert tg.solution.success, tg.solution.message
        # independent: whole-body FK of the planned joints at the target's time
        k = int(np.argmin(np.abs(result.t - tg.time_s)))
        T = robot.head_pose(result.q[k], result.base)
        assert np.linalg.norm(T[:3, 3] - tg.position) <= 1e-4
        assert np.degrees(np.arccos(np.clip(T[:3, 0] @ tg.direction, -1, 1))) <= 0.05
        # a target's state keeps the static margin the moves to and from it keep (else no path leaves it stably)
        margin = stability.static_margin(robot, result.q[k], result.base, contact="ground")
        assert margin >= DETOUR_MARGIN - 1e-6, (tg.name, margin)
        # ... and keeps it on the base alone: a pose that stands only because a lifted link rests on the ground
        # cannot be reached from the air
        base_margin = stability.static_margin(robot, result.q[k], result.base, contact="footprint")
        assert base_margin >= DETOUR_MARGIN - 1e-6, (tg.name, base_margin)
    assert result.stability.inside.all(), f"ZMP outside at t = {result.t[result.stability.argmin]:.3f} s"
    below = coll.below_ground(robot, result.q, result.base)
    assert not below.any()
    assert coll.self_clearance(robot, result.q[::5], result.base).min() > 0  # no two links overlap
    assert np.all(np.diff(result.t) > 0) and result.q.shape == (len(result.t), 16)
    assert np.all(result.q >= robot.lower - 1e-9) and np.all(result.q <= robot.upper + 1e-9)
    assert result.success


def test_spheres(spheres, controller):
    check(spheres, controller.robot)
    # the paper's phases: the bending state (on the ground), lifting the head, then the targets
    labels = [lab for lab, _, _ in spheres.states]
    assert labels[0] == "bending state" and "initial state (head lifted)" in labels
    np.testing.assert_array_equal(spheres.states[0][2], start_state.bending_state(controller))
    names = [t.name for t in spheres.targets]
    assert names == ["sphere 1", "sphere 2"]


def test_hole(hole, controller):
    check(hole, controller.robot)
    assert hole.obstacle_distance is not None and hole.obstacle_distance.min() > 0  # no link touches the wall
    # the reported least distance is the exact one at the samples (every sample's exact distance, independently),
    # not the proof's lower bound between them (which stops tightening once positive)
    truth = coll.collision_check(controller.robot, hole.q, hole.obstacles, hole.base, exact_within=np.inf).distance
    assert hole.min_obstacle_distance_m == pytest.approx(truth.min(), abs=1e-12)
    assert hole.min_obstacle_distance_m > 1e-3 > hole.obstacle_distance.min()  # the bound is far below it here
    # The head link is through: the head tip beyond the wall's far face, on the hole's axis.
    last = controller.robot.head_pose(hole.q[-1], hole.base)
    assert last[1, 3] > HOLE_CENTRE[1] + WALL_SIZE[2] / 2
    assert np.linalg.norm(last[[0, 2], 3] - HOLE_CENTRE[[0, 2]]) < 1e-4
    # nothing but the head link crosses the wall's near face
    F = controller.robot.frames_many(hole.q, hole.base)
    head_link = controller.robot.body.model.joint_child_links[-1]
    near = HOLE_CENTRE[1] - WALL_SIZE[2] / 2
    assert F[:, :head_link + 1, 1, 3].max() < near  # every joint up to the head link's stays in front


def test_bad_parameters(controller):
    with pytest.raises(ValueError, match="acceleration"):
        snakehead.plan(paper_scene("spheres"), controller=controller, timing={"acceleration_limit": 0.0})
    with pytest.raises(TypeError, match="timing"):
        snakehead.plan(paper_scene("spheres"), controller=controller, timing=2.0)
    with pytest.raises(TypeError, match="controller"):
        snakehead.plan(paper_scene("spheres"), controller="no")


def test_wall_stands_on_the_ground():
    wall = WALL
    R = wall.rotation
    centre = wall.centre + R[:, :2] @ wall.hole_offset  # the wall's own centre
    corners = np.array([centre + R @ (np.array([sx, sy, sz]) * wall.size / 2)
                        for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    assert corners[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    assert corners[:, 2].max() == pytest.approx(WALL_SIZE[1])
    # the hole's centre is in the wall and free; a point of the wall just outside the hole's rim is solid
    assert wall.distance_to_points(HOLE_CENTRE[None])[0] == pytest.approx(wall.hole_diameter / 2)
    assert wall.distance_to_points((HOLE_CENTRE + [0, 0, -0.05])[None])[0] == 0.0


def test_bending_state_of_a_base_with_no_stable_curl(controller):
    """A straight base has no support polygon with an interior (its contact points are collinear): no curl is
    stable on it. The bending state says so (it failed on an empty array before, and crashed the planner's choice
    of a base for a random target)."""
    with pytest.raises(Infeasible, match="no curl of the neck and head"):
        start_state.bending_state(controller, np.zeros(controller.robot.n_joints))


def test_bending_state(controller):
    robot = controller.robot
    q = start_state.bending_state(controller)
    np.testing.assert_array_equal(q[robot.parts.base], controller.q_initial[robot.parts.base])
    pitch = np.abs(np.asarray(robot.body.model.joint_axes)[:, 1]) > 0.5
    np.testing.assert_array_equal(q[pitch], 0.0)  # everything lies flat on the ground
    clearance = coll.ground_clearance(robot, q)[0]
    boxed = np.isfinite(clearance)
    np.testing.assert_allclose(clearance[boxed], 0.0, atol=1e-12)
    assert coll.self_clearance(robot, q)[0] > start_state.BENDING_CLEARANCE
    # once lifted, only the base supports: the curl keeps the whole body's CoM over the base's polygon
    from snakehead.dynamics import stability

    assert stability.static_margin(robot, q) > 0.02


def test_self_clearance_detects_overlap(controller):
    robot = controller.robot
    assert coll.self_clearance(robot, np.zeros(16))[0] == pytest.approx(0.0865)  # straight: a module apart
    q = start_state.bending_state(controller)
    yaw_up = [8, 10, 12, 14]
    q[yaw_up] = np.radians([90, 90, 0, 0])  # curls the head across the base: link_14 lies on link_4
    assert coll.self_clearance(robot, q)[0] < 0


@pytest.mark.parametrize("qs, match", [(np.zeros(15), r"qs has shape \(15,\); expected \(T, 16\)"),
                                       (np.zeros((3, 4)), r"qs has shape \(3, 4\); expected \(T, 16\)"),
                                       (np.full(16, np.nan), "qs contains NaN or inf")])
def test_self_clearance_bad_input(controller, qs, match):
    with pytest.raises(InputError, match=match):
        coll.self_clearance(controller.robot, qs)


def test_lift_kept_per_base_shape_gives_the_plan_a_fresh_controller_gives(controller):
    """The controller keeps the lift's checked path and its timing per base shape (they do not depend on where the
    base lies): a plan that reuses them, at another placement, equals the plan of a fresh controller there, and
    its lift is the default placement's in joint space."""
    robot = controller.robot
    moved = snakehead.BasePlacement(0.4, -0.3, 0.8)
    H = robot.head_pose(controller.q_initial, moved)
    target = [(H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0])]
    snakehead.plan([(robot.head_pose(controller.q_initial)[:3, 3], robot.head_pose(controller.q_initial)[:3, 0])],
                   controller=controller)  # the default placement: fills the caches
    assert len(plan_cache_of(controller).lift_paths) and len(plan_cache_of(controller).timed_lifts)
    reused = snakehead.plan(target, controller=controller, base=moved, allow_relocation=False)
    fresh = snakehead.plan(target, controller=HeadController(robot, method="free_roll", seed=0), base=moved,
                           allow_relocation=False)
    assert reused.success and fresh.success, (reused.failure, fresh.failure)
    assert reused.base == moved and fresh.base == moved
    assert reused.q.shape == fresh.q.shape and np.abs(reused.q - fresh.q).max() < 1e-9
    assert [lab for lab, _, _ in reused.states] == [lab for lab, _, _ in fresh.states]
