"""Terrain files, read without trusting them: a heightfield from a ``.npy`` array of z in metres or a 16-bit
greyscale PNG times a height scale, and a triangle surface from a mesh file (OBJ, STL, PLY... through trimesh, as
:func:`snakehead.geometry.meshes.read_mesh_file` reads the obstacles' meshes).

Each reader checks the file before reading it (a regular file, bounded in size: :data:`MAX_HEIGHTFIELD_BYTES`,
:data:`~snakehead.geometry.meshes.MAX_MESH_BYTES`) and what it holds (shape, dtype, finite values, at most
:data:`~snakehead.limits.MAX_TERRAIN_CELLS` cells or :data:`~snakehead.limits.MAX_TERRAIN_TRIANGLES` triangles).
Every failure is an :class:`~snakehead.InputError` of one line, ``"{where} {file name}: {what is wrong}"``.

A heightfield's array ``heights[i, j]`` has i along x and j along y (:mod:`snakehead.terrain.surfaces`). A PNG is
an image of the ground seen from above, x to the right and y up: its column c is i = c and its row r (from the
top) is j = rows - 1 - r.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._errors import InputError
from .._validate import input_file, positive
from ..geometry.meshes import read_mesh_file
from ..limits import MAX_TERRAIN_CELLS, MAX_TERRAIN_TRIANGLES

__all__ = ["MAX_HEIGHTFIELD_BYTES", "HEIGHTFIELD_SUFFIXES", "MESH_SUFFIXES", "read_heights", "read_npy_heights",
           "read_png_heights", "read_mesh_surface"]

#: The largest heightfield file read (bytes): MAX_TERRAIN_CELLS cells' float64 heights (a 2 x N grid has the most
#: heights per cell, two), and room for a header.
MAX_HEIGHTFIELD_BYTES = 16 * (MAX_TERRAIN_CELLS + 1) + (1 << 16)
#: The heightfield files read, by suffix.
HEIGHTFIELD_SUFFIXES = (".npy", ".png")
#: The mesh files a terrain may be (trimesh reads them as data).
MESH_SUFFIXES = (".obj", ".stl", ".ply")


def _named(path: Path, where: str) -> str:
    return f"{where} {path.name}"


def _check_grid(shape: tuple[int, ...], path: Path, where: str) -> None:
    """InputError unless ``shape`` is a grid of at least 2 x 2 and at most MAX_TERRAIN_CELLS cells."""
    if len(shape) != 2 or shape[0] < 2 or shape[1] < 2:
        raise InputError(f"{_named(path, where)}: expected a 2-D array of finite heights, got shape {tuple(shape)} "
                         "(at least 2 x 2)")
    cells = (shape[0] - 1) * (shape[1] - 1)
    if cells > MAX_TERRAIN_CELLS:
        raise InputError(f"{_named(path, where)}: {shape[0]} x {shape[1]} heights are {cells} cells; at most "
                         f"{MAX_TERRAIN_CELLS} (MAX_TERRAIN_CELLS)")


def _finite(heights: np.ndarray, path: Path, where: str) -> np.ndarray:
    if not np.all(np.isfinite(heights)):
        bad = int(np.count_nonzero(~np.isfinite(heights)))
        raise InputError(f"{_named(path, where)}: expected a 2-D array of finite heights, got {bad} NaN or infinite")
    return heights


def read_npy_heights(path: str | os.PathLike, where: str) -> np.ndarray:
    """The heights (nx, ny) m of a ``.npy`` file of floats (float32 or float64; no objects, never unpickled)."""
    p = Path(path)
    input_file(p, f"{where} heightfield file", MAX_HEIGHTFIELD_BYTES)
    try:
        array = np.load(p, mmap_mode="r", allow_pickle=False)  # mapped: a header's shape is checked before reading
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"{_named(p, where)}: not a .npy array ({' '.join(str(exc).split())})") from None
    if not isinstance(array, np.ndarray):  # a .npz archive
        getattr(array, "close", lambda: None)()
        raise InputError(f"{_named(p, where)}: not a .npy array (an archive of arrays?)")
    if array.dtype not in (np.float32, np.float64):
        raise InputError(f"{_named(p, where)}: expected heights as float32 or float64 metres, got dtype {array.dtype}")
    _check_grid(array.shape, p, where)
    return _finite(np.array(array, dtype=float), p, where)


def read_png_heights(path: str | os.PathLike, height_scale: float, where: str) -> np.ndarray:
    """The heights (nx, ny) m of a 16-bit greyscale PNG: grey level (0...65535) times ``height_scale`` (m per
    level, > 0), laid out as the module's docstring says. An 8-bit or colour image is refused."""
    from PIL import Image, UnidentifiedImageError  # only PNG heightfields need Pillow (matplotlib's dependency)

    p = Path(path)
    scale = positive(height_scale, f"{where} height_scale")
    input_file(p, f"{where} heightfield file", MAX_HEIGHTFIELD_BYTES)
    try:
        with Image.open(p) as image:
            if image.format != "PNG":
                raise InputError(f"{_named(p, where)}: not a PNG image (Pillow reads it as {image.format})")
            if image.mode not in ("I;16", "I;16B", "I;16L", "I"):
                raise InputError(f"{_named(p, where)}: expected a 16-bit greyscale PNG, got mode {image.mode!r} "
                                 f"({'8-bit' if image.mode in ('L', 'P', '1') else 'not 16-bit greyscale'})")
            _check_grid((image.width, image.height), p, where)  # before the pixels are decoded
            pixels = np.asarray(image, dtype=np.int64)
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{_named(p, where)}: not a PNG image ({' '.join(str(exc).split())})") from None
    if pixels.ndim != 2 or pixels.min() < 0 or pixels.max() > 65535:
        raise InputError(f"{_named(p, where)}: expected a 16-bit greyscale PNG (levels 0...65535)")
    return pixels[::-1, :].T * scale


def read_heights(path: str | os.PathLike, where: str, height_scale: float | None = None) -> np.ndarray:
    """The heights of a ``.npy`` (``height_scale`` must be None) or ``.png`` file (``height_scale`` required)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".npy":
        if height_scale is not None:
            raise InputError(f"{_named(p, where)}: height_scale is for PNG files; a .npy holds metres")
        return read_npy_heights(p, where)
    if suffix == ".png":
        if height_scale is None:
            raise InputError(f"{_named(p, where)}: a PNG heightfield needs height_scale (metres per grey level)")
        return read_png_heights(p, height_scale, where)
    raise InputError(f"{_named(p, where)}: a heightfield file must be one of {HEIGHTFIELD_SUFFIXES}, got {suffix!r}")


def read_mesh_surface(path: str | os.PathLike, where: str, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The vertices (V, 3) m (scaled by ``scale`` > 0) and triangles (F, 3) of a mesh file (OBJ, STL, PLY)."""
    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(f"{_named(p, where)}: a mesh terrain file must be one of {MESH_SUFFIXES}, got "
                         f"{p.suffix.lower()!r}")
    factor = positive(scale, f"{where} scale")
    vertices, faces = read_mesh_file(p, _named(p, where))
    if len(faces) == 0:
        raise InputError(f"{_named(p, where)}: the mesh has no triangles")
    if len(faces) > MAX_TERRAIN_TRIANGLES:
        raise InputError(f"{_named(p, where)}: {len(faces)} triangles; at most {MAX_TERRAIN_TRIANGLES} "
                         "(MAX_TERRAIN_TRIANGLES)")
    if not np.all(np.isfinite(vertices)):
        raise InputError(f"{_named(p, where)}: the mesh has vertices that are not finite")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise InputError(f"{_named(p, where)}: a triangle names a vertex the mesh does not have")
    vertices = vertices * factor
    corners = vertices[faces]
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    if not np.any(area > 0):
        raise InputError(f"{_named(p, where)}: every triangle of the mesh has zero area")
    return vertices, faces[area > 0]  # triangles of no area (common in STL exports) bound nothing: left out
