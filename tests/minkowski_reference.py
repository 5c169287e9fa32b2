"""An independent reference for the signed distance of two convex shapes (box, cylinder, sphere, convex hull of
points): from their support functions alone, with no GJK, no EPA and no collision library.

For convex A and B, the gap of their projections on a unit direction d is -(h_A(d) + h_B(-d)), with h_X(d) the
support function max over x in X of d.x, and the signed distance is the largest gap over all directions:

    sd(A, B) = -min over |d| = 1 of h_M(d),   M = A - B (the Minkowski difference), h_M(d) = h_A(d) + h_B(-d).

Apart this is the separating-axis theorem; in penetration it is minus the distance from the origin to the surface
of M, i.e. the penetration depth, the shortest translation that separates the shapes (moving B by min h_M along
the minimising d).

The minimum over the sphere of directions is found by a certified branch and bound: a dense grid of directions
(a cube's six faces, each cut into cells, projected onto the sphere), refined where it may hold the minimum. A
cell with centre c, support point m = s_M(c) and angular radius rho holds no direction e with h_M(e) below

    max(h_M(c) - R * 2 sin(rho / 2),  |m| cos(angle(m, c) + rho))

(the first since h_M is R-Lipschitz on the sphere, R bounding |x| over M; the second since h_M(e) >= m.e for
any m in M); cells whose bound is above the best value found are dropped, the others cut in four. The result is
an interval [lower, upper] that holds the true minimum, upper being h_M of a direction actually found."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Shape:
    """A convex shape at a world pose (4x4): kind "box" (size: full extents), "cylinder" (size: radius, length;
    axis along the pose's z), "sphere" (size: radius) or "convex" (vertices (V, 3) in the shape's frame)."""

    kind: str
    size: np.ndarray
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    vertices: np.ndarray | None = None


def support(shape: Shape, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(h, points): the support function h(d) (n,) and a point of the shape attaining it (n, 3), for world unit
    directions d (n, 3)."""
    R, t = shape.pose[:3, :3], shape.pose[:3, 3]
    local = d @ R  # each direction in the shape's frame
    if shape.kind == "box":
        p = np.where(local >= 0, 1.0, -1.0) * (np.asarray(shape.size) / 2)
    elif shape.kind == "cylinder":
        r, half = shape.size[0], shape.size[1] / 2
        radial = np.hypot(local[:, 0], local[:, 1])
        scale = np.divide(r, radial, out=np.zeros_like(radial), where=radial > 0)  # the cap's centre on the axis
        p = np.stack([local[:, 0] * scale, local[:, 1] * scale, np.where(local[:, 2] >= 0, half, -half)], axis=1)
    elif shape.kind == "sphere":
        p = shape.size[0] * local
    elif shape.kind == "convex":
        v = np.asarray(shape.vertices, float)
        p = v[np.argmax(local @ v.T, axis=1)]
    else:
        raise ValueError(f"unknown kind {shape.kind!r}")
    points = p @ R.T + t
    return np.einsum("ij,ij->i", points, d), points


def radius(shape: Shape) -> float:
    """An upper bound of |x| over the shape, in the world."""
    t = np.linalg.norm(shape.pose[:3, 3])
    if shape.kind == "box":
        return float(t + np.linalg.norm(shape.size) / 2)
    if shape.kind == "cylinder":
        return float(t + np.hypot(shape.size[0], shape.size[1] / 2))
    if shape.kind == "sphere":
        return float(t + shape.size[0])
    return float(t + np.linalg.norm(np.asarray(shape.vertices), axis=1).max())


# The cube's six faces: (normal, u axis, v axis); a cell of face f at (u, v) in [-1, 1]^2 is the direction
# normal + u * u_axis + v * v_axis, normalised (a gnomonic projection: a cell's sides are great-circle arcs).
_FACES = [(np.eye(3)[a] * s, np.eye(3)[(a + 1) % 3], np.eye(3)[(a + 2) % 3]) for a in range(3) for s in (1.0, -1.0)]


def _directions(face: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    normal = np.array([f[0] for f in _FACES])[face]
    ua = np.array([f[1] for f in _FACES])[face]
    va = np.array([f[2] for f in _FACES])[face]
    d = normal + u[:, None] * ua + v[:, None] * va
    return d / np.linalg.norm(d, axis=1, keepdims=True)


@dataclass
class Depth:
    """The signed distance's certified bounds (lower <= sd <= upper) and the direction d found minimising
    h_A(d) + h_B(-d): the gap of the shapes' projections on d is `lower`, which is also `signed`."""

    lower: float
    upper: float
    direction: np.ndarray
    cells: int  # cells evaluated (the search's cost)

    @property
    def signed(self) -> float:
        return self.lower


def signed_distance(a: Shape, b: Shape, tolerance: float = 1e-7, start: int = 24, max_cells: int = 4_000_000) -> Depth:
    """The signed distance of a and b (> 0 apart, < 0 minus the penetration depth) within `tolerance` (m), by the
    branch and bound described above, starting from start x start cells per cube face."""
    R = radius(a) + radius(b)

    def h(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ha, pa = support(a, d)
        hb, pb = support(b, -d)
        return ha + hb, pa - pb

    g = (np.arange(start) + 0.5) / start * 2 - 1
    uu, vv = np.meshgrid(g, g, indexing="ij")
    face = np.repeat(np.arange(6), start * start)
    u, v = np.tile(uu.ravel(), 6), np.tile(vv.ravel(), 6)
    half = np.full(len(u), 1.0 / start)  # half side of each cell in (u, v)
    best, best_d, evaluated = np.inf, np.zeros(3), 0
    while len(u):
        d = _directions(face, u, v)
        value, m = h(d)
        evaluated += len(u)
        k = int(np.argmin(value))
        if value[k] < best:
            best, best_d = float(value[k]), d[k]
        # the cell's angular radius: its farthest corner (the cell is convex on the sphere)
        rho = np.zeros(len(u))
        for su, sv in ((-1, -1), (-1, 1), (1, -1), (1, 1)):
            corner = _directions(face, u + su * half, v + sv * half)
            rho = np.maximum(rho, np.arccos(np.clip(np.einsum("ij,ij->i", corner, d), -1.0, 1.0)))
        norm_m = np.linalg.norm(m, axis=1)
        angle = np.arccos(np.clip(value / np.maximum(norm_m, 1e-300), -1.0, 1.0))
        bound = np.maximum(value - R * 2 * np.sin(rho / 2), norm_m * np.cos(np.minimum(np.pi, angle + rho)))
        keep = bound < best - tolerance
        if 4 * np.count_nonzero(keep) + evaluated > max_cells:
            lowest = min(float(bound[keep].min()), best - tolerance)  # not refined to the tolerance: wider
            return Depth(-best, -lowest, best_d, evaluated)
        face, u, v, half = face[keep], u[keep], v[keep], half[keep] / 2
        face = np.repeat(face, 4)
        u = np.repeat(u, 4) + np.tile([-1, -1, 1, 1], len(half)) * np.repeat(half, 4)
        v = np.repeat(v, 4) + np.tile([-1, 1, -1, 1], len(half)) * np.repeat(half, 4)
        half = np.repeat(half, 4)
    # every direction holds h_M >= best - tolerance: sd in [-best, -best + tolerance]
    return Depth(-best, -best + tolerance, best_d, evaluated)
