"""Multi-segment joint-space interpolation sampled at the 2 ms control period (paper Section 3.2, Section 4).

* :func:`joint_trajectory` / :func:`joint_interpolation` -- through waypoints: the C4 quintic spline, or the
  piecewise quintic that never overshoots (:class:`MonotoneQuintic`).
* :func:`sample_times`, :func:`minimum_jerk` -- the sample grid and the rest-to-rest time scaling.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.interpolate import BSpline, PPoly, make_interp_spline

from .. import _core
from .._errors import Infeasible, InputError
from .._validate import finite_array, finite_float, joint_vector, positive, sample_count

__all__ = ["CONTROL_PERIOD", "JointTrajectory", "joint_spline", "MonotoneQuintic", "sample_times", "joint_trajectory",
           "joint_interpolation", "minimum_jerk"]

#: The joint controller's period (s), Section 4.
CONTROL_PERIOD = 0.002


@dataclass(frozen=True)
class JointTrajectory:
    """A sampled joint trajectory: t (T,) s, q (T, n) rad, qd (T, n) rad/s, qdd (T, n) rad/s^2, and the
    spline it samples (``spline(t, nu)`` evaluates the nu-th derivative anywhere; None for
    :func:`~snakehead.trajectory.cartesian.cartesian_trajectory`)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    spline: BSpline | None


def _check_waypoints(times: npt.ArrayLike, waypoints: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    times = finite_array(times, "times", (None,))
    if times.shape[0] < 2:
        raise InputError(f"times needs at least two waypoints, got {times.shape[0]}")
    if np.any(np.diff(times) <= 0):
        raise InputError("times must increase strictly")
    waypoints = finite_array(waypoints, "waypoints", (times.shape[0], None))
    if waypoints.shape[1] < 1:
        raise InputError("waypoints have no joints")
    return times, waypoints


def joint_spline(times: np.ndarray, waypoints: np.ndarray) -> BSpline:
    """The interpolating spline of :func:`joint_trajectory`: times (K,) s, waypoints (K, n) rad -> BSpline.

    A quintic spline (degree 5, scipy ``make_interp_spline``) through every waypoint with zero velocity and
    zero acceleration at both ends: C4 inside (position, velocity, acceleration, jerk and snap continuous),
    at rest at the ends. With two waypoints it is the minimum-jerk quintic 10 s^3 - 15 s^4 + 6 s^5.
    Like every interpolating spline it may overshoot between waypoints (see ``lower``/``upper`` of
    :func:`joint_trajectory`).
    """
    times, waypoints = _check_waypoints(times, waypoints)
    zero = np.zeros(waypoints.shape[1])
    ends = [(1, zero), (2, zero)]
    return make_interp_spline(times, waypoints, k=5, bc_type=(ends, ends), axis=0)


class MonotoneQuintic:
    """Piecewise quintic Hermite interpolation that does not overshoot: times (K,) s, waypoints (K, n).

    Each segment is the quintic with the waypoints' positions, zero accelerations and velocities chosen like
    PCHIP's (Fritsch-Carlson): zero where the neighbouring slopes differ in sign or at either end, else their
    harmonic mean. Position, velocity and acceleration are continuous (the acceleration is zero at every
    waypoint), and a joint never leaves the range of the two waypoints around it: safe for waypoints that
    sit on a joint limit, where the C4 spline of :func:`joint_spline` can overshoot. Call as ``f(t, nu)``.
    """

    def __init__(self, times: np.ndarray, waypoints: np.ndarray) -> None:
        self.times, self.q = _check_waypoints(times, waypoints)
        h = np.diff(self.times)[:, None]
        d = np.diff(self.q, axis=0) / h  # secant slopes (K-1, n)
        v = np.zeros_like(self.q)
        a, b = d[:-1], d[1:]
        same = a * b > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            hm = np.where(same, 2 * a * b / (a + b), 0.0)
        v[1:-1] = hm
        self.v = v
        # each segment's quintic in its local s = (t - t_k) / h (the Hermite basis above, expanded): q(s) =
        # sum_i c_i s^i; scipy's PPoly holds it in t - t_k (c_i / h^i, highest power first) and its derivatives'
        # coefficients; the core evaluates them (``_core.evaluate_piecewise_polynomial``: PPoly's numbers to the bit)
        dp, hv0, hv1 = np.diff(self.q, axis=0), h * v[:-1], h * v[1:]
        c = np.stack([self.q[:-1], hv0, np.zeros_like(dp), 10 * dp - 6 * hv0 - 4 * hv1, -15 * dp + 8 * hv0 + 7 * hv1,
                      6 * dp - 3 * hv0 - 3 * hv1], axis=1)  # (K-1, 6, n)
        c = c / h[:, :, None] ** np.arange(6.0)[None, :, None]
        position = PPoly(np.ascontiguousarray(c[:, ::-1].transpose(1, 0, 2)), self.times)
        #: q, q' and q'' as scipy PPoly (the coefficients the core evaluates)
        self.pieces = (position, position.derivative(1), position.derivative(2))

    def __call__(self, t: npt.ArrayLike, nu: int = 0) -> np.ndarray:
        if nu not in (0, 1, 2):
            raise InputError("nu must be 0, 1 or 2")
        return self.derivatives(t, (nu,))[0]

    def derivatives(self, t: npt.ArrayLike, orders: tuple[int, ...] = (0, 1, 2)) -> list[np.ndarray]:
        """The derivatives of the given ``orders`` (0, 1 or 2) at times t (N,): a list of (N, n). Outside the
        waypoints' times, the first and last segments' quintics continue."""
        if any(nu not in (0, 1, 2) for nu in orders):
            raise InputError(f"orders must be 0, 1 or 2, got {orders}")
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(t, float)).ravel())
        if not np.isfinite(t).all():
            raise InputError("t must be finite")
        return [_core.evaluate_piecewise_polynomial(self.pieces[nu].c, self.pieces[nu].x, t) for nu in orders]


def sample_times(t0: float, t1: float, dt: float = CONTROL_PERIOD) -> np.ndarray:
    """t0, t0 + dt, ... up to t1, with t1 itself as the last sample: (T,) s."""
    t0, t1 = finite_float(t0, "t0"), finite_float(t1, "t1")
    dt = positive(dt, "dt")
    if t1 < t0:
        raise InputError(f"t1 must be >= t0, got t0 = {t0:g} s and t1 = {t1:g} s")
    steps = sample_count(t1 - t0, dt, "the trajectory (t1 - t0)") - 1  # at most MAX_SAMPLES: checked before allocating
    t = t0 + dt * np.arange(steps + 1)
    # A gap under a microsecond is round-off, not a sample: stretch the last step to t1 instead of adding a
    # sample a hair after it (two samples closer than any controller or file can tell apart).
    if t1 - t[-1] > min(1e-6, 1e-3 * dt):
        t = np.append(t, t1)
    t[-1] = t1
    return t


def joint_trajectory(times: np.ndarray, waypoints: np.ndarray, dt: float = CONTROL_PERIOD, *,
                     lower: np.ndarray | None = None, upper: np.ndarray | None = None, method: str = "spline"
                     ) -> JointTrajectory:
    """Multi-segment joint-space interpolation through waypoints, sampled every ``dt`` s.

    times (K,) strictly increasing (s); waypoints (K, n) joint vectors (rad), the first at rest and the last at
    rest. ``method``: "spline", the C4 quintic spline of :func:`joint_spline`, or "monotone", the piecewise
    quintic of :class:`MonotoneQuintic` that never overshoots the waypoints (use it for dense waypoints or
    waypoints on joint limits). The samples are t0, t0 + dt, ... and the last time;
    the first and last samples equal the first and last waypoints exactly. With ``lower``/``upper`` ((n,), rad)
    a trajectory that overshoots the joint limits raises ValueError.
    """
    dt = positive(dt, "dt")
    times, waypoints = _check_waypoints(times, waypoints)
    if method == "spline":
        spline = joint_spline(times, waypoints)
    elif method == "monotone":
        spline = MonotoneQuintic(times, waypoints)
    else:
        raise InputError(f"method must be 'spline' or 'monotone', got {method!r}")
    t = sample_times(times[0], times[-1], dt)
    q, qd, qdd = spline(t), spline(t, 1), spline(t, 2)
    q[0], q[-1] = waypoints[0], waypoints[-1]
    qd[[0, -1]] = 0.0
    qdd[[0, -1]] = 0.0
    n = waypoints.shape[1]
    for bound, name, bad in ((lower, "lower", lambda a, b: a < b), (upper, "upper", lambda a, b: a > b)):
        if bound is None:
            continue
        b = joint_vector(bound, n, name)
        over = bad(q, b + (1e-9 if name == "upper" else -1e-9))
        if over.any():
            k, j = np.argwhere(over)[0]
            raise Infeasible(f"the interpolation overshoots the {name} limit of joint {j} "
                             f"({q[k, j]:.4f} rad at t = {t[k]:.3f} s; limit {b[j]:.4f} rad)")
    return JointTrajectory(t, q, qd, qdd, spline)


def joint_interpolation(times: np.ndarray, waypoints: np.ndarray, dt: float = CONTROL_PERIOD
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Multi-segment joint-space interpolation (Section 3.2): -> (t (T,) s, q (T, n) rad) at the control period.

    Continuous in velocity and acceleration, at rest at both ends; see :func:`joint_trajectory` for the
    velocities and accelerations.
    """
    traj = joint_trajectory(times, waypoints, dt)
    return traj.t, traj.q


def minimum_jerk(tau: np.ndarray) -> np.ndarray:
    """The rest-to-rest time scaling 10 tau^3 - 15 tau^4 + 6 tau^5 of tau in [0, 1]."""
    tau = np.asarray(tau, float)
    return tau ** 3 * (10.0 - 15.0 * tau + 6.0 * tau ** 2)
