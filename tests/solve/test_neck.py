"""Neck part: Eqs. 18-22 and the accepted range of Section 3.3 (3)."""
import numpy as np
import pytest
from scipy.optimize import minimize

from snakehead import BasePlacement, InputError, SnakeRobot
from snakehead.solve import neck as nk


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def curled_base(robot):
    q = np.zeros(robot.n_joints)
    q[robot.parts.base][::2] = np.pi / 4  # yaw joints bend the base in the ground plane
    return q


def test_eq20_geometry():
    rng = np.random.default_rng(0)
    for _ in range(100):
        P0, G0 = rng.normal(size=3), rng.normal(size=3)
        Lc = rng.uniform(0.05, 0.5)
        g = nk.neck_goal(P0, G0, Lc)
        assert np.linalg.norm(g.r_d) == pytest.approx(1.0)
        assert np.linalg.norm(g.G0 - g.P_d) == pytest.approx(Lc)  # Eq. 18 at the desired B0
        # P_d on the line P0 -> G0 (Eq. 19): collinear, between or beyond P0 as Lc says
        np.testing.assert_allclose(np.cross(g.P_d - P0, g.r_d), 0, atol=1e-12)
        assert (g.P_d - P0) @ g.r_d == pytest.approx(np.linalg.norm(G0 - P0) - Lc)


def test_dexterous_distance():
    assert nk.dexterous_distance([0.3, 0.4, 0.0]) == pytest.approx(0.5)


def test_neck_length_is_two_modules(robot):
    assert robot.neck_length == pytest.approx(2 * 0.0865)


def test_solve_neck_matches_a_general_minimiser(robot):
    """Eq. 22 solved by the bounded LM is at least as good as scipy's SLSQP from many starts."""
    q = curled_base(robot)
    P0 = robot.frame(q, "base_end")
    neck = robot.neck_chain
    rng = np.random.default_rng(1)
    for _ in range(10):
        # reachable goals: the neck end at random joint angles, pointing a bit off its own x-axis
        qn = rng.uniform(neck.lower, neck.upper)
        B = P0 @ neck.fk(qn)
        G0 = B[:3, 3] + 0.3 * B[:3, 0] + rng.normal(scale=0.05, size=3)
        goal = nk.neck_goal(P0[:3, 3], G0, 0.3)
        ours = nk.solve_neck(neck, P0, goal)
        assert np.all(ours.q >= neck.lower - 1e-12) and np.all(ours.q <= neck.upper + 1e-12)

        def cost(x):
            T = P0 @ neck.fk(x)
            return np.sum((T[:3, 3] - goal.P_d) ** 2) + 0.01 * np.sum(np.cross(goal.r_d, T[:3, 0]) ** 2)

        ref = min(
            (minimize(cost, x0, method="SLSQP", bounds=list(zip(neck.lower, neck.upper)), options={"ftol": 1e-14})
             for x0 in np.stack(np.meshgrid(np.linspace(-1.4, 1.4, 4), np.linspace(-1.4, 1.4, 4)), -1).reshape(-1, 2)),
            key=lambda r: r.fun,
        )
        assert ours.cost == pytest.approx(cost(ours.q), abs=1e-12)
        assert ours.cost <= ref.fun + 1e-9


def test_solve_neck_exact_when_goal_is_reachable(robot):
    q = curled_base(robot)
    P0 = robot.frame(q, "base_end")
    neck = robot.neck_chain
    qn = np.array([-0.7, 0.4])
    B = P0 @ neck.fk(qn)
    goal = nk.neck_goal(P0[:3, 3], B[:3, 3] + 0.25 * B[:3, 0], 0.25)
    # P_d = B and r_d = x-axis of B only when B's x-axis points away from P0 along the line; build such a goal
    goal = nk.NeckGoal(P0=P0[:3, 3], G0=B[:3, 3] + 0.25 * B[:3, 0], Lc=0.25, r_d=B[:3, 0], P_d=B[:3, 3])
    sol = nk.solve_neck(neck, P0, goal)
    assert sol.position_error_m < 1e-8
    assert sol.direction_error_deg < 1e-5
    np.testing.assert_allclose(sol.q, qn, atol=1e-6)


def test_accepted_range():
    P0 = np.zeros(3)
    assert nk.accepted_range([0.45, 0, 0], P0, Lc=0.3, neck_length=0.173, slack=0.1).accepted
    far = nk.accepted_range([0.6, 0, 0], P0, Lc=0.3, neck_length=0.173, slack=0.1)
    assert not far.accepted and "too far" in far.reason
    near = nk.accepted_range([0.31, 0, 0], P0, Lc=0.3, neck_length=0.173, slack=0.1)
    assert not near.accepted and "too close" in near.reason


def test_base_move_brings_target_in_range(robot):
    q = curled_base(robot)
    base = BasePlacement(0.0, 0.0, 0.0)
    P0_local = np.linalg.inv(robot.root_pose(base)) @ robot.frame(q, "base_end", base)
    Lc, length, slack = 0.3, robot.neck_length, 0.1
    for target in ([2.0, 1.0, 0.3], [-1.0, 0.5, 0.35], [-0.05, 0.42, 0.25]):
        assert not nk.accepted_range(target, robot.frame(q, "base_end", base)[:3, 3], Lc, length, slack).accepted
        moved = nk.base_move_into_range(target, P0_local, base, Lc, length, slack, robot.body_axis_height)
        P0 = robot.frame(q, "base_end", moved)
        check = nk.accepted_range(target, P0[:3, 3], Lc, length, slack)
        assert check.accepted, check.reason
        # P0's body axis points at the target in the ground plane
        heading = P0[:2, 0] / np.linalg.norm(P0[:2, 0])
        to_target = (np.array(target[:2]) - P0[:2, 3]) / np.linalg.norm(np.array(target[:2]) - P0[:2, 3])
        assert heading @ to_target == pytest.approx(1.0, abs=1e-9)


def test_base_move_impossible_when_too_high(robot):
    q = curled_base(robot)
    base = BasePlacement()
    P0_local = robot.frame(q, "base_end", base)
    P0_local = np.linalg.inv(robot.root_pose(base)) @ P0_local
    assert nk.base_move_into_range([0.2, 0.2, 3.0], P0_local, base, 0.3, 0.173, 0.1, robot.body_axis_height) is None


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda: nk.neck_goal([0, 0, 0], [0, 0, 0], 0.3), "coincides"),
        (lambda: nk.neck_goal([0, 0, np.nan], [1, 0, 0], 0.3), "NaN"),
        (lambda: nk.neck_goal([0, 0], [1, 0, 0], 0.3), "shape"),
        (lambda: nk.neck_goal([0, 0, 0], [1, 0, 0], -0.3), "positive"),
        (lambda: nk.accepted_range([1, 0, 0], [0, 0, 0], 0.3, 0.0, 0.1), "positive"),
        (lambda: nk.solve_neck(SnakeRobot.default().neck_chain, np.eye(3), nk.neck_goal([0, 0, 0], [1, 0, 0], 0.3)), "shape"),
        (lambda: nk.solve_neck(SnakeRobot.default().neck_chain, np.eye(4), nk.neck_goal([0, 0, 0], [1, 0, 0], 0.3), h=0), "positive"),
    ],
)
def test_bad_input(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_core_neck_fit_rejects_bad_settings(robot):
    """The core's Eq. 22 fit says which of its inputs is wrong (InputError naming it)."""
    from snakehead import _core

    neck, P0 = robot.lift_chain, np.eye(4)
    good = dict(h=0.01, grid_points=5, grid_fraction=0.9, iterations=60, tolerance=1e-9, continuity_tolerance=1e-4)
    q, cost = _core.fit_neck(neck.model, P0, [0.3, 0.0, 0.1], [1.0, 0.0, 0.0], None, **good)
    assert q.shape == (neck.n_joints,) and cost >= 0.0
    for change, word in ((dict(h=0.0), "h"), (dict(grid_points=0), "grid_points"), (dict(iterations=-1), "iterations"),
                         (dict(grid_fraction=1.5), "grid_fraction"), (dict(tolerance=np.nan), "tolerances")):
        with pytest.raises(InputError, match=word):
            _core.fit_neck(neck.model, P0, [0.3, 0.0, 0.1], [1.0, 0.0, 0.0], None, **{**good, **change})
    with pytest.raises(InputError, match="q_init"):
        _core.fit_neck(neck.model, P0, [0.3, 0.0, 0.1], [1.0, 0.0, 0.0], np.zeros(neck.n_joints + 1), **good)
    with pytest.raises(InputError, match="finite"):
        _core.fit_neck(neck.model, P0, [np.nan, 0.0, 0.1], [1.0, 0.0, 0.0], None, **good)
    with pytest.raises(InputError, match="rigid"):
        _core.fit_neck(neck.model, np.diag([1.0, 1.0, 1.0, 2.0]), [0.3, 0.0, 0.1], [1.0, 0.0, 0.0], None, **good)


def test_solve_neck_refuses_a_neck_without_limits(mixed_urdf):
    """Eq. 22's grid spans the neck's joint limits: a continuous joint (no limits; a robot file must give it some)
    is refused with an InputError that says so, not a NaN grid."""
    from snakehead.model.chain import Chain

    neck = Chain.from_urdf(mixed_urdf, "base", "b")  # j1 revolute, j2 continuous
    with pytest.raises(InputError, match="finite limits"):
        nk.solve_neck(neck, np.eye(4), nk.neck_goal([0.0, 0.0, 0.0], [0.3, 0.0, 0.1], 0.2))
