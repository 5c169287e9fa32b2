"""The obstacles of a scene, one model for planning (:mod:`snakehead.collision.body_collisions`) and simulation
(:mod:`snakehead.sim`): boxes, a wall with a round hole and meshes (their convex hulls). Scene files
(:mod:`snakehead.scenes`) describe them. Each obstacle gives its convex ``shapes()`` in the world (the wall as
convex pieces around a polygon inscribed in its hole, so that collisions with it err on the safe side).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np
import numpy.typing as npt
from scipy.spatial import ConvexHull

from .._errors import InputError
from .._validate import finite_array, finite_float, positive, rotation_matrix, unit_vector3, vector3
from .meshes import convex_hull_vertices
from .shapes import Shape

__all__ = ["WALL_HOLE_SIDES", "BoxObstacle", "WallWithHole", "MeshObstacle", "OBSTACLE_TYPES"]

#: Sides of the polygon inscribed in a wall's hole: the pieces of the wall's solid meet the hole's circle at the
#: polygon's vertices and stand into it by at most r (1 - cos(pi / 32)) = 0.5 % of its radius.
WALL_HOLE_SIDES = 32


def _pose(rotation: np.ndarray, centre: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = rotation, centre
    return T


@dataclass(frozen=True)
class BoxObstacle:
    """A box: centre (3,) m world, size (3,) full extents m, rotation (3, 3) its axes in the world."""

    centre: np.ndarray
    size: np.ndarray
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", vector3(self.centre, "box centre"))
        size = vector3(self.size, "box size")
        if np.any(size <= 0):
            raise InputError(f"box size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "rotation", rotation_matrix(self.rotation, "box rotation"))

    def shapes(self) -> list[Shape]:
        """The box as a world shape (frame 0: the world)."""
        return [Shape("box", 0, _pose(self.rotation, self.centre), self.size)]

    @classmethod
    def from_yaw(cls, centre: npt.ArrayLike, size: npt.ArrayLike, yaw: float = 0.0) -> "BoxObstacle":
        """A box standing upright, turned by ``yaw`` rad about the world z-axis."""
        yaw = finite_float(yaw, "box yaw")
        c, s = np.cos(yaw), np.sin(yaw)
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return cls(np.asarray(centre, float), np.asarray(size, float), R)


@dataclass(frozen=True)
class WallWithHole:
    """A wall (a thin box) with a round hole through it.

    centre (3,) m: the hole's centre, in the middle of the wall's thickness; normal (3,): the hole's axis
    (the wall's thickness direction); size (w, h, thickness) m: w along the horizontal direction in the wall
    (normal x world z; world x if the normal is vertical), h along the third axis; hole_diameter m;
    hole_offset (2,) m: where the wall's centre is relative to the hole along (w, h) (default: the hole is at
    the wall's centre). The hole must lie inside the wall.
    """

    centre: np.ndarray
    normal: np.ndarray
    size: np.ndarray
    hole_diameter: float
    hole_offset: np.ndarray = field(default_factory=lambda: np.zeros(2))

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", vector3(self.centre, "wall centre"))
        object.__setattr__(self, "normal", unit_vector3(self.normal, "wall normal"))
        size = vector3(self.size, "wall size (w, h, thickness)")
        if np.any(size <= 0):
            raise InputError(f"wall size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "hole_diameter", positive(self.hole_diameter, "hole_diameter"))
        off = finite_array(self.hole_offset, "hole_offset", (2,))
        object.__setattr__(self, "hole_offset", off)
        r = self.hole_diameter / 2
        if np.any(np.abs(off) + r >= size[:2] / 2):
            raise InputError("the hole does not lie inside the wall")

    @classmethod
    def standing(cls, hole_centre: npt.ArrayLike, normal: npt.ArrayLike, size: npt.ArrayLike, hole_diameter: float
                 ) -> "WallWithHole":
        """A wall standing on the ground (its bottom at z = 0) with the hole on its vertical centre line, facing
        along the horizontal ``normal``: the paper's wall of Section 4.2 as snakehead places it."""
        normal = unit_vector3(normal, "wall normal")
        if abs(normal[2]) > 1e-9:
            raise InputError(f"a standing wall's normal must be horizontal, got {normal.tolist()}")
        hole_centre = vector3(hole_centre, "hole centre")
        size = vector3(size, "wall size (w, h, thickness)")
        if hole_centre[2] <= 0 or hole_centre[2] >= size[1]:
            raise InputError(f"the hole's centre ({hole_centre[2]} m high) must lie within the wall's height "
                             f"(0, {size[1]}) m")
        facing = cls(centre=hole_centre, normal=normal, size=size, hole_diameter=hole_diameter)
        wall_centre = np.array([hole_centre[0], hole_centre[1], size[1] / 2])
        # hole_offset is the wall centre's position relative to the hole along the wall's own (width, height)
        # axes (the height axis may point down)
        offset = (wall_centre - hole_centre) @ facing.rotation[:, :2]
        return cls(centre=hole_centre, normal=normal, size=size, hole_diameter=hole_diameter, hole_offset=offset)

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) columns: the width axis, the height axis, the normal (world)."""
        nrm = self.normal
        u = np.cross(nrm, [0.0, 0.0, 1.0])
        if np.linalg.norm(u) < 1e-9:
            u = np.array([1.0, 0.0, 0.0]) - nrm[0] * nrm
        u /= np.linalg.norm(u)
        return np.column_stack([u, np.cross(nrm, u), nrm])

    def slab(self) -> BoxObstacle:
        """The wall without its hole, as a box."""
        R = self.rotation
        return BoxObstacle(self.centre + R[:, :2] @ self.hole_offset, self.size, R)

    def shapes(self) -> list[Shape]:
        """The wall's solid as convex world shapes: one prism per side of a polygon of :data:`WALL_HOLE_SIDES`
        sides inscribed in the hole, reaching out to the wall's rectangle along the rays through the polygon's
        vertices (each piece the region of one angular sector, convex since the sector is under 180 degrees)."""
        half = self.size / 2
        r = self.hole_diameter / 2
        angles = 2 * np.pi * np.arange(WALL_HOLE_SIDES + 1) / WALL_HOLE_SIDES
        lo, hi = self.hole_offset - half[:2], self.hole_offset + half[:2]  # the rectangle, hole coordinates
        corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
        corner_angles = np.mod(np.arctan2(corners[:, 1], corners[:, 0]), 2 * np.pi)
        out = []
        for a, b in zip(angles[:-1], angles[1:]):
            ring = [r * np.array([np.cos(a), np.sin(a)]), r * np.array([np.cos(b), np.sin(b)]),
                    _ray_to_rectangle(b, lo, hi)]
            inside = (corner_angles > a) & (corner_angles < b)
            ring += [c for _, c in sorted(zip(corner_angles[inside], corners[inside]), key=lambda t: -t[0])]
            ring.append(_ray_to_rectangle(a, lo, hi))
            flat = np.array(ring)
            v = np.concatenate([np.c_[flat, np.full(len(flat), -half[2])], np.c_[flat, np.full(len(flat), half[2])]])
            out.append(Shape("convex", 0, _pose(self.rotation, self.centre), np.ones(3), vertices=v))
        return out

    def distance_to_points(self, x: np.ndarray) -> np.ndarray:
        """Exact distance (m) of world points x (..., 3) to the wall's solid (0 inside it).

        The solid is (rectangle minus disc) x [-thickness/2, thickness/2], a prism, so the squared distance is
        the in-plane distance to the rectangle-minus-disc squared plus the distance along the normal squared.
        """
        R = self.rotation
        loc = (np.asarray(x, float) - self.centre) @ R  # (..., 3) hole coordinates
        uv, w = loc[..., :2], loc[..., 2]
        half = self.size / 2
        dw = np.maximum(np.abs(w) - half[2], 0.0)
        rel = uv - self.hole_offset  # coordinates from the wall's centre
        outside_rect = np.linalg.norm(np.maximum(np.abs(rel) - half[:2], 0.0), axis=-1)
        rho = np.linalg.norm(uv, axis=-1)
        in_hole = np.maximum(self.hole_diameter / 2 - rho, 0.0)
        d_plane = np.where(outside_rect > 0, outside_rect, in_hole)
        return np.hypot(d_plane, dw)


def _ray_to_rectangle(angle: float, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Where the ray from the origin at ``angle`` leaves the rectangle [lo, hi] (which holds the origin)."""
    d = np.array([np.cos(angle), np.sin(angle)])
    t = np.inf
    for k in range(2):
        if d[k] > 1e-12:
            t = min(t, hi[k] / d[k])
        elif d[k] < -1e-12:
            t = min(t, lo[k] / d[k])
    return t * d


@dataclass(frozen=True, eq=False)
class MeshObstacle:
    """A mesh file's convex hull (STL, OBJ, DAE... through trimesh), scaled by ``scale`` and placed at ``pose``
    (4, 4) in the world. ``vertices`` (V, 3): the hull's vertices in the mesh's frame, scaled (loaded once)."""

    path: Path
    pose: np.ndarray
    scale: np.ndarray
    vertices: np.ndarray

    @classmethod
    def load(cls, path: str | os.PathLike, position: npt.ArrayLike, yaw: float = 0.0,
             scale: npt.ArrayLike = (1.0, 1.0, 1.0), where: str = "mesh obstacle") -> "MeshObstacle":
        """A mesh obstacle from a file, standing at ``position`` (m), turned by ``yaw`` rad about the world z."""
        scale_v = vector3(scale, "mesh scale")
        if np.any(scale_v <= 0):
            raise InputError(f"{where}: mesh scale must be positive, got {scale_v.tolist()}")
        yaw = finite_float(yaw, "mesh yaw")
        c, s = np.cos(yaw), np.sin(yaw)
        pose = _pose(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), vector3(position, "mesh position"))
        vertices = convex_hull_vertices(Path(path), scale_v, where)
        return cls(Path(path), pose, scale_v, vertices)

    def shapes(self) -> list[Shape]:
        """The mesh's convex hull as a world shape."""
        return [Shape("convex", 0, self.pose, np.ones(3), vertices=self.vertices, source=os.fspath(self.path))]

    @property
    def world_vertices(self) -> np.ndarray:
        """(V, 3) the hull's vertices in the world."""
        return self.vertices @ self.pose[:3, :3].T + self.pose[:3, 3]

    @cached_property
    def _planes(self) -> np.ndarray:
        return np.asarray(ConvexHull(self.world_vertices).equations)  # (F, 4): n . x + d, n outward

    def distance_to_points(self, x: np.ndarray) -> np.ndarray:
        """Signed distance (m) of world points x (..., 3) to the hull by its face planes: exact inside (< 0) and
        where a face is closest; elsewhere outside a lower bound (the largest plane distance)."""
        P = self._planes
        return (np.asarray(x, float) @ P[:, :3].T + P[:, 3]).max(axis=-1)


#: The kinds of obstacle (one model for planning and simulation).
OBSTACLE_TYPES = (BoxObstacle, WallWithHole, MeshObstacle)
