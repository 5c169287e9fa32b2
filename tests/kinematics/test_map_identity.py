"""Maps know what they are (hostile input): a shard of a map, a map of another head, or a map lacking what a caller
needs is refused with its reason wherever a map is accepted (HeadController, --map, a robot file's map, pose queries,
base placements, the viewer, G0), while shards still load and merge; and the sweep's numbers (``snakehead
workspace`` and ``snakehead.compute_map``) are checked against documented limits before any work, as InputErrors
naming the option, never pybind11's "incompatible function arguments"."""
from __future__ import annotations

import dataclasses
import types
from pathlib import Path

import numpy as np
import pytest
from conftest import SMALL_MAP, head6_robot

import snakehead
from snakehead import HeadController, SnakeRobot, _core, default_urdf_path
from snakehead._errors import InputError, InputTypeError
from snakehead.app import cli
from snakehead.app.robot_check import map_summary
from snakehead.kinematics import base_placement as bp
from snakehead.kinematics import reachability as ws
from snakehead.kinematics.reachability import map_queries as mq
from snakehead.model.robot_file import write_robot_file

# Small maps of the default robot's 7-DOF head: about half a second each.
SMALL = SMALL_MAP
DATA = Path(__file__).resolve().parents[1] / "data"
POSE = ([0.2, 0.0, 0.1], [1.0, 0.0, 0.0])  # a pose in the head's base frame


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def whole(small_map):
    return small_map


@pytest.fixture(scope="module")
def files(robot, whole, tmp_path_factory):
    """The whole map, its two shards and a map of the 6-DOF head (another chain), as files."""
    folder = tmp_path_factory.mktemp("maps")
    out = {"whole": folder / "whole.npz", "other": folder / "head6.npz"}
    ws.save(whole, out["whole"])
    for i in (0, 1):
        out[f"shard{i}"] = folder / f"shard{i}of2.npz"
        ws.save(ws.compute(robot, progress=False, shard=(i, 2), **SMALL), out[f"shard{i}"])
    ws.save(ws.compute(head6_robot(), progress=False, **SMALL), out["other"])
    return out


def cli_run(argv, capsys):
    """``snakehead ARGV`` in this process: (exit status, stderr's lines)."""
    try:
        code = cli.main([str(a) for a in argv])
    except SystemExit as exc:  # argparse's errors
        code = exc.code
    return code, capsys.readouterr().err.strip().splitlines()


def one_error(lines, command):
    """The one error line of ``command`` (progress lines may come before it)."""
    errors = [line for line in lines if "error" in line]
    assert len(errors) == 1 and errors[0] == lines[-1], lines
    assert lines[-1].startswith(f"snakehead {command}: error: "), lines
    assert "Traceback" not in "\n".join(lines) and "incompatible function arguments" not in lines[-1]
    return lines[-1]


# --- finding 1: a shard is not the map -----------------------------------------------------------------------
def test_a_shard_is_refused_by_the_controller(robot, files):
    """A shard's G0 is 37 cm from the map's, and HeadController took it without a word."""
    shard = ws.load(files["shard0"])
    assert shard.shard == (0, 2) and len(shard) < ws.load(files["whole"]).hull_voxels
    with pytest.raises(InputError, match=r"shard 0/2 of a map.*merge the shards") as err:
        HeadController(robot, shard)
    assert str(files["shard0"]) in str(err.value) and "\n" not in str(err.value)
    HeadController(robot, ws.load(files["whole"]))  # the whole map is taken


def test_a_shard_has_no_g0_nor_dexterous_band_nor_index_lookup(files):
    shard = ws.load(files["shard1"])
    for call in (shard.center, shard.clusters, shard.dexterous_threshold, lambda: shard.dexterous(None),
                 lambda: shard.index_at([0.1, 0.0, 0.0])):
        with pytest.raises(InputError, match="shard 1/2"):
            call()
    assert "shard 1/2" in shard.summary() and "merge" in shard.summary()  # says what it is instead of a G0


def test_a_shard_is_refused_by_pose_queries_and_base_placements(robot, files):
    shard = ws.load(files["shard0"])
    for call in (lambda: shard.reachable(*POSE), lambda: shard.reachable(*POSE, interpolate=False),
                 lambda: mq.reachability(shard, *POSE), lambda: shard.inverse(*POSE), lambda: mq.direction_bits(shard),
                 lambda: bp.base_placements(robot, shard, [0.0, 0.5, 0.3], [0, 1, 0], neck_samples=2, yaw_samples=4),
                 lambda: bp.placements_from_frames(shard, np.eye(4)[None], np.zeros((1, 2)), [0, 0.5, 0.3], [0, 1, 0])):
        with pytest.raises(InputError, match="shard 0/2"):
            call()


def test_a_shard_is_refused_by_the_viewer(robot, files):
    from snakehead.viz import viewer

    plan = types.SimpleNamespace(robot=robot)  # refused before anything of the plan is read
    with pytest.raises(InputError, match="shard 0/2"):
        viewer.viewer_scene(plan, workspace_map=ws.load(files["shard0"]))
    with pytest.raises(InputError, match="another head chain"):
        viewer.viewer_scene(plan, workspace_map=ws.load(files["other"]))


@pytest.mark.parametrize("command", ["plan", "demo"])
def test_map_option_refuses_a_shard_with_one_line(command, files, tmp_path, capsys):
    argv = [command, "--out", tmp_path / "out", "--no-sim", "--fast", "--map", files["shard0"]]
    if command == "plan":
        argv += ["--position", "0.1", "0.5", "0.3", "--direction", "0", "1", "0"]
    code, lines = cli_run(argv, capsys)
    line = one_error(lines, command)
    assert code == 2
    assert f"--map {str(files['shard0'])!r} is shard 0/2" in line and "--merge" in line
    assert not (tmp_path / "out" / "report.json").exists()


def test_a_robot_files_shard_is_refused_by_map_for_and_reported_by_info(files, tmp_path):
    robot_file = write_robot_file(tmp_path / "robot.toml", urdf=default_urdf_path(), base_end="base_end",
                                  neck_end="neck_end", head_tip="head_tip", map=files["shard1"])
    robot = SnakeRobot.from_file(robot_file)
    with pytest.raises(InputError, match=r"the robot file's map .*shard1of2.npz.* is shard 1/2"):
        ws.map_for(robot)
    with pytest.raises(InputError, match="shard 1/2"):
        HeadController(robot)
    line, problem = map_summary(robot)
    assert problem is not None and "shard 1/2" in problem


# --- another robot's head ---------------------------------------------------------------------------------------
def test_a_map_of_another_head_is_refused_everywhere(robot, files, tmp_path, capsys):
    other = ws.load(files["other"])
    with pytest.raises(InputError, match=r"another head chain .*hash .*snakehead workspace"):
        HeadController(robot, other)
    with pytest.raises(InputError, match="another head chain"):
        bp.base_placements(robot, other, [0.0, 0.5, 0.3], [0, 1, 0], neck_samples=2, yaw_samples=4)
    code, lines = cli_run(["plan", "--out", tmp_path / "out", "--no-sim", "--map", files["other"], "--position", "0.1",
                           "0.5", "0.3", "--direction", "0", "1", "0"], capsys)
    assert code == 2 and "another head chain" in one_error(lines, "plan")


# --- a map lacking what the caller needs ----------------------------------------------------------------------
def _first(m, k):
    """The map with its first k voxels only (a whole map of too few voxels)."""
    return dataclasses.replace(m, centers=m.centers[:k], solved=m.solved[:k], voxel_ids=m.voxel_ids[:k],
                               reached=m.reached[:k], hull_voxels=k, cache={})


def test_a_map_without_enough_voxels_is_refused_with_its_reason(robot, whole):
    with pytest.raises(InputError, match="holds no voxels"):
        HeadController(robot, _first(whole, 0))
    with pytest.raises(InputError, match="holds 2 voxels; the dexterous centre G0 needs at least 3"):
        HeadController(robot, _first(whole, 2))
    with pytest.raises(InputError, match="holds no voxels"):
        _first(whole, 0).reachable(*POSE)


def test_pose_queries_need_per_direction_results_along_the_heads_axis(robot, whole):
    old = ws.load(DATA / "map_format1.npz")  # the first format: no per-direction results
    with pytest.raises(InputError, match="no per-direction results"):
        old.reachable(*POSE)
    with pytest.raises(InputError, match="no per-direction results"):
        bp.base_placements(robot, old, [0.0, 0.5, 0.3], [0, 1, 0], neck_samples=2, yaw_samples=4)
    HeadController(robot, old)  # G0 needs no per-direction results
    z = ws.compute(robot, progress=False, approach_axis="z", **SMALL)
    with pytest.raises(InputError, match="approach axis 'z'"):
        z.reachable(*POSE)  # answered, before, for the head's z-axis as if it were its pointing x-axis
    assert isinstance(whole.reachable(*POSE), bool)


def test_require_map_names_the_wrong_kind(robot):
    with pytest.raises(InputTypeError, match="workspace_map must be a ReachabilityMap"):
        HeadController(robot, "map.npz")
    with pytest.raises(InputTypeError, match="must be a ReachabilityMap"):
        mq.reachable("map.npz", *POSE)


# --- shards still load and merge ------------------------------------------------------------------------------
def test_shards_load_and_merge_by_the_cli(robot, whole, files, tmp_path, capsys):
    merged_path = tmp_path / "merged.npz"
    code, lines = cli_run(["workspace", "--out", merged_path, "--merge", files["shard1"], files["shard0"]], capsys)
    assert code == 0, lines
    merged = ws.load(merged_path)
    assert merged.same_map_as(whole) and merged.shard == (0, 1) and merged.lacks == ()
    HeadController(robot, merged.require_whole_for(robot, needs=("G0", "poses")))
    code, lines = cli_run(["workspace", "--out", tmp_path / "m.npz", "--merge", files["shard0"]], capsys)
    assert code == 2 and "missing shard 1/2" in one_error(lines, "workspace")
    code, lines = cli_run(["workspace", "--out", tmp_path / "m.npz", "--merge", files["shard0"], files["shard1"],
                           "--shard", "0/2"], capsys)
    assert code == 2 and "--shard" in one_error(lines, "workspace")
    assert not (tmp_path / "m.npz").exists()


def test_empty_shards_merge_without_losing_the_per_direction_results(robot, whole, tmp_path):
    """A shard of no voxels was read back as a map lacking per-direction results, and the merge of it with the others
    then dropped theirs (the writer leaves an empty array out)."""
    n = 8  # more shards than the grid's tiles: some are empty
    paths = []
    for i in range(n):
        paths.append(tmp_path / f"s{i}.npz")
        ws.save(ws.compute(robot, progress=False, shard=(i, n), **SMALL), paths[-1])
    shards = [ws.load(p) for p in paths]
    assert any(len(s) == 0 for s in shards)
    assert all(s.lacks == () and s.reached is not None for s in shards)
    merged = ws.merge(shards)
    assert merged.lacks == () and merged.same_map_as(whole)


# --- finding 2: the sweep's numbers ---------------------------------------------------------------------------
HUGE = [
    (["--directions", "99999999999"], "--directions: must be at most 4096"),
    (["--rolls", "99999999999"], "--rolls: must be at most 360"),
    (["--threads", "99999999999"], "--threads: must be at most 256"),
    (["--seed", "99999999999999999999999"], "--seed: must be at most 18446744073709551615"),
    (["--timeout", "1e308"], "timeout must be at most 86400 s"),
    (["--shard", "0/99999999999999999999"], "0 <= i < N <= 4096"),
    (["--shard", "4096/4097"], "0 <= i < N <= 4096"),
    (["--voxel", "1e308"], "voxel size 1e+308 m is too large"),
    (["--voxel", "0.4"], "at least 4 (voxel size < 0.37"),
    (["--voxel", "1e-9"], "voxel size 1e-09 m is too small"),
    (["--directions", "4000", "--rolls", "4"], "directions x rolls (frames per voxel) must be at most 4096"),
]


@pytest.mark.parametrize("options, message", HUGE, ids=[" ".join(o) for o, _ in HUGE])
def test_workspace_numbers_beyond_their_limits_are_refused_before_any_work(options, message, tmp_path, capsys):
    out = tmp_path / "m.npz"
    code, lines = cli_run(["workspace", "--out", out, "--quiet", *options], capsys)
    assert code == 2
    line = one_error(lines, "workspace")
    assert message in line, line
    assert len(lines) == 1, lines  # refused before the sweep says what it computes
    assert not out.exists()


def test_workspace_help_documents_the_limits(capsys):
    with pytest.raises(SystemExit, match="^0$"):  # --help exits 0
        cli.main(["workspace", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for limit in ("1 to 4096", "1 to 360", "1 to 256", "0 <= i < N <= 4096", "at most 86400", "0 to 2^64 - 1",
                  "4 to 256 voxels per axis", "--merge"):
        assert limit in text, limit


COMPUTE_BAD = [
    ({"directions": 99999999999}, InputError, "directions must be between 1 and 4096"),
    ({"rolls": 99999999999}, InputError, "rolls must be between 1 and 360"),
    ({"threads": 99999999999}, InputError, "threads must be between 0 and 256"),
    ({"seed": 2**64}, InputError, "seed must be between 0 and 18446744073709551615"),
    ({"cloud_samples": 10**12}, InputError, "cloud_samples must be between 100 and 10000000"),
    ({"timeout": 1e308}, InputError, "timeout must be at most 86400 s"),
    ({"timeout": 10**400}, InputError, "timeout must be a finite number"),
    ({"voxel": 1e308}, InputError, "voxel size 1e+308 m is too large"),
    ({"voxel": 5e-324}, InputError, "too small"),
    ({"shard": (0, 10**20)}, InputError, "shard must be i/N"),
    ({"shard": "0/99999999999999999999"}, InputError, "shard must be i/N"),
    ({"shard": (0.5, 2)}, InputError, "shard must be 'i/N' or"),
    ({"directions": "20"}, InputTypeError, "directions must be an integer"),
    ({"seed": None}, InputTypeError, "seed must be an integer"),
    ({"voxel": "0.1"}, InputTypeError, "voxel must be a number"),
    ({"directions": 4000, "rolls": 4}, InputError, "frames per voxel"),
]


@pytest.mark.parametrize("change, kind, message", COMPUTE_BAD, ids=[str(c)[:40] for c, _, _ in COMPUTE_BAD])
def test_compute_map_names_the_argument(robot, change, kind, message):
    with pytest.raises(kind, match=None) as err:
        snakehead.compute_map(robot, progress=False, **{**SMALL, **change})
    text = str(err.value)
    assert message in text and "incompatible function arguments" not in text and "\n" not in text, text


def test_compute_map_with_an_executor_bounds_the_shards(robot):
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as ex:
        with pytest.raises(InputError, match="shards must be between 1 and 4096"):
            snakehead.compute_map(robot, progress=False, executor=ex, shards=10**20, **SMALL)


def test_the_limits_are_the_cores():
    """The Python limits are the C++ core's: its own check takes each and refuses one more."""
    for field, most, extra in (("directions", ws.MAX_DIRECTIONS, {"rolls": 1}),
                               ("rolls", ws.MAX_ROLLS, {"directions": 1}),
                               ("cloud_samples", ws.MAX_CLOUD_SAMPLES, {}), ("threads", ws.MAX_THREADS, {})):
        o = _core.WorkspaceOptions()
        for k, v in extra.items():
            setattr(o, k, v)
        setattr(o, field, most)
        o.validate()
        setattr(o, field, most + 1)
        with pytest.raises(ValueError, match=field):
            o.validate()
    o = _core.WorkspaceOptions()
    o.seed = ws.MAX_SEED  # the largest the binding takes
    o.timeout = ws.MAX_TIMEOUT_S
    o.validate()
    o.timeout = np.nextafter(ws.MAX_TIMEOUT_S, np.inf)
    with pytest.raises(ValueError, match="timeout"):
        o.validate()
