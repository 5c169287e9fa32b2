"""Rough terrain in MuJoCo: a heightfield, a triangle mesh or a staircase (``snakehead.terrain``) as the floor, an
``hfield`` geom.

A heightfield goes in as its own grid. A mesh or a staircase is sampled on a grid of :data:`FIELD_SPACING_M` over its
extent (its highest surface point on each vertical line; where it has no surface, its lowest height): a riser becomes
a slope one cell wide. MuJoCo's hfield spans x along its columns and y along its rows, centred on its geom, with its
elevations scaled into [0, 1]: the grid is laid out and scaled so that the hfield's surface is the terrain's
piecewise-linear one.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._errors import InputError
from ..limits import MAX_TERRAIN_CELLS
from ..terrain.surfaces import HeightfieldTerrain, MeshTerrain, StepsTerrain

__all__ = ["FIELD_SPACING_M", "ROUGH_TERRAINS", "terrain_grid", "add_terrain_floor"]

#: m: the grid spacing a mesh or a staircase is sampled on for MuJoCo.
FIELD_SPACING_M = 0.005
#: The terrains MuJoCo gets as an hfield.
ROUGH_TERRAINS = (HeightfieldTerrain, MeshTerrain, StepsTerrain)


def terrain_grid(terrain: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """heights (nx, ny) m above ``origin``'s z, extent (2,) m and origin (3,) of a grid holding ``terrain``'s surface
    (the layout of :class:`~snakehead.terrain.surfaces.HeightfieldTerrain`)."""
    if isinstance(terrain, HeightfieldTerrain):
        return np.asarray(terrain.heights, float), np.asarray(terrain.extent, float), np.asarray(terrain.origin)
    if not isinstance(terrain, (MeshTerrain, StepsTerrain)):
        raise InputError(f"MuJoCo's hfield takes a heightfield, mesh or steps terrain, got {type(terrain).__name__}")
    vertices = terrain.vertices if isinstance(terrain, MeshTerrain) else terrain.triangles()[0]
    lo, hi = vertices[:, :2].min(axis=0), vertices[:, :2].max(axis=0)
    n = np.maximum(2, np.ceil((hi - lo) / FIELD_SPACING_M).astype(int) + 1)
    if (n[0] - 1) * (n[1] - 1) > MAX_TERRAIN_CELLS:
        raise InputError(f"a terrain of {hi - lo} m sampled every {FIELD_SPACING_M} m has more than "
                         f"{MAX_TERRAIN_CELLS} cells (MAX_TERRAIN_CELLS)")
    x, y = np.linspace(lo[0], hi[0], n[0]), np.linspace(lo[1], hi[1], n[1])
    xy = np.stack(np.meshgrid(x, y, indexing="ij"), axis=-1)
    h = terrain.height(xy)
    h = np.where(np.isfinite(h), h, np.nanmin(h) if np.isfinite(h).any() else 0.0)
    return h, hi - lo, np.array([lo[0], lo[1], 0.0])


def add_terrain_floor(mj: Any, spec: Any, terrain: Any, name: str, surface: dict) -> float:
    """The terrain as the hfield geom ``name`` in ``spec``'s world (contacts with the robot); its lowest height (m)."""
    heights, extent, origin = terrain_grid(terrain)
    low, high = float(heights.min()), float(heights.max())
    rise = max(high - low, 1e-6)  # MuJoCo's elevation scale; a flat field keeps a tiny one
    field = spec.add_hfield(name=f"{name}_field", nrow=heights.shape[1], ncol=heights.shape[0],
                            size=[extent[0] / 2, extent[1] / 2, rise, max(0.01, 0.1 * rise)])
    field.userdata = ((heights - low) / rise).T.reshape(-1).tolist()  # rows along y, columns along x
    centre = [origin[0] + extent[0] / 2, origin[1] + extent[1] / 2, origin[2] + low]
    spec.worldbody.add_geom(name=name, type=mj.mjtGeom.mjGEOM_HFIELD, hfieldname=field.name, pos=centre,
                            contype=0, conaffinity=1, **surface)
    return origin[2] + low if math.isfinite(low) else 0.0
