"""A scene file's [terrain] table: each kind read and written back; a scene without one is as before (flat
ground); every bad table, and every file outside the scene's folder, an InputError of one line naming the file
and the field."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from snakehead._errors import InputError
from snakehead.scenes.scene import load_scene, paper_scene, save_scene, scene_to_toml
from snakehead.terrain import FlatGround, HeightfieldTerrain, MeshTerrain, PlaneTerrain, StepsTerrain

trimesh = pytest.importorskip("trimesh")

TARGET = '''
[[targets]]
name = "t"
position = [0.2, 0.5, 0.3]
direction = [0.0, 1.0, 0.0]
'''


def scene(folder: Path, terrain: str, name: str = "scene.toml") -> Path:
    path = folder / name
    path.write_text(TARGET + "\n[terrain]\n" + terrain)
    return path


def test_a_scene_without_terrain_is_flat():
    for name in ("spheres", "hole"):
        s = paper_scene(name)
        assert s.terrain == FlatGround()
        assert "[terrain]" not in scene_to_toml(s)


def test_the_shipped_slope():
    s = load_scene(Path(__import__("snakehead.scenes", fromlist=["x"]).__file__).with_name("slope.toml"))
    assert isinstance(s.terrain, PlaneTerrain)
    assert np.isclose(s.terrain.height([1.0, 0.0]), np.tan(np.radians(5.0)))


def test_planning_on_a_terrain_other_than_a_plane_is_refused_not_planned_on_flat_ground(tmp_path: Path):
    """The planner plans on flat ground, on planes and at the foot of a staircase up
    (tests/planning/test_plan_on_slope.py, test_plan_at_a_step.py); a scene on a heightfield or mesh is refused
    with a line saying so (CLI exit 2), never planned as if the ground were
    flat."""
    import subprocess
    import sys

    import snakehead

    np.save(tmp_path / "h.npy", np.zeros((4, 4)))
    path = scene(tmp_path, 'kind = "heightfield"\nfile = "h.npy"\nextent = [1.0, 1.0]\n')
    with pytest.raises(InputError, match="plans on flat ground, on planes and at the foot"):
        snakehead.plan(path)
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(path), "--out", str(tmp_path / "out")],
                       capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 2, r.stderr
    assert "plans on flat ground, on planes and at the foot" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())  # nothing half-written


def round_trip(path: Path):
    first = load_scene(path)
    again = path.with_name("again.toml")
    save_scene(first, again)
    second = load_scene(again)
    p = np.random.default_rng(0).uniform(-1, 1, (200, 3))
    assert type(second.terrain) is type(first.terrain)
    assert np.array_equal(second.terrain.signed_distance(p), first.terrain.signed_distance(p))
    return first


def test_each_kind_reads_and_writes_back(tmp_path: Path):
    np.save(tmp_path / "ground.npy", np.random.default_rng(1).uniform(-0.05, 0.05, (20, 30)))
    Image.fromarray(np.arange(12, dtype=np.uint16).reshape(3, 4) * 1000).save(tmp_path / "ground.png")
    trimesh.creation.box((2.0, 2.0, 0.2)).export(tmp_path / "rocks.stl")
    tables = {
        "plane normal": 'kind = "plane"\nnormal = [0.1, 0.0, 1.0]\npoint = [0.0, 0.0, 0.05]\n',
        "plane roll pitch": 'kind = "plane"\nroll_deg = 3.0\npitch_deg = -5.0\n',
        "npy": 'kind = "heightfield"\nfile = "ground.npy"\nextent = [2.0, 3.0]\norigin = [-1.0, -1.5, 0.0]\n',
        "png": 'kind = "heightfield"\nfile = "ground.png"\nheight_scale = 1e-5\nextent = [2.0, 2.0]\n',
        "mesh": 'kind = "mesh"\nfile = "rocks.stl"\nscale = 0.5\n',
        "steps": 'kind = "steps"\nstep_height = 0.05\nstep_depth = 0.3\ncount = 3\nheading_deg = 90.0\n',
    }
    kinds = {"plane normal": PlaneTerrain, "plane roll pitch": PlaneTerrain, "npy": HeightfieldTerrain,
             "png": HeightfieldTerrain, "mesh": MeshTerrain, "steps": StepsTerrain}
    for what, table in tables.items():
        s = round_trip(scene(tmp_path, table))
        assert isinstance(s.terrain, kinds[what]), what
    assert np.isclose(load_scene(scene(tmp_path, tables["mesh"])).terrain.height([0.0, 0.0]), 0.05)


def test_a_generated_heightfield_cannot_be_saved(tmp_path: Path):
    from snakehead.scenes.scene import Scene, Target

    s = Scene("s", (Target("t", np.array([0.2, 0.5, 0.3]), np.array([0.0, 1.0, 0.0])),),
              terrain=HeightfieldTerrain(np.zeros((3, 3)), np.ones(2)))
    with pytest.raises(InputError, match="not read from a file"):
        scene_to_toml(s, tmp_path)


def bad_tables(folder: Path) -> dict[str, tuple[str, str]]:
    """What each bad table must name: (table, a text its message holds)."""
    (folder / "inside").mkdir()
    np.save(folder / "outside.npy", np.zeros((3, 3)))
    np.save(folder / "inside" / "heightfield.npy", np.zeros(3))
    np.save(folder / "inside" / "ints.npy", np.zeros((3, 3), dtype=np.int64))
    np.save(folder / "inside" / "nan.npy", np.full((3, 3), np.nan))
    Image.fromarray(np.zeros((4, 4), dtype=np.uint8)).save(folder / "inside" / "eight.png")
    (folder / "inside" / "empty.stl").write_bytes(b"")
    (folder / "inside" / "link.npy").symlink_to(folder / "outside.npy")
    side = int(np.sqrt(2**20)) + 2
    np.save(folder / "inside" / "huge.npy", np.zeros((side, side)))
    hf = 'kind = "heightfield"\nextent = [1.0, 1.0]\nfile = '
    return {
        "shape": (hf + '"heightfield.npy"\n', "heightfield.npy: expected a 2-D array of finite heights, got shape (3,)"),
        "dtype": (hf + '"ints.npy"\n', "ints.npy: expected heights as float32 or float64"),
        "nan": (hf + '"nan.npy"\n', "nan.npy"),
        "8-bit": (hf + '"eight.png"\nheight_scale = 0.001\n', "eight.png: expected a 16-bit greyscale PNG"),
        "outside": (hf + '"../outside.npy"\n', "is outside the scene file's folder"),
        "absolute": (hf + f'"{folder / "outside.npy"}"\n', "is outside the scene file's folder"),
        "link": (hf + '"link.npy"\n', "is outside the scene file's folder"),
        "too many cells": (hf + '"huge.npy"\n', "MAX_TERRAIN_CELLS"),
        "missing": (hf + '"nothing.npy"\n', "nothing.npy"),
        "empty mesh": ('kind = "mesh"\nfile = "empty.stl"\n', "empty.stl"),
        "kind": ('kind = "lava"\n', "kind must be one of"),
        "unknown key": ('kind = "plane"\ncolour = 1\n', "unknown key 'colour'"),
        "both normals": ('kind = "plane"\nnormal = [0, 0, 1]\npitch_deg = 3.0\n', "not both"),
        "down": ('kind = "plane"\nnormal = [0, 0, -1]\n', "must point up"),
        "extent": ('kind = "heightfield"\nfile = "ints.npy"\nextent = [1.0]\n', "extent must be a list of 2"),
        "steps": ('kind = "steps"\nstep_height = 0.0\nstep_depth = 0.3\n', "step_height"),
        "count": ('kind = "steps"\nstep_height = 0.1\nstep_depth = 0.3\ncount = 1.5\n', "count"),
    }


def test_bad_tables_are_one_line_naming_the_file_and_the_field(tmp_path: Path):
    for what, (table, expected) in bad_tables(tmp_path).items():
        path = scene(tmp_path / "inside", table)
        with pytest.raises(InputError) as info:
            load_scene(path)
        message = str(info.value)
        assert "scene.toml" in message and "[terrain]" in message, (what, message)
        assert expected in message and "\n" not in message, (what, message)
