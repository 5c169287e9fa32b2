"""Snakes with fat collision cylinders (wider than a module is long): the lift from the bending state.

Regression: on the RSNAKE-style robot with r = 0.05 m cylinders on 0.09 m modules, the tracked Cartesian lift folded
the head so that links two joints apart overlapped (module_8 / module_10 by 4.6 mm), the planner fell back to a
random joint-space detour, and that detour turned the neck's first yaw joint (whose link lies on the ground) by
11 deg and back while the links next to it were still down. The plan claimed success (ZMP 8.7 mm inside), but in
MuJoCo the loaded neck links were dragged over the ground: the base yawed 5.7 deg and slid 38 mm, the head missed
its direction by 2.6 deg and the ZMP left the polygon by 26 mm.
"""
from __future__ import annotations

import numpy as np
import pytest

import snakehead
from snakehead.collision import body_collisions as coll
from snakehead.kinematics import reachability as ws
from snakehead.planning import start_state, waypoints
from snakehead.samples import published
from snakehead.trajectory import cartesian


@pytest.fixture(scope="module")
def fat_rsnake(tmp_path_factory):
    robot = snakehead.SnakeRobot.from_file(published.write_robot("rsnake", tmp_path_factory.mktemp("fat")))
    opts = ws.default_map_options(robot)
    m = ws.compute(robot, progress=False, voxel=1.5 * opts["voxel"], directions=12, rolls=2)
    controller = snakehead.HeadController(robot, m, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    return robot, controller, snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)


def test_lift_keeps_the_ground_links_and_the_body_clear(fat_rsnake):
    robot, _, plan = fat_rsnake
    assert plan.success, plan.failure
    # the joints before the neck's first pitch joint hold links on the ground: no part of the plan turns them
    held = plan.q[:, :robot.lift_joints.start]
    assert np.abs(held - held[0]).max() < 1e-9
    # the lift is the tracked Cartesian interpolation, not a detour: the fit keeps the thick links apart
    assert dict(plan.segments)["initial state (head lifted)"].startswith("cartesian")
    assert coll.self_clearance(robot, plan.q[::10], plan.base).min() > 0.0


def test_lift_fit_does_not_amplify_rounding(fat_rsnake):
    """Regression: the fit's self-clearance gradient (finite differences of GJK distances) was noise at a 1e-6 rad
    step, and the fit of this lift ended anywhere from -1.6 to +4.0 mm apart when the end pose moved by 1e-10 rad
    (as numpy's BLAS kernels round it differently): the plan failed on some CPUs."""
    robot, controller, _ = fat_rsnake
    qa = start_state.bending_state(controller)
    qb = qa.copy()
    lift = slice(robot.lift_joints.start, None)
    qb[lift] = controller.q_initial[lift]
    rng = np.random.default_rng(0)
    closest = []
    for k in range(8):
        q_end = qb.copy()
        if k:
            q_end[lift] += rng.uniform(-1e-10, 1e-10, len(q_end[lift]))
        fit = cartesian.tracking_interpolation(robot, qa, q_end, 12)
        closest.append(coll.self_clearance(robot, fit.q).min())
    assert np.ptp(closest) < 2e-4, closest
    assert min(closest) > 0.5 * cartesian.TRACKING_SELF_CLEARANCE, closest


def test_detour_moves_only_the_lifting_joints(fat_rsnake):
    robot, controller, _ = fat_rsnake
    way = waypoints.Waypoints(robot, snakehead.BasePlacement())
    qa = start_state.bending_state(controller)
    qb = qa.copy()
    qb[robot.lift_joints.start:] = controller.q_initial[robot.lift_joints.start:]
    way.feasible = lambda qs: np.zeros(len(qs), bool)  # nothing passes: every detour is tried
    path, method = way._joint_path(qa, qb, 8)
    assert "detour" in method
    assert np.abs(path[:, :robot.lift_joints.start] - qa[:robot.lift_joints.start]).max() < 1e-12


def test_fat_plan_tracks_in_mujoco(mujoco, fat_rsnake):
    _, _, plan = fat_rsnake
    sim = snakehead.simulate(plan)
    m = sim.metrics
    assert m["position_error_m"] < 0.002
    assert m["direction_error_deg"] < 1.0
    assert m["base_slide_m"] < 0.002
    root = sim.result.root_pose[:, :3, :3]
    turn = np.degrees(np.arccos(np.clip((np.einsum("ji,tjk->tik", root[0], root).trace(axis1=1, axis2=2) - 1) / 2,
                                        -1.0, 1.0)))
    assert turn.max() < 1.0
    # the simulated ZMP stays in the planned polygon; contact chatter as the neck leaves the ground moves the
    # per-tick centre of pressure by a few mm (the tail's 0.3 N contact drops out for single ticks), hence 1 mm
    assert m["zmp_min_margin_m"] > -0.001
