"""TOPP-RA (Pham and Pham 2018) over the gridpoints of a path: its constraints in the canonical form the C++ core
takes (:class:`Canonical`: rows ``P u + Q x <= R`` and a bound on x, with u = s'' and x = s'^2), their
discretization, and the solve in the core (``snakehead._core.topp_ra``, ``include/snakehead/topp_ra.hpp``), whose
passes and per-stage 2-D LPs are those of the ``toppra`` package's ``seidel`` solver.

The rows are the joints' (:mod:`.joint_constraints`) and the stability rows F (w_a u + w_b x) <= g
(:mod:`.stability_constraint`), computed for every gridpoint at once. The discretization is toppra's
*interpolation* one: stage i keeps the rows of gridpoint i at (u, x) and those of gridpoint i+1 at the state it
reaches there, (u, x + 2 delta_i u), so that a stage's constant path acceleration keeps the limits at both of its
ends.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from .joint_constraints import PathLimits, acceleration_rows, torque_rows, velocity_bound

__all__ = ["PathLimits", "Canonical", "Solution", "canonical", "interpolated", "solve", "solve_stages"]


@dataclass(frozen=True)
class Canonical:
    """The constraints at N+1 gridpoints: rows P u + Q x <= R (N+1, m) and x <= x_max (N+1,)."""

    P: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    x_max: np.ndarray


@dataclass(frozen=True)
class Solution:
    """A solve: sd (N+1,) the path speeds s' at the gridpoints (None when no timing keeps the constraints); K
    (N+1, 2) the controllable sets of x = s'^2 (NaN at ``failed_at`` and before it when the backward pass found
    none); failed_at: the gridpoint where it failed (-1 when feasible)."""

    sd: np.ndarray | None
    K: np.ndarray
    failed_at: int


def canonical(limits: PathLimits, dq: np.ndarray, ddq: np.ndarray, tau_a: np.ndarray, tau_b: np.ndarray,
              tau_hold: np.ndarray, stability_a: np.ndarray, stability_b: np.ndarray, stability_g: np.ndarray
              ) -> Canonical:
    """The canonical rows at N+1 gridpoints from q', q'' (N+1, n); the torque tau_a u + tau_b x + tau_hold
    (N+1, n each); the stability rows stability_a u + stability_b x <= stability_g (N+1, k each). Columns: the
    accelerations', the torques', then the stability rows."""
    acc, tau = acceleration_rows(limits, dq, ddq), torque_rows(limits, tau_a, tau_b, tau_hold)
    P = np.hstack([acc[0], tau[0], stability_a])
    Q = np.hstack([acc[1], tau[1], stability_b])
    R = np.hstack([acc[2], tau[2], stability_g])
    return Canonical(P, Q, R, velocity_bound(limits, dq))


def interpolated(rows: Canonical, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The stage rows A u + B x <= C (N, 2m) of the interpolation discretization: gridpoint i's rows at (u, x) and
    gridpoint i+1's at (u, x + 2 delta_i u)."""
    delta = np.diff(grid)[:, None]
    A = np.hstack([rows.P[:-1], rows.P[1:] + 2.0 * delta * rows.Q[1:]])
    B = np.hstack([rows.Q[:-1], rows.Q[1:]])
    C = np.hstack([rows.R[:-1], rows.R[1:]])
    return A, B, C


def solve(grid: np.ndarray, rows: Canonical) -> Solution:
    """Time-optimal rest-to-rest path speeds over ``grid`` (N+1,) under ``rows`` (TOPP-RA in the core,
    ``_core.topp_ra_canonical``: the stages of :func:`interpolated` made there, stage by stage, with u free and
    x in [0, x_max]; the same result as ``_core.topp_ra`` over :func:`interpolated`'s matrices, to the bit)."""
    result = _core.topp_ra_canonical(grid, rows.P, rows.Q, rows.R, rows.x_max, 0.0, 0.0)
    sd = np.sqrt(result.x) if result.status == "feasible" else None
    return Solution(sd, result.K, int(result.failed_at))


def solve_stages(grid: np.ndarray, rows: Canonical) -> Solution:
    """:func:`solve` over the stage matrices of :func:`interpolated` (``_core.topp_ra``): the reference of
    :func:`solve`."""
    A, B, C = interpolated(rows, grid)
    N = len(grid) - 1
    u_bounds = np.tile([-np.inf, np.inf], (N, 1))
    x_bounds = np.column_stack([np.zeros(N + 1), rows.x_max])
    result = _core.topp_ra(grid, A, B, C, u_bounds, x_bounds, 0.0, 0.0)
    sd = np.sqrt(result.x) if result.status == "feasible" else None
    return Solution(sd, result.K, int(result.failed_at))
