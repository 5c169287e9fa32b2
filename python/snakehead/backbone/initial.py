"""The initial configuration of Section 3.3 (1) (Fig. 14): the base on its plane arc, the neck and head on a
plane cubic Bezier curve joined to it tangent-continuously (G1) at P0, in a vertical plane.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import optimize

from .._errors import Infeasible, InputError, InputTypeError
from .._validate import finite_array, positive
from ..dynamics import stability
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from .base_arc import (
    ArcOptimum,
    PlaneArc,
    arc_joint_angles,
    base_arc,
    checked_central_angle,
    checked_turn,
    optimize_base_arc,
)
from .curves import SpaceCurve, cubic_bezier, planar_bezier_length
from .discretize import curve_joint_angles

__all__ = ["HEIGHT_SHARE", "REACH_SHARE", "SHAPE_SEARCH", "InitialBackbone", "UpCurveShape", "initial_backbone",
           "initial_configuration", "up_curve", "up_curve_joint_angles", "up_length"]

#: The default up curve's end point as shares of the neck and head's length (0.55 m and -0.10 m of 0.738 m on
#: the default robot), so that the shape scales with any robot.
HEIGHT_SHARE = 0.55 / 0.738
REACH_SHARE = -0.10 / 0.738
#: Shapes tried when the scaled default does not fit a robot (joints beyond limits, or the body's centre of mass
#: outside the support polygon): (height share, reach share, tip angle in deg); the one with the largest static
#: margin is kept.
SHAPE_SEARCH = tuple((h, r, a) for a in (140.0, 120.0, 160.0) for h in (0.745, 0.65, 0.55, 0.85)
                     for r in (-0.1355, -0.25, -0.05, -0.35))


@dataclass(frozen=True)
class UpCurveShape:
    """The neck-and-head backbone: a cubic Bezier in the vertical plane through P0 and the base arc's end
    tangent T0, in that plane's coordinates (u along T0, w up, origin at P0 on the body axis):

        B0 = (0, 0),  B1 = (a, 0),  B2 = B3 - b (cos psi, sin psi),  B3 = (reach, height),

    B1 on the tangent makes the join G1 (tangent-continuous). The handle lengths a and b = handle_ratio * a
    are solved (scipy.optimize.brentq) so that the curve is exactly as long as the neck and head
    (0.738 m on the default robot), so the head tip ends at B3 up to the discretisation's error.

    height : w of the end point B3 above the body axis at P0 (m); default 0.55 (the default robot's; use
        :meth:`for_robot` for a shape scaled to any robot's neck and head).
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

    def __post_init__(self) -> None:
        finite_array([self.height, self.reach, self.tip_angle, self.handle_ratio], "UpCurveShape", (4,))
        if self.height <= 0:
            raise InputError(f"height must be > 0 m (the head is raised), got {self.height}")
        if not 0 < self.tip_angle < math.pi:
            raise InputError(f"tip_angle must be in (0, pi) rad, got {self.tip_angle}")
        if self.handle_ratio <= 0:
            raise InputError(f"handle_ratio must be > 0, got {self.handle_ratio}")

    @classmethod
    def for_robot(cls, robot: SnakeRobot, *, height_share: float = HEIGHT_SHARE, reach_share: float = REACH_SHARE,
                  tip_angle: float = math.radians(140.0), handle_ratio: float = 2.0) -> "UpCurveShape":
        """The shape scaled to ``robot``'s neck and head: height and reach are shares of their length
        (:func:`up_length`); the defaults give the default robot's 0.55 m and -0.10 m."""
        L = up_length(as_robot(robot))
        return cls(height=height_share * L, reach=reach_share * L, tip_angle=tip_angle, handle_ratio=handle_ratio)

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
            raise Infeasible(f"the head tip (reach {self.reach}, height {self.height}) is {chord:.4g} m from P0, "
                             f"beyond the {L:.4g} m the neck and head can reach")
        a_max = L
        while planar_bezier_length(pts(a_max)) < L:
            a_max *= 2.0
            if a_max > 1e3 * L:
                raise Infeasible("no handle length gives the curve the body's length")
        a = optimize.brentq(lambda a: planar_bezier_length(pts(a)) - L, 0.0, a_max, xtol=1e-14, rtol=1e-14)
        return pts(a)


def up_curve(arc: PlaneArc, shape: UpCurveShape, length: float) -> tuple[SpaceCurve, np.ndarray]:
    """The neck-and-head Bezier in the world, joined G1 to ``arc`` at its end P0: (curve, (4, 3) points)."""
    if not isinstance(shape, UpCurveShape):
        raise InputTypeError(f"shape must be an UpCurveShape, got {type(shape).__name__}")
    B = shape.plane_control_points(length)
    p0 = arc.point(arc.length)
    T0 = arc.tangent(arc.length)
    z = np.array([0.0, 0.0, 1.0])
    P = p0 + np.outer(B[:, 0], T0) + np.outer(B[:, 1], z)
    return cubic_bezier(P), P


def up_length(robot: SnakeRobot) -> float:
    """Body arc length from P0 to the last frame (the head tip), m: the up curve's length."""
    return robot.body_length - robot.base_length


def up_curve_joint_angles(robot: SnakeRobot, shape: UpCurveShape, turn: int
                          ) -> tuple[np.ndarray, SpaceCurve, np.ndarray, float]:
    """The joint angles (rad) after the base that lay the neck and head along ``shape``'s up curve (Eqs. 3-7),
    computed at theta = pi and the default placement, with the curve (world), its (4, 3) control points (m) and
    its phase at P0 (rad). Infeasible when Eqs. 3-7 cannot follow the curve.

    The up curve is rigidly attached to the arc's end frame, so its curvature, torsion and initial phase, and
    hence these angles, do not depend on the arc's central angle or the placement.
    """
    arc = base_arc(robot, math.pi, None, turn=turn, anchor="end")
    q_base = arc_joint_angles(robot.base_length, math.pi, robot, turn=turn)
    nb = robot.parts.base.stop
    q = np.concatenate([q_base, np.zeros(robot.n_joints - nb)])
    F = robot.frames(q)
    R0 = F[robot.body.link_index(robot.parts.base_end), :3, :3]
    try:  # the shape and the robot are valid; a curve they make that Eqs. 3-7 cannot follow has no answer
        curve, P = up_curve(arc, shape, up_length(robot))
        phi0 = curve.initial_phase(R0)
        q_up = curve_joint_angles(robot, curve, slice(nb, robot.n_joints), s_start=robot.base_length, phi0=phi0)
    except InputError as exc:
        raise Infeasible(f"the up curve of {shape} cannot be discretised: {exc}") from None
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


def initial_backbone(robot: SnakeRobot, *, central_angle: float | None = None,
                     shape: UpCurveShape | None = None, base: BasePlacement | None = None, turn: int = 1,
                     min_margin: float = 0.0) -> InitialBackbone:
    """Section 3.3 (1): the base on a plane arc, the neck and head on a plane cubic Bezier joined G1 at P0 in
    the vertical plane through the arc's end tangent, both discretised into joint angles (Eqs. 3-9).

    Parameters
    ----------
    robot : the snake.
    central_angle : the base arc's theta (rad, (0, 2 pi]); default None: :func:`optimize_base_arc`.
    shape : the up curve; default None: ``UpCurveShape.for_robot(robot)`` (on the default robot the head tip
        0.55 m above the body axis, 0.10 m behind P0, pointing 140 deg from the forward horizontal, i.e. leaning
        back over the base), or, when that shape does not fit the robot (joints beyond their limits, or no arc
        keeps the centre of mass inside the support polygon by ``min_margin``), the shape of ``SHAPE_SEARCH``
        with the largest static margin.
    base : placement of the tail, default ``BasePlacement()`` (tail end at the origin, body along +x).
    turn : +1 the base curves left (counter-clockwise seen from above), -1 right.
    min_margin : required static margin (m) when theta is optimised.

    The base uses Eq. 9 (``"arclength"`` chords) so the robot's last base link leaves along the arc's end
    tangent, which is the Bezier's start tangent; the up curve is discretised by the general method
    (Eqs. 3-7) with the phase read from the robot's P0 frame. Raises Infeasible if a joint leaves its limits.
    """
    robot = as_robot(robot)
    base = BasePlacement() if base is None else base
    turn = checked_turn(turn)
    if shape is None:
        try:
            return initial_backbone(robot, central_angle=central_angle, shape=UpCurveShape.for_robot(robot),
                                    base=base, turn=turn, min_margin=min_margin)
        except Infeasible as first_error:
            return _searched_backbone(robot, central_angle, base, turn, min_margin, first_error)
    q_up, _, _, phi0 = up_curve_joint_angles(robot, shape, turn)
    optimum = None
    if central_angle is None:
        optimum = optimize_base_arc(robot, q_up, base, min_margin=min_margin, turn=turn)
        theta = optimum.central_angle
    else:
        theta = checked_central_angle(central_angle)
    q_base = arc_joint_angles(robot.base_length, theta, robot, turn=turn)
    q = np.concatenate([q_base, q_up])
    bad = np.flatnonzero((q < robot.lower - 1e-12) | (q > robot.upper + 1e-12))
    if len(bad):
        raise Infeasible("the backbone needs joints beyond their limits: " + ", ".join(
            f"joint {i + 1} = {math.degrees(q[i]):.1f} deg" for i in bad))
    arc = base_arc(robot, theta, base, turn=turn, anchor="end")
    curve, P = up_curve(arc, shape, up_length(robot))
    return InitialBackbone(q=q, central_angle=theta, arc=arc, up_curve=curve, control_points=P, phi0=phi0,
                           shape=shape, base=base, optimum=optimum)


def _searched_backbone(robot: SnakeRobot, central_angle: float | None, base: BasePlacement | None, turn: int,
                       min_margin: float, first_error: Infeasible) -> InitialBackbone:
    """The backbone of SHAPE_SEARCH's shapes with the largest static margin (see :func:`initial_backbone`)."""
    L = up_length(robot)
    best, best_margin = None, -math.inf
    for h, r, a in SHAPE_SEARCH:
        shape = UpCurveShape(height=h * L, reach=r * L, tip_angle=math.radians(a))
        try:
            bb = initial_backbone(robot, central_angle=central_angle, shape=shape, base=base, turn=turn,
                                  min_margin=min_margin)
        except Infeasible:
            continue
        margin = stability.static_margin(robot, bb.q, base)
        if margin > best_margin:
            best, best_margin = bb, margin
    if best is None:
        raise Infeasible(f"no up-curve shape fits this robot ({first_error}): the neck and head cannot rise over its "
                         "base; 'snakehead info --robot FILE' suggests a split of the parts (base_end, neck_end in the "
                         "robot file) that works")
    return best


def initial_configuration(robot: SnakeRobot, **kwargs: Any) -> np.ndarray:
    """The initial configuration q (n,) of Section 3.3 (1); see :func:`initial_backbone` for the keyword
    arguments (central_angle, shape, base, turn, min_margin) and their defaults."""
    return initial_backbone(robot, **kwargs).q
