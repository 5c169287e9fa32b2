"""Refining TOPP-RA's grid where a solution breaks a limit between gridpoints (TOPP-RA keeps the limits at the
gridpoints only): each stage is probed inside with its constant path acceleration (:func:`stages_over`), the stages
that break a limit are cut in four and their neighbours in two (:func:`refined_grid`), and the path is solved
again, up to :data:`REFINE_ROUNDS` times (:meth:`~snakehead.retiming.rest_to_rest.Piece.time`). A stage probed
within the limits in one round is not probed again while its ends and speeds stay the same (:func:`stage_keys`).
"""
from __future__ import annotations

import numpy as np

from ..dynamics.inverse_dynamics import newton_euler
from ..model.robot import BasePlacement, SnakeRobot
from .joint_path import PathFunction, path_values
from .limit_check import limit_ratios
from .retiming_limits import RetimingLimits
from .support_polygon import Support

__all__ = ["REFINE_ROUNDS", "REFINE_ZMP_M", "REFINE_GROWTH", "REFINE_EXTRA_POINTS", "PROBES", "stage_keys",
           "refined_grid", "stages_over", "probe_support"]

#: Rounds of grid refinement: stages that break a limit between their gridpoints are cut in four (their neighbours
#: in two) and the path is solved again.
REFINE_ROUNDS = 4
#: m: how far the ZMP may come inside its required margin between gridpoints before the stage is halved (less is
#: round-off of the path's curvature, not worth a finer grid).
REFINE_ZMP_M = 1e-5
#: The refinement stops when the grid would grow beyond this multiple of its first size plus REFINE_EXTRA_POINTS.
REFINE_GROWTH = 3.0
REFINE_EXTRA_POINTS = 1000
#: Points probed inside each stage for the refinement.
PROBES = 5


def stage_keys(s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(N-1,) keys of the stages of gridpoints s with x = s'^2 there (N,): the bytes of (s_i, s_i+1, x_i, x_i+1),
    equal exactly when the four numbers are (s and x are never -0.0 or NaN here), for np.isin."""
    rows = np.ascontiguousarray(np.column_stack([s[:-1], s[1:], x[:-1], x[1:]]), dtype=float)
    return rows.view(np.dtype((np.void, 4 * rows.itemsize))).ravel()


def refined_grid(grid: np.ndarray, split: np.ndarray) -> np.ndarray:
    """The grid with each stage in ``split`` cut in four and its neighbours in two."""
    ds = np.diff(grid)
    near = split.copy()
    near[1:] |= split[:-1]
    near[:-1] |= split[1:]
    new = [grid[:-1][near] + 0.5 * ds[near]]
    new += [grid[:-1][split] + f * ds[split] for f in (0.25, 0.75)]
    return np.unique(np.concatenate([grid] + new))


def stages_over(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, f: PathFunction, grid: np.ndarray,
                sd: np.ndarray, support: Support, only: np.ndarray | None = None) -> np.ndarray:
    """(N-1,) bool: the stages of a solution that break a limit between their gridpoints. Probed at PROBES points
    inside each stage, with its constant path acceleration; the ZMP against the support polygon of the nearer
    gridpoint, or the probe's own where the stage's two gridpoints stand on different polygons
    (:func:`probe_support`). ``only``: (N-1,) bool, the stages to probe (the others are reported within the
    limits)."""
    x = sd ** 2
    ds = np.diff(grid)
    u = (x[1:] - x[:-1]) / (2 * ds)
    frac = (np.arange(PROBES) + 0.5) / PROBES
    probed = np.arange(len(ds)) if only is None else np.flatnonzero(only)
    stage = np.repeat(probed, PROBES)
    fr = np.tile(frac, len(probed))
    s = grid[stage] + fr * ds[stage]
    xs = np.maximum(x[stage] + 2 * u[stage] * (s - grid[stage]), 0.0)
    q, dq, ddq = path_values(f, s)
    qd, qdd = dq * np.sqrt(xs)[:, None], dq * u[stage][:, None] + ddq * xs[:, None]
    nearer = np.where(fr < 0.5, stage, stage + 1)
    dyn = newton_euler(robot, q, qd, qdd, base)  # in the core along q: no frames array, the CoM with it
    assert dyn.com is not None
    sub = probe_support(robot, base, limits, support, q, stage, nearer, dyn.com)
    r = limit_ratios(robot, base, limits, sub, q, qd, qdd, dyn=dyn)
    over = np.zeros(len(s), bool)
    for key in ("velocity", "acceleration", "torque", "friction"):
        over |= r[key] > 1.0
    over |= r["zmp_slack"] < -REFINE_ZMP_M
    bad = np.zeros(len(ds), bool)
    bad[stage[over]] = True
    return bad


def probe_support(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, support: Support, q: np.ndarray,
                  stage: np.ndarray, nearer: np.ndarray, com: np.ndarray) -> Support:
    """The support the probes q (M, n) of stages ``stage`` (M,) are checked against: the nearer gridpoint's
    (``nearer`` (M,)), except in a stage whose two gridpoints stand on different polygons (a link touches down or
    lifts off between them), where each probe's own polygon is computed: the plan's check takes every 2 ms sample's
    own, and a link lifting between gridpoints narrows it there."""
    a, b = stage, stage + 1
    changed = (np.any(support.offset[a] != support.offset[b], axis=1)
               | np.any(support.normal[a] != support.normal[b], axis=(1, 2)))
    if not base.on_flat_ground:  # as Support.of keeps it: moved along gravity to the ground point below
        com = np.column_stack([base.below_along_gravity(com), com[:, 2]])
    near = Support(support.normal[nearer], support.offset[nearer], com, support.static[nearer],
                   support.required[nearer], support.weight[nearer])
    if not changed.any():
        return near
    own = Support.of(robot, q[changed], base, limits.zmp_margin)
    order = np.argsort(np.concatenate([np.flatnonzero(~changed), np.flatnonzero(changed)]), kind="stable")
    return near.take(np.flatnonzero(~changed)).joined(own).take(order)
