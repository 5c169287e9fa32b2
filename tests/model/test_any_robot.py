"""Any snake robot through the whole pipeline: map -> controller -> plan -> simulate, on generated snakes that
differ from the default robot in joint count, module length, section, mass, neck and head sizes, first axis and
frame names; and the same from the command line with a robot file.

Each robot's target is reachable by construction: the head pose of a whole-body configuration near the robot's
initial configuration (the planner's base arc), statically stable, clear of the ground and of itself.
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import generated_specs

import snakehead
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.kinematics import reachability as ws
from snakehead.model.generate import snake_urdf
from snakehead.model.robot_file import write_robot_file

ROBOTS = generated_specs()

#: Coarse maps keep the suite fast (the defaults take minutes per robot on 2 cores).
def map_options(robot) -> dict:
    return dict(voxel=1.5 * ws.default_map_options(robot)["voxel"], directions=12, rolls=2)


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def setup(request, tmp_path_factory):
    name = request.param
    spec, frames = ROBOTS[name]
    folder = tmp_path_factory.mktemp(name)
    (folder / f"{name}.urdf").write_text(snake_urdf(spec))
    robot_file = write_robot_file(folder / f"{name}.toml", urdf=folder / f"{name}.urdf", **frames)
    robot = snakehead.SnakeRobot.from_file(robot_file)
    m = ws.compute(robot, progress=False, **map_options(robot))
    controller = snakehead.HeadController(robot, m, method="free_roll", seed=1)
    return name, robot, robot_file, m, controller, folder


def reachable_target(robot, controller, seed: int):
    """A target reachable by construction: the head pose of the initial configuration with its neck and head
    joints moved a little, kept only if stable, clear of the ground and of itself."""
    rng = np.random.default_rng(seed)
    up = np.arange(robot.lift_joints.start, robot.n_joints)
    for _ in range(200):
        q = controller.q_initial.copy()
        q[up] += rng.normal(0.0, 0.12, len(up))
        q = np.clip(q, robot.lower, robot.upper)
        # the links after the first one the neck lifts (that one pivots on its proximal edge on the ground)
        first_lifted = robot.body.model.joint_child_links[robot.lift_joints.start]
        clear = coll.ground_clearance(robot, q)[0, robot.lifted_links[robot.lifted_links > first_lifted]]
        if (stability.static_margin(robot, q) > 0.01 and clear.min() > 0.02
                and coll.self_clearance(robot, q)[0] > 0.005):
            H = robot.head_pose(q)
            return H[:3, 3], H[:3, 0]
    raise AssertionError("no stable, clear pose near the initial configuration")


def test_map_and_dexterous_band(setup):
    name, robot, _, m, controller, _ = setup
    assert m.chain_hash == robot.head_chain.hash and len(m) > 100
    t = m.dexterous_threshold()
    if name == "pitchy":  # a 6-DOF head: no voxel reaches index 100 in number, the best band is used (never a refusal)
        assert t < 100.0 and "best band" in controller.dexterous_note
    else:
        assert t == 100.0
    assert np.sum(m.indices >= t) >= 3
    G0 = controller.G0_local
    assert np.linalg.norm(G0) < robot.head_chain.reach


def test_plan_and_simulate(mujoco, setup):
    name, robot, _, _, controller, _ = setup
    position, direction = reachable_target(robot, controller, seed={"long20": 3, "pitchy": 0}[name])
    plan = snakehead.plan([(position, direction)], controller=controller)
    assert plan.success, plan.failure
    # independent checks of the plan: the base rests on the ground, FK reaches the target, nothing in the ground
    F = robot.frames_many(plan.q, plan.base)
    low = robot.lowest_z(F, robot.base_links)
    assert np.abs(low.min(axis=1)).max() < 1e-4  # lowest base box corner at z = 0 within 0.1 mm
    tg = plan.targets[0]
    k = int(np.argmin(np.abs(plan.t - tg.time_s)))
    H = robot.head_pose(plan.q[k], plan.base)
    assert np.linalg.norm(H[:3, 3] - position) < 1e-4 and H[:3, 0] @ direction > np.cos(np.radians(0.05))
    assert plan.min_ground_clearance_m >= -coll.GROUND_TOLERANCE
    assert plan.stability.inside.all()
    sim = snakehead.simulate(plan)
    assert sim.position_error_m <= 2e-3, sim.metrics
    assert sim.direction_error_deg <= 1.0, sim.metrics
    assert sim.zmp_inside, sim.metrics
    assert sim.metrics["base_slide_m"] < 2e-3


def test_cli_with_a_robot_file(setup):
    name, robot, robot_file, _, _, folder = setup
    if name != "pitchy":
        pytest.skip("one robot is enough for the command line")
    env_run = [sys.executable, "-m", "snakehead"]
    map_path = folder / "head.npz"
    opts = map_options(robot)
    proc = subprocess.run(env_run + ["workspace", "--robot", str(robot_file), "--out", str(map_path), "--quiet",
                                     "--voxel", str(opts["voxel"]), "--directions", str(opts["directions"]),
                                     "--rolls", str(opts["rolls"])], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "best band" in proc.stdout  # the summary says which band is the dexterous workspace
    position, direction = reachable_target(robot, snakehead.HeadController(robot, ws.load(map_path), seed=1), seed=0)
    out = folder / "plan"
    proc = subprocess.run(env_run + ["plan", "--robot", str(robot_file), "--map", str(map_path), "--fast",
                                     "--method", "free_roll", "--position", *map(str, position), "--direction",
                                     *map(str, direction), "--out", str(out)], capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads((out / "report.json").read_text())
    entry = report["scenarios"]["target"]
    assert entry["success"] and report["robot"]["joints"] == 13 and report["robot"]["parts"]["neck"] == 1
    assert entry["sim"]["position_error_m"] <= 2e-3 and entry["sim"]["zmp_inside"]
    header = (out / "target_trajectory.csv").read_text().splitlines()[0]
    assert header.split(",")[1] == "j1_rad"  # the robot's own joint names
