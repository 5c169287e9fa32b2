"""A scene file's ``[terrain]`` table: the ground the scene lies on (flat ground, z = 0, when there is none)::

    [terrain]
    kind = "plane"                  # a slope: normal = [nx, ny, nz] (upward), or roll_deg and pitch_deg
    roll_deg = 0.0                  #   (:func:`snakehead.terrain.surfaces.plane_normal_deg`)
    pitch_deg = -5.0
    point = [0.0, 0.0, 0.0]         # optional: a point of the plane (m, default the origin)

    [terrain]
    kind = "heightfield"            # heights[i, j] at x0 + i sx / (nx - 1), y0 + j sy / (ny - 1)
    file = "ground.npy"             # a .npy of z (m), or a 16-bit greyscale .png with
    height_scale = 0.0001           #   height_scale (m per grey level; PNG only)
    extent = [4.0, 4.0]             # sx, sy (m)
    origin = [-2.0, -2.0, 0.0]      # optional: x0, y0, z0 (m, default 0)

    [terrain]
    kind = "mesh"                   # a triangle surface (OBJ, STL, PLY), its normals up
    file = "rocks.stl"
    scale = 0.001                   # optional (default 1)

    [terrain]
    kind = "steps"                  # a staircase (:class:`snakehead.terrain.surfaces.StepsTerrain`)
    step_height = 0.05              # m (negative: down)
    step_depth = 0.3                # m
    count = 3                       # optional (default 1)
    heading_deg = 0.0               # optional: the direction the stairs climb
    start = [0.5, 0.0, 0.0]         # optional: where the first riser stands (m)
    width = 2.0                     # optional (m)
    apron = 1.0                     # optional: flat ground before and after (m)

A scene file is not trusted: ``file`` must lie inside the scene file's folder once symbolic links are resolved
(:func:`scene_file_inside`), every file is bounded in size and content (:mod:`snakehead.terrain.terrain_files`),
and every bad value is an :class:`~snakehead.InputError` of one line naming the file and the field.
"""
from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import InputError, InputTypeError
from ..model.robot_file import check_keys, path_from, toml_string
from ..terrain.surfaces import (
    FlatGround,
    HeightfieldTerrain,
    MeshTerrain,
    PlaneTerrain,
    StepsTerrain,
    Terrain,
)
from ..terrain.terrain_files import read_heights, read_mesh_surface

__all__ = ["TERRAIN_KINDS", "scene_file_inside", "written_inside", "terrain_from_table", "terrain_entry"]

#: Each kind's required and optional keys.
TERRAIN_KINDS = {
    "plane": (("kind",), ("normal", "roll_deg", "pitch_deg", "point")),
    "heightfield": (("kind", "file", "extent"), ("origin", "height_scale")),
    "mesh": (("kind", "file"), ("scale",)),
    "steps": (("kind", "step_height", "step_depth"), ("count", "heading_deg", "start", "width", "apron")),
}


def scene_file_inside(folder: Path, name: Any, where: str) -> Path:
    """The file ``name`` (a relative path string) resolved inside ``folder``, the scene file's; InputError naming
    ``where`` for anything else: not a string, absolute, or outside the folder once links are resolved (without
    saying whether it exists)."""
    if not isinstance(name, str) or not name or "\0" in name:
        raise InputError(f"{where}: file must be a file name relative to the scene file, got {name!r}")
    root = folder.resolve()
    resolved = (root / name).resolve()
    if Path(name).is_absolute() or not resolved.is_relative_to(root):
        raise InputError(f"{where}: file {name!r} is outside the scene file's folder {os.fspath(root)!r}; a scene "
                         "reads only files in its own folder")
    return resolved


def written_inside(folder: Path, name: str, where: str) -> None:
    """InputError unless the file ``name`` a scene file written in ``folder`` would name lies inside it (the check
    :func:`scene_file_inside` makes when the file is read), saying that ``save_scene`` copies it there."""
    try:
        scene_file_inside(folder, name, where)
    except InputError as exc:
        raise InputError(f"{exc} (save_scene copies it into the folder)") from None


def _numbers(value: Any, where: str, n: int) -> np.ndarray:
    if not isinstance(value, list) or len(value) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value):
        raise InputError(f"{where} must be a list of {n} finite numbers, got {value!r}")
    return np.array(value, dtype=float)


def _number(value: Any, where: str) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _plane(t: dict, where: str) -> PlaneTerrain:
    point = _numbers(t["point"], f"{where} point", 3) if "point" in t else np.zeros(3)
    if "normal" in t:
        if "roll_deg" in t or "pitch_deg" in t:
            raise InputError(f"{where}: give normal or roll_deg and pitch_deg, not both")
        return PlaneTerrain(_numbers(t["normal"], f"{where} normal", 3), point)
    return PlaneTerrain.from_roll_pitch(_number(t.get("roll_deg", 0.0), f"{where} roll_deg"),
                                        _number(t.get("pitch_deg", 0.0), f"{where} pitch_deg"), point)


def _heightfield(t: dict, folder: Path, where: str) -> HeightfieldTerrain:
    extent = _numbers(t["extent"], f"{where} extent", 2)  # the numbers before the file is read
    origin = _numbers(t["origin"], f"{where} origin", 3) if "origin" in t else np.zeros(3)
    scale = _number(t["height_scale"], f"{where} height_scale") if "height_scale" in t else None
    path = scene_file_inside(folder, t["file"], where)
    heights = read_heights(path, where, scale)
    return HeightfieldTerrain(heights, extent, origin, source=path, height_scale=scale)


def _mesh(t: dict, folder: Path, where: str) -> MeshTerrain:
    path = scene_file_inside(folder, t["file"], where)
    scale = _number(t.get("scale", 1.0), f"{where} scale")
    vertices, faces = read_mesh_surface(path, where, scale)
    return MeshTerrain(vertices, faces, source=path, scale=scale)


def _steps(t: dict, where: str) -> StepsTerrain:
    count = t.get("count", 1)
    if not isinstance(count, int) or isinstance(count, bool):
        raise InputError(f"{where} count must be an integer, got {count!r}")
    return StepsTerrain(_number(t["step_height"], f"{where} step_height"),
                        _number(t["step_depth"], f"{where} step_depth"), count,
                        _number(t.get("heading_deg", 0.0), f"{where} heading_deg"),
                        _numbers(t["start"], f"{where} start", 3) if "start" in t else np.zeros(3),
                        _number(t.get("width", 2.0), f"{where} width"), _number(t.get("apron", 1.0), f"{where} apron"))


def terrain_from_table(table: Any, folder: Path | None, where: str) -> Terrain:
    """The terrain of a scene file's ``[terrain]`` table (``folder``: the scene file's; None: the working folder)."""
    where = f"{where}: [terrain]"
    if not isinstance(table, dict):
        raise InputError(f"{where} must be a table, got {table!r}")
    kind = table.get("kind")
    if not isinstance(kind, str) or kind not in TERRAIN_KINDS:
        raise InputError(f"{where} kind must be one of {sorted(TERRAIN_KINDS)}, got {kind!r}")
    check_keys(table, *TERRAIN_KINDS[kind], where)
    base = folder if folder is not None else Path.cwd()
    try:
        if kind == "plane":
            return _plane(table, where)
        if kind == "heightfield":
            return _heightfield(table, base, where)
        if kind == "mesh":
            return _mesh(table, base, where)
        return _steps(table, where)
    except InputError as exc:
        text = str(exc)
        raise InputError(text if where in text else f"{where}: {text}") from None


def _floats(v: Any) -> str:
    return "[" + ", ".join(repr(float(x)) for x in np.asarray(v, float).ravel()) + "]"


def terrain_entry(terrain: Terrain, folder: Path, where: str, inside: bool = True) -> dict[str, str] | None:
    """The ``[terrain]`` table's keys as TOML values (None for flat ground, which a scene file leaves out), its
    files named relative to ``folder``. InputError for a generated heightfield or mesh (no file to name) and, when
    ``inside``, for a file outside ``folder``, which :func:`terrain_from_table` would refuse (``save_scene`` copies
    it into the folder first: :func:`snakehead.scenes.scene.with_meshes_in`)."""
    if isinstance(terrain, FlatGround):
        return None
    if isinstance(terrain, PlaneTerrain):
        return {"kind": '"plane"', "normal": _floats(terrain.unit_normal), "point": _floats(terrain.point)}
    if isinstance(terrain, StepsTerrain):
        return {"kind": '"steps"', "step_height": repr(terrain.step_height), "step_depth": repr(terrain.step_depth),
                "count": str(terrain.count), "heading_deg": repr(terrain.heading_deg), "start": _floats(terrain.start),
                "width": repr(terrain.width), "apron": repr(terrain.apron)}
    if isinstance(terrain, (HeightfieldTerrain, MeshTerrain)):
        if terrain.source is None:
            raise InputError(f"{where}: the terrain was not read from a file, and a scene file can only name its "
                             "heightfield's or mesh's file (save the heights with numpy.save first)")
        name = path_from(folder, terrain.source)
        if inside:
            written_inside(folder, name, where)
        entry = {"kind": '"heightfield"' if isinstance(terrain, HeightfieldTerrain) else '"mesh"',
                 "file": toml_string(name)}
        if isinstance(terrain, HeightfieldTerrain):
            entry["extent"] = _floats(terrain.extent)
            entry["origin"] = _floats(terrain.origin)
            if terrain.height_scale is not None:
                entry["height_scale"] = repr(terrain.height_scale)
        else:
            entry["scale"] = repr(terrain.scale)
        return entry
    raise InputTypeError(f"{where}: not a terrain: {type(terrain).__name__}")
