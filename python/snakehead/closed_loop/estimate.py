"""Where the body is, estimated from the body itself as a robot would: its joint angles (encoders) and the
orientation of one link (an IMU's attitude), never the simulator's positions.

* Orientation: the IMU link's world orientation and the joint angles give every link's orientation (forward
  kinematics from the IMU link).
* Shape: the body's points (the middle of each link's collision shapes: a box's centre) in world axes, relative
  to the root frame's origin.
* Height: the body rests on the ground, so the lowest point of its collision shapes is at z = 0.
* Planar position, by contact odometry: the links that touch the ground (the lowest point of their shapes within
  ``contact_height`` of it) hold it through their contact points -- the middle of the link's shape points (box
  corners, cylinder rims, sphere and hull vertices: :class:`ShapePoints`) that are lowest, a material point of the
  link. Between two updates the body is moved by the translation that balances the friction of those contact
  points (``odometry="friction"``, the default: the weighted geometric median of the shifts that would keep each
  still, loads the links' masses, :func:`snakehead.dynamics.sliding.balance_translation`; contacts slip where the
  others outpull them, and stay put where they hold), or by the average of those shifts (``odometry="no-slip"``:
  every contact assumed not to slip).
* The virtual chassis (:func:`snakehead.locomotion.gaits.virtual_chassis`, after Rollinson and Choset, "Virtual
  Chassis for Snake Robots", IROS 2011): a frame at the centroid of the body's points whose x-axis is the principal
  axis of the shape (its direction kept from update to update, towards the head when the body is straight) and
  z-axis the third principal axis turned upwards. It moves smoothly while a gait's joints cycle, so it says where
  "the body" is better than any one link.

On a slope (a plane terrain: the estimator's ``ground``, a :class:`~snakehead.model.placement.GroundFrame`) every
pose is in the slope's ground frame, as the planner's are: the IMU measures its orientation against world gravity
(its tilt is the slope's), and the estimator turns it into the ground frame with the known slope; the height, the
contacts and the odometry are then those of flat ground in that frame. What the odometry does not model there:
gravity's pull down the slope, which makes the slipping contacts creep downhill (bench/RESULTS.md, "Gaits on
slopes").

What it cannot see: how the load is really spread over the contacts, and inertia. In MuJoCo the contact patches
of a gait slip by a few centimetres per cycle (friction 0.8); the friction balance follows most of that slip in
sidewinding, turning and the curl on the ground, no-slip odometry none of it (bench/RESULTS.md, "Gaits"); rolling,
whose contacts roll rather than slip, is the exception. The orientation is the IMU's.

:class:`BodyPoseEstimator` keeps that estimate; :class:`BodyPose` is a pose of the body (estimated or true) and
:func:`pose_error` compares two.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array, joint_vector, rotation_matrix
from ..dynamics.sliding import balance_translation
from ..geometry.shapes import shape_points
from ..ground_contact import RESTING_TOLERANCE
from ..locomotion.gaits import virtual_chassis
from ..model.placement import WORLD_FRAME, GroundFrame
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from ..sim.sensors import so3_exp

__all__ = ["CONTACT_HEIGHT", "PATCH_HEIGHT", "ODOMETRY", "BodyPose", "pose_error", "ShapePoints", "BodyPoseEstimator",
           "TILT_TIME_CONSTANT_S", "AttitudeFilter"]

#: A link whose lowest shape point is within this height (m) of the ground touches it: the planner's resting band.
CONTACT_HEIGHT = RESTING_TOLERANCE
#: A link's shape points within this height (m) of its lowest make its contact patch.
PATCH_HEIGHT = 0.001
#: How the estimate moves the body between updates (see the module).
ODOMETRY = ("friction", "no-slip")


@dataclass(frozen=True)
class BodyPose:
    """Where the body is.

    root: world pose (4, 4) of the root frame (the tail link's); chassis: world pose (4, 4) of the virtual chassis;
    body_in_root: the body frame in the root frame (:attr:`SnakeRobot.body_in_root`; identity for snakes written
    along x), so that :attr:`body` is the body frame's world pose, the frame ``BasePlacement`` places. "World" is
    the ground frame ``ground`` (:class:`~snakehead.model.placement.GroundFrame`): the world on flat ground, the
    slope's frame on a slope (:attr:`base` lies on it).
    """

    root: np.ndarray
    chassis: np.ndarray
    body_in_root: np.ndarray = field(default_factory=lambda: np.eye(4))
    ground: GroundFrame = WORLD_FRAME

    @property
    def body(self) -> np.ndarray:
        """World pose (4, 4) of the body frame (x along the body towards the head at q = 0, z up)."""
        return self.root @ self.body_in_root

    @property
    def base(self) -> BasePlacement:
        """The body frame's planar pose (x, y m; yaw rad of its x-axis seen from above), as the planner places
        the base."""
        B = self.body
        return BasePlacement(float(B[0, 3]), float(B[1, 3]), math.atan2(B[1, 0], B[0, 0]), self.ground)

    @property
    def heading(self) -> float:
        """Yaw (rad) of the virtual chassis' x-axis seen from above."""
        x = self.chassis[:3, 0]
        return math.atan2(x[1], x[0])

    @property
    def tilt_deg(self) -> float:
        """Angle (deg) between the body frame's z-axis and the ground's normal: 0 when the tail lies upright."""
        return math.degrees(math.acos(float(np.clip(self.body[2, 2], -1.0, 1.0))))


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def pose_error(estimate: BodyPose, truth: BodyPose) -> dict:
    """How far ``estimate`` is from ``truth``: ``position_error_m`` (the body frame's origin -- the base
    placement's -- in the ground plane), ``yaw_error_deg`` (the body frame's heading), ``chassis_position_error_m``
    (the virtual chassis' origin, 3-D), ``chassis_heading_error_deg``."""
    return {
        "position_error_m": float(np.linalg.norm(estimate.body[:2, 3] - truth.body[:2, 3])),
        "yaw_error_deg": abs(math.degrees(_wrap(estimate.base.yaw - truth.base.yaw))),
        "chassis_position_error_m": float(np.linalg.norm(estimate.chassis[:3, 3] - truth.chassis[:3, 3])),
        "chassis_heading_error_deg": abs(math.degrees(_wrap(estimate.heading - truth.heading))),
    }


class ShapePoints:
    """Points of the robot's collision shapes, fixed in their links: box corners, cylinder rims, the vertices of a
    sphere's and a hull's mesh (:func:`snakehead.geometry.shapes.shape_points`), for the links ``links`` (default
    the robot's shaped links), in contiguous runs per link. ``local`` (P, 3) in the link frames, ``link`` (P,) the
    position in ``links`` of each point's link, ``starts`` (k,) where each link's run begins; ``centres`` (k, 3)
    the middle of each link's shapes (the centre of their bounding box in the link frame; a box's centre)."""

    def __init__(self, robot: SnakeRobot, links: np.ndarray | None = None, segments: int = 16) -> None:
        self.links = np.asarray(robot.shaped_links if links is None else links, dtype=np.intp).reshape(-1)
        geometry = robot.geometry
        local, owner = [], []
        for c, link in enumerate(int(k) for k in self.links):
            for k in geometry.shapes_of([link]):
                pts = shape_points(geometry.shapes[int(k)], segments)
                local.append(pts)
                owner.append(np.full(len(pts), c))
        if not local:
            raise InputError("the robot has no collision shapes on these links")
        self.local = np.concatenate(local)
        self.link = np.concatenate(owner)
        self.starts = np.searchsorted(self.link, np.arange(len(self.links)))
        hi = np.maximum.reduceat(self.local, self.starts, axis=0)
        lo = np.minimum.reduceat(self.local, self.starts, axis=0)
        self.centres = 0.5 * (hi + lo)

    def world(self, frames: np.ndarray) -> np.ndarray:
        """The points (P, 3) for poses ``frames`` (k, 4, 4) of the links (world, or any common frame)."""
        F = frames[self.link]
        return np.einsum("pij,pj->pi", F[:, :3, :3], self.local) + F[:, :3, 3]

    def lowest(self, z: np.ndarray) -> np.ndarray:
        """Each link's lowest value (k,) of per-point heights ``z`` (P,)."""
        return np.minimum.reduceat(z, self.starts)

    def highest(self, z: np.ndarray) -> np.ndarray:
        """Each link's highest value (k,) of per-point heights ``z`` (P,)."""
        return np.maximum.reduceat(z, self.starts)

    def centre_points(self, frames: np.ndarray) -> np.ndarray:
        """The middle (k, 3) of each link's shapes for poses ``frames`` (k, 4, 4)."""
        return np.einsum("kij,kj->ki", frames[:, :3, :3], self.centres) + frames[:, :3, 3]


class BodyPoseEstimator:
    """The body's pose from joint angles and one link's orientation (see the module).

    robot: the snake; imu_link: the frame that carries the IMU (default: the shaped link nearest the middle of the
    body); contact_height / patch_height: m; odometry: one of ODOMETRY (see the module). Call :meth:`reset` with
    the known starting pose, then :meth:`update` at every control tick with the measured joint angles and the
    IMU's world orientation. ``ground``: the plane the body lies on (default flat ground); the IMU's orientation
    is always the world's (gravity's), the estimate is in ``ground`` (see the module).
    """

    def __init__(self, robot: SnakeRobot, imu_link: str | None = None, *, contact_height: float = CONTACT_HEIGHT,
                 patch_height: float = PATCH_HEIGHT, odometry: str = "friction",
                 ground: GroundFrame = WORLD_FRAME) -> None:
        self.robot = as_robot(robot)
        if not isinstance(ground, GroundFrame):
            raise InputError(f"ground must be a GroundFrame, got {type(ground).__name__}")
        self.ground = ground
        self._to_ground = None if ground.is_world else np.reshape(ground.rotation, (3, 3)).T
        shaped = self.robot.shaped_links
        self._body_in_root = self.robot.body_in_root
        if imu_link is None:
            F0 = np.linalg.inv(self._body_in_root) @ self.robot.body.fk_all(np.zeros(self.robot.n_joints))
            middle = F0[0, 0, 3] + 0.5 * self.robot.body_length  # along the straight body, in the body frame
            imu_link = self.robot.link_names[int(shaped[np.argmin(np.abs(F0[shaped, 0, 3] - middle))])]
        self.imu_link = imu_link
        self.imu_index = self.robot.link_index(imu_link)  # ValueError for a frame that is not on the body
        for name, value in (("contact_height", contact_height), ("patch_height", patch_height)):
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"{name} must be a positive number of metres, got {value!r}")
        self.contact_height = float(contact_height)
        self.patch_height = float(patch_height)
        if odometry not in ODOMETRY:
            raise InputError(f"odometry must be one of {ODOMETRY}, got {odometry!r}")
        self.odometry = odometry
        self._points = ShapePoints(self.robot, shaped)
        self._masses = self.robot.masses[shaped]
        self._W: np.ndarray | None = None  # link poses relative to the root origin, world axes, at the last update
        self._R_root: np.ndarray | None = None
        self._origin: np.ndarray | None = None  # the root frame's estimated world position
        self._chassis: Any = None
        self._contacts: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._heading_correction = np.eye(3)  # turns the IMU's heading (about the world's vertical) onto the known
        # one (set by reset)

    # --- the body in world axes, relative to the root origin --------------------------------------
    def _links(self, q: npt.ArrayLike, R_imu: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Shaped links' poses (k, 4, 4) relative to the root origin in ground axes, and the root's rotation in the
        ground frame (the IMU's world orientation, its heading corrected about the world's vertical, turned into the
        ground frame by the known slope)."""
        q = joint_vector(q, self.robot.n_joints)
        R_imu = self._heading_correction @ rotation_matrix(R_imu, "IMU orientation")
        if self._to_ground is not None:
            R_imu = self._to_ground @ R_imu
        F = self.robot.body.fk_all(q)  # in the root frame
        R_root = R_imu @ F[self.imu_index, :3, :3].T
        B = F[self._points.links]
        W = np.empty_like(B)
        W[:, :3, :3] = R_root @ B[:, :3, :3]
        W[:, :3, 3] = B[:, :3, 3] @ R_root.T
        W[:, 3] = (0.0, 0.0, 0.0, 1.0)
        return W, R_root

    def _contact_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The links that touch the ground: their positions in the shaped links (m,), contact points in their link
        frames (m, 3) and weights (m,) falling linearly from 1 on the ground to 0 at ``contact_height``."""
        P = self._points
        z = points[:, 2]
        low = P.lowest(z)  # relative to the root origin
        above = low - low.min()
        touching = np.flatnonzero(above < self.contact_height)
        patch = (above[P.link] < self.contact_height) & (z - low[P.link] <= self.patch_height)
        sums = np.zeros((len(P.links), 3))
        np.add.at(sums, P.link[patch], P.local[patch])
        counts = np.bincount(P.link[patch], minlength=len(P.links))
        local = sums[touching] / counts[touching, None]
        return touching, local, 1.0 - above[touching] / self.contact_height

    def _world_points(self, W: np.ndarray, links: np.ndarray, local: np.ndarray) -> np.ndarray:
        return np.einsum("mij,mj->mi", W[links, :3, :3], local) + W[links, :3, 3]

    def _remember(self, W: np.ndarray, R_root: np.ndarray, origin: np.ndarray, points: np.ndarray) -> None:
        self._W, self._R_root, self._origin = W, R_root, origin
        self._contacts = self._contact_points(points)

    def pose(self) -> BodyPose:
        """The estimated pose now."""
        if self._W is None:
            raise InputError("call reset() with the starting pose first")
        root = np.eye(4)
        root[:3, :3] = self._R_root
        root[:3, 3] = self._origin
        points = self._points.centre_points(self._W) + self._origin
        self._chassis = virtual_chassis(points, self._chassis, points[-1] - points[0])
        return BodyPose(root=root, chassis=self._chassis, body_in_root=self._body_in_root, ground=self.ground)

    # --- the estimate ----------------------------------------------------------------------------------
    def reset(self, q: np.ndarray, R_imu: npt.ArrayLike, body_xy: npt.ArrayLike, body_yaw: float | None = None) -> BodyPose:
        """Start from joint angles q (n,), the IMU's world orientation (3, 3) and the body frame's known planar
        position (x, y) m (a :class:`BasePlacement`'s x and y, in the estimator's ground frame); with ``body_yaw``
        (rad, the known heading of the body frame's x-axis: the placement's yaw), the IMU's heading is corrected
        onto it from now on (a gyro's heading is only relative: the correction turns about the world's vertical,
        the axis the attitude filter cannot see; on a slope it is found by a few fixed-point steps, the yaw in the
        ground frame being nearly the world's)."""
        body_xy = finite_array(body_xy, "body_xy", (2,))
        self._heading_correction = np.eye(3)
        if body_yaw is not None:
            want = float(finite_array(body_yaw, "body_yaw", ()))
            a = 0.0
            for _ in range(1 if self._to_ground is None else 8):
                _, R_root = self._links(q, R_imu)
                R_body = R_root @ self._body_in_root[:3, :3]
                step = _wrap(want - math.atan2(R_body[1, 0], R_body[0, 0])) if self._to_ground is not None else \
                    want - math.atan2(R_body[1, 0], R_body[0, 0])
                a += step
                self._heading_correction = np.array([[math.cos(a), -math.sin(a), 0.0],
                                                     [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
                if abs(step) < 1e-13:
                    break
        W, R_root = self._links(q, R_imu)
        points = self._points.world(W)
        offset = R_root @ self._body_in_root[:3, 3]  # the body frame's origin from the root's, world axes
        self._chassis = None
        self._remember(W, R_root, np.array([body_xy[0] - offset[0], body_xy[1] - offset[1], -points[:, 2].min()]),
                       points)
        return self.pose()

    def update(self, q: np.ndarray, R_imu: npt.ArrayLike) -> None:
        """The body moved to joint angles q (n,) with the IMU at world orientation R_imu (3, 3): move the estimate
        by the contact odometry (see the module; :meth:`pose` reads it)."""
        if self._W is None or self._contacts is None or self._origin is None:
            raise InputError("call reset() with the starting pose before update()")
        W, R_root = self._links(q, R_imu)
        points = self._points.world(W)
        links, local, weights = self._contacts
        origin = self._origin.copy()
        if links.size:
            shift = self._world_points(self._W, links, local) - self._world_points(W, links, local)
            if self.odometry == "friction":
                origin[:2] += balance_translation(shift[:, :2], weights * self._masses[links])
            else:
                origin[:2] += weights @ shift[:, :2] / weights.sum()
        origin[2] = -points[:, 2].min()
        self._remember(W, R_root, origin, points)


#: Time constant (s) with which the attitude filter pulls its tilt towards the accelerometer's gravity.
TILT_TIME_CONSTANT_S = 2.0


class AttitudeFilter:
    """The IMU link's world orientation from the IMU's streams alone (:class:`snakehead.sim.sensors.Imu`): the gyro
    integrated (R <- R exp(omega dt)), the tilt pulled towards the accelerometer's gravity with time constant
    ``tilt_time_constant_s`` (a complementary filter, Mahony et al., IEEE TAC 2008: omega + k a x R^T z). The
    heading has no reference: it drifts with the gyro's noise and bias (the estimator keeps it from the start's)."""

    def __init__(self, tilt_time_constant_s: float = TILT_TIME_CONSTANT_S) -> None:
        if not (np.isfinite(tilt_time_constant_s) and tilt_time_constant_s > 0):
            raise InputError(f"tilt_time_constant_s must be > 0, got {tilt_time_constant_s!r}")
        self.gain = 1.0 / float(tilt_time_constant_s)
        self.R = np.eye(3)

    def reset(self, accel: npt.ArrayLike, yaw: float = 0.0) -> np.ndarray:
        """Start level with the accelerometer's gravity ``accel`` (3,) (read at rest), heading ``yaw`` rad."""
        up = finite_array(accel, "accel", (3,))
        up = up / np.linalg.norm(up)  # the world's z in the IMU's axes: R^T z
        z = np.array([0.0, 0.0, 1.0])
        axis = np.cross(up, z)  # the rotation taking R^T z to z, in the IMU's axes: the tilt
        s, c = float(np.linalg.norm(axis)), float(up @ z)
        tilt = so3_exp(axis / s * math.atan2(s, c)) if s > 1e-12 else np.eye(3)
        Rz = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
        self.R = Rz @ tilt
        return self.R.copy()

    def update(self, gyro: npt.ArrayLike, accel: npt.ArrayLike, dt: float) -> np.ndarray:
        """One control period of ``dt`` s: the new orientation (3, 3)."""
        a = np.asarray(accel, float)
        norm = float(np.linalg.norm(a))
        w = np.asarray(gyro, float)
        if norm > 1e-9:
            w = w + self.gain * np.cross(a / norm, self.R[2])  # R^T z is R's third row
        self.R = self.R @ so3_exp(w * dt)
        return self.R.copy()
