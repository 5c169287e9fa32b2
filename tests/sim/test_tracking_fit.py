"""The core's tracking fit (snakehead._core.TrackingFit, include/snakehead/tracking_fit.hpp): one step's stacked
residual, Jacobian and step against the numpy code it replaced (tests/tracking_reference.py), and whole
interpolations against the fit's definition stated independently (tests/fit_reference.py: pinocchio's forward
kinematics, closed-form lowest points, coal's distances; scipy's least_squares on the same objective), on the default
robot and on published-style snakes (cylinders along z, meshes, fat cylinders, spheres), from random start/end pairs
with the ground and self terms active and not.
"""
from __future__ import annotations

import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares

import snakehead
from snakehead import InputError, _core
from snakehead.geometry.shapes import pair_distances
from snakehead.samples import published
from snakehead.trajectory import cartesian

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tracking_reference import tracking_system  # noqa: E402

STYLES = ["default", "sea", "mesh", "rsnake", "head6"]


@pytest.fixture(scope="module", params=STYLES)
def styled(request, tmp_path_factory) -> tuple[str, snakehead.SnakeRobot]:
    if request.param == "default":
        return "default", snakehead.SnakeRobot.default()
    folder = tmp_path_factory.mktemp(request.param)
    return request.param, snakehead.SnakeRobot.from_file(published.write_robot(request.param, folder))


def configurations(robot: snakehead.SnakeRobot, draws: int = 2000, seed: int = 3) -> dict[str, list[np.ndarray]]:
    """Random configurations (the joints before the lift at zero: the base on the ground; the lifted ones uniform
    within their limits), up to three of each kind: "self" (shapes of the fit's self pairs closer than
    TRACKING_SELF_CLEARANCE), "self, apart" (those of them with no shapes overlapping), "ground" (no such pair, some
    lifted link below TRACKING_CLEARANCE), "clear" (neither)."""
    rng = np.random.default_rng(seed)
    base = snakehead.BasePlacement()
    lift, _, pairs = fit_inputs(robot)
    qs = np.zeros((draws, robot.n_joints))
    qs[:, lift] = rng.uniform(robot.lower[lift], robot.upper[lift], (draws, len(lift)))
    F = robot.frames_many(qs, base)
    d = pair_distances(F, robot.geometry, F, robot.geometry, pairs).min(axis=1, initial=np.inf)
    close = d < cartesian.TRACKING_SELF_CLEARANCE
    low = robot.lowest_z(F, robot.lifted_links).min(axis=1) < cartesian.TRACKING_CLEARANCE
    kinds = {"self": close, "self, apart": close & (d >= 0.0), "ground": low & ~close, "clear": ~low & ~close}
    return {k: list(qs[np.flatnonzero(m)[:3]]) for k, m in kinds.items()}


def fit_inputs(robot: snakehead.SnakeRobot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    lift = np.arange(robot.lift_joints.start, robot.n_joints)
    return lift, cartesian.tracked_points(robot), cartesian.lifted_self_pairs(robot, lift)


def test_one_step_is_the_numpy_step(styled):
    """Residual, Jacobian and step of the core equal the numpy ones, with ground and self rows and without."""
    style, robot = styled
    base = snakehead.BasePlacement()
    lift, pts, pairs = fit_inputs(robot)
    fit = cartesian.tracking_fit(robot, base, lift, pts)
    rng = np.random.default_rng(5)
    rows = {}
    for kind, qs in configurations(robot).items():
        for q in qs if kind != "self, apart" else []:
            current = q[lift] + rng.normal(0.0, 0.05, len(lift))
            target = robot.frames(q, base)[pts, :3, 3] + rng.normal(0.0, 0.02, (len(pts), 3))
            r, J, step = fit.step(q, current, target)
            r_ref, J_ref = tracking_system(robot, q, current, target, lift, pts, pairs, base)
            assert r.shape == r_ref.shape and J.shape == J_ref.shape
            np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-12)
            # the self rows' forward differences divide the distances' round-off by the 1e-6 rad step
            np.testing.assert_allclose(J, J_ref, rtol=0, atol=1e-6)
            A = J_ref.T @ J_ref + cartesian.TRACKING_DAMPING ** 2 * np.eye(len(lift))
            np.testing.assert_allclose(step, -np.linalg.solve(A, J_ref.T @ r_ref), rtol=0, atol=1e-6)
            F = robot.frames(q, base)
            ground = int((robot.lowest_point_per_link(F, robot.lifted_links)[:, 2] < cartesian.TRACKING_CLEARANCE).sum())
            rows.setdefault(kind, []).append((ground, len(r) - 3 * len(pts) - len(lift) - ground))
    # the systems compared had self rows, ground rows, and (where the robot has such poses) neither
    assert rows["self"] and all(selfc > 0 for _, selfc in rows["self"])
    assert rows["ground"] and all(g > 0 and selfc == 0 for g, selfc in rows["ground"])
    assert all(g == 0 and selfc == 0 for g, selfc in rows.get("clear", []))
    if style == "default":
        assert rows["clear"]


def planner_like_pairs(robot: snakehead.SnakeRobot, count: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Start/end pairs like a plan's moves: the joints before the lift at zero, the lifted ones within 0.6 of their
    limits, the body clear of itself at both ends."""
    rng = np.random.default_rng(seed)
    base = snakehead.BasePlacement()
    lift, _, pairs = fit_inputs(robot)
    out: list[tuple[np.ndarray, np.ndarray]] = []
    while len(out) < count:
        qs = np.zeros((2, robot.n_joints))
        qs[:, lift] = 0.6 * rng.uniform(robot.lower[lift], robot.upper[lift], (2, len(lift)))
        F = robot.frames_many(qs, base)
        if pair_distances(F, robot.geometry, F, robot.geometry, pairs).min(initial=np.inf) > 0.0:
            out.append((qs[0], qs[1]))
    return out


def contact_rows(robot: snakehead.SnakeRobot, ref: cartesian.TrackingInterpolation) -> tuple[int, int]:
    """The ground and self rows of the fit's systems (the numpy code's) at each interior sample's result, summed."""
    base = snakehead.BasePlacement()
    lift, pts, pairs = fit_inputs(robot)
    ground = selfc = 0
    for j in range(1, len(ref.q) - 1):
        F = robot.frames(ref.q[j], base)
        g = int((robot.lowest_point_per_link(F, robot.lifted_links)[:, 2] < cartesian.TRACKING_CLEARANCE).sum())
        r, _ = tracking_system(robot, ref.q[j], ref.q[j - 1][lift], ref.points[j], lift, pts, pairs, base)
        ground, selfc = ground + g, selfc + len(r) - 3 * len(pts) - len(lift) - g
    return ground, selfc


def short_moves_near_contact(robot: snakehead.SnakeRobot, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Moves of up to 0.05 rad per lifted joint from poses whose links are closer than TRACKING_SELF_CLEARANCE
    (not overlapping): the fit's self rows are active along them."""
    rng = np.random.default_rng(seed)
    lift = fit_inputs(robot)[0]
    out = []
    for qa in configurations(robot)["self, apart"]:
        qb = qa.copy()
        qb[lift] = np.clip(qa[lift] + rng.uniform(-0.05, 0.05, len(lift)), robot.lower[lift], robot.upper[lift])
        out.append((qa, qb))
    return out


def fit_objective(robot: snakehead.SnakeRobot, base: snakehead.BasePlacement):
    """The fit's objective stated independently (tests/fit_reference.py: pinocchio, closed-form lowest points, coal)
    with the TRACKING_* weights and clearances."""
    pytest.importorskip("pinocchio")
    pytest.importorskip("coal")
    from fit_reference import FitObjective

    c = cartesian
    return FitObjective(robot, base, *fit_inputs(robot), dict(
        clearance=c.TRACKING_CLEARANCE, ground_weight=c.TRACKING_GROUND_WEIGHT, continuity=c.TRACKING_CONTINUITY,
        self_clearance=c.TRACKING_SELF_CLEARANCE))


def moves(robot: snakehead.SnakeRobot) -> list[tuple[np.ndarray, np.ndarray]]:
    """Plan-like moves and short moves near self contact, "chaotic" ones included (those whose fit a 1e-13 m nudge
    of the base moves by radians: the numpy fit it replaced skipped them)."""
    return planner_like_pairs(robot, 8, seed=7) + short_moves_near_contact(robot, seed=2)


def sample_problem(obj, res: cartesian.TrackingInterpolation, qa: np.ndarray, qb: np.ndarray, j: int):
    """Interior sample j's problem: the joints before the lift (their linear interpolation), the previous sample's
    fitted lifted joints (the warm start and the continuity term's reference), the self pairs that can matter near
    the samples (closer than 5 cm at j or j - 1: those farther add nothing within a step of 1e-6 rad)."""
    q_lin = (1 - res.s[j]) * qa + res.s[j] * qb
    return q_lin, res.q[j - 1, obj.lift], obj.near_pairs([res.q[j], res.q[j - 1]], 0.05)


def one_sided_gradients(obj, x, q_lin, target, current, pairs, h=1e-7) -> tuple[np.ndarray, np.ndarray]:
    """The smaller and larger one-sided difference quotients of the reference objective along each lifted joint: a
    gradient of it lies between them (where a lifted link's lowest point is a tie of corners, e.g. an edge parallel
    to the ground, the objective has a kink and the core differentiates one of the corners)."""
    v = obj.value(x, q_lin, target, current, pairs)
    up = np.array([(obj.value(x + h * e, q_lin, target, current, pairs) - v) / h for e in np.eye(len(x))])
    down = np.array([(v - obj.value(x - h * e, q_lin, target, current, pairs)) / h for e in np.eye(len(x))])
    return np.minimum(up, down), np.maximum(up, down)


def distance_accuracy(obj, pair) -> float:
    """m: how close the core's signed distance of a pair is to the exact one (tests/geometry/test_shape_set.py's bounds: ~1e-6
    on polytopes and spheres; libccd's GJK and EPA on a cylinder stop up to 5e-6 and 3e-5 short)."""
    return 3e-5 if "cylinder" in (obj.shapes[pair[0]].kind, obj.shapes[pair[1]].kind) else 1e-6


#: The core's gradient of the points, ground and continuity rows (exact derivatives) against the reference's
#: one-sided differences (h = 1e-7 rad, their truncation ~1e-7 x the objective's curvature), relative to the largest
#: entry when above 1: measured at most 2.1e-8 on the default, mesh, rsnake and head6 robots, 2.5e-6 on sea's steeper
#: objective (its gradients reach ~50).
GRADIENT_TOLERANCE = 1e-6


@pytest.mark.parametrize("styled", [pytest.param(s, marks=[pytest.mark.slow] if s in ("sea", "mesh") else [])
                                    for s in STYLES], indirect=True)
def test_interpolation_meets_its_definition(styled):
    """Every move, none skipped, against the fit's definition stated independently (tests/fit_reference.py): the
    ends are the given configurations; the joints before the lift interpolate linearly; the lifted ones stay within
    their limits; the points are Eq. 41's between the ends' frame origins (pinocchio's FK), and ``actual`` and
    ``deviation`` are where pinocchio puts the fitted joints. At every interior sample the system the core iterates
    is the reference objective: its sum of squares equal (within what the core's distances are known to be off), its
    self rows the reference's active pairs, the gradient of its other rows (exact derivatives) the reference's.
    Where the fit has converged (its step below 1e-6 rad, no joint on a limit) it is a local minimum: scipy's
    least_squares started there finds nothing lower. (Not every sample converges, and the fit is not always as good
    as scipy's: test_each_sample_is_as_good_as_scipy_from_the_same_start.) The self rows' Jacobian, forward
    differences of the core's own distances, is compared with the numpy code's only (test_one_step_is_the_numpy_step):
    on cylinders libccd's distances are too rough for a difference of 1e-4 rad to match a reference's derivative."""
    style, robot = styled
    base = snakehead.BasePlacement()
    obj = fit_objective(robot, base)
    fit = cartesian.tracking_fit(robot, base, obj.lift, obj.points)
    lift, m, w = obj.lift, len(obj.points), cartesian.TRACKING_GROUND_WEIGHT
    other = np.setdiff1d(np.arange(robot.n_joints), lift)
    none = np.zeros((0, 2), np.int64)
    converged = samples = ground = selfc = 0
    worst = {"value": 0.0, "value / bound": 0.0, "gradient": 0.0, "above scipy": 0.0}
    for qa, qb in moves(robot):
        res = cartesian.tracking_interpolation(robot, qa, qb, 12, base)
        assert np.array_equal(res.q[0], qa) and np.array_equal(res.q[-1], qb)
        lin = (1 - res.s)[:, None] * qa + res.s[:, None] * qb
        np.testing.assert_allclose(res.q[:, other], lin[:, other], rtol=0, atol=1e-15)
        assert (res.q[:, lift] >= obj.lower).all() and (res.q[:, lift] <= obj.upper).all()
        ends = np.array([obj.tracked(qa), obj.tracked(qb)])
        np.testing.assert_allclose(res.points, (1 - res.s)[:, None, None] * ends[0] + res.s[:, None, None] * ends[1],
                                   rtol=0, atol=1e-12)
        actual = np.array([obj.tracked(q) for q in res.q])
        np.testing.assert_allclose(res.actual, actual, rtol=0, atol=1e-12)
        np.testing.assert_allclose(res.deviation, np.linalg.norm(actual - res.points, axis=2).max(axis=1), rtol=0,
                                   atol=1e-12)
        g, c = contact_rows(robot, res)
        ground, selfc = ground + g, selfc + c
        for j in range(1, len(res.q) - 1):
            q_lin, current, pairs = sample_problem(obj, res, qa, qb, j)
            x, target = res.q[j, lift], res.points[j]
            r, J, step = fit.step(res.q[j], current, target)
            ref = obj.residual(x, q_lin, target, current, pairs)
            value = float(ref @ ref)
            assert obj.value(x, q_lin, target, current) == pytest.approx(value, rel=1e-14)  # the far pairs add 0
            # the sum of squares, within what the core's distances may be off by (delta per pair): each active self
            # row w (d - c) moves by w delta, its square by w^2 (2 |d - c| delta + delta^2)
            gaps = ref[3 * m + len(obj.ground):len(ref) - len(lift)] / w
            delta = np.array([distance_accuracy(obj, p) for p in pairs])
            near = gaps < delta  # active in the reference, or within delta of it
            bound = 1e-12 + (w ** 2 * (2 * np.abs(gaps[near]) * delta[near] + delta[near] ** 2)).sum()
            worst["value"] = max(worst["value"], abs(r @ r - value))
            worst["value / bound"] = max(worst["value / bound"], abs(r @ r - value) / bound)
            assert abs(r @ r - value) <= bound, (j, r @ r, value, bound)
            # the rows: points, ground (the reference's active links), self (its active pairs), continuity
            nb = int((ref[3 * m:3 * m + len(obj.ground)] < 0.0).sum())
            core_self = r[3 * m + nb:len(r) - len(lift)] / w
            assert len(core_self) >= (gaps < -delta).sum() and len(core_self) <= near.sum()
            np.testing.assert_allclose(np.sort(core_self), np.sort(gaps[gaps < 0])[:len(core_self)], rtol=0,
                                       atol=delta.max(initial=0.0))
            exact = np.r_[0:3 * m + nb, len(r) - len(lift):len(r)]
            low, high = one_sided_gradients(obj, x, q_lin, target, current, none)
            core_gradient = 2 * J[exact].T @ r[exact]
            excess = np.maximum(low - core_gradient, core_gradient - high).max()
            worst["gradient"] = max(worst["gradient"], excess)
            assert excess <= GRADIENT_TOLERANCE * max(1.0, np.abs(core_gradient).max()), (j, core_gradient, low, high)
            samples += 1
            if np.abs(step).max() < 1e-6 and ((x > obj.lower) & (x < obj.upper)).all():
                converged += 1
                polished = least_squares(lambda y: obj.residual(y, q_lin, target, current, pairs), x,
                                         bounds=(obj.lower, obj.upper), xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                         max_nfev=200)
                # a step below 1e-6 rad leaves ~|J dq|^2 ~ 1e-12 to gain; the core minimises with its own distances,
                # whose objective is within `bound` of the reference's (measured: at most 5e-13 on boxes and spheres,
                # 1.7e-10 with cylinders)
                worst["above scipy"] = max(worst["above scipy"], value - 2 * polished.cost)
                assert value <= 2 * polished.cost * (1 + 1e-9) + 2 * bound, (j, value, 2 * polished.cost)
    print(f"{style}: {samples} samples, {converged} converged, {ground} ground rows, {selfc} self rows; largest "
          f"differences: {worst}")
    # the systems compared had ground rows and, on the default and head6 robots, self rows
    assert converged > 0 and ground > 0
    assert selfc > 0 or style not in ("default", "head6")


@pytest.mark.xfail(strict=True, reason=(
    "open: the fit's Levenberg-Marquardt steps keep a fixed damping (0.01 m), take every step (no acceptance "
    "test) and clip it at the joint limits, 12 steps at most: measured on the default robot's 11 moves, 87 of 110 "
    "samples end above scipy's minimum from the same start (up to 27.3 against 0.31, move 4), 34 of them above "
    "their own start, and samples with a joint on a limit stall where the projected gradient is not zero. "
    "cartesian.tracking_interpolation's 'the fit is the closest in the least-squares sense' holds only where the "
    "fit converged (test_interpolation_meets_its_definition); the fit is in C++, not changed here."))
def test_each_sample_is_as_good_as_scipy_from_the_same_start():
    """At every interior sample of every move (default robot), the fit's objective is no higher than what scipy's
    least_squares (trust-region reflective, within the limits) reaches on the same objective (tests/fit_reference.py)
    from the same start: the previous sample's fitted lifted joints."""
    robot = snakehead.SnakeRobot.default()
    base = snakehead.BasePlacement()
    obj = fit_objective(robot, base)
    worse = []
    for m, (qa, qb) in enumerate(moves(robot)):
        res = cartesian.tracking_interpolation(robot, qa, qb, 12, base)
        for j in range(1, len(res.q) - 1):
            q_lin, current, pairs = sample_problem(obj, res, qa, qb, j)
            target = res.points[j]
            best = least_squares(lambda y: obj.residual(y, q_lin, target, current, pairs), current,
                                 bounds=(obj.lower, obj.upper), xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
            value = obj.value(res.q[j, obj.lift], q_lin, target, current, pairs)
            if value > 2 * best.cost * (1 + 1e-6) + 1e-12:
                rose = value > obj.value(current, q_lin, target, current, pairs)
                worse.append((m, j, round(value, 6), round(2 * best.cost, 6), "above its start" if rose else ""))
    assert not worse, f"{len(worse)} samples above scipy's minimum (move, sample, fit, scipy): {worse}"


def test_one_fit_serves_many_threads():
    """Threads sharing one TrackingFit (the GIL released in fit) get what each call gets alone."""
    robot = snakehead.SnakeRobot.default()
    base = snakehead.BasePlacement()
    lift, pts, _ = fit_inputs(robot)
    fit = cartesian.tracking_fit(robot, base, lift, pts)
    problems = []
    for qa, qb in planner_like_pairs(robot, 6, seed=9):
        s = np.linspace(0.0, 1.0, 12)
        ends = robot.frames_many(np.stack([qa, qb]), base)[:, pts][..., :3, 3]
        problems.append(((1 - s)[:, None] * qa + s[:, None] * qb,
                         (1 - s)[:, None, None] * ends[0] + s[:, None, None] * ends[1]))
    alone = [fit.fit(q, P) for q, P in problems]
    with ThreadPoolExecutor(4) as pool:
        together = list(pool.map(lambda p: fit.fit(*p), problems * 3))
    for k, q in enumerate(together):
        np.testing.assert_array_equal(q, alone[k % len(problems)])


def test_fit_checks_its_input():
    robot = snakehead.SnakeRobot.default()
    base = snakehead.BasePlacement()
    lift, pts, _ = fit_inputs(robot)
    fit = cartesian.tracking_fit(robot, base, lift, pts)
    q = np.zeros((5, robot.n_joints))
    with pytest.raises(InputError, match="targets"):
        fit.fit(q, np.zeros((5, len(pts) + 1, 3)))
    with pytest.raises(InputError, match="q must have shape"):
        fit.fit(np.zeros((5, robot.n_joints + 1)), np.zeros((5, len(pts), 3)))
    bad = q.copy()
    bad[2, 3] = np.nan
    with pytest.raises(InputError, match="finite"):
        fit.fit(bad, np.zeros((5, len(pts), 3)))
    c = cartesian
    settings = dict(damping=c.TRACKING_DAMPING, iterations=c.TRACKING_ITERATIONS, step_tolerance=c.TRACKING_STEP_TOLERANCE,
                    clearance=c.TRACKING_CLEARANCE, ground_weight=c.TRACKING_GROUND_WEIGHT,
                    continuity=c.TRACKING_CONTINUITY, self_clearance=c.TRACKING_SELF_CLEARANCE,
                    self_step=c.TRACKING_SELF_STEP)
    none = np.zeros(0, np.int64)
    with pytest.raises(InputError, match="lifted joint"):
        _core.TrackingFit(robot.body.model, robot.geometry.core, np.eye(4), np.array([robot.n_joints]), pts, none,
                          np.zeros((0, 2), np.int64), **settings)
    with pytest.raises(InputError, match="self_step"):
        _core.TrackingFit(robot.body.model, robot.geometry.core, np.eye(4), lift, pts, none,
                          np.zeros((0, 2), np.int64), **{**settings, "self_step": 0.0})
