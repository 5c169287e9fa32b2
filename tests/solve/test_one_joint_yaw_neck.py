"""A one-joint yaw neck before a pitch-first 6-DOF head (issue 34, item 9): the neck has no pitch joint, so its
lifting part is empty (``SnakeRobot.lift_joints`` is the empty slice at the head's first joint) and its lift frame
is the neck's end. The planner built the chain lift_frame -> neck_end, which then has no link, and every plan of
such a robot stopped with exit 3 (``InternalError: ... base and tip are the same link 'b0'``). Now the neck's
solve is skipped (B0 is the lift frame) and the head's pitch joints lift the head."""
from __future__ import annotations

import numpy as np
import pytest
from plan_verification import verify_plan

import snakehead
from snakehead.app import cli
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.model.robot_file import write_robot_file
from snakehead.samples.targets import reachable_targets

#: 13 joints, yaw first: base joints 1-6, the neck joint 7 (yaw), the head joints 8-13 (pitch first)
SPEC = SnakeSpec(n_joints=13, module_length=0.10, section=0.06, mass_per_module=0.3, first_axis="yaw",
                 markers={"p0": 6, "b0": 7}, name="yaw_neck_snake")


def yaw_neck_robot() -> snakehead.SnakeRobot:
    return snakehead.SnakeRobot.from_urdf(snake_urdf(SPEC), base_end="p0", neck_end="b0", head_tip="head_tip")


@pytest.fixture(scope="module")
def controller():
    return snakehead.HeadController(yaw_neck_robot(), method="free_roll", seed=1)


def test_the_robot_is_the_case(controller):
    """The neck is one yaw joint and the head begins with a pitch joint: nothing of the neck lifts."""
    robot = controller.robot
    assert robot.joint_kinds[robot.parts.neck] == ("yaw",)
    assert robot.joint_kinds[robot.parts.head.start] == "pitch"
    assert robot.lift_joints == slice(robot.parts.head.start, robot.parts.head.start)
    assert robot.lift_frame == robot.parts.neck_end


def test_the_head_solve_starts_at_the_neck_end(controller):
    """The segmented solve of a reachable target: the neck's part is B0 where the base puts it (no joint moves),
    and the head reaches the target from it."""
    robot = controller.robot
    t = reachable_targets(controller, "same", 1, np.random.default_rng(0))[0]
    sol = controller.solve(t.position, t.direction)
    assert sol.neck is not None and sol.neck.q.shape == (0,)
    np.testing.assert_allclose(sol.neck.frame, robot.frame(sol.q, robot.parts.neck_end, controller.base), atol=1e-12)
    assert np.array_equal(sol.q[robot.parts.neck], controller.q_initial[robot.parts.neck])


def test_a_reachable_target_plans(controller):
    """The first reachable target plans and its motion passes the independent checks (it raised InternalError)."""
    t = reachable_targets(controller, "same", 1, np.random.default_rng(0))[0]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    verify_plan(plan, t.position, t.direction)


def test_the_command_line_plans_it(tmp_path):
    """``snakehead plan`` with the robot's file: exit 0 (it was 3), and the planned head where the target is."""
    urdf = tmp_path / "yaw_neck.urdf"
    urdf.write_text(snake_urdf(SPEC))
    robot_file = write_robot_file(tmp_path / "yaw_neck.toml", urdf=urdf, base_end="p0", neck_end="b0",
                                  head_tip="head_tip")
    controller = snakehead.HeadController(snakehead.SnakeRobot.from_file(robot_file), method="free_roll", seed=1)
    t = reachable_targets(controller, "same", 1, np.random.default_rng(0))[0]
    code = cli.main(["plan", "--robot", str(robot_file), "--position", *map(str, t.position),
                     "--direction", *map(str, t.direction), "--out", str(tmp_path / "out"), "--no-sim", "--method", "free_roll"])
    assert code == 0


@pytest.mark.slow
def test_plans_track_in_mujoco(controller, mujoco):
    """Three reachable targets of each kind planned and tracked in MuJoCo within the README's 2 mm and 1 deg."""
    rng = np.random.default_rng(3)
    for kind in ("same", "shape", "place"):
        for t in reachable_targets(controller, kind, 3, rng):
            plan = snakehead.plan([(t.position, t.direction)], controller=controller)
            verify_plan(plan, t.position, t.direction)
            sim = snakehead.simulate(plan)
            assert sim.position_error_m <= 2e-3 and sim.direction_error_deg <= 1.0, (kind, sim.position_error_m)
            assert sim.zmp_inside
