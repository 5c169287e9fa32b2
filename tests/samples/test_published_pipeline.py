"""Each published-style snake (snakehead.samples.published) through the command line from its robot file, as a user
would: ``info`` (exit 0, the parts), ``workspace`` (a coarse map of its head), ``plan`` with the MuJoCo check of a
target reachable by construction (the head pose of a stable, collision-free configuration on the robot's initial
base, snakehead.samples.targets): success, the head within 2 mm and 1 deg in MuJoCo, the body in place,
the simulated ZMP in the planned support polygon (to 1 mm)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead.kinematics import reachability as ws
from snakehead.samples import published
from snakehead.samples.targets import reachable_targets

CLI = [sys.executable, "-m", "snakehead"]


def run(*args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(CLI + list(args), capture_output=True, text=True, timeout=timeout)


@pytest.mark.parametrize("style", published.STYLES)
def test_published_style_through_the_command_line(style: str, tmp_path: Path) -> None:
    robot_file = published.write_robot(style, tmp_path / style)
    info = run("info", "--robot", str(robot_file), "--quick")
    assert info.returncode == 0, info.stdout + info.stderr
    assert "base:" in info.stdout and "PROBLEM" not in info.stdout

    robot = snakehead.SnakeRobot.from_file(robot_file)
    map_path = tmp_path / "head.npz"
    voxel = 1.5 * ws.default_map_options(robot.head_chain)["voxel"]
    proc = run("workspace", "--robot", str(robot_file), "--out", str(map_path), "--quiet", "--voxel", str(voxel),
               "--directions", "12", "--rolls", "2")
    assert proc.returncode == 0, proc.stderr

    controller = snakehead.HeadController(robot, ws.load(map_path), method="free_roll", seed=1)
    target = reachable_targets(controller, "same", 1, np.random.default_rng(0))[0]
    position, direction = target.position, target.direction
    out = tmp_path / "plan"
    proc = run("plan", "--robot", str(robot_file), "--map", str(map_path), "--fast", "--method", "free_roll",
               "--position", *map(str, position), "--direction", *map(str, direction), "--out", str(out), timeout=900)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    entry = json.loads((out / "report.json").read_text())["scenarios"]["target"]
    assert entry["success"], entry["failure"]
    sim = entry["sim"]
    assert sim["position_error_m"] <= 2e-3 and sim["direction_error_deg"] <= 1.0, sim
    # the body stays put, and the simulated ZMP (each tick's centre of pressure of MuJoCo's floor contacts) stays in
    # the planned support polygon to within 1 mm (cylinders' contacts switch between links tick to tick)
    assert sim["base_slide_m"] < 2e-3 and sim["base_lift_m"] < 2e-3, sim
    assert sim["zmp_min_margin_m"] > -1e-3, sim
    assert "paper" not in entry  # the paper's numbers are its robot's
