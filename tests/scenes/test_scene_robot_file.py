"""A scene file's robot file: read from the scene file's own folder only (a scene file is untrusted), and written by
save_scene only where the file it writes reads it back (a robot file is not copied: outside the folder a scene is
saved in, the save is refused, nothing written). The command line's --robot is the user's and may be anywhere."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from snakehead import InputError, default_urdf_path
from snakehead.app.cli import main
from snakehead.model.robot_file import write_robot_file
from snakehead.scenes import Scene, Target, load_scene, save_scene, scene_from_dict, scene_to_toml

TARGET = (Target("t", [0.15, 0.51, 0.40], [0.0, 1.0, 0.0]),)
TARGET_TEXT = '''
[[targets]]
name = "t"
position = [0.15, 0.51, 0.40]
direction = [0.0, 1.0, 0.0]
'''


def robot(path: Path) -> Path:
    """A robot file at ``path`` (and its URDF beside it): the default robot without masses, so that a plan stops at
    once, saying "no mass", once the robot file has been read."""
    path.parent.mkdir(parents=True, exist_ok=True)
    urdf = path.with_suffix(".urdf")
    urdf.write_text(re.sub(r"<inertial>.*?</inertial>", "", default_urdf_path().read_text(), flags=re.S))
    return write_robot_file(path, urdf=urdf, base_end="base_end", neck_end="neck_end", head_tip="head_tip")


def scene_file(folder: Path, robot_name: str | None) -> Path:
    """A scene file in ``folder`` with one target, naming the robot file ``robot_name`` (as written; None: none)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "scene.toml"
    line = f'robot = "{robot_name}"\n' if robot_name is not None else ""
    path.write_text(line + TARGET_TEXT)
    return path


def escape(tmp_path: Path, how: str) -> tuple[Path, str]:
    """A scene file whose robot file lies outside its folder (by ``how``), and the name it gives it."""
    outside = robot(tmp_path / "elsewhere" / "snake.toml")
    folder = tmp_path / "scene"
    folder.mkdir()
    if how == "parent":
        name = "../elsewhere/snake.toml"
    elif how == "absolute":
        name = str(outside)
    elif how == "symlink":
        (folder / "snake.toml").symlink_to(outside)
        name = "snake.toml"
    else:
        (folder / "robots").symlink_to(outside.parent, target_is_directory=True)
        name = "robots/snake.toml"
    return scene_file(folder, name), name


HOWS = ["parent", "absolute", "symlink", "symlinked folder"]


# --- reading: the scene file's folder only -------------------------------------------------------------------------
@pytest.mark.parametrize("how", HOWS)
def test_a_robot_file_outside_the_scene_folder_is_refused(tmp_path: Path, how: str) -> None:
    path, name = escape(tmp_path, how)
    with pytest.raises(InputError) as caught:
        load_scene(path)
    text = str(caught.value)
    assert "\n" not in text and repr(os.fspath(path)) in text and ": robot:" in text and repr(name) in text, text
    assert "outside the scene file's folder" in text and "--robot" in text


@pytest.mark.parametrize("how", HOWS)
def test_a_robot_file_outside_the_scene_folder_is_exit_status_2(tmp_path: Path, how: str,
                                                                capsys: pytest.CaptureFixture) -> None:
    path, name = escape(tmp_path, how)
    out = tmp_path / "out"
    assert main(["plan", "--scene", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "outside the scene file's folder" in err and repr(name) in err and "robot" in err, err
    assert "Traceback" not in err and "no mass" not in err  # refused before the robot file is read
    assert not out.exists()


def test_the_command_refuses_it_in_a_process_of_its_own(tmp_path: Path) -> None:
    """`python -m snakehead plan --scene FILE --out DIR`: one error line, status 2, nothing written."""
    path, name = escape(tmp_path, "symlink")
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(path), "--out", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("snakehead plan: error: ") and "Traceback" not in r.stderr
    assert repr(os.fspath(path)) in line and ": robot:" in line and repr(name) in line
    assert not out.exists()


def test_a_scene_read_from_a_table_confines_its_robot_to_the_working_folder(tmp_path: Path,
                                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """scene_from_dict without a folder: the robot file's path is relative to the working folder, and inside it."""
    robot(tmp_path / "elsewhere" / "snake.toml")
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    table = {"robot": "../elsewhere/snake.toml", "targets": [{"name": "t", "position": [0.15, 0.51, 0.4],
                                                               "direction": [0.0, 1.0, 0.0]}]}
    with pytest.raises(InputError, match=r"robot: file '\.\./elsewhere/snake\.toml' is outside"):
        scene_from_dict(table)
    (tmp_path / "work" / "snake.toml").symlink_to(tmp_path / "elsewhere" / "snake.toml")
    with pytest.raises(InputError, match="is outside"):
        scene_from_dict({**table, "robot": "snake.toml"})
    robot(tmp_path / "work" / "own.toml")
    assert scene_from_dict({**table, "robot": "own.toml"}).robot_file == tmp_path / "work" / "own.toml"


def test_a_robot_file_inside_the_scene_folder_is_read(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """Beside the scene file, in a subfolder, through a link that stays inside: loaded, and planned with (its robot
    has no mass: the plan stops saying so, status 2, which it can only say once it read the robot file)."""
    folder = tmp_path / "scene"
    beside = robot(folder / "snake.toml")
    below = robot(folder / "robots" / "long.toml")
    (folder / "link.toml").symlink_to(below)
    for name, file in (("snake.toml", beside), ("robots/long.toml", below), ("./robots/../link.toml", below)):
        assert load_scene(scene_file(folder, name)).robot_file == file.resolve(), name
    assert main(["plan", "--scene", str(scene_file(folder, "robots/long.toml")), "--out", str(tmp_path / "out")]) == 2
    assert "no mass" in capsys.readouterr().err
    with pytest.raises(InputError, match="robot file .* does not exist"):
        load_scene(scene_file(folder, "missing.toml"))


def test_the_robot_option_may_name_a_robot_file_anywhere(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """--robot is the user's own (trusted): a robot file outside the scene's folder is read (and, here, found to have
    no mass), never refused as outside."""
    elsewhere = robot(tmp_path / "elsewhere" / "snake.toml")
    path = scene_file(tmp_path / "scene", None)
    assert main(["plan", "--scene", str(path), "--robot", str(elsewhere), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "no mass" in err and "outside" not in err


# --- writing: the robot file inside the folder the scene file goes in, or refused ---------------------------------
def test_a_scene_saved_where_its_robot_file_lies_names_it(tmp_path: Path) -> None:
    """In the robot file's folder or one above it the scene names it and reads back with it."""
    file = robot(tmp_path / "robots" / "snake.toml")
    scene = Scene(name="s", targets=TARGET, robot_file=file)
    for out, name in ((tmp_path / "robots" / "s.toml", "snake.toml"), (tmp_path / "s.toml", "robots/snake.toml")):
        assert f'robot = "{name}"' in save_scene(scene, out).read_text()
        assert load_scene(out).robot_file == file.resolve()
        assert f'robot = "{name}"' in scene_to_toml(scene, out.parent)


@pytest.mark.parametrize("how", ["other folder", "link out"])
def test_a_scene_saved_away_from_its_robot_file_is_refused_with_the_way_out(tmp_path: Path, how: str) -> None:
    """A robot file is a folder's worth (its URDF, meshes, map), not copied: the save is refused with one line saying
    what to do, before anything is written or copied (the scene's mesh file here), and naming no absolute path (the
    live viewer shows it to a browser)."""
    import trimesh

    from snakehead.geometry.obstacles import MeshObstacle

    file = robot(tmp_path / "robots" / "snake.toml")
    out = tmp_path / "out"
    out.mkdir()
    if how == "link out":  # a link in the output folder leads out of it: the written name would not load
        (out / "snake.toml").symlink_to(file)
        file = out / "snake.toml"
    trimesh.creation.box(extents=(0.2, 0.3, 0.25)).export(tmp_path / "rock.stl")
    rock = MeshObstacle.load(tmp_path / "rock.stl", [0.9, 0.3, 0.125])
    scene = Scene(name="s", targets=TARGET, obstacles=(rock,), robot_file=file)
    before = sorted(p.name for p in out.iterdir())
    for write in (lambda: save_scene(scene, out / "s.toml"), lambda: scene_to_toml(scene, out)):
        with pytest.raises(InputError) as caught:
            write()
        text = str(caught.value)
        assert "\n" not in text and "scene 's'" in text and "'../robots/snake.toml'" in text, text
        assert "robot file's folder" in text and "robot_file=None" in text and "--robot" in text, text
        assert str(tmp_path) not in text
    assert sorted(p.name for p in out.iterdir()) == before  # no scene file, no copy of the mesh
    # without its robot, it saves (the robot given when planning)
    import dataclasses

    save_scene(dataclasses.replace(scene, robot_file=None), out / "s.toml")
    assert load_scene(out / "s.toml").robot_file is None


@pytest.mark.parametrize("key", ["urdf", "packages"])
def test_a_robot_file_in_the_scenes_folder_reads_nothing_outside_it(tmp_path: Path, key: str):
    """A robot file beside the scene file is untrusted too: its urdf (and map, packages) must lie in the scene's
    folder; the same robot file given by the user (--robot) may name files anywhere."""
    import snakehead

    outside = tmp_path / "elsewhere"
    outside.mkdir()
    urdf = outside / "snake.urdf"
    urdf.write_text(default_urdf_path().read_text())
    folder = tmp_path / "scene"
    folder.mkdir()
    lines = ['base_end = "base_end"', 'neck_end = "neck_end"', 'head_tip = "head_tip"']
    if key == "urdf":
        lines.insert(0, 'urdf = "../elsewhere/snake.urdf"')
    else:
        (folder / "snake.urdf").write_text(default_urdf_path().read_text())
        lines = ['urdf = "snake.urdf"'] + lines + ["", "[packages]", 'meshes = "../elsewhere"']
    (folder / "snake.toml").write_text("\n".join(lines) + "\n")
    scene = scene_file(folder, "snake.toml")
    with pytest.raises(InputError, match=f"its {key}.*outside the folder"):
        snakehead.plan(scene)
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(scene), "--out",
                        str(tmp_path / "out"), "--no-sim"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "outside the folder" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    # the user's own robot file may read from anywhere
    assert snakehead.SnakeRobot.from_file(folder / "snake.toml").n_joints == 16
