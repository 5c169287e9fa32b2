"""The path q(s) the retiming times: a smooth curve through the waypoints in joint space, s its length (rad) there,
and its derivatives q'(s), q''(s).

"monotone" (:class:`~snakehead.trajectory.interpolation.MonotoneQuintic`) never leaves the range of two neighbouring
waypoints, so never a joint limit; "spline" is a not-a-knot cubic spline, toppra's own, which may overshoot.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.interpolate import CubicSpline

from ..trajectory.interpolation import MonotoneQuintic

__all__ = ["PathFunction", "INTERPOLATIONS", "path_function", "path_derivatives", "path_values"]

#: q(s) and its derivatives: f(s (N,), order 0, 1 or 2) -> (N, n).
PathFunction = Callable[[np.ndarray, int], np.ndarray]

#: The paths :func:`~snakehead.retiming.timing.retime` can join the waypoints with.
INTERPOLATIONS = ("monotone", "spline")


def path_function(s: np.ndarray, waypoints: np.ndarray, interpolation: str) -> PathFunction:
    """q(s) through the waypoints at path positions s (knots): f(s, order) -> (N, n)."""
    if interpolation == "monotone":
        return MonotoneQuintic(s, waypoints)
    spline = CubicSpline(s, waypoints, bc_type="not-a-knot", axis=0)  # as toppra's SplineInterpolator

    def f(x: np.ndarray, order: int = 0) -> np.ndarray:
        return np.asarray(spline(x, order))

    return f


def path_derivatives(f: PathFunction, s: np.ndarray, orders: tuple[int, ...]) -> list[np.ndarray]:
    """The path's derivatives of the given orders at s (N, n each): the monotone path's in one pass."""
    if isinstance(f, MonotoneQuintic):
        return f.derivatives(s, orders)
    return [f(s, nu) for nu in orders]


def path_values(f: PathFunction, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q(s), q'(s), q''(s) (N, n) each."""
    q, dq, ddq = path_derivatives(f, s, (0, 1, 2))
    return q, dq, ddq
