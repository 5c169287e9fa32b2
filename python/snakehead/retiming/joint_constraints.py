"""The joints' limits as TOPP-RA constraints along a path q(s) (Pham and Pham 2018), with u = s'' and x = s'^2: the
accelerations q' u + q'' x and the torques tau_a u + tau_b x + tau_hold as rows ``P u + Q x <= R`` at every
gridpoint at once, the velocities q' s' as a bound on x alone. A joint's rows are left out where its limit is inf.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PathLimits", "acceleration_rows", "torque_rows", "velocity_bound"]

#: Rows P u + Q x <= R at N gridpoints: P, Q, R (N, m) each.
Rows = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class PathLimits:
    """The limits TOPP-RA is given, per joint (n,): velocity (rad/s), acceleration (rad/s^2), torque (N m); inf
    for none. x_cap: the cap on x = s'^2 where the joint velocities leave it unbounded (a path that stands still)."""

    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    x_cap: float


def acceleration_rows(limits: PathLimits, dq: np.ndarray, ddq: np.ndarray) -> Rows:
    """|q' u + q'' x| <= the acceleration limit, from q', q'' (N, n): 2 rows per limited joint (upper, then lower
    bounds)."""
    acc = np.isfinite(limits.acceleration)
    a_lim = limits.acceleration[acc]
    bound = np.broadcast_to(a_lim, (len(dq), len(a_lim)))
    return (np.hstack([dq[:, acc], -dq[:, acc]]), np.hstack([ddq[:, acc], -ddq[:, acc]]), np.hstack([bound, bound]))


def torque_rows(limits: PathLimits, tau_a: np.ndarray, tau_b: np.ndarray, tau_hold: np.ndarray) -> Rows:
    """|tau_a u + tau_b x + tau_hold| <= the torque limit, from the torques' coefficients (N, n each): 2 rows per
    limited joint (upper, then lower bounds)."""
    tau = np.isfinite(limits.torque)
    t_lim, hold = limits.torque[tau], tau_hold[:, tau]
    return (np.hstack([tau_a[:, tau], -tau_a[:, tau]]), np.hstack([tau_b[:, tau], -tau_b[:, tau]]),
            np.hstack([t_lim - hold, t_lim + hold]))


def velocity_bound(limits: PathLimits, dq: np.ndarray) -> np.ndarray:
    """x_max (N,): |q' s'| <= the velocity limit as x <= (min_j v_j / |q'_j|)^2, at most ``limits.x_cap``."""
    with np.errstate(divide="ignore"):
        sd_max = (limits.velocity / np.abs(dq)).min(axis=1)  # inf where no joint moves
    return np.minimum(sd_max ** 2, limits.x_cap)
