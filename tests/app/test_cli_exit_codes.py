"""The command line's exit statuses, for every subcommand (issue 14): 0 success, 1 planned but not successful,
2 bad input (one line on stderr), 3 an internal error (one line saying it is a bug), 130 interrupted; never a
traceback unless SNAKEHEAD_TRACEBACK=1.

The successful runs of demo and plan, and most bad arguments, are in test_cli.py; here each status is reached
through each subcommand that can give it. Everything but the internal errors runs as a subprocess.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from snakehead import default_robot_file, default_urdf_path
from snakehead.app import cli, commands
from snakehead.model.robot_file import write_robot_file

SMALL_MAP = ["--voxel", "0.2", "--directions", "2", "--rolls", "1", "--quiet"]


def run(*args: str, timeout: float = 300, env: dict | None = None, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "snakehead", *args], capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, **(env or {})}, **kw)


def one_error_line(stderr: str, command: str) -> str:
    """The last line of stderr, checked to be the one error line of ``command`` (progress lines may come first)."""
    assert "Traceback" not in stderr, stderr
    line = stderr.strip().splitlines()[-1]
    assert line.startswith(f"snakehead {command}: error: ") or line.startswith(f"snakehead {command}: internal"), line
    return line


@pytest.fixture(scope="module")
def massless_robot(tmp_path_factory) -> Path:
    """The default robot without any <inertial>: valid URDF, but nothing to balance."""
    folder = tmp_path_factory.mktemp("massless")
    urdf = folder / "massless.urdf"
    urdf.write_text(re.sub(r"<inertial>.*?</inertial>", "", default_urdf_path().read_text(), flags=re.S))
    return write_robot_file(folder / "massless.toml", urdf=urdf, base_end="base_end", neck_end="neck_end",
                            head_tip="head_tip")


# --- 0 and 1 ----------------------------------------------------------------------------------------------
def test_info_and_workspace_succeed(tmp_path):
    assert run("info").returncode == 0
    r = run("workspace", "--out", str(tmp_path / "m.npz"), *SMALL_MAP)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "m.npz").is_file()


def test_plan_of_an_unreachable_target_is_1_with_its_outputs(tmp_path):
    """3 m above the ground: planned (the outputs are written) but not successfully."""
    r = run("plan", "--position", "0.5", "0.5", "3.0", "--direction", "1", "0", "0", "--out", str(tmp_path),
            "--no-sim", "--fast")
    assert r.returncode == 1, r.stderr
    assert "NOT successful" in r.stdout and "Traceback" not in r.stderr
    assert (tmp_path / "report.json").is_file() and (tmp_path / "target_trajectory.csv").is_file()


# --- 2 ------------------------------------------------------------------------------------------------------
def test_bad_input_is_2_with_one_line_for_every_subcommand(tmp_path, massless_robot):
    not_a_map = tmp_path / "not_a_map.npz"
    not_a_map.write_bytes(b"PK\x03\x04 truncated")
    empty_dir = tmp_path / "empty"
    empty_dir.mkdir()
    cases = [
        (["info", "--robot", str(massless_robot)], "info", "no mass"),
        (["info", "--robot", "/dev/zero"], "info", "character device"),
        (["demo", "--out", str(tmp_path / "d"), "--robot", str(massless_robot)], "demo", "no mass"),
        (["demo", "--out", str(tmp_path / "d"), "--map", str(not_a_map)], "demo", "not a .npz archive"),
        (["plan", "--position", "0", "0.5", "0.3", "--direction", "0", "1", "0", "--out", str(tmp_path / "p"),
          "--robot", str(massless_robot)], "plan", "no mass"),
        (["plan", "--scene", str(tmp_path), "--out", str(tmp_path / "p")], "plan", "is a directory"),
        (["workspace", "--out", str(tmp_path / "m.npz"), "--timeout", "1e300", *SMALL_MAP], "workspace",
         "timeout must be at most 86400"),
        (["workspace", "--out", str(tmp_path / "m.npz"), "--robot", str(massless_robot), *SMALL_MAP], "workspace",
         "no mass"),
        (["view", str(tmp_path / "missing")], "view", "is not a directory"),
        (["view", str(empty_dir)], "view", "holds no viewer scenes"),
    ]
    for argv, command, message in cases:
        r = run(*argv, timeout=120)
        assert r.returncode == 2, (argv, r.returncode, r.stderr)
        assert message in one_error_line(r.stderr, command), (argv, r.stderr)
    # argparse's own errors: one line too (argparse alone prints the whole usage first)
    r = run("plan", "--position", "a", "0", "0", "--out", str(tmp_path / "p"))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "not a number: 'a'" in r.stderr, r.stderr
    for out in (tmp_path / "d", tmp_path / "p"):  # nothing written (the folder may have been made)
        assert not out.exists() or not any(out.iterdir())
    assert not (tmp_path / "m.npz").exists()


def test_a_traceback_only_when_asked(tmp_path):
    argv = ["info", "--robot", str(tmp_path / "missing.toml")]
    quiet = run(*argv)
    assert quiet.returncode == 2 and "Traceback" not in quiet.stderr
    for off in ("", "0"):
        assert "Traceback" not in run(*argv, env={"SNAKEHEAD_TRACEBACK": off}).stderr
    loud = run(*argv, env={"SNAKEHEAD_TRACEBACK": "1"})
    assert loud.returncode == 1 and "Traceback" in loud.stderr and "InputError" in loud.stderr


# --- 3 ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", ["info", "demo", "plan", "workspace", "view"])
def test_an_internal_error_is_3_with_one_line(command, monkeypatch, capsys, tmp_path):
    """A bug (here: each subcommand's function raising an unexpected exception) is not bad input: exit 3, one line
    naming it and saying how to get the traceback."""
    def broken(args):
        raise KeyError("a bug")

    monkeypatch.setattr(commands, f"{command}_command", broken)
    argv = {"info": ["info"], "demo": ["demo", "--out", str(tmp_path)],
            "plan": ["plan", "--out", str(tmp_path), "--position", "0", "0.5", "0.3", "--direction", "0", "1", "0"],
            "workspace": ["workspace", "--out", str(tmp_path / "m.npz")], "view": ["view", str(tmp_path)]}[command]
    monkeypatch.delenv("SNAKEHEAD_TRACEBACK", raising=False)
    assert cli.main(argv) == cli.EXIT_INTERNAL_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"snakehead {command}: internal error (KeyError: 'a bug'); this is a bug in snakehead")
    assert "SNAKEHEAD_TRACEBACK=1" in err
    monkeypatch.setenv("SNAKEHEAD_TRACEBACK", "1")
    with pytest.raises(KeyError, match="a bug"):
        cli.main(argv)


# --- 130 ----------------------------------------------------------------------------------------------------
#: ``python -c`` this, MODULE, NAME, then snakehead's arguments: ``snakehead ...`` with MODULE.NAME (the work the
#: command is under way in: the plan, the sweep) run again and again until the Ctrl-C, after a line on stderr that
#: says it has started. However fast the machine, the signal finds the command working, not finished.
_UNDER_WAY = "the work is under way"
_REPEATED = f"""
import functools, importlib, runpy, sys
module, name = sys.argv.pop(1), sys.argv.pop(1)
owner = importlib.import_module(module)
real = getattr(owner, name)
@functools.wraps(real)
def again(*args, **kwargs):
    print({_UNDER_WAY!r}, file=sys.stderr, flush=True)
    while True:
        real(*args, **kwargs)
setattr(owner, name, again)
runpy.run_module("snakehead", run_name="__main__", alter_sys=True)
"""


def _interrupted(argv: list[str], work: str) -> subprocess.CompletedProcess:
    """Start ``snakehead argv`` with ``work`` (MODULE.NAME) repeated until the signal (_REPEATED), wait until it is
    under way, then send SIGINT (Ctrl-C)."""
    module, name = work.rsplit(".", 1)
    p = subprocess.Popen([sys.executable, "-c", _REPEATED, module, name, *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    lines = []
    while True:  # (no clock: the command either gets under way or ends, and either way stderr tells)
        line = p.stderr.readline()
        lines.append(line)
        if _UNDER_WAY in line or not line:
            break
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    return subprocess.CompletedProcess(argv, p.returncode, out, "".join(lines) + err)


@pytest.mark.parametrize("argv, work", [
    (["workspace", "--voxel", "0.01", "--quiet"], "snakehead.kinematics.reachability.compute"),
    (["plan", "--position", "0.1", "0.5", "0.35", "--direction", "0", "1", "0", "--fast"],
     "snakehead.planning.planner.plan"),
    (["demo", "--fast"], "snakehead.planning.planner.plan"),
], ids=["workspace", "plan", "demo"])
def test_interrupted_is_130(argv, work, tmp_path):
    out = str(tmp_path / ("m.npz" if argv[0] == "workspace" else "out"))
    r = _interrupted([argv[0], "--out", out, *argv[1:]], work)
    assert r.returncode == 130, r.stderr
    assert r.stderr.strip().splitlines()[-1] == f"snakehead {argv[0]}: interrupted"
    assert "Traceback" not in r.stderr
    if argv[0] == "workspace":
        assert not Path(out).exists()


def test_view_stops_with_ctrl_c_and_0(tmp_path):
    """view runs until Ctrl-C: that is how it ends, with 0."""
    from snakehead.viz import viewer

    scene = viewer.ViewerScene(name="s", title="s", times=np.zeros(1), shape_positions=np.zeros((1, 1, 3)),
                               shape_wxyz=np.array([[[1.0, 0, 0, 0]]]), shape_scales=np.full((1, 3), 0.1),
                               shape_colors=np.zeros((1, 3), np.uint8), shape_mesh=np.zeros(1, np.int32),
                               mesh_vertices=viewer.CUBE_VERTICES.astype(float),
                               mesh_triangles=viewer.CUBE_TRIANGLES.astype(np.int32),
                               mesh_vertex_starts=np.array([0, 8]), mesh_triangle_starts=np.array([0, 12]),
                               head_tip=np.zeros((1, 3)),
                               map_frame_positions=np.zeros((1, 3)), map_frame_wxyz=np.array([[1.0, 0, 0, 0]]),
                               voxel_centers=np.zeros((0, 3)), voxel_indices=np.zeros(0), voxel_size=0.05,
                               zmp=np.zeros((1, 2)), com=np.zeros((1, 3)), zmp_path=np.zeros((1, 2)),
                               polygons=np.zeros((1, 3, 2)), polygon_of_frame=np.zeros(1, np.int32),
                               target_positions=np.zeros((0, 3)), target_directions=np.zeros((0, 3)),
                               target_names=np.zeros(0, str), target_diameters=np.zeros(0),
                               obstacle_centres=np.zeros((0, 3)), obstacle_sizes=np.zeros((0, 3)),
                               obstacle_wxyz=np.zeros((0, 4)), wall_vertices=np.zeros((0, 3)),
                               wall_triangles=np.zeros((0, 3), np.int32), hole_rims=np.zeros((0, 65, 3)))
    viewer.save_viewer_scene(scene, tmp_path / f"s{viewer.SCENE_SUFFIX}")
    p = subprocess.Popen([sys.executable, "-m", "snakehead", "view", str(tmp_path), "--port", "0"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = p.stdout.readline()
    assert "Ctrl-C stops" in first, (first, p.stderr.read() if p.poll() is not None else "")
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 0, err
    assert "Traceback" not in err


def test_the_exit_statuses_are_documented():
    text = cli.build_parser().format_help()
    for status, meaning in ((0, "success"), (1, "not successfully"), (2, "bad arguments"), (3, "internal error"),
                            (130, "interrupted")):
        assert re.search(rf"^  {status}\s+.*{meaning}", text, re.M), (status, text)
    assert "SNAKEHEAD_TRACEBACK=1" in text
    assert default_robot_file().is_file()
