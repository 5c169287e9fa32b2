"""The ground as a surface: flat ground (z = 0, the default), a plane, a heightfield, a triangle mesh and a
staircase, each an immutable value holding its C++ :class:`snakehead._core.Terrain`.

Every kind answers the same three queries over many points at once, in the C++ core without the GIL (so many
threads may query one terrain at once):

- ``height(xy)``: the surface's z (m) under points ``xy`` (..., 2) -> (...), NaN where there is no surface (outside
  a heightfield's extent, beside a mesh); for a mesh, the highest surface point on the vertical line;
- ``normal(xy)``: the unit upward normal (n_z >= 0) of the facet there, (..., 2) -> (..., 3);
- ``signed_distance(points)``: the exact distance (m) of points (..., 3) to the surface's triangles, positive
  above it (plane, heightfield; a staircase: on its open side) or, for a mesh, on the side its face normals point
  to (the side from which a triangle's vertices run counter-clockwise).

A heightfield's heights ``heights[i, j]`` (nx, ny) lie at ``x = x0 + i * sx / (nx - 1)``,
``y = y0 + j * sy / (ny - 1)``, ``z = z0 + heights[i, j]``; each grid cell is split into two triangles along its
diagonal from (i, j) to (i + 1, j + 1), so the surface is piecewise linear and every query is exact against those
triangles (``include/snakehead/terrain.hpp``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError, InputTypeError
from .._validate import finite_array, finite_float, integer, positive, vector3
from ..geometry.obstacles import BoxObstacle
from ..limits import MAX_TERRAIN_CELLS, MAX_TERRAIN_TRIANGLES

__all__ = ["TerrainQueries", "FlatGround", "PlaneTerrain", "HeightfieldTerrain", "MeshTerrain", "StepsTerrain",
           "TERRAIN_TYPES", "Terrain", "plane_normal_deg"]


class TerrainQueries:
    """The queries every terrain answers, on its C++ ``core`` (a :class:`snakehead._core.Terrain`)."""

    core: _core.Terrain

    def height(self, xy: npt.ArrayLike) -> np.ndarray:
        """The surface's z (m) under points ``xy`` (..., 2) -> (...); NaN where there is no surface."""
        flat, lead = _rows(xy, 2, "xy")
        return self.core.height(flat).reshape(lead)

    def normal(self, xy: npt.ArrayLike) -> np.ndarray:
        """The unit upward normal of the facet under points ``xy`` (..., 2) -> (..., 3); NaN where none."""
        flat, lead = _rows(xy, 2, "xy")
        return self.core.normal(flat).reshape(*lead, 3)

    def signed_distance(self, points: npt.ArrayLike) -> np.ndarray:
        """The signed distance (m) of ``points`` (..., 3) to the surface (> 0 above) -> (...)."""
        flat, lead = _rows(points, 3, "points")
        return self.core.signed_distance(flat).reshape(lead)


    def sphere_clearance(self, centres: npt.ArrayLike, radii: npt.ArrayLike) -> np.ndarray:
        """Spheres' clearance (m): their centres' (..., 3) signed distance minus their radii (...) -> (...)."""
        flat, lead = _rows(centres, 3, "centres")
        r = np.ascontiguousarray(np.broadcast_to(np.asarray(radii, float), lead).reshape(-1))
        return self.core.sphere_clearance(flat, r).reshape(lead)

    def capsule_clearance(self, a: npt.ArrayLike, b: npt.ArrayLike, radii: npt.ArrayLike) -> np.ndarray:
        """Capsules' clearance (m): segments ``a`` -> ``b`` (..., 3) of radii (...): the segment's distance to the
        surface minus the radius, exact while the segment is clear of the surface on its positive side; where it
        touches or crosses it, the smaller of 0 and its ends' signed distances, minus the radius (exact for a
        plane; for a heightfield or a mesh, an upper bound of minus the penetration)."""
        fa, lead = _rows(a, 3, "a")
        fb, lead_b = _rows(b, 3, "b")
        if lead_b != lead:
            raise InputError(f"b must have the shape of a, {(*lead, 3)}, got {(*lead_b, 3)}")
        r = np.ascontiguousarray(np.broadcast_to(np.asarray(radii, float), lead).reshape(-1))
        return self.core.capsule_clearance(fa, fb, r).reshape(lead)


def _rows(a: npt.ArrayLike, columns: int, name: str) -> tuple[np.ndarray, tuple[int, ...]]:
    """``a`` (..., columns) as float rows (N, columns), C-contiguous, and its leading shape. NaN passes (gives NaN)."""
    try:
        arr = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise InputTypeError(f"{name} must be an array of numbers of shape (..., {columns})") from None
    if arr.ndim < 1 or arr.shape[-1] != columns:
        raise InputError(f"{name} must have shape (..., {columns}), got {arr.shape}")
    return np.ascontiguousarray(arr.reshape(-1, columns)), arr.shape[:-1]


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class FlatGround(TerrainQueries):
    """The plane z = 0 everywhere: the default ground. Its height is 0 and a point's signed distance is its z."""

    core: _core.Terrain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _set(self, "core", _core.Terrain.plane(np.array([0.0, 0.0, 1.0]), np.zeros(3)))


def plane_normal_deg(roll_deg: float, pitch_deg: float) -> np.ndarray:
    """The unit normal of the ground turned by ``roll_deg`` about the world x-axis, then ``pitch_deg`` about the
    world y-axis: ``Ry(pitch) Rx(roll) e_z = (cos r sin p, -sin r, cos r cos p)``. A positive pitch lowers the
    ground along +x (dz/dx = -tan p at zero roll); a positive roll raises it along +y (dz/dy = tan r / cos p)."""
    r = math.radians(finite_float(roll_deg, "roll_deg"))
    p = math.radians(finite_float(pitch_deg, "pitch_deg"))
    if not (abs(r) < math.pi / 2 and abs(p) < math.pi / 2):
        raise InputError(f"roll_deg and pitch_deg must each be within (-90, 90), got {roll_deg!r}, {pitch_deg!r}")
    return np.array([math.cos(r) * math.sin(p), -math.sin(r), math.cos(r) * math.cos(p)])


@dataclass(frozen=True, eq=False)
class PlaneTerrain(TerrainQueries):
    """A plane through ``point`` (3,) m with the upward normal ``unit_normal`` (3,) (given at any length, stored
    unit; n_z > 0). (``normal`` is the query every terrain answers.)

    ``height(x, y) = p_z - (n_x (x - p_x) + n_y (y - p_y)) / n_z``; signed distance ``n . (x - p)``."""

    unit_normal: np.ndarray
    point: np.ndarray
    core: _core.Terrain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = vector3(self.unit_normal, "a plane terrain's normal")
        if not np.linalg.norm(n) > 0:
            raise InputError("a plane terrain's normal must be non-zero")
        n = n / np.linalg.norm(n)
        if not n[2] > 0:
            raise InputError(f"a plane terrain's normal must point up (n_z > 0), got {n.tolist()}")
        _set(self, "unit_normal", n)
        _set(self, "point", vector3(self.point, "a plane terrain's point"))
        _set(self, "core", _core.Terrain.plane(n, self.point))

    @classmethod
    def from_roll_pitch(cls, roll_deg: float, pitch_deg: float, point: npt.ArrayLike = (0.0, 0.0, 0.0)) \
            -> "PlaneTerrain":
        """The plane through ``point`` whose normal is :func:`plane_normal_deg` (``roll_deg``, ``pitch_deg``)."""
        return cls(plane_normal_deg(roll_deg, pitch_deg), np.asarray(point, float))


@dataclass(frozen=True, eq=False)
class HeightfieldTerrain(TerrainQueries):
    """A triangulated grid of heights (see the module's docstring for the layout and the triangles).

    heights (nx, ny) m, nx, ny >= 2, at most :data:`~snakehead.limits.MAX_TERRAIN_CELLS` cells; extent (sx, sy)
    m > 0; origin (x0, y0, z0) m: the grid's corner at i = j = 0, z0 added to every height. ``source`` and
    ``height_scale``: the file it was read from and, for a PNG, metres per grey level (kept to write the scene back).
    """

    heights: np.ndarray
    extent: np.ndarray
    origin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    source: Path | None = None
    height_scale: float | None = None
    core: _core.Terrain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        h = np.asarray(self.heights)
        if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
            raise InputError(f"a heightfield's heights must be a 2-D array of at least 2 x 2, got shape {h.shape}")
        cells = (h.shape[0] - 1) * (h.shape[1] - 1)
        if cells > MAX_TERRAIN_CELLS:
            raise InputError(f"a heightfield of {h.shape[0]} x {h.shape[1]} heights has {cells} cells; at most "
                             f"{MAX_TERRAIN_CELLS} (MAX_TERRAIN_CELLS)")
        h = finite_array(h, "a heightfield's heights")
        extent = finite_array(self.extent, "a heightfield's extent", (2,))
        if not np.all(extent > 0):
            raise InputError(f"a heightfield's extent must be > 0, got {extent.tolist()}")
        h.setflags(write=False)
        _set(self, "heights", h)
        _set(self, "extent", extent)
        _set(self, "origin", vector3(self.origin, "a heightfield's origin"))
        _set(self, "core", _core.Terrain.heightfield(h, extent, self.origin))


@dataclass(frozen=True, eq=False)
class MeshTerrain(TerrainQueries):
    """A triangle surface (not a solid, not its hull): vertices (V, 3) m and faces (F, 3) int, at most
    :data:`~snakehead.limits.MAX_TERRAIN_TRIANGLES` triangles. Its positive side is the one its face normals point
    to (counter-clockwise seen from there): make them point up or out. ``source`` and ``scale``: the file it was
    read from and the scale applied (kept to write the scene back)."""

    vertices: np.ndarray
    faces: np.ndarray
    source: Path | None = None
    scale: float = 1.0
    core: _core.Terrain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        v = finite_array(self.vertices, "a mesh terrain's vertices")
        f = np.asarray(self.faces)
        if v.ndim != 2 or v.shape[1] != 3:
            raise InputError(f"a mesh terrain's vertices must have shape (V, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0 or not np.issubdtype(f.dtype, np.integer):
            raise InputError(f"a mesh terrain's faces must be integers of shape (F, 3), F >= 1, got {f.dtype} "
                             f"{f.shape}")
        if len(f) > MAX_TERRAIN_TRIANGLES:
            raise InputError(f"a mesh terrain of {len(f)} triangles; at most {MAX_TERRAIN_TRIANGLES} "
                             "(MAX_TERRAIN_TRIANGLES)")
        f = np.ascontiguousarray(f, dtype=np.int64)
        v.setflags(write=False)
        f.setflags(write=False)
        _set(self, "vertices", v)
        _set(self, "faces", f)
        _set(self, "core", _core.Terrain.mesh(v, f))


@dataclass(frozen=True, eq=False)
class StepsTerrain(TerrainQueries):
    """A staircase, generated as a triangle mesh of horizontal treads and vertical risers (exact steps at any
    heading, which a heightfield could only slope across one cell).

    Along the heading ``u = (x - x_s) cos h + (y - y_s) sin h`` from ``start`` (x_s, y_s, z_s) m and across it
    ``|v| <= width / 2``: the ground is ``z_s`` for ``-apron <= u < 0``, then step k (0 <= k < count) is
    ``z_s + (k + 1) * step_height`` for ``k * step_depth <= u < (k + 1) * step_depth``, the last one reaching on to
    ``count * step_depth + apron``. ``step_height`` may be negative (a staircase down). Outside that rectangle there
    is no surface (NaN height). Its positive side is above the treads and in front of the risers.
    """

    step_height: float
    step_depth: float
    count: int = 1
    heading_deg: float = 0.0
    start: np.ndarray = field(default_factory=lambda: np.zeros(3))
    width: float = 2.0
    apron: float = 1.0
    core: _core.Terrain = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        rise = finite_float(self.step_height, "a staircase's step_height")
        if rise == 0:
            raise InputError("a staircase's step_height must be non-zero (flat ground is FlatGround)")
        _set(self, "step_height", rise)
        _set(self, "step_depth", positive(self.step_depth, "a staircase's step_depth"))
        _set(self, "count", integer(self.count, "a staircase's count", least=1, most=MAX_TERRAIN_TRIANGLES // 8))
        _set(self, "heading_deg", finite_float(self.heading_deg, "a staircase's heading_deg"))
        _set(self, "start", vector3(self.start, "a staircase's start"))
        _set(self, "width", positive(self.width, "a staircase's width"))
        _set(self, "apron", positive(self.apron, "a staircase's apron"))
        vertices, faces = self.triangles()
        _set(self, "core", _core.Terrain.mesh(vertices, faces))

    def triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """The staircase's vertices (V, 3) m in the world and triangles (F, 3): treads up, risers facing down the
        stairs (towards -u for a staircase up, +u for one down)."""
        edges = np.concatenate([[-self.apron], self.step_depth * np.arange(self.count + 1, dtype=float)])
        edges[-1] = self.count * self.step_depth + self.apron
        levels = self.step_height * np.arange(self.count + 1, dtype=float)
        quads = [self._quad(edges[k], edges[k + 1], levels[k], levels[k]) for k in range(self.count + 1)]
        quads += [self._quad(edges[k + 1], edges[k + 1], levels[k], levels[k + 1]) for k in range(self.count)]
        local = np.concatenate(quads)  # (4 Q, 3) in (u, v, z)
        h = math.radians(self.heading_deg)
        c, s = math.cos(h), math.sin(h)
        world = np.column_stack([c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1], local[:, 2]])
        world += self.start
        corners = 4 * np.arange(len(quads))[:, None]
        faces = np.concatenate([corners + [0, 1, 2], corners + [0, 2, 3]])
        unique, index = np.unique(world, axis=0, return_inverse=True)  # shared corners: one vertex (pseudonormals)
        return unique, index.reshape(-1)[faces].astype(np.int64)

    def risen_blocks(self) -> list[BoxObstacle]:
        """A staircase up as the solid it raises above its start's level: one box per step, from that level up to
        the step's tread and from its riser to the staircase's far end, across its width (world). Their union is
        the ground above ``start``'s level: what a body lying on the apron keeps clear of."""
        if self.step_height <= 0:
            raise InputError("a staircase down has no risen blocks: it drops below its start's level")
        h = math.radians(self.heading_deg)
        R = np.array([[math.cos(h), -math.sin(h), 0.0], [math.sin(h), math.cos(h), 0.0], [0.0, 0.0, 1.0]])
        end = self.count * self.step_depth + self.apron
        blocks = []
        for k in range(self.count):
            u0, top = k * self.step_depth, (k + 1) * self.step_height
            size = np.array([end - u0, self.width, top if k == 0 else self.step_height])
            bottom = 0.0 if k == 0 else k * self.step_height  # stacked: each box one step high above the one before
            centre = self.start + R @ np.array([(u0 + end) / 2, 0.0, bottom + size[2] / 2])
            blocks.append(BoxObstacle(centre, size, R))
        return blocks

    def _quad(self, u0: float, u1: float, z0: float, z1: float) -> np.ndarray:
        """A tread (u0 < u1, z0 = z1: counter-clockwise from above) or a riser (u0 = u1, facing down the stairs)."""
        w = self.width / 2
        if u0 != u1:
            return np.array([[u0, -w, z0], [u1, -w, z1], [u1, w, z1], [u0, w, z0]])
        if z1 > z0:  # a riser up: faces -u
            return np.array([[u0, w, z0], [u0, -w, z0], [u0, -w, z1], [u0, w, z1]])
        return np.array([[u0, -w, z1], [u0, w, z1], [u0, w, z0], [u0, -w, z0]])  # a riser down: faces +u


#: The kinds of terrain a scene may hold.
TERRAIN_TYPES = (FlatGround, PlaneTerrain, HeightfieldTerrain, MeshTerrain, StepsTerrain)
#: Any one of them (for annotations).
Terrain = FlatGround | PlaneTerrain | HeightfieldTerrain | MeshTerrain | StepsTerrain
