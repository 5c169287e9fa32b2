"""Backbone curves and their discretisation into joint angles: paper Section 2.1 (Eqs. 1-9) and the
initial configuration of Section 3.3 step (1) (Fig. 14).

Contents
--------
* :class:`SpaceCurve` -- any regular parametric space curve r(t), t in [t0, t1]: curvature and torsion
  by Eq. 7 (from user-supplied derivatives or from finite differences), arc length s(t) and phase
  phi(s) = int tau ds (Eq. 3) by numerical integration (scipy.integrate), the curvature projections
  kappa_y, kappa_p (Eq. 4) and their integrals over arc-length intervals (Eqs. 5, 6).
* :func:`joint_layout`, :func:`curve_joint_angles` -- how a curve becomes the joint angles of a snake with
  alternating yaw / pitch axes (the mapping is documented below, "Joint intervals").
* :class:`PlaneArc`, :func:`arc_joint_angles`, :func:`arc_segment_area`, :func:`arc_area_maximum` --
  the plane arc of the base (Eqs. 1, 2, 8, 9).
* :func:`optimize_base_arc` -- the base arc's central angle that maximises the area of the discretised
  support polygon with the whole body's centre of mass inside it.
* :func:`cubic_bezier`, :class:`UpCurveShape`, :func:`initial_backbone`, :func:`initial_configuration`
  -- the plane arc of the base joined tangent-continuously (G1) at P0 to a plane cubic Bezier curve in a
  vertical plane for the neck and head (Section 3.3 (1)).

Conventions
-----------
SI units (m, rad). Arc length ``s`` of a curve is measured from the curve's start. A joint's *body arc
length* is its distance from the tail end along the straight body (q = 0). The discretisation's body frame
at arc length s is (x, y, z) = (T, M1, M2): T the unit tangent, and (M1, M2) the normal plane's axes that
the phase of Eq. 3 is measured from, so that the Frenet normal is N = cos(phi) M1 + sin(phi) M2.
Then kappa_y = kappa cos(phi) is the bending about the body's z-axis (towards +y) and kappa_p =
kappa sin(phi) the bending about its y-axis (towards +z). (M1, M2) is the rotation-minimising (Bishop)
frame: d phi / ds = tau is exactly Eq. 3.

Joint signs. The URDF's yaw joints turn about the local +z axis, so a yaw joint's angle is +theta_y
(Eq. 5; positive turns the body left, towards +y). The pitch joints turn about the local +y axis, and a
positive rotation about +y turns the body's x-axis towards -z (down); bending towards +z (kappa_p > 0,
Eq. 6) is therefore the joint angle -theta_p. Joints whose axis is -z or -y flip sign accordingly.

Joint intervals (the mapping of Eqs. 5-6 onto an alternating yaw/pitch snake)
-----------------------------------------------------------------------------
A yaw joint can only make yaw bending and a pitch joint only pitch bending, so each kind of joint must
carry *all* the bending of its kind: the yaw joints' intervals tile the curve, and so do the pitch joints'.
Joint i (at arc length s_i on the curve) takes the interval [s1, s2] of Eqs. 5-6 bounded by the midpoints
between it and the previous / next joint *of the same kind*; the first joint of a kind starts its
interval at the curve's start and the last one ends it at the curve's end. For an alternating snake with
equal modules the midpoint between two yaw joints is the pitch joint between them, so a yaw joint takes
the yaw bending from the pitch joint before it to the pitch joint after it (2 module lengths, centred on
the joint) and a pitch joint the pitch bending between its two yaw neighbours. On the default robot the
base's yaw joints 1, 3, 5, 7 take [0, s_2], [s_2, s_4], [s_4, s_6], [s_6, P0]; the neck's pitch joint 8
sits exactly at P0 and starts the up curve's pitch intervals. The sum of the yaw angles is therefore the
total yaw bending of the curve (for the plane arc: its central angle), so the last link leaves along the
curve's end tangent when the first lies along its start tangent.

Limitations. Eqs. 3-4 use the Frenet frame, which is undefined where the curvature vanishes; a curve whose
normal flips where its curvature passes through zero (an inflection) is rejected with a ValueError (split
it into pieces and give each piece its own initial frame). A curve that is straight everywhere is accepted
(all angles zero), and so is one that starts straight (kappa(t0) = 0): its initial phase is read where it
first bends.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from scipy import integrate, optimize

from ._validate import finite_array, positive
from .robot import BODY_AXIS_HEIGHT, BasePlacement, SnakeRobot, as_robot

YAW = "yaw"
PITCH = "pitch"

#: Relative finite-difference step (times t1 - t0) used when no derivatives are supplied.
DEFAULT_FD_STEP = 2e-3

#: Default relative tolerance of the arc-length / phase / bending integration (scipy solve_ivp, DOP853).
DEFAULT_RTOL = 1e-10

#: A curve counts as straight (tau = 0, Frenet frame undefined) where its curvature is below this times its
#: largest curvature (sampled on 257 points of [t0, t1]).
STRAIGHT_TOLERANCE = 1e-7

# ---------------------------------------------------------------------------------------------------
# validation helpers
# ---------------------------------------------------------------------------------------------------


def _finite_float(x, name: str) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {x!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {x!r}")
    return v



def _check_central_angle(theta) -> float:
    th = _finite_float(theta, "central_angle")
    if not 0.0 < th <= 2.0 * math.pi:
        raise ValueError(f"central_angle must be in (0, 2*pi] rad, got {th!r}")
    return th


def _check_turn(turn) -> int:
    if turn not in (1, -1):
        raise ValueError(f"turn must be +1 (left, counter-clockwise from above) or -1 (right), got {turn!r}")
    return int(turn)


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
                 fd_step: float | None = None, rtol: float = DEFAULT_RTOL):
        if not callable(r):
            raise ValueError(f"r must be a callable t -> (3,) array, got {type(r).__name__}")
        self.t0 = _finite_float(t0, "t0")
        self.t1 = _finite_float(t1, "t1")
        if not self.t1 > self.t0:
            raise ValueError(f"the parameter interval must have t1 > t0, got [{self.t0}, {self.t1}]")
        self._r = r
        if derivatives is not None:
            if len(derivatives) != 3 or not all(callable(d) for d in derivatives):
                raise ValueError("derivatives must be three callables (dr, d2r, d3r), each t -> (3,) array")
            self._d = tuple(derivatives)
        else:
            self._d = None
        span = self.t1 - self.t0
        self.fd_step = positive(fd_step, "fd_step") if fd_step is not None else DEFAULT_FD_STEP * span
        self.rtol = positive(rtol, "rtol")
        self._sol = None
        self._check_shape()

    # -- evaluation --------------------------------------------------------------------------------
    @staticmethod
    def _call(f, t: float, name: str) -> np.ndarray:
        try:
            v = f(t)
        except Exception as exc:  # a user's callable failing is an input error
            raise ValueError(f"{name}({t!r}) failed: {type(exc).__name__}: {exc}") from exc
        return finite_array(v, f"{name}({t:.6g})", (3,))

    def point(self, t: float) -> np.ndarray:
        """r(t), (3,) m."""
        return self._call(self._r, float(t), "r")

    def derivs(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r'(t), r''(t), r'''(t)), each (3,): supplied, or central finite differences."""
        t = float(t)
        if self._d is not None:
            return tuple(self._call(f, t, n) for f, n in zip(self._d, ("dr", "d2r", "d3r")))
        h = self.fd_step
        P = np.array([self._call(self._r, t + k * h, "r") for k in _OFFSETS])  # (7, 3)
        return _D1 @ P / h, _D2 @ P / h ** 2, _D3 @ P / h ** 3

    def curvature_torsion(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Curvature kappa (1/m) and torsion tau (1/m) at t (scalar or (m,)), Eq. 7:

        kappa = |r' x r''| / |r'|^3,   tau = (r' x r'') . r''' / |r' x r''|^2.

        Where the curve is straight (kappa below ``STRAIGHT_TOLERANCE`` times its largest) tau is 0.
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
        straight = c2 == 0.0 or kappa <= STRAIGHT_TOLERANCE * self._kappa_max
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
        speeds, cs = [], []
        for t in ts:
            d1, d2, _ = self.derivs(t)
            speeds.append(np.linalg.norm(d1))
            cs.append(np.cross(d1, d2))
        speeds = np.array(speeds)
        cs = np.array(cs)
        if speeds.min() <= 1e-9 * max(speeds.max(), 1e-300):
            i = int(np.argmin(speeds))
            raise ValueError(f"the curve is not regular: r'(t) = 0 near t = {ts[i]:.6g}")
        norms = np.linalg.norm(cs, axis=1) / speeds ** 3  # kappa
        approx_length = float(speeds.mean()) * (self.t1 - self.t0)
        if norms.max() * approx_length < 1e-8:  # bends by less than 1e-8 rad in all: a straight line
            self._straight = True
            self._kappa_max = math.inf  # every point counts as straight: tau = 0
            return
        self._straight = False
        self._kappa_max = float(norms.max())
        # an inflection flips the binormal B = r' x r'' / |r' x r''| (and the normal) across a zero of kappa
        ok = norms > STRAIGHT_TOLERANCE * norms.max()
        B = cs[ok] / np.linalg.norm(cs[ok], axis=1)[:, None]
        flips = np.flatnonzero(np.einsum("ij,ij->i", B[1:], B[:-1]) < 0.0)
        if len(flips):
            i = np.flatnonzero(ok)[flips[0]]
            raise ValueError(
                f"the curvature of the curve vanishes between t = {ts[i]:.6g} and the next sample and its normal "
                "flips there (an inflection): the Frenet frame of Eqs. 3-4 is undefined; split the curve at that point")
        self._first_curved_t = float(ts[np.flatnonzero(ok)[0]])

    # -- integration of s, phi and the bending integrals -----------------------------------------
    def _rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        kappa, tau, speed = self._kappa_tau(t)
        phi = y[1]
        # ds/dt = |r'|; dphi/dt = tau ds/dt (Eq. 3); d/dt int kappa cos(phi) ds, int kappa sin(phi) ds (Eq. 4)
        return np.array([speed, tau * speed, kappa * math.cos(phi) * speed, kappa * math.sin(phi) * speed])

    def _solution(self):
        if self._sol is None:
            sol = integrate.solve_ivp(self._rhs, (self.t0, self.t1), np.zeros(4), method="DOP853",
                                      rtol=self.rtol, atol=self.rtol * 1e-3, dense_output=True)
            if not sol.success:
                raise ValueError(f"integrating the curve failed: {sol.message}")
            self._sol = sol
        return self._sol

    @property
    def length(self) -> float:
        """Total arc length L = int_t0^t1 |r'(t)| dt (m)."""
        return float(self._solution().y[0, -1])

    def arc_length(self, t) -> np.ndarray | float:
        """s(t) = int_t0^t |r'| dt (m) at t (scalar or array within [t0, t1])."""
        ta = np.asarray(t, dtype=np.float64)
        if np.any(ta < self.t0 - 1e-12) or np.any(ta > self.t1 + 1e-12):
            raise ValueError(f"t must lie in [{self.t0}, {self.t1}]")
        s = self._solution().sol(np.clip(ta, self.t0, self.t1))[0]
        return float(s) if ta.ndim == 0 else s

    def t_at(self, s) -> np.ndarray | float:
        """Inverse of :meth:`arc_length`: the parameter t at arc length s (scalar or array in [0, L])."""
        sa = np.atleast_1d(np.asarray(s, dtype=np.float64))
        L = self.length
        if np.any(~np.isfinite(sa)) or np.any(sa < -1e-12) or np.any(sa > L + 1e-9 * max(L, 1.0)):
            raise ValueError(f"arc length must lie in [0, {L:.6g}] m")
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

    def _state_at_s(self, s) -> np.ndarray:
        t = np.atleast_1d(self.t_at(s))
        return self._solution().sol(t)  # (4, m)

    def phase(self, s, phi0: float = 0.0) -> np.ndarray | float:
        """phi(s) = phi0 + int_0^s tau ds (rad), Eq. 3; scalar or array."""
        phi = self._state_at_s(s)[1] + _finite_float(phi0, "phi0")
        return float(phi[0]) if np.ndim(s) == 0 else phi

    def curvature_projections(self, s, phi0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(kappa_y, kappa_p) = kappa (cos phi, sin phi) at arc lengths s (1/m), Eq. 4."""
        sa = np.atleast_1d(np.asarray(s, dtype=np.float64))
        t = np.atleast_1d(self.t_at(sa))
        phi = self._solution().sol(t)[1] + _finite_float(phi0, "phi0")
        kappa = np.array([self._kappa_tau(ti)[0] for ti in t])
        ky, kp = kappa * np.cos(phi), kappa * np.sin(phi)
        if np.ndim(s) == 0:
            return float(ky[0]), float(kp[0])
        return ky, kp

    def bending(self, s1, s2, phi0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(theta_y, theta_p) = (int_s1^s2 kappa_y ds, int_s1^s2 kappa_p ds) in rad, Eqs. 5-6.

        s1, s2 scalars or equal-shape arrays (m) within [0, L]. phi0 is the phase at s = 0 (Eq. 3's
        constant: the angle of the Frenet normal N(0) from the body's y-axis towards its z-axis).
        """
        s1a = np.atleast_1d(np.asarray(s1, dtype=np.float64))
        s2a = np.atleast_1d(np.asarray(s2, dtype=np.float64))
        if s1a.shape != s2a.shape:
            raise ValueError(f"s1 and s2 must have the same shape, got {s1a.shape} and {s2a.shape}")
        phi0 = _finite_float(phi0, "phi0")
        y1, y2 = self._state_at_s(s1a), self._state_at_s(s2a)
        dc, ds_ = y2[2] - y1[2], y2[3] - y1[3]  # int kappa cos(phi - phi0), int kappa sin(phi - phi0)
        c, s = math.cos(phi0), math.sin(phi0)
        ty = c * dc - s * ds_  # int kappa cos(phi0 + .) ds
        tp = s * dc + c * ds_  # int kappa sin(phi0 + .) ds
        if np.ndim(s1) == 0 and np.ndim(s2) == 0:
            return float(ty[0]), float(tp[0])
        return ty, tp

    def initial_phase(self, frame0) -> float:
        """phi0 for a body whose frame at the curve's start has rotation ``frame0`` (3, 3) (columns x, y, z).

        Its x-axis must be the curve's start tangent (to 1e-6); phi0 = atan2(N.z, N.y) with N the Frenet
        normal at t0 (0 for a straight curve).
        """
        R = finite_array(frame0, "frame0", (3, 3))
        F = self.frenet(self.t0)
        if abs(float(R[:, 0] @ F[:, 0]) - 1.0) > 1e-6:
            raise ValueError("the body frame's x-axis is not the curve's start tangent: "
                             f"x = {R[:, 0].round(6).tolist()}, T(t0) = {F[:, 0].round(6).tolist()}")
        if self._straight:
            return 0.0
        k0 = self._kappa_tau(self.t0)[0]
        if np.all(np.isfinite(F[:, 1])) and k0 > STRAIGHT_TOLERANCE * 1e3 * self._kappa_max:
            N = F[:, 1]
            return math.atan2(float(N @ R[:, 2]), float(N @ R[:, 1]))
        # the curve starts straight (kappa(t0) = 0): take the normal where it first bends and undo the
        # torsion accumulated up to there (Eq. 3), with the body frame carried along (without twist) as
        # the start is straight
        t1 = self._first_curved_t
        N = self.frenet(t1)[:, 1]
        s1 = self.arc_length(t1)
        return math.atan2(float(N @ R[:, 2]), float(N @ R[:, 1])) - self.phase(s1)


# ---------------------------------------------------------------------------------------------------
# joints along the body and the interval mapping
# ---------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class JointLayout:
    """Where the joints sit along the straight body and how they bend.

    s : (n,) body arc length of each joint from the tail end (m), at q = 0.
    kinds : (n,) ``"yaw"`` (axis +-z) or ``"pitch"`` (axis +-y).
    signs : (n,) +1 or -1, the sign of the axis (+z / +y is +1).
    length : body length from the tail end to the last frame (m).
    """

    s: np.ndarray
    kinds: tuple
    signs: np.ndarray
    length: float


def joint_layout(robot: SnakeRobot) -> JointLayout:
    """The :class:`JointLayout` of ``robot`` from its URDF (FK at q = 0 and the joint axes).

    Raises ValueError unless the body is straight along x at q = 0 and every axis is +-y or +-z.
    """
    robot = as_robot(robot)
    F = robot.body.fk_all(np.zeros(robot.n_joints))
    p = F[:, :3, 3]
    if np.abs(p[:, 1:]).max() > 1e-9 or np.any(np.diff(p[:, 0]) < -1e-12):
        raise ValueError("the body is not straight along x at q = 0; the backbone discretisation needs that")
    child = np.asarray(robot.body.model.joint_child_links)
    s = p[child, 0] - p[0, 0]
    axes = np.asarray(robot.body.model.joint_axes, dtype=np.float64)
    kinds, signs = [], []
    for i, a in enumerate(axes):
        if np.allclose(np.abs(a), (0, 0, 1), atol=1e-9):
            kinds.append(YAW)
        elif np.allclose(np.abs(a), (0, 1, 0), atol=1e-9):
            kinds.append(PITCH)
        else:
            raise ValueError(f"joint {i + 1} has axis {a.tolist()}; "
                             "only yaw (+-z) and pitch (+-y) joints bend a backbone")
        signs.append(1.0 if a.sum() > 0 else -1.0)
    return JointLayout(s=s, kinds=tuple(kinds), signs=np.array(signs), length=float(p[-1, 0] - p[0, 0]))


def joint_intervals(s_joints, kinds: Sequence[str], curve_length: float) -> np.ndarray:
    """The [s1, s2] of Eqs. 5-6 for each joint (see the module notes, "Joint intervals"): (m, 2) m.

    s_joints (m,) arc lengths of the joints on the curve (increasing, within [0, curve_length]);
    kinds (m,) ``"yaw"``/``"pitch"``. A joint's interval runs from the midpoint with the previous joint of
    its kind (or the curve's start) to the midpoint with the next one (or the curve's end).
    """
    s = finite_array(s_joints, "s_joints", (None,))
    L = positive(curve_length, "curve_length")
    if len(kinds) != len(s):
        raise ValueError(f"kinds has {len(kinds)} entries for {len(s)} joints")
    if np.any(np.diff(s) <= 0) or s[0] < -1e-12 or s[-1] > L + 1e-12:
        raise ValueError(f"joint arc lengths must increase within [0, {L:.6g}] m, got {s.tolist()}")
    out = np.empty((len(s), 2))
    for kind in set(kinds):
        if kind not in (YAW, PITCH):
            raise ValueError(f"joint kind must be 'yaw' or 'pitch', got {kind!r}")
        idx = [i for i, k in enumerate(kinds) if k == kind]
        sk = s[idx]
        mids = 0.5 * (sk[1:] + sk[:-1])
        out[idx, 0] = np.concatenate([[0.0], mids])
        out[idx, 1] = np.concatenate([mids, [L]])
    return out


def discretize(curve: SpaceCurve, s_joints, kinds: Sequence[str], *, phi0: float = 0.0,
               end: float | None = None) -> np.ndarray:
    """Eqs. 3-6: the bending angle theta (rad) of each joint, theta_y for yaw joints and theta_p for pitch
    joints, integrated over :func:`joint_intervals` of the stretch [0, end] of the curve (default: all of
    it; m). s_joints (m,) arc lengths on the curve (m), kinds (m,) "yaw"/"pitch", phi0 the phase at s = 0.
    Returns (m,) in the curve's sign convention (URDF joint angles: :func:`curve_joint_angles`)."""
    if not isinstance(curve, SpaceCurve):
        raise TypeError(f"curve must be a SpaceCurve, got {type(curve).__name__}")
    end = curve.length if end is None else min(positive(end, "end"), curve.length)
    iv = joint_intervals(s_joints, kinds, end)
    ty, tp = curve.bending(iv[:, 0], iv[:, 1], phi0=phi0)
    return np.where(np.array(kinds) == YAW, ty, tp)


def curve_joint_angles(robot: SnakeRobot, curve: SpaceCurve, joints: slice, *, s_start: float | None = None,
                       phi0: float | None = None, frame0=None) -> np.ndarray:
    """URDF joint angles (rad) of ``robot.joints[joints]`` that lay the body along ``curve``.

    Parameters
    ----------
    robot : the snake.
    curve : the backbone; its start (s = 0) lies at body arc length ``s_start``.
    joints : slice into the joint vector, e.g. ``robot.parts.base``.
    s_start : body arc length (m) where the curve starts; default: the tail end (0) for a slice starting
        at joint 0, else the position of the slice's first joint.
    phi0 / frame0 : the phase at the curve's start, either directly (rad) or from the body frame's rotation
        (3, 3) there (see :meth:`SpaceCurve.initial_phase`); default 0 (the curve's normal along the body's y).

    Returns (len(joints),) joint angles: +theta_y (Eq. 5) at +z yaw joints, -theta_p (Eq. 6) at +y pitch
    joints, over the intervals of :func:`joint_intervals` on the part's stretch of the curve: from its start
    to the first joint after the slice (or the body's last frame); a longer curve is cut there. Raises
    ValueError if the curve is too short for the joints, or both phi0 and frame0 are given.
    """
    if not isinstance(curve, SpaceCurve):
        raise TypeError(f"curve must be a SpaceCurve, got {type(curve).__name__}")
    lay = joint_layout(robot)
    idx = np.arange(robot.n_joints)[joints]
    if len(idx) == 0:
        raise ValueError("joints selects no joint")
    if s_start is None:
        s_start = 0.0 if idx[0] == 0 else float(lay.s[idx[0]])
    s_start = _finite_float(s_start, "s_start")
    if phi0 is not None and frame0 is not None:
        raise ValueError("give phi0 or frame0, not both")
    if frame0 is not None:
        phi0 = curve.initial_phase(np.asarray(frame0, dtype=np.float64)[:3, :3])
    phi0 = 0.0 if phi0 is None else _finite_float(phi0, "phi0")
    s_on = lay.s[idx] - s_start
    if s_on[0] < -1e-12:
        raise ValueError(f"the curve starts at body arc length {s_start:.6g} m, after the first joint")
    if s_on[-1] > curve.length + 1e-12:
        raise ValueError(f"the curve ({curve.length:.6g} m) is shorter than the body it must cover "
                         f"({s_on[-1]:.6g} m to the last joint)")
    # the part ends where the next joint begins (or at the body's last frame); a longer curve is cut there
    part_end = (lay.s[idx[-1] + 1] if idx[-1] + 1 < robot.n_joints else lay.length) - s_start
    kinds = [lay.kinds[i] for i in idx]
    theta = discretize(curve, np.maximum(s_on, 0.0), kinds, phi0=phi0, end=part_end)
    sign = np.where(np.array(kinds) == YAW, 1.0, -1.0) * lay.signs[idx]
    return sign * theta


# ---------------------------------------------------------------------------------------------------
# the plane arc: Eqs. 1, 2, 8, 9
# ---------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PlaneArc:
    """A circular arc in the horizontal plane z = ``height``.

    radius (m), central_angle (rad, in (0, 2 pi]), start (2,) world xy of the arc's start, heading (rad)
    the direction of its start tangent, turn +1 (counter-clockwise seen from above, towards the left) or -1.
    """

    radius: float
    central_angle: float
    start: np.ndarray = field(default_factory=lambda: np.zeros(2))
    heading: float = 0.0
    turn: int = 1
    height: float = BODY_AXIS_HEIGHT

    def __post_init__(self):
        positive(self.radius, "radius")
        _check_central_angle(self.central_angle)
        _check_turn(self.turn)
        object.__setattr__(self, "start", finite_array(self.start, "start", (2,)))
        _finite_float(self.heading, "heading")
        _finite_float(self.height, "height")

    @property
    def length(self) -> float:
        """Arc length r * theta (m), Eq. 1."""
        return self.radius * self.central_angle

    @property
    def center(self) -> np.ndarray:
        """(2,) world xy of the circle's centre."""
        n = self.turn * np.array([-math.sin(self.heading), math.cos(self.heading)])
        return np.asarray(self.start, dtype=np.float64) + self.radius * n

    def point(self, s) -> np.ndarray:
        """(..., 3) world points at arc lengths s (m)."""
        s = np.asarray(s, dtype=np.float64)
        a = self.heading + self.turn * s / self.radius
        c = self.center
        # the start sits at angle heading - turn*pi/2 seen from the centre
        x = c[0] + self.radius * np.sin(a) * self.turn
        y = c[1] - self.radius * np.cos(a) * self.turn
        return np.stack([x, y, np.full_like(x, self.height)], axis=-1)

    def tangent(self, s) -> np.ndarray:
        """(..., 3) unit tangents at arc lengths s."""
        a = self.heading + self.turn * np.asarray(s, dtype=np.float64) / self.radius
        return np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)

    def curve(self) -> SpaceCurve:
        """The arc as a :class:`SpaceCurve` parametrised by arc length, with exact derivatives."""
        k = self.turn / self.radius  # signed curvature

        def d1(t):
            return self.tangent(t)

        def d2(t):
            a = self.heading + k * t
            return k * np.array([-math.sin(a), math.cos(a), 0.0])

        def d3(t):
            a = self.heading + k * t
            return -k * k * np.array([math.cos(a), math.sin(a), 0.0])

        return SpaceCurve(self.point, 0.0, self.length, derivatives=(d1, d2, d3))


CHORD_MODES = ("arclength", "exact")


def arc_joint_angles(length: float, central_angle: float, robot: SnakeRobot | None = None, *,
                     joints: slice | None = None, chords: str = "arclength", turn: int = 1) -> np.ndarray:
    """Joint angles (rad) that lay the base along a plane arc of length ``length`` and central angle
    ``central_angle`` in the ground plane (Eqs. 1, 8, 9): theta_y = Delta s / r at yaw joints, 0 at pitch.

    Parameters
    ----------
    length : arc length l (m), > 0; it starts at the tail end (at the first selected joint when ``joints``
        does not start at joint 0) and must reach past the last selected joint
        (the default robot's base is 0.646 m: :func:`base_length`).
    central_angle : theta (rad), in (0, 2 pi].
    robot : default ``SnakeRobot.default()``.
    joints : which joints lie on the arc; default ``robot.parts.base``.
    chords : how the arc's length is shared out.

        * ``"arclength"`` -- the paper's Eq. 9 with r = l / theta (Eq. 1) and Delta s the joint's interval
          (:func:`joint_intervals`): the links are taken as pieces of the arc. The yaw angles add up to
          theta, so the body leaves along the arc's end tangent; the joints lie within O(kappa d^2) of the arc.
        * ``"exact"`` -- the links are chords of the arc: the tail end, every yaw joint and the point at
          body arc length ``length`` (P0) lie exactly on a circle, and the first and last of these on the
          ends of an arc of central angle theta. The chords c_j between these points subtend
          alpha_j = 2 asin(c_j / 2r), with r solved from sum alpha_j = theta; a yaw joint turns by
          (alpha_before + alpha_after) / 2 -- Eq. 9 with Delta s measured on the circle between the midpoints
          of the arcs its two links subtend. The arc is then slightly longer than l (r theta > l).
          Pitch joints, straight, sit on the chords.
    turn : +1 bends left (counter-clockwise seen from above: positive yaw), -1 right.

    Returns (len(joints),) joint angles. Raises ValueError on a non-positive or non-finite length, a
    central angle outside (0, 2 pi], an unknown chord mode, or a length that does not reach the joints.
    """
    l = positive(length, "length")
    theta = _check_central_angle(central_angle)
    turn = _check_turn(turn)
    if chords not in CHORD_MODES:
        raise ValueError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    robot = SnakeRobot.default() if robot is None else as_robot(robot)
    joints = robot.parts.base if joints is None else joints
    lay = joint_layout(robot)
    idx = np.arange(robot.n_joints)[joints]
    s = lay.s[idx] - (0.0 if idx[0] == 0 else lay.s[idx[0]])
    if s[-1] >= l:
        raise ValueError(f"the arc ({l:.6g} m) does not reach past the last joint ({s[-1]:.6g} m)")
    kinds = [lay.kinds[i] for i in idx]
    q = np.zeros(len(idx))
    yaw = np.array([k == YAW for k in kinds])
    if chords == "arclength":
        r = l / theta  # Eq. 1
        iv = joint_intervals(s, kinds, l)
        q[yaw] = (iv[yaw, 1] - iv[yaw, 0]) / r  # Eq. 9: theta_y = kappa_y * Delta s = Delta s / r
    else:
        vertices = np.concatenate([[0.0], s[yaw], [l]])
        c = np.diff(vertices)
        r = exact_chord_radius(c, theta)
        alpha = 2.0 * np.arcsin(np.minimum(c / (2.0 * r), 1.0))
        q[yaw] = 0.5 * (alpha[:-1] + alpha[1:])
    return turn * q * lay.signs[idx]


def exact_chord_radius(chords, central_angle: float) -> float:
    """Radius r of the circle on which a polyline with chord lengths ``chords`` (m) spans ``central_angle``
    (rad): sum_j 2 asin(c_j / 2r) = theta. ValueError when no such circle exists (theta too large)."""
    c = finite_array(chords, "chords", (None,))
    if np.any(c <= 0):
        raise ValueError("chord lengths must be positive")
    theta = _check_central_angle(central_angle)

    def span(r):
        return float(np.sum(2.0 * np.arcsin(np.minimum(c / (2.0 * r), 1.0))))

    r_min = 0.5 * c.max()
    if span(r_min) < theta:
        raise ValueError(f"chords {c.round(4).tolist()} cannot span a central angle of {theta:.4f} rad "
                         "with every chord on a minor arc")
    if span(r_min) == theta:
        return r_min
    r_max = c.sum() / theta * 2.0 + r_min
    while span(r_max) > theta:
        r_max *= 2.0
    return float(optimize.brentq(lambda r: span(r) - theta, r_min, r_max, xtol=1e-15, rtol=1e-15))


def base_length(robot: SnakeRobot | None = None) -> float:
    """Body arc length of P0 (the ``base_end`` frame) from the tail end (m): the base arc's length l."""
    robot = SnakeRobot.default() if robot is None else as_robot(robot)
    F = robot.body.fk_all(np.zeros(robot.n_joints))
    k = robot.body.link_index(robot.parts.base_end)
    return float(F[k, 0, 3] - F[0, 0, 3])


def base_arc(robot: SnakeRobot, central_angle: float, base: BasePlacement | None = None, *,
             chords: str = "arclength", turn: int = 1, anchor: str = "tail") -> PlaneArc:
    """The world :class:`PlaneArc` that :func:`arc_joint_angles` discretises, for a base placed at ``base``.

    With ``"exact"`` chords the arc's radius is :func:`exact_chord_radius`, it starts at the tail end and
    its start tangent is turned back by half the first chord's angle, so that the first chord lies along the
    tail link: the tail end, the yaw joints and P0 lie on it exactly.

    With ``"arclength"`` chords (Eq. 9) the radius is l / theta (Eq. 1) and the start tangent is the tail
    link's x-axis, so the end tangent is the robot's P0 x-axis (the yaw angles add up to theta). ``anchor``
    says which end of the body lies exactly on the arc: ``"tail"`` -- the arc starts at the tail end;
    ``"end"`` -- the arc is translated so that it ends at the robot's P0 (``base_end``), which then is the
    exact G1 join with a curve continuing the body (what :func:`initial_backbone` uses). Either way the
    other joints lie within the discretisation error of the arc (about 1.4 cm at theta = 3 on the default
    robot, growing with theta).
    """
    robot = as_robot(robot)
    theta = _check_central_angle(central_angle)
    turn = _check_turn(turn)
    if anchor not in ("tail", "end"):
        raise ValueError(f"anchor must be 'tail' or 'end', got {anchor!r}")
    base = BasePlacement() if base is None else base
    l = base_length(robot)
    heading = base.yaw
    if chords == "arclength":
        r = l / theta
    elif chords == "exact":
        lay = joint_layout(robot)
        idx = np.arange(robot.n_joints)[robot.parts.base]
        s = lay.s[idx]
        yaw = np.array([lay.kinds[i] == YAW for i in idx])
        c = np.diff(np.concatenate([[0.0], s[yaw], [l]]))
        r = exact_chord_radius(c, theta)
        heading = base.yaw - turn * math.asin(min(c[0] / (2 * r), 1.0))
    else:
        raise ValueError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    arc = PlaneArc(radius=r, central_angle=theta, start=np.array([base.x, base.y]), heading=heading,
                   turn=turn, height=BODY_AXIS_HEIGHT)
    if anchor == "end":
        q = np.zeros(robot.n_joints)
        q[robot.parts.base] = arc_joint_angles(l, theta, robot, chords=chords, turn=turn)
        p0 = robot.frame(q, robot.parts.base_end, base)[:3, 3]
        shift = p0[:2] - arc.point(arc.length)[:2]
        arc = PlaneArc(radius=r, central_angle=theta, start=arc.start + shift, heading=heading, turn=turn,
                       height=BODY_AXIS_HEIGHT)
    return arc


def arc_segment_area(length: float, central_angle) -> np.ndarray | float:
    """Eq. 2 with Eq. 1: the area (m^2) between a plane arc of length l and its chord,
    S(theta) = 1/2 r^2 (theta - sin theta) with r = l / theta; theta scalar or array in (0, 2 pi]."""
    l = positive(length, "length")
    th = finite_array(central_angle, "central_angle")
    if np.any(th <= 0) or np.any(th > 2 * np.pi):
        raise ValueError("central_angle must be in (0, 2*pi] rad")
    r = l / th  # Eq. 1
    S = 0.5 * r ** 2 * (th - np.sin(th))  # Eq. 2
    return float(S) if th.ndim == 0 else S


def arc_area_maximum(length: float) -> tuple[float, float]:
    """The maximum of Eq. 2 over theta in (0, 2 pi] for a fixed arc length l: (theta*, S*) = (pi, l^2 / 2 pi).

    Derivation. With r = l / theta, S = (l^2 / 2) f(theta), f = (theta - sin theta) / theta^2, and

        f'(theta) = [2 sin theta - theta (1 + cos theta)] / theta^3
                  = 2 cos(theta/2) [2 sin(theta/2) - theta cos(theta/2)] / theta^3.

    The bracket is positive on (0, 2 pi) (tan x > x on (0, pi/2); on [pi/2, pi) sin > 0 >= cos), so f' has
    the sign of cos(theta/2): positive below pi, negative above. The only stationary point in (0, 2 pi] is
    theta = pi, a maximum, where S = 1/2 r^2 pi = l^2 / (2 pi) with r = l / pi -- the half disc, as the paper
    says (and as Dido's problem says: a curve of given length cutting the most area off a straight line is a
    semicircle). The next root of the bracket, tan(theta/2) = theta/2 at theta = 8.987, lies beyond 2 pi.
    The paper's claim holds when the arc's length l is fixed (the robot's base); read with the radius r fixed
    instead, dS/dtheta = r^2 (1 - cos theta) / 2 >= 0, there is no interior maximum and S grows to the full
    disc pi r^2 at theta = 2 pi.
    """
    l = positive(length, "length")
    return math.pi, l * l / (2.0 * math.pi)


# ---------------------------------------------------------------------------------------------------
# support polygon area and the optimised central angle
# ---------------------------------------------------------------------------------------------------
def polygon_area(vertices) -> float:
    """Area (m^2) of a simple polygon given by its (k, 2) vertices in order (shoelace formula)."""
    v = finite_array(vertices, "vertices", (None, 2))
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _stability():
    from . import stability  # imported lazily: stability.py imports robot only, not this module
    return stability


def _support_area_and_margin(robot: SnakeRobot, q: np.ndarray, base: BasePlacement | None) -> tuple[float, float]:
    """(area of the support polygon (m^2), static margin of the whole-body CoM (m, > 0 inside))."""
    st = _stability()
    poly = st.support_polygon(robot, q, base)
    return polygon_area(poly), float(st.static_margin(robot, q, base))


def arc_angle_limit(robot: SnakeRobot, *, turn: int = 1, chords: str = "arclength") -> float:
    """Largest central angle (rad, <= 2 pi) whose discretisation keeps every base yaw joint within its limit.

    ``"arclength"``: theta <= min_i limit_i * l / Delta s_i (Eq. 9 is linear in theta). ``"exact"``: the
    root (scipy.optimize.brentq) of max_i q_i(theta) / limit_i = 1, capped where the chords stop fitting
    on minor arcs (:func:`exact_chord_radius`).
    """
    robot = as_robot(robot)
    turn = _check_turn(turn)
    if chords not in CHORD_MODES:
        raise ValueError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    l = base_length(robot)
    idx = np.arange(robot.n_joints)[robot.parts.base]
    if chords == "arclength":
        q1 = arc_joint_angles(l, 1.0, robot, turn=turn)  # angles per radian of central angle
        lim = np.where(q1 > 0, robot.upper[idx], robot.lower[idx])
        with np.errstate(divide="ignore"):
            ratio = np.where(q1 != 0, lim / q1, np.inf)
        return float(min(2.0 * math.pi, ratio.min()))
    lay = joint_layout(robot)
    yaw = np.array([lay.kinds[i] == YAW for i in idx])
    c = np.diff(np.concatenate([[0.0], lay.s[idx][yaw], [l]]))
    top = min(2.0 * math.pi, float(np.sum(2.0 * np.arcsin(c / c.max()))))

    def usage(theta: float) -> float:  # the largest |q_i| / |limit_i|, increasing in theta
        q = arc_joint_angles(l, theta, robot, chords="exact", turn=turn)
        lim = np.where(q > 0, robot.upper[idx], -robot.lower[idx])
        return float(np.max(np.abs(q) / lim))

    if usage(top) <= 1.0:
        return top
    return float(optimize.brentq(lambda t: usage(t) - 1.0, 1e-6, top, xtol=1e-13))


@dataclass(frozen=True)
class ArcOptimum:
    """Result of :func:`optimize_base_arc`.

    central_angle : optimised theta (rad).
    area : area of the discretised support polygon there (m^2).
    margin : static margin of the whole body's CoM there (m, > 0 inside).
    q : (n,) the whole-body joint vector there.
    angle_limit : the joint-limit bound on theta (rad).
    eq2_angle, eq2_area : Eq. 2's maximiser pi and its area l^2 / 2 pi (continuous arc, m^2).
    area_at_eq2_angle : the discretised polygon's area at theta = pi (m^2; NaN if pi is beyond the bounds).
    grid : (m, 3) the scanned (theta, area, margin) rows.
    """

    central_angle: float
    area: float
    margin: float
    q: np.ndarray
    angle_limit: float
    eq2_angle: float
    eq2_area: float
    area_at_eq2_angle: float
    grid: np.ndarray


def optimize_base_arc(robot: SnakeRobot | None = None, q_up=None, base: BasePlacement | None = None, *,
                      min_margin: float = 0.0, turn: int = 1, bounds: tuple[float, float] | None = None,
                      n_grid: int = 41, chords: str = "arclength") -> ArcOptimum:
    """The base arc's central angle that maximises the area of the discretised support polygon
    (``stability.support_polygon``) subject to the whole body's centre of mass lying inside it by at least
    ``min_margin`` (``stability.static_margin``) and the base's yaw joints within their limits.

    Parameters
    ----------
    robot : default ``SnakeRobot.default()``.
    q_up : joint angles (rad) of the joints after the base (neck and head), held fixed while theta varies;
        default: the up curve of :func:`initial_backbone`'s default :class:`UpCurveShape`.
    base : where the tail lies (default ``BasePlacement()``).
    min_margin : required static margin (m), >= 0.
    turn : +1 left, -1 right.
    bounds : (theta_lo, theta_hi) rad; default (0.05, :func:`arc_angle_limit`).
    chords : the base's discretisation (:func:`arc_joint_angles`); default ``"arclength"`` (Eq. 9), the one
        :func:`initial_backbone` uses.
    n_grid : points of the coarse scan before the bounded scalar refinement (scipy.optimize.minimize_scalar).

    The scan finds the best feasible grid angle; the refinement maximises the area between its neighbours,
    cut at the margin constraint's boundary (scipy.optimize.brentq) when a neighbour is infeasible. Raises
    ValueError if no angle is feasible.

    Measured on the default robot with the default up curve (support polygon of the links' endpoints):

    * ``"arclength"`` (Eq. 9): theta* = 2.977 rad (170.6 deg), area 628.4 cm^2, CoM margin 2.0 cm;
      at theta = pi the area is 626.5 cm^2. Eq. 2's continuous arc gives 664.2 cm^2 at pi: the discrete
      polygon loses about 5 %, and its best angle is 9.4 deg below pi (the Eq. 9 polyline is not
      symmetric: the first yaw joint turns by 0.127/r, the others by 0.173/r, and the tail link is
      0.0405 m long against 0.0865 m for the last base link).
    * ``"exact"``: theta* = pi (to the optimiser's tolerance), area 630.8 cm^2. This is Eq. 2's answer
      exactly, for a reason independent of Eq. 2: a polygon with given sides and one free side (the chord)
      has the largest area when it is inscribed in a semicircle on the free side.
    * The margin constraint is inactive there (the margin grows with theta); asking 3 cm moves theta* to
      4.23 rad (242 deg, area 536.6 cm^2).
    """
    robot = SnakeRobot.default() if robot is None else as_robot(robot)
    turn = _check_turn(turn)
    min_margin = _finite_float(min_margin, "min_margin")
    if min_margin < 0:
        raise ValueError(f"min_margin must be >= 0 m, got {min_margin}")
    nb = robot.parts.base.stop
    if q_up is None:
        q_up = _q_up_for(robot, UpCurveShape(), turn)[0]
    q_up = finite_array(q_up, "q_up", (robot.n_joints - nb,))
    lim = arc_angle_limit(robot, turn=turn, chords=chords)
    lo, hi = (0.05, lim) if bounds is None else (
        _finite_float(bounds[0], "bounds[0]"), _finite_float(bounds[1], "bounds[1]"))
    if not 0 < lo < hi <= lim + 1e-12:
        raise ValueError(f"bounds must satisfy 0 < lo < hi <= {lim:.6g} (joint limits), got ({lo}, {hi})")
    if int(n_grid) < 5:
        raise ValueError("n_grid must be >= 5")
    l = base_length(robot)

    def q_of(theta: float) -> np.ndarray:
        return np.concatenate([arc_joint_angles(l, theta, robot, chords=chords, turn=turn), q_up])

    def evaluate(theta: float) -> tuple[float, float]:
        return _support_area_and_margin(robot, q_of(theta), base)

    thetas = np.linspace(lo, hi, int(n_grid))
    rows = np.array([(t, *evaluate(t)) for t in thetas])
    feasible = rows[:, 2] >= min_margin
    if not feasible.any():
        raise ValueError(f"no central angle in [{lo:.4g}, {hi:.4g}] rad keeps the centre of mass inside the "
                         f"support polygon by {min_margin} m (best margin {rows[:, 2].max():.4g} m)")
    k = int(np.argmax(np.where(feasible, rows[:, 1], -np.inf)))
    a = thetas[max(k - 1, 0)]
    b = thetas[min(k + 1, len(thetas) - 1)]

    def margin_gap(t: float) -> float:
        return evaluate(t)[1] - min_margin

    if k > 0 and not feasible[k - 1]:
        a = optimize.brentq(margin_gap, thetas[k - 1], thetas[k], xtol=1e-12)
    if k < len(thetas) - 1 and not feasible[k + 1]:
        b = optimize.brentq(margin_gap, thetas[k], thetas[k + 1], xtol=1e-12)
    res = optimize.minimize_scalar(lambda t: -evaluate(t)[0], bounds=(a, b), method="bounded",
                                   options={"xatol": 1e-9})
    best = float(res.x)
    area, margin = evaluate(best)
    if margin < min_margin or area < rows[k, 1]:  # refinement fell off the feasible side: keep the grid point
        best, area, margin = float(thetas[k]), float(rows[k, 1]), float(rows[k, 2])
    eq2_angle, eq2_area = arc_area_maximum(l)
    area_pi = evaluate(math.pi)[0] if lo <= math.pi <= hi else float("nan")
    return ArcOptimum(central_angle=best, area=area, margin=margin, q=q_of(best), angle_limit=lim,
                      eq2_angle=eq2_angle, eq2_area=eq2_area, area_at_eq2_angle=area_pi, grid=rows)


# ---------------------------------------------------------------------------------------------------
# the neck and head: a plane cubic Bezier in a vertical plane, G1 at P0 (Section 3.3 (1))
# ---------------------------------------------------------------------------------------------------
def cubic_bezier(control_points) -> SpaceCurve:
    """The cubic Bezier curve B(t) = sum_k C(3,k) (1-t)^(3-k) t^k P_k, t in [0, 1], of four (3,) control
    points (m), as a :class:`SpaceCurve` with its exact derivatives."""
    P = finite_array(control_points, "control_points", (4, 3))

    def r(t):
        u = 1.0 - t
        return u ** 3 * P[0] + 3 * u * u * t * P[1] + 3 * u * t * t * P[2] + t ** 3 * P[3]

    def d1(t):
        u = 1.0 - t
        return 3.0 * (u * u * (P[1] - P[0]) + 2 * u * t * (P[2] - P[1]) + t * t * (P[3] - P[2]))

    def d2(t):
        return 6.0 * ((1.0 - t) * (P[2] - 2 * P[1] + P[0]) + t * (P[3] - 2 * P[2] + P[1]))

    def d3(t):
        return 6.0 * (P[3] - 3 * P[2] + 3 * P[1] - P[0])

    return SpaceCurve(r, 0.0, 1.0, derivatives=(d1, d2, d3))


_GL_X, _GL_W = np.polynomial.legendre.leggauss(64)


def _planar_bezier_length(B: np.ndarray) -> float:
    """Length of the planar cubic Bezier with (4, 2) control points (64-point Gauss-Legendre)."""
    t = 0.5 * (_GL_X + 1.0)
    u = 1.0 - t
    d = 3.0 * (np.outer(u * u, B[1] - B[0]) + np.outer(2 * u * t, B[2] - B[1]) + np.outer(t * t, B[3] - B[2]))
    return float(0.5 * np.dot(_GL_W, np.linalg.norm(d, axis=1)))


@dataclass(frozen=True)
class UpCurveShape:
    """The neck-and-head backbone: a cubic Bezier in the vertical plane through P0 and the base arc's end
    tangent T0, in that plane's coordinates (u along T0, w up, origin at P0 on the body axis):

        B0 = (0, 0),  B1 = (a, 0),  B2 = B3 - b (cos psi, sin psi),  B3 = (reach, height),

    B1 on the tangent makes the join G1 (tangent-continuous). The handle lengths a and b = handle_ratio * a
    are solved (scipy.optimize.brentq) so that the curve is exactly as long as the neck and head
    (0.738 m on the default robot), so the head tip ends at B3 up to the discretisation's error.

    height : w of the end point B3 above the body axis at P0 (m); default 0.55.
    reach : u of B3, horizontal distance ahead of P0 along T0 (m; negative: behind P0, over the base);
        default -0.10.
    tip_angle : psi, direction of the curve at B3 above the horizontal (rad), in (0, pi); default 140 deg
        (the head leans back over the base).
    handle_ratio : b / a, > 0; default 2.

    Why these defaults. A convex curve (no inflection, which Eqs. 3-4 need) that leaves P0 horizontally is
    no longer than the two tangent segments from its ends to where its end tangents meet, so a 0.738 m
    neck and head that ends near P0 must lean back (psi > 90 deg). Leaning back over the base also keeps
    the whole body's centre of mass inside the support polygon: with these defaults the static margin is
    about 2 cm at the optimised base arc, the pitch joints are at most 68 deg, and every frame of the neck
    and head lies within 2.1 cm of the curve. Other shapes are rejected with a ValueError when the curve
    would need an inflection, cannot have the body's length, or needs joints beyond their limits.
    """

    height: float = 0.55
    reach: float = -0.10
    tip_angle: float = math.radians(140.0)
    handle_ratio: float = 2.0

    def __post_init__(self):
        finite_array([self.height, self.reach, self.tip_angle, self.handle_ratio], "UpCurveShape", (4,))
        if self.height <= 0:
            raise ValueError(f"height must be > 0 m (the head is raised), got {self.height}")
        if not 0 < self.tip_angle < math.pi:
            raise ValueError(f"tip_angle must be in (0, pi) rad, got {self.tip_angle}")
        if self.handle_ratio <= 0:
            raise ValueError(f"handle_ratio must be > 0, got {self.handle_ratio}")

    def plane_control_points(self, length: float) -> np.ndarray:
        """(4, 2) control points (u, w) in m of the curve of the given arc length (m)."""
        L = positive(length, "length")
        psi = self.tip_angle
        end = np.array([self.reach, self.height])
        back = np.array([math.cos(psi), math.sin(psi)])

        def pts(a: float) -> np.ndarray:
            return np.array([[0.0, 0.0], [a, 0.0], end - self.handle_ratio * a * back, end])

        chord = float(np.linalg.norm(end))
        if chord >= L:
            raise ValueError(f"the head tip (reach {self.reach}, height {self.height}) is {chord:.4g} m from P0, "
                             f"beyond the {L:.4g} m the neck and head can reach")
        a_max = L
        while _planar_bezier_length(pts(a_max)) < L:
            a_max *= 2.0
            if a_max > 1e3 * L:
                raise ValueError("no handle length gives the curve the body's length")
        a = optimize.brentq(lambda a: _planar_bezier_length(pts(a)) - L, 0.0, a_max, xtol=1e-14, rtol=1e-14)
        return pts(a)


def up_curve(arc: PlaneArc, shape: UpCurveShape, length: float) -> tuple[SpaceCurve, np.ndarray]:
    """The neck-and-head Bezier in the world, joined G1 to ``arc`` at its end P0: (curve, (4, 3) points)."""
    if not isinstance(shape, UpCurveShape):
        raise TypeError(f"shape must be an UpCurveShape, got {type(shape).__name__}")
    B = shape.plane_control_points(length)
    p0 = arc.point(arc.length)
    T0 = arc.tangent(arc.length)
    z = np.array([0.0, 0.0, 1.0])
    P = p0 + np.outer(B[:, 0], T0) + np.outer(B[:, 1], z)
    return cubic_bezier(P), P


def up_length(robot: SnakeRobot) -> float:
    """Body arc length from P0 to the last frame (the head tip), m: the up curve's length."""
    return joint_layout(robot).length - base_length(robot)


def _q_up_for(robot: SnakeRobot, shape: UpCurveShape, turn: int) -> tuple[np.ndarray, SpaceCurve, np.ndarray, float]:
    """Joint angles after the base for ``shape``, computed at theta = pi and the default placement.

    The up curve is rigidly attached to the arc's end frame, so its curvature, torsion and initial phase, and
    hence these angles, do not depend on the arc's central angle or the placement.
    """
    arc = base_arc(robot, math.pi, None, turn=turn, anchor="end")
    q_base = arc_joint_angles(base_length(robot), math.pi, robot, turn=turn)
    nb = robot.parts.base.stop
    q = np.concatenate([q_base, np.zeros(robot.n_joints - nb)])
    F = robot.frames(q)
    R0 = F[robot.body.link_index(robot.parts.base_end), :3, :3]
    curve, P = up_curve(arc, shape, up_length(robot))
    phi0 = curve.initial_phase(R0)
    q_up = curve_joint_angles(robot, curve, slice(nb, robot.n_joints), phi0=phi0)
    return q_up, curve, P, phi0


@dataclass(frozen=True)
class InitialBackbone:
    """The initial configuration of Section 3.3 (1) and the curves it discretises.

    q : (n,) whole-body joint angles (rad).
    central_angle : the base arc's theta (rad).
    arc : the base's :class:`PlaneArc` (world).
    up_curve : the neck-and-head Bezier as a :class:`SpaceCurve` (world); control_points (4, 3) m.
    phi0 : phase of the up curve at P0 (rad; pi/2: its normal points up).
    shape : the :class:`UpCurveShape` used.
    base : the :class:`BasePlacement`.
    optimum : the :class:`ArcOptimum` when theta was optimised, else None.
    """

    q: np.ndarray
    central_angle: float
    arc: PlaneArc
    up_curve: SpaceCurve
    control_points: np.ndarray
    phi0: float
    shape: UpCurveShape
    base: BasePlacement
    optimum: ArcOptimum | None


def initial_backbone(robot: SnakeRobot | None = None, *, central_angle: float | None = None,
                     shape: UpCurveShape | None = None, base: BasePlacement | None = None, turn: int = 1,
                     min_margin: float = 0.0) -> InitialBackbone:
    """Section 3.3 (1): the base on a plane arc, the neck and head on a plane cubic Bezier joined G1 at P0 in
    the vertical plane through the arc's end tangent, both discretised into joint angles (Eqs. 3-9).

    Parameters
    ----------
    robot : default ``SnakeRobot.default()``.
    central_angle : the base arc's theta (rad, (0, 2 pi]); default None: :func:`optimize_base_arc`.
    shape : the up curve, default ``UpCurveShape()`` (head tip 0.55 m above the body axis, 0.10 m behind
        P0, pointing 140 deg from the forward horizontal, i.e. leaning back over the base).
    base : placement of the tail, default ``BasePlacement()`` (tail end at the origin, body along +x).
    turn : +1 the base curves left (counter-clockwise seen from above), -1 right.
    min_margin : required static margin (m) when theta is optimised.

    The base uses Eq. 9 (``"arclength"`` chords) so the robot's last base link leaves along the arc's end
    tangent, which is the Bezier's start tangent; the up curve is discretised by the general method
    (Eqs. 3-7) with the phase read from the robot's P0 frame. Raises ValueError if a joint leaves its limits.
    """
    robot = SnakeRobot.default() if robot is None else as_robot(robot)
    shape = UpCurveShape() if shape is None else shape
    base = BasePlacement() if base is None else base
    turn = _check_turn(turn)
    q_up, _, _, phi0 = _q_up_for(robot, shape, turn)
    optimum = None
    if central_angle is None:
        optimum = optimize_base_arc(robot, q_up, base, min_margin=min_margin, turn=turn)
        theta = optimum.central_angle
    else:
        theta = _check_central_angle(central_angle)
    q_base = arc_joint_angles(base_length(robot), theta, robot, turn=turn)
    q = np.concatenate([q_base, q_up])
    bad = np.flatnonzero((q < robot.lower - 1e-12) | (q > robot.upper + 1e-12))
    if len(bad):
        raise ValueError("the backbone needs joints beyond their limits: " + ", ".join(
            f"joint {i + 1} = {math.degrees(q[i]):.1f} deg" for i in bad))
    arc = base_arc(robot, theta, base, turn=turn, anchor="end")
    curve, P = up_curve(arc, shape, up_length(robot))
    return InitialBackbone(q=q, central_angle=theta, arc=arc, up_curve=curve, control_points=P, phi0=phi0,
                           shape=shape, base=base, optimum=optimum)


def initial_configuration(robot: SnakeRobot | None = None, **kwargs) -> np.ndarray:
    """The initial configuration q (n,) of Section 3.3 (1); see :func:`initial_backbone` for the keyword
    arguments (central_angle, shape, base, turn, min_margin) and their defaults."""
    return initial_backbone(robot, **kwargs).q
