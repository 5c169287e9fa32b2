"""The checks of a successful single-target plan recomputed from its samples (FK, limits, the ZMP from finite
differences, ground and self clearance, a still base), shared by the test folders that plan on other robots."""
from __future__ import annotations

import numpy as np
import pytest

from snakehead import margins
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability


def verify_plan(plan, position, direction):
    """Every check of a successful plan, recomputed from its samples."""
    robot, base = plan.robot, plan.base
    assert plan.success, plan.failure
    (tg,) = plan.targets
    k = int(np.argmin(np.abs(plan.t - tg.time_s)))
    H = robot.head_pose(plan.q[k], base)  # whole-body FK of the planned joints when the plan arrives
    assert np.linalg.norm(H[:3, 3] - position) <= 1e-4
    assert np.degrees(np.arccos(np.clip(H[:3, 0] @ direction, -1.0, 1.0))) <= 0.05
    dt = np.diff(plan.t)  # the 2 ms control period (the last step to the end may be shorter)
    assert np.all(dt[:-1] == pytest.approx(0.002)) and 0 < dt[-1] <= 0.002 + 1e-12
    assert np.all(plan.q >= robot.lower - 1e-9) and np.all(plan.q <= robot.upper + 1e-9)
    # the ZMP from finite differences of the samples (not the plan's own velocities) inside by the plan's margin,
    # up to the difference between the two derivatives
    dyn = stability.dynamic_stability(robot, plan.t, plan.q, base, contact="ground")
    assert dyn.min_margin >= margins.ZMP_MARGIN - 1e-3, dyn.min_margin
    assert coll.ground_clearance(robot, plan.q, base)[:, robot.lifted_links].min() >= -coll.GROUND_TOLERANCE
    assert coll.self_clearance(robot, plan.q[::2], base).min() > 0.0
    # the base lies still on the ground throughout
    assert np.abs(plan.q[:, :robot.lift_joints.start] - plan.q[0, :robot.lift_joints.start]).max() < 1e-9
