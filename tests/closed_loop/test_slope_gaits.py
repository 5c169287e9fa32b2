"""Gaits and the estimate on a slope (issue 35 item 7): the GaitSimulator on a plane terrain's ground frame (the
MuJoCo floor tilted, every pose in the ground frame), the estimator turning the IMU's world orientation into that
frame with the known slope, the locomotion's planar poses keeping their ground; each checked against what does not
go through the code under test (the plane's normal from its angles, the planner's kinematics, the flat run)."""
import math

import numpy as np
import pytest

from snakehead import BasePlacement, SnakeRobot
from snakehead.closed_loop.estimate import BodyPoseEstimator, pose_error
from snakehead.locomotion import goals as lc
from snakehead.model.placement import WORLD_FRAME, GroundFrame
from snakehead.terrain.surfaces import plane_normal_deg


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def slope(pitch_deg, roll_deg=0.0):
    return GroundFrame.of_plane(plane_normal_deg(roll_deg, pitch_deg), (0.0, 0.0, 0.0))


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# ------------------------------------------------------------------------------------------------------------
# no simulator: the planar poses and the estimator
# ------------------------------------------------------------------------------------------------------------
def test_composed_poses_keep_their_ground():
    g = slope(5.0)
    a = BasePlacement(0.3, -0.2, 0.4, ground=g)
    b = lc.compose(a, BasePlacement(0.1, 0.05, 0.2))
    assert b.ground == g
    assert lc.relative(a, b).ground.is_world  # a motion, on no ground
    c = lc.compose(a, lc.relative(a, b))
    assert c.ground == g and np.allclose((c.x, c.y, c.yaw), (b.x, b.y, b.yaw))
    assert lc.straight_pose_for(SnakeRobot.default(), a, np.zeros(16)).ground == g


@pytest.mark.parametrize("pitch, roll, yaw", [(5.0, 0.0, 0.0), (10.0, 0.0, 1.2), (7.0, -4.0, -2.5)])
def test_the_estimate_of_a_body_on_a_slope_is_in_its_ground_frame(robot, pitch, roll, yaw):
    """The IMU reads its link's world orientation (leaning with the slope); the estimator, told the slope, puts
    the body where the planner's kinematics put it in the ground frame: upright on the plane (tilt 0), at the
    placement. The IMU's heading is off by a turn about the world's vertical (a gyro knows no heading): reset with
    the known yaw takes it out."""
    g = slope(pitch, roll)
    base = BasePlacement(0.4, -0.3, yaw, ground=g)
    q = np.where([k == "yaw" for k in robot.joint_kinds], 0.2, 0.0)
    frames = robot.frames(q, base)  # the ground frame
    est = BodyPoseEstimator(robot, ground=g)
    R_world = g.matrix[:3, :3] @ frames[est.imu_index, :3, :3]
    for heading_error in (0.0, 1.0, -2.8):
        pose = est.reset(q, rz(heading_error) @ R_world, (base.x, base.y), base.yaw)
        np.testing.assert_allclose(pose.root, frames[0], atol=1e-9)
        assert pose.tilt_deg == pytest.approx(0.0, abs=1e-6)
        assert pose.base.ground == g
        assert np.allclose((pose.base.x, pose.base.y, pose.base.yaw), (base.x, base.y, base.yaw), atol=1e-9)
        est.update(q, rz(heading_error) @ R_world)  # still: the estimate stays
        np.testing.assert_allclose(est.pose().root, frames[0], atol=1e-9)
    # without the slope the same reading leans by the slope's angle
    flat = BodyPoseEstimator(robot).reset(q, R_world, (base.x, base.y), base.yaw)
    assert flat.tilt_deg == pytest.approx(g.slope_deg, abs=0.5)


# ------------------------------------------------------------------------------------------------------------
# MuJoCo
# ------------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def on_five(mujoco, robot):
    from snakehead.closed_loop.gait_runner import GaitSimulator

    return GaitSimulator(robot, ground=slope(5.0))


def test_a_body_lying_on_a_slope_rests_on_the_plane_and_holds_still(mujoco, robot, on_five):
    g = on_five.ground
    base = BasePlacement(0.2, -0.1, 0.7, ground=g)
    state = on_five.lying(base)
    # the root's world position: body_axis_height above the tilted plane (its normal from the angles), within a mm
    root_world = on_five.data.xpos[on_five.sim.root_body]
    n = plane_normal_deg(0.0, 5.0)
    assert n @ root_world == pytest.approx(robot.body_axis_height, abs=0.001)
    truth = on_five.true_pose()
    assert truth.root[2, 3] == pytest.approx(robot.body_axis_height, abs=0.001)  # in the ground frame
    assert truth.tilt_deg < 0.2 and truth.base.ground == g
    assert pose_error(truth, BodyPose_of(robot, base))["position_error_m"] < 0.001
    # held still for 2 s on 5 deg (tan 5 deg = 0.087 < 0.8): neither the body nor its estimate moves
    held = on_five.run_path(state, np.zeros(robot.n_joints), 2.0, rest_s=0.0)
    assert np.linalg.norm(held.truth.root[:3, 3] - held.start_truth.root[:3, 3]) < 0.001
    assert held.estimate_error["position_error_m"] < 0.001 and held.estimate_error["yaw_error_deg"] < 0.1
    assert held.estimate.tilt_deg < 0.2 and held.estimate.base.ground == g
    assert held.height.max() < 2 * robot.body_axis_height + 0.002 and held.contact_fraction.min() == 1.0


def BodyPose_of(robot, base):
    from snakehead.closed_loop.estimate import BodyPose

    root = robot.root_pose(base)
    return BodyPose(root=root, chassis=root, body_in_root=robot.body_in_root, ground=base.ground)


def test_a_base_on_another_ground_is_refused(mujoco, robot, on_five):
    from snakehead import InputError

    with pytest.raises(InputError, match="ground"):
        on_five.lying(BasePlacement(0.0, 0.0, 0.0))  # flat ground's placement on the slope's simulator
    with pytest.raises(InputError, match="ground"):
        on_five.lying(BasePlacement(0.0, 0.0, 0.0, ground=slope(10.0)))
    with pytest.raises(TypeError, match="GroundFrame"):
        type(on_five)(robot, ground=(0.0, 0.0, 1.0))


def test_a_gait_on_five_degrees_moves_the_body_and_drifts_downhill(mujoco, robot, on_five):
    """One cycle of sidewinding across the slope goes nearly as far as on flat ground, a little downhill; one cycle
    of turning in place turns as on flat ground but slides the body downhill (+x of the slope's frame: a positive
    pitch lowers the ground along +x), a centimetre and more beyond its shift that way on flat ground. The estimate follows in
    the ground frame (its IMU told the slope)."""
    from snakehead.closed_loop.gait_runner import GaitSimulator
    from snakehead.locomotion.gaits import make_gait

    flat = GaitSimulator(robot)
    runs = {}
    for name, sim in (("flat", flat), ("slope", on_five)):
        state = sim.lying(BasePlacement(ground=sim.ground))
        runs[name] = {gait: sim.run(state, make_gait(gait, +1, frequency=0.5), 1, rest_s=0.3)
                      for gait in ("sidewinding", "turning")}
    assert runs["flat"]["sidewinding"].truth.base.ground == WORLD_FRAME
    side_flat, side = runs["flat"]["sidewinding"], runs["slope"]["sidewinding"]
    assert side.truth.base.ground == on_five.ground
    assert side.travel[1] > 0.8 * side_flat.travel[1] > 0.1  # to the body's left (+y), across the slope
    turn_flat, turn = runs["flat"]["turning"], runs["slope"]["turning"]
    assert turn.turn_deg == pytest.approx(turn_flat.turn_deg, abs=10.0)
    downhill = turn.truth.chassis[0, 3] - turn.start_truth.chassis[0, 3]
    downhill_flat = turn_flat.truth.chassis[0, 3] - turn_flat.start_truth.chassis[0, 3]
    assert downhill > downhill_flat + 0.01
    for run in (side, turn):
        assert run.estimate.base.ground == on_five.ground and run.estimate.tilt_deg < 1.0
        assert run.estimate_error["yaw_error_deg"] < 1.0 and run.estimate_error["position_error_m"] < 0.06


def test_a_slope_run_replays_from_its_sensor_stream(mujoco, robot):
    """With the onboard sensors on a slope the run's SensorLog (which keeps the slope) gives its estimate back
    without the simulator."""
    from snakehead.closed_loop.gait_runner import GaitSimulator, replay_estimate
    from snakehead.locomotion.gaits import make_gait
    from snakehead.sim.sensors import OnboardSensors

    sim = GaitSimulator(robot, ground=slope(10.0), sensors=OnboardSensors.realistic(seed=3))
    run = sim.run(sim.lying(BasePlacement(0.1, 0.0, 0.5, ground=sim.ground)), make_gait("turning", -1), 0.5,
                  rest_s=0.1)
    assert run.sensor_log is not None and run.sensor_log.ground == sim.ground
    pose, _ = replay_estimate(robot, run.sensor_log)
    np.testing.assert_array_equal(pose.root, run.estimate.root)
    assert pose.base.ground == sim.ground


# ------------------------------------------------------------------------------------------------------------
# the closed loop on 5 deg
# ------------------------------------------------------------------------------------------------------------
def test_the_loop_reaches_its_staging_pose_and_raises_the_head_on_five_degrees(mujoco, robot):
    """The paper's sphere 1 on a 5 deg slope (the target given where it lies on flat ground, in the slope's frame,
    then written in the world as a scene is), the body straight where its curl should bring the base to the goal:
    the curl (which the slope turns by some 12 deg more than the friction model predicts), the head camera's fix,
    the head phases in MuJoCo on the tilted floor and the final approach, on the robot's own senses (14 s measured;
    the target held 0.1 s, no dynamics check of the plan, as the CI-sized flat tests)."""
    import dataclasses

    from snakehead import HeadController
    from snakehead.closed_loop.loop import ClosedLoop
    from snakehead.scenes import Scene
    from snakehead.terrain.surfaces import PlaneTerrain

    g = slope(5.0)
    target = g.to_world([-0.0405, 0.5443, 0.3]), g.direction_to_world([0.0, 1.0, 0.0])
    scene = dataclasses.replace(Scene.from_targets([target], name="sphere", hold_s=0.1),
                                terrain=PlaneTerrain.from_roll_pitch(0.0, 5.0))
    loop = ClosedLoop(scene, controller=HeadController(robot, seed=1), dynamics_check=False)
    assert loop.ground == g and loop.simulator.ground == g
    start = loop.straight_start()
    assert start.ground == g
    run = loop.run(start)
    assert run.success, run.failure
    assert run.plan.base.ground == g and run.head.settings["slope_deg"] == pytest.approx(5.0)
    assert run.fixes and run.fixes[-1]["source"] == "head camera"
    assert run.fixes[-1]["fix"]["position_error_m"] < 0.002 and run.fixes[-1]["fix"]["yaw_error_deg"] < 0.5
    assert run.metrics["zmp_inside"] and run.metrics["base_lift_m"] < 0.005
    assert run.metrics["final_position_error_m"] < 0.002 and run.metrics["final_direction_error_deg"] < 1.0


def test_on_a_slope_the_loop_goes_by_the_curl_it_saw(mujoco, robot):
    """The friction model's curl knows no slope (on 10 deg the body's curl into the bending state turns some 20 deg
    less than predicted): once the body curled from straight on a slope, the loop plans the next curl from the
    motion it saw (estimated), not from the model; on flat ground it keeps the model."""
    import dataclasses

    from snakehead import HeadController
    from snakehead.closed_loop.episode import Episode
    from snakehead.closed_loop.loop import ClosedLoop
    from snakehead.scenes import Scene
    from snakehead.terrain.surfaces import PlaneTerrain

    controller = HeadController(robot, seed=1)
    flat_scene = Scene.from_targets([((-0.0405, 0.5443, 0.3), (0.0, 1.0, 0.0))], name="sphere", hold_s=0.1)
    steep = dataclasses.replace(flat_scene, terrain=PlaneTerrain.from_roll_pitch(0.0, 10.0))
    seen = {}
    for name, scene in (("flat", flat_scene), ("slope", steep)):
        loop = ClosedLoop(scene, controller=controller, dynamics_check=False)
        start = loop.straight_start()
        ep = Episode(loop, start, start, np.zeros(robot.n_joints), lambda text: None)
        before = ep.est.base
        ep.curl(ep.q_bend, "curl into the bending state")
        predicted = lc.curl_displacement(robot, np.zeros(robot.n_joints), ep.q_bend)
        model_or_seen = ep.curl_motion(np.zeros(robot.n_joints), ep.q_bend)
        seen[name] = lc.relative(before, ep.est.base)
        if name == "flat":
            assert ep.curl_seen is None and model_or_seen == predicted
        else:
            assert model_or_seen == seen[name] and ep.curl_seen is not None
            other = np.where(np.arange(robot.n_joints) == 0, 0.1, 0.0)  # a curl from another shape: the model
            assert ep.curl_motion(other, ep.q_bend) == lc.curl_displacement(robot, other, ep.q_bend)
    turned = {k: math.degrees(lc.wrap_angle(v.yaw)) for k, v in seen.items()}
    assert abs(turned["flat"] - turned["slope"]) > 10.0  # the slope changes the curl's turn by more than 10 deg
