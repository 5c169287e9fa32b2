"""Gaits in MuJoCo: run a gait (:mod:`snakehead.locomotion.gaits`) on the friction ground from a simulated state, and
say where the body went, as the robot estimates it (:mod:`snakehead.closed_loop.estimate`) and as it truly is.

The building block of a closed loop: a :class:`GaitSimulator` holds one robot's MuJoCo model;
``run(state, gait, cycles)`` continues the simulation from ``state`` for the whole run (ramp up, ``cycles`` cycles,
ramp down, then ``rest_s`` holding the last configuration), and returns a :class:`GaitRun` whose ``state`` is where
the next phase starts and whose ``estimate`` is the body's pose as the robot knows it (its ``base`` the
:class:`~snakehead.model.robot.BasePlacement` a planner needs); ``truth`` is MuJoCo's, for measuring only.

    simulator = GaitSimulator(robot)
    state = simulator.lying(BasePlacement(0.0, 0.0, 0.0))
    run = simulator.run(state, make_gait("sidewinding", direction=+1), cycles=2)
    run.estimate.base, run.estimate_error, run.state

On a slope (``ground=``, a :class:`~snakehead.model.placement.GroundFrame`: a plane terrain's, as a plan on it has
in ``plan.base.ground``) the ground is that plane tilted in the world (:func:`snakehead.sim.build_spec`'s ``ground``,
gravity still the world's), the placements are in its frame (``lying(base)`` with ``base.ground`` the simulator's),
and so is every pose a run reports, true or estimated (MuJoCo's turned at one boundary, :meth:`GaitSimulator.true_pose`;
the estimate through the known slope, :class:`~snakehead.closed_loop.estimate.BodyPoseEstimator`); the IMU still reads
world gravity, as a real one does. Flat ground (the default) is the world frame, the runs what they always were.

``run_path(state, q_path, duration_s)`` runs any joint path on the ground the same way (a curl of the body from one
flat shape to another, which slides it: :mod:`snakehead.dynamics.sliding`).

Control: the same PD servos as :func:`snakehead.sim.simulate_trajectory` (gains derived per joint,
:mod:`snakehead.sim.gains`), without gravity compensation (the body lies on the ground); the reference is the gait's
joint trajectory at the 2 ms control period.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import finite_array, finite_float, joint_vector
from ..locomotion.gaits import Gait, virtual_chassis
from ..model.placement import WORLD_FRAME, GroundFrame
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from ..sim.gains import default_gains, gain_vector
from ..sim.mjcf import DEFAULT_CONTROL_DT, DEFAULT_TIMESTEP, build_model, import_mujoco, in_ground
from ..sim.sensors import OnboardSensors
from ..sim.tracking import SimState
from .estimate import AttitudeFilter, BodyPose, BodyPoseEstimator, ShapePoints, pose_error

__all__ = ["SensorLog", "replay_estimate", "GaitRun", "GaitSimulator"]


@dataclass
class SensorLog:
    """What the estimator of a ground run read (``sensing="onboard"``): where it started (``q0`` the encoders,
    ``R0`` the attitude filter's orientation, ``start_xy`` / ``start_yaw`` the pose it was told), then every control
    tick's encoders ``q`` (K, n) rad, gyro (K, 3) rad/s and accelerometer (K, 3) m/s^2, ``dt`` s apart;
    ``imu_link``, ``odometry`` and ``ground`` (the slope's frame, the world's on flat ground) as the estimator's.
    :func:`replay_estimate` gives the estimate back from it alone."""

    q0: np.ndarray
    R0: np.ndarray
    start_xy: np.ndarray
    start_yaw: float
    q: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    dt: float
    imu_link: str
    odometry: str
    tilt_time_constant_s: float
    ground: GroundFrame = WORLD_FRAME


def replay_estimate(robot: SnakeRobot, log: SensorLog) -> tuple[BodyPose, np.ndarray]:
    """The estimate at the end of a ground run from its :class:`SensorLog` alone (no simulator): the pose and the
    attitude filter's orientation (3, 3)."""
    estimator = BodyPoseEstimator(robot, log.imu_link, odometry=log.odometry, ground=log.ground)
    attitude = AttitudeFilter(log.tilt_time_constant_s)
    attitude.R = log.R0.copy()
    estimator.reset(log.q0, attitude.R, log.start_xy, log.start_yaw)
    for k in range(len(log.q)):
        estimator.update(log.q[k], attitude.update(log.gyro[k], log.accel[k], log.dt))
    return estimator.pose(), attitude.R.copy()


@dataclass
class GaitRun:
    """What a gait run (or a joint path run on the ground: ``gait`` None) did.

    name: the gait's, or the path's; state: the simulated state at its end (start the next phase here); estimate /
    truth: the body's pose at the end (:class:`~snakehead.closed_loop.estimate.BodyPose`), estimated and true; start_truth:
    the true pose at the start. t (T,) s, q / q_ref (T, n) rad: recorded every ``record_every`` control ticks;
    chassis_truth / chassis_estimate (T, 3) m: the virtual chassis' origin; heading_truth / heading_estimate (T,)
    rad; height (T,) m: the highest point of the collision shapes above the ground; contact_fraction (T,): the share of
    the links with shapes touching the ground (within 3 mm); root_truth / root_estimate (T, 4, 4): the root frame's
    world pose. On a slope every pose and heading is in the simulator's ground frame.
    """

    gait: Gait | None
    cycles: float
    state: SimState
    estimate: BodyPose
    truth: BodyPose
    start_truth: BodyPose
    t: np.ndarray
    q: np.ndarray
    q_ref: np.ndarray
    chassis_truth: np.ndarray
    chassis_estimate: np.ndarray
    heading_truth: np.ndarray
    heading_estimate: np.ndarray
    height: np.ndarray
    contact_fraction: np.ndarray
    settings: dict = field(default_factory=dict)
    name: str = ""
    root_truth: np.ndarray | None = None
    root_estimate: np.ndarray | None = None
    start_estimate: BodyPose | None = None
    sensor_log: SensorLog | None = None

    @property
    def estimate_error(self) -> dict:
        """:func:`~snakehead.closed_loop.estimate.pose_error` of the final estimate against the truth."""
        return pose_error(self.estimate, self.truth)

    @property
    def travel(self) -> np.ndarray:
        """The virtual chassis' true displacement (2,) m over the run, in the body's frame at the start (x along
        the body towards the head, y to its left)."""
        d = self.truth.chassis[:2, 3] - self.start_truth.chassis[:2, 3]
        h = self.start_truth.heading
        c, s = math.cos(h), math.sin(h)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    @property
    def travel_direction_deg(self) -> float:
        """Direction of :attr:`travel` in the start body frame (deg; +90 = to the left)."""
        return math.degrees(math.atan2(self.travel[1], self.travel[0]))

    @property
    def turn_deg(self) -> float:
        """The true change of the body's heading over the run (deg, counter-clockwise positive; followed through
        the run, so a turn of more than half a revolution counts in full)."""
        return math.degrees(self.heading_truth[-1] - self.start_truth.heading)

    def body_lengths_per_cycle(self, robot: SnakeRobot) -> float:
        return float(np.linalg.norm(self.travel)) / robot.body_length / self.cycles

    @property
    def turn_deg_per_cycle(self) -> float:
        return self.turn_deg / self.cycles


class GaitSimulator:
    """One robot on the friction ground in MuJoCo, ready to run gaits from any state.

    kp, kd: PD gains (default: derived per joint, :func:`snakehead.sim.gains.default_gains`); imu_link: the frame
    carrying the IMU of the pose estimate (default: mid-body); imu_yaw_drift_deg_per_s: a gyro's heading drift
    (deg/s; the IMU reads the link's true orientation turned by drift x time about the vertical; default 0, a
    perfect attitude); ground: the plane the robot lies on (a :class:`~snakehead.model.placement.GroundFrame`, default
    flat ground; see the module); odometry: the estimate's (:data:`snakehead.closed_loop.estimate.ODOMETRY`); sensors: the robot's own
    (:class:`snakehead.sim.sensors.OnboardSensors`: the estimate then reads the encoders and the IMU's gyro and
    accelerometer through an :class:`~snakehead.closed_loop.estimate.AttitudeFilter`, and every run keeps a
    :class:`SensorLog`; None, the default: the true joint angles and the IMU link's true orientation); other keywords
    (friction, torque_limit, obstacles, armature, joint_damping, timestep...) go to :func:`snakehead.sim.build_spec`.
    """

    def __init__(self, robot: SnakeRobot, *, kp: npt.ArrayLike | None = None, kd: npt.ArrayLike | None = None,
                 imu_link: str | None = None, imu_yaw_drift_deg_per_s: float = 0.0,
                 control_dt: float = DEFAULT_CONTROL_DT, timestep: float = DEFAULT_TIMESTEP,
                 odometry: str = "friction", sensors: OnboardSensors | None = None,
                 ground: GroundFrame = WORLD_FRAME, **model_options: Any) -> None:
        self._mj = import_mujoco()
        self.robot = as_robot(robot)
        n = self.robot.n_joints
        armature = model_options.get("armature", 1e-3)
        if not isinstance(ground, GroundFrame):
            raise InputTypeError(f"ground must be a GroundFrame, got {type(ground).__name__}")
        self.ground = ground
        self.sim = build_model(self.robot, timestep=timestep, ground=ground, **model_options)
        if kp is None or kd is None:
            kp_load, kd_load = default_gains(self.robot, armature=armature)
            kp = kp_load if kp is None else kp
            kd = kd_load if kd is None else kd
        self.kp = gain_vector(kp, n, "kp", allow_zero=False)
        self.kd = gain_vector(kd, n, "kd", allow_zero=True)
        m = self.sim.model
        m.actuator_biasprm[:, 1] = -self.kp
        m.actuator_biasprm[:, 2] = -self.kd
        self.substeps = int(round(control_dt / timestep))
        if self.substeps < 1 or abs(self.substeps * timestep - control_dt) > 1e-9 * control_dt:
            raise InputError(f"control_dt ({control_dt} s) must be a whole multiple of timestep ({timestep} s)")
        self.control_dt = float(control_dt)
        self.data = self._mj.MjData(m)
        self.estimator = BodyPoseEstimator(self.robot, imu_link, odometry=odometry, ground=ground)
        self.imu_yaw_drift = math.radians(finite_float(imu_yaw_drift_deg_per_s, "imu_yaw_drift_deg_per_s"))
        self.time = 0.0  # simulated time (s) of the state in ``data``
        self._imu_body = int(self.sim.body_ids[self.estimator.imu_index])
        self._points = ShapePoints(self.robot)
        self._shape_bodies = self.sim.body_ids[self._points.links]
        if sensors is not None and not isinstance(sensors, OnboardSensors):
            raise InputTypeError(f"sensors must be an OnboardSensors or None, got {type(sensors).__name__}")
        self.sensors = sensors
        self.attitude = AttitudeFilter()

    # --- states -------------------------------------------------------------------------------------
    def lying(self, base: BasePlacement | None = None, q: npt.ArrayLike | None = None, settle_s: float = 0.3) -> SimState:
        """The robot lying at ``base`` (default placement; on the simulator's ground: ``base.ground`` must be
        ``ground``) with joints ``q`` (default straight), settled on the ground for ``settle_s`` s while its
        servos hold q."""
        base = BasePlacement(ground=self.ground) if base is None else as_base(base)
        q = np.zeros(self.robot.n_joints) if q is None else joint_vector(q, self.robot.n_joints)
        settle_s = finite_float(settle_s, "settle_s")
        if settle_s < 0:
            raise InputError(f"settle_s must be >= 0, got {settle_s!r}")
        d = self.data
        self.sim.set_state(d, q, base, lift=2e-4)
        for _ in range(int(round(settle_s / self.control_dt))):
            self._step(q, np.zeros_like(q))
        self.time = 0.0
        if self.sensors is not None:  # the IMU starts; the attitude levels itself on gravity, heading 0
            self.sensors.imu.start(self._imu_true())
            _, accel = self.sensors.imu.read(self._imu_true(), self.control_dt)
            self.attitude.reset(accel)
        return self._snapshot(0.0)

    def _snapshot(self, time: float) -> SimState:
        return SimState(self.data.qpos.copy(), self.data.qvel.copy(), time)

    def restore(self, state: SimState) -> None:
        """Put the simulation in ``state``."""
        if not isinstance(state, SimState):
            raise InputTypeError(f"state must be a SimState (from GaitSimulator.lying or a GaitRun), got "
                            f"{type(state).__name__}")
        state.load(self.sim, self.data)
        self.time = float(state.time)

    def _step(self, q_ref: np.ndarray, qd_ref: np.ndarray) -> None:
        """One control period; then the positions of everything (what the sensors read) for the new state."""
        self.data.ctrl[:] = self.kp * q_ref + self.kd * qd_ref
        self._mj.mj_step(self.sim.model, self.data, self.substeps)
        self._mj.mj_kinematics(self.sim.model, self.data)

    # --- measurements ---------------------------------------------------------------------------------
    def joint_angles(self) -> np.ndarray:
        """The joint angles now (the encoders)."""
        return self.data.qpos[self.sim.qpos_adr].copy()

    def _imu_true(self) -> np.ndarray:
        return self.data.xmat[self._imu_body].reshape(3, 3).copy()

    def measured_joints(self) -> np.ndarray:
        """The joint angles as the robot knows them: the encoders' reading with sensors, else the true angles."""
        q = self.joint_angles()
        return q if self.sensors is None else self.sensors.encoders.read(q)

    def measured_attitude(self) -> np.ndarray:
        """The IMU link's orientation as the robot knows it: the attitude filter's with sensors, else
        :meth:`imu_orientation`."""
        return self.imu_orientation() if self.sensors is None else self.attitude.R.copy()

    def _sense(self) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray] | None]:
        """One control period's readings: the joints, the attitude and (with sensors) the IMU's (gyro, accel)."""
        if self.sensors is None:
            return self.joint_angles(), self.imu_orientation(), None
        gyro, accel = self.sensors.imu.read(self._imu_true(), self.control_dt)
        return self.measured_joints(), self.attitude.update(gyro, accel, self.control_dt), (gyro, accel)

    def reset_attitude(self, R: npt.ArrayLike) -> None:
        """The robot learnt its IMU link's orientation ``R`` (3, 3) otherwise (a fix): the attitude filter starts
        from it, and the IMU from the link's orientation now (after a motion simulated elsewhere)."""
        if self.sensors is not None:
            self.sensors.imu.start(self._imu_true())
            self.attitude.R = np.array(R, float).reshape(3, 3)

    def imu_orientation(self) -> np.ndarray:
        """What a perfect IMU reads now: its link's world orientation (3, 3) (MuJoCo's world, gravity along -z, on
        a slope too), turned about the vertical by the drift."""
        R = self._imu_true()
        if self.imu_yaw_drift:
            a = self.imu_yaw_drift * self.time
            c, s = math.cos(a), math.sin(a)
            R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ R
        return R

    def true_pose(self, previous: BodyPose | None = None) -> BodyPose:
        """MuJoCo's pose of the body now (ground truth), in the ground frame; the chassis' x-axis kept close to
        ``previous``'s."""
        d = self.data
        root = np.eye(4)
        rb = self.sim.root_body
        root[:3, :3] = d.xmat[rb].reshape(3, 3)
        root[:3, 3] = d.xpos[rb]
        points = self._points.centre_points(self._shape_frames())
        chassis = virtual_chassis(points, None if previous is None else previous.chassis, points[-1] - points[0])
        return BodyPose(root=in_ground(self.ground, root), chassis=chassis, body_in_root=self.robot.body_in_root,
                        ground=self.ground)

    def _shape_frames(self) -> np.ndarray:
        """Poses (k, 4, 4) of the links with collision shapes, now, in the ground frame (the world's on flat
        ground)."""
        d = self.data
        F = np.zeros((len(self._shape_bodies), 4, 4))
        F[:, :3, :3] = d.xmat[self._shape_bodies].reshape(-1, 3, 3)
        F[:, :3, 3] = d.xpos[self._shape_bodies]
        F[:, 3, 3] = 1.0
        return in_ground(self.ground, F)

    def _shape_heights(self) -> tuple[float, float]:
        """(highest point of the collision shapes above the ground (m), share of the shaped links whose lowest
        point is within 3 mm of it)."""
        z = self._points.world(self._shape_frames())[:, 2]
        return float(z.max()), float(np.mean(self._points.lowest(z) < 0.003))

    # --- running a gait -----------------------------------------------------------------------------------
    def run(self, state: SimState, gait: Gait, cycles: float, *, rest_s: float = 0.5, record_every: int = 5,
            start_estimate: BodyPose | None = None) -> GaitRun:
        """Run ``gait`` for ``cycles`` cycles from ``state`` (see the module). The estimate starts from
        ``start_estimate`` (default: the true pose at the start: the robot knows where it starts) and follows the
        joint angles and the IMU from there."""
        if not isinstance(gait, Gait):
            raise InputTypeError(f"gait must be a snakehead.locomotion.gaits.Gait (make_gait), got {type(gait).__name__}")
        cycles = finite_float(cycles, "cycles")
        if cycles <= 0:
            raise InputError(f"cycles must be > 0, got {cycles!r}")
        gait.check(self.robot)
        _, q_plan = gait.trajectory(self.robot, cycles, self.control_dt)
        return self._run(state, q_plan, gait.name, rest_s, record_every, start_estimate, gait=gait, cycles=cycles)

    def run_path(self, state: SimState, q_path: npt.ArrayLike, duration_s: float, *, rest_s: float = 0.5, record_every: int = 5,
                 start_estimate: BodyPose | None = None, name: str = "path") -> GaitRun:
        """Run the joint path ``q_path`` (K, n) rad from ``state``: its configurations evenly spread over
        ``duration_s`` s and joined by a smooth-step in time (zero joint velocity at both ends), linear in the joints
        between them; then ``rest_s`` holding the last. The reference starts from the joints' angles in ``state``
        when they differ from q_path[0] (it is not a jump: the path is prefixed with them). Otherwise as :meth:`run`
        (``cycles`` is 1 in the result)."""
        n = self.robot.n_joints
        q_path = finite_array(q_path, "q_path")
        q_path = finite_array(q_path[None] if q_path.ndim == 1 else q_path, "q_path", (None, n))
        if len(q_path) == 0:
            raise InputError("q_path must hold at least one configuration")
        outside = (q_path < self.robot.lower - 1e-9) | (q_path > self.robot.upper + 1e-9)
        if outside.any():
            k, j = np.argwhere(outside)[0]
            raise InputError(f"q_path[{k}, {j}] = {q_path[k, j]:.4g} rad is outside the joint limits of "
                             f"{self.robot.joint_names[j]!r}")
        duration_s = finite_float(duration_s, "duration_s")
        if duration_s <= 0:
            raise InputError(f"duration_s must be > 0, got {duration_s!r}")
        self.restore(state)
        q_now = self.measured_joints()
        if np.abs(q_path[0] - q_now).max() > 1e-9:
            q_path = np.vstack([q_now, q_path])
        ticks = max(int(round(duration_s / self.control_dt)), 1)
        s = np.arange(1, ticks + 1) / ticks
        u = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)  # smooth step: rest to rest
        x = u * (len(q_path) - 1)
        i = np.minimum(np.floor(x).astype(int), len(q_path) - 2) if len(q_path) > 1 else np.zeros(ticks, int)
        if len(q_path) == 1:
            q_plan = np.repeat(q_path, ticks, axis=0)
        else:
            f = (x - i)[:, None]
            q_plan = q_path[i] + f * (q_path[i + 1] - q_path[i])
        return self._run(state, q_plan, name, rest_s, record_every, start_estimate, gait=None, cycles=1.0)

    def _run(self, state: SimState, q_plan: np.ndarray, name: str, rest_s: float, record_every: int,
             start_estimate: BodyPose | None, *, gait: Gait | None, cycles: float) -> GaitRun:
        """Track the reference q_plan (one row per control tick) from ``state``, then rest; record and estimate."""
        rest_s = _checked_run_options(rest_s, record_every, start_estimate)
        self.restore(state)
        q_plan, qd_plan = self._reference(q_plan, rest_s)
        start_truth = self.true_pose()
        est0 = start_truth if start_estimate is None else start_estimate
        q0, R0 = self.measured_joints(), self.measured_attitude()
        self.estimator.reset(q0, R0, (est0.base.x, est0.base.y), est0.base.yaw)
        arr, readings, estimate, truth = self._track(state, q_plan, qd_plan, record_every, name, start_truth)
        end = self._snapshot(self.time)
        log = None
        if self.sensors is not None:
            log = SensorLog(q0=q0, R0=R0, start_xy=np.array([est0.base.x, est0.base.y]), start_yaw=est0.base.yaw,
                            q=np.array([r[0] for r in readings]), gyro=np.array([r[1] for r in readings]),
                            accel=np.array([r[2] for r in readings]), dt=self.control_dt,
                            imu_link=self.estimator.imu_link, odometry=self.estimator.odometry,
                            tilt_time_constant_s=1.0 / self.attitude.gain, ground=self.ground)
        # headings unwrapped from the start's, so that turns beyond half a revolution count in full
        heading_truth = np.unwrap(np.concatenate([[start_truth.heading], arr["ht"]]))[1:]
        heading_estimate = np.unwrap(np.concatenate([[est0.heading], arr["he"]]))[1:]
        return GaitRun(gait=gait, cycles=float(cycles), state=end, estimate=estimate, truth=truth,
                       start_truth=start_truth, t=arr["t"], q=arr["q"], q_ref=arr["q_ref"],
                       chassis_truth=arr["ct"], chassis_estimate=arr["ce"], heading_truth=heading_truth,
                       heading_estimate=heading_estimate, height=arr["height"], contact_fraction=arr["contact"],
                       settings=dict(imu_link=self.estimator.imu_link, control_dt=self.control_dt,
                                     imu_yaw_drift_deg_per_s=math.degrees(self.imu_yaw_drift),
                                     odometry=self.estimator.odometry, rest_s=float(rest_s), kp=self.kp.tolist(),
                                     kd=self.kd.tolist()),
                       name=name, root_truth=arr["rt"], root_estimate=arr["re"], start_estimate=est0,
                       sensor_log=log)

    def _reference(self, q_plan: np.ndarray, rest_s: float) -> tuple[np.ndarray, np.ndarray]:
        """The reference of a run: q_plan (one row per control tick) then ``rest_s`` s holding its last row, and
        its rates (0 while resting)."""
        n_rest = int(round(rest_s / self.control_dt))
        q_plan = np.vstack([q_plan, np.repeat(q_plan[-1:], n_rest, axis=0)])
        qd_plan = np.gradient(q_plan, self.control_dt, axis=0) if len(q_plan) > 1 else np.zeros_like(q_plan)
        qd_plan[len(q_plan) - n_rest:] = 0.0
        return q_plan, qd_plan

    def _track(self, state: SimState, q_plan: np.ndarray, qd_plan: np.ndarray, record_every: int, name: str,
               truth: BodyPose) -> tuple[dict[str, np.ndarray], list, BodyPose, BodyPose]:
        """Step the servos along the reference from ``state``'s time, the estimator reading the senses at every
        tick; every ``record_every`` ticks (and the last) the record's row. The record's arrays, the IMU's
        readings, and the estimate and the truth (``truth``: the start's) at the end."""
        estimate = self.estimator.pose()
        readings: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        rec: dict[str, list] = {k: [] for k in ("t", "q", "q_ref", "ct", "ce", "ht", "he", "height", "contact", "rt",
                                                "re")}
        for k in range(len(q_plan)):
            self._step(q_plan[k], qd_plan[k])
            self.time = state.time + (k + 1) * self.control_dt
            q_sensed, R_sensed, imu = self._sense()
            if imu is not None:
                readings.append((q_sensed, *imu))
            self.estimator.update(q_sensed, R_sensed)
            if k % record_every == 0 or k == len(q_plan) - 1:
                estimate = self.estimator.pose()
                truth = self.true_pose(truth)
                self._record_row(rec, q_plan[k], truth, estimate)
            if not np.all(np.isfinite(self.data.qpos)):
                raise RuntimeError(f"the simulation diverged {self.control_dt * k:.3f} s into the {name} run")
        return {k: np.asarray(v) for k, v in rec.items()}, readings, estimate, truth

    def _record_row(self, rec: dict[str, list], q_ref: np.ndarray, truth: BodyPose, estimate: BodyPose) -> None:
        """One row of a run's record: the time, the joints and their reference, the chassis and the heading (true
        and estimated), the body's height and its share of links on the ground, the root frame's poses."""
        h, c = self._shape_heights()
        rec["t"].append(self.time)
        rec["q"].append(self.joint_angles())
        rec["q_ref"].append(q_ref)
        rec["ct"].append(truth.chassis[:3, 3])
        rec["ce"].append(estimate.chassis[:3, 3])
        rec["ht"].append(truth.heading)
        rec["he"].append(estimate.heading)
        rec["height"].append(h)
        rec["contact"].append(c)
        rec["rt"].append(truth.root)
        rec["re"].append(estimate.root)


def _checked_run_options(rest_s: float, record_every: int, start_estimate: BodyPose | None) -> float:
    """A run's ``rest_s`` (s, >= 0), checked with ``record_every`` (a positive integer) and ``start_estimate``."""
    rest_s = finite_float(rest_s, "rest_s")
    if rest_s < 0:
        raise InputError(f"rest_s must be >= 0, got {rest_s!r}")
    if isinstance(record_every, bool) or not isinstance(record_every, (int, np.integer)) or record_every < 1:
        raise InputError(f"record_every must be a positive integer, got {record_every!r}")
    if start_estimate is not None and not isinstance(start_estimate, BodyPose):
        raise InputTypeError(f"start_estimate must be a BodyPose, got {type(start_estimate).__name__}")
    return rest_s
