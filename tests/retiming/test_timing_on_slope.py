"""The retiming on a slope times the path with the slope's leaning gravity (the base's ground frame): the samples of a
slope plan's path retimed at its base keep the ZMP margin and the friction measured on the slope, and its own check
is the slope's, not the flat ground's; on flat ground the timing is the same at every placement."""
from __future__ import annotations

import numpy as np

import snakehead
from snakehead import HeadController, SnakeRobot
from snakehead.model.placement import BasePlacement, GroundFrame
from snakehead.retiming.limit_check import check_limits
from snakehead.retiming.timing import resolve_limits, retime
from snakehead.samples.targets import reachable_targets
from snakehead.terrain.surfaces import plane_normal_deg


def test_a_slope_plans_path_is_timed_with_the_slopes_gravity():
    robot = SnakeRobot.default()
    slope = GroundFrame.of_plane(plane_normal_deg(0.0, 10.0), (0.0, 0.0, 0.0))
    controller = HeadController(robot, base_pose=BasePlacement(0.3, -0.2, 0.0, slope), seed=1)
    t = reachable_targets(controller, "same", 1, np.random.default_rng(5))[0]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    assert plan.success, plan.failure
    waypoints = np.array([q for _, _, q in plan.states])
    keep = np.r_[True, np.abs(np.diff(waypoints, axis=0)).max(axis=1) > 0]  # the holds' repeated waypoints out
    waypoints = waypoints[keep]
    limits = resolve_limits(robot)
    on_slope = retime(robot, waypoints, plan.base)
    check = check_limits(robot, on_slope.q, on_slope.qd, on_slope.qdd, plan.base, limits)
    assert check.within(), check
    flat = [retime(robot, waypoints, BasePlacement(x, y, yaw)) for x, y, yaw in ((0.0, 0.0, 0.0), (1.0, -2.0, 2.0))]
    assert np.array_equal(flat[0].t, flat[1].t)  # on flat ground the placement does not matter
    # the retiming's own check of its samples is the slope's: its ZMP margin is check_limits' at the plan's base,
    # not the flat ground's (the weight leans by 10 deg)
    assert on_slope.check is not None and flat[0].check is not None
    assert on_slope.check.zmp_margin_m == check.zmp_margin_m
    assert abs(on_slope.check.zmp_margin_m - flat[0].check.zmp_margin_m) > 1e-3
