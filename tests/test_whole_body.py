"""The stability-aware whole-body solve (control.whole_body): gradients against finite differences, and solutions
for targets reachable by construction checked by independent computations (FK, support polygon, clearances)."""
from __future__ import annotations

import numpy as np
import pytest

import snakehead
from snakehead import BasePlacement, SnakeRobot
from snakehead.control import whole_body as wb
from snakehead.dynamics import stability
from snakehead.geometry import collision as coll
from snakehead.kinematics import workspace as ws
from snakehead.model.generate import SnakeSpec, snake_urdf


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
    obj = wb._Objective(prob, q0, base, np.array([0.1, 0.5, 0.3]), np.array([0.0, 1.0, 0.0]), True, [box],
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
    with pytest.raises(TypeError):
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
    monkeypatch.setattr(wb, "lifted_candidates", no_ik)
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
