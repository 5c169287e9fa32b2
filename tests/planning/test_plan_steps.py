"""The named steps of plan() (planning.planner), of the base's choice (planning.base_choice) and of the whole-body solve
(solve.whole_body.TargetSearch), each on its own, against independent computations (distances by hand, the
uncached bending state, the solves of the public entry points)."""
import numpy as np
import pytest

import snakehead
from snakehead._errors import InputError, InputTypeError, MotionTooLong
from snakehead.geometry import BoxObstacle
from snakehead.margins import DETOUR_MARGIN
from snakehead.planning import base_choice, plan_bounds, planner, start_state
from snakehead.planning.plan_cache import plan_cache_of
from snakehead.planning.plan_result import PlanProgress
from snakehead.planning.waypoints import Waypoints
from snakehead.samples.targets import reachable_targets
from snakehead.scenes import Scene, Target
from snakehead.solve import whole_body as wb
from snakehead.solve.head_controller import HeadController


@pytest.fixture(scope="module")
def controller():
    return HeadController(snakehead.SnakeRobot.default(), method="free_roll", seed=1)


@pytest.fixture(scope="module")
def reachable(controller):
    return reachable_targets(controller, "same", 2, np.random.default_rng(7))


def head_target(controller, dz=-0.05):
    H = controller.robot.head_pose(controller.q_initial, controller.base)
    return H[:3, 3] + [0.0, 0.0, dz], H[:3, 0]


# --- plan(): its input steps ----------------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, error, match", [
    (dict(timing=[1]), InputTypeError, "timing must be a dict"),
    (dict(method="fast"), InputError, "method must be"),
    (dict(seed=-1), InputError, "seed"),
    (dict(allow_relocation="False"), InputTypeError, "allow_relocation must be True or False"),
])
def test_check_options_names_the_bad_option(kwargs, error, match):
    options = dict(timing=None, method="rotated", seed=1, allow_relocation=True) | kwargs
    with pytest.raises(error, match=match):
        planner._check_options(**options)
    planner._check_options(timing={}, method="free_roll", seed=None, allow_relocation=np.bool_(False))  # all good


def test_controller_for_uses_or_makes_the_controller(controller):
    scene = Scene.from_targets([head_target(controller)])
    placed = snakehead.BasePlacement(0.1, 0.2, 0.3)
    saved = controller.base
    try:
        assert planner._controller_for(scene, None, controller, placed, "rotated", 1) is controller
        assert controller.base == placed  # placed where the plan starts
    finally:
        controller.base = saved
    with pytest.raises(InputError, match="not both"):
        planner._controller_for(scene, snakehead.SnakeRobot.default(), controller, None, "rotated", 1)
    with pytest.raises(InputTypeError, match="controller must be a HeadController"):
        planner._controller_for(scene, None, "controller", None, "rotated", 1)
    with pytest.raises(InputTypeError, match="robot must be a SnakeRobot"):
        planner._controller_for(scene, "snake16.toml", None, None, "rotated", 1)
    made = planner._controller_for(scene, controller.robot, None, placed, "free_roll", 3)
    assert made is not controller and made.robot is controller.robot and made.base == placed
    assert made.method == "free_roll"


def test_start_shapes_default_the_base_shape_to_the_start(controller):
    n = controller.robot.n_joints
    q = np.linspace(-0.1, 0.1, n)
    start, shape = planner._start_shapes(controller.robot, q, None)
    np.testing.assert_array_equal(start, q)
    np.testing.assert_array_equal(shape, q)
    start, shape = planner._start_shapes(controller.robot, None, np.zeros(n))
    assert start is None and np.array_equal(shape, np.zeros(n))
    assert planner._start_shapes(controller.robot, None, None) == (None, None)
    with pytest.raises(InputError, match="start_q"):
        planner._start_shapes(controller.robot, np.zeros(n + 1), None)
    with pytest.raises(InputError, match="base_shape"):
        planner._start_shapes(controller.robot, None, [0.0])


def test_progress_reports_and_stops_a_motion_too_long(controller, monkeypatch):
    robot = controller.robot
    scene = Scene.from_targets([head_target(controller), head_target(controller, -0.08)])
    records = []
    report = planner._Progress(records.append, scene, 0.0, robot, {"velocity_limit": 0.5})
    report.stage("base", "choosing")
    assert records[0].kind == "stage" and records[0].name == "base" and records[0].count == 2
    way = Waypoints(robot, controller.base)
    way.start("a", controller.q_initial)
    q = controller.q_initial.copy()
    q[-1] += 0.3
    way._append("b", q)
    way.hold(2.0)

    class Solved:
        success, message = True, ""

    report.target(0, Solved(), 0.5, way)
    assert records[1] == PlanProgress("target", scene.targets[0].name, 1, 2, True, 0.5, records[1].elapsed_s, "")
    # independent: the one step of 0.3 rad at 0.5 rad/s, and the hold
    assert way.least_duration(np.full(robot.n_joints, 0.5)) == pytest.approx(0.3 / 0.5 + 2.0)
    monkeypatch.setattr(plan_bounds, "MAX_MOTION_S", 2.5)
    with pytest.raises(MotionTooLong, match=r"target 2 of 2 .* lasts at least 3 s"):
        report.target(1, Solved(), 0.5, way)


def test_progress_without_a_callback_reports_nothing(controller):
    scene = Scene.from_targets([head_target(controller)])
    report = planner._Progress(None, scene, 0.0, controller.robot, None)
    report.stage("timing", "nothing to tell")  # no callback: nothing called, nothing raised


# --- plan(): the lift and the targets ---------------------------------------------------------------------------
def test_lift_ends_at_the_initial_state_and_keeps_its_path(controller):
    robot = controller.robot
    plan_cache_of(controller).clear()
    q_shape = controller.q_initial
    first = Waypoints(robot, controller.base)
    first.start("bending state", start_state.bending_state(controller, q_shape))
    q = planner._lift(first, controller, q_shape)
    np.testing.assert_array_equal(q, base_choice.shape_of(robot, q_shape, controller.q_initial))
    np.testing.assert_allclose(first.qs[-1], q, atol=1e-12)  # the path ends there (to round-off)
    assert first.lift_index == len(first.qs) - 1 and first.stops == [first.lift_index]
    assert first.lift_cache is plan_cache_of(controller).timed_lifts and len(plan_cache_of(controller).lift_paths) == 1
    # every waypoint of the lift passes the path's own checks
    assert first.feasible(np.array(first.qs)).all()
    again = Waypoints(robot, controller.base)
    again.start("bending state", start_state.bending_state(controller, q_shape))
    planner._lift(again, controller, q_shape)
    assert again.labels == first.labels and all(np.array_equal(a, b) for a, b in zip(again.qs, first.qs))


def test_no_lift_where_the_initial_state_is_in_an_obstacle(controller):
    robot = controller.robot
    head = robot.head_pose(controller.q_initial, controller.base)[:3, 3]
    box = BoxObstacle(centre=head, size=[0.05, 0.05, 0.05])
    way = Waypoints(robot, controller.base, [box])
    q_bend = start_state.bending_state(controller)
    way.start("bending state", q_bend)
    q = planner._lift(way, controller, controller.q_initial)
    np.testing.assert_array_equal(q, q_bend)  # the first move goes from the bending state
    assert len(way.qs) == 1 and way.lift_index is None and way.stops == []


def run_of(scene, controller):
    lines = plan_bounds.check_size(scene)
    return planner._Run(controller, scene, lines, controller.base, [], Waypoints(controller.robot, controller.base),
                        [], wb.PlanSolves(), planner._Progress(None, scene, 0.0, controller.robot, None))


def test_reach_targets_groups_the_line_approaches_into_runs(controller):
    a, d = head_target(controller)
    scene = Scene(name="runs", targets=(
        Target("t0", a, d), Target("t1", a + [0.02, 0, 0], d, approach="line"), Target("t2", a, d),
        Target("t3", a + [0, 0.02, 0], d), Target("t4", a + [0, 0.04, 0], d, approach="line"),
        Target("t5", a + [0, 0.06, 0], d, approach="line")))
    run = run_of(scene, controller)
    calls = []
    run.reach_target = lambda k, q: calls.append(("one", k)) or q
    run.reach_line_run = lambda k, end, q: calls.append(("line", k, end)) or q
    run.reach_targets(controller.q_initial)
    assert calls == [("line", 0, 1), ("one", 2), ("line", 3, 5)]


def test_line_run_poses_follow_the_lines(controller):
    a, d = head_target(controller)
    b = a + [0.0, 0.025, 0.0]
    scene = Scene(name="line", targets=(Target("a", a, d), Target("b", b, d, approach="line", step_m=0.01)))
    poses, owner = run_of(scene, controller).line_run_poses(0, 1)
    # independent: a, then every 10 mm along the 25 mm line, and b
    assert [p[0] for p in poses] == ["a", "b (1/3)", "b (2/3)", "b"]
    assert owner == [0, 1, 1, 1]
    np.testing.assert_allclose(np.array([p[1] for p in poses]),
                               [a, a + [0, 0.01, 0], a + [0, 0.02, 0], b], atol=1e-12)
    assert poses[0][3] is scene.targets[0] and poses[-1][3] is scene.targets[1]
    assert poses[1][3] is None and poses[2][3] is None


def test_reach_target_moves_to_the_solution_and_stops(controller, reachable):
    t = reachable[0]
    scene = Scene(name="one", targets=(Target("t", t.position, t.direction, hold_s=0.5),))
    run = run_of(scene, controller)
    run.way.start("bending state", start_state.bending_state(controller))
    q = run.reach_target(0, controller.q_initial)
    sol = run.results[0].solution
    np.testing.assert_array_equal(q, sol.q)
    assert sol.success
    H = controller.robot.head_pose(q, controller.base)  # independent: forward kinematics
    assert np.linalg.norm(H[:3, 3] - t.position) <= 1e-4
    assert run.results[0].time_s == len(run.way.qs) - 2  # the stop's index, then the hold's waypoint
    assert run.way.holds == {len(run.way.qs) - 2: 0.5}


# --- the base's choice -------------------------------------------------------------------------------------------
def test_first_failure(controller, reachable):
    q0 = controller.q_initial
    assert base_choice._first_failure(controller, controller.base, q0, reachable, [], wb.PlanSolves()) == (None, None)
    far = Target("far", [3.0, 0.0, 0.3], [1.0, 0.0, 0.0])
    first, sol = base_choice._first_failure(controller, controller.base, q0, list(reachable) + [far], [], wb.PlanSolves())
    assert first is far and not sol.success
    q_bend = start_state.bending_state(controller)
    P = controller.robot.frames(q_bend, controller.base)[:, :3, 3].mean(axis=0)
    on_start = BoxObstacle(centre=[P[0], P[1], 0.02], size=[0.3, 0.3, 0.04])
    assert base_choice._first_failure(controller, controller.base, q0, reachable, [on_start], wb.PlanSolves()) == ("the start",
                                                                                                     None)
    assert base_choice._first_failure(controller, controller.base, np.zeros_like(q0), reachable, [], wb.PlanSolves()) == (
        "no curl", None)


def test_has_curl_is_the_bending_state_existing(controller):
    straight = np.zeros(controller.robot.n_joints)
    plan_cache_of(controller).clear()
    assert base_choice.has_curl(controller, controller.q_initial)
    assert not base_choice.has_curl(controller, straight)
    assert len(plan_cache_of(controller).shapes_without_curl) == 1
    assert not base_choice.has_curl(controller, straight)  # from the cache


def test_relocated_for_a_target_out_of_reach(controller):
    robot = controller.robot
    q_far = controller.q_initial
    moved = snakehead.BasePlacement(0.6, 0.3, 0.5)
    H = robot.head_pose(q_far, moved)
    far = Target("far", H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0])
    assert base_choice._first_failure(controller, controller.base, q_far, [far], [], wb.PlanSolves())[0] is far
    found = base_choice._relocated_for(controller, far, q_far, [far], [], wb.PlanSolves())
    assert found is not None
    base, q_shape = found
    assert base != controller.base
    assert np.hypot(base.x - controller.base.x, base.y - controller.base.y) <= base_choice.MAX_RELOCATION_M
    # independent: from that base and shape the target is solved with the base kept, and the shape holds a curl
    sol = wb.solve_target(controller, far.position, far.direction, q_prev=q_shape, base=base, allow_base_move=False,
                          problem=controller.body_problem, min_margin=DETOUR_MARGIN)
    assert sol.success
    start_state.bending_state(controller, q_shape)


# --- the whole-body solve's steps --------------------------------------------------------------------------------
def search_for(controller, position, direction, **kw):
    options = dict(q_prev=None, base=None, obstacles=(), min_margin=DETOUR_MARGIN, budget=wb.SOLVE_BUDGET, problem=None,
                   seed=0, shape_ok=None) | kw
    return wb.TargetSearch(controller, np.asarray(position, float), np.asarray(direction, float), **options)


def test_beyond_reach_is_the_reach_of_the_last_joint(controller):
    """The head link is rigid with the tip: the last joint is its length behind the tip, along the direction, and
    no farther from the frame the neck lifts from than the chain between them."""
    robot = controller.robot
    origin = robot.frame(controller.q_initial, robot.lift_frame, controller.base)[:3, 3]
    reach = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    up, ahead = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    inside = search_for(controller, origin + (reach - 1e-3) * up, up)  # the chain straight up
    outside = search_for(controller, origin + (reach + 2 * wb.POSITION_TOLERANCE) * up, up)
    assert not inside.beyond_reach() and outside.beyond_reach()
    # pointing ahead, the last joint is the head link's length behind the tip
    link = robot.head_link_length
    assert not search_for(controller, origin + (reach - link - 1e-3) * up + link * ahead, ahead).beyond_reach()
    assert search_for(controller, origin + (reach - link + 2 * wb.POSITION_TOLERANCE) * up + link * ahead,
                      ahead).beyond_reach()
    assert search_for(controller, origin + (reach - 1e-3) * up, ahead).beyond_reach()  # the old bound's inside


def test_consider_keeps_the_best_attempt_and_returns_only_a_solution(controller, reachable):
    t = reachable[0]
    search = search_for(controller, t.position, t.direction)
    assert search.consider(controller.q_initial, controller.base, wb.STAGES[1], 0) is None
    worst = search.best
    found = search.consider(t.q, t.base, wb.STAGES[1], 1)  # the configuration the target was made from
    assert found is not None and found.success and search.best is found
    assert wb.solution_rank(found) > wb.solution_rank(worst)
    assert search.consider(controller.q_initial, controller.base, wb.STAGES[1], 2) is None
    assert search.best is found


def test_base_kept_solves_a_reachable_target_where_the_entry_does(controller, reachable):
    t = reachable[1]
    sol = search_for(controller, t.position, t.direction, min_margin=DETOUR_MARGIN).base_kept(near=False)
    assert sol is not None and sol.success and sol.base == controller.base
    assert sol.stage in wb.STAGES[:2]
    H = controller.robot.head_pose(sol.q, sol.base)  # independent: forward kinematics
    assert np.linalg.norm(H[:3, 3] - t.position) <= wb.POSITION_TOLERANCE
    entry = wb.solve_checked_target(controller, t.position, t.direction, min_margin=DETOUR_MARGIN,
                                    allow_base_move=False)
    np.testing.assert_array_equal(entry.q, sol.q)


def test_base_moved_reaches_beyond_and_respects_shape_ok(controller):
    robot = controller.robot
    moved = snakehead.BasePlacement(0.6, 0.3, 0.5)
    H = robot.head_pose(controller.q_initial, moved)
    position, direction = H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0]
    search = search_for(controller, position, direction)
    assert search.base_kept(near=False) is None  # out of reach from the base as it is
    sol = search.base_moved()
    assert sol is not None and sol.success and sol.stage == wb.STAGES[2] and sol.base != controller.base
    H = robot.head_pose(sol.q, sol.base)
    assert np.linalg.norm(H[:3, 3] - position) <= wb.POSITION_TOLERANCE
    refused = search_for(controller, position, direction, shape_ok=lambda q: False)
    assert refused.base_moved() is None
    assert refused.best is None or refused.best.stage is None or refused.best.base == controller.base
