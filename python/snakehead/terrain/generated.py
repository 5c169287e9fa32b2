"""The terrains the benchmark uses, generated from a few numbers: a slope (a plane), a step and a staircase (a
mesh of treads and risers), an undulating surface and an egg-crate (heightfields).

The heightfields sample their formula on a grid of spacing at most ``spacing`` (m) over ``extent`` (sx, sy) m
centred on the world origin (unless ``origin`` is given): between the grid's points the surface is the grid's
triangles (:mod:`snakehead.terrain.surfaces`), so it is the formula exactly at the points and within
``amplitude * (pi * spacing / wavelength) ** 2 / 2`` of it between them.
"""
from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array, finite_float, positive, vector3
from ..limits import MAX_TERRAIN_CELLS
from .surfaces import HeightfieldTerrain, PlaneTerrain, StepsTerrain

__all__ = ["DEFAULT_EXTENT_M", "DEFAULT_SPACING_M", "slope", "step", "staircase", "undulating", "egg_crate"]

#: A generated heightfield's default extent (m): the default snake (1.38 m) lying straight fits with room.
DEFAULT_EXTENT_M = (4.0, 4.0)
#: A generated heightfield's default grid spacing (m).
DEFAULT_SPACING_M = 0.01


def slope(angle_deg: float, heading_deg: float = 0.0, point: npt.ArrayLike = (0.0, 0.0, 0.0)) -> PlaneTerrain:
    """A plane through ``point`` rising at ``angle_deg`` (-90, 90) towards the heading ``heading_deg`` (from the
    world x-axis, counter-clockwise): ``z = p_z + tan(a) ((x - p_x) cos h + (y - p_y) sin h)``."""
    a = math.radians(finite_float(angle_deg, "a slope's angle_deg"))
    if not abs(a) < math.pi / 2:
        raise InputError(f"a slope's angle_deg must be within (-90, 90), got {angle_deg!r}")
    h = math.radians(finite_float(heading_deg, "a slope's heading_deg"))
    t = math.tan(a)
    return PlaneTerrain(np.array([-t * math.cos(h), -t * math.sin(h), 1.0]), vector3(point, "a slope's point"))


def step(height: float, heading_deg: float = 0.0, start: npt.ArrayLike = (0.0, 0.0, 0.0), *, depth: float = 1.0,
         width: float = 2.0, apron: float = 1.0) -> StepsTerrain:
    """One step of ``height`` m (negative: down) at ``start``, facing the heading: ground at ``start``'s z for
    ``apron`` m before it, the raised level for ``depth + apron`` m after it (:class:`StepsTerrain`, count 1)."""
    return StepsTerrain(height, depth, 1, heading_deg, np.asarray(start, float), width, apron)


def staircase(step_height: float, step_depth: float, count: int, heading_deg: float = 0.0,
              start: npt.ArrayLike = (0.0, 0.0, 0.0), *, width: float = 2.0, apron: float = 1.0) -> StepsTerrain:
    """``count`` steps of ``step_height`` m rising every ``step_depth`` m along the heading (:class:`StepsTerrain`)."""
    return StepsTerrain(step_height, step_depth, count, heading_deg, np.asarray(start, float), width, apron)


def _grid(extent: npt.ArrayLike, spacing: float, origin: npt.ArrayLike | None) \
        -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The grid's extent (2,), origin (3,) and point coordinates x (nx, 1), y (1, ny)."""
    size = finite_array(extent, "a heightfield's extent", (2,))
    if not np.all(size > 0):
        raise InputError(f"a heightfield's extent must be > 0, got {size.tolist()}")
    d = positive(spacing, "a heightfield's spacing")
    nx, ny = (int(math.ceil(s / d - 1e-9)) + 1 for s in size)
    if (nx - 1) * (ny - 1) > MAX_TERRAIN_CELLS:
        raise InputError(f"a heightfield of {size.tolist()} m at {d:g} m spacing has {(nx - 1) * (ny - 1)} cells; "
                         f"at most {MAX_TERRAIN_CELLS} (MAX_TERRAIN_CELLS): widen the spacing")
    o = np.array([-size[0] / 2, -size[1] / 2, 0.0]) if origin is None else vector3(origin, "a heightfield's origin")
    x = o[0] + size[0] * np.arange(nx)[:, None] / (nx - 1)
    y = o[1] + size[1] * np.arange(ny)[None, :] / (ny - 1)
    return size, o, x, y


def undulating(amplitude: float, wavelength: float, heading_deg: float = 0.0, *,
               extent: npt.ArrayLike = DEFAULT_EXTENT_M, spacing: float = DEFAULT_SPACING_M,
               origin: npt.ArrayLike | None = None) -> HeightfieldTerrain:
    """Parallel waves along the heading: ``z = z0 + A sin(2 pi (x cos h + y sin h) / wavelength)``."""
    A = finite_float(amplitude, "an undulating terrain's amplitude")
    lam = positive(wavelength, "an undulating terrain's wavelength")
    h = math.radians(finite_float(heading_deg, "an undulating terrain's heading_deg"))
    size, o, x, y = _grid(extent, spacing, origin)
    return HeightfieldTerrain(A * np.sin(2 * np.pi * (x * math.cos(h) + y * math.sin(h)) / lam), size, o)


def egg_crate(amplitude: float, period: float, *, extent: npt.ArrayLike = DEFAULT_EXTENT_M,
              spacing: float = DEFAULT_SPACING_M, origin: npt.ArrayLike | None = None) -> HeightfieldTerrain:
    """Bumps and hollows on a square lattice: ``z = z0 + A sin(2 pi x / period) sin(2 pi y / period)``."""
    A = finite_float(amplitude, "an egg-crate's amplitude")
    P = positive(period, "an egg-crate's period")
    size, o, x, y = _grid(extent, spacing, origin)
    return HeightfieldTerrain(A * np.sin(2 * np.pi * x / P) * np.sin(2 * np.pi * y / P), size, o)
