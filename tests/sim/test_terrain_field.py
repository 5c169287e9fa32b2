"""Rough terrain in MuJoCo (sim.terrain_field): the hfield floor's surface, found by MuJoCo's own ray casts, is the
terrain's (its heights from the C++ terrain query): exactly for a heightfield, away from the risers for a staircase
(sampled every FIELD_SPACING_M); a body lying on undulating ground rests on the hfield."""
from __future__ import annotations

import numpy as np
import pytest

from snakehead import BasePlacement, HeadController, InputError, SnakeRobot, sim
from snakehead.model.placement import GroundFrame
from snakehead.planning.start_state import bending_state
from snakehead.sim.mjcf import FLOOR
from snakehead.sim.terrain_field import FIELD_SPACING_M
from snakehead.terrain import HeightfieldTerrain, PlaneTerrain
from snakehead.terrain.generated import step, undulating

mujoco = pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def surface_by_rays(robot, terrain, xy):
    """z of the floor geom under each point, by MuJoCo's ray cast (NaN where the ray hits something else)."""
    m = sim.build_spec(robot, terrain=terrain).compile()
    d = mujoco.MjData(m)
    d.qpos[:3] = (100.0, 100.0, 100.0)  # the robot out of the rays' way (its free joint's position)
    mujoco.mj_forward(m, d)
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, FLOOR)
    z = np.full(len(xy), np.nan)
    hit = np.zeros(1, np.int32)
    for k, (x, y) in enumerate(xy):
        dist = mujoco.mj_ray(m, d, np.array([x, y, 2.0]), np.array([0.0, 0.0, -1.0]), None, 1, -1, hit)
        if hit[0] == floor:
            z[k] = 2.0 - dist
    return z


def test_a_heightfield_is_the_hfield(robot):
    x, y = np.linspace(0, 1, 41), np.linspace(0, 2, 61)
    heights = 0.03 * np.sin(2 * np.pi * x / 0.5)[:, None] + 0.02 * (y / 2)[None, :]  # not symmetric in x or y
    terrain = HeightfieldTerrain(heights, np.array([1.0, 2.0]), np.array([-0.5, -1.0, 0.01]))
    xy = np.random.default_rng(0).uniform([-0.45, -0.95], [0.45, 0.95], (300, 2))
    z = surface_by_rays(robot, terrain, xy)
    assert np.isfinite(z).all()
    np.testing.assert_allclose(z, terrain.height(xy), atol=1e-6)


def test_a_staircase_is_the_hfield_away_from_its_risers(robot):
    terrain = step(0.04, 30.0, (0.0, 0.0, 0.0))
    xy = np.random.default_rng(1).uniform([-0.8, -0.8], [0.8, 0.8], (300, 2))
    u = xy @ np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    far = (np.abs(u) > 2 * FIELD_SPACING_M) & np.isfinite(terrain.height(xy))  # the riser at u = 0; on the stairs
    z = surface_by_rays(robot, terrain, xy[far])
    np.testing.assert_allclose(z, terrain.height(xy[far]), atol=1e-6)


def test_a_body_lies_on_undulating_ground(robot):
    """3 cm amplitude, 0.5 m wavelength: the lying body settles on the hfield, every contact on its surface."""
    terrain = undulating(0.03, 0.5)
    q = bending_state(HeadController(robot))
    res = sim.simulate_trajectory(robot, np.array([0.0, 0.3]), np.vstack([q, q]), BasePlacement(0.0, 0.0, 0.0),
                                  settle=0.5, terrain=terrain, noslip_iterations=10, drop=0.035)
    points = res.contact_points[-1]
    assert len(points) >= 4
    np.testing.assert_allclose(points[:, 2], terrain.height(points[:, :2]), atol=2e-3)  # MuJoCo's soft contacts


def test_a_plane_or_a_tilted_frame_is_not_a_terrain_field(robot):
    with pytest.raises(InputError, match="terrain must be"):
        sim.build_spec(robot, terrain=PlaneTerrain(np.array([0.1, 0.0, 1.0]), np.zeros(3)))
    with pytest.raises(InputError, match="terrain must be"):
        sim.build_spec(robot, terrain=undulating(0.03, 0.5),
                       ground=GroundFrame.of_plane((0.1, 0.0, 1.0), (0.0, 0.0, 0.0)))
