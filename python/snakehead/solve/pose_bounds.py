"""Necessary conditions for a whole-body pose that puts the head tip at a position, pointing along a direction:
cheap tests that prove the whole-body solve cannot pass its exact checks
(:func:`~.solution_checks.check_solution`: the head within its position and direction tolerances,
the static margin of the links lying on the ground, the lifted links above the ground), so that a reach map
(``planning.whole_body_reach``) need not run it. Every test allows for the checks' tolerances; none depends on how
the solve searches.

* ground (any base): the links rigidly attached to the head tip are a fixed shape around the tip; with the tip
  at the position and pointing along the direction, for the best roll about the direction, their lowest point is
  still below the ground's tolerance;
* reach: the first frame rigid with the tip (the last joint) lies no farther from the frame the neck lifts from
  than the chain between them; with the base kept that frame is where it is; with any base (lying flat) it is at a
  fixed height, so the height difference alone must be within the chain's length;
* stability (base kept): each lifted link's centre of mass lies within its chain distance of the tip and of the
  frame the neck lifts from; the centre of mass of the whole body then lies in a convex set, and when an axis
  separates that set from the support polygon of the links on the ground shrunk by the margin, the pose cannot
  be stable (the check's margin is at most the margin over those links, :mod:`.base_support`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from ..collision.body_collisions import GROUND_TOLERANCE
from ..model.robot import BasePlacement, SnakeRobot
from . import base_support
from .solution_checks import DIRECTION_TOLERANCE, POSITION_TOLERANCE

__all__ = ["PoseBounds", "ROLL_SAMPLES"]

#: Rolls about the direction at which the ground test evaluates the tip's shapes (its bound covers the gaps).
ROLL_SAMPLES = 72
#: Horizontal axes (besides the support polygon's edge normals) along which the stability test looks for a
#: separation.
SEPARATING_AXES = 48


def _tolerances() -> tuple[float, float]:
    """The solution checks' position (m) and direction (rad) tolerances."""
    return float(POSITION_TOLERANCE), float(DIRECTION_TOLERANCE)


@dataclass(frozen=True)
class PoseBounds:
    """The robot's numbers the tests need, computed once (:meth:`of`): the tip's rigid shape points
    ``tip_points`` (P, 3) and the first frame rigid with the tip ``joint_point`` (3,), both in the tip's frame;
    the chain length from the frame the neck lifts from to that frame ``joint_reach``; the height of the frame the
    neck lifts from with the base flat ``lift_height``; the lifted links with a mass ``lifted`` (k,), their masses
    ``lifted_mass`` (k,) and the chain distances from their centres of mass to the lift frame ``to_lift`` (k,) and
    to the tip ``to_tip`` (k,)."""

    robot: SnakeRobot
    tip_points: np.ndarray
    joint_point: np.ndarray
    joint_reach: float
    lift_height: float
    lifted: np.ndarray
    lifted_mass: np.ndarray
    to_lift: np.ndarray
    to_tip: np.ndarray

    @classmethod
    def of(cls, robot: SnakeRobot, q: np.ndarray) -> PoseBounds:
        """The bounds of ``robot`` (``q``: a configuration of the base lying flat, e.g. the planner's initial one;
        only the lift frame's height is taken from it)."""
        lift, tip = robot.link_index(robot.lift_frame), robot.link_index(robot.parts.head_tip)
        F = robot.frames(q, BasePlacement())
        rigid = _rigid_with(robot, lift, tip)
        first = int(min(rigid))
        to_tip_frame = np.linalg.inv(F[tip])
        links, local = robot.link_points
        pts = [_apply(to_tip_frame @ F[k], local[i]) for i, k in enumerate(links) if int(k) in rigid]
        tip_points = np.concatenate(pts) if pts else np.zeros((1, 3))
        chain = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(F[lift:tip + 1, :3, 3], axis=0), axis=1))])
        heavy = np.array([k for k in range(lift + 1, tip + 1) if robot.masses[k] > 0], int)
        coms = F[heavy, :3, 3] + np.einsum("kij,kj->ki", F[heavy, :3, :3], robot.coms[heavy])
        to_lift = chain[heavy - lift] + np.linalg.norm(robot.coms[heavy], axis=1)
        nxt = np.minimum(heavy + 1, tip)
        to_tip = np.linalg.norm(coms - F[nxt, :3, 3], axis=1) + chain[-1] - chain[nxt - lift]
        return cls(robot, tip_points, _apply(to_tip_frame @ F[first], np.zeros((1, 3)))[0],
                   float(chain[first - lift]), float(F[lift, 2, 3]), heavy, robot.masses[heavy].astype(float),
                   to_lift, to_tip)

    # --- the tests: (N,) bool, True where no pose can pass -------------------------------------------------------
    def below_ground(self, positions: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """Whether the shapes rigid with the tip reach below the ground for every roll about the direction."""
        pos_tol, dir_tol = _tolerances()
        p, d = np.atleast_2d(positions), np.atleast_2d(directions)
        e1, e2 = _perpendiculars(d)
        c = self.tip_points
        phi = 2 * np.pi * np.arange(ROLL_SAMPLES) / ROLL_SAMPLES
        # z of R(phi) c: c_x d_z + cos(phi) (c_y e1_z + c_z e2_z) + sin(phi) (c_y e2_z - c_z e1_z)
        a = c[None, :, 1] * e1[:, None, 2] + c[None, :, 2] * e2[:, None, 2]
        b = c[None, :, 1] * e2[:, None, 2] - c[None, :, 2] * e1[:, None, 2]
        z = (p[:, None, None, 2] + c[None, None, :, 0] * d[:, None, None, 2]
             + np.cos(phi)[None, :, None] * a[:, None, :] + np.sin(phi)[None, :, None] * b[:, None, :])
        best = z.min(axis=2).max(axis=1)  # the best roll's lowest point
        rho = float(np.linalg.norm(c[:, 1:], axis=1).max())
        slack = (rho * np.sqrt(np.clip(1 - d[:, 2] ** 2, 0, 1)) * np.pi / ROLL_SAMPLES
                 + pos_tol + float(np.linalg.norm(c, axis=1).max()) * dir_tol + 1e-9)
        return best + slack < -GROUND_TOLERANCE

    def out_of_reach(self, positions: np.ndarray, directions: np.ndarray, lift_origin: np.ndarray | None = None
                     ) -> np.ndarray:
        """Whether the last joint cannot be where the tip's pose puts it: farther from ``lift_origin`` (3,) (the
        base kept) than the chain's length, or (None: any base lying flat) higher or lower than that from the
        lift frame's height."""
        pos_tol, dir_tol = _tolerances()
        p, d = np.atleast_2d(positions), np.atleast_2d(directions)
        c = self.joint_point
        centre = p + c[0] * d  # the joint is on a circle of radius |c_yz| around it, for the rolls
        slack = float(np.linalg.norm(c[1:])) + pos_tol + float(np.linalg.norm(c)) * dir_tol + 1e-9
        if lift_origin is None:
            gap = np.abs(centre[:, 2] - self.lift_height)
        else:
            gap = np.linalg.norm(centre - np.asarray(lift_origin, float), axis=1)
        return gap - slack > self.joint_reach

    def unstable(self, positions: np.ndarray, q: np.ndarray, base: BasePlacement, min_margin: float) -> np.ndarray:
        """Whether no pose with the base kept (placement ``base``, flat shape of ``q``) that puts the tip at the
        positions can hold the centre of mass inside the ground links' support polygon by ``min_margin``."""
        pos_tol, _ = _tolerances()
        robot = self.robot
        p = np.atleast_2d(positions)
        F = robot.frames(q, base)
        poly, _ = base_support.contact_points(robot, F, base_support.ground_links(robot))
        hull = poly[np.asarray(_core.convex_hull_2d(np.ascontiguousarray(poly[:, :2])))][:, :2]
        if len(hull) < 3:
            return np.ones(len(p), bool)  # (the margin is -inf)
        lift = robot.link_index(robot.lift_frame)
        ground = np.array([k for k in range(lift + 1) if robot.masses[k] > 0], int)
        m_ground = robot.masses[ground]
        c_ground = F[ground, :3, 3] + np.einsum("kij,kj->ki", F[ground, :3, :3], robot.coms[ground])
        total = float(m_ground.sum() + self.lifted_mass.sum())
        o = F[lift, :3, 3]
        u = _axes(hull)  # (A, 2) unit
        top = (hull @ u.T).max(axis=0) - min_margin  # (A,): the shrunk polygon lies below this along each axis
        ground_part = (m_ground[:, None] * (c_ground[:, :2] @ u.T)).sum(axis=0)  # (A,)
        # the least u.c_i: c_i within to_lift of o and within to_tip (+ the tolerance) of the tip
        near_lift = (o[:2] @ u.T)[None, :] - self.to_lift[:, None]  # (k, A)
        near_tip = (p[:, :2] @ u.T)[:, None, :] - (self.to_tip + pos_tol)[None, :, None]  # (N, k, A)
        least = ground_part[None, :] + (self.lifted_mass[None, :, None]
                                        * np.maximum(near_lift[None], near_tip)).sum(axis=1)
        return (least / total > top[None, :] + 1e-9).any(axis=1)


def _apply(T: np.ndarray, pts: np.ndarray) -> np.ndarray:
    return pts @ T[:3, :3].T + T[:3, 3]


def _rigid_with(robot: SnakeRobot, lift: int, tip: int) -> set[int]:
    """The frames between the lift frame and the tip that do not move relative to the tip (random configurations
    agree)."""
    rng = np.random.default_rng(0)
    Fs = [robot.frames(robot.random_configuration(rng), BasePlacement()) for _ in range(3)]
    rel = [np.linalg.inv(F[tip]) @ F for F in Fs]
    return {k for k in range(lift + 1, tip + 1) if all(np.allclose(r[k], rel[0][k], atol=1e-9) for r in rel[1:])}


def _perpendiculars(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors (N, 3) each, perpendicular to each other and to the unit directions d."""
    helper = np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(d, e1)


def _axes(hull: np.ndarray) -> np.ndarray:
    """Unit horizontal axes: the polygon's edge normals and evenly spaced ones."""
    edges = np.roll(hull, -1, axis=0) - hull
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals = normals[np.linalg.norm(normals, axis=1) > 1e-12]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    a = 2 * np.pi * np.arange(SEPARATING_AXES) / SEPARATING_AXES
    return np.vstack([normals, -normals, np.column_stack([np.cos(a), np.sin(a)])])
