"""An independent reference for the ZMP check (``_core.zmp_check``, reached through ``dynamics.stability``), for
tests/collision/test_path_check.py: nothing here calls snakehead's kinematics, momenta, lowest points or hulls.

* world link frames: pinocchio's forward kinematics of the robot's URDF, placed by the robot's root pose;
* momenta: pinocchio's centroidal momentum (Eqs. 25-31 summed by another library), moved to the world origin;
* ZMP: Eqs. 39-40 (p_z = 0) with the momentum rates from ``np.gradient`` along the samples (what
  ``stability.zmp`` documents), or from pinocchio's exact centroidal momentum rate when joint accelerations are given;
* contact points: each shape's documented ground candidates (include/snakehead/shape_set.hpp, ``lowest_points``: a
  box's corners, a sphere's lowest point, a cylinder's exact lowest point on each rim and 8 evenly spaced points on
  each rim, a convex shape's vertices), the ``per_shape`` lowest of them, those at most ``tolerance`` above the ground,
  in numpy from the shapes' sizes and poses;
* support polygon: ``scipy.spatial.ConvexHull`` of those points' (x, y), once per sample (no runs, no kept hulls);
* margin: the plain distance from the ZMP to the polygon's edges as segments, positive inside (inside from the hull's
  facet equations); a segment (collinear contacts) or a point has no inside: minus the distance to it.
"""
from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.spatial import ConvexHull, QhullError

from snakehead.model.physics import GRAVITY

BOX_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
RIM_SAMPLES = 8


class PinRobot:
    """pinocchio's model of a snakehead robot's URDF, its frames in the robot's link order, and the root's world pose
    at a placement."""

    def __init__(self, robot, base) -> None:
        src = robot.urdf
        self.model = pin.buildModelFromXML(src) if src.lstrip().startswith("<") else pin.buildModelFromUrdf(src)
        assert [self.model.names[i] for i in range(1, self.model.njoints)] == list(robot.joint_names)
        self.data = self.model.createData()
        self.frame_ids = [self.model.getFrameId(name) for name in robot.link_names]
        self.root = robot.root_pose(base)
        root = self.model.inertias[0]  # the fixed root link (on the universe): left out of pinocchio's CoM and momenta
        self.root_mass, self.root_com = root.mass, np.array(root.lever)

    def frames(self, q: np.ndarray) -> np.ndarray:
        """World poses (n_links, 4, 4) of the robot's links at q."""
        pin.framesForwardKinematics(self.model, self.data, q)
        return np.array([self.root @ self.data.oMf[i].homogeneous for i in self.frame_ids])

    def total_mass(self) -> float:
        pin.centerOfMass(self.model, self.data, pin.neutral(self.model))
        return float(self.data.mass[0] + self.root_mass)

    def momenta(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World P, L about the world origin, and the whole robot's CoM."""
        h = pin.computeCentroidalMomentum(self.model, self.data, q, qd)  # about the moving bodies' CoM, root axes
        c = self.data.com[0]
        moving = self.data.mass[0]
        com = (moving * c + self.root_mass * self.root_com) / (moving + self.root_mass)
        R, p = self.root[:3, :3], self.root[:3, 3]
        P = R @ h.linear
        L = R @ (h.angular + np.cross(c, h.linear)) + np.cross(p, P)
        return P, L, R @ com + p

    def momentum_rates(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World dP/dt and dL/dt (about the world origin) from pinocchio's exact centroidal momentum rate."""
        dh = pin.computeCentroidalMomentumTimeVariation(self.model, self.data, q, qd, qdd)
        c = self.data.com[0]
        R, p = self.root[:3, :3], self.root[:3, 3]
        Pdot = R @ dh.linear
        # d/dt (L_G + c x P) = dL_G + cdot x P + c x Pdot, and cdot x P = 0 (P = M cdot)
        return Pdot, R @ (dh.angular + np.cross(c, dh.linear)) + np.cross(p, Pdot)


def zmp_from_rates(com: np.ndarray, Pdot: np.ndarray, Ldot: np.ndarray, mass: float) -> np.ndarray:
    """Eqs. 39-40 with p_z = 0: (T, 2); NaN where M g + dP_z/dt <= 0 (no ZMP)."""
    den = mass * GRAVITY + Pdot[:, 2]
    den = np.where(den > 0.0, den, np.nan)
    return np.stack([(mass * GRAVITY * com[:, 0] - Ldot[:, 1]) / den,
                     (mass * GRAVITY * com[:, 1] + Ldot[:, 0]) / den], axis=1)


def shape_candidates(shape, pose: np.ndarray) -> np.ndarray:
    """The shape's ground-contact candidates (k, 3) in the world; pose: the shape's own world pose."""
    R, p = pose[:3, :3], pose[:3, 3]
    if shape.kind == "box":
        local = BOX_SIGNS * np.asarray(shape.size) / 2
    elif shape.kind == "sphere":
        return (p - [0.0, 0.0, shape.size[0]])[None]
    elif shape.kind == "cylinder":
        r, half = shape.size[0], shape.size[1] / 2
        a = 2 * np.pi * np.arange(RIM_SAMPLES) / RIM_SAMPLES
        ring = np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(a)], axis=1)
        local = np.concatenate([ring + [0.0, 0.0, -half], ring + [0.0, 0.0, half]])
        down = R.T @ [0.0, 0.0, -1.0]  # the world's down in the shape's frame
        radial = np.array([down[0], down[1], 0.0])
        if np.linalg.norm(radial) > 1e-12:  # (an upright cylinder: every rim point is as low)
            radial *= r / np.linalg.norm(radial)
            local = np.concatenate([local, [radial + [0.0, 0.0, -half], radial + [0.0, 0.0, half]]])
    else:
        local = np.asarray(shape.vertices, float)
    return local @ R.T + p


def contact_points(robot, frames: np.ndarray, links, per_shape: int, tolerance: float) -> np.ndarray:
    """(k, 2) world (x, y) of the touching candidates of the shapes on ``links``: each shape's ``per_shape`` lowest
    candidates, those at most ``tolerance`` high."""
    links = set(int(k) for k in links)
    out = []
    for s in robot.geometry.shapes:
        if s.frame in links:
            c = shape_candidates(s, frames[s.frame] @ s.origin)
            c = c[np.argsort(c[:, 2], kind="stable")[:per_shape]]
            out.append(c[c[:, 2] <= tolerance, :2])
    return np.concatenate(out) if out else np.zeros((0, 2))


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    s = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + s * ab)))


def polygon_margin(points: np.ndarray, p: np.ndarray) -> float:
    """Signed distance of p to the convex hull of points (k, 2), > 0 inside; -inf without points."""
    if len(points) == 0 or not np.all(np.isfinite(p)):
        return -np.inf
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError):  # a point or collinear points: the segment between the extremes
        axis = points[np.argmax(np.linalg.norm(points - points[0], axis=1))] - points[0]
        s = points @ axis
        return -segment_distance(p, points[np.argmin(s)], points[np.argmax(s)])
    ring = points[hull.vertices]
    d = min(segment_distance(p, ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring)))
    inside = bool(np.all(hull.equations[:, :2] @ p + hull.equations[:, 2] <= 0.0))
    return d if inside else -d


def zmp_check(robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, base, links, per_shape: int, tolerance: float,
              qdd: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The ZMP check of a sampled motion: P, L, com (T, 3), zmp (T, 2), margin (T,) and, with ``qdd``, zmp_exact
    (T, 2) from the exact momentum rates."""
    ref = PinRobot(robot, base)
    mass = ref.total_mass()
    T = len(t)
    P, L, com = np.empty((T, 3)), np.empty((T, 3)), np.empty((T, 3))
    for k in range(T):
        P[k], L[k], com[k] = ref.momenta(q[k], qd[k])
    zmp = zmp_from_rates(com, np.gradient(P, t, axis=0, edge_order=2), np.gradient(L, t, axis=0, edge_order=2), mass)
    margin = np.array([polygon_margin(contact_points(robot, ref.frames(q[k]), links, per_shape, tolerance), zmp[k])
                       for k in range(T)])
    out = {"P": P, "L": L, "com": com, "zmp": zmp, "margin": margin}
    if qdd is not None:
        rates = [ref.momentum_rates(q[k], qd[k], qdd[k]) for k in range(T)]
        out["zmp_exact"] = zmp_from_rates(com, np.array([r[0] for r in rates]), np.array([r[1] for r in rates]), mass)
    return out
