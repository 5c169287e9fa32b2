"""Each published-style snake (snakehead.model.published) through the command line from its robot file, as a user
would: ``info`` (exit 0, the parts), ``workspace`` (a coarse map of its head), ``plan`` with the MuJoCo check of a
target reachable by construction (the head pose of a stable, collision-free configuration near the robot's
initial state): success, the head within 2 mm and 1 deg in MuJoCo, the ZMP inside."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead.dynamics import stability
from snakehead.geometry import collision as coll
from snakehead.kinematics import workspace as ws
from snakehead.model import published

pytest.importorskip("mujoco")

CLI = [sys.executable, "-m", "snakehead"]


def run(*args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(CLI + list(args), capture_output=True, text=True, timeout=timeout)


def reachable_target(robot: snakehead.SnakeRobot, controller: snakehead.HeadController,
                     seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The head pose of the initial configuration with its lifted joints moved a little: statically stable, clear
    of the ground and of itself (a target reachable by construction)."""
    rng = np.random.default_rng(seed)
    up = np.arange(robot.lift_joints.start, robot.n_joints)
    first_lifted = robot.body.model.joint_child_links[robot.lift_joints.start]
    for _ in range(300):
        q = np.clip(controller.q_initial + np.isin(np.arange(robot.n_joints), up) * rng.normal(0.0, 0.12, robot.n_joints),
                    robot.lower, robot.upper)
        clear = coll.ground_clearance(robot, q)[0, robot.lifted_links[robot.lifted_links > first_lifted]]
        if (stability.static_margin(robot, q) > 0.01 and clear.min() > 0.02
                and coll.self_clearance(robot, q)[0] > 0.005):
            H = robot.head_pose(q)
            return H[:3, 3], H[:3, 0]
    raise AssertionError("no stable, clear pose near the initial configuration")


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
    position, direction = reachable_target(robot, controller, seed=0)
    out = tmp_path / "plan"
    proc = run("plan", "--robot", str(robot_file), "--map", str(map_path), "--fast", "--method", "free_roll",
               "--position", *map(str, position), "--direction", *map(str, direction), "--out", str(out), timeout=900)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    entry = json.loads((out / "report.json").read_text())["scenarios"]["target"]
    assert entry["success"], entry["failure"]
    sim = entry["sim"]
    assert sim["position_error_m"] <= 2e-3 and sim["direction_error_deg"] <= 1.0, sim
    assert sim["zmp_inside"], sim
    assert "paper" not in entry  # the paper's numbers are its robot's
