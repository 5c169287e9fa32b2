"""Space curves for the backbone: paper Eqs. 3-7 (curvature, torsion, phase and bending integrals) and the
plane cubic Bezier of Section 3.3 (1).

* :class:`SpaceCurve` -- any regular parametric space curve r(t), t in [t0, t1]: curvature and torsion
  by Eq. 7 (from user-supplied derivatives or from finite differences), arc length s(t) and phase
  phi(s) = int tau ds (Eq. 3) by numerical integration (scipy.integrate), the curvature projections
  kappa_y, kappa_p (Eq. 4) and their integrals over arc-length intervals (Eqs. 5, 6).
* :func:`cubic_bezier` -- the cubic Bezier curve of four control points as a :class:`SpaceCurve`.

The phase and the body frame it is measured from are described in :mod:`snakehead.backbone.discretize`.

Limitations. Eqs. 3-4 use the Frenet frame, which is undefined where the curvature vanishes; a curve whose
normal flips where its curvature passes through zero (an inflection) is rejected with a ValueError (split
it into pieces and give each piece its own initial frame). A curve that is straight everywhere is accepted
(all angles zero), and so is one that starts straight (kappa(t0) = 0): its initial phase is read where it
first bends.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt
from scipy import integrate, optimize

from .._errors import InputError
from .._validate import finite_array, finite_float, positive
from ..model.body_frame import AXIS_TOLERANCE_DEG

__all__ = ["DEFAULT_FD_STEP", "DEFAULT_RTOL", "STRAIGHT_CURVATURE_RATIO", "SpaceCurve", "cubic_bezier",
           "planar_bezier_length"]

#: Relative finite-difference step (times t1 - t0) used when no derivatives are supplied.
DEFAULT_FD_STEP = 2e-3

#: Default relative tolerance of the arc-length / phase / bending integration (scipy solve_ivp, DOP853).
DEFAULT_RTOL = 1e-10

#: A curve counts as straight (tau = 0, Frenet frame undefined) where its curvature is below this times its
#: largest curvature (sampled on 257 points of [t0, t1]).
STRAIGHT_CURVATURE_RATIO = 1e-7

# ---------------------------------------------------------------------------------------------------
# general space curves: Eqs. 3-7
# ---------------------------------------------------------------------------------------------------
# central finite-difference stencils on the offsets -3..3 (units of h)
_D1 = np.array([-1.0, 9.0, -45.0, 0.0, 45.0, -9.0, 1.0]) / 60.0  # O(h^6)
_D2 = np.array([2.0, -27.0, 270.0, -490.0, 270.0, -27.0, 2.0]) / 180.0  # O(h^6)
_D3 = np.array([1.0, -8.0, 13.0, 0.0, -13.0, 8.0, -1.0]) / 8.0  # O(h^4)
_OFFSETS = np.arange(-3, 4, dtype=np.float64)


class SpaceCurve:
    """A regular parametric space curve r(t), t in [t0, t1], for the discretisation of Eqs. 3-7.

    Parameters
    ----------
    r : callable
        ``r(t) -> (3,)`` position (m) at the scalar parameter t.
    t0, t1 : float
        Parameter interval, t0 < t1.
    derivatives : sequence of three callables, optional
        ``(dr, d2r, d3r)``, each ``t -> (3,)``: r', r'', r''' with respect to t. Without them the
        derivatives come from central finite differences of ``r`` (7 points, O(h^6) for r', r'' and
        O(h^4) for r'''); then ``r`` must also be defined on [t0 - 3h, t1 + 3h].
    fd_step : float, optional
        The finite-difference step h in units of t; default ``DEFAULT_FD_STEP * (t1 - t0)``.
    rtol : float
        Relative tolerance of the integration of s, phi and the bending integrals (default 1e-10).

    Raises ValueError when a callable returns something other than a finite (3,) array, when the
    interval is empty, the curve is not regular (r' = 0 somewhere) or its curvature passes through zero
    (the Frenet frame of Eqs. 3-4 is undefined there; see the module notes).
    """

    def __init__(self, r: Callable[[float], np.ndarray], t0: float, t1: float, *,
                 derivatives: Sequence[Callable[[float], np.ndarray]] | None = None,
                 fd_step: float | None = None, rtol: float = DEFAULT_RTOL) -> None:
        if not callable(r):
            raise InputError(f"r must be a callable t -> (3,) array, got {type(r).__name__}")
        self.t0 = finite_float(t0, "t0")
        self.t1 = finite_float(t1, "t1")
        if not self.t1 > self.t0:
            raise InputError(f"the parameter interval must have t1 > t0, got [{self.t0}, {self.t1}]")
        self._r = r
        if derivatives is not None:
            if len(derivatives) != 3 or not all(callable(d) for d in derivatives):
                raise InputError("derivatives must be three callables (dr, d2r, d3r), each t -> (3,) array")
            self._d: tuple[Callable[[float], np.ndarray], ...] | None = tuple(derivatives)
        else:
            self._d = None
        span = self.t1 - self.t0
        self.fd_step = positive(fd_step, "fd_step") if fd_step is not None else DEFAULT_FD_STEP * span
        self.rtol = positive(rtol, "rtol")
        self._sol = None
        self._check_shape()

    # -- evaluation --------------------------------------------------------------------------------
    @staticmethod
    def _call(f: Any, t: float, name: str) -> np.ndarray:
        try:
            v = f(t)
        except Exception as exc:  # a user's callable failing is an input error
            raise InputError(f"{name}({t!r}) failed: {type(exc).__name__}: {exc}") from exc
        return finite_array(v, f"{name}({t:.6g})", (3,))

    def point(self, t: float) -> np.ndarray:
        """r(t), (3,) m."""
        return self._call(self._r, float(t), "r")

    def derivs(self, t: float) -> tuple[np.ndarray, ...]:
        """(r'(t), r''(t), r'''(t)), each (3,): supplied, or central finite differences."""
        t = float(t)
        if self._d is not None:
            return tuple(self._call(f, t, n) for f, n in zip(self._d, ("dr", "d2r", "d3r")))
        h = self.fd_step
        P = np.array([self._call(self._r, t + k * h, "r") for k in _OFFSETS])  # (7, 3)
        return _D1 @ P / h, _D2 @ P / h ** 2, _D3 @ P / h ** 3

    def curvature_torsion(self, t: npt.ArrayLike) -> tuple[Any, Any]:
        """Curvature kappa (1/m) and torsion tau (1/m) at t (scalar or (m,)), Eq. 7:

        kappa = |r' x r''| / |r'|^3,   tau = (r' x r'') . r''' / |r' x r''|^2.

        Where the curve is straight (kappa below ``STRAIGHT_CURVATURE_RATIO`` times its largest) tau is 0.
        """
        ts = np.atleast_1d(np.asarray(t, dtype=np.float64))
        k = np.empty(ts.shape)
        tau = np.empty(ts.shape)
        for i, ti in enumerate(ts):
            k[i], tau[i] = self._kappa_tau(ti)[:2]
        if np.ndim(t) == 0:
            return float(k[0]), float(tau[0])
        return k, tau

    def _kappa_tau(self, t: float) -> tuple[float, float, float]:
        d1, d2, d3 = self.derivs(t)
        c = np.cross(d1, d2)
        c2 = float(c @ c)
        speed = float(np.linalg.norm(d1))
        kappa = math.sqrt(c2) / speed ** 3  # Eq. 7
        # straight here: the Frenet frame (and tau) is undefined; finite-difference noise must not twist phi
        straight = c2 == 0.0 or kappa <= STRAIGHT_CURVATURE_RATIO * self._kappa_max
        tau = 0.0 if straight else float(c @ d3) / c2  # Eq. 7
        return kappa, tau, speed

    def frenet(self, t: float) -> np.ndarray:
        """Frenet frame at t as a (3, 3) matrix with columns (T, N, B); N, B are NaN where straight."""
        d1, d2, _ = self.derivs(t)
        T = d1 / np.linalg.norm(d1)
        c = np.cross(d1, d2)
        nc = np.linalg.norm(c)
        if nc == 0.0:
            return np.column_stack([T, np.full(3, np.nan), np.full(3, np.nan)])
        B = c / nc
        return np.column_stack([T, np.cross(B, T), B])

    def _check_shape(self, n: int = 257) -> None:
        """Regularity and no inflection: sample r' and r' x r'' on an even grid of t."""
        ts = np.linspace(self.t0, self.t1, n)
        self.point(self.t0)  # shape / NaN check of r itself
        speed_list, cross_list = [], []
        for t in ts:
            d1, d2, _ = self.derivs(t)
            speed_list.append(np.linalg.norm(d1))
            cross_list.append(np.cross(d1, d2))
        speeds = np.array(speed_list)
        cs = np.array(cross_list)
        if speeds.min() <= 1e-9 * max(speeds.max(), 1e-300):
            i = int(np.argmin(speeds))
            raise InputError(f"the curve is not regular: r'(t) = 0 near t = {ts[i]:.6g}")
        norms = np.linalg.norm(cs, axis=1) / speeds ** 3  # kappa
        approx_length = float(speeds.mean()) * (self.t1 - self.t0)
        if norms.max() * approx_length < 1e-8:  # bends by less than 1e-8 rad in all: a straight line
            self._straight = True
            self._kappa_max = math.inf  # every point counts as straight: tau = 0
            return
        self._straight = False
        self._kappa_max = float(norms.max())
        # an inflection flips the binormal B = r' x r'' / |r' x r''| (and the normal) across a zero of kappa
        ok = norms > STRAIGHT_CURVATURE_RATIO * norms.max()
        B = cs[ok] / np.linalg.norm(cs[ok], axis=1)[:, None]
        flips = np.flatnonzero(np.einsum("ij,ij->i", B[1:], B[:-1]) < 0.0)
        if len(flips):
            i = np.flatnonzero(ok)[flips[0]]
            raise InputError(
                f"the curvature of the curve vanishes between t = {ts[i]:.6g} and the next sample and its normal "
                "flips there (an inflection): the Frenet frame of Eqs. 3-4 is undefined; split the curve at that point")
        self._first_curved_t = float(ts[np.flatnonzero(ok)[0]])

    # -- integration of s, phi and the bending integrals -----------------------------------------
    def _rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        kappa, tau, speed = self._kappa_tau(t)
        phi = y[1]
        # ds/dt = |r'|; dphi/dt = tau ds/dt (Eq. 3); d/dt int kappa cos(phi) ds, int kappa sin(phi) ds (Eq. 4)
        return np.array([speed, tau * speed, kappa * math.cos(phi) * speed, kappa * math.sin(phi) * speed])

    def _solution(self) -> Any:
        if self._sol is None:
            sol = integrate.solve_ivp(self._rhs, (self.t0, self.t1), np.zeros(4), method="DOP853",
                                      rtol=self.rtol, atol=self.rtol * 1e-3, dense_output=True)
            if not sol.success:
                raise InputError(f"integrating the curve failed: {sol.message}")
            self._sol = sol
        return self._sol

    @property
    def length(self) -> float:
        """Total arc length L = int_t0^t1 |r'(t)| dt (m)."""
        return float(self._solution().y[0, -1])

    def arc_length(self, t: npt.ArrayLike) -> np.ndarray | float:
        """s(t) = int_t0^t |r'| dt (m) at t (scalar or array within [t0, t1])."""
        ta = np.asarray(t, dtype=np.float64)
        if np.any(ta < self.t0 - 1e-12) or np.any(ta > self.t1 + 1e-12):
            raise InputError(f"t must lie in [{self.t0}, {self.t1}]")
        s = self._solution().sol(np.clip(ta, self.t0, self.t1))[0]
        return float(s) if ta.ndim == 0 else s

    def t_at(self, s: npt.ArrayLike) -> np.ndarray | float:
        """Inverse of :meth:`arc_length`: the parameter t at arc length s (scalar or array in [0, L])."""
        sa = np.atleast_1d(np.asarray(s, dtype=np.float64))
        L = self.length
        if np.any(~np.isfinite(sa)) or np.any(sa < -1e-12) or np.any(sa > L + 1e-9 * max(L, 1.0)):
            raise InputError(f"arc length must lie in [0, {L:.6g}] m")
        sol = self._solution().sol
        out = np.empty(sa.shape)
        for i, si in enumerate(np.clip(sa, 0.0, L)):
            if si <= 0.0:
                out[i] = self.t0
            elif si >= L:
                out[i] = self.t1
            else:
                out[i] = optimize.brentq(lambda t: sol(t)[0] - si, self.t0, self.t1, xtol=1e-15, rtol=1e-15)
        return float(out[0]) if np.ndim(s) == 0 else out

    def _state_at_s(self, s: npt.ArrayLike) -> np.ndarray:
        t = np.atleast_1d(self.t_at(s))
        return self._solution().sol(t)  # (4, m)

    def phase(self, s: npt.ArrayLike, phi0: float = 0.0) -> Any:
        """phi(s) = phi0 + int_0^s tau ds (rad), Eq. 3; scalar or array."""
        phi = self._state_at_s(s)[1] + finite_float(phi0, "phi0")
        return float(phi[0]) if np.ndim(s) == 0 else phi

    def curvature_projections(self, s: npt.ArrayLike, phi0: float = 0.0) -> tuple[Any, Any]:
        """(kappa_y, kappa_p) = kappa (cos phi, sin phi) at arc lengths s (1/m), Eq. 4."""
        sa = np.atleast_1d(np.asarray(s, dtype=np.float64))
        t = np.atleast_1d(self.t_at(sa))
        phi = self._solution().sol(t)[1] + finite_float(phi0, "phi0")
        kappa = np.array([self._kappa_tau(ti)[0] for ti in t])
        ky, kp = kappa * np.cos(phi), kappa * np.sin(phi)
        if np.ndim(s) == 0:
            return float(ky[0]), float(kp[0])
        return ky, kp

    def bending(self, s1: Any, s2: Any, phi0: float = 0.0) -> tuple[Any, Any]:
        """(theta_y, theta_p) = (int_s1^s2 kappa_y ds, int_s1^s2 kappa_p ds) in rad, Eqs. 5-6.

        s1, s2 scalars or equal-shape arrays (m) within [0, L]. phi0 is the phase at s = 0 (Eq. 3's
        constant: the angle of the Frenet normal N(0) from the body's y-axis towards its z-axis).
        """
        s1a = np.atleast_1d(np.asarray(s1, dtype=np.float64))
        s2a = np.atleast_1d(np.asarray(s2, dtype=np.float64))
        if s1a.shape != s2a.shape:
            raise InputError(f"s1 and s2 must have the same shape, got {s1a.shape} and {s2a.shape}")
        phi0 = finite_float(phi0, "phi0")
        y1, y2 = self._state_at_s(s1a), self._state_at_s(s2a)
        dc, ds_ = y2[2] - y1[2], y2[3] - y1[3]  # int kappa cos(phi - phi0), int kappa sin(phi - phi0)
        c, s = math.cos(phi0), math.sin(phi0)
        ty = c * dc - s * ds_  # int kappa cos(phi0 + .) ds
        tp = s * dc + c * ds_  # int kappa sin(phi0 + .) ds
        if np.ndim(s1) == 0 and np.ndim(s2) == 0:
            return float(ty[0]), float(tp[0])
        return ty, tp

    def initial_phase(self, frame0: npt.ArrayLike) -> float:
        """phi0 for a body whose frame at the curve's start has rotation ``frame0`` (3, 3) (columns x, y, z).

        Its x-axis must be the curve's start tangent, within :data:`~snakehead.model.body_frame.AXIS_TOLERANCE_DEG`
        (a description's joint axes may be that far off its body's y or z, which tilts a bent base's end by as
        much); phi0 = atan2(N.z, N.y) with N the Frenet normal at t0 (0 for a straight curve).
        """
        R = finite_array(frame0, "frame0", (3, 3))
        F = self.frenet(self.t0)
        if float(R[:, 0] @ F[:, 0]) < math.cos(math.radians(AXIS_TOLERANCE_DEG)):
            raise InputError("the body frame's x-axis is not the curve's start tangent: "
                             f"x = {R[:, 0].round(6).tolist()}, T(t0) = {F[:, 0].round(6).tolist()}")
        if self._straight:
            return 0.0
        k0 = self._kappa_tau(self.t0)[0]
        if np.all(np.isfinite(F[:, 1])) and k0 > STRAIGHT_CURVATURE_RATIO * 1e3 * self._kappa_max:
            N = F[:, 1]
            return math.atan2(float(N @ R[:, 2]), float(N @ R[:, 1]))
        # the curve starts straight (kappa(t0) = 0): take the normal where it first bends and undo the
        # torsion accumulated up to there (Eq. 3), with the body frame carried along (without twist) as
        # the start is straight
        t1 = self._first_curved_t
        N = self.frenet(t1)[:, 1]
        s1 = self.arc_length(t1)
        return math.atan2(float(N @ R[:, 2]), float(N @ R[:, 1])) - self.phase(s1)


def cubic_bezier(control_points: npt.ArrayLike) -> SpaceCurve:
    """The cubic Bezier curve B(t) = sum_k C(3,k) (1-t)^(3-k) t^k P_k, t in [0, 1], of four (3,) control
    points (m), as a :class:`SpaceCurve` with its exact derivatives."""
    P = finite_array(control_points, "control_points", (4, 3))

    def r(t: float) -> np.ndarray:
        u = 1.0 - t
        return u ** 3 * P[0] + 3 * u * u * t * P[1] + 3 * u * t * t * P[2] + t ** 3 * P[3]

    def d1(t: float) -> np.ndarray:
        u = 1.0 - t
        return 3.0 * (u * u * (P[1] - P[0]) + 2 * u * t * (P[2] - P[1]) + t * t * (P[3] - P[2]))

    def d2(t: float) -> np.ndarray:
        return 6.0 * ((1.0 - t) * (P[2] - 2 * P[1] + P[0]) + t * (P[3] - 2 * P[2] + P[1]))

    def d3(t: float) -> np.ndarray:
        return 6.0 * (P[3] - 3 * P[2] + 3 * P[1] - P[0])

    return SpaceCurve(r, 0.0, 1.0, derivatives=(d1, d2, d3))


_GL_X, _GL_W = np.polynomial.legendre.leggauss(64)


def planar_bezier_length(B: np.ndarray) -> float:
    """Length of the planar cubic Bezier with (4, 2) control points (64-point Gauss-Legendre)."""
    t = 0.5 * (_GL_X + 1.0)
    u = 1.0 - t
    d = 3.0 * (np.outer(u * u, B[1] - B[0]) + np.outer(2 * u * t, B[2] - B[1]) + np.outer(t * t, B[3] - B[2]))
    return float(0.5 * np.dot(_GL_W, np.linalg.norm(d, axis=1)))
