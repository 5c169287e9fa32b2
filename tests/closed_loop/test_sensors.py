"""The onboard sensing models (snakehead.sim.sensors) against closed forms and statistics, the attitude filter
against the true orientation, and the estimate of a ground run replayed from its sensor stream alone."""
import math

import numpy as np
import pytest

from snakehead.closed_loop.estimate import AttitudeFilter
from snakehead.geometry.obstacles import BoxObstacle, WallWithHole
from snakehead.sim import sensors as sn


def _chi2_bounds(n):
    """A 6-sigma band on the ratio of a sample variance to the true one over n samples (var of s^2/sigma^2 is
    2/(n-1))."""
    half = 6.0 * math.sqrt(2.0 / (n - 1))
    return 1.0 - half, 1.0 + half


def test_encoder_quantisation():
    enc = sn.Encoders()
    step = 2 * math.pi / 4096
    assert enc.resolution_rad == pytest.approx(step)
    q = np.random.default_rng(0).uniform(-1.5, 1.5, 10000)
    r = enc.read(q)
    # every reading is a whole count, within half a count of the truth, and the error is uniform: std step/sqrt(12)
    np.testing.assert_allclose(r / step, np.round(r / step), atol=1e-9)
    assert np.abs(r - q).max() <= 0.5 * step + 1e-15
    lo, hi = _chi2_bounds(len(q))
    assert lo < np.var(r - q) / (step ** 2 / 12) < hi
    with pytest.raises(ValueError, match="counts_per_rev"):
        sn.Encoders(1)


def test_gyro_white_noise_and_bias_walk_statistics():
    """At rest: gyro readings are bias + white noise of std N/sqrt(dt); the bias walks with variance K^2 t."""
    dt, n_steps, n_imus = 0.002, 100, 300
    N, K = sn.GYRO_NOISE_DENSITY, sn.GYRO_BIAS_RANDOM_WALK
    biases, noise = [], []
    for seed in range(n_imus):
        imu = sn.Imu(seed=seed)
        imu.start(np.eye(3))
        readings = np.array([imu.read(np.eye(3), dt)[0] for _ in range(n_steps)])
        biases.append(imu.bias.copy())
        noise.append(readings[-1] - imu.bias)  # one reading's white noise (the bias is known here)
    biases, noise = np.array(biases), np.array(noise)
    lo, hi = _chi2_bounds(biases.size)
    assert lo < np.var(biases) / (K ** 2 * n_steps * dt) < hi  # random walk: variance K^2 t
    assert lo < np.var(noise) / (N ** 2 / dt) < hi
    assert abs(noise.mean()) < 6 * N / math.sqrt(dt) / math.sqrt(noise.size)


def test_accelerometer_reads_gravity_in_its_axes_with_noise():
    rng = np.random.default_rng(1)
    R = sn.so3_exp(rng.normal(0, 0.5, 3))
    imu = sn.Imu(seed=3)
    imu.start(R)
    acc = np.array([imu.read(R, 0.002)[1] for _ in range(4000)])
    np.testing.assert_allclose(acc.mean(0), R.T @ [0, 0, sn.GRAVITY], atol=6 * sn.ACCEL_NOISE_DENSITY / math.sqrt(0.002) / math.sqrt(4000))
    lo, hi = _chi2_bounds(acc.size)
    assert lo < np.var(acc - R.T @ [0, 0, sn.GRAVITY]) / (sn.ACCEL_NOISE_DENSITY ** 2 / 0.002) < hi


def test_noise_free_gyro_integrates_to_the_true_orientation():
    """A noise-free IMU on a tumbling link: the gyro integrated (no accelerometer pull) gives the orientation back
    to machine precision; with the tilt pull, a wrong start tilt converges to the truth."""
    rng = np.random.default_rng(2)
    Rs = [np.eye(3)]
    for _ in range(500):
        Rs.append(Rs[-1] @ sn.so3_exp(rng.normal(0, 0.01, 3)))
    imu = sn.Imu(gyro_noise_density=0, gyro_bias_random_walk=0, accel_noise_density=0)
    imu.start(Rs[0])
    R = Rs[0].copy()
    for Rt in Rs[1:]:
        gyro, _ = imu.read(Rt, 0.002)
        R = R @ sn.so3_exp(gyro * 0.002)
    np.testing.assert_allclose(R, Rs[-1], atol=1e-10)
    # the filter, started 5 deg off in tilt at rest, levels itself with its time constant (e^-5 after 5 tau)
    f = AttitudeFilter(0.5)
    f.R = sn.so3_exp([math.radians(5.0), 0.0, 0.0])
    imu.start(np.eye(3))
    for _ in range(int(2.5 / 0.002)):
        f.update(*imu.read(np.eye(3), 0.002), 0.002)
    tilt = math.degrees(math.acos(min(1.0, f.R[2, 2])))
    assert tilt == pytest.approx(5.0 * math.exp(-5.0), rel=0.05)
    # reset: level from gravity seen in the IMU's axes, heading as told
    R_true = sn.so3_exp([0.1, -0.2, 0.7])
    level = f.reset(R_true.T @ [0, 0, 9.81])
    np.testing.assert_allclose(level[2], R_true[2], atol=1e-12)  # the same world z in the IMU's axes
    turned = f.reset(R_true.T @ [0, 0, 9.81], yaw=0.3)
    np.testing.assert_allclose(turned, sn.so3_exp([0, 0, 0.3]) @ level, atol=1e-12)


def _head_at(p, x_axis):
    x = np.asarray(x_axis, float) / np.linalg.norm(x_axis)
    z = np.array([0.0, 0.0, 1.0]) - x[2] * x
    z /= np.linalg.norm(z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, p
    return T


def _slab_hit(a, b, lo, hi):
    """Whether segment a-b meets the axis-aligned box [lo, hi] (the slab method)."""
    t0, t1 = 0.0, 1.0
    d = b - a
    for i in range(3):
        if abs(d[i]) < 1e-15:
            if not lo[i] <= a[i] <= hi[i]:
                return False
            continue
        u, v = sorted(((lo[i] - a[i]) / d[i], (hi[i] - a[i]) / d[i]))
        t0, t1 = max(t0, u), min(t1, v)
    return t0 <= t1


def test_occlusion_against_the_slab_method():
    box = BoxObstacle(np.array([0.5, 0.0, 0.2]), np.array([0.1, 0.4, 0.4]))
    lo, hi = box.centre - box.size / 2, box.centre + box.size / 2
    rng = np.random.default_rng(4)
    agree = 0
    for _ in range(300):
        a, b = rng.uniform([-0.2, -0.5, 0.0], [1.2, 0.5, 0.5], (2, 3))
        hit = _slab_hit(a, b, lo, hi)
        # skip grazing rays (within the sight line's radius of an edge): either answer is right there
        margin = sn.SIGHT_RADIUS_M * 3
        if _slab_hit(a, b, lo - margin, hi + margin) != _slab_hit(a, b, lo + margin, hi - margin):
            continue
        assert sn.occluded(a, b, [box]) == hit
        agree += 1
    assert agree > 250
    # a wall with a hole: seen through the hole, hidden beside it
    wall = WallWithHole.standing([0.2, 0.5, 0.4], [0, 1, 0], [0.7, 0.58, 0.01], 0.07)
    assert not sn.occluded([0.2, 0.3, 0.4], [0.2, 0.538, 0.4], [wall])
    assert sn.occluded([0.2, 0.3, 0.4], [0.3, 0.538, 0.4], [wall])


def test_head_sensor_field_of_view_range_and_noise():
    target = (np.array([1.0, 0.0, 0.3]), np.array([1.0, 0.0, 0.0]))
    cam = sn.HeadSensor([target], seed=5)
    marker = cam.markers[0]
    np.testing.assert_allclose(marker[:3, 3], [1.0 + sn.MARKER_AHEAD_M, 0.0, 0.3])
    np.testing.assert_allclose(marker[:3, :3], np.eye(3), atol=1e-15)
    head = _head_at([0.5, 0.0, 0.3], [1, 0, 0])
    assert cam.visible(head) == [0]
    half = math.radians(sn.HEAD_HALF_FOV_DEG)
    for off, seen in ((half - 0.01, True), (half + 0.01, False)):
        turned = _head_at([0.5, 0.0, 0.3], [math.cos(off), math.sin(off), 0.0])
        assert cam.in_view(turned, 0) is seen
    assert not cam.in_view(_head_at([-0.5, 0.0, 0.3], [1, 0, 0]), 0)  # 1.65 m: beyond the range
    assert cam.read(_head_at([0.5, 0.0, 0.3], [-1, 0, 0]), 0) is None  # behind the camera
    # hidden by a box in between
    box = BoxObstacle(np.array([0.75, 0.0, 0.3]), np.array([0.05, 0.2, 0.2]))
    assert sn.HeadSensor([target], [box]).visible(head) == []
    # noise: position std per axis about the true relative pose; the target recovered from the marker
    truth = np.linalg.solve(head, marker)
    readings = [cam.read(head, 0) for _ in range(3000)]
    P = np.array([r.pose[:3, 3] for r in readings])
    np.testing.assert_allclose(P.mean(0), truth[:3, 3], atol=6 * sn.HEAD_POSITION_NOISE_M / math.sqrt(3000))
    lo, hi = _chi2_bounds(P.size)
    assert lo < np.var(P - truth[:3, 3]) / sn.HEAD_POSITION_NOISE_M ** 2 < hi
    # rotation noise: a rotation vector of sigma per axis, so the angle is Maxwell-distributed: mean 2 sigma sqrt(2/pi)
    angles = np.array([np.linalg.norm(sn.so3_log(truth[:3, :3].T @ r.pose[:3, :3])) for r in readings])
    sigma = math.radians(sn.HEAD_DIRECTION_NOISE_DEG)
    assert angles.mean() == pytest.approx(2 * sigma * math.sqrt(2 / math.pi), rel=0.05)
    mean = sn.mean_pose([r.target_in_head for r in readings])
    np.testing.assert_allclose(mean[:3, 3], [0.5, 0.0, 0.0], atol=1e-4)
    assert np.linalg.norm(sn.so3_log(mean[:3, :3])) < 1e-3
    # reproducible
    a = sn.HeadSensor([target], seed=9).read(head, 0)
    b = sn.HeadSensor([target], seed=9).read(head, 0)
    assert np.array_equal(a.pose, b.pose)


def test_ground_run_estimate_replays_from_its_sensor_stream_alone():
    """The estimate of a gait run in MuJoCo with the onboard sensors is a function of the recorded sensor stream
    alone: replayed into a fresh estimator (no simulator), the same estimate bit for bit, and the same next gait
    the locomotion would command from it."""
    pytest.importorskip("mujoco")
    from snakehead import BasePlacement, SnakeRobot
    from snakehead.closed_loop.gait_runner import GaitSimulator, replay_estimate
    from snakehead.locomotion import goals as lc
    from snakehead.locomotion.gaits import make_gait

    robot = SnakeRobot.default()
    sim = GaitSimulator(robot, sensors=sn.OnboardSensors.realistic(seed=3))
    state = sim.lying(BasePlacement(0.2, -0.1, 0.4))
    run = sim.run(state, make_gait("turning", 1), 1, rest_s=0.1)
    log = run.sensor_log
    assert log is not None and len(log.q) == len(log.gyro) == len(log.accel) > 100
    # the encoders' readings are whole counts
    step = 2 * math.pi / sn.ENCODER_COUNTS_PER_REV
    np.testing.assert_allclose(log.q / step, np.round(log.q / step), atol=1e-9)
    estimate, R = replay_estimate(robot, log)
    assert np.array_equal(estimate.root, run.estimate.root)
    np.testing.assert_array_equal(R, sim.attitude.R)
    goal = BasePlacement(1.0, 0.5, 1.0)
    rates = lc.GaitRates.first_guess(robot)
    a, b = lc.next_step(robot, run.estimate.base, goal, rates), lc.next_step(robot, estimate.base, goal, rates)
    assert a == b
    # and the estimate is not the truth (the sensors are noisy) but near it
    err = run.estimate_error
    assert 0 < err["yaw_error_deg"] < 1.0 and err["position_error_m"] < 0.05


def test_servo_step_is_a_newton_step_on_the_head_chain():
    """The final approach's correction against forward kinematics: a target reached by moving the head chain a
    little is reached by the correction to second order (the error after one step is the square of the first,
    scaled), the base's joints never move, and the fix from a marker reading gives back the root pose exactly."""
    from snakehead import SnakeRobot
    from snakehead.closed_loop import servo as sv

    robot = SnakeRobot.default()
    k = robot.link_index(robot.parts.head_tip)
    joints = sv.servo_joints(robot)
    assert joints.min() >= robot.lift_joints.start and joints.max() < robot.parts.head.stop
    rng = np.random.default_rng(7)
    q = np.where([kind == "pitch" for kind in robot.joint_kinds], 0.3, 0.1)
    for scale in (0.01, 0.003):
        d = np.zeros_like(q)
        d[joints] = rng.normal(0, scale, len(joints))
        target = robot.body.fk_all(q + d)[k]
        before = sv.head_error(np.linalg.solve(robot.body.fk_all(q)[k], target))
        dq = sv.servo_step(robot, q, np.linalg.solve(robot.body.fk_all(q)[k], target))
        assert np.all(dq[np.setdiff1d(np.arange(robot.n_joints), joints)] == 0.0)
        after = sv.head_error(np.linalg.solve(robot.body.fk_all(q + dq)[k], target))
        assert after[0] < 0.05 * before[0] and after[1] < 0.05 * before[1] + 1e-6
    # the fix: a noise-free reading of a marker at a known pose, and the joints, give the root pose back
    root = np.eye(4)
    root[:3, :3] = sn.so3_exp([0.01, -0.02, 1.2])
    root[:3, 3] = [0.3, -0.4, 0.02]
    head = root @ robot.body.fk_all(q)[k]
    marker = head @ sn.target_frame([0.3, 0.05, 0.02], [1.0, 0.1, 0.0])
    reading = sn.HeadReading(0, np.linalg.solve(head, marker))
    np.testing.assert_allclose(sv.root_from_head_reading(robot, [reading, reading], marker, q), root, atol=1e-12)
