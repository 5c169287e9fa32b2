"""TOPP-RA in the core (snakehead._core.topp_ra, retiming.topp_ra) against toppra itself (tests/topp_reference.py: toppra's
TOPPRA with its seidel solver over the same constraints, built by toppra's own constraint classes) on random paths,
random limits and random robots; its 2-D LP against scipy's HiGHS; a closed-form bang-bang profile; retime's motions
on both solvers; the steps retime is made of; bad input.

Tolerances: toppra computes its velocity bound in single precision (its _CythonUtils: ``cdef float sdmax``), about
1e-7 relative on x = s'^2, so the controllable sets and the path speeds are compared to REL_TOL of their largest
value; the same gridpoint fails when a path is infeasible."""
from __future__ import annotations

import concurrent.futures
import dataclasses
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.optimize import linprog

import snakehead
from snakehead import _core
from snakehead._errors import Infeasible, InputError
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.retiming import gridpoints, rest_to_rest, timeline, timing, topp_ra
from snakehead.samples import published

#: Controllable sets and path speeds: this share of their largest value (toppra's float32 velocity bound: ~1e-7).
REL_TOL = 1e-6
#: retime's motions on the two solvers: durations within this share (the grids are refined the same way unless a
#: probe between gridpoints lands within round-off of a limit).
DURATION_TOL = 1e-3

GEN14 = SnakeSpec(n_joints=14, module_length=0.08, section=0.045, mass_per_module=0.22, first_axis="yaw",
                  markers={"p0": 7, "b0": 9}, tip_name="tip", name="gen14")


def _robot(name: str) -> snakehead.SnakeRobot:
    if name == "default":
        return snakehead.SnakeRobot.default()
    if name == "gen14":
        return snakehead.SnakeRobot.from_urdf(snake_urdf(GEN14), base_end="p0", neck_end="b0", head_tip="tip")
    style = name.split(":")[1]
    return snakehead.SnakeRobot.from_file(published.write_robot(style, Path(tempfile.mkdtemp()) / style))


@pytest.fixture(scope="module", params=["default", "gen14", "published:head6"])
def robot(request: pytest.FixtureRequest) -> snakehead.SnakeRobot:
    return _robot(request.param)


@pytest.fixture(scope="module")
def reference(toppra: Any) -> Any:
    """tests/topp_reference.py (toppra's TOPPRA over the same constraints), for the tests that compare with it: they
    alone need toppra."""
    import topp_reference

    return topp_reference


def random_waypoints(robot: snakehead.SnakeRobot, rng: np.random.Generator) -> np.ndarray:
    """From the straight body, the neck and head (and a few base yaws) to a random lift, through a waypoint near
    halfway (no turn: one rest-to-rest piece)."""
    n = robot.n_joints
    up = np.arange(robot.parts.neck.start, n)
    W = np.zeros((3, n))
    W[2, up] = rng.uniform(-0.9, 0.9, len(up))
    W[2, :up[0]] = rng.uniform(-0.3, 0.3, up[0]) * (np.arange(up[0]) % 2 == 0)
    W[1] = (0.5 + rng.uniform(-0.05, 0.05, n)) * W[2]
    return np.clip(W, robot.lower, robot.upper)


def random_limits(robot: snakehead.SnakeRobot, rng: np.random.Generator) -> timing.RetimingLimits:
    return timing.resolve_limits(robot, velocity_limit=rng.uniform(0.2, 1.0) * robot.velocity_limit,
                                 acceleration_limit=rng.uniform(0.3, 5.0),
                                 torque_limit=rng.uniform(0.3, 1.0) * robot.effort, zmp_margin=rng.uniform(0.0, 0.02),
                                 friction=rng.uniform(0.1, 0.8))


def grid_points(robot: snakehead.SnakeRobot, W: np.ndarray, limits: timing.RetimingLimits, grid_step: float
                ) -> tuple[rest_to_rest.Piece, timing.GridPoints]:
    piece = rest_to_rest.Piece(robot, snakehead.BasePlacement(), limits, W, 0, len(W) - 1, "monotone")
    return piece, timing.GridPoints.of(robot, piece.base, piece.f, piece.first_grid(grid_step), limits.zmp_margin)


# ------------------------------------------------------------------------------------------------
# the 2-D LP
# ------------------------------------------------------------------------------------------------
def test_lp2d_against_highs() -> None:
    rng = np.random.default_rng(0)
    outcomes = []
    for trial in range(200):
        m = int(rng.integers(0, 30))
        rows = rng.normal(size=(m, 3))
        rows[:, 2] += 2.0 * (trial % 2)
        lo, hi = -rng.uniform(0.5, 5, 2), rng.uniform(0.5, 5, 2)
        v = rng.normal(size=2)
        feasible, u, x = _core.solve_lp2d(v[0], v[1], rows, lo, hi)
        ref = linprog(-v, A_ub=rows[:, :2] if m else None, b_ub=rows[:, 2] if m else None, bounds=list(zip(lo, hi)),
                      method="highs")
        assert feasible == (ref.status == 0), trial
        outcomes.append(feasible)
        if feasible:
            assert v @ [u, x] == pytest.approx(-ref.fun, rel=1e-7, abs=1e-7), trial
            assert m == 0 or (rows[:, :2] @ [u, x] - rows[:, 2]).max() <= 1e-8
    assert 0.2 < np.mean(outcomes) < 0.9  # both kinds, many of each


# ------------------------------------------------------------------------------------------------
# the solver against toppra
# ------------------------------------------------------------------------------------------------
def test_core_matches_toppra_on_random_paths_and_limits(robot: snakehead.SnakeRobot, reference: Any) -> None:
    """Same controllable sets and path speeds, or infeasible at the same gridpoint, over the real constraint set."""
    rng = np.random.default_rng(11)
    kinds = {"feasible": 0, "infeasible": 0}
    for _ in range(10):
        W, limits = random_waypoints(robot, rng), random_limits(robot, rng)
        try:
            _, points = grid_points(robot, W, limits, rng.uniform(0.01, 0.05))
        except Infeasible:  # the lifted body spans no support polygon somewhere: nothing to solve
            continue
        ours = gridpoints.solve_grid(robot, points, limits)
        try:
            ref = reference.toppra_solve_grid(robot, points, limits)
        except ZeroDivisionError:
            # toppra's seidel LP divides by zero on a row 0 u + 0 x <= g < 0 (the path stands still at its ends,
            # q' = q'' = 0, where the CoM is outside the polygon): the core reports that stage infeasible
            assert ours.sd is None
            stage = topp_ra.interpolated(_canonical(robot, points, limits), points.s)
            A, B, C = (M[ours.failed_at] for M in stage)
            assert np.any((A == 0) & (B == 0) & (C < 0))
            continue
        assert ours.failed_at == ref.failed_at
        computed = slice(ours.failed_at + 1, None)  # toppra leaves zeros below the failure, the core NaN
        scale = np.abs(ref.K[computed]).max()
        assert np.abs(ours.K[computed] - ref.K[computed]).max() <= REL_TOL * scale
        if ref.sd is None:
            assert ours.sd is None
            assert np.isnan(ours.K[:ours.failed_at + 1]).all()
            kinds["infeasible"] += 1
        else:
            assert ours.sd is not None
            assert np.abs(ours.sd - ref.sd).max() <= REL_TOL * ref.sd.max()
            kinds["feasible"] += 1
    assert kinds["feasible"] >= 2, kinds


def test_canonical_solve_equals_the_stage_solve_to_the_bit(robot: snakehead.SnakeRobot) -> None:
    """topp_ra.solve (the core discretizes the gridpoints' rows itself, _core.topp_ra_canonical) gives the result of
    _core.topp_ra over the stage matrices of topp_ra.interpolated, to the bit: feasible and infeasible paths."""
    rng = np.random.default_rng(23)
    kinds = set()
    for _ in range(12):
        W, limits = random_waypoints(robot, rng), random_limits(robot, rng)
        try:
            _, points = grid_points(robot, W, limits, rng.uniform(0.01, 0.05))
        except Infeasible:
            continue
        rows = _canonical(robot, points, limits)
        ours, ref = topp_ra.solve(points.s, rows), topp_ra.solve_stages(points.s, rows)
        assert ours.failed_at == ref.failed_at
        np.testing.assert_array_equal(ours.K, ref.K)
        assert (ours.sd is None) == (ref.sd is None)
        if ours.sd is not None:
            np.testing.assert_array_equal(ours.sd, ref.sd)
        kinds.add(ours.sd is not None)
    assert True in kinds, "no feasible path was drawn: the comparison covered only failures"


def test_canonical_solve_refuses_malformed_rows() -> None:
    grid = np.linspace(0.0, 1.0, 6)
    P, Q, R = np.ones((6, 2)), np.zeros((6, 2)), np.ones((6, 2))
    x_max = np.ones(6)
    assert _core.topp_ra_canonical(grid, P, Q, R, x_max).status == "feasible"
    none = np.zeros((6, 0))  # no rows: x_max alone bounds the path, as topp_ra with no stage rows
    ours = _core.topp_ra_canonical(grid, none, none, none, x_max)
    ref = _core.topp_ra(grid, np.zeros((5, 0)), np.zeros((5, 0)), np.zeros((5, 0)), np.tile([-np.inf, np.inf], (5, 1)),
                        np.column_stack([np.zeros(6), x_max]))
    np.testing.assert_array_equal(ours.x, ref.x)
    bad = P.copy()
    bad[2, 1] = np.nan
    for args, match in (((grid, bad, Q, R, x_max), "P must be finite"),
                        ((grid, P, Q[:, :1], R, x_max), "Q must have shape"),
                        ((grid, P, Q, R[:5], x_max), "R must have shape"),
                        ((grid, P, Q, R, x_max[:5]), "x_max"),
                        ((grid, P, Q, R, np.where(np.arange(6) == 3, np.nan, x_max)), "NaN"),
                        ((grid[::-1], P, Q, R, x_max), "increasing")):
        with pytest.raises(InputError, match=match):
            _core.topp_ra_canonical(*args)


def _canonical(robot: snakehead.SnakeRobot, points: timing.GridPoints, limits: timing.RetimingLimits
               ) -> topp_ra.Canonical:
    F, g = timing.stability_rows(robot, points.support, gridpoints.stability_limits(limits), timing.SOLVE_ZMP_EXTRA_M)
    return topp_ra.canonical(gridpoints.path_limits(limits), points.dq, points.ddq, points.tau_a, points.tau_b,
                           points.tau_hold, np.einsum("nkj,nj->nk", F, points.w_a),
                           np.einsum("nkj,nj->nk", F, points.w_b), g)


def test_core_reports_infeasible_where_toppra_does(reference: Any) -> None:
    """The default robot lifting its head over its CoM margin: both solvers fail at the same gridpoint."""
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(5)
    found = 0
    for _ in range(30):
        W, limits = random_waypoints(robot, rng), random_limits(robot, rng)
        try:
            _, points = grid_points(robot, W, limits, 0.03)
        except Infeasible:
            continue
        if points.support.static[1:].min() > 0:
            continue  # stable all along: feasible
        ours = gridpoints.solve_grid(robot, points, limits)
        try:
            ref = reference.toppra_solve_grid(robot, points, limits)
        except ZeroDivisionError:
            continue  # see above
        assert ours.sd is None and ref.sd is None
        assert ours.failed_at == ref.failed_at
        found += 1
    assert found >= 2


def test_closed_form_bang_bang_profile_and_duration() -> None:
    """One joint along a straight path, |q'| <= v, |q''| <= a: x(s) = min(2 a s, v^2, 2 a (L - s)), and the motion
    lasts L / v + v / a (the grid has the profile's corners, v^2 / (2 a) = 0.2 from either end, as gridpoints)."""
    L, v, a = 1.2, 0.8, 1.6
    grid = np.linspace(0.0, L, 61)
    ones, zeros = np.ones((len(grid), 1)), np.zeros((len(grid), 1))
    none = np.zeros((len(grid), 0))
    limits = topp_ra.PathLimits(np.array([v]), np.array([a]), np.array([np.inf]), 1e6)
    rows = topp_ra.canonical(limits, ones, zeros, zeros, zeros, zeros, none, none, none)
    assert rows.P.shape == (len(grid), 2)  # the torque rows left out: no limit
    solution = topp_ra.solve(grid, rows)
    assert solution.sd is not None and solution.failed_at == -1
    exact = np.minimum.reduce([2 * a * grid, np.full_like(grid, v * v), 2 * a * (L - grid)])
    assert np.abs(solution.sd ** 2 - exact).max() < 1e-6
    assert np.allclose(solution.K[:, 1], np.minimum(v * v, 2 * a * (L - grid)), atol=1e-9)
    line = timeline.Timeline(1)
    line.add_piece(lambda s, order: np.asarray(s)[:, None] if order == 0 else np.full((len(s), 1), float(order == 1)),
                   grid, solution.sd)
    assert line.end == pytest.approx(L / v + v / a, rel=1e-6)


# ------------------------------------------------------------------------------------------------
# retime on both solvers
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,seed", [("default", 2), ("gen14", 4)])
def test_retime_matches_toppra_retime(name: str, seed: int, reference: Any) -> None:
    robot = _robot(name)
    rng = np.random.default_rng(seed)
    for _ in range(20):  # the first random lift whose start and path stand
        W = random_waypoints(robot, rng)
        try:
            ours = timing.retime(robot, W)
            break
        except Infeasible:
            continue
    else:
        pytest.fail("no stable random lift")
    with reference.toppra_solver():
        ref = timing.retime(robot, W)
    assert ours.duration == pytest.approx(ref.duration, rel=DURATION_TOL)
    assert np.allclose(ours.waypoint_times, ref.waypoint_times, rtol=DURATION_TOL, atol=1e-6)
    assert ours.check is not None and ours.check.within(), ours.check
    assert ours.notes == ref.notes


# ------------------------------------------------------------------------------------------------
# retime's steps
# ------------------------------------------------------------------------------------------------
def test_refined_grid_points_equal_a_fresh_computation() -> None:
    """GridPoints.merged (a refinement computes only its new points) gives what GridPoints.of gives on the union,
    also when the two sets' polygons have different edge counts (padded)."""
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(2)
    W = random_waypoints(robot, rng)
    limits = timing.resolve_limits(robot)
    piece, coarse = grid_points(robot, W, limits, 0.05)
    extra = np.sort(rng.uniform(0, piece.knots[-1], 37))
    added = timing.GridPoints.of(robot, piece.base, piece.f, extra, limits.zmp_margin)
    merged = coarse.merged(added)
    fresh = timing.GridPoints.of(robot, piece.base, piece.f, np.sort(np.r_[coarse.s, extra]), limits.zmp_margin)
    for field in ("s", "q", "dq", "ddq", "tau_a", "tau_b", "tau_hold", "w_a", "w_b"):
        assert np.allclose(getattr(merged, field), getattr(fresh, field), rtol=1e-12, atol=1e-12), field
    for field in ("com", "static", "required"):
        assert np.allclose(getattr(merged.support, field), getattr(fresh.support, field), atol=1e-12), field
    xy = rng.uniform(-0.3, 0.3, (len(merged.s), 2))  # the same polygons, whatever their padding
    assert np.allclose(merged.support.margins(xy), fresh.support.margins(xy), atol=1e-12)
    assert np.array_equal(topp_ra.solve(merged.s, _canonical(robot, merged, limits)).sd,
                          topp_ra.solve(fresh.s, _canonical(robot, fresh, limits)).sd)


def test_refined_grid_rows_equal_rows_computed_on_the_refined_grid() -> None:
    """The solve's rows a refinement carries over (the old points' kept, the new points' computed, padded to one edge
    count and merged) are bit for bit those computed on the merged grid at once; the solve over them the same. Both
    ways round: the kept points' polygons with more edges than the new points', and with fewer."""
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(2)
    limits = timing.resolve_limits(robot)
    piece, coarse = grid_points(robot, random_waypoints(robot, rng), limits, 0.05)

    def points(s: np.ndarray) -> timing.GridPoints:
        return timing.GridPoints.of(robot, piece.base, piece.f, s, limits.zmp_margin)

    mids = 0.5 * (coarse.s[:-1] + coarse.s[1:])
    few = [m for m in mids if points(np.array([m])).support.offset.shape[1] < coarse.support.offset.shape[1]]
    added = points(np.array(few))
    assert added.support.offset.shape[1] < coarse.support.offset.shape[1]  # the padding is exercised
    for kept, new in ((coarse, added), (added, coarse)):
        kept, new = dataclasses.replace(kept, rows={}), dataclasses.replace(new, rows={})
        gridpoints.grid_rows(robot, kept, limits)
        merged = kept.merged(new)
        carried = gridpoints.grid_rows(robot, merged, limits)
        fresh = gridpoints.grid_rows(robot, dataclasses.replace(merged, rows={}), limits)
        for name in ("P", "Q", "R", "x_max"):
            np.testing.assert_array_equal(getattr(carried.canonical, name), getattr(fresh.canonical, name), name)
        assert (carried.joint, carried.edges) == (fresh.joint, fresh.edges) == (carried.joint, coarse.support.offset.shape[1])
        np.testing.assert_array_equal(topp_ra.solve(merged.s, _canonical(robot, merged, limits)).sd,
                                      gridpoints.solve_grid(robot, merged, limits).sd)


def test_first_grid_and_checked_waypoints() -> None:
    robot = snakehead.SnakeRobot.default()
    W = np.zeros((3, robot.n_joints))
    W[1, 10], W[2, 10] = 0.1, 0.5
    piece = rest_to_rest.Piece(robot, snakehead.BasePlacement(), timing.resolve_limits(robot), W, 0, 2, "monotone")
    grid = piece.first_grid(0.02)
    assert np.all(np.diff(grid) <= 0.02 + 1e-12) and np.all(np.diff(grid) > 0)
    assert np.isin(piece.knots, grid).all()  # every waypoint a gridpoint
    assert (np.searchsorted(grid, piece.knots[1]) >= timing.MIN_GRID_PER_SEGMENT)  # the short segment still has 8
    assert piece.near(len(grid) - 2, grid) == 1
    with pytest.raises(InputError, match="waypoint 1 has joint"):
        timing.checked_waypoints(robot, np.vstack([W[0], robot.upper + 0.1]))
    with pytest.raises(InputError, match="at least two"):
        timing.checked_waypoints(robot, W[:1])


# ------------------------------------------------------------------------------------------------
# the binding
# ------------------------------------------------------------------------------------------------
def _straight(N: int = 30) -> tuple:
    grid = np.linspace(0.0, 1.0, N + 1)
    A = np.tile([1.0, -1.0], (N, 1))
    return grid, A, np.zeros_like(A), np.ones_like(A), np.tile([-np.inf, np.inf], (N, 1)), np.tile([0.0, 1.0], (N + 1, 1))


def test_bad_input_is_input_error() -> None:
    grid, A, B, C, ub, xb = _straight()
    bad = [((grid[::-1], A, B, C, ub, xb), "grid must be strictly increasing"),
           ((grid, A[:-1], B, C, ub, xb), r"A must have shape \(N, m\) = \(30, 2\)"),
           ((grid, A, B, C, ub, xb[:-1]), r"x_bounds must have shape \(N \+ 1, 2\)"),
           ((grid, A, B, C, ub[:, :1], xb), "u_bounds .* has the wrong shape"),
           ((grid[:, None], A, B, C, ub, xb), "grid must be one-dimensional"),
           ((grid, np.where(A > 0, np.nan, A), B, C, ub, xb), "A must be finite"),
           ((grid, A, B, C, ub, np.full_like(xb, np.nan)), "x_bounds must not be NaN"),
           ((grid[:1], A[:0], B[:0], C[:0], ub[:0], xb[:1]), "grid needs at least two gridpoints, got 1")]
    for args, match in bad:
        with pytest.raises(InputError, match=match):
            _core.topp_ra(*args)
    with pytest.raises(InputError, match="x_start"):
        _core.topp_ra(grid, A, B, C, ub, xb, -1.0, 0.0)
    with pytest.raises(InputError, match="rows .* has the wrong shape"):
        _core.solve_lp2d(1.0, 1.0, np.zeros((3, 2)), np.zeros(2), np.ones(2))


def test_many_threads_same_result() -> None:
    """The solve releases the GIL and keeps no state between calls: threads give the single-threaded result."""
    args = _straight(2000)
    one = _core.topp_ra(*args)
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: _core.topp_ra(*args), range(8)))
    for r in results:
        assert r.status == "feasible"
        assert np.array_equal(r.x, one.x) and np.array_equal(r.K, one.K)


def test_refinement_probing_only_changed_stages_gives_the_same_grid(monkeypatch: pytest.MonkeyPatch) -> None:
    """Piece._refine probes again only the stages whose ends or speeds changed since a round found them within the
    limits: the same grid and profile as probing every stage every round."""
    robot = snakehead.SnakeRobot.default()
    W = random_waypoints(robot, np.random.default_rng(2))
    limits = timing.resolve_limits(robot, acceleration_limit=4.0)
    probed: list[tuple[int, int]] = []  # per round: stages probed, stages
    original = rest_to_rest.stages_over

    def spy(*args: object, only: np.ndarray | None = None) -> np.ndarray:
        assert only is not None
        probed.append((int(only.sum()), len(only)))
        return original(*args, only=only)  # type: ignore[arg-type]

    def every_stage(*args: object, only: np.ndarray | None = None) -> np.ndarray:
        return original(*args)  # type: ignore[arg-type]

    def timed() -> tuple[np.ndarray, np.ndarray]:
        piece = rest_to_rest.Piece(robot, snakehead.BasePlacement(), limits, W, 0, 2, "monotone")
        return piece.time(timing.GRID_STEP, [])

    monkeypatch.setattr(rest_to_rest, "stages_over", spy)
    grid, sd = timed()
    assert len(probed) >= 2, "the path needs no refinement: no test"
    monkeypatch.setattr(rest_to_rest, "stages_over", every_stage)
    grid_all, sd_all = timed()
    assert np.array_equal(grid, grid_all) and np.array_equal(sd, sd_all)
    assert probed[0][0] == probed[0][1]  # the first round probes every stage
    assert all(todo < stages for todo, stages in probed[1:]), probed  # later ones only those that changed
