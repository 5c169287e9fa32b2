"""The new user's findings, each fixed: where a part ends is shown, design errors say what to change (and a split
that works is computed), a target that needs the base moved says so on the result line and can be refused, a map
without a dexterous band says why, the report's paper column is for the paper's robot."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead.app import robot_check
from snakehead.app.pipeline import outcome_line
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.model.robot_file import write_robot_file

CLI = [sys.executable, "-m", "snakehead"]


def info(robot_file: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(CLI + ["info", "--robot", str(robot_file), *extra], capture_output=True, text=True,
                          timeout=600)


def test_info_says_where_each_part_ends(tmp_path: Path) -> None:
    """A marker at a link's distal end sits on the next joint; the link's own name sits on its own joint: the same
    joint counts, a base one link apart, and info shows which."""
    default = snakehead.SnakeRobot.default()
    marker = robot_check.frame_position(default, "base_end")
    link = robot_check.frame_position(default, "link_7")
    assert marker.endswith("on joint_8") and link.endswith("on joint_7")
    assert float(marker.split(" m")[0]) - float(link.split(" m")[0]) == pytest.approx(0.0865, abs=1e-9)
    proc = info(snakehead.default_robot_file(), "--quick")
    assert proc.returncode == 0, proc.stderr
    assert "base: link_0 (0.0000 m, before the first joint) -> base_end (0.6460 m, on joint_8)" in proc.stdout
    assert "7 joints" in proc.stdout and "design: the base holds the lifted neck and head" in proc.stdout


def test_a_design_that_cannot_work_gets_a_split_that_does(tmp_path: Path) -> None:
    """A base of 2 joints cannot hold a 14-joint neck and head: info says so (exit 1) and names a base_end that
    works, found by trying it; the planner's own errors point at info."""
    spec = SnakeSpec(n_joints=16, markers={"p0": 2, "b0": 4}, tip_name="tip", name="short_base")
    urdf = tmp_path / "short_base.urdf"
    urdf.write_text(snake_urdf(spec))
    robot_file = write_robot_file(tmp_path / "short_base.toml", urdf=urdf, base_end="p0", neck_end="b0",
                                  head_tip="tip")
    robot = snakehead.SnakeRobot.from_file(robot_file)
    problems = robot_check.design_problems(robot)
    assert problems and all("snakehead info" in p for p in problems)
    found = robot_check.suggest_split(robot)
    assert found is not None
    change, better = found
    assert robot_check.design_problems(better) == []
    proc = info(robot_file)
    assert proc.returncode == 1
    assert "PROBLEM:" in proc.stdout and f"SUGGESTION: in the robot file, {change}" in proc.stdout


def test_relocation_is_on_the_result_line_and_can_be_refused() -> None:
    robot = snakehead.SnakeRobot.default()
    far = ([1.6, 0.2, 0.3], [1.0, 0.0, 0.0])  # beyond the lifted chain's reach from the default base
    kept = snakehead.plan([far], robot=robot, allow_relocation=False)
    assert not kept.success and kept.relocation is None
    moved = snakehead.plan([far], robot=robot)
    assert moved.success and moved.relocation is not None, moved.failure
    line = outcome_line(moved.success, moved.failure, moved.relocation.as_dict())
    assert line.startswith("success after relocating the base") and "--no-relocation" in line
    assert outcome_line(True, None, None) == "success"


def test_no_relocation_on_the_command_line(tmp_path: Path) -> None:
    proc = subprocess.run(CLI + ["plan", "--position", "1.6", "0.2", "0.3", "--direction", "1", "0", "0",
                                 "--no-sim", "--fast", "--no-relocation", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "NOT successful" in proc.stdout


def test_a_map_without_a_dexterous_band_says_why_and_what_to_do(tmp_path: Path) -> None:
    """A 5-DOF head mapped with rolls reaches none of its rolled frames: the summary and the controller say free
    roll is needed; the workspace command's header says which directions it sweeps."""
    from snakehead.kinematics import reachability as ws

    spec = SnakeSpec(n_joints=12, markers={"p0": 5, "b0": 7}, tip_name="tip", name="head5")
    robot = snakehead.SnakeRobot.from_urdf(snake_urdf(spec), base_end="p0", neck_end="b0", head_tip="tip")
    rolled = ws.compute(robot, progress=False, voxel=0.1, directions=6, rolls=2)
    assert rolled.dexterous_threshold() == 0.0
    assert "free roll" in rolled.quality_problem() and "free roll" in rolled.summary()
    controller = snakehead.HeadController(robot, rolled, method="free_roll")
    assert "free roll" in controller.dexterous_note
    free = ws.compute(robot, progress=False, voxel=0.1, directions=6, free_roll=True)
    assert free.quality_problem() is None
    urdf = tmp_path / "head5.urdf"
    urdf.write_text(snake_urdf(spec))
    robot_file = write_robot_file(tmp_path / "head5.toml", urdf=urdf, base_end="p0", neck_end="b0", head_tip="tip")
    proc = subprocess.run(CLI + ["workspace", "--robot", str(robot_file), "--out", str(tmp_path / "m.npz"), "--quiet",
                                 "--voxel", "0.1", "--directions", "6", "--free-roll"], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "6 directions x free roll" in proc.stderr


def test_the_paper_column_is_for_the_papers_robot(tmp_path: Path) -> None:
    from snakehead.app.report import is_default_robot

    assert is_default_robot(snakehead.SnakeRobot.default())
    spec = SnakeSpec(n_joints=12, markers={"p0": 5, "b0": 7}, tip_name="tip", name="other")
    other = snakehead.SnakeRobot.from_urdf(snake_urdf(spec), base_end="p0", neck_end="b0", head_tip="tip")
    assert not is_default_robot(other)
    assert np.isfinite(other.body_axis_height)
