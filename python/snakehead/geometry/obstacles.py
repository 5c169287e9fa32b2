"""The obstacles of a scene, one model for planning (:mod:`snakehead.geometry.collision`) and simulation
(:mod:`snakehead.sim`): boxes and a wall with a round hole. Scene files (:mod:`snakehead.scenes`) describe them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import finite_array, finite_float, positive, rotation_matrix, unit_vector3, vector3

import numpy.typing as npt


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
            raise ValueError(f"box size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "rotation", rotation_matrix(self.rotation, "box rotation"))

    @classmethod
    def from_yaw(cls, centre: npt.ArrayLike, size: npt.ArrayLike, yaw: float = 0.0) -> "BoxObstacle":
        """A box standing upright, turned by ``yaw`` rad about the world z-axis."""
        yaw = finite_float(yaw, "box yaw")
        c, s = np.cos(yaw), np.sin(yaw)
        return cls(np.asarray(centre, float), np.asarray(size, float), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))


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
            raise ValueError(f"wall size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "hole_diameter", positive(self.hole_diameter, "hole_diameter"))
        off = finite_array(self.hole_offset, "hole_offset", (2,))
        object.__setattr__(self, "hole_offset", off)
        r = self.hole_diameter / 2
        if np.any(np.abs(off) + r >= size[:2] / 2):
            raise ValueError("the hole does not lie inside the wall")

    @classmethod
    def standing(cls, hole_centre: npt.ArrayLike, normal: npt.ArrayLike, size: npt.ArrayLike, hole_diameter: float
                 ) -> "WallWithHole":
        """A wall standing on the ground (its bottom at z = 0) with the hole on its vertical centre line, facing
        along the horizontal ``normal``: the paper's wall of Section 4.2 as snakehead places it."""
        normal = unit_vector3(normal, "wall normal")
        if abs(normal[2]) > 1e-9:
            raise ValueError(f"a standing wall's normal must be horizontal, got {normal.tolist()}")
        hole_centre = vector3(hole_centre, "hole centre")
        size = vector3(size, "wall size (w, h, thickness)")
        if hole_centre[2] <= 0 or hole_centre[2] >= size[1]:
            raise ValueError(f"the hole's centre ({hole_centre[2]} m high) must lie within the wall's height "
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
