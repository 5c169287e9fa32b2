"""The neck part (paper, Section 2.4 and Section 3.3 (3)): where the head's base must go, and the neck joints.

Given P0 (end of the base part), the desired head position P_hd and the head's dexterous centre G0 (in the
head's base frame, from the reachability map), the neck end frame B0 should sit on the line from P0 to the
target, L_c = |G0| short of it, pointing along that line (Eqs. 18-20); the neck joints minimise Eq. 22.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError, InputTypeError
from .._validate import finite_array, finite_float, pose, positive, vector3
from ..model.chain import Chain
from ..model.robot import BasePlacement
from .head import angle_between_deg

__all__ = ["CONTINUITY_TOLERANCE", "DEFAULT_H", "FIT_ITERATIONS", "FIT_TOLERANCE", "GRID_FRACTION", "GRID_POINTS",
           "NeckGoal", "NeckSolution", "RangeCheck", "accepted_range", "base_move_into_range", "dexterous_distance",
           "neck_goal", "solve_neck"]

#: Eq. 22's weight of the direction term (the paper: "h can be set 0.01").
DEFAULT_H = 0.01
#: How much lower (m^2) Eq. 22's cost from another start must be to leave the minimum reached from q_init.
CONTINUITY_TOLERANCE = 1e-4
#: The coarse grid that gives Eq. 22's second start (it is not convex): this many values per neck joint, evenly over
#: this fraction of its limits.
GRID_POINTS = 5
GRID_FRACTION = 0.9
#: Levenberg-Marquardt steps per start, at most; a step lowering the cost by less than this fraction of it ends the
#: start (the neck needs no more than ~1e-9 rad: the head's IK absorbs what the neck leaves).
FIT_ITERATIONS = 60
FIT_TOLERANCE = 1e-9


@dataclass(frozen=True)
class NeckGoal:
    """Eqs. 18-20 in the world frame: the desired origin P_d and x-axis r_d of the neck end frame B0."""

    P0: np.ndarray  # (3,) end of the base part (m)
    G0: np.ndarray  # (3,) where the dexterous centre should be: the desired head position (m)
    Lc: float  # Eq. 18: |B0 - G0| (m), the dexterous centre's distance from the head's base
    r_d: np.ndarray  # Eq. 19: unit direction from P0 to G0
    P_d: np.ndarray  # Eq. 20: G0 - Lc r_d


def neck_goal(P0: npt.ArrayLike, G0: npt.ArrayLike, Lc: float) -> NeckGoal:
    """Eqs. 19-20: r_d = (G0 - P0) / |G0 - P0|, P_d = G0 - Lc r_d. P0, G0 (3,) world, Lc (m)."""
    P0, G0 = vector3(P0, "P0"), vector3(G0, "G0")
    Lc = positive(Lc, "Lc")
    d = G0 - P0
    dist = float(np.linalg.norm(d))
    if dist < 1e-12:
        raise InputError("G0 coincides with P0: the neck direction is undefined")
    r_d = d / dist
    return NeckGoal(P0=P0, G0=G0, Lc=Lc, r_d=r_d, P_d=G0 - Lc * r_d)


def dexterous_distance(G0_local: npt.ArrayLike) -> float:
    """Eq. 18: L_c = |B0 - G0| with G0 given in the head's base frame B0 (3,) (m)."""
    return float(np.linalg.norm(vector3(G0_local, "G0 (head base frame)")))


@dataclass(frozen=True)
class RangeCheck:
    """Section 3.3 (3): is the target's distance from P0 one the neck can span?"""

    accepted: bool
    span: float  # |P_hd - P0| - L_c: how far the neck must carry B0 from P0 (m)
    neck_length: float  # sum of the neck links (m)
    slack: float  # the largest accepted neck_length - span (the paper's L_0) (m)
    reason: str


def accepted_range(P_hd: npt.ArrayLike, P0: npt.ArrayLike, Lc: float, neck_length: float, slack: float) -> RangeCheck:
    """Section 3.3 (3): accepted iff  0 < sum(L_i) - (|P_hd - P0| - L_c) < L_0.

    The paper's condition lost its operators in print; we read it as: the neck (links summing to
    ``neck_length``) can reach a point ``|P_hd - P0| - L_c`` away from P0 (second inequality), and is not
    so much longer that it must fold back on itself (first inequality, ``slack`` = L_0).
    """
    P_hd, P0 = vector3(P_hd, "P_hd"), vector3(P0, "P0")
    Lc, neck_length, slack = positive(Lc, "Lc"), positive(neck_length, "neck_length"), positive(slack, "slack")
    span = float(np.linalg.norm(P_hd - P0)) - Lc
    if neck_length <= span:
        reason = f"target too far: the neck must span {span:.4f} m but is {neck_length:.4f} m long"
        ok = False
    elif neck_length - span >= slack:
        reason = (f"target too close: the neck ({neck_length:.4f} m) would have {neck_length - span:.4f} m slack "
                  f"(> {slack:.4f} m)")
        ok = False
    else:
        reason = "in range"
        ok = True
    return RangeCheck(ok, span, neck_length, slack, reason)


@dataclass(frozen=True)
class NeckSolution:
    """Eq. 22's minimum: the neck joints and the neck end frame B0 they reach."""

    q: np.ndarray  # (n_neck,) joint angles (rad)
    frame: np.ndarray  # (4, 4) world pose of the neck end B0 reached
    cost: float  # Eq. 22's E_n at q
    position_error_m: float  # |P_a - P_d|
    direction_error_deg: float  # angle between r_a and r_d (deg)


def solve_neck(neck: Chain, P0_frame: npt.ArrayLike, goal: NeckGoal, h: float = DEFAULT_H,
               q_init: npt.ArrayLike | None = None) -> NeckSolution:
    """Eq. 22: argmin |P_a - P_d|^2 + h |r_d x r_a|^2 over the neck joints within their limits.

    ``neck`` is the chain from the base's end frame (P0) to the neck end frame (B0); ``P0_frame`` (4, 4) is
    the world pose of P0. Eq. 22 is a sum of squares of six residuals, so it is solved by a bounded
    Levenberg-Marquardt with the analytic Jacobian in the C++ core (``_core.fit_neck``, neck_fit.hpp), started from
    ``q_init`` and from the best point of a coarse grid (GRID_POINTS per joint; Eq. 22 is not convex); the minimum
    reached from ``q_init`` is kept unless the grid's is lower by more than ``CONTINUITY_TOLERANCE``.
    """
    if not isinstance(neck, Chain):
        raise InputTypeError(f"neck must be a snakehead Chain, got {type(neck).__name__}")
    if not isinstance(goal, NeckGoal):
        raise InputTypeError(f"goal must be a NeckGoal (neck_goal()), got {type(goal).__name__}")
    P0_frame = pose(P0_frame, "P0_frame")  # a rigid frame: a scaled or sheared one would distort Eq. 22
    h = positive(h, "h")
    if neck.n_joints == 0:  # nothing to move: the neck end is where the chain puts it
        T = P0_frame @ neck.fk(np.zeros(0))
        ra = T[:3, 0]
        cost = float(np.sum((T[:3, 3] - goal.P_d) ** 2) + h * np.sum(np.cross(goal.r_d, ra) ** 2))
        return NeckSolution(q=np.zeros(0), frame=T, cost=cost,
                            position_error_m=float(np.linalg.norm(T[:3, 3] - goal.P_d)),
                            direction_error_deg=angle_between_deg(ra, goal.r_d))
    q_init = None if q_init is None else finite_array(q_init, "q_init", (neck.n_joints,))
    best_q, best_cost = _core.fit_neck(neck.model, P0_frame, goal.P_d, goal.r_d, q_init, h=h,
                                       grid_points=GRID_POINTS, grid_fraction=GRID_FRACTION,
                                       iterations=FIT_ITERATIONS, tolerance=FIT_TOLERANCE,
                                       continuity_tolerance=CONTINUITY_TOLERANCE)
    T = P0_frame @ neck.fk(best_q)
    return NeckSolution(q=best_q, frame=T, cost=float(best_cost),
                        position_error_m=float(np.linalg.norm(T[:3, 3] - goal.P_d)),
                        direction_error_deg=angle_between_deg(T[:3, 0], goal.r_d))


def base_move_into_range(P_hd: npt.ArrayLike, P0_local: npt.ArrayLike, base: BasePlacement, Lc: float, length: float,
                         slack: float, height: float) -> BasePlacement | None:
    """The planar move of the base (as the rolling gait or turning in place would give) that brings P_hd in range.

    ``P0_local`` (4, 4) is P0's pose relative to the body frame (fixed while the base keeps its shape);
    ``height`` the body frame's height above the ground (``SnakeRobot.body_axis_height``). The base turns so that
    P0's body axis points horizontally at the target, then slides along it so that the neck must span the middle of
    the accepted band. Returns None when no placement can do it
    (the target is too high for the neck and head to reach from the ground).
    """
    P_hd = vector3(P_hd, "P_hd")
    P0_local = pose(P0_local, "P0_local")
    if not isinstance(base, BasePlacement):
        raise InputTypeError(f"base must be a BasePlacement, got {type(base).__name__}")
    Lc, length, slack = positive(Lc, "Lc"), positive(length, "length"), positive(slack, "slack")
    height = finite_float(height, "height")
    want = Lc + length - 0.5 * slack  # |P_hd - P0| in the middle of the accepted band
    dz = P_hd[2] - (base.matrix(height) @ P0_local)[2, 3]
    if want <= abs(dz):
        return None
    horizontal = np.sqrt(want**2 - dz**2)
    # Turn: P0's x-axis heading (in the base frame) plus the new yaw must point at the target.
    axis_heading = np.arctan2(P0_local[1, 0], P0_local[0, 0])
    P0_world = base.matrix(height) @ P0_local
    to_target = P_hd[:2] - P0_world[:2, 3]
    yaw = float(np.arctan2(to_target[1], to_target[0]) - axis_heading)
    u = np.array([np.cos(yaw + axis_heading), np.sin(yaw + axis_heading)])
    P0_xy = P_hd[:2] - horizontal * u
    c, s = np.cos(yaw), np.sin(yaw)
    offset = np.array([[c, -s], [s, c]]) @ P0_local[:2, 3]
    x, y = P0_xy - offset
    return base.moved(float(x), float(y), float(np.arctan2(np.sin(yaw), np.cos(yaw))))
