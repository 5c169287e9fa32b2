"""The stability-aware whole-body solve (solve.whole_body): gradients against finite differences, and solutions
for targets reachable by construction checked by independent computations (FK, support polygon, clearances)."""
from __future__ import annotations

import numpy as np
import pytest

import snakehead
from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import InputTypeError
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.ground_contact import GROUND_TOLERANCE
from snakehead.kinematics import reachability as ws
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.solve import target_search
from snakehead.solve import whole_body as wb


@pytest.fixture(scope="module")
def default():
    robot = SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    return robot, controller, wb.BodyProblem(robot)


@pytest.fixture(scope="module")
def generated():
    spec = SnakeSpec(n_joints=20, module_length=0.07, section=0.05, mass_per_module=0.15,
                     markers={"p0": 10, "b0": 12}, tip_name="tip")
    robot = SnakeRobot.from_urdf(snake_urdf(spec), base_end="p0", neck_end="b0", head_tip="tip")
    m = ws.compute(robot, voxel=0.07, directions=12, rolls=2, progress=False)
    controller = snakehead.HeadController(robot, m, method="free_roll", seed=1)
    return robot, controller, wb.BodyProblem(robot)


def reachable(robot, controller, prob, rng, kind: str):
    """A target reachable by construction: the head pose of a random configuration (neck and head joints uniform
    within their limits; for kind "shape" the base's yaw joints too, for "place" another placement) that is
    statically stable, keeps the neck and head above the ground and does not touch itself."""
    for _ in range(5000):
        q = controller.q_initial.copy()
        lift = np.arange(robot.lift_joints.start, robot.n_joints)
        q[lift] = rng.uniform(robot.lower[lift], robot.upper[lift])
        base = BasePlacement()
        if kind == "shape":
            yaw = np.flatnonzero(prob.ground_yaw)
            q[yaw] = rng.uniform(robot.lower[yaw], robot.upper[yaw])
        if kind == "place":
            base = BasePlacement(*rng.uniform([-1, -1, -np.pi], [1, 1, np.pi]))
        if (stability.static_margin(robot, q, base, contact="ground") > 0.005
                and coll.ground_clearance(robot, q, base)[0, robot.lifted_links].min() >= 0
                and coll.self_clearance(robot, q, base)[0] > 0):
            H = robot.head_pose(q, base)
            return H[:3, 3], H[:3, 0]
    raise AssertionError("no reachable target drawn")


def independent_checks(robot, sol, position, direction, base_start, q_start):
    assert sol.success, (sol.reason, sol)
    H = robot.head_pose(sol.q, sol.base)  # FK of the whole body
    assert np.linalg.norm(H[:3, 3] - position) <= 1e-4
    assert np.degrees(np.arccos(np.clip(H[:3, 0] @ direction, -1, 1))) <= 0.05
    assert stability.static_margin(robot, sol.q, sol.base, contact="ground") >= wb.MIN_MARGIN - 1e-12
    assert coll.ground_clearance(robot, sol.q, sol.base)[0, robot.lifted_links].min() >= -coll.GROUND_TOLERANCE
    assert coll.self_clearance(robot, sol.q, sol.base)[0] > 0
    assert np.all(sol.q >= robot.lower - 1e-12) and np.all(sol.q <= robot.upper + 1e-12)
    # the base lies flat on the ground: its pitch joints at zero, its boxes resting on the ground
    flat = wb.BodyProblem(robot).flat
    np.testing.assert_array_equal(sol.q[flat], 0.0)
    F = robot.frames(sol.q, sol.base)
    assert np.abs(robot.lowest_z(F[None], robot.base_links)).max() < 1e-9
    if sol.stage in ("segmented", "whole-body, base kept"):
        assert sol.base == base_start
        np.testing.assert_array_equal(sol.q[robot.parts.base], q_start[robot.parts.base])


def test_gradients_match_finite_differences(default):
    robot, controller, prob = default
    rng = np.random.default_rng(0)
    q0 = controller.q_initial.copy()
    q0[prob.free] += rng.normal(0, 0.05, prob.free.sum())
    base = BasePlacement(0.1, -0.2, 0.3)
    box = snakehead.BoxObstacle([0.3, 0.5, 0.2], [0.1, 0.1, 0.1])
    obj = wb.RefinementProblem(prob, q0, base, np.array([0.1, 0.5, 0.3]), np.array([0.0, 1.0, 0.0]), True, [box],
                               0.005, 0.002, 0.002, None)
    z = obj.pack(q0, base)
    e = obj.evaluate(z)
    h = 1e-7
    for value, jac in (("eq", "eq_jac"), ("ineq", "ineq_jac"), ("margin", "margin_jac")):
        fd = np.array([(np.atleast_1d(obj.evaluate(z + h * u)[value]) - np.atleast_1d(obj.evaluate(z - h * u)[value]))
                       / (2 * h) for u in np.eye(len(z))]).T
        np.testing.assert_allclose(np.atleast_2d(e[jac]), fd, atol=1e-6)


def test_segment_closest_matches_dense_sampling():
    """The capsules' closest points (Ericson 5.1.9), against a brute-force search over both segments; parallel,
    crossing and degenerate (point) segments included."""
    rng = np.random.default_rng(7)
    p1, q1, p2, q2 = (rng.normal(size=(60, 3)) for _ in range(4))
    q2[:10] = p2[:10] + 2.0 * (q1[:10] - p1[:10])  # parallel
    q1[10:15] = p1[10:15]  # a point against a segment
    q2[15:20], q1[15:20] = p2[15:20], p1[15:20]  # two points
    s, t = coll.segment_closest(p1, q1, p2, q2)
    assert np.all((0 <= s) & (s <= 1) & (0 <= t) & (t <= 1))
    found = np.linalg.norm(p1 + s[:, None] * (q1 - p1) - p2 - t[:, None] * (q2 - p2), axis=1)
    u = np.linspace(0.0, 1.0, 401)
    a = p1[:, None] + u[None, :, None] * (q1 - p1)[:, None]  # (60, 401, 3)
    b = p2[:, None] + u[None, :, None] * (q2 - p2)[:, None]
    brute = np.linalg.norm(a[:, :, None] - b[:, None], axis=-1).min(axis=(1, 2))
    assert np.all(found <= brute + 1e-12)
    assert np.all(found >= brute - 2e-2 * np.linalg.norm(q1 - p1, axis=1).clip(1e-3))


def test_checked_margin_ignores_lifted_links_resting_on_the_ground(default):
    """With the body problem, check_solution's static margin is the smaller of the ground contact's (every corner
    that touches) and the base's own (here the links before the lift, lying flat: the 'footprint' model); a pose
    whose neck rests on the ground is judged by the base alone. Independent: stability.static_margin."""
    robot, controller, prob = default
    assert np.array_equal(prob.ground_links, np.arange(robot.parts.base.stop + 1))  # the base's links
    rng = np.random.default_rng(4)
    lifted = np.arange(robot.lift_joints.start, robot.n_joints)
    touching = 0
    for _ in range(40):
        q = controller.q_initial.copy()
        q[lifted] += rng.normal(0.0, 0.5, len(lifted))
        q = np.clip(q, robot.lower, robot.upper)
        base = controller.base
        H = robot.head_pose(q, base)
        chk = wb.check_solution(robot, q, base, H[:3, 3], H[:3, 0], problem=prob)
        ground = stability.static_margin(robot, q, base, contact="ground")
        footprint = stability.static_margin(robot, q, base, contact="footprint")
        assert chk["static_margin_m"] == pytest.approx(min(ground, footprint), abs=1e-9)
        touching += ground > footprint + 1e-6
    assert touching > 0  # some poses do lean on a lifted link: the case the check is for


def test_hull_indices_match_qhull():
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(1)
    for k in range(300):
        p = rng.normal(size=(int(rng.integers(3, 50)), 2))
        if k % 3 == 0:
            p = np.round(p, 1)  # duplicates and collinear points
        h = stability.hull_indices(p)
        assert ConvexHull(p[h]).volume == pytest.approx(ConvexHull(p).volume, abs=1e-12)
    assert len(stability.hull_indices(np.array([[0, 0], [1, 1], [2, 2.0]]))) == 2  # collinear: the extremes


@pytest.mark.parametrize("kind, count", [("same", 12), ("shape", 6), ("place", 6)])
def test_reachable_targets_default_robot(default, kind, count):
    robot, controller, prob = default
    rng = np.random.default_rng({"same": 10, "shape": 11, "place": 12}[kind])
    stages = []
    for _ in range(count):
        p, d = reachable(robot, controller, prob, rng, kind)
        sol = wb.solve_target(controller, p, d, problem=prob)
        independent_checks(robot, sol, p, d, controller.base, controller.q_initial)
        stages.append(sol.stage)
    assert set(stages) <= set(wb.STAGES)


def test_reachable_targets_generated_robot(generated):
    robot, controller, prob = generated
    rng = np.random.default_rng(5)
    for kind in ("same", "shape", "place"):
        for _ in range(3):
            p, d = reachable(robot, controller, prob, rng, kind)
            sol = wb.solve_target(controller, p, d, problem=prob)
            independent_checks(robot, sol, p, d, controller.base, controller.q_initial)


def test_base_kept_when_not_allowed_to_move(default):
    robot, controller, prob = default
    far = np.array([2.0, 2.0, 0.3])
    sol = wb.solve_target(controller, far, [1.0, 0.0, 0.0], problem=prob, allow_base_move=False)
    assert not sol.success and sol.reason == "out of reach" and sol.base == controller.base
    moved = wb.solve_target(controller, far, [1.0, 0.0, 0.0], problem=prob)
    independent_checks(robot, moved, far, np.array([1.0, 0.0, 0.0]), controller.base, controller.q_initial)
    assert moved.stage == "whole-body, base moved"


def test_failure_reasons(default):
    robot, controller, prob = default
    high = wb.solve_target(controller, [0.3, 0.3, 3.0], [0, 0, 1], problem=prob, budget=8)
    assert high.reason == "out of reach" and high.stage is None
    # a box over the only region the head can reach from here: no clear pose with the base kept
    sol = wb.solve_target(controller, [0.15, 0.5, 0.4], [0, 1, 0], problem=prob, allow_base_move=False,
                          obstacles=[snakehead.BoxObstacle([0.15, 0.3, 0.3], [1.5, 0.3, 0.6])], budget=8)
    assert sol.reason in ("no clear pose", "out of reach")


def test_bad_input(default):
    robot, controller, prob = default
    with pytest.raises(ValueError, match="position"):
        wb.solve_target(controller, [0.1, np.nan, 0.3], [0, 1, 0], problem=prob)
    with pytest.raises(ValueError, match="direction"):
        wb.solve_target(controller, [0.1, 0.5, 0.3], [0, 0, 0], problem=prob)
    with pytest.raises(ValueError, match="start"):
        wb.solve_whole_body(robot, [0.1, 0.5, 0.3], [0, 1, 0], [])
    with pytest.raises(InputTypeError, match="robot must be a SnakeRobot, got str"):
        wb.BodyProblem("robot")


@pytest.mark.parametrize("which", ["default", "generated"])
def test_beyond_the_lifted_chain_reach_is_out_of_reach_without_ik(default, generated, which, monkeypatch):
    """The pre-check that skips the base-kept stages: the lifted chain's reach bounds the head tip's distance from
    the frame the neck lifts from (checked on random configurations), and a target beyond it is out of reach with the
    base kept without any IK run (the segmented solve and the lifted chain's IK are replaced by failing stubs)."""
    robot, controller = (default[0], default[1]) if which == "default" else (generated[0], generated[1])
    rng = np.random.default_rng(3)
    reach = robot.sub_chain(robot.lift_frame, robot.parts.head_tip).reach
    for _ in range(300):
        q = robot.random_configuration(rng)
        F = robot.frames(q)
        assert np.linalg.norm(F[robot.link_index(robot.parts.head_tip), :3, 3]
                              - F[robot.link_index(robot.lift_frame), :3, 3]) <= reach + 1e-12
    origin = robot.frame(controller.q_initial, robot.lift_frame, controller.base)[:3, 3]
    far = origin + [reach + 0.05, 0.0, 0.0]

    def no_ik(*args, **kwargs):
        raise AssertionError("no IK should run for a target beyond the reach")

    monkeypatch.setattr(controller, "solve", no_ik)
    monkeypatch.setattr(target_search, "lifted_candidates", no_ik)
    sol = wb.solve_target(controller, far, [1.0, 0.0, 0.0], allow_base_move=False)
    assert not sol.success and sol.reason == "out of reach" and sol.base == controller.base
    assert sol.position_error_m > 0.05


def test_margin_alone_equals_margin_and_gradient(default, generated):
    """BodyProblem.margin (the checks') is margin_and_gradient's margin, on random configurations of two robots."""
    for robot, _, prob in (default, (generated[0], generated[1], wb.BodyProblem(generated[0]))):
        rng = np.random.default_rng(8)
        base = BasePlacement(0.2, -0.4, 0.9)
        for _ in range(40):
            q = robot.random_configuration(rng)
            F = prob.frames(q, base)
            expected = prob.margin_and_gradient(F, base)[0]
            got = prob.margin(F)
            assert got == expected or abs(got - expected) < 1e-12, (got, expected)


def _mixed_batch(robot, controller, prob, rng, count):
    """Configurations around the initial one: the base's flat shape and the lifted joints perturbed (some lean on a
    lifted link, some tip over, some touch themselves)."""
    qs = np.tile(controller.q_initial, (count, 1))
    lifted = np.arange(robot.lift_joints.start, robot.n_joints)
    yaw = np.flatnonzero(prob.ground_yaw)
    qs[:, lifted] += rng.normal(0.0, 0.6, (count, len(lifted)))
    qs[1::2, yaw] += rng.normal(0.0, 0.4, (count // 2, len(yaw)))
    return np.clip(qs, robot.lower, robot.upper)


def test_body_problem_margins_of_a_batch_match_qhull(default):
    """BodyProblem.margins (a batch at once: the contacts masked, the core's hull per sample) against Qhull's hull of
    each sample's ground-link box corners within GROUND_TOLERANCE of each link's lowest, and the centre of mass summed
    link by link; collinear contacts give -inf."""
    from hull_reference import com_reference, hull_vertices, margin_to_hull
    from shape_reference import box_corners

    robot, controller, prob = default
    rng = np.random.default_rng(21)
    base = BasePlacement(-0.3, 0.5, 2.0)
    qs = _mixed_batch(robot, controller, prob, rng, 40)
    qs[0, :robot.lift_joints.start] = 0.0  # a straight base: its contacts are two lines (a rectangle)
    frames = robot.frames_many(qs, base)
    got = prob.margins(frames)
    for k in range(len(qs)):
        kept = []
        for link in prob.ground_links:
            c = box_corners(robot, frames[k:k + 1], [link])[0]
            kept.append(c[c[:, 2] <= c[:, 2].min() + GROUND_TOLERANCE, :2])
        pts = np.concatenate(kept)
        xy = com_reference(robot, frames[k])[:2]
        ref = margin_to_hull(pts, xy) if hull_vertices(pts) is not None else -np.inf
        assert got[k] == pytest.approx(ref, abs=1e-9), k
        assert prob.margin(frames[k]) == got[k]
    # a degenerate support (every contact on one line): -inf, as the single margin says
    line = np.zeros((1,) + frames.shape[1:])
    line[0] = frames[0]
    assert prob.margins(line)[0] == prob.margin(frames[0])


def test_check_solutions_of_a_batch_match_independent_checks(default):
    """check_solutions (a batch in one pass) field by field against independent computations per configuration:
    the head by forward kinematics (robot.head_pose), the static margin by Qhull over the box corners on the ground
    (the smaller of every link's and the ground links' own), the lowest lifted box corner, the self clearance and
    the obstacle clearance by the one-configuration routines; and the verdict by the rule written out."""
    from hull_reference import com_reference, hull_vertices, margin_to_hull
    from shape_reference import box_corners

    robot, controller, prob = default
    rng = np.random.default_rng(22)
    base = BasePlacement(0.1, -0.2, 0.3)
    qs = _mixed_batch(robot, controller, prob, rng, 24)
    obstacles = [snakehead.BoxObstacle(robot.head_pose(qs[3], base)[:3, 3] + [0.0, 0.0, 0.06], [0.1, 0.1, 0.05])]
    reasons = set()
    for target in (0, 3, 5):  # the head pose of one configuration of the batch: that one reaches it
        H = robot.head_pose(qs[target], base)
        got = wb.check_solutions(robot, qs, base, H[:3, 3], H[:3, 0], obstacles, min_margin=wb.MIN_MARGIN,
                                 problem=prob)
        for k, chk in enumerate(got):
            F = robot.frames(qs[k], base)
            Hk = F[robot.link_index(robot.parts.head_tip)]
            pe = np.linalg.norm(Hk[:3, 3] - H[:3, 3])
            de = np.degrees(np.arccos(np.clip(Hk[:3, 0] @ H[:3, 0], -1, 1)))
            corners = box_corners(robot, F[None], robot.shaped_links)[0]
            order = np.argsort(corners.reshape(-1, 8, 3)[..., 2], axis=-1, kind="stable")
            lowest = np.take_along_axis(corners.reshape(-1, 8, 3), order[..., None], 1)[:, :4].reshape(-1, 3)
            xy = com_reference(robot, F)[:2]
            whole = margin_to_hull(lowest[lowest[:, 2] <= GROUND_TOLERANCE, :2], xy)
            own = []
            for link in prob.ground_links:
                c = box_corners(robot, F[None], [link])[0]
                own.append(c[c[:, 2] <= c[:, 2].min() + GROUND_TOLERANCE, :2])
            own_pts = np.concatenate(own)
            base_own = margin_to_hull(own_pts, xy) if hull_vertices(own_pts) is not None else -np.inf
            margin = min(whole, base_own)
            ground = box_corners(robot, F[None], robot.lifted_links)[0][:, 2].min()
            selfc = coll.self_clearance(robot, qs[k], base)[0]
            obst = coll.collision_check(robot, qs[k][None], obstacles, base, exact_within=0.01).distance[0]
            assert chk["position_error_m"] == pytest.approx(pe, abs=1e-12)
            assert chk["direction_error_deg"] == pytest.approx(de, abs=1e-6)
            assert chk["static_margin_m"] == pytest.approx(margin, abs=1e-9)
            assert chk["ground_clearance_m"] == pytest.approx(ground, abs=1e-12)
            assert chk["self_clearance_m"] == pytest.approx(selfc, abs=1e-12)
            assert chk["obstacle_clearance_m"] == pytest.approx(obst, abs=1e-12)
            reason = ("out of reach" if pe > wb.POSITION_TOLERANCE or np.radians(de) > wb.DIRECTION_TOLERANCE else
                      "no stable pose" if margin < wb.MIN_MARGIN else
                      "no clear pose" if (ground < -coll.GROUND_TOLERANCE or selfc <= 0.0
                                          or obst <= wb.OBSTACLE_CLEARANCE) else None)
            assert chk["reason"] == reason
            reasons.add(reason)
            one = wb.check_solution(robot, qs[k], base, H[:3, 3], H[:3, 0], obstacles, problem=prob)
            assert one["reason"] == chk["reason"]
            for key in ("position_error_m", "static_margin_m", "ground_clearance_m", "self_clearance_m"):
                assert one[key] == pytest.approx(chk[key], abs=1e-12)
    assert "out of reach" in reasons and len(reasons) >= 2  # the rule's branches are exercised


def test_solve_is_deterministic_and_its_work_counted(default):
    """The same target, placement and seed give the same solution twice (the search is bounded by a count of
    solves, not by the clock); a smaller budget bounds stage 3's solves and solve_whole_body's starts."""
    robot, controller, prob = default
    moved = BasePlacement(0.6, 0.3, 0.5)
    H = robot.head_pose(controller.q_initial, moved)
    position, direction = H[:3, 3] + [0.0, 0.0, -0.05], H[:3, 0]
    first = wb.solve_target(controller, position, direction, problem=prob)
    again = wb.solve_target(controller, position, direction, problem=prob)
    assert first.success and first.stage == wb.STAGES[2]
    np.testing.assert_array_equal(first.q, again.q)
    assert (first.base, first.reason, first.static_margin_m) == (again.base, again.reason, again.static_margin_m)
    far = np.array([3.0, 0.0, 0.05])  # out of reach of every placement the search tries
    for budget in (1, 3, 7):
        search = wb.TargetSearch(controller, far, np.array([0.0, 0.0, 1.0]), None, None, (), wb.MIN_MARGIN, budget,
                                 prob, 0, None)
        assert search.base_moved() is None and search.spent == budget
    sol = wb.solve_whole_body(robot, far, [0, 0, 1], [(controller.q_initial, controller.base)] * 3, problem=prob,
                              budget=2)
    assert sol.starts == 2 and not sol.success
    with pytest.raises(ValueError, match="budget"):
        wb.solve_target(controller, far, [0, 0, 1], problem=prob, budget=0)


def test_relocation_solves_nothing_twice(default, monkeypatch):
    """choose_base for a target reached only from another base shape: with the plan's PlanSolves, no segmented solve,
    no batch of the lifted chain's IK and no solve with the base kept is made twice with the same arguments (the
    relocation's search takes the failed solve with the base kept from the first failure), and the plan's own
    solve of the target is a hit."""
    from snakehead.planning import base_choice, target_solves
    from snakehead.samples.targets import reachable_targets

    robot, controller, prob = default
    calls: list[tuple] = []
    solve_checked = type(controller).solve_checked

    def counted(self, position, direction, q_prev=None, base=None, accept=None, allow_base_move=None):
        calls.append((np.asarray(position).tobytes(), np.asarray(q_prev).tobytes(), base, accept is None))
        return solve_checked(self, position, direction, q_prev, base, accept, allow_base_move)

    kept_calls = []
    base_kept = wb.TargetSearch.base_kept

    def counted_kept(self, near):
        kept_calls.append((self.position.tobytes(), self.q_now.tobytes(), self.base))
        return base_kept(self, near)

    ik_calls = []
    lifted_candidates = wb.lifted_candidates

    def counted_ik(prob, q_now, base, position, direction, seed=0):
        ik_calls.append((q_now.tobytes(), base, position.tobytes(), direction.tobytes(), seed))
        return lifted_candidates(prob, q_now, base, position, direction, seed)

    monkeypatch.setattr(type(controller), "solve_checked", counted)
    monkeypatch.setattr(wb.TargetSearch, "base_kept", counted_kept)
    monkeypatch.setattr(target_search, "lifted_candidates", counted_ik)
    t = reachable_targets(controller, "shape", 1, np.random.default_rng(3))[0]
    target = snakehead.scenes.Target("t", t.position, t.direction)
    memo = wb.PlanSolves()
    chosen, q_shape, relocation, _ = base_choice.choose_base(controller, [target], solved=memo)
    assert relocation is not None  # the target needs another base
    assert len(calls) == len(set(calls)) and len(kept_calls) == len(set(kept_calls))
    assert len(ik_calls) == len(set(ik_calls))
    before = (len(calls), len(kept_calls), len(ik_calls))
    sol = target_solves.solve_kept(controller, target.position, target.direction, q_shape, chosen, [], memo)
    assert sol.success and (len(calls), len(kept_calls), len(ik_calls)) == before  # the plan's: from the choice
    # without a PlanSolves the same steps repeat solves (what the memo saves), and find the same base
    calls.clear(), ik_calls.clear()
    q0 = controller.q_initial
    assert base_choice._first_failure(controller, controller.base, q0, [target], [], None)[0] is target
    again = base_choice._relocated_for(controller, target, q0, [target], [], None)
    assert again is not None and again[0] == chosen and np.array_equal(again[1], q_shape)
    assert len(calls) + len(ik_calls) > len(set(calls)) + len(set(ik_calls))


def test_rolled_frames_are_roll_about_x():
    """The candidates' rolled frames (one call for every angle) are head.roll_about_x's, bit for bit (the IK's
    seeded results, and so the plans, depend on them)."""
    from snakehead.solve.head import frame_from_direction, roll_about_x

    T = frame_from_direction([0.3, -0.2, 0.4], [0.2, 0.5, 0.8])
    angles = 2 * np.pi * np.arange(wb.CANDIDATE_ROLLS) / wb.CANDIDATE_ROLLS
    got = wb.rolled_frames(T, angles)
    for k, a in enumerate(angles):
        np.testing.assert_array_equal(got[k], roll_about_x(T, a))
        # independent: the rotation about the frame's own x-axis keeps x and turns y towards z by the angle
        np.testing.assert_allclose(got[k][:3, 0], T[:3, 0], atol=1e-15)
        assert got[k][:3, 1] @ T[:3, 1] == pytest.approx(np.cos(a), abs=1e-12)
        assert got[k][:3, 1] @ T[:3, 2] == pytest.approx(np.sin(a), abs=1e-12)

