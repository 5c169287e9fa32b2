"""MuJoCo on a slope (snakehead.sim with a plan's ground frame): the floor is the tilted plane in the world, the robot
and the obstacles are put through the ground frame's pose, and what is measured comes back in the ground frame; each
checked against a computation that does not go through the code under test (the slope's normal from its angles,
Coulomb's law, statics, the planner's kinematics). On flat ground the simulation is the one it always was, bit for
bit."""
import math

import numpy as np
import pytest

import snakehead
from snakehead import BasePlacement, HeadController, SnakeRobot, sim
from snakehead.dynamics import stability
from snakehead.geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from snakehead.model.physics import GRAVITY
from snakehead.model.placement import WORLD_FRAME, GroundFrame
from snakehead.planning.start_state import bending_state
from snakehead.samples.targets import reachable_targets
from snakehead.sim import sensors, tracking
from snakehead.solve.head import angle_between_deg
from snakehead.terrain.surfaces import plane_normal_deg


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def lying(robot):
    """The bending state the planner starts from (the base on its arc, the neck and head curled on the ground)."""
    return bending_state(HeadController(robot))


def slope(pitch_deg, roll_deg=0.0, point=(0.0, 0.0, 0.0)):
    return GroundFrame.of_plane(plane_normal_deg(roll_deg, pitch_deg), point)


def held(q, seconds):
    """A trajectory holding q for ``seconds``."""
    return np.array([0.0, seconds]), np.vstack([q, q])


# ------------------------------------------------------------------------------------------------------------
# the model: floor, placement, obstacles
# ------------------------------------------------------------------------------------------------------------
def test_the_floor_is_the_slope_and_the_robot_rests_on_it(mujoco, robot, lying):
    ground = slope(7.0, roll_deg=-4.0, point=(0.3, -0.2, 0.15))
    s = sim.build_model(robot, ground=ground)
    d = mujoco.MjData(s.model)
    base = BasePlacement(0.2, -0.1, 0.6, ground=ground)
    s.set_state(d, lying, base)
    n = d.geom_xmat[s.floor_geom].reshape(3, 3)[:, 2]
    np.testing.assert_allclose(n, plane_normal_deg(-4.0, 7.0), atol=1e-12)  # the slope's normal, from its angles
    np.testing.assert_allclose(n, ground.matrix[:3, 2], atol=1e-12)
    assert n @ (d.geom_xpos[s.floor_geom] - (0.3, -0.2, 0.15)) == pytest.approx(0.0, abs=1e-12)  # through the point
    np.testing.assert_allclose(s.model.opt.gravity, (0.0, 0.0, -GRAVITY))  # the world's gravity, untouched
    # the robot where the planner puts it: its frames in the ground frame, and in the world through the frame's pose
    expected = robot.frames(lying, base)
    np.testing.assert_allclose(s.frames(d), expected, atol=1e-12)
    np.testing.assert_allclose(d.xpos[s.body_ids], ground.to_world(expected[:, :3, 3]), atol=1e-12)
    np.testing.assert_allclose(d.xmat[s.body_ids].reshape(-1, 3, 3), ground.matrix[:3, :3] @ expected[:, :3, :3],
                               atol=1e-12)
    # lying on the tilted plane: touching it, not in it nor above it
    floor = [i for i in range(d.ncon) if s.floor_geom in (d.contact[i].geom1, d.contact[i].geom2)]
    assert len(floor) >= 8
    assert max(abs(d.contact[i].dist) for i in floor) < 1e-9


def test_obstacles_are_placed_through_the_ground_frame(mujoco, robot):
    ground = slope(10.0, roll_deg=3.0, point=(0.0, 0.0, -0.05))
    R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    box = BoxObstacle(np.array([0.5, 0.4, 0.1]), np.array([0.1, 0.2, 0.2]), R)
    wall = WallWithHole(np.array([0.8, 0.0, 0.2]), np.array([-1.0, 0.2, 0.0]), np.array([0.4, 0.4, 0.02]), 0.15)
    pose = np.eye(4)
    pose[:3, 3] = (-0.4, 0.3, 0.05)
    rock = MeshObstacle(None, pose, np.ones(3), np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]))
    obstacles = [box, wall, rock]
    flat, tilted = (sim.build_model(robot, obstacles=obstacles, ground=g) for g in (WORLD_FRAME, ground))
    df, dt = mujoco.MjData(flat.model), mujoco.MjData(tilted.model)
    mujoco.mj_forward(flat.model, df)
    mujoco.mj_forward(tilted.model, dt)
    k = [g for g in range(flat.model.ngeom) if flat.model.geom_bodyid[g] == 0 and g != flat.floor_geom]
    assert len(k) > 10  # the box, the wall's staircase and the rock
    np.testing.assert_allclose(dt.geom_xpos[k], ground.to_world(df.geom_xpos[k]), atol=1e-12)
    np.testing.assert_allclose(dt.geom_xmat[k].reshape(-1, 3, 3),
                               ground.matrix[:3, :3] @ df.geom_xmat[k].reshape(-1, 3, 3), atol=1e-12)


def test_a_base_on_another_ground_than_the_models_is_refused(mujoco, robot, lying):
    s = sim.build_model(robot)
    d = mujoco.MjData(s.model)
    with pytest.raises(snakehead.InputError, match="slope"):
        s.set_state(d, lying, BasePlacement(ground=slope(5.0)))
    s = sim.build_model(robot, ground=slope(5.0))
    with pytest.raises(snakehead.InputError, match="another ground"):
        s.set_state(mujoco.MjData(s.model), lying, BasePlacement(ground=slope(6.0)))


# ------------------------------------------------------------------------------------------------------------
# what is measured, in the ground frame
# ------------------------------------------------------------------------------------------------------------
def test_momenta_on_a_slope_three_ways(mujoco, robot):
    """Subtree momenta == per-body sum == the planner's Eqs. 25-31 in the ground frame (root held still)."""
    rng = np.random.default_rng(5)
    ground = slope(12.0, roll_deg=5.0, point=(0.1, 0.2, 0.3))
    s = sim.build_model(robot, ground=ground)
    d = mujoco.MjData(s.model)
    q, qd = robot.body.random_configuration(rng), rng.uniform(-1, 1, robot.n_joints)
    base = BasePlacement(0.2, -0.1, 0.4, ground=ground)
    s.set_state(d, q, base)
    d.qvel[s.dof_adr] = qd
    mujoco.mj_forward(s.model, d)
    P, L = tracking.momenta_of_state(s, d)
    P2, L2 = tracking.momenta_per_body(s, d)
    P3, L3 = stability.momenta_from_velocities(robot, q, qd, base)
    for a, b in ((P, P2), (L, L2), (P, P3), (L, L3)):
        np.testing.assert_allclose(a, b, atol=1e-9)


def test_resting_on_a_slope_the_contacts_carry_the_weight_below_the_centre_of_mass(mujoco, robot, lying):
    """Statics: the ground's forces on a body at rest are minus its weight, the slope's gravity in the ground frame
    (from the slope's angle: M G (sin a, 0, cos a) up the slope and off it), and their centre of pressure is the
    point of the slope below the centre of mass along gravity."""
    a = 8.0
    ground = slope(a)
    base = BasePlacement(0.1, 0.0, 0.3, ground=ground)
    res = sim.simulate_trajectory(robot, *held(lying, 0.2), base, settle=0.5)
    M = robot.total_mass
    f = res.contact_forces[-1].sum(axis=0)
    np.testing.assert_allclose(f, M * GRAVITY * np.array([-math.sin(math.radians(a)), 0.0, math.cos(math.radians(a))]),
                               atol=0.01 * M * GRAVITY)  # the downhill direction is the ground frame's +x here
    com = stability.center_of_mass(robot, lying, base)
    np.testing.assert_allclose(res.com[-1], com, atol=2e-4)
    np.testing.assert_allclose(res.zmp[-1], base.below_along_gravity(com), atol=5e-4)  # measured: 0.04 mm
    assert np.all(np.abs(res.contact_points[-1][:, 2]) < 1e-4)  # on the slope's plane, z = 0 of the ground frame


# ------------------------------------------------------------------------------------------------------------
# friction: holding on a gentle slope, sliding on a steep one
# ------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("noslip", [None, 0])
def test_a_lying_body_stays_on_a_gentle_slope(mujoco, robot, lying, noslip):
    """5 deg, friction 0.8 > tan 5 deg = 0.087: the body stays (with MuJoCo's soft contacts alone too: noslip 0).
    Measured: the root moves 0.0003 mm in 1 s (0.027 mm with noslip 0)."""
    ground = slope(5.0, roll_deg=2.0)
    res = sim.simulate_trajectory(robot, *held(lying, 1.0), BasePlacement(0.0, 0.0, 0.8, ground=ground),
                                  settle=0.1, friction=0.8, noslip_iterations=noslip)
    assert res.t[-1] - res.t[0] >= 1.0
    moved = np.linalg.norm(res.root_pose[:, :3, 3] - res.root_pose[0, :3, 3], axis=1).max()
    assert moved < 2e-3
    assert res.base_slide_m < 2e-3


def test_a_lying_body_slides_down_a_steep_slope_as_coulomb_says(mujoco, robot, lying):
    """25 deg, friction 0.3 < tan 25 deg = 0.466: the body slides downhill with a = G (sin a - mu cos a)
    = 1.48 m/s^2, 0.74 m in the first second (from rest; MuJoCo's soft contacts, nothing of ours)."""
    a, mu = math.radians(25.0), 0.3
    assert math.tan(a) > mu
    ground = slope(25.0)
    res = sim.simulate_trajectory(robot, *held(lying, 1.0), BasePlacement(ground=ground), settle=0.0, friction=mu)
    d = res.root_pose[-1, :3, 3] - res.root_pose[0, :3, 3]
    span = res.t[-1] - res.t[0]
    expected = 0.5 * GRAVITY * (math.sin(a) - mu * math.cos(a)) * span**2
    assert np.linalg.norm(d) > 0.05
    assert d[0] == pytest.approx(expected, rel=0.02)  # the ground frame's +x is downhill (measured: 0.7397 m)
    assert abs(d[1]) < 0.01 * expected and abs(d[2]) < 5e-3  # straight down the slope, on it


def test_the_imu_reads_the_worlds_gravity_on_a_slope(mujoco, robot, lying):
    """A link lying on a 9 deg slope: the accelerometer (noise-free) reads G, leaning 9 deg from the link's z (the
    slope's normal), downhill; the gyro reads nothing at rest."""
    ground = slope(9.0)
    s = sim.build_model(robot, ground=ground)
    d = mujoco.MjData(s.model)
    s.set_state(d, lying, BasePlacement(ground=ground))
    imu = sensors.Imu(gyro_noise_density=0.0, gyro_bias_random_walk=0.0, accel_noise_density=0.0)
    R = d.xmat[s.root_body].reshape(3, 3)  # MuJoCo's world orientation, what the closed loop gives the IMU
    imu.start(R)
    gyro, accel = imu.read(R, 0.002)
    np.testing.assert_allclose(gyro, 0.0, atol=1e-12)
    assert np.linalg.norm(accel) == pytest.approx(GRAVITY, rel=1e-12)
    assert angle_between_deg(accel, np.array([0.0, 0.0, 1.0])) == pytest.approx(9.0, abs=1e-9)
    # the specific force points up the slope, against the ground frame's gravity, seen in the link's axes
    Rg = s.frames(d)[0, :3, :3]
    np.testing.assert_allclose(accel, -Rg.T @ ground.gravity, atol=1e-12)


# ------------------------------------------------------------------------------------------------------------
# flat ground: the world frame's path, bit for bit; a moved ground frame: the same motion
# ------------------------------------------------------------------------------------------------------------
ARRAYS = ("t", "q", "qdot", "q_ref", "tau", "head_pose", "P", "L", "com", "zmp", "base_positions", "root_pose")


def _lift(robot, lying, seconds=0.6):
    q1 = lying.copy()
    j = robot.lift_joints.start
    q1[j] += 0.4  # the neck's first joint turns: the body's load moves on the ground
    t = np.arange(0.0, seconds + 1e-9, 0.002)
    s = t / seconds
    return t, lying + (10 * s**3 - 15 * s**4 + 6 * s**5)[:, None] * (q1 - lying)


def test_flat_ground_through_a_ground_frame_is_the_world_path_bit_for_bit(mujoco, robot, lying):
    t, q = _lift(robot, lying)
    obstacles = [BoxObstacle(np.array([-0.6, -0.6, 0.1]), np.array([0.2, 0.2, 0.2]), np.eye(3))]
    runs = [sim.simulate_trajectory(robot, t, q, b, obstacles=obstacles, settle=0.1)
            for b in (BasePlacement(0.1, 0.05, 0.2),
                      BasePlacement(0.1, 0.05, 0.2, ground=GroundFrame.of_plane((0, 0, 1), (0, 0, 0))))]
    for name in ARRAYS:
        np.testing.assert_array_equal(getattr(runs[0], name), getattr(runs[1], name), err_msg=name)
    for a, b in zip(runs[0].contact_forces + runs[0].contact_points, runs[1].contact_forces + runs[1].contact_points):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(runs[0].end_state.qpos, runs[1].end_state.qpos)
    assert "noslip_iterations" not in runs[0].settings and runs[0].settings == runs[1].settings


def test_a_level_ground_frame_moved_and_turned_gives_the_flat_motion(mujoco, robot, lying):
    """A ground frame that is the plane z = 0.2 m turned 90 deg about z (level, but not the world's frame: it goes
    through every transform of the slope's path) gives the flat-ground simulation in the ground frame, up to the
    rounding of MuJoCo's arithmetic in other coordinates (no no-slip solver on either, to compare like with like)."""
    t, q = _lift(robot, lying)
    turned = GroundFrame((0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0), (0.3, -0.1, 0.2))
    assert not turned.is_world
    base = (0.1, 0.05, 0.2)
    flat = sim.simulate_trajectory(robot, t, q, BasePlacement(*base), settle=0.1)
    moved = sim.simulate_trajectory(robot, t, q, BasePlacement(*base, ground=turned), settle=0.1, noslip_iterations=0)
    for name in ("head_pose", "base_positions", "P", "L", "com", "zmp"):  # measured: within 3e-14
        np.testing.assert_allclose(getattr(moved, name), getattr(flat, name), atol=1e-9, err_msg=name)
    np.testing.assert_allclose(moved.tau, flat.tau, atol=1e-9)  # N m; measured 7e-13
    for a, b in zip(moved.contact_forces, flat.contact_forces):
        np.testing.assert_allclose(a, b, atol=1e-9)


# ------------------------------------------------------------------------------------------------------------
# a plan on a slope, simulated
# ------------------------------------------------------------------------------------------------------------
def test_a_plan_on_a_5_degree_slope_reaches_its_targets_in_mujoco(mujoco, robot):
    """Two targets reachable by construction on a 5 deg slope (the head poses of stable, collision-free
    configurations from the planner's initial one, in the ground frame): the simulated head within 2 mm and 1 deg
    of each (README's figure for flat ground). Measured (the planner's plan varies from run to run, 19.9 or 20.9
    s long): 0.9-1.2 and 0.16-0.21 mm, 0.03-0.06 and 0.03 deg; the base slid 0.24 mm; 4 s in all."""
    ground = slope(5.0)
    base = BasePlacement(ground=ground)
    controller = HeadController(robot, base_pose=base)
    targets = reachable_targets(controller, "same", 2, np.random.default_rng(0))
    plan = snakehead.plan([(tg.position, tg.direction) for tg in targets], controller=controller, base=base,
                          allow_relocation=False)
    assert plan.success, (plan.failure, plan.notes)
    assert plan.base.ground == ground
    checked = snakehead.simulate(plan)
    assert checked.result.settings["slope_deg"] == pytest.approx(5.0)
    assert checked.position_error_m < 2e-3 and checked.direction_error_deg < 1.0, checked.metrics
    assert checked.zmp_inside and checked.metrics["base_slide_m"] < 2e-3
    # the same errors from the world: the simulated head's world pose against the targets put into the world
    r = checked.result
    for planned, target in zip(plan.targets, targets):
        k = int(np.argmin(np.abs(r.t - planned.time_s)))
        H = ground.matrix @ r.head_pose[k]
        assert np.linalg.norm(H[:3, 3] - ground.to_world(target.position)) < 2e-3
        assert angle_between_deg(H[:3, 0], ground.direction_to_world(target.direction)) < 1.0
