"""The contact wrench cone (dynamics.contact_set, wrench_balance) against MuJoCo's contact forces on a slope, all in
the world frame (world gravity, the slope's normal from its angles): the wrench MuJoCo's floor contacts exert on a
body lying still on a slope lies inside the cone of those contacts and equals minus the gravito-inertial wrench; and
the cone's verdict on that wrench (can the contacts hold the body?) is MuJoCo's (does the body stay or slide?) on
both sides of the friction limit tan(slope)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from snakehead import BasePlacement, HeadController, SnakeRobot, sim
from snakehead.dynamics import stability
from snakehead.dynamics.contact_set import ContactSet, contact_wrench_cone
from snakehead.dynamics.wrench_balance import cwc_margin, gravito_inertial_wrench, is_balanced_lp
from snakehead.model.physics import GRAVITY
from snakehead.model.placement import GroundFrame
from snakehead.planning.start_state import bending_state
from snakehead.terrain.surfaces import plane_normal_deg

pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def lying(robot):
    return bending_state(HeadController(robot))


def lie(robot, q, slope_deg, friction, seconds):
    """MuJoCo: the body lying still (q held) on a slope rising along world x; the result and its ground frame."""
    ground = GroundFrame.of_plane(plane_normal_deg(0.0, -slope_deg), (0.0, 0.0, 0.0))
    base = BasePlacement(0.0, 0.0, 0.4, ground=ground)
    res = sim.simulate_trajectory(robot, np.array([0.0, seconds]), np.vstack([q, q]), base, settle=0.0,
                                  friction=friction)
    return res, base


def world_contacts(res, ground, k, mu):
    """MuJoCo's floor contacts at tick k in the world: a ContactSet on the slope's normal, and their wrench about
    the world origin."""
    points = ground.to_world(res.contact_points[k])
    forces = ground.direction_to_world(res.contact_forces[k])
    normal = ground.matrix[:3, 2]
    wrench = np.r_[forces.sum(axis=0), np.cross(points, forces).sum(axis=0)]
    return ContactSet(points, np.broadcast_to(normal, points.shape), mu=mu), wrench


def test_mujocos_contact_wrench_at_rest_on_a_slope_is_inside_the_cone_and_balances_the_weight(robot, lying):
    res, base = lie(robot, lying, 8.0, 0.8, 0.3)
    ground = base.ground
    contacts, wrench = world_contacts(res, ground, -1, 0.8)
    assert len(contacts) >= 8
    assert is_balanced_lp(contacts, -wrench)  # the span form of all of MuJoCo's contacts holds MuJoCo's wrench
    # the face form on the contacts' hull corners: on one plane with one normal, a force at any contact is a convex
    # combination of the same force at the corners (its wrench too), so the corners' cone is all the contacts'
    in_plane = res.contact_points[-1][:, :2]
    corners = ConvexHull(in_plane).vertices
    A = contact_wrench_cone(ContactSet(contacts.points[corners], contacts.normals[corners], mu=0.8))
    # MuJoCo's own contact forces make a wrench the cone holds (w_c inside: the margin of w_gi = -w_c >= 0)
    assert cwc_margin(A, -wrench) >= -1e-6 * np.linalg.norm(wrench)
    # at rest it is minus the gravito-inertial wrench, the weight at the CoM (world gravity)
    c = ground.to_world(stability.center_of_mass(robot, lying, base))
    w_gi = gravito_inertial_wrench(robot.total_mass, c, np.zeros(3), np.zeros(3))
    weight = robot.total_mass * GRAVITY
    np.testing.assert_allclose(wrench[:3], -w_gi[:3], atol=0.01 * weight)
    np.testing.assert_allclose(wrench[3:], -w_gi[3:], atol=0.01 * weight * 0.5)  # moments about the origin, N m
    assert cwc_margin(A, w_gi) > 0.0


@pytest.mark.parametrize("mu, holds", [(0.35, True), (0.2, False)])
def test_the_cones_verdict_on_friction_is_mujocos(robot, lying, mu, holds):
    """15 deg: tan 15 deg = 0.268. With mu 0.35 the cone holds the weight and MuJoCo's body stays; with mu 0.2 the
    cone cannot and MuJoCo's body slides down the slope."""
    slope_deg = 15.0
    assert (mu > math.tan(math.radians(slope_deg))) == holds
    res, base = lie(robot, lying, slope_deg, mu, 0.5)
    contacts, _ = world_contacts(res, base.ground, 5, mu)  # 10 ms in: lying, not yet moving
    c = base.ground.to_world(stability.center_of_mass(robot, lying, base))
    w_gi = gravito_inertial_wrench(robot.total_mass, c, np.zeros(3), np.zeros(3))
    assert is_balanced_lp(contacts, w_gi) == holds
    moved = np.linalg.norm(res.root_pose[-1, :3, 3] - res.root_pose[0, :3, 3])
    if holds:
        assert moved < 2e-3
    else:
        assert moved > 2e-2
