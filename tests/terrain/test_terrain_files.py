"""Terrain files: .npy and 16-bit PNG heightfields and OBJ/STL/PLY surfaces read as written, and every bad file an
InputError naming it; the generated terrains against their formulas."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from snakehead._errors import InputError
from snakehead.limits import MAX_TERRAIN_CELLS
from snakehead.terrain import HeightfieldTerrain, MeshTerrain, egg_crate, slope, step, undulating
from snakehead.terrain.terrain_files import read_heights, read_mesh_surface

trimesh = pytest.importorskip("trimesh")


def test_npy_heights(tmp_path: Path):
    h = np.random.default_rng(0).uniform(-0.1, 0.1, (5, 4))
    np.save(tmp_path / "g.npy", h)
    assert np.array_equal(read_heights(tmp_path / "g.npy", "here"), h)
    np.save(tmp_path / "f.npy", h.astype(np.float32))
    assert np.array_equal(read_heights(tmp_path / "f.npy", "here"), h.astype(np.float32).astype(float))


def test_png_heights_are_seen_from_above(tmp_path: Path):
    levels = np.array([[0, 1000, 2000], [3000, 4000, 65535]], dtype=np.uint16)  # 2 rows (y), 3 columns (x)
    Image.fromarray(levels).save(tmp_path / "g.png")
    h = read_heights(tmp_path / "g.png", "here", height_scale=0.001)
    assert h.shape == (3, 2)  # (nx, ny)
    assert np.allclose(h[:, 1], levels[0] * 0.001)  # the top row is the largest y
    assert np.allclose(h[:, 0], levels[1] * 0.001)


def test_mesh_surfaces(tmp_path: Path):
    box = trimesh.creation.box((1.0, 2.0, 3.0))
    for suffix in ("obj", "stl", "ply"):
        path = tmp_path / f"box.{suffix}"
        box.export(path)
        v, f = read_mesh_surface(path, "here", scale=2.0)
        terrain = MeshTerrain(v, f)
        assert np.isclose(terrain.height([0.1, 0.2]), 3.0)  # the top face, scaled
        assert np.isclose(terrain.signed_distance([0.0, 0.0, 4.0]), 1.0)


def bad_files(folder: Path) -> dict[str, tuple[Path, float | None]]:
    """Files each reader must refuse, by what is wrong."""
    np.save(folder / "ints.npy", np.zeros((3, 3), dtype=np.int32))
    np.save(folder / "nan.npy", np.array([[0.0, np.nan], [0.0, 0.0]]))
    np.save(folder / "flat.npy", np.zeros(3))
    np.save(folder / "objects.npy", np.array([[None, 1], [2, 3]], dtype=object), allow_pickle=True)
    (folder / "garbage.npy").write_bytes(b"not an array at all")
    Image.fromarray(np.zeros((4, 4), dtype=np.uint8)).save(folder / "eight.png")
    Image.fromarray(np.zeros((4, 4, 3), dtype=np.uint8)).save(folder / "rgb.png")
    (folder / "garbage.png").write_bytes(b"\x89PNG but not")
    side = int(np.sqrt(MAX_TERRAIN_CELLS)) + 2
    Image.fromarray(np.zeros((side, side), dtype=np.uint16)).save(folder / "huge.png")
    (folder / "empty.stl").write_bytes(b"")
    (folder / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    (folder / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    return {"wrong dtype": (folder / "ints.npy", None), "NaN": (folder / "nan.npy", None),
            "not 2-D": (folder / "flat.npy", None), "pickled objects": (folder / "objects.npy", None),
            "not .npy": (folder / "garbage.npy", None), "8-bit PNG": (folder / "eight.png", 0.001),
            "colour PNG": (folder / "rgb.png", 0.001), "not PNG": (folder / "garbage.png", 0.001),
            "too many cells": (folder / "huge.png", 0.001), "PNG without a scale": (folder / "eight.png", None),
            "empty mesh": (folder / "empty.stl", None), "no triangles": (folder / "points.obj", None),
            "no area": (folder / "flat.obj", None), "missing": (folder / "nothing.npy", None),
            "unknown suffix": (folder / "g.tif", None)}


def test_bad_files_are_input_errors_naming_them(tmp_path: Path):
    for what, (path, scale) in bad_files(tmp_path).items():
        with pytest.raises(InputError) as info:
            if path.suffix in (".stl", ".obj"):
                read_mesh_surface(path, "scene.toml: [terrain]")
            else:
                read_heights(path, "scene.toml: [terrain]", scale)
        message = str(info.value)
        assert path.name in message and "scene.toml: [terrain]" in message and "\n" not in message, (what, message)


def test_npy_message_names_the_shape(tmp_path: Path):
    np.save(tmp_path / "heightfield.npy", np.zeros(3))
    with pytest.raises(InputError, match=r"^scene.toml: \[terrain\] heightfield.npy: expected a 2-D array of finite "
                                         r"heights, got shape \(3,\)"):
        read_heights(tmp_path / "heightfield.npy", "scene.toml: [terrain]")


def test_generated_terrains_are_their_formulas():
    xy = np.random.default_rng(1).uniform(-1.5, 1.5, (300, 2))
    s = slope(10.0, heading_deg=30.0, point=(0.1, 0.2, 0.3))
    h = np.radians(30.0)
    expected = 0.3 + np.tan(np.radians(10.0)) * ((xy[:, 0] - 0.1) * np.cos(h) + (xy[:, 1] - 0.2) * np.sin(h))
    assert np.allclose(s.height(xy), expected, atol=1e-12)
    u = undulating(0.03, 0.4, heading_deg=45.0, extent=(3.2, 3.2), spacing=0.004)
    formula = 0.03 * np.sin(2 * np.pi * (xy[:, 0] + xy[:, 1]) * np.cos(np.pi / 4) / 0.4)
    bound = 0.03 * (np.pi * 0.004 * np.sqrt(2) / 0.4) ** 2  # linear interpolation's error on the cell's diagonal
    assert np.all(np.abs(u.height(xy) - formula) <= bound)
    e = egg_crate(0.02, 0.5, spacing=0.005)
    grid_points = np.array([[0.125, 0.125], [0.125, -0.125], [0.0, 0.3]])
    assert np.allclose(e.height(grid_points), [0.02, -0.02, 0.0], atol=1e-12)
    assert isinstance(u, HeightfieldTerrain)
    stair = step(0.08, heading_deg=180.0)
    assert np.allclose(stair.height([[0.5, 0.0], [-0.5, 0.0]]), [0.0, 0.08])


def test_generated_grid_is_bounded():
    with pytest.raises(InputError, match="MAX_TERRAIN_CELLS"):
        egg_crate(0.02, 0.5, extent=(100.0, 100.0), spacing=0.01)
