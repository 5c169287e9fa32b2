"""Gaits (snakehead.locomotion.gaits) and where the body is (snakehead.closed_loop.estimate): the joint-angle generators
against their formula, each gait in MuJoCo going where it is commanded on two robots, the pose estimate against
closed forms and MuJoCo's ground truth, and bad input."""
import math

import numpy as np
import pytest
from conftest import pitch_first

from snakehead import BasePlacement, InputError, SnakeRobot
from snakehead.backbone import initial_configuration
from snakehead.locomotion.gaits import GAITS, Gait, Wave, make_gait, virtual_chassis
from snakehead.model.generate import SnakeSpec, snake_urdf


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


# ------------------------------------------------------------------------------------------------
# the generators (pure kinematics)
# ------------------------------------------------------------------------------------------------
def test_joint_angles_follow_the_serpenoid_formula():
    robot = pitch_first()
    gait = make_gait("sidewinding", -1, yaw_amplitude=0.5, pitch_amplitude=0.2, waves=1.2, frequency=0.8, ramp_s=0.5)
    cycles = 2.0
    t = np.array([0.0, 0.25, 0.5, 0.9, 1.7, 2.5, 2.75, 3.0, 3.25, 3.5])
    q = gait.joint_angles(robot, t, cycles)
    # the formula written out joint by joint: q_j = sign_j e(t) A sin(2 pi (f (t - ramp) - w s_j / L) + phase)
    for i, ti in enumerate(t):
        running = min(max(ti - 0.5, 0.0), cycles / 0.8)
        rise, fall = min(ti / 0.5, 1.0), min(max((gait.duration(cycles) - ti) / 0.5, 0.0), 1.0)
        e = 0.5 - 0.5 * math.cos(math.pi * min(rise, fall))
        for j in range(robot.n_joints):
            s = robot.joint_arc_lengths[j] / robot.body_length
            yaw = robot.joint_kinds[j] == "yaw"
            amp, phase = (0.5, 0.0) if yaw else (0.2, +math.pi / 2)  # direction -1: the pitch wave a quarter ahead
            expected = robot.joint_signs[j] * e * amp * math.sin(2 * math.pi * (0.8 * running - 1.2 * s) + phase)
            assert q[i, j] == pytest.approx(expected, abs=1e-12)
    # straight at both ends, the full amplitude in between
    assert np.all(q[0] == 0.0) and np.abs(q[-1]).max() < 1e-12
    assert gait.duration(cycles) == pytest.approx(cycles / 0.8 + 1.0)
    t_run, q_run = gait.trajectory(robot, cycles)
    assert t_run[-1] == pytest.approx(gait.duration(cycles)) and np.allclose(np.diff(t_run), 0.002)


def test_the_gaits_shapes(robot):
    """Rolling: every joint of a kind alike (an arc), lying on the ground (yaw only) where it starts and ends;
    turning: the pitch amplitude runs from -A at the tail through 0 to +A at the head."""
    roll = make_gait("rolling", 1)
    t = roll.ramp_s + np.linspace(0.0, roll.period_s, 9)
    q = roll.joint_angles(robot, t, 1.0) * robot.joint_signs
    yaw = np.array([k == "yaw" for k in robot.joint_kinds])
    assert np.allclose(q[:, yaw], q[:, yaw][:, :1]) and np.allclose(q[:, ~yaw], q[:, ~yaw][:, :1])
    assert np.allclose(q[0, ~yaw], 0.0) and np.allclose(np.abs(q[0, yaw]), 0.3)
    assert np.allclose(q[-1], q[0])  # one whole cycle later, the same shape
    turn = make_gait("turning", 1)
    s = robot.joint_arc_lengths / robot.body_length
    np.testing.assert_allclose(turn.pitch.amplitudes(s), 0.2 * (2 * s - 1))
    undulation = make_gait("lateral_undulation", 1)
    assert undulation.pitch.amplitude == 0.0 and undulation.yaw.waves < 0  # the wave runs towards the tail


def test_virtual_chassis_of_simple_shapes():
    # a straight row of points: x along it (towards ``forward``), at its centroid
    pts = np.column_stack([np.linspace(0, 1, 11), np.full(11, 2.0), np.full(11, 0.1)])
    T = virtual_chassis(pts, forward=(-1, 0, 0))
    np.testing.assert_allclose(T[:3, 3], (0.5, 2.0, 0.1), atol=1e-12)
    np.testing.assert_allclose(T[:3, 0], (-1, 0, 0), atol=1e-12)
    # a planar arc lying on the ground: x along its chord, z up, a right-handed frame
    a = np.linspace(-1.0, 1.0, 21)
    arc = np.column_stack([np.sin(a), 1 - np.cos(a), np.zeros_like(a)])
    T = virtual_chassis(arc, forward=(1, 0, 0))
    np.testing.assert_allclose(T[:3, 0], (1, 0, 0), atol=1e-9)
    np.testing.assert_allclose(T[:3, 2], (0, 0, 1), atol=1e-9)
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)
    # the x-axis keeps its sense from the previous frame
    assert virtual_chassis(arc[::-1], previous=T)[:3, 0] @ T[:3, 0] > 0


@pytest.mark.parametrize("call, error, match", [
    (lambda: make_gait("slithering"), ValueError, "unknown gait 'slithering'"),
    (lambda: make_gait(3), ValueError, "unknown gait"),
    (lambda: make_gait("rolling", amplitude=-0.1), ValueError, "amplitude must be >= 0"),
    (lambda: make_gait("sidewinding", pitch_amplitude=float("nan")), ValueError, "amplitude"),
    (lambda: make_gait("sidewinding", waves=float("inf")), ValueError, "waves"),
    (lambda: make_gait("turning", frequency=0.0), ValueError, "frequency must be a positive"),
    (lambda: make_gait("turning", frequency=-1.0), ValueError, "frequency"),
    (lambda: make_gait("rolling", ramp_s=-1.0), ValueError, "ramp_s"),
    (lambda: make_gait("rolling", direction=0), ValueError, "direction must be"),
    (lambda: make_gait("rolling", direction=True), ValueError, "direction must be"),
    (lambda: make_gait("rolling", speed=2), TypeError, "rolling"),
    (lambda: Wave(0.3, taper=1.5), ValueError, "taper"),
    (lambda: Wave("big"), TypeError, "amplitude must be a real number, got str"),
])
def test_bad_gait_parameters(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_a_gait_the_robot_cannot_run(robot):
    with pytest.raises(ValueError, match="beyond its limit"):
        make_gait("rolling", amplitude=2.0).check(robot)
    short = SnakeRobot.from_urdf(snake_urdf(SnakeSpec(n_joints=8, markers={"p0": 3, "b0": 4})), base_end="p0",
                                 neck_end="b0", head_tip="head_tip")
    with pytest.raises(ValueError, match="joints per wave"):  # 4 yaw joints cannot carry 1.5 waves
        make_gait("sidewinding").check(short)
    gait = make_gait("sidewinding")
    with pytest.raises(ValueError, match="cycles"):
        gait.joint_angles(robot, [0.0, 1.0], cycles=float("nan"))
    with pytest.raises(ValueError, match="cycles"):
        gait.trajectory(robot, cycles=0)
    with pytest.raises(ValueError, match="NaN"):
        gait.joint_angles(robot, [0.0, float("nan")], cycles=1.0)
    with pytest.raises(TypeError, match="SnakeRobot"):
        gait.joint_angles("snake16", [0.0], cycles=1.0)
    assert set(GAITS) >= {"rolling", "sidewinding", "turning"}
    assert isinstance(gait, Gait)


# ------------------------------------------------------------------------------------------------
# the estimate against closed forms (no simulator)
# ------------------------------------------------------------------------------------------------
def _rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def test_estimate_of_a_body_rolling_over_its_edge(robot):
    """The straight body rolled 90 deg about its axis, pivoting on its bottom edge: its axis moves sideways by the
    section's width (0.043 m) and stays at half of it above the ground."""
    from snakehead.closed_loop.estimate import BodyPoseEstimator

    est = BodyPoseEstimator(robot, imu_link="link_8")
    q = np.zeros(robot.n_joints)
    start = est.reset(q, np.eye(3), (0.2, 0.1), body_yaw=0.0)
    np.testing.assert_allclose(start.root[:3, 3], (0.2, 0.1, 0.0215), atol=1e-12)
    for a in np.radians(np.linspace(0.5, 90.0, 180)):
        est.update(q, _rot_x(a))  # + about x: the top goes towards -y, the body rolls over its -y edge
    end = est.pose()
    np.testing.assert_allclose(end.root[:3, 3], (0.2, 0.1 - 0.043, 0.0215), atol=2e-4)
    np.testing.assert_allclose(end.root[:3, :3], _rot_x(math.pi / 2), atol=1e-12)
    assert end.tilt_deg == pytest.approx(90.0)


def test_estimate_stays_put_while_only_lifted_joints_move(robot):
    """The base lies still and only the raised head sways: the contacts do not move, nor does the estimate."""
    from snakehead.closed_loop.estimate import BodyPoseEstimator

    base = BasePlacement(0.5, -0.3, 1.0)
    q1 = initial_configuration(robot, base=base)
    imu = robot.link_names[robot.base_links[3]]
    est = BodyPoseEstimator(robot, imu_link=imu)
    world = lambda q: robot.frames(q, base)[robot.link_index(imu), :3, :3]  # noqa: E731 - a perfect IMU
    start = est.reset(q1, world(q1), (base.x, base.y), body_yaw=base.yaw)
    np.testing.assert_allclose(start.root, robot.root_pose(base), atol=1e-12)
    head = np.arange(robot.n_joints) >= robot.parts.head.start
    for s in np.linspace(0.0, 1.0, 50):
        q = q1 + 0.2 * math.sin(math.pi * s) * head
        est.update(q, world(q))
    np.testing.assert_allclose(est.pose().root, robot.root_pose(base), atol=1e-12)
    got = est.pose().base  # to round-off: the root's yaw comes back through its rotation matrix
    np.testing.assert_allclose([got.x, got.y, got.yaw], [base.x, base.y, base.yaw], rtol=0, atol=1e-12)


def test_bad_estimator_input(robot):
    from snakehead.closed_loop.estimate import BodyPoseEstimator

    with pytest.raises(ValueError, match="nowhere"):
        BodyPoseEstimator(robot, imu_link="nowhere")
    with pytest.raises(ValueError, match="contact_height"):
        BodyPoseEstimator(robot, contact_height=-1.0)
    est = BodyPoseEstimator(robot)
    with pytest.raises(InputError, match="reset"):
        est.update(np.zeros(robot.n_joints), np.eye(3))
    with pytest.raises(ValueError, match="not a rotation"):
        est.reset(np.zeros(robot.n_joints), 2 * np.eye(3), (0, 0))
    with pytest.raises(ValueError, match="NaN"):
        est.reset(np.zeros(robot.n_joints), np.eye(3), (0, float("nan")))
    with pytest.raises(ValueError, match="shape"):
        est.reset(np.zeros(3), np.eye(3), (0, 0))


# ------------------------------------------------------------------------------------------------
# in MuJoCo
# ------------------------------------------------------------------------------------------------

#: Short runs for the suite: one cycle at 1 Hz with half-second ramps (bench/gaits.py runs longer ones).
QUICK = dict(frequency=1.0, ramp_s=0.5)
START = BasePlacement(0.3, -0.2, 0.7)


@pytest.fixture(scope="module")
def simulators(mujoco, robot):
    from snakehead.closed_loop import GaitSimulator

    return {"default": GaitSimulator(robot), "pitch_first": GaitSimulator(pitch_first())}


CASES = [("default", g, d) for g in ("rolling", "sidewinding", "turning", "linear_progression") for d in (1, -1)] + \
        [("pitch_first", g, 1) for g in ("rolling", "sidewinding", "turning")]


@pytest.mark.parametrize("which, name, direction", CASES)
def test_each_gait_goes_where_it_is_commanded(simulators, which, name, direction):
    """Translating gaits: the body's centre moves to the commanded side, within 20 deg of square to the body
    (measured 79-91 deg), by at least 0.05 body lengths per cycle. Linear progression: along the body's axis the
    commanded way (within 5 deg), by at least 0.05 body lengths per cycle, without turning. Turning: the body turns the commanded way by
    at least 15 deg per cycle (measured 22-39) and its centre moves less than 0.05 body lengths. None of them
    tumbles: the tail ends upright, some boxes always touch the ground, and no box rises higher than the gait's
    shape reaches plus 25 mm (the body rests on its lowest points, not on its best-fit plane)."""
    sim = simulators[which]
    gait = make_gait(name, direction, **QUICK)
    run = sim.run(sim.lying(START), gait, 1.0, rest_s=0.3)
    L = sim.robot.body_length
    moved = np.linalg.norm(run.travel) / L
    if gait.motion == "translate":
        assert abs(run.travel_direction_deg - 90.0 * direction) < 20.0, run.travel_direction_deg
        assert moved > 0.05
        assert abs(run.turn_deg) < 10.0
    elif gait.motion == "forward":
        assert abs(math.remainder(run.travel_direction_deg - (0.0 if direction > 0 else 180.0), 360.0)) < 5.0
        assert moved > 0.05, moved
        assert abs(run.turn_deg) < 2.0
    else:
        assert direction * run.turn_deg > 15.0, run.turn_deg
        assert moved < 0.05
    assert run.truth.tilt_deg < 5.0
    # linear progression's one wave per body rests on its troughs: two of the 17 links at the least (measured)
    assert run.contact_fraction.min() >= (0.1 if gait.motion == "forward" else 0.15)
    if gait.motion == "forward":  # its shape is a vertical wave: the height is that of its hull in the body's frame
        t = gait.ramp_s + np.linspace(0.0, gait.period_s, 40, endpoint=False)
        z = sim.robot.hull_points(sim.robot.frames_many(gait.joint_angles(sim.robot, t, 1.0)))[..., 2]
        reach = float(max(np.ptp(zt) for zt in z))
    else:
        reach = gait.shape_height(sim.robot)
    assert run.height.max() <= reach + 0.025
    # the joints followed the gait
    assert np.abs(run.q - run.q_ref).max() < math.radians(10.0)
    # the estimate: the orientation is the IMU's (exact here), the position off by what the contacts slipped
    err = run.estimate_error
    assert err["yaw_error_deg"] < 1e-6
    assert err["position_error_m"] < 0.1


def test_runs_chain_from_state_to_state(simulators):
    """A loop's step: run from the state and the estimate another run left; the time goes on, the estimate carries
    over (it is not reset to the truth), and a copy of a state replays the same run."""
    sim = simulators["pitch_first"]
    first = sim.run(sim.lying(START), make_gait("sidewinding", 1, **QUICK), 1.0, rest_s=0.2)
    again = sim.run(first.state.copy(), make_gait("turning", 1, **QUICK), 1.0, rest_s=0.2,
                    start_estimate=first.estimate)
    assert again.t[0] > first.t[-1] - 1e-9 and again.state.time > first.state.time
    np.testing.assert_allclose(again.start_truth.root, first.truth.root, atol=1e-9)
    assert again.estimate_error["position_error_m"] >= 0.0
    replay = sim.run(first.state.copy(), make_gait("turning", 1, **QUICK), 1.0, rest_s=0.2,
                     start_estimate=first.estimate)
    np.testing.assert_allclose(replay.truth.root, again.truth.root, atol=1e-9)
    np.testing.assert_allclose(replay.estimate.root, again.estimate.root, atol=1e-9)
    base = again.estimate.base
    assert isinstance(base, BasePlacement) and np.isfinite([base.x, base.y, base.yaw]).all()


def test_imu_heading_drift_shows_in_the_estimate(mujoco, robot):
    from snakehead.closed_loop import GaitSimulator

    sim = GaitSimulator(robot, imu_yaw_drift_deg_per_s=2.0)
    run = sim.run(sim.lying(START), make_gait("turning", 1, **QUICK), 1.0, rest_s=0.0)
    duration = make_gait("turning", 1, **QUICK).duration(1.0)
    assert run.estimate_error["yaw_error_deg"] == pytest.approx(2.0 * duration, abs=0.01)


def test_bad_run_input(simulators):
    sim = simulators["default"]
    state = sim.lying(START, settle_s=0.0)
    gait = make_gait("rolling", **QUICK)
    with pytest.raises(ValueError, match="cycles"):
        sim.run(state, gait, -1.0)
    with pytest.raises(ValueError, match="cycles"):
        sim.run(state, gait, float("nan"))
    with pytest.raises(TypeError, match="Gait"):
        sim.run(state, "rolling", 1.0)
    with pytest.raises(TypeError, match="SimState"):
        sim.run("lying", gait, 1.0)
    with pytest.raises(ValueError, match="another robot"):
        sim.run(simulators["pitch_first"].lying(START, settle_s=0.0), gait, 1.0)
    with pytest.raises(ValueError, match="record_every"):
        sim.run(state, gait, 1.0, record_every=0)
    with pytest.raises(ValueError, match="NaN"):
        sim.lying(START, q=np.full(sim.robot.n_joints, np.nan))
    with pytest.raises(ValueError, match="NaN"):
        BasePlacement(float("nan"), 0.0, 0.0)
