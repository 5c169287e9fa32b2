"""plan_many and snakehead reach on a published-style snake (snakehead.samples.published's "sea": a CMU SEA snake's
convention -- a link-less dummy root and a fixed joint rotated by -90 deg about y, modules along their own z of two
links each, cylinders and an STL tail mesh, the head looking along its z), not only on the default robot:

* plan_many over a thread pool gives the plans snakehead.plan gives one after the other (targets reachable by
  construction, so each plan also succeeds);
* ``snakehead reach`` (a tiny map: coarse voxels, two directions) writes a whole-body map whose reached poses full
  plans reach and whose unreached poses full plans do not (a spot-check; every pose in the slow variant).
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from conftest import plan_agrees

import snakehead as sh
from snakehead.app import cli
from snakehead.kinematics import reachability as ws
from snakehead.planning.plan_many import plan_many
from snakehead.samples import published
from snakehead.samples.targets import reachable_targets

STYLE = "sea"
#: The reach map's grid: voxels of a quarter of its side (the coarsest allowed: 4 x 4 voxels per layer), 2 directions.
DIRECTIONS = 2
#: Targets planned by plan_many.
TARGETS = 2


@pytest.fixture(scope="module")
def sea(tmp_path_factory: pytest.TempPathFactory) -> tuple[sh.SnakeRobot, Path]:
    """The robot and its robot file, naming a coarse head map computed here (the default map takes minutes)."""
    folder = tmp_path_factory.mktemp(STYLE)
    robot_file = published.write_robot(STYLE, folder)
    bare = sh.SnakeRobot.from_file(robot_file)
    m = ws.compute(bare, progress=False, voxel=2 * ws.default_map_options(bare)["voxel"], directions=8, rolls=2)
    m.save(folder / "head.npz")
    text = robot_file.read_text()
    head, tables = text.split("\n[", 1)
    robot_file.write_text(f'{head}\nmap = "head.npz"\n\n[{tables}')
    robot = sh.SnakeRobot.from_file(robot_file)
    assert robot.map_path is not None and Path(robot.map_path).name == "head.npz"
    return robot, robot_file


def test_the_style_is_the_published_convention(sea: tuple[sh.SnakeRobot, Path]) -> None:
    """What makes this robot unlike the default one (so that the tests below test something the default robot's
    do not): the rotated dummy root, several links per module, the head's axis z."""
    robot, _ = sea
    assert robot.description_arguments["root"] == "kdl_dummy_root"
    assert robot.description_arguments["head_axis"] == "z"
    assert len(robot.body.model.link_names) >= 2 * robot.n_joints


@pytest.fixture(scope="module")
def targets(sea: tuple[sh.SnakeRobot, Path]) -> list:
    robot, _ = sea
    controller = sh.HeadController(robot, method="rotated", seed=1)
    found = reachable_targets(controller, "same", TARGETS, np.random.default_rng(3))
    return [[(t.position, t.direction)] for t in found]


def _same(a: list, b: list) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.success == y.success
        assert x.q.shape == y.q.shape
        np.testing.assert_allclose(x.q, y.q, atol=1e-9)
        np.testing.assert_allclose(x.t, y.t, atol=1e-12)


def test_plan_many_over_threads_equals_plan(sea: tuple[sh.SnakeRobot, Path], targets: list) -> None:
    robot, _ = sea
    serial = [sh.plan(s, robot=robot) for s in targets]
    assert all(p.success for p in serial), [p.failure for p in serial]  # reachable by construction
    with ThreadPoolExecutor(2) as pool:
        many = plan_many(targets, robot=robot, executor=pool)
    _same(serial, many)
    assert all(p.robot is robot for p in many)


@pytest.fixture(scope="module")
def body_map(sea: tuple[sh.SnakeRobot, Path], tmp_path_factory: pytest.TempPathFactory) -> ws.ReachabilityMap:
    """``snakehead reach`` on the robot file, as a user runs it."""
    robot, robot_file = sea
    out = tmp_path_factory.mktemp("reach")
    voxel = 2.0 * robot.body_length / 4  # the coarsest grid check_options allows
    code = cli.main(["reach", "--robot", str(robot_file), "--voxel", f"{voxel:.6f}", "--directions", str(DIRECTIONS),
                     "--quiet", "--out", str(out)])
    assert code == 0
    return ws.require_map(sh.load_map(out / "reach.npz"), robot, kind=ws.KIND_WHOLE_BODY)


def test_reach_map_of_the_published_robot(sea: tuple[sh.SnakeRobot, Path], body_map: ws.ReachabilityMap) -> None:
    robot, _ = sea
    assert body_map.kind == ws.KIND_WHOLE_BODY and len(body_map.sphere_directions) == DIRECTIONS
    bits = body_map.reached_units()
    yes, no = np.argwhere(bits), np.argwhere(~bits)
    assert len(yes) and len(no)  # the grid holds both
    assert np.all(np.isfinite(body_map.base_placements[bits])) and np.all(np.isnan(body_map.base_placements[~bits]))
    rng = np.random.default_rng(0)
    pairs = np.concatenate([yes[rng.choice(len(yes), 1, replace=False)], no[rng.choice(len(no), 1, replace=False)]])
    assert all(plan_agrees(robot, body_map, pairs))


@pytest.mark.slow  # every reached pose of the tiny grid, and as many unreached ones, planned in full (minutes)
def test_every_reached_pose_of_the_published_robot_is_planned(sea: tuple[sh.SnakeRobot, Path],
                                                              body_map: ws.ReachabilityMap) -> None:
    robot, _ = sea
    bits = body_map.reached_units()
    yes, no = np.argwhere(bits), np.argwhere(~bits)
    rng = np.random.default_rng(1)
    pairs = np.concatenate([yes, no[rng.choice(len(no), min(len(no), len(yes)), replace=False)]])
    assert np.mean(plan_agrees(robot, body_map, pairs)) >= 0.98
