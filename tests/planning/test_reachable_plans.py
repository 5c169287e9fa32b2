"""Plans of head targets reachable by construction (``samples.targets``) that the planner once failed, each now
planned and its motion checked by independent computations (FK, support polygons, ground and self clearance at
every 2 ms sample); and the pieces of the planner that fixed them: a relocated base holds a stable curl of the
neck and head (``choose_base``), long steps of a move are split and every move is checked densely, and after the
lift a move's static margin is the base's own (``waypoints.Waypoints``)."""
from __future__ import annotations

import numpy as np
import pytest
from plan_verification import verify_plan
from shape_reference import box_corners

import snakehead
from snakehead import margins
from snakehead._errors import Infeasible
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.planning import start_state, waypoints
from snakehead.samples.targets import reachable_targets
from snakehead.solve import whole_body as wb


@pytest.fixture(scope="module")
def controller():
    # as bench/targets.py makes it
    return snakehead.HeadController(snakehead.SnakeRobot.default(), method="free_roll", seed=1)


def test_long_step_of_a_tracked_move_is_no_longer_trusted(controller):
    """Target 1 of ``reachable_targets(controller, "same", 8, default_rng(0))``: the tracked Cartesian move ended
    in a 3.1 rad jump (its fit stuck at joint limits) that three checked configurations per step did not see
    dipping to 7 mm of static margin; the plan failed ("the centre of mass is 0.5 mm outside the support polygon
    near waypoint 10"). Now planned; the path's steps are at most MAX_WAYPOINT_STEP."""
    t = reachable_targets(controller, "same", 8, np.random.default_rng(0))[1]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    verify_plan(plan, t.position, t.direction)
    Q = np.array([q for _, _, q in plan.states])
    assert np.abs(np.diff(Q, axis=0)).max() <= waypoints.MAX_WAYPOINT_STEP + 1e-9


def test_relocated_base_holds_a_stable_curl(controller):
    """Target 44 of ``reachable_targets(controller, "shape", 100, default_rng(1))`` is reached only from another
    base. The whole-body solve with the base moved finds it first with a straight base, where no curl of the neck
    and head is stable (the bending state every plan lifts from), so the planner kept the start's base and failed
    ("out of reach"). With ``shape_ok`` the solve goes on to a shape that holds one; the plan succeeds."""
    robot = controller.robot
    t = reachable_targets(controller, "shape", 100, np.random.default_rng(1))[44]
    prob = controller.body_problem
    plain = wb.solve_target(controller, t.position, t.direction, problem=prob, min_margin=margins.DETOUR_MARGIN)
    assert plain.success and plain.stage == wb.STAGES[2]
    with pytest.raises(Infeasible, match="no curl"):  # the case: the first base found holds no curl
        start_state.bending_state(controller, plain.q)

    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    verify_plan(plan, t.position, t.direction)
    assert plan.relocation is not None
    # independent: the plan starts with the neck and head lying flat on the ground (every pitch joint 0) over the
    # relocated base, stable on the base's own footprint and clear of itself
    q_bend = plan.q[0]
    pitch = np.array([k == "pitch" for k in robot.joint_kinds])
    np.testing.assert_allclose(q_bend[pitch], 0.0, atol=1e-12)
    assert stability.static_margin(robot, q_bend, plan.base, contact="footprint") > 0.0
    assert coll.self_clearance(robot, q_bend[None], plan.base)[0] > 0.0


def test_shape_ok_is_obeyed(controller):
    """solve_target's ``shape_ok``: a solution with the base moved has a shape that passes it (here: every yaw
    joint of the base bent by more than 0.1 rad); the solution passes every check, recomputed independently."""
    robot = controller.robot
    t = reachable_targets(controller, "shape", 100, np.random.default_rng(1))[44]
    yaw = np.flatnonzero(controller.body_problem.ground_yaw)
    refused = []

    def bent(q):
        ok = bool(np.abs(q[yaw]).min() > 0.1)
        refused.extend([] if ok else [q.copy()])
        return ok

    sol = wb.solve_target(controller, t.position, t.direction, problem=controller.body_problem,
                          min_margin=margins.DETOUR_MARGIN, shape_ok=bent)
    assert sol.success and sol.stage == wb.STAGES[2] and np.abs(sol.q[yaw]).min() > 0.1
    assert refused  # a straight shape was found first and refused
    H = robot.head_pose(sol.q, sol.base)
    assert np.linalg.norm(H[:3, 3] - t.position) <= 1e-4
    assert np.degrees(np.arccos(np.clip(H[:3, 0] @ t.direction, -1.0, 1.0))) <= 0.05
    assert min(stability.static_margin(robot, sol.q, sol.base, contact=c) for c in ("ground", "footprint")) \
        >= margins.DETOUR_MARGIN - 1e-9
    assert coll.ground_clearance(robot, sol.q, sol.base)[0, robot.lifted_links].min() >= -coll.GROUND_TOLERANCE
    assert coll.self_clearance(robot, sol.q[None], sol.base)[0] > 0.0


def test_split_steps_and_checked_configurations():
    qs = np.array([[0.0, 0.0], [0.3, -0.1], [1.3, 0.9], [1.3, 0.9]])
    split = waypoints.split_steps(qs, most=0.5)
    # the same straight segments: 1 + 2 + 1 steps, none longer than 0.5 rad, the waypoints kept
    assert len(split) == 1 + 1 + 2 + 1
    assert np.abs(np.diff(split, axis=0)).max() <= 0.5 + 1e-12
    for q in qs:
        assert np.min(np.abs(split - q).max(axis=1)) < 1e-12
    np.testing.assert_allclose(split[2], [0.8, 0.4])
    checked = waypoints.check_points(qs, step=0.05)
    assert np.abs(np.diff(checked, axis=0)).max() <= 0.05 + 1e-12
    assert len(checked) == 1 + 6 + 20 + waypoints.DENSIFY + 1


def test_after_the_lift_a_move_stands_on_the_base(controller):
    """Once the head is up, ``Waypoints.feasible`` takes the smaller of the ground contact's margin and the
    base's own: a configuration that keeps DETOUR_MARGIN only because a neck or head link rests on the ground is
    refused after the lift (and accepted before it). Independent: stability.static_margin with both models."""
    robot = controller.robot
    rng = np.random.default_rng(4)
    lifted = np.arange(robot.lift_joints.start, robot.n_joints)
    way = waypoints.Waypoints(robot, controller.base)
    found = 0
    for _ in range(400):
        q = controller.q_initial.copy()
        q[lifted] += rng.normal(0.0, 0.6, len(lifted))
        q = np.clip(q, robot.lower, robot.upper)
        ground = stability.static_margin(robot, q, controller.base, contact="ground")
        footprint = stability.static_margin(robot, q, controller.base, contact="footprint")
        if not (ground >= margins.DETOUR_MARGIN > footprint):
            continue
        if (coll.ground_clearance(robot, q, controller.base)[0, robot.lifted_links].min() < -coll.GROUND_TOLERANCE
                or coll.self_clearance(robot, q[None], controller.base)[0] <= 0):
            continue
        way.lift_index = None
        assert way.feasible(q[None])[0]
        way.lift_index = 15
        assert not way.feasible(q[None])[0]
        found += 1
    assert found > 0  # the case the check is for was drawn


def base_only_margin(robot, q, base):
    """Independent of the planner's code: the CoM's signed distance to the convex hull (scipy's qhull) of the
    bottom corners (tests/shape_reference.py) of the boxes of the links before the first lifted one (those lie flat on the ground)."""
    from scipy.spatial import ConvexHull

    first_lifted = robot.body.model.joint_child_links[robot.lift_joints.start]
    links = robot.shaped_links[robot.shaped_links < first_lifted]
    corners = box_corners(robot, robot.frames(q, base)[None], links)[0]
    bottom = corners[corners[:, 2] < 1e-9][:, :2]
    hull = ConvexHull(bottom)
    c = stability.center_of_mass(robot, q, base)[:2]
    return -float(np.max(hull.equations[:, :2] @ c + hull.equations[:, 2]))


@pytest.fixture(scope="module")
def generated():
    """A generated snake unlike the default: 13 joints starting with a pitch joint, 10 cm modules, 6 cm section,
    parts named by link frames (the base ends at a real link, not a marker), a 1-joint neck, a 6-DOF head."""
    from snakehead.kinematics import reachability as ws
    from snakehead.model.generate import SnakeSpec, snake_urdf

    spec = SnakeSpec(n_joints=13, module_length=0.1, section=0.06, mass_per_module=0.3, first_axis="pitch",
                     link_prefix="seg", joint_prefix="j", tip_name="nose")
    robot = snakehead.SnakeRobot.from_urdf(snake_urdf(spec), base_end="seg6", neck_end="seg7", head_tip="nose")
    m = ws.compute(robot, progress=False, voxel=1.5 * ws.default_map_options(robot)["voxel"], directions=12, rolls=2)
    return snakehead.HeadController(robot, m, method="free_roll", seed=1)


def test_targets_stand_on_the_links_that_stay_on_the_ground(generated):
    """Every reachable-by-construction target of a generated snake stands on the links that stay on the ground by
    the targets' margin (scipy's hull), and keeps its neck and head above the ground."""
    robot = generated.robot
    for kind in ("same", "shape", "place"):
        for t in reachable_targets(generated, kind, 5, np.random.default_rng(3)):
            assert base_only_margin(robot, t.q, t.base) > 0.005
            assert coll.ground_clearance(robot, t.q, t.base)[0, robot.lifted_links].min() >= 0.0
            H = robot.head_pose(t.q, t.base)
            np.testing.assert_allclose(H[:3, 3], t.position, atol=1e-12)


def test_generated_snake_plans_other_shapes(generated):
    """A generated snake (13 joints, pitch first) plans targets that need another base shape: relocated, every
    check recomputed, and after the lift every planned waypoint stands on the links that stay on the ground by
    DETOUR_MARGIN (scipy's hull), as ``Waypoints.feasible`` asks."""
    for t in reachable_targets(generated, "shape", 3, np.random.default_rng(0)):
        plan = snakehead.plan([(t.position, t.direction)], controller=generated)
        verify_plan(plan, t.position, t.direction)
        lifted = [q for label, _, q in plan.states if not label.startswith(("bending", "initial"))]
        assert lifted
        assert min(base_only_margin(plan.robot, q, plan.base) for q in lifted) >= margins.DETOUR_MARGIN - 1e-9


def test_margins_after_the_lift_on_a_generated_snake(generated):
    """``Waypoints.static_margins`` after the lift: the smaller of the ground contact's margin and that over the links
    that stay on the ground (here the base's last link is a real link, not a marker: the 'footprint' model leaves
    it out, the planner must not). Independent: stability.static_margin and scipy's hull."""
    robot = generated.robot
    rng = np.random.default_rng(2)
    way = waypoints.Waypoints(robot, snakehead.BasePlacement(0.2, -0.1, 0.7))
    way.lift_index = 1
    lifted = np.arange(robot.lift_joints.start, robot.n_joints)
    qs = np.tile(generated.q_initial, (30, 1))
    qs[:, lifted] += rng.normal(0.0, 0.4, (30, len(lifted)))
    qs[15:, :robot.lift_joints.start] *= 0.5  # a second base shape
    qs = np.clip(qs, robot.lower, robot.upper)
    expected = [min(stability.static_margin(robot, q, way.base, contact="ground"), base_only_margin(robot, q, way.base))
                for q in qs]
    np.testing.assert_allclose(way.static_margins(qs), expected, atol=1e-9)
    footprint = [stability.static_margin(robot, q, way.base, contact="footprint") for q in qs]
    assert np.max(np.array(expected) - footprint) > 0.01  # the case: the footprint model would refuse far more


def test_targets_keep_the_lifted_links_off_the_ground():
    """A target's pose keeps every link after the first one the neck lifts (which pivots on its edge) at least
    TARGET_GROUND_CLEARANCE above the ground: a head resting on the ground is a contact no plan counts on."""
    from snakehead.samples.targets import KINDS, TARGET_GROUND_CLEARANCE

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    pivot = int(robot.joint_frames[robot.lift_joints.start])
    after = robot.lifted_links[robot.lifted_links > pivot]
    rng = np.random.default_rng(4)
    for kind in KINDS:
        for t in reachable_targets(controller, kind, 5, rng):
            clear = coll.ground_clearance(robot, t.q, t.base)[0]
            assert clear[after].min() >= TARGET_GROUND_CLEARANCE and clear[robot.lifted_links].min() >= 0.0
