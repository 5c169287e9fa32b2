"""snakehead.TracIK: solutions checked with FK (and pinocchio-free closed forms), solve types, free roll,
seeds, threads, timeouts and bad input."""
from __future__ import annotations

import threading

import numpy as np
import pytest
from conftest import head6_robot

import snakehead
from snakehead import TracIK
from snakehead._errors import InputTypeError
from snakehead.kinematics.ik import FREE_ROLL, pose_error

EPS = 1e-5


@pytest.fixture(scope="module")
def robot():
    return snakehead.SnakeRobot.default()


@pytest.fixture(scope="module", params=["head6", "head7"])
def chain(request, robot):
    return head6_robot().head_chain if request.param == "head6" else robot.head_chain


@pytest.fixture(scope="module")
def head7(robot):
    return robot.head_chain


@pytest.fixture(scope="module")
def solver7(head7):
    return TracIK.from_chain(head7, seed=0)  # seeded: what it finds does not depend on the clock


def roll_about_x(angle):
    c, s = np.cos(angle), np.sin(angle)
    R = np.eye(4)
    R[1:3, 1:3] = [[c, -s], [s, c]]
    return R


def rotation_angle(Ra, Rb):
    return float(np.arccos(np.clip((np.trace(Ra.T @ Rb) - 1) / 2, -1, 1)))


def assert_solution(chain, T, q, eps=EPS):
    """Independent of the solver's pose error: limits, then position distance and rotation angle from FK
    (a per-axis bound of eps allows at most sqrt(3) eps in norm)."""
    assert q is not None
    q = np.asarray(q)
    assert q.shape == (chain.n_joints,)
    assert np.all(q >= chain.lower) and np.all(q <= chain.upper)
    F = chain.fk(q)
    assert np.linalg.norm(F[:3, 3] - T[:3, 3]) <= np.sqrt(3) * eps * (1 + 1e-9)
    assert rotation_angle(F[:3, :3], T[:3, :3]) <= np.sqrt(3) * eps * (1 + 1e-6) + 1e-7


def test_constructors_and_properties(robot, head7):
    a = TracIK(snakehead.default_urdf_path(), "neck_end", "head_tip", timeout=0.01, epsilon=1e-6, solve_type="Distance")
    b = TracIK(snakehead.default_urdf_path().read_text(), "neck_end", "head_tip")
    c = TracIK.from_chain(head7, seed=3)
    for s in (a, b, c):
        assert s.n_joints == 7
        np.testing.assert_array_equal(s.lower, head7.lower)
        np.testing.assert_array_equal(s.upper, head7.upper)
    assert (a.timeout, a.epsilon, a.solve_type, a.seed) == (0.01, 1e-6, "Distance", None)
    assert c.seed == 3 and b.solve_type == "Speed"
    q = np.linspace(-1, 1, 7)
    np.testing.assert_allclose(c.fk(q), head7.fk(q), atol=1e-14)
    assert "7 joints" in repr(c)


def test_pose_error_is_in_the_target_frame():
    T = np.eye(4)
    T[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # 90 deg about z
    C = T.copy()
    C[1, 3] += 0.1  # base +y is the target's +x
    C = C @ roll_about_x(0.2)
    np.testing.assert_allclose(pose_error(T, C), [0.1, 0, 0, 0.2, 0, 0], atol=1e-12)


def test_solutions_reach_the_pose_within_the_limits(chain):
    ik = TracIK.from_chain(chain, timeout=0.02, seed=1)  # seeded: an evaluation budget, the same count under load
    rng = np.random.default_rng(1)
    solved = 0
    for _ in range(40):
        T = chain.fk(chain.random_configuration(rng))
        q = ik.ik(T, chain.random_configuration(rng))
        if q is not None:
            solved += 1
            assert_solution(chain, T, q)
            assert np.all(np.abs(pose_error(T, chain.fk(q))) <= EPS * (1 + 1e-9))
    assert solved >= 39


@pytest.mark.parametrize("solve_type", ["Speed", "Distance", "Manip1", "Manip2"])
def test_every_solve_type_solves_reachable_targets(head7, solve_type):
    ik = TracIK.from_chain(head7, timeout=0.02, solve_type=solve_type, seed=2)  # seeded: not cut by the clock
    rng = np.random.default_rng(2)
    for _ in range(5):
        T = head7.fk(head7.random_configuration(rng))
        q = ik.ik(T, head7.random_configuration(rng))
        assert_solution(head7, T, q)


def test_distance_is_no_farther_than_speed(head7):
    # Same seed: both follow the same search up to Speed's (first) solution; Distance then keeps the closest.
    rng = np.random.default_rng(3)
    for k in range(5):
        T = head7.fk(head7.random_configuration(rng))
        q0 = head7.random_configuration(rng)
        qs = TracIK.from_chain(head7, timeout=0.003, seed=k).ik(T, q0)
        qd = TracIK.from_chain(head7, timeout=0.003, seed=k, solve_type="Distance").ik(T, q0)
        assert_solution(head7, T, qs)
        assert_solution(head7, T, qd)
        assert np.linalg.norm(qd - q0) <= np.linalg.norm(qs - q0) + 1e-12


def test_manipulability_types_do_no_worse_than_speed(head7):
    rng = np.random.default_rng(4)
    T = head7.fk(head7.random_configuration(rng))
    q0 = head7.random_configuration(rng)

    def measures(q):
        J = head7.jacobian(q)
        s = np.linalg.svd(J, compute_uv=False)
        return np.sqrt(np.linalg.det(J @ J.T)), s[-1] / s[0]

    qs = TracIK.from_chain(head7, timeout=0.003, seed=7).ik(T, q0)
    q1 = TracIK.from_chain(head7, timeout=0.003, seed=7, solve_type="Manip1").ik(T, q0)
    q2 = TracIK.from_chain(head7, timeout=0.003, seed=7, solve_type="Manip2").ik(T, q0)
    for q in (qs, q1, q2):
        assert_solution(head7, T, q)
    assert measures(q1)[0] >= measures(qs)[0] * (1 - 1e-9)
    assert measures(q2)[1] >= measures(qs)[1] * (1 - 1e-9)


def test_free_roll(chain):
    ik = TracIK.from_chain(chain, timeout=0.03, seed=5)  # seeded: an evaluation budget, the same count under load
    rng = np.random.default_rng(5)
    solved = rolled = 0
    for _ in range(30):
        # Position and x-axis reachable (they come from FK); the roll about x is random, often unreachable.
        T = chain.fk(chain.random_configuration(rng)) @ roll_about_x(rng.uniform(-np.pi, np.pi))
        q = ik.ik(T, chain.random_configuration(rng), bounds=FREE_ROLL)
        if q is None:
            continue
        solved += 1
        F = chain.fk(q)
        assert np.all(q >= chain.lower) and np.all(q <= chain.upper)
        assert np.linalg.norm(F[:3, 3] - T[:3, 3]) <= np.sqrt(3) * EPS
        assert np.arccos(np.clip(F[:3, 0] @ T[:3, 0], -1, 1)) <= 2 * EPS + 1e-7
        rolled += np.arccos(np.clip(F[:3, 1] @ T[:3, 1], -1, 1)) > 1e-3
    assert solved >= 29
    assert rolled >= 10, "the roll about x does not look free"
    # The same targets with the roll enforced are often out of reach: the bound matters.
    strict = TracIK.from_chain(chain, timeout=0.002, seed=5)
    rng = np.random.default_rng(5)
    misses = 0
    for _ in range(10):
        T = chain.fk(chain.random_configuration(rng)) @ roll_about_x(rng.uniform(-np.pi, np.pi))
        misses += strict.ik(T, chain.random_configuration(rng)) is None
    if chain.n_joints == 6:
        assert misses >= 3


def test_seeded_calls_are_identical(chain):
    rng = np.random.default_rng(6)
    T = chain.fk(chain.random_configuration(rng))
    q0 = chain.random_configuration(rng)
    for solve_type in ("Speed", "Distance"):
        a = TracIK.from_chain(chain, timeout=0.002, seed=42, solve_type=solve_type)
        b = TracIK.from_chain(chain, timeout=0.002, seed=42, solve_type=solve_type)
        runs = [a.ik(T, q0) for _ in range(3)] + [b.ik(T, q0)]
        assert runs[0] is not None
        for r in runs[1:]:
            np.testing.assert_array_equal(r, runs[0])
    # Without q_init the start comes from the seed alone: identical calls, identical results.
    a = TracIK.from_chain(chain, seed=5)
    b = TracIK.from_chain(chain, seed=5)
    first = a.ik(T)
    assert first is not None
    for _ in range(3):
        np.testing.assert_array_equal(a.ik(T), first)
        np.testing.assert_array_equal(b.ik(T), first)
    poses = np.array([T, T @ roll_about_x(0.0)])
    np.testing.assert_array_equal(a.ik_many(poses)[0], b.ik_many(poses)[0])


@pytest.mark.parametrize("seed", [7, None], ids=["seeded", "unseeded"])
def test_eight_threads_share_one_solver(head7, seed):
    # Seeded, each call is bounded by evaluations, not the clock: 8 threads give what one thread gives, bit for bit,
    # however the machine schedules them. Unseeded (the race, with the pool's workers), what is found is checked, not
    # how much: that depends on the clock.
    solver7 = TracIK.from_chain(head7, timeout=0.05, seed=seed)
    rng = np.random.default_rng(7)
    jobs = [[(head7.fk(head7.random_configuration(rng)), head7.random_configuration(rng)) for _ in range(20)]
            for _ in range(8)]
    results = [None] * 8
    errors = []

    def work(t):
        try:
            results[t] = [solver7.ik(T, q0) for T, q0 in jobs[t]]
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(t,)) for t in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    for t in range(8):
        found = [(T, q) for (T, _), q in zip(jobs[t], results[t]) if q is not None]
        for T, q in found:
            assert_solution(head7, T, q)
        if seed is not None:
            assert len(found) >= 19
            for (T, q0), q in zip(jobs[t], results[t]):
                serial = solver7.ik(T, q0)
                assert (q is None) == (serial is None)
                if q is not None:
                    np.testing.assert_array_equal(q, serial)


def test_ik_many(head7):
    rng = np.random.default_rng(8)
    poses = np.array([head7.fk(head7.random_configuration(rng)) for _ in range(30)])
    q0 = np.array([head7.random_configuration(rng) for _ in range(30)])
    ik = TracIK.from_chain(head7, seed=1)
    q, ok = ik.ik_many(poses, q0)
    assert q.shape == (30, 7) and ok.shape == (30,) and ok.dtype == bool
    assert ok.sum() >= 29
    for k in np.flatnonzero(ok):
        assert_solution(head7, poses[k], q[k])
    q2, ok2 = ik.ik_many(poses, q0)
    np.testing.assert_array_equal(q, q2)
    np.testing.assert_array_equal(ok, ok2)
    q3, ok3 = TracIK.from_chain(head7).ik_many(poses)  # random starts, unseeded
    for k in np.flatnonzero(ok3):
        assert_solution(head7, poses[k], q3[k])
    assert ik.ik_many(np.zeros((0, 4, 4)))[0].shape == (0, 7)


def test_ik_many_streams_solve_part_of_a_batch(head7):
    """A subset of a seeded batch, each target with its index in the batch as its stream, gives that batch's
    answers bit for bit; without the streams the subset's targets get other searches."""
    rng = np.random.default_rng(3)
    poses = np.array([head7.fk(head7.random_configuration(rng)) for _ in range(12)])
    q0 = np.array([head7.random_configuration(rng) for _ in range(12)])
    ik = TracIK.from_chain(head7, seed=2)
    q, ok = ik.ik_many(poses, q0)
    part = np.array([1, 6, 7, 11])
    q_part, ok_part = ik.ik_many(poses[part], q0[part], streams=part)
    np.testing.assert_array_equal(q_part, q[part])
    np.testing.assert_array_equal(ok_part, ok[part])
    assert not np.array_equal(ik.ik_many(poses[part], q0[part])[0], q[part])
    for bad in ([1, 2], [0, 1, 2, -1], [0.0, 1.0, 2.0, 3.0], [[0, 1, 2, 3]]):
        with pytest.raises(ValueError, match="streams"):
            ik.ik_many(poses[part], q0[part], streams=bad)


def test_unreachable_target_returns_none(head7):
    # (how long it takes is measured in bench/; a seeded call ends on its evaluation budget, tests/cpp/test_trac_ik.cpp)
    far = np.eye(4)
    far[0, 3] = 3.0  # beyond reach
    for seed in (None, 1):
        ik = TracIK.from_chain(head7, timeout=0.01, seed=seed)
        assert ik.ik(far, np.zeros(7)) is None


def test_kdl_reference_binding(head7):
    rng = np.random.default_rng(9)
    qt = head7.random_configuration(rng)
    T = head7.fk(qt)
    found, q = snakehead._core.kdl_nr_jl_ik(head7.model, T, np.clip(qt + 0.02, head7.lower, head7.upper), 0.01, 1e-5)
    assert found
    assert np.linalg.norm(head7.fk(q)[:3, 3] - T[:3, 3]) < 2e-5


# --- bad input ---------------------------------------------------------------------------------------------

def good_pose(head7):
    return head7.fk(np.zeros(7))


@pytest.mark.parametrize("pose, match", [
    (np.eye(3), "shape"),
    (np.eye(4)[:, :3], "shape"),
    ("not a pose", "must be numbers, got str"),
])
def test_bad_pose_shapes(solver7, pose, match):
    with pytest.raises(TypeError if isinstance(pose, str) else ValueError, match=match):
        solver7.ik(pose)


def test_bad_pose_values(solver7, head7):
    T = good_pose(head7)
    skew = T.copy()
    skew[0, 1] += 0.1
    with pytest.raises(ValueError, match="not a rotation"):
        solver7.ik(skew)
    mirrored = T.copy()
    mirrored[:3, 0] *= -1
    with pytest.raises(ValueError, match="not a rotation"):
        solver7.ik(mirrored)
    nan = T.copy()
    nan[1, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        solver7.ik(nan)
    last = T.copy()
    last[3, 0] = 1
    with pytest.raises(ValueError, match="last row"):
        solver7.ik(last)
    # The C++ checks stand on their own too.
    with pytest.raises(ValueError, match="orthonormal"):
        solver7._solver.ik(skew, np.zeros(7), None, None, "TRAC-IK")
    with pytest.raises(ValueError, match="NaN"):
        solver7._solver.ik(nan, np.zeros(7), None, None, "TRAC-IK")


def test_bad_q_init(solver7, head7):
    T = good_pose(head7)
    with pytest.raises(ValueError, match="shape"):
        solver7.ik(T, np.zeros(6))
    with pytest.raises(ValueError, match="outside the joint limits"):
        solver7.ik(T, np.full(7, 2.0))
    with pytest.raises(ValueError, match="NaN"):
        solver7.ik(T, np.full(7, np.nan))
    with pytest.raises(ValueError, match="q_init"):
        solver7._solver.ik(T, np.zeros(6), None, None, "TRAC-IK")
    with pytest.raises(ValueError, match="outside the limits"):
        solver7._solver.ik(T, np.full(7, 2.0), None, None, "TRAC-IK")


@pytest.mark.parametrize("kwargs, match", [
    (dict(timeout=0), "timeout"),
    (dict(timeout=-1), "timeout"),
    (dict(timeout=float("nan")), "timeout"),
    (dict(epsilon=0), "epsilon"),
    (dict(epsilon=-1e-5), "epsilon"),
    (dict(solve_type="Fastest"), "solve_type"),
    (dict(seed=-1), "seed"),
    (dict(seed=1.5), "seed must be an integer, got float"),
    (dict(bounds=[0, 0, 0]), "bounds"),
    (dict(bounds=[0, 0, 0, -1, 0, 0]), "bounds"),
    (dict(timeout=10**400), "timeout is too large for a float"),  # was OverflowError
    (dict(timeout=1e10), "timeout must be at most 86400 s"),
    (dict(timeout="1"), "timeout must be a real number, got str"),  # was accepted as 1 s
    (dict(timeout=True), "timeout must be a real number, got bool"),  # was accepted as 1 s
    (dict(epsilon=None), "epsilon must be a real number"),
    (dict(seed=True), "seed must be an integer, got bool"),
    (dict(solve_type=None), "solve_type"),
])
def test_bad_options(head7, kwargs, match):
    """Issue 14, finding 9: a number of the wrong kind is a TypeError, a wrong value a ValueError; both name it."""
    kind = TypeError if "real number" in match or "an integer, got" in match else ValueError
    with pytest.raises(kind, match=match):
        TracIK.from_chain(head7, **kwargs)


def test_bad_options_reach_cpp_checks(head7):
    with pytest.raises(ValueError, match="timeout"):
        snakehead._core.TracIK(head7.model, 0.0, 1e-5, "Speed", np.zeros(6))
    with pytest.raises(ValueError, match="epsilon"):
        snakehead._core.TracIK(head7.model, 0.005, -1.0, "Speed", np.zeros(6))
    with pytest.raises(ValueError, match="solve type"):
        snakehead._core.TracIK(head7.model, 0.005, 1e-5, "Fastest", np.zeros(6))
    with pytest.raises(ValueError, match="bounds"):
        snakehead._core.TracIK(head7.model, 0.005, 1e-5, "Speed", np.zeros(5))


def test_bad_call_bounds(solver7, head7):
    T = good_pose(head7)
    with pytest.raises(ValueError, match="6 entries"):
        solver7.ik(T, bounds=[0, 0])
    with pytest.raises(ValueError, match=">= 0"):
        solver7.ik(T, bounds=[0, 0, 0, 0, 0, -0.1])
    with pytest.raises(ValueError, match=">= 0"):
        solver7.ik(T, bounds=[0, 0, 0, 0, 0, np.nan])
    with pytest.raises(ValueError, match="bounds"):
        solver7._solver.ik(T, np.zeros(7), np.array([0, 0, 0, 0, 0, -1.0]), None, "TRAC-IK")


def test_bad_batch_input(solver7, head7):
    T = good_pose(head7)
    with pytest.raises(ValueError, match="shape"):
        solver7.ik_many(np.array([T, T]), np.zeros((3, 7)))
    with pytest.raises(ValueError, match="shape"):
        solver7.ik_many(np.eye(4))
    skew = T.copy()
    skew[0, 1] += 0.1
    with pytest.raises(ValueError, match=r"poses\[1\]"):
        solver7.ik_many(np.array([T, skew]), np.zeros((2, 7)))
    with pytest.raises(ValueError, match=r"q_inits\[0\]"):
        solver7.ik_many(np.array([T]), np.full((1, 7), 3.0))
    with pytest.raises(ValueError, match="shape"):
        solver7._solver.ik_many(np.array([T, T]), np.zeros((2, 6)))


def test_bad_algorithm_and_fk(solver7, head7):
    with pytest.raises(ValueError, match="algorithm"):
        solver7.ik_ex(good_pose(head7), algorithm="CCD")
    with pytest.raises(ValueError, match="shape"):
        solver7.fk(np.zeros(3))
    with pytest.raises(InputTypeError, match="chain must be a snakehead.Chain, got str"):
        TracIK.from_chain("not a chain")


def test_pose_and_start_forms_accepted(solver7, head7):
    # Lists, integer arrays and a last row within 1e-9 of [0, 0, 0, 1] pass (the fast check defers to
    # _validate.pose for anything it does not accept outright).
    T = good_pose(head7)
    assert solver7.ik(T.tolist(), np.zeros(7).tolist()) is not None
    T2 = T.copy()
    T2[3, 3] += 1e-12
    assert solver7.ik(T2, np.zeros(7, dtype=int)) is not None
    I = np.eye(4, dtype=int)
    I[0, 3] = 5  # out of reach, but a valid pose
    assert TracIK.from_chain(head7, timeout=0.001).ik(I, np.zeros(7)) is None


def test_mixed_chain_with_continuous_and_prismatic_joints():
    # Unbounded (continuous) and prismatic joints; position-only target (all rotation bounds open).
    from pathlib import Path
    chain = snakehead.Chain.from_urdf(Path(__file__).resolve().parents[1] / "data" / "mixed_chain.urdf", "world", "tool")
    assert "continuous" in chain.joint_types and "prismatic" in chain.joint_types
    ik = TracIK.from_chain(chain, timeout=0.02, bounds=[0, 0, 0, np.inf, np.inf, np.inf], seed=10)  # not the clock
    rng = np.random.default_rng(10)
    for _ in range(10):
        T = chain.fk(chain.random_configuration(rng))
        q = ik.ik(T)
        assert q is not None
        assert np.all(q >= chain.lower) and np.all(q <= chain.upper)
        assert np.linalg.norm(chain.fk(q)[:3, 3] - T[:3, 3]) <= np.sqrt(3) * EPS
