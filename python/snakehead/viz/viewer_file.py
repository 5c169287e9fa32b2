"""``NAME_viewer.npz``: a :class:`~.viewer_arrays.ViewerScene` in a file (``numpy.load`` reads it), written by
``snakehead plan`` and ``snakehead demo`` beside each scenario's outputs and served by ``snakehead view DIR``.

:func:`load_viewer_scene` takes a file from anywhere: it checks every array's kind and shape against the others,
that numbers are finite and indices point inside what they index, and that names are plain text, before the
viewer draws anything of it.

Two formats: a scene on flat ground without terrain is written as format 2, as before slopes (the same file); a
scene on a slope or with a terrain as format 3, which adds the ground fields (the ground frame's world pose, the
terrain's triangles: :data:`~.viewer_arrays.GROUND_FIELDS`), so that a reader of format 2 refuses it rather than
drawing a slope flat. Both are read.
"""
from __future__ import annotations

import os
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import InputError
from .._files import atomic_open, read_npz
from .._validate import display_text, name_text
from .viewer_arrays import GROUND_FIELDS, ViewerScene

__all__ = ["SCENE_SUFFIX", "SCENE_FORMAT", "FLAT_SCENE_FORMAT", "MAX_SCENE_BYTES", "save_viewer_scene", "load_viewer_scene", "scenes_in"]

#: What :func:`save_viewer_scene` appends to a scenario's name.
SCENE_SUFFIX = "_viewer.npz"
#: Format of ``NAME_viewer.npz`` on a slope or a terrain (stored in the file; :func:`load_viewer_scene` reads it and
#: :data:`FLAT_SCENE_FORMAT`, and refuses other versions).
SCENE_FORMAT = 3
#: Format of a scene on flat ground without terrain: format 3 without the ground fields.
FLAT_SCENE_FORMAT = 2


def save_viewer_scene(scene: ViewerScene, path: str | Path) -> Path:
    """Write ``scene`` as a compressed ``.npz`` (atomically); returns the path. Format 2 on flat ground without
    terrain, else 3 (see the module)."""
    path = Path(path)
    flat = scene.flat
    arrays = {f.name: np.asarray(getattr(scene, f.name)) for f in fields(scene)
              if not (flat and f.name in GROUND_FIELDS)}
    arrays["format"] = np.asarray(FLAT_SCENE_FORMAT if flat else SCENE_FORMAT)
    with atomic_open(path, "wb") as f:
        np.savez_compressed(f, **arrays)  # type: ignore[arg-type]
    return path


#: The largest viewer scene read (bytes, unpacked): a scene of 2000 frames of a 100-link robot is ~20 MB.
MAX_SCENE_BYTES = 512 << 20

#: Each array of a viewer scene: its dtype kind ("f" numbers, "i" integers, "U" text) and its shape, in symbols
#: that must agree across arrays (F frames, K shapes, G1 = G + 1 for G meshes of MV vertices and MT triangles, V voxels,
#: Z ZMP samples, P polygons of M vertices, N targets, B obstacle boxes, W wall vertices, T wall triangles, H hole rims
#: of R points).
_SCENE_ARRAYS = {
    "name": ("U", ()), "title": ("U", ()), "times": ("f", ("F",)), "shape_positions": ("f", ("F", "K", 3)),
    "shape_wxyz": ("f", ("F", "K", 4)), "shape_scales": ("f", ("K", 3)), "shape_colors": ("i", ("K", 3)),
    "shape_mesh": ("i", ("K",)), "mesh_vertices": ("f", ("MV", 3)), "mesh_triangles": ("i", ("MT", 3)),
    "mesh_vertex_starts": ("i", ("G1",)), "mesh_triangle_starts": ("i", ("G1",)),
    "head_tip": ("f", ("F", 3)), "map_frame_positions": ("f", ("F", 3)), "map_frame_wxyz": ("f", ("F", 4)),
    "voxel_centers": ("f", ("V", 3)), "voxel_indices": ("f", ("V",)), "voxel_size": ("f", ()),
    "zmp": ("f", ("F", 2)), "com": ("f", ("F", 3)), "zmp_path": ("f", ("Z", 2)), "polygons": ("f", ("P", "M", 2)),
    "polygon_of_frame": ("i", ("F",)), "target_positions": ("f", ("N", 3)), "target_directions": ("f", ("N", 3)),
    "target_names": ("U", ("N",)), "target_diameters": ("f", ("N",)), "obstacle_centres": ("f", ("B", 3)),
    "obstacle_sizes": ("f", ("B", 3)), "obstacle_wxyz": ("f", ("B", 4)), "wall_vertices": ("f", ("W", 3)),
    "wall_triangles": ("i", ("T", 3)), "hole_rims": ("f", ("H", "R", 3)),
    "ground_pose": ("f", (4, 4)), "terrain_vertices": ("f", ("TV", 3)), "terrain_triangles": ("i", ("TT", 3)),
}
#: Arrays that may hold NaN (polygons are NaN-padded; a target without a diameter is an arrow).
_SCENE_NAN_ALLOWED = ("polygons", "target_diameters")


def _check_scene_arrays(where: str, values: dict[str, np.ndarray]) -> None:
    """ValueError naming the array unless every array has its kind and a shape consistent with the others, numbers
    are finite (where NaN means nothing) and indices point inside what they index."""
    sizes: dict[str, int] = {}
    for key, (kind, shape) in _SCENE_ARRAYS.items():
        a = values[key]
        if not (a.dtype.kind == kind or (kind == "f" and a.dtype.kind in "iu") or (kind == "i" and a.dtype.kind == "u")):
            raise InputError(f"{where}: {key} holds {a.dtype}, not {dict(f='numbers', i='integers', U='text')[kind]}")
        if a.ndim != len(shape):
            raise InputError(f"{where}: {key} has shape {a.shape}, expected {len(shape)} dimensions")
        for d, want in zip(a.shape, shape):
            if isinstance(want, int) and d != want or isinstance(want, str) and sizes.setdefault(want, d) != d:
                raise InputError(f"{where}: {key} has shape {a.shape}, which disagrees with the other arrays")
        if kind == "f" and key not in _SCENE_NAN_ALLOWED and not np.all(np.isfinite(a)):
            raise InputError(f"{where}: {key} holds NaN or inf")
    if sizes["F"] < 1 or np.any(np.diff(values["times"]) < 0):
        raise InputError(f"{where}: times must be at least one time, in order")
    for key, bound in (("polygon_of_frame", "P"), ("wall_triangles", "W"), ("terrain_triangles", "TV")):
        a = values[key]
        if a.size and (a.min() < 0 or a.max() >= sizes[bound]):
            raise InputError(f"{where}: {key} points outside its {sizes[bound]} entries")
    vs, ts = values["mesh_vertex_starts"], values["mesh_triangle_starts"]
    if (sizes["G1"] < 1 or vs[0] != 0 or ts[0] != 0 or vs[-1] != sizes["MV"] or ts[-1] != sizes["MT"]
            or np.any(np.diff(vs) < 0) or np.any(np.diff(ts) < 0)):
        raise InputError(f"{where}: mesh_vertex_starts / mesh_triangle_starts must run in order from 0 to the number "
                         "of mesh vertices / triangles")
    mesh = values["shape_mesh"]
    if mesh.size and (mesh.min() < 0 or mesh.max() >= sizes["G1"] - 1):
        raise InputError(f"{where}: shape_mesh points outside its {sizes['G1'] - 1} meshes")
    for g in range(sizes["G1"] - 1):
        tri = values["mesh_triangles"][ts[g]:ts[g + 1]]
        if tri.size and (tri.min() < 0 or tri.max() >= vs[g + 1] - vs[g]):
            raise InputError(f"{where}: mesh_triangles of mesh {g} point outside its {vs[g + 1] - vs[g]} vertices")
    if np.any((values["voxel_indices"] < 0) | (values["voxel_indices"] > 100)) or not values["voxel_size"] >= 0:
        raise InputError(f"{where}: voxel_indices must be within [0, 100] and voxel_size >= 0")
    G = np.asarray(values["ground_pose"], float)
    R = G[:3, :3]
    if not (np.allclose(R.T @ R, np.eye(3), atol=1e-9) and np.linalg.det(R) > 0 and np.array_equal(G[3], [0, 0, 0, 1])):
        raise InputError(f"{where}: ground_pose must be a rigid transform (a rotation and a translation)")


def load_viewer_scene(path: str | Path) -> ViewerScene:
    """Read a scene written by :func:`save_viewer_scene`: ValueError if the file is not one, is damaged (see
    ``snakehead._files.read_npz``) or its arrays disagree (shapes, kinds, indices)."""
    where = f"{os.fspath(path)}"
    contents = read_npz(path, "viewer scene", max_bytes=MAX_SCENE_BYTES)
    version = contents.pop("format", None)
    formats = (FLAT_SCENE_FORMAT, SCENE_FORMAT)
    if version is None or version.shape != () or version.dtype.kind not in "iu" or int(version) not in formats:
        raise InputError(f"{where}: not a viewer scene of format {FLAT_SCENE_FORMAT} or {SCENE_FORMAT} (format "
                         f"{version!r})")
    names = {f.name for f in fields(ViewerScene)}
    if int(version) == FLAT_SCENE_FORMAT:  # flat ground, no terrain: the ground fields at their defaults
        names -= set(GROUND_FIELDS)
    missing = names - set(contents)
    if missing:
        raise InputError(f"{where}: viewer scene without {sorted(missing)}")
    values: dict[str, Any] = {k: contents[k] for k in names}
    flat: dict[str, Any] = {"ground_pose": np.eye(4), "terrain_vertices": np.zeros((0, 3)),  # a format-2 scene's ground
                            "terrain_triangles": np.zeros((0, 3), np.int32)}
    _check_scene_arrays(where, {**flat, **values})
    values["name"] = name_text(str(values["name"]), f"{where}: name")
    values["title"] = display_text(str(values["title"]), f"{where}: title")
    for k, target in enumerate(values["target_names"].tolist()):
        name_text(target, f"{where}: target_names[{k}]")
    values["voxel_size"] = float(values["voxel_size"])
    return ViewerScene(**values)


def scenes_in(directory: str | Path) -> list[Path]:
    """The viewer scenes (``*_viewer.npz``) in the output folder of ``snakehead plan`` or ``demo``, sorted."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"{directory} is not a directory")
    return sorted(directory.glob("*" + SCENE_SUFFIX))
