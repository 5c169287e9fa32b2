"""A scene file's mesh obstacles: read from the scene file's own folder only (a scene file is untrusted), and copied
into the folder a scene is saved in, so that the file written reads back (the obstacle's hull the same)."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from snakehead import InputError
from snakehead._files import write_new_file
from snakehead.app.cli import main
from snakehead.geometry.obstacles import MeshObstacle
from snakehead.scenes import Scene, Target, load_scene, save_scene, scene_to_toml, with_meshes_in

TARGET = (Target("t", [0.15, 0.51, 0.40], [0.0, 1.0, 0.0]),)


def rock(path: Path, extents: tuple[float, float, float] = (0.2, 0.3, 0.25)) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=extents).export(path)
    return path


def scene_file(folder: Path, mesh: str) -> Path:
    """A scene file in ``folder`` with one target and one mesh obstacle, its file ``mesh`` (as written)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "scene.toml"
    path.write_text(f'''
[[targets]]
name = "t"
position = [0.15, 0.51, 0.40]
direction = [0.0, 1.0, 0.0]

[[obstacles]]
kind = "mesh"
file = "{mesh}"
position = [0.9, 0.3, 0.125]
''')
    return path


# --- reading: the scene file's folder only -------------------------------------------------------------------------
@pytest.mark.parametrize("how", ["parent", "absolute", "symlink", "symlinked folder"])
def test_a_mesh_outside_the_scene_folder_is_refused(tmp_path: Path, how: str) -> None:
    outside = rock(tmp_path / "elsewhere" / "rock.stl")
    folder = tmp_path / "scene"
    folder.mkdir()
    if how == "parent":
        name = "../elsewhere/rock.stl"
    elif how == "absolute":
        name = str(outside)
    elif how == "symlink":
        (folder / "link.stl").symlink_to(outside)
        name = "link.stl"
    else:
        (folder / "meshes").symlink_to(outside.parent, target_is_directory=True)
        name = "meshes/rock.stl"
    path = scene_file(folder, name)
    with pytest.raises(InputError) as caught:
        load_scene(path)
    text = str(caught.value)
    assert "\n" not in text and repr(os.fspath(path)) in text and "obstacles[0]" in text and repr(name) in text
    assert "outside the scene file's folder" in text


def test_a_mesh_outside_the_scene_folder_is_exit_status_2(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    rock(tmp_path / "rock.stl")
    path = scene_file(tmp_path / "scene", "../rock.stl")
    assert main(["plan", "--scene", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "outside the scene file's folder" in err and "'../rock.stl'" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_mesh_inside_the_scene_folder_is_read(tmp_path: Path) -> None:
    """A file of the folder, one of a subfolder, and a link that stays inside the folder are read."""
    folder = tmp_path / "scene"
    rock(folder / "rock.stl")
    rock(folder / "meshes" / "stone.stl")
    (folder / "link.stl").symlink_to(folder / "meshes" / "stone.stl")
    for name in ("rock.stl", "meshes/stone.stl", "./meshes/../link.stl"):
        (ob,) = load_scene(scene_file(folder, name)).obstacles
        assert isinstance(ob, MeshObstacle) and len(ob.vertices) == 8


# --- writing: a scene saved elsewhere takes a copy of its meshes ---------------------------------------------------
def test_a_scene_saved_in_another_folder_copies_its_mesh(tmp_path: Path) -> None:
    rock(tmp_path / "scene" / "meshes" / "rock.stl")
    first = load_scene(scene_file(tmp_path / "scene", "meshes/rock.stl"))
    out = tmp_path / "out" / "saved.toml"
    out.parent.mkdir()
    text = save_scene(first, out).read_text()
    assert 'file = "rock.stl"' in text
    assert (out.parent / "rock.stl").read_bytes() == (tmp_path / "scene" / "meshes" / "rock.stl").read_bytes()
    again = load_scene(out)
    np.testing.assert_array_equal(again.obstacles[0].vertices, first.obstacles[0].vertices)
    np.testing.assert_array_equal(again.obstacles[0].pose, first.obstacles[0].pose)
    # saved again (there, or beside it): the same copy, no second one
    save_scene(first, out.parent / "twice.toml")
    save_scene(again, out)
    assert sorted(p.name for p in out.parent.iterdir()) == ["rock.stl", "saved.toml", "twice.toml"]
    # saved in its own folder: nothing copied, its name as it was
    assert 'file = "meshes/rock.stl"' in save_scene(first, tmp_path / "scene" / "copy.toml").read_text()
    assert sorted(p.name for p in (tmp_path / "scene").iterdir()) == ["copy.toml", "meshes", "scene.toml"]


def test_a_copy_never_replaces_another_file(tmp_path: Path) -> None:
    """A different file (or a link) of the mesh's name in the output folder is left alone: the copy takes the next
    free name; two meshes of one name from two folders get two copies."""
    big = MeshObstacle.load(rock(tmp_path / "a" / "rock.stl", (0.4, 0.4, 0.4)), [0.9, 0.3, 0.2])
    small = MeshObstacle.load(rock(tmp_path / "b" / "rock.stl"), [0.9, -0.3, 0.2])
    out = tmp_path / "out"
    out.mkdir()
    (out / "rock.stl").write_text("someone else's file")
    (out / "rock-2.stl").symlink_to(tmp_path / "a" / "rock.stl")  # a link out is never named, nor written through
    scene = Scene(name="two", targets=TARGET, obstacles=(big, small, big))
    text = save_scene(scene, out / "two.toml").read_text()
    assert (out / "rock.stl").read_text() == "someone else's file"
    assert (out / "rock-2.stl").is_symlink() and os.readlink(out / "rock-2.stl") == str(tmp_path / "a" / "rock.stl")
    assert text.count('file = "rock-3.stl"') == 2 and text.count('file = "rock-4.stl"') == 1
    again = load_scene(out / "two.toml")
    for a, b in zip(again.obstacles, scene.obstacles):
        np.testing.assert_array_equal(a.vertices, b.vertices)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_a_copy_is_named_portably(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    odd = MeshObstacle.load(rock(tmp_path / "in" / "CON .rock é.stl"), [0.9, 0.3, 0.2])
    nul = MeshObstacle.load(rock(tmp_path / "in" / "nul.stl"), [0.9, 0.3, 0.2])
    moved = with_meshes_in(Scene(name="odd", targets=TARGET, obstacles=(odd, nul)), out)
    assert [ob.path.name for ob in moved.obstacles] == ["CON_rock.stl", "mesh_nul.stl"]
    assert sorted(p.name for p in out.iterdir()) == ["CON_rock.stl", "mesh_nul.stl"]


def test_the_text_of_a_scene_names_no_mesh_outside_its_folder(tmp_path: Path) -> None:
    """scene_to_toml writes only what load_scene reads: a mesh outside the folder is refused, with the way out."""
    ob = MeshObstacle.load(rock(tmp_path / "meshes" / "rock.stl"), [0.9, 0.3, 0.2])
    scene = Scene(name="s", targets=TARGET, obstacles=(ob,))
    (tmp_path / "out").mkdir()
    with pytest.raises(InputError, match=r"obstacles\[0\].*outside.*save_scene copies it"):
        scene_to_toml(scene, tmp_path / "out")
    assert 'file = "meshes/rock.stl"' in scene_to_toml(scene, tmp_path)
    assert not (tmp_path / "out" / "rock.stl").exists()


def test_a_scene_that_cannot_be_saved_copies_nothing(tmp_path: Path) -> None:
    ob = MeshObstacle.load(rock(tmp_path / "meshes" / "rock.stl"), [0.9, 0.3, 0.2])
    with pytest.raises(InputError, match="cannot write"):
        save_scene(Scene(name="s", targets=TARGET, obstacles=(ob,)), tmp_path / "missing" / "s.toml")
    assert not (tmp_path / "missing").exists()
    tilted = MeshObstacle(ob.path, np.array([[1, 0, 0, 0.9], [0, 0, -1, 0.3], [0, 1, 0, 0.2], [0, 0, 0, 1.0]]),
                          ob.scale, ob.vertices)
    (tmp_path / "out").mkdir()
    with pytest.raises(InputError, match="turned other than about the world z-axis"):
        save_scene(Scene(name="s", targets=TARGET, obstacles=(tilted,)), tmp_path / "out" / "s.toml")
    assert not any((tmp_path / "out").iterdir())


def test_write_new_file_writes_over_nothing(tmp_path: Path) -> None:
    assert write_new_file(tmp_path / "a.bin", b"first").read_bytes() == b"first"
    (tmp_path / "link").symlink_to(tmp_path / "nowhere")
    for name in ("a.bin", "link"):
        with pytest.raises(FileExistsError):
            write_new_file(tmp_path / name, b"second")
    assert (tmp_path / "a.bin").read_bytes() == b"first" and not (tmp_path / "nowhere").exists()
    with pytest.raises(InputError, match="cannot write"):
        write_new_file(tmp_path / "missing" / "b.bin", b"x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.bin", "link"]


def test_a_scene_file_is_never_written_over_its_mesh(tmp_path: Path) -> None:
    """Named as its mesh's copy would be, the scene file keeps its name and the copy takes the next; named as its
    mesh file itself, it is refused (the mesh left as it was)."""
    ob = MeshObstacle.load(rock(tmp_path / "meshes" / "rock.stl"), [0.9, 0.3, 0.2])
    scene = Scene(name="s", targets=TARGET, obstacles=(ob,))
    (tmp_path / "out").mkdir()
    assert 'file = "rock-2.stl"' in save_scene(scene, tmp_path / "out" / "rock.stl").read_text()
    np.testing.assert_array_equal(load_scene(tmp_path / "out" / "rock.stl").obstacles[0].vertices, ob.vertices)
    before = ob.path.read_bytes()
    with pytest.raises(InputError, match="it is the scene's mesh file"):
        save_scene(scene, ob.path)
    assert ob.path.read_bytes() == before
