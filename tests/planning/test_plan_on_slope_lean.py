"""On a slope the planner's start chooses with the leaning weight: the bending state's curl is weighed with the CoM's
point below it along the slope's gravity (and kept per ground and heading only), and where the initial state is not
safe at the plan's base the lift ends at a safe lifted state near it instead of going from the curl on the ground
straight to the target (a path that often passes through the ground). A published-style snake plans a target on a
10 deg slope at the heading (up the slope) where it failed before."""
from __future__ import annotations

import math

import numpy as np
import pytest

import snakehead
from snakehead.dynamics import stability
from snakehead.model.placement import BasePlacement, GroundFrame
from snakehead.planning.start_state import bending_state, ground_curl
from snakehead.planning.waypoints import Waypoints
from snakehead.samples import published
from snakehead.samples.targets import reachable_targets
from snakehead.terrain.surfaces import plane_normal_deg


def slope(deg: float) -> GroundFrame:
    return GroundFrame.of_plane(plane_normal_deg(0.0, -deg), (0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def sea(tmp_path_factory) -> snakehead.SnakeRobot:
    return snakehead.SnakeRobot.from_file(published.write_robot("sea", tmp_path_factory.mktemp("sea") / "sea"))


def _leaning_margin(robot, q, base):
    com = base.below_along_gravity(stability.center_of_mass(robot, q[None], base))
    poly = stability.support_polygon(robot, q, base)
    return stability.polygon_margin_many(poly[None], np.ones((1, len(poly)), bool), com)[0]


def test_the_curl_on_a_slope_is_weighed_leaning_and_kept_per_heading(sea):
    up, down = (BasePlacement(0.0, 0.0, yaw, slope(10.0)) for yaw in (0.0, math.pi))
    controller = snakehead.HeadController(sea, base_pose=up, seed=1)
    shape = controller.q_initial
    flat = ground_curl(sea, shape)
    assert np.array_equal(bending_state(controller, shape), flat)  # without a base: as on flat ground
    for base in (up, down):
        curl = bending_state(controller, shape, base)
        assert np.array_equal(curl, ground_curl(sea, shape, base))
        # the curl with the largest leaning margin: at least the flat-ground curl's on this slope
        assert _leaning_margin(sea, curl, base) >= _leaning_margin(sea, flat, base) - 1e-12
    assert not np.array_equal(bending_state(controller, shape, up), bending_state(controller, shape, down))


def test_a_published_style_snake_plans_up_a_10_deg_slope(sea):
    """sea, 10 deg, body up the slope: the initial state's margin leans below DETOUR_MARGIN there, and the plan
    used to go from the curl on the ground straight to the target, 47 mm into the ground (bench/terrain.py)."""
    base = BasePlacement(0.0, 0.0, 0.0, slope(10.0))
    controller = snakehead.HeadController(sea, base_pose=base, seed=1)
    way = Waypoints(sea, base)
    assert not way.feasible(controller.q_initial[None])[0]  # the initial state is not safe here
    t = reachable_targets(controller, "same", 2, np.random.default_rng(100))[1]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    assert plan.success, plan.failure
    assert any("leaning" in label for label, _ in plan.segments)
    assert plan.min_ground_clearance_m >= -1e-3 and plan.min_zmp_margin_m > 0
