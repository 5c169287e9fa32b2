"""The "wheeled" quirk sample (issue 34): passive wheels hanging off every module, their bottoms 1 mm below the
modules', so that the body stands on its wheels. The paper's initial state (the base arc optimised on the links' end
points) stood 2 cm inside the end points' support polygon but 1.6 cm outside the wheels'; the planner could not lift
the head into it and moved from the neck and head curled on the ground straight to each target, through the ground
(bench/targets.py: 11/20, 16/20, 18/20 of the reachable sets). ``solve.initial_state`` now chooses the initial
state on the actual contacts when the paper's does not stand on them."""
from __future__ import annotations

import numpy as np
import pytest
from plan_verification import verify_plan

import snakehead
from snakehead import backbone, margins
from snakehead.samples.published import write_robot
from snakehead.samples.targets import reachable_targets
from snakehead.solve.initial_state import INITIAL_MARGIN, initial_margins, stable_initial_configuration


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    return snakehead.SnakeRobot.from_file(write_robot("wheeled", tmp_path_factory.mktemp("wheeled")))


@pytest.fixture(scope="module")
def controller(robot):
    return snakehead.HeadController(robot, method="free_roll", seed=1)  # as bench/targets.py makes it


def test_the_paper_initial_state_does_not_stand_on_the_wheels(robot):
    """The case: the paper's initial configuration is stable on the end points, not on the wheels' contacts."""
    from snakehead.dynamics import stability

    q0 = backbone.initial_configuration(robot)
    assert stability.static_margin(robot, q0) > margins.DETOUR_MARGIN  # the end points' polygon
    assert initial_margins(robot, q0)[0] < 0.0  # the wheels'


def test_the_initial_state_stands_on_the_wheels(robot, controller):
    q = controller.q_initial
    assert initial_margins(robot, q)[0] >= INITIAL_MARGIN
    # the neck and head keep the paper's up curve; only the base arc changed
    q0 = backbone.initial_configuration(robot)
    nb = robot.parts.base.stop
    np.testing.assert_array_equal(q[nb:], q0[nb:])
    assert not np.allclose(q[:nb], q0[:nb])


def test_a_robot_on_its_modules_keeps_the_paper_initial_state():
    robot = snakehead.SnakeRobot.default()
    np.testing.assert_array_equal(stable_initial_configuration(robot), backbone.initial_configuration(robot))


@pytest.mark.parametrize("index", [1, 4, 5])
def test_reachable_targets_plan(controller, index):
    """Targets 2, 5 and 6 of bench/targets.py's "same" set (seed 0) went into the ground (33.5 mm, 170.8 mm, ...)."""
    t = reachable_targets(controller, "same", 6, np.random.default_rng(0))[index]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    verify_plan(plan, t.position, t.direction)


@pytest.mark.slow
def test_mujoco_tracks_a_plan(controller):
    """A plan of the "same" set executed in MuJoCo: within 2 mm and 1 deg (the first five of bench/targets.py's are,
    1.10 mm at most). Not yet everywhere: on the "shape" set 4 of 20 miss by up to 3.2 mm (the base rocks ~1 mm on
    the wheels, bench/RESULTS.md)."""
    t = reachable_targets(controller, "same", 2, np.random.default_rng(0))[1]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    verify_plan(plan, t.position, t.direction)
    sim = snakehead.simulate(plan)
    assert sim.position_error_m <= 0.002 and sim.direction_error_deg <= 1.0
    assert sim.zmp_inside
