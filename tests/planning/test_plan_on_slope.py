"""Plans on a slope (a plane terrain), checked in the world against independent computations: the ZMP the plan
reports (its ground frame, gravity leaning) equals the centre of pressure of the contact wrench that world gravity
asks for on the tilted plane; the contacts can give that wrench within their friction cones (a feasibility LP);
a 0 deg plane plans bit for bit as flat ground; a slope steeper than the friction holds is Infeasible by name.
(Terrains other than planes are refused: tests/scenes/test_scene_terrain.py.)"""
from __future__ import annotations

import math
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead._errors import Infeasible
from snakehead.dynamics import stability
from snakehead.dynamics.contact_set import ContactSet
from snakehead.dynamics.wrench_balance import is_balanced_lp
from snakehead.model.physics import GRAVITY
from snakehead.model.placement import WORLD_FRAME, BasePlacement, GroundFrame
from snakehead.samples.targets import reachable_targets
from snakehead.scenes.ground_scene import base_on_slope, scene_in_ground_frame
from snakehead.scenes.scene import load_scene
from snakehead.terrain.surfaces import plane_normal_deg

SLOPE = resources.files("snakehead") / "scenes" / "slope.toml"


def frame(pitch_deg: float, roll_deg: float = 0.0) -> GroundFrame:
    return GroundFrame.of_plane(plane_normal_deg(roll_deg, pitch_deg), (0.1, -0.2, 0.05))


def test_the_ground_frame_of_a_plane():
    assert GroundFrame.of_plane((0, 0, 1), (3.0, 4.0, 0.0)).is_world
    f = frame(10.0, 4.0)
    R = f.matrix[:3, :3]
    assert np.allclose(R.T @ R, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)
    assert np.allclose(R[:, 2], plane_normal_deg(4.0, 10.0))
    assert np.isclose(f.slope_deg, math.degrees(math.acos(plane_normal_deg(4.0, 10.0)[2])))
    assert np.allclose(f.gravity, R.T @ [0, 0, -GRAVITY])
    p = np.random.default_rng(0).normal(size=(5, 3))
    assert np.allclose(f.to_world(f.to_ground(p)), p)
    # the frame's origin lies on the plane
    n = plane_normal_deg(4.0, 10.0)
    assert np.isclose(n @ (np.array(f.origin) - [0.1, -0.2, 0.05]), 0.0)


def test_a_base_given_in_the_world_lies_on_the_slope_with_its_heading_seen_from_above():
    f = frame(10.0, 3.0)
    robot = snakehead.SnakeRobot.default()
    for x, y, yaw in ((0.0, 0.0, 0.0), (0.4, -0.3, 1.0), (-1.0, 2.0, -2.5)):
        base = base_on_slope(BasePlacement(x, y, yaw), f)
        root = f.matrix @ robot.root_pose(base)
        n = f.matrix[:3, 2]
        # the root sits body_axis_height above the plane, at (x, y) seen along the plane's normal from the world
        assert np.isclose(n @ (root[:3, 3] - np.array(f.origin)), robot.body_axis_height)
        foot = root[:3, 3] - robot.body_axis_height * n
        assert np.allclose(foot[:2], (x, y), atol=1e-12)
        body_x = (f.matrix @ robot.body_pose(base))[:3, 0]
        assert np.isclose(math.atan2(body_x[1], body_x[0]), yaw)


def test_a_scene_on_a_slope_is_rewritten_in_its_frame():
    scene = load_scene(SLOPE)
    ground, f = scene_in_ground_frame(scene)
    assert not f.is_world and np.isclose(f.slope_deg, 5.0)
    assert ground.base is not None and ground.base.ground == f
    for a, b in zip(scene.targets, ground.targets):
        assert np.allclose(f.to_world(b.position), a.position)
        assert np.allclose(f.direction_to_world(b.direction), a.direction)


def _world_cop(plan, rows):
    """The centre of pressure on the tilted plane (world) of the contact wrench world gravity asks for, from the
    plan's momenta and CoM moved to the world: w_c = (dP/dt - M g, dL/dt - c x M g) about the world origin; the
    point p of the plane where the moment of w_c about p is along the normal."""
    G, robot = plan.base.ground, plan.robot
    R, o = G.matrix[:3, :3], np.array(G.origin)
    dyn = plan.stability
    P, L, com = dyn.P @ R.T, dyn.L @ R.T, dyn.com @ R.T + o
    L = L + np.cross(o, P)  # about the world origin
    Pdot, Ldot = np.gradient(P, plan.t, axis=0), np.gradient(L, plan.t, axis=0)
    g = np.array([0.0, 0.0, -GRAVITY])
    M = robot.total_mass
    out = []
    for k in rows:
        f = Pdot[k] - M * g
        tau = Ldot[k] - np.cross(com[k], M * g)
        a, b = R[:, 0], R[:, 1]
        # (tau - (o + u a + v b) x f) . a = 0 and . b = 0: linear in (u, v)
        A = np.array([[np.cross(a, f) @ a, np.cross(b, f) @ a], [np.cross(a, f) @ b, np.cross(b, f) @ b]])
        rhs = np.array([(tau - np.cross(o, f)) @ a, (tau - np.cross(o, f)) @ b])
        out.append(np.linalg.solve(A, rhs))
    return np.array(out)


@pytest.fixture(scope="module")
def slope_plan():
    f = frame(10.0, 3.0)
    controller = snakehead.HeadController(snakehead.SnakeRobot.default(), base_pose=BasePlacement(0.2, -0.1, 0.7, f),
                                          seed=1)
    t = reachable_targets(controller, "same", 1, np.random.default_rng(5))[0]
    plan = snakehead.plan([(t.position, t.direction)], controller=controller)
    assert plan.success, (plan.failure, plan.notes)
    return plan


def test_the_planned_zmp_is_the_centre_of_pressure_world_gravity_asks_for(slope_plan):
    plan = slope_plan
    rows = np.linspace(2, len(plan.t) - 3, 400).astype(int)
    cop = _world_cop(plan, rows)
    assert np.abs(cop - plan.stability.zmp[rows]).max() < 1e-6
    # and it is not the flat-ground ZMP: the lean matters on 10 deg
    flat = stability._zmp_from(plan.stability.com[rows], np.gradient(plan.stability.P, plan.t, axis=0)[rows],
                               np.gradient(plan.stability.L, plan.t, axis=0)[rows], plan.robot.total_mass)
    assert np.abs(flat - cop).max() > 5e-3


def test_the_contacts_can_hold_the_body_on_the_slope_within_friction(slope_plan):
    """At samples along the plan, the lowest points of the links touching the tilted plane (world), with the
    plane's normal and the plan's friction, can give the contact wrench world gravity asks for (one LP each)."""
    plan = slope_plan
    G, robot = plan.base.ground, plan.robot
    R, o = G.matrix[:3, :3], np.array(G.origin)
    links = np.asarray(robot.base_links, int)
    for k in np.linspace(0, len(plan.t) - 1, 6).astype(int):
        frames = robot.frames_many(plan.q[k][None], plan.base)
        pts, _ = robot.lowest_points(frames, links[np.isin(links, robot.shaped_links)])
        pts = pts[0][pts[0][:, 2] <= 1e-3]
        world = pts @ R.T + o
        c = stability.center_of_mass(robot, plan.q[k], plan.base) @ R.T + o
        M = robot.total_mass
        gi = np.r_[M * np.array([0, 0, -GRAVITY]), np.cross(c, M * np.array([0, 0, -GRAVITY]))]  # at rest
        contacts = ContactSet(world, np.broadcast_to(R[:, 2], world.shape), mu=0.5)
        assert is_balanced_lp(contacts, gi)
        # with too little friction for the slope (tan 10.4 deg ~ 0.18), the same contacts cannot hold it
        assert not is_balanced_lp(ContactSet(world, np.broadcast_to(R[:, 2], world.shape), mu=0.1), gi)


def test_a_level_plane_plans_bit_for_bit_as_flat_ground():
    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, seed=1)
    t = reachable_targets(controller, "same", 1, np.random.default_rng(2))[0]
    flat = snakehead.plan([(t.position, t.direction)], robot=robot, seed=1)
    level = snakehead.plan([(t.position, t.direction)], robot=robot, seed=1,
                           base=BasePlacement(ground=GroundFrame.of_plane((0, 0, 1), (0, 0, 0))))
    assert level.base.ground == WORLD_FRAME
    assert np.array_equal(flat.q, level.q) and np.array_equal(flat.t, level.t)
    assert np.array_equal(flat.stability.zmp, level.stability.zmp, equal_nan=True)


def test_a_slope_steeper_than_friction_is_infeasible_by_name():
    base = BasePlacement(ground=frame(40.0))
    with pytest.raises(Infeasible, match="steeper than the friction"):
        snakehead.plan([((0.0, 0.5, 0.3), (0.0, 1.0, 0.0))], base=base)


def test_the_cli_plans_the_shipped_slope_scene(tmp_path: Path):
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(SLOPE), "--out", str(out),
                        "--no-sim"], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert any(out.iterdir())


def test_a_scene_in_a_ground_frame_is_not_saved_as_if_on_flat_ground(slope_plan, tmp_path: Path):
    """A scene file holds world poses (and a [terrain] table): a scene whose base lies in a slope's ground frame (a
    plan's, or the live viewer's on a slope) would load on flat ground, so it is refused by name; the live viewer
    refuses a scene file on a slope (its gizmos move ground-frame targets)."""
    from snakehead._errors import InputError
    from snakehead.scenes.scene import Scene, Target, save_scene
    from snakehead.viz.live import LiveViewer

    t = slope_plan.targets[0]
    scene = Scene(name="s", targets=(Target("t", t.position, t.direction),), base=slope_plan.base)
    with pytest.raises(InputError, match="ground frame"):
        save_scene(scene, tmp_path / "s.toml")
    assert not (tmp_path / "s.toml").exists()
    with pytest.raises(InputError, match="live viewer takes scenes on flat ground"):
        LiveViewer(load_scene(SLOPE), port=0, save_dir=tmp_path)
