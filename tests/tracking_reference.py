"""The reference for the core's tracking fit (snakehead._core.TrackingFit, include/snakehead/tracking_fit.hpp): the
numpy code of ``trajectory.cartesian.tracking_interpolation``'s fit before the core took it over, unchanged but for the
split of one step's stacked system into :func:`tracking_system` (the setup before the fit and the result after it
are cartesian's own, shared).

``tracking_interpolation_numpy`` has the signature and result of ``cartesian.tracking_interpolation``;
``numpy_tracking()`` swaps it into the planner (``planning.waypoints``) for a block (tests/sim/test_tracking_fit.py,
bench/tracking_fit.py).
"""
from __future__ import annotations

import contextlib
from typing import Iterator

import numpy as np
import numpy.typing as npt

from snakehead.geometry.shapes import pair_distances
from snakehead.model.robot import BasePlacement, SnakeRobot
from snakehead.planning import waypoints
from snakehead.trajectory.cartesian import (
    TRACKING_CLEARANCE,
    TRACKING_CONTINUITY,
    TRACKING_DAMPING,
    TRACKING_GROUND_WEIGHT,
    TRACKING_ITERATIONS,
    TRACKING_SELF_CLEARANCE,
    TRACKING_SELF_STEP,
    TRACKING_STEP_TOLERANCE,
    TrackingInterpolation,
    lifted_self_pairs,
    tracking_interpolation_with,
)


def _self_term(robot: SnakeRobot, qj: np.ndarray, lift: np.ndarray, pairs: np.ndarray, base: BasePlacement,
               F: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The tracking fit's self-clearance rows: residuals (c,) and their Jacobian (c, len(lift)) of the pairs closer
    than TRACKING_SELF_CLEARANCE (exact signed distances of the shapes; forward differences in the lifted joints),
    or None when none is."""
    if pairs.size == 0:
        return None
    geom = robot.geometry
    d = pair_distances(F[None], geom, F[None], geom, pairs, 2 * TRACKING_SELF_CLEARANCE)[0]
    close = d < TRACKING_SELF_CLEARANCE
    if not close.any():
        return None
    near = pairs[close]
    steps = np.tile(qj, (len(lift), 1))
    steps[np.arange(len(lift)), lift] += TRACKING_SELF_STEP
    Fs = robot.frames_many(steps, base)
    ds = pair_distances(Fs, geom, Fs, geom, near)  # (len(lift), c)
    J = ((ds - d[close][None, :]) / TRACKING_SELF_STEP).T
    return TRACKING_GROUND_WEIGHT * (d[close] - TRACKING_SELF_CLEARANCE), TRACKING_GROUND_WEIGHT * J


def tracking_system(robot: SnakeRobot, qj: np.ndarray, current: np.ndarray, target: np.ndarray, lift: np.ndarray,
                    pts_idx: np.ndarray, pairs: np.ndarray, base: BasePlacement) -> tuple[np.ndarray, np.ndarray]:
    """One step's stacked residual (rows,) and Jacobian (rows, len(lift)) at qj towards target (m, 3)."""
    lifted = robot.lifted_links
    F = robot.frames(qj, base)
    r = (F[pts_idx, :3, 3] - target).reshape(-1)
    J = robot.point_jacobians(F, F[pts_idx, :3, 3], pts_idx)[:, :, lift].reshape(-1, len(lift))
    # the ground as a stiff one-sided spring on the lifted links' lowest points: stay TRACKING_CLEARANCE up
    low = robot.lowest_point_per_link(F, lifted)
    below = low[:, 2] < TRACKING_CLEARANCE
    if below.any():
        Jz = robot.point_jacobians(F, low[below], lifted[below])[:, 2, lift]
        r = np.concatenate([r, TRACKING_GROUND_WEIGHT * (low[below, 2] - TRACKING_CLEARANCE)])
        J = np.vstack([J, TRACKING_GROUND_WEIGHT * Jz])
    # and itself: links two or more joints apart stay TRACKING_SELF_CLEARANCE apart
    selfc = _self_term(robot, qj, lift, pairs, base, F)
    if selfc is not None:
        r = np.concatenate([r, selfc[0]])
        J = np.vstack([J, selfc[1]])
    # continuity: every joint's change from the previous sample costs TRACKING_CONTINUITY m per rad, so
    # the fit follows one branch instead of jumping between distant ones
    r = np.concatenate([r, TRACKING_CONTINUITY * (qj[lift] - current)])
    J = np.vstack([J, TRACKING_CONTINUITY * np.eye(len(lift))])
    return r, J


def numpy_fit(robot: SnakeRobot, base: BasePlacement, lift: np.ndarray, pts_idx: np.ndarray, q: np.ndarray,
              P: np.ndarray) -> np.ndarray:
    """The lifted joints of q's interior samples fitted to P by the numpy loop (a ``cartesian.LiftedFit``)."""
    q = q.copy()
    lo, hi = robot.lower[lift], robot.upper[lift]
    pairs = lifted_self_pairs(robot, lift)
    lam2 = TRACKING_DAMPING ** 2
    current = q[0, lift].copy()
    for j in range(1, len(q) - 1):
        qj = q[j].copy()
        qj[lift] = current
        for _ in range(TRACKING_ITERATIONS):
            r, J = tracking_system(robot, qj, current, P[j], lift, pts_idx, pairs, base)
            step = -np.linalg.solve(J.T @ J + lam2 * np.eye(len(lift)), J.T @ r)
            qj[lift] = np.clip(qj[lift] + step, lo, hi)
            if np.abs(step).max() < TRACKING_STEP_TOLERANCE:
                break
        q[j] = qj
        current = qj[lift]
    return q


def tracking_interpolation_numpy(robot: SnakeRobot, q_start: npt.ArrayLike, q_end: npt.ArrayLike, n: int,
                                 base: BasePlacement | None = None) -> TrackingInterpolation:
    """``cartesian.tracking_interpolation`` with the numpy fit (as it was before the core's TrackingFit)."""
    return tracking_interpolation_with(robot, q_start, q_end, n, base, numpy_fit)


@contextlib.contextmanager
def numpy_tracking() -> Iterator[None]:
    """Plans made in this block fit their moves with :func:`tracking_interpolation_numpy`."""
    saved = waypoints.tracking_interpolation
    waypoints.tracking_interpolation = tracking_interpolation_numpy  # type: ignore[assignment]
    try:
        yield
    finally:
        waypoints.tracking_interpolation = saved  # type: ignore[assignment]
