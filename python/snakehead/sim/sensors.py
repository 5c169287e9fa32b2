"""The robot's own senses in the simulation: what a real snake robot measures about itself and its target, with
stated, realistic figures. The closed loop (:mod:`snakehead.closed_loop.loop`, ``sensing="onboard"``) reads the simulator
only through these models (:class:`OnboardSensors`); the estimator (:mod:`snakehead.closed_loop.estimate`) turns their
streams into a pose.

* :class:`Encoders` -- every joint's absolute angle, quantised to ``counts_per_rev`` counts per revolution
  (ENCODER_COUNTS_PER_REV: a 12-bit magnetic encoder).
* :class:`Imu` -- one MEMS IMU on a link: the gyroscope reads the link's angular velocity in its own axes plus
  white noise (GYRO_NOISE_DENSITY) and a bias that wanders as a random walk (GYRO_BIAS_RANDOM_WALK); the
  accelerometer reads the specific force plus white noise (ACCEL_NOISE_DENSITY). The true angular velocity over a
  control period is the rotation between the link's orientations at its ends, so that integrating a noise-free
  gyro gives the orientation back exactly. The accelerometer's true value is gravity alone (quasi-static: the
  gaits at 0.5 Hz move the links by less than 0.1 m/s^2, 1 % of g; not modelled). Both read the link's orientation
  in MuJoCo's world (``data.xmat``), where gravity is (0, 0, -GRAVITY) on a slope too: on a slope the reading of a
  link lying on it leans by the slope's angle, as a real IMU's does (not the ground-frame poses of
  :meth:`snakehead.sim.mjcf.SimModel.frames`, where gravity leans instead).
* :class:`HeadSensor` -- a camera in the head that sees a target's fiducial marker (at a known world pose:
  MARKER_AHEAD_M ahead of each of the scene's targets along its direction) and measures its pose relative to the
  head tip frame: position with HEAD_POSITION_NOISE_M per axis and orientation with HEAD_DIRECTION_NOISE_DEG per
  axis, only within HEAD_HALF_FOV_DEG of the head's axis, between
  HEAD_RANGE_M, and when the line of sight does not pass through an obstacle (a ray test against the obstacles'
  convex shapes, :mod:`snakehead.collision.body_collisions`).

Every noise comes from one seeded :class:`numpy.random.Generator` per sensor (``seed``), so a run is reproducible.
What is not modelled: encoder backlash and calibration offsets, the IMU's scale factors and misalignment, the
camera's calibration error and latency.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_float
from ..collision.body_collisions import obstacle_shapes
from ..geometry.shapes import Shape, ShapeSet, pair_min_distances
from ..model.physics import GRAVITY  # the simulated world's (sim.mjcf sets MuJoCo's gravity to it)

__all__ = ["ENCODER_COUNTS_PER_REV", "GYRO_NOISE_DENSITY", "GYRO_BIAS_RANDOM_WALK", "ACCEL_NOISE_DENSITY",
           "HEAD_POSITION_NOISE_M", "HEAD_DIRECTION_NOISE_DEG", "HEAD_HALF_FOV_DEG", "MARKER_AHEAD_M", "HEAD_RANGE_M",
           "SIGHT_RADIUS_M", "so3_log", "so3_exp", "Encoders", "Imu", "target_frame", "marker_frame", "HeadReading",
           "mean_pose", "HeadSensor", "occluded", "OnboardSensors"]

#: Encoder counts per joint revolution: 12-bit absolute magnetic encoders (AS5045/AS5048-class; the Dynamixel
#: X-series servos also report 4096 counts/rev): a step of 0.088 deg.
ENCODER_COUNTS_PER_REV = 4096
#: Gyroscope white noise density (rad/s/sqrt(Hz)): 0.01 deg/s/sqrt(Hz), consumer MEMS IMUs (MPU-6000 / ICM-20948
#: datasheets: 0.005-0.015 deg/s/sqrt(Hz)).
GYRO_NOISE_DENSITY = 1.7e-4
#: Gyroscope bias random walk (rad/s^2/sqrt(Hz), i.e. rad/s per sqrt(s)): the Allan-variance figure used for that
#: class of part in visual-inertial calibration (about 2e-5; 4 deg/h of bias wander after an hour).
GYRO_BIAS_RANDOM_WALK = 2.0e-5
#: Accelerometer white noise density (m/s^2/sqrt(Hz)): 200 micro-g/sqrt(Hz) (MPU-6000: 400, ICM-20948: 230,
#: BMI088: 160).
ACCEL_NOISE_DENSITY = 2.0e-3
#: Head camera: noise of one frame's marker pose at 0.1-0.6 m (a calibrated camera and a fiducial marker: about
#: a millimetre and half a degree per frame), per axis of the position and about the direction.
HEAD_POSITION_NOISE_M = 0.001
HEAD_DIRECTION_NOISE_DEG = 0.5
#: Half the head camera's field of view (deg): a 120 deg wide-angle lens (camera modules: 60-160 deg).
HEAD_HALF_FOV_DEG = 60.0
#: Each head target is marked by a fiducial this far ahead of it along its direction (m): a camera at the head tip
#: aiming along the target's direction sees it, in front of the head.
MARKER_AHEAD_M = 0.15
#: Nearest and farthest distances (m) at which the head camera resolves the marker's pose.
HEAD_RANGE_M = (0.02, 1.5)
#: Radius (m) of the line of sight in the occlusion test (a thin cylinder: the ray).
SIGHT_RADIUS_M = 1e-4


def _rng(seed: int | None) -> np.random.Generator:
    return np.random.default_rng(seed)


def so3_log(R: np.ndarray) -> np.ndarray:
    """The rotation vector (3,) of a rotation matrix (angle < pi)."""
    c = float(np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0))
    angle = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-8:
        return 0.5 * w
    return angle / (2.0 * math.sin(angle)) * w


def so3_exp(v: npt.ArrayLike) -> np.ndarray:
    """The rotation matrix of a rotation vector (Rodrigues)."""
    v = np.asarray(v, float)
    angle = float(np.linalg.norm(v))
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    if angle < 1e-8:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + math.sin(angle) / angle * K + (1.0 - math.cos(angle)) / angle ** 2 * K @ K


@dataclass(frozen=True)
class Encoders:
    """Absolute joint encoders: an angle is read as the nearest multiple of 2 pi / ``counts_per_rev``."""

    counts_per_rev: int = ENCODER_COUNTS_PER_REV

    def __post_init__(self) -> None:
        if isinstance(self.counts_per_rev, bool) or int(self.counts_per_rev) != self.counts_per_rev \
                or self.counts_per_rev < 2:
            raise InputError(f"counts_per_rev must be an integer >= 2, got {self.counts_per_rev!r}")

    @property
    def resolution_rad(self) -> float:
        return 2.0 * math.pi / self.counts_per_rev

    def read(self, q: npt.ArrayLike) -> np.ndarray:
        """The encoders' reading (n,) of the true angles ``q`` (n,) rad."""
        step = self.resolution_rad
        return np.round(np.asarray(q, float) / step) * step


class Imu:
    """A MEMS IMU (see the module): ``read(R_now, dt)`` gives (gyro (3,) rad/s, accel (3,) m/s^2) in the IMU's
    axes for the control period of ``dt`` s that ended with the IMU link at world orientation ``R_now`` (MuJoCo's
    world, gravity along -z, also on a slope).
    ``start(R)`` puts it on a link at orientation R (the gyro's bias is kept). Figures: the module's constants."""

    def __init__(self, *, gyro_noise_density: float = GYRO_NOISE_DENSITY,
                 gyro_bias_random_walk: float = GYRO_BIAS_RANDOM_WALK,
                 accel_noise_density: float = ACCEL_NOISE_DENSITY, gyro_bias: npt.ArrayLike = (0.0, 0.0, 0.0),
                 seed: int | None = 0) -> None:
        for name, value in (("gyro_noise_density", gyro_noise_density),
                            ("gyro_bias_random_walk", gyro_bias_random_walk),
                            ("accel_noise_density", accel_noise_density)):
            if finite_float(value, name) < 0:
                raise InputError(f"{name} must be >= 0, got {value!r}")
        self.gyro_noise_density = float(gyro_noise_density)
        self.gyro_bias_random_walk = float(gyro_bias_random_walk)
        self.accel_noise_density = float(accel_noise_density)
        self.bias = np.array(gyro_bias, float).reshape(3)
        self._rng = _rng(seed)
        self._R: np.ndarray | None = None

    def start(self, R: npt.ArrayLike) -> None:
        self._R = np.array(R, float).reshape(3, 3)

    def read(self, R_now: npt.ArrayLike, dt: float) -> tuple[np.ndarray, np.ndarray]:
        R_now = np.asarray(R_now, float).reshape(3, 3)
        if self._R is None:
            raise InputError("Imu.start(R) first: the IMU must know its orientation at the start")
        omega = so3_log(self._R.T @ R_now) / dt  # body axes: R_now = R_prev exp(omega dt)
        self._R = R_now.copy()
        e = self._rng.standard_normal(9)
        # discrete white noise: density / sqrt(dt); the bias walks by density * sqrt(dt) per period
        root = math.sqrt(dt)
        self.bias = self.bias + self.gyro_bias_random_walk * root * e[:3]
        gyro = omega + self.bias + self.gyro_noise_density / root * e[3:6]
        accel = GRAVITY * R_now[2] + self.accel_noise_density / root * e[6:]  # R^T (0, 0, g)
        return gyro, accel


def target_frame(position: npt.ArrayLike, direction: npt.ArrayLike) -> np.ndarray:
    """The world frame (4, 4) of a head target: at ``position``, x along ``direction``, z as close to the world's
    up as x allows (the world's x when the direction is vertical)."""
    x = np.asarray(direction, float) / np.linalg.norm(direction)
    up = np.array([0.0, 0.0, 1.0]) if abs(x[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    z = up - (up @ x) * x
    z /= np.linalg.norm(z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, position
    return T


def marker_frame(position: npt.ArrayLike, direction: npt.ArrayLike, ahead_m: float = MARKER_AHEAD_M) -> np.ndarray:
    """The world frame (4, 4) of the marker of a head target: :func:`target_frame` moved ``ahead_m`` along the
    target's direction (where a camera looking along the head's axis sees it)."""
    T = target_frame(position, direction)
    T[:3, 3] += ahead_m * T[:3, 0]
    return T


@dataclass(frozen=True)
class HeadReading:
    """One head camera frame: the marker's pose (4, 4) in the head tip frame, and which target it marks."""

    target: int
    pose: np.ndarray

    @property
    def target_in_head(self) -> np.ndarray:
        """The target's frame (4, 4) in the head tip frame, from this reading (the marker is MARKER_AHEAD_M
        ahead of it along its x-axis)."""
        T = self.pose.copy()
        T[:3, 3] -= MARKER_AHEAD_M * T[:3, 0]
        return T


def mean_pose(poses: Sequence[np.ndarray]) -> np.ndarray:
    """The mean (4, 4) of nearby poses: positions averaged, rotations averaged on the tangent space of the
    first."""
    R0 = poses[0][:3, :3]
    T = np.eye(4)
    T[:3, :3] = R0 @ so3_exp(np.mean([so3_log(R0.T @ P[:3, :3]) for P in poses], axis=0))
    T[:3, 3] = np.mean([P[:3, 3] for P in poses], axis=0)
    return T


class HeadSensor:
    """The head camera (see the module). ``targets``: (position (3,), direction (3,)) world poses of the scene's
    targets, each marked by a fiducial (:func:`marker_frame`); ``obstacles``: the scene's (they hide a marker
    behind them)."""

    def __init__(self, targets: Sequence[tuple[npt.ArrayLike, npt.ArrayLike]], obstacles: Sequence[Any] = (), *,
                 position_noise_m: float = HEAD_POSITION_NOISE_M,
                 direction_noise_deg: float = HEAD_DIRECTION_NOISE_DEG, half_fov_deg: float = HEAD_HALF_FOV_DEG,
                 range_m: tuple[float, float] = HEAD_RANGE_M, seed: int | None = 0) -> None:
        self.markers = [marker_frame(p, d) for p, d in targets]
        self.obstacles = list(obstacles)
        for name, value in (("position_noise_m", position_noise_m), ("direction_noise_deg", direction_noise_deg)):
            if finite_float(value, name) < 0:
                raise InputError(f"{name} must be >= 0, got {value!r}")
        if not 0.0 < finite_float(half_fov_deg, "half_fov_deg") <= 180.0:
            raise InputError(f"half_fov_deg must be in (0, 180], got {half_fov_deg!r}")
        if not 0.0 <= range_m[0] < range_m[1]:
            raise InputError(f"range_m must be (near, far) with 0 <= near < far, got {range_m!r}")
        self.position_noise_m = float(position_noise_m)
        self.direction_noise_rad = math.radians(direction_noise_deg)
        self.half_fov_rad = math.radians(half_fov_deg)
        self.range_m = (float(range_m[0]), float(range_m[1]))
        self._rng = _rng(seed)

    def in_view(self, head: np.ndarray, k: int) -> bool:
        """Whether the marker of target ``k`` is seen from the head tip's world pose ``head`` (4, 4): in range,
        within the field of view about the head's x-axis, and not hidden by an obstacle."""
        p = self.markers[k][:3, 3]
        d = p - head[:3, 3]
        dist = float(np.linalg.norm(d))
        if not self.range_m[0] <= dist <= self.range_m[1]:
            return False
        if float(d @ head[:3, 0]) < dist * math.cos(self.half_fov_rad):
            return False
        return not occluded(head[:3, 3], p, self.obstacles)

    def visible(self, head: np.ndarray) -> list[int]:
        """The targets whose markers are in view from the head tip's world pose ``head`` (4, 4)."""
        return [k for k in range(len(self.markers)) if self.in_view(head, k)]

    def read(self, head: np.ndarray, k: int) -> HeadReading | None:
        """One frame of the marker of target ``k`` from the head tip's world pose ``head`` (4, 4), or None when it
        is not in view: its true pose in the head frame, the position off by Gaussian noise of
        ``position_noise_m`` per axis, the rotation by a rotation vector of ``direction_noise_deg`` per axis."""
        if not self.in_view(head, k):
            return None
        T = np.linalg.solve(head, self.markers[k])
        e = self._rng.standard_normal(6)
        T[:3, 3] += self.position_noise_m * e[:3]
        T[:3, :3] = T[:3, :3] @ so3_exp(self.direction_noise_rad * e[3:])
        return HeadReading(k, T)


def occluded(a: npt.ArrayLike, b: npt.ArrayLike, obstacles: Sequence[Any]) -> bool:
    """Whether the segment from ``a`` to ``b`` (3,) m passes through any of the obstacles' shapes (a thin cylinder
    of SIGHT_RADIUS_M along it, against their convex shapes)."""
    if not obstacles:
        return False
    a, b = np.asarray(a, float), np.asarray(b, float)
    axis = b - a
    length = float(np.linalg.norm(axis))
    if length < 1e-9:
        return False
    z = axis / length
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, 0.5 * (a + b)
    ray = ShapeSet((Shape("cylinder", 0, T, np.array([SIGHT_RADIUS_M, length, 0.0])),), 1)
    shapes, _ = obstacle_shapes(obstacles)
    pairs = np.array([[0, s] for s in range(len(shapes.shapes))], dtype=np.int64)
    eye = np.eye(4)[None, None]
    return bool(pair_min_distances(eye, ray, eye, shapes, pairs)[0] <= 0.0)


@dataclass
class OnboardSensors:
    """Every sensor of the robot on one simulated body (see the module): ``encoders``, ``imu`` (on the estimator's
    IMU link) and ``head`` (a :class:`HeadSensor`, None without one)."""

    encoders: Encoders
    imu: Imu
    head: HeadSensor | None = None

    @classmethod
    def realistic(cls, targets: Sequence[tuple[npt.ArrayLike, npt.ArrayLike]] = (), obstacles: Sequence[Any] = (),
                  seed: int | None = 0) -> "OnboardSensors":
        """The module's figures; the IMU's and the camera's noise drawn from streams spawned from ``seed``."""
        a, b = (np.random.SeedSequence(seed).spawn(2) if seed is not None else (None, None))
        imu_seed = None if a is None else int(a.generate_state(1)[0])
        head_seed = None if b is None else int(b.generate_state(1)[0])
        head = HeadSensor(targets, obstacles, seed=head_seed) if len(targets) else None
        return cls(Encoders(), Imu(seed=imu_seed), head)
