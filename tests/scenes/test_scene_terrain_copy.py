"""A scene's terrain file (a heightfield's .npy or PNG, a mesh terrain's OBJ/STL/PLY) saved into another folder: copied
beside the new scene file as its mesh obstacles' are (scenes.scene.with_meshes_in), so that the file written reads
back as the same ground (the same signed distances), never over another file."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from snakehead import InputError
from snakehead.scenes import load_scene, save_scene, scene_to_toml, with_meshes_in

trimesh = pytest.importorskip("trimesh")

TARGET = '''
[[targets]]
name = "t"
position = [0.2, 0.5, 0.3]
direction = [0.0, 1.0, 0.0]
'''
TABLES = {
    "npy": ("ground.npy", 'kind = "heightfield"\nfile = "{file}"\nextent = [2.0, 3.0]\norigin = [-1.0, -1.5, 0.0]\n'),
    "png": ("ground.png", 'kind = "heightfield"\nfile = "{file}"\nheight_scale = 1e-5\nextent = [2.0, 2.0]\n'),
    "mesh": ("rocks.stl", 'kind = "mesh"\nfile = "{file}"\nscale = 0.5\n'),
}
POINTS = np.random.default_rng(0).uniform(-1, 1, (300, 3))


def terrain_file(path: Path, kind: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "npy":
        np.save(path, np.random.default_rng(1).uniform(-0.05, 0.05, (20, 30)))
    elif kind == "png":
        Image.fromarray(np.arange(12, dtype=np.uint16).reshape(3, 4) * 1000).save(path)
    else:
        trimesh.creation.box((2.0, 2.0, 0.2)).export(path)
    return path


def scene_file(folder: Path, kind: str, file: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "scene.toml"
    path.write_text(TARGET + "\n[terrain]\n" + TABLES[kind][1].format(file=file))
    return path


def same_ground(a, b) -> None:
    assert type(a) is type(b)
    assert np.array_equal(a.signed_distance(POINTS), b.signed_distance(POINTS))


@pytest.mark.parametrize("kind", sorted(TABLES))
def test_a_scene_saved_in_another_folder_copies_its_terrain_file(tmp_path: Path, kind: str) -> None:
    name = TABLES[kind][0]
    source = terrain_file(tmp_path / "scene" / "ground" / name, kind)
    first = load_scene(scene_file(tmp_path / "scene", kind, f"ground/{name}"))
    out = tmp_path / "out" / "saved.toml"
    out.parent.mkdir()
    text = save_scene(first, out).read_text()
    assert f'file = "{name}"' in text and "../" not in text
    assert (out.parent / name).read_bytes() == source.read_bytes()
    again = load_scene(out)
    same_ground(again.terrain, first.terrain)
    assert again.terrain.source == (out.parent / name).resolve()
    # saved again (there, or beside it): the same copy, no second one
    save_scene(first, out.parent / "twice.toml")
    save_scene(again, out)
    assert sorted(p.name for p in out.parent.iterdir()) == sorted([name, "saved.toml", "twice.toml"])
    # saved in its own folder: nothing copied, its name as it was
    assert f'file = "ground/{name}"' in save_scene(first, tmp_path / "scene" / "copy.toml").read_text()
    assert sorted(p.name for p in (tmp_path / "scene").iterdir()) == ["copy.toml", "ground", "scene.toml"]
    same_ground(load_scene(tmp_path / "scene" / "copy.toml").terrain, first.terrain)


def test_a_terrain_copy_never_replaces_another_file(tmp_path: Path) -> None:
    """A different file, and a link, of the terrain file's name in the output folder are left alone: the copy takes
    the next free name; the scene file's own name is not taken either; no temporary file is left."""
    terrain_file(tmp_path / "scene" / "ground.npy", "npy")
    first = load_scene(scene_file(tmp_path / "scene", "npy", "ground.npy"))
    out = tmp_path / "out"
    out.mkdir()
    (out / "ground.npy").write_text("someone else's file")
    (out / "ground-2.npy").symlink_to(tmp_path / "scene" / "ground.npy")  # never named, nor written through
    text = save_scene(first, out / "ground-3.npy").read_text()  # the scene file named as the next copy would be
    assert 'file = "ground-4.npy"' in text
    assert (out / "ground.npy").read_text() == "someone else's file"
    assert (out / "ground-2.npy").is_symlink()
    assert os.readlink(out / "ground-2.npy") == str(tmp_path / "scene" / "ground.npy")
    same_ground(load_scene(out / "ground-3.npy").terrain, first.terrain)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
    before = (tmp_path / "scene" / "ground.npy").read_bytes()
    with pytest.raises(InputError, match="it is the scene's terrain file"):
        save_scene(first, tmp_path / "scene" / "ground.npy")
    assert (tmp_path / "scene" / "ground.npy").read_bytes() == before


def test_one_file_for_the_terrain_and_a_mesh_obstacle_is_copied_once(tmp_path: Path) -> None:
    terrain_file(tmp_path / "scene" / "rocks.stl", "mesh")
    path = scene_file(tmp_path / "scene", "mesh", "rocks.stl")
    path.write_text(path.read_text() + '\n[[obstacles]]\nkind = "mesh"\nfile = "rocks.stl"\nposition = [0.9, 0.3, 0.1]\n')
    first = load_scene(path)
    (tmp_path / "moved").mkdir()
    moved = with_meshes_in(first, tmp_path / "moved")  # the working API: the scene with its files in the folder
    assert moved.terrain.source == moved.obstacles[0].path == tmp_path / "moved" / "rocks.stl"
    same_ground(moved.terrain, first.terrain)
    assert sorted(p.name for p in (tmp_path / "moved").iterdir()) == ["rocks.stl"]
    (tmp_path / "out").mkdir()
    text = save_scene(first, tmp_path / "out" / "s.toml").read_text()
    assert text.count('file = "rocks.stl"') == 2
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["rocks.stl", "s.toml"]


def test_the_text_of_a_scene_names_no_terrain_file_outside_its_folder(tmp_path: Path) -> None:
    """scene_to_toml writes only what load_scene reads: a terrain file outside the folder is refused with the way
    out; a scene that cannot be saved copies nothing."""
    terrain_file(tmp_path / "scene" / "ground.npy", "npy")
    first = load_scene(scene_file(tmp_path / "scene", "npy", "ground.npy"))
    (tmp_path / "out").mkdir()
    with pytest.raises(InputError, match=r"terrain.*outside.*save_scene copies it") as caught:
        scene_to_toml(first, tmp_path / "out")
    assert "\n" not in str(caught.value)
    assert 'file = "ground.npy"' in scene_to_toml(first, tmp_path / "scene")
    with pytest.raises(InputError, match="cannot write"):
        save_scene(first, tmp_path / "missing" / "s.toml")
    assert not (tmp_path / "missing").exists() and not any((tmp_path / "out").iterdir())
