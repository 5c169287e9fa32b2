"""An independent statement of the tracking fit's objective (include/snakehead/tracking_fit.hpp,
``cartesian.tracking_interpolation``), for tests/sim/test_tracking_fit.py: what each interior sample's lifted joints
minimise, evaluated without snakehead's kinematics or distances.

At sample j, with the joints before the lift at their linear interpolation and ``current`` the previous sample's
fitted lifted joints, the fit minimises within the joint limits the sum of squares of

* x_i(q) - p_ij for every tracked frame origin (Eq. 41's interpolated points);
* w_g min(0, z_k(q) - c_g) for every lifted link k, z_k its shapes' lowest point;
* w_g min(0, d_p(q) - c_s) for every self pair p of shapes, d_p their signed distance;
* w_c (q_lift - current).

(The core adds a row only where the min is negative; its value and gradient are the same: the hinge is C1.)
Frames: pinocchio's forward kinematics of the robot's URDF placed by its root pose; lowest points: closed forms per
shape kind (a box's lowest corner, a cylinder's lowest rim point, a sphere's bottom, a convex shape's lowest vertex);
signed distances: coal's GJK/EPA (another library than the core's FCL/libccd), or where coal's EPA gives up (it
reports -DBL_MAX) tests/minkowski_reference.py's branch and bound on the Minkowski difference.
"""
from __future__ import annotations

import coal
import minkowski_reference as minkowski
import numpy as np
import pinocchio as pin

BOX_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)


def coal_geometry(shape):
    if shape.kind == "box":
        return coal.Box(*shape.size)
    if shape.kind == "cylinder":
        return coal.Cylinder(shape.size[0], shape.size[1])
    if shape.kind == "sphere":
        return coal.Sphere(shape.size[0])
    points = coal.StdVec_Vec3s()
    for p in np.asarray(shape.vertices, float):
        points.append(p)
    return coal.Convex.convexHull(points, False, None)


def lowest_z(shape, pose: np.ndarray) -> float:
    """The lowest world z of a shape at its world pose, in closed form."""
    R, p = pose[:3, :3], pose[:3, 3]
    if shape.kind == "box":
        return float(p[2] - np.abs(R[2]) @ (np.asarray(shape.size) / 2))
    if shape.kind == "sphere":
        return float(p[2] - shape.size[0])
    if shape.kind == "cylinder":
        r, half = shape.size[0], shape.size[1] / 2  # the axis' z component, and its horizontal part's length
        return float(p[2] - half * abs(R[2, 2]) - r * np.hypot(R[0, 2], R[1, 2]))
    return float((np.asarray(shape.vertices, float) @ R[2] + p[2]).min())


class FitObjective:
    """The objective of one interior sample of the tracking fit (module docstring) for a robot at a base placement:
    ``lift`` the fitted joints, ``points`` the tracked frames (link indices), ``pairs`` the self pairs (shape
    indices), ``settings`` the fit's weights and clearances (``cartesian.TRACKING_*``)."""

    def __init__(self, robot, base, lift, points, pairs, settings: dict) -> None:
        src = robot.urdf
        self.model = pin.buildModelFromXML(src) if src.lstrip().startswith("<") else pin.buildModelFromUrdf(src)
        assert [self.model.names[i] for i in range(1, self.model.njoints)] == list(robot.joint_names)
        self.data = self.model.createData()
        self.ids = {k: self.model.getFrameId(name) for k, name in enumerate(robot.link_names)}
        self.root = robot.root_pose(base)
        self.lift, self.points = np.asarray(lift), np.asarray(points)
        self.lower, self.upper = robot.lower[self.lift], robot.upper[self.lift]
        self.shapes = robot.geometry.shapes
        self.geoms = [coal_geometry(s) for s in self.shapes]
        self.ground = [[i for i, s in enumerate(self.shapes) if s.frame == k] for k in robot.lifted_links]
        self.pairs = np.asarray(pairs).reshape(-1, 2)
        self.s = settings
        self.request = coal.DistanceRequest()
        self.request.gjk_tolerance = self.request.epa_tolerance = 1e-10

    def frames(self, q: np.ndarray) -> dict[int, np.ndarray]:
        pin.framesForwardKinematics(self.model, self.data, q)
        return {k: self.root @ self.data.oMf[i].homogeneous for k, i in self.ids.items()}

    def tracked(self, q: np.ndarray) -> np.ndarray:
        """(m, 3) the tracked frames' origins at q."""
        F = self.frames(q)
        return np.array([F[int(k)][:3, 3] for k in self.points])

    def distances(self, F: dict[int, np.ndarray], pairs: np.ndarray) -> np.ndarray:
        out = np.empty(len(pairs))
        for n, (a, b) in enumerate(pairs):
            A, B = F[self.shapes[a].frame] @ self.shapes[a].origin, F[self.shapes[b].frame] @ self.shapes[b].origin
            out[n] = coal.distance(self.geoms[a], coal.Transform3s(A[:3, :3].copy(), A[:3, 3].copy()), self.geoms[b],
                                   coal.Transform3s(B[:3, :3].copy(), B[:3, 3].copy()), self.request,
                                   coal.DistanceResult())
            if abs(out[n]) > 1.0:  # coal's EPA gave up
                out[n] = minkowski.signed_distance(self._minkowski(a, A), self._minkowski(b, B)).signed
        return out

    def _minkowski(self, i: int, pose: np.ndarray) -> minkowski.Shape:
        s = self.shapes[i]
        return minkowski.Shape(s.kind, np.asarray(s.size, float), pose,
                               None if s.vertices is None else np.asarray(s.vertices, float))

    def residual(self, x: np.ndarray, q: np.ndarray, target: np.ndarray, current: np.ndarray,
                 pairs: np.ndarray | None = None) -> np.ndarray:
        """The stacked residual at lifted joints x (the other joints from q); ``pairs`` a subset of the self pairs
        (default all)."""
        s = self.s
        q = q.copy()
        q[self.lift] = x
        F = self.frames(q)
        pts = np.array([F[int(k)][:3, 3] for k in self.points]) - target
        z = np.array([min(lowest_z(self.shapes[i], F[self.shapes[i].frame] @ self.shapes[i].origin) for i in group)
                      for group in self.ground])
        d = self.distances(F, self.pairs if pairs is None else pairs)
        return np.concatenate([pts.ravel(), s["ground_weight"] * np.minimum(0.0, z - s["clearance"]),
                               s["ground_weight"] * np.minimum(0.0, d - s["self_clearance"]),
                               s["continuity"] * (x - current)])

    def value(self, x, q, target, current, pairs=None) -> float:
        r = self.residual(x, q, target, current, pairs)
        return float(r @ r)

    def near_pairs(self, qs, within: float) -> np.ndarray:
        """The self pairs closer than ``within`` at any of the configurations qs (the others add nothing to the
        objective near them)."""
        if len(self.pairs) == 0:
            return self.pairs
        close = np.zeros(len(self.pairs), bool)
        for q in qs:
            close |= self.distances(self.frames(q), self.pairs) < within
        return self.pairs[close]
