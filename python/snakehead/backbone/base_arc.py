"""The base part's plane arc: paper Eqs. 1, 2, 8, 9, and the central angle that maximises the support polygon.

* :class:`PlaneArc`, :func:`arc_joint_angles`, :func:`base_arc` -- the arc in the ground plane and its
  discretisation (Eqs. 1, 8, 9).
* :func:`arc_segment_area`, :func:`arc_area_maximum` -- Eq. 2 and its maximum.
* :func:`optimize_base_arc` -- the central angle that maximises the area of the discretised support polygon
  with the whole body's centre of mass inside it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import numpy.typing as npt
from scipy import optimize

from .._errors import Infeasible, InputError
from .._validate import finite_array, finite_float, positive
from ..dynamics import stability
from ..model.robot import YAW, BasePlacement, SnakeRobot, as_robot
from .curves import SpaceCurve
from .discretize import joint_intervals

__all__ = ["CHORD_MODES", "ArcOptimum", "PlaneArc", "arc_angle_limit", "arc_area_maximum", "arc_joint_angles",
           "arc_segment_area", "base_arc", "checked_central_angle", "checked_turn", "exact_chord_radius",
           "optimize_base_arc", "polygon_area"]


def checked_central_angle(theta: float) -> float:
    """A central angle (rad) checked to be finite and in (0, 2 pi] (InputError otherwise)."""
    th = finite_float(theta, "central_angle")
    if not 0.0 < th <= 2.0 * math.pi:
        raise InputError(f"central_angle must be in (0, 2*pi] rad, got {th!r}")
    return th


def checked_turn(turn: int) -> int:
    """A turning sense checked to be +1 (left) or -1 (right) (InputError otherwise)."""
    if turn not in (1, -1):
        raise InputError(f"turn must be +1 (left, counter-clockwise from above) or -1 (right), got {turn!r}")
    return int(turn)


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
    height: float = 0.0

    def __post_init__(self) -> None:
        positive(self.radius, "radius")
        checked_central_angle(self.central_angle)
        checked_turn(self.turn)
        object.__setattr__(self, "start", finite_array(self.start, "start", (2,)))
        finite_float(self.heading, "heading")
        finite_float(self.height, "height")

    @property
    def length(self) -> float:
        """Arc length r * theta (m), Eq. 1."""
        return self.radius * self.central_angle

    @property
    def center(self) -> np.ndarray:
        """(2,) world xy of the circle's centre."""
        n = self.turn * np.array([-math.sin(self.heading), math.cos(self.heading)])
        return np.asarray(self.start, dtype=np.float64) + self.radius * n

    def point(self, s: npt.ArrayLike) -> np.ndarray:
        """(..., 3) world points at arc lengths s (m)."""
        s = np.asarray(s, dtype=np.float64)
        a = self.heading + self.turn * s / self.radius
        c = self.center
        # the start sits at angle heading - turn*pi/2 seen from the centre
        x = c[0] + self.radius * np.sin(a) * self.turn
        y = c[1] - self.radius * np.cos(a) * self.turn
        return np.stack([x, y, np.full_like(x, self.height)], axis=-1)

    def tangent(self, s: npt.ArrayLike) -> np.ndarray:
        """(..., 3) unit tangents at arc lengths s."""
        a = self.heading + self.turn * np.asarray(s, dtype=np.float64) / self.radius
        return np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)

    def curve(self) -> SpaceCurve:
        """The arc as a :class:`SpaceCurve` parametrised by arc length, with exact derivatives."""
        k = self.turn / self.radius  # signed curvature

        def d1(t: float) -> np.ndarray:
            return self.tangent(t)

        def d2(t: float) -> np.ndarray:
            a = self.heading + k * t
            return k * np.array([-math.sin(a), math.cos(a), 0.0])

        def d3(t: float) -> np.ndarray:
            a = self.heading + k * t
            return -k * k * np.array([math.cos(a), math.sin(a), 0.0])

        return SpaceCurve(self.point, 0.0, self.length, derivatives=(d1, d2, d3))


CHORD_MODES = ("arclength", "exact")


def arc_joint_angles(length: float, central_angle: float, robot: SnakeRobot, *,
                     joints: slice | None = None, chords: str = "arclength", turn: int = 1) -> np.ndarray:
    """Joint angles (rad) that lay the base along a plane arc of length ``length`` and central angle
    ``central_angle`` in the ground plane (Eqs. 1, 8, 9): theta_y = Delta s / r at yaw joints, 0 at pitch.

    Parameters
    ----------
    length : arc length l (m), > 0; it starts at the tail end (at the first selected joint when ``joints``
        does not start at joint 0) and must reach past the last selected joint
        (the default robot's base is 0.646 m: :attr:`SnakeRobot.base_length`).
    central_angle : theta (rad), in (0, 2 pi].
    robot : the snake.
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
    theta = checked_central_angle(central_angle)
    turn = checked_turn(turn)
    if chords not in CHORD_MODES:
        raise InputError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    robot = as_robot(robot)
    joints = robot.parts.base if joints is None else joints
    idx = np.arange(robot.n_joints)[joints]
    s_joint = robot.joint_arc_lengths
    s = s_joint[idx] - (0.0 if idx[0] == 0 else s_joint[idx[0]])
    if s[-1] > l + 1e-12:
        raise InputError(f"the arc ({l:.6g} m) does not reach past the last joint ({s[-1]:.6g} m)")
    kinds = [robot.joint_kinds[i] for i in idx]
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
    return turn * q * robot.joint_signs[idx]


def exact_chord_radius(chords: npt.ArrayLike, central_angle: float) -> float:
    """Radius r of the circle on which a polyline with chord lengths ``chords`` (m) spans ``central_angle``
    (rad): sum_j 2 asin(c_j / 2r) = theta. ValueError when no such circle exists (theta too large)."""
    c = finite_array(chords, "chords", (None,))
    if np.any(c <= 0):
        raise InputError("chord lengths must be positive")
    theta = checked_central_angle(central_angle)

    def span(r: Any) -> float:
        return float(np.sum(2.0 * np.arcsin(np.minimum(c / (2.0 * r), 1.0))))

    r_min = 0.5 * c.max()
    if span(r_min) < theta:
        raise InputError(f"chords {c.round(4).tolist()} cannot span a central angle of {theta:.4f} rad "
                         "with every chord on a minor arc")
    if span(r_min) == theta:
        return r_min
    r_max = c.sum() / theta * 2.0 + r_min
    while span(r_max) > theta:
        r_max *= 2.0
    return float(optimize.brentq(lambda r: span(r) - theta, r_min, r_max, xtol=1e-15, rtol=1e-15))


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
    exact G1 join with a curve continuing the body (what :func:`~snakehead.backbone.initial.initial_backbone` uses). Either way the
    other joints lie within the discretisation error of the arc (about 1.4 cm at theta = 3 on the default
    robot, growing with theta).
    """
    robot = as_robot(robot)
    theta = checked_central_angle(central_angle)
    turn = checked_turn(turn)
    if anchor not in ("tail", "end"):
        raise InputError(f"anchor must be 'tail' or 'end', got {anchor!r}")
    base = BasePlacement() if base is None else base
    l = robot.base_length
    heading = base.yaw
    if chords == "arclength":
        r = l / theta
    elif chords == "exact":
        idx = np.arange(robot.n_joints)[robot.parts.base]
        s = robot.joint_arc_lengths[idx]
        yaw = np.array([robot.joint_kinds[i] == YAW for i in idx])
        c = np.diff(np.concatenate([[0.0], s[yaw], [l]]))
        r = exact_chord_radius(c, theta)
        heading = base.yaw - turn * math.asin(min(c[0] / (2 * r), 1.0))
    else:
        raise InputError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    arc = PlaneArc(radius=r, central_angle=theta, start=np.array([base.x, base.y]), heading=heading,
                   turn=turn, height=robot.body_axis_height)
    if anchor == "end":
        q = np.zeros(robot.n_joints)
        q[robot.parts.base] = arc_joint_angles(l, theta, robot, chords=chords, turn=turn)
        p0 = robot.frame(q, robot.parts.base_end, base)[:3, 3]
        shift = p0[:2] - arc.point(arc.length)[:2]
        arc = PlaneArc(radius=r, central_angle=theta, start=arc.start + shift, heading=heading, turn=turn,
                       height=robot.body_axis_height)
    return arc


def arc_segment_area(length: float, central_angle: npt.ArrayLike) -> np.ndarray | float:
    """Eq. 2 with Eq. 1: the area (m^2) between a plane arc of length l and its chord,
    S(theta) = 1/2 r^2 (theta - sin theta) with r = l / theta; theta scalar or array in (0, 2 pi]."""
    l = positive(length, "length")
    th = finite_array(central_angle, "central_angle")
    if np.any(th <= 0) or np.any(th > 2 * np.pi):
        raise InputError("central_angle must be in (0, 2*pi] rad")
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
def polygon_area(vertices: npt.ArrayLike) -> float:
    """Area (m^2) of a simple polygon given by its (k, 2) vertices in order (shoelace formula)."""
    v = finite_array(vertices, "vertices", (None, 2))
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _support_area_and_margin(robot: SnakeRobot, q: np.ndarray, base: BasePlacement | None) -> tuple[float, float]:
    """(area of the support polygon (m^2), static margin of the whole-body CoM (m, > 0 inside))."""
    poly = stability.support_polygon(robot, q, base)
    return polygon_area(poly), float(stability.static_margin(robot, q, base))


def arc_angle_limit(robot: SnakeRobot, *, turn: int = 1, chords: str = "arclength") -> float:
    """Largest central angle (rad, <= 2 pi) whose discretisation keeps every base yaw joint within its limit.

    ``"arclength"``: theta <= min_i limit_i * l / Delta s_i (Eq. 9 is linear in theta). ``"exact"``: the
    root (scipy.optimize.brentq) of max_i q_i(theta) / limit_i = 1, capped where the chords stop fitting
    on minor arcs (:func:`exact_chord_radius`).
    """
    robot = as_robot(robot)
    turn = checked_turn(turn)
    if chords not in CHORD_MODES:
        raise InputError(f"chords must be one of {CHORD_MODES}, got {chords!r}")
    l = robot.base_length
    idx = np.arange(robot.n_joints)[robot.parts.base]
    if chords == "arclength":
        q1 = arc_joint_angles(l, 1.0, robot, turn=turn)  # angles per radian of central angle
        lim = np.where(q1 > 0, robot.upper[idx], robot.lower[idx])
        with np.errstate(divide="ignore"):
            ratio = np.where(q1 != 0, lim / q1, np.inf)
        return float(min(2.0 * math.pi, ratio.min()))
    yaw = np.array([robot.joint_kinds[i] == YAW for i in idx])
    c = np.diff(np.concatenate([[0.0], robot.joint_arc_lengths[idx][yaw], [l]]))
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


def optimize_base_arc(robot: SnakeRobot, q_up: npt.ArrayLike | None = None, base: BasePlacement | None = None, *,
                      min_margin: float = 0.0, turn: int = 1, bounds: tuple[float, float] | None = None,
                      n_grid: int = 41, chords: str = "arclength") -> ArcOptimum:
    """The base arc's central angle that maximises the area of the discretised support polygon
    (``stability.support_polygon``) subject to the whole body's centre of mass lying inside it by at least
    ``min_margin`` (``stability.static_margin``) and the base's yaw joints within their limits.

    Parameters
    ----------
    robot : the snake.
    q_up : joint angles (rad) of the joints after the base (neck and head), held fixed while theta varies;
        default: the up curve of :func:`~snakehead.backbone.initial.initial_backbone`'s default :class:`~snakehead.backbone.initial.UpCurveShape`.
    base : where the tail lies (default ``BasePlacement()``).
    min_margin : required static margin (m), >= 0.
    turn : +1 left, -1 right.
    bounds : (theta_lo, theta_hi) rad; default (0.05, :func:`arc_angle_limit`).
    chords : the base's discretisation (:func:`arc_joint_angles`); default ``"arclength"`` (Eq. 9), the one
        :func:`~snakehead.backbone.initial.initial_backbone` uses.
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
    robot = as_robot(robot)
    turn = checked_turn(turn)
    min_margin = finite_float(min_margin, "min_margin")
    if min_margin < 0:
        raise InputError(f"min_margin must be >= 0 m, got {min_margin}")
    nb = robot.parts.base.stop
    if q_up is None:
        from .initial import UpCurveShape, up_curve_joint_angles  # a cycle: initial.py builds on this module

        q_up = up_curve_joint_angles(robot, UpCurveShape.for_robot(robot), turn)[0]
    q_up = finite_array(q_up, "q_up", (robot.n_joints - nb,))
    lim = arc_angle_limit(robot, turn=turn, chords=chords)
    lo, hi = _angle_bounds(bounds, lim)
    if int(n_grid) < 5:
        raise InputError("n_grid must be >= 5")
    l = robot.base_length

    def q_of(theta: float) -> np.ndarray:
        return np.concatenate([arc_joint_angles(l, theta, robot, chords=chords, turn=turn), q_up])

    def evaluate(theta: float) -> tuple[float, float]:
        return _support_area_and_margin(robot, q_of(theta), base)

    thetas = np.linspace(lo, hi, int(n_grid))
    rows = np.array([(t, *evaluate(t)) for t in thetas])
    best, area, margin = _refined_best(evaluate, thetas, rows, min_margin)
    eq2_angle, eq2_area = arc_area_maximum(l)
    area_pi = evaluate(math.pi)[0] if lo <= math.pi <= hi else float("nan")
    return ArcOptimum(central_angle=best, area=area, margin=margin, q=q_of(best), angle_limit=lim,
                      eq2_angle=eq2_angle, eq2_area=eq2_area, area_at_eq2_angle=area_pi, grid=rows)


def _angle_bounds(bounds: tuple[float, float] | None, lim: float) -> tuple[float, float]:
    """:func:`optimize_base_arc`'s (theta_lo, theta_hi), rad: ``bounds`` checked against the joint-limit bound
    ``lim``, default (0.05, lim)."""
    lo, hi = (0.05, lim) if bounds is None else (
        finite_float(bounds[0], "bounds[0]"), finite_float(bounds[1], "bounds[1]"))
    if not 0 < lo < hi <= lim + 1e-12:
        raise InputError(f"bounds must satisfy 0 < lo < hi <= {lim:.6g} (joint limits), got ({lo}, {hi})")
    return lo, hi


def _refined_best(evaluate: Callable[[float], tuple[float, float]], thetas: np.ndarray, rows: np.ndarray,
                  min_margin: float) -> tuple[float, float, float]:
    """The largest area among the scanned angles ``thetas`` whose margin is at least ``min_margin`` (``rows``:
    their (theta, area, margin)), refined between its neighbours (cut at the margin's boundary where a neighbour
    falls short of it): (theta, area, margin). Infeasible when no scanned angle keeps the margin."""
    feasible = rows[:, 2] >= min_margin
    if not feasible.any():
        raise Infeasible(f"no central angle in [{thetas[0]:.4g}, {thetas[-1]:.4g}] rad keeps the centre of mass "
                         f"inside the support polygon by {min_margin} m (best margin {rows[:, 2].max():.4g} m)")
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
    return best, area, margin
