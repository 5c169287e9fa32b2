"""Mesh files read into convex hulls (STL, OBJ, DAE, PLY... through trimesh), with the checks that make a bad
file an InputError naming the place it was met: the robot's collision meshes and the scene's mesh obstacles."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from .._errors import InputError
from .._validate import MAX_COORDINATE_M, input_file

__all__ = ["MAX_MESH_BYTES", "MIN_MESH_THICKNESS_M", "convex_hull_vertices", "read_mesh_file"]

#: A collision mesh larger than this is not a snake module's (and would stall the hull).
MAX_MESH_BYTES = 64 * 1024 * 1024
#: A collision mesh thinner than this (m) once scaled is flat: a scale that is wrong (mm read as m twice, a 0).
MIN_MESH_THICKNESS_M = 1e-6


def convex_hull_vertices(path: Path, scale: np.ndarray, where: str) -> np.ndarray:
    """The vertices (V, 3) of the convex hull of the mesh file ``path`` (STL, OBJ, DAE, PLY... through trimesh),
    scaled. A missing, unreadable, empty or flat mesh (flat as written or once scaled: thinner than
    :data:`MIN_MESH_THICKNESS_M`) is an InputError naming ``where`` and the path."""
    shown = repr(os.fspath(path))
    vertices, _ = read_mesh_file(path, where)
    vertices = vertices[np.all(np.isfinite(vertices), axis=1)]
    if len(vertices) == 0:
        raise InputError(f"{where}: mesh file {shown} has no vertices (not a mesh trimesh reads: STL, OBJ, PLY, "
                         "DAE, ...)")
    if _thickness(vertices) <= 0:
        raise InputError(f"{where}: mesh file {shown} is flat ({len(vertices)} vertices on a plane, a line or a "
                         "point): a collision mesh must enclose a volume")
    scale = np.asarray(scale, float).reshape(3)
    vertices = vertices * scale
    thickness = _thickness(vertices)
    if thickness < MIN_MESH_THICKNESS_M:
        extent = vertices.max(axis=0) - vertices.min(axis=0)
        raise InputError(f"{where}: mesh file {shown} scaled by {' '.join(f'{s:g}' for s in scale)} is "
                         f"{thickness:.3g} m thin (extent {' x '.join(f'{e:.3g}' for e in extent)} m): no volume "
                         f"(at least {MIN_MESH_THICKNESS_M:g} m; is the scale right?)")
    if np.abs(vertices).max() > MAX_COORDINATE_M:
        raise InputError(f"{where}: mesh file {shown} has a vertex {np.abs(vertices).max():.3g} m from its "
                         f"origin (at most {MAX_COORDINATE_M:g} m; is the scale right?)")
    try:
        hull = ConvexHull(vertices)
    except QhullError as exc:  # nearly flat, or coordinates whose round-off swamps the shape
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "qhull failed"
        raise InputError(f"{where}: mesh file {shown} has no convex hull ({first})") from None
    return np.ascontiguousarray(vertices[hull.vertices])


def read_mesh_file(path: Path, where: str) -> tuple[np.ndarray, np.ndarray]:
    """The vertices (V, 3) float and triangles (F, 3) int of the mesh file ``path`` (STL, OBJ, DAE, PLY... through
    trimesh, as written: not merged, not repaired). A missing, oversized (:data:`MAX_MESH_BYTES`), empty or
    unreadable file is an InputError naming ``where`` and the path; the values are not checked further."""
    import trimesh  # heavy to import (~0.2 s): only descriptions and scenes with meshes need it

    shown = repr(os.fspath(path))
    input_file(path, f"{where}: mesh file", MAX_MESH_BYTES)
    if os.path.getsize(path) == 0:
        raise InputError(f"{where}: mesh file {shown} is empty (0 bytes)")
    try:
        loaded: Any = trimesh.load(os.fspath(path), force="mesh", process=False)
        vertices = np.asarray(loaded.vertices, dtype=float)
        faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
    except Exception as exc:  # trimesh raises many kinds for a bad file
        raise InputError(f"{where}: cannot read mesh file {shown}: {' '.join(str(exc).split())}") from None
    if vertices.ndim != 2 or vertices.shape[1] != 3:  # e.g. an OBJ "v" line with two coordinates
        raise InputError(f"{where}: mesh file {shown} has vertices of shape {vertices.shape}, not (V, 3)")
    return vertices, faces


def _thickness(vertices: np.ndarray) -> float:
    """The width (m) of points (V, 3) across their thinnest principal direction (0 for fewer than 4 points)."""
    if len(vertices) < 4:
        return 0.0
    centred = vertices - vertices.mean(axis=0)
    scale = float(np.abs(centred).max())
    if scale == 0:
        return 0.0
    _, s, vt = np.linalg.svd(centred / scale, full_matrices=False)
    if s[-1] <= 1e-12 * s[0]:
        return 0.0
    across = centred @ vt[-1]
    return float(across.max() - across.min())
