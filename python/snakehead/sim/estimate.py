"""Where the body is, estimated from the body itself as a robot would: its joint angles (encoders) and the
orientation of one link (an IMU's attitude), never the simulator's positions.

* Orientation: the IMU link's world orientation and the joint angles give every link's orientation (forward
  kinematics from the IMU link).
* Shape: the body's points (each box's centre) in world axes, relative to the root frame's origin.
* Height: the body rests on the ground, so its lowest box corner is at z = 0.
* Planar position, by contact odometry: the boxes that touch the ground (their lowest corner within
  ``contact_height`` of it) hold it through their contact points -- the middle of a box's corners that are
  lowest, a material point of the box. Between two updates the body is moved by the translation that balances
  the friction of those contact points (``odometry="friction"``, the default: the weighted geometric median of
  the shifts that would keep each still, loads the links' masses, :func:`snakehead.dynamics.sliding.
  balance_translation`; contacts slip where the others outpull them, and stay put where they hold), or by the
  average of those shifts (``odometry="no-slip"``: every contact assumed not to slip).
* The virtual chassis (:func:`snakehead.motion.gaits.virtual_chassis`, after Rollinson and Choset, "Virtual
  Chassis for Snake Robots", IROS 2011): a frame at the centroid of the body's points whose x-axis is the principal
  axis of the shape (its direction kept from update to update, towards the head when the body is straight) and
  z-axis the third principal axis turned upwards. It moves smoothly while a gait's joints cycle, so it says where
  "the body" is better than any one link.

What it cannot see: how the load is really spread over the contacts, and inertia. In MuJoCo the contact patches
of a gait slip by a few centimetres per cycle (friction 0.8); the friction balance follows most of that slip in
sidewinding, turning and the curl on the ground, no-slip odometry none of it (bench/RESULTS.md, "Gaits"); rolling,
whose contacts roll rather than slip, is the exception. The orientation is the IMU's.

:class:`BodyPoseEstimator` keeps that estimate; :class:`BodyPose` is a pose of the body (estimated or true) and
:func:`pose_error` compares two.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import finite_array, joint_vector, rotation_matrix
from ..dynamics.sliding import balance_translation
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from ..motion.gaits import virtual_chassis

import numpy.typing as npt

#: A box whose lowest corner is within this height (m) of the ground touches it.
CONTACT_HEIGHT = 0.003
#: Corners within this height (m) of a box's lowest corner make its contact patch.
PATCH_HEIGHT = 0.001
#: How the estimate moves the body between updates (see the module).
ODOMETRY = ("friction", "no-slip")


@dataclass(frozen=True)
class BodyPose:
    """Where the body is.

    root: world pose (4, 4) of the root frame (the tail link's; ``BasePlacement``'s frame);
    chassis: world pose (4, 4) of the virtual chassis.
    """

    root: np.ndarray
    chassis: np.ndarray

    @property
    def base(self) -> BasePlacement:
        """The root frame's planar pose (x, y m; yaw rad of its x-axis seen from above), as the planner places
        the base."""
        x = self.root[:3, 0]
        return BasePlacement(float(self.root[0, 3]), float(self.root[1, 3]), math.atan2(x[1], x[0]))

    @property
    def heading(self) -> float:
        """Yaw (rad) of the virtual chassis' x-axis seen from above."""
        x = self.chassis[:3, 0]
        return math.atan2(x[1], x[0])

    @property
    def tilt_deg(self) -> float:
        """Angle (deg) between the root frame's z-axis and the world's: 0 when the tail lies upright."""
        return math.degrees(math.acos(float(np.clip(self.root[2, 2], -1.0, 1.0))))


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def pose_error(estimate: BodyPose, truth: BodyPose) -> dict:
    """How far ``estimate`` is from ``truth``: ``position_error_m`` (the root frame's origin, in the ground
    plane), ``yaw_error_deg`` (the root frame's heading), ``chassis_position_error_m`` (the virtual chassis'
    origin, 3-D), ``chassis_heading_error_deg``."""
    return {
        "position_error_m": float(np.linalg.norm(estimate.root[:2, 3] - truth.root[:2, 3])),
        "yaw_error_deg": abs(math.degrees(_wrap(estimate.base.yaw - truth.base.yaw))),
        "chassis_position_error_m": float(np.linalg.norm(estimate.chassis[:3, 3] - truth.chassis[:3, 3])),
        "chassis_heading_error_deg": abs(math.degrees(_wrap(estimate.heading - truth.heading))),
    }


class BodyPoseEstimator:
    """The body's pose from joint angles and one link's orientation (see the module).

    robot: the snake; imu_link: the frame that carries the IMU (default: the boxed link nearest the middle of the
    body); contact_height / patch_height: m; odometry: one of ODOMETRY (see the module). Call :meth:`reset` with
    the known starting pose, then :meth:`update` at every control tick with the measured joint angles and the
    IMU's world orientation.
    """

    def __init__(self, robot: SnakeRobot, imu_link: str | None = None, *, contact_height: float = CONTACT_HEIGHT,
                 patch_height: float = PATCH_HEIGHT, odometry: str = "friction") -> None:
        self.robot = as_robot(robot)
        boxed = self.robot.boxed_links
        if imu_link is None:
            F0 = self.robot.body.fk_all(np.zeros(self.robot.n_joints))
            middle = 0.5 * self.robot.body_length
            imu_link = self.robot.link_names[int(boxed[np.argmin(np.abs(F0[boxed, 0, 3] - middle))])]
        self.imu_link = imu_link
        self.imu_index = self.robot.link_index(imu_link)  # ValueError for a frame that is not on the body
        for name, value in (("contact_height", contact_height), ("patch_height", patch_height)):
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number of metres, got {value!r}")
        self.contact_height = float(contact_height)
        self.patch_height = float(patch_height)
        if odometry not in ODOMETRY:
            raise ValueError(f"odometry must be one of {ODOMETRY}, got {odometry!r}")
        self.odometry = odometry
        self._masses = self.robot.masses[boxed]
        self._boxed = boxed
        self._half = 0.5 * self.robot.box_sizes[boxed]  # (k, 3)
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
        self._corners_local = signs[None, :, :] * self._half[:, None, :]  # (k, 8, 3) in each box's frame
        self._W = None  # box poses relative to the root origin, world axes, at the last update
        self._R_root = None
        self._origin = None  # the root frame's estimated world position
        self._chassis = None
        self._contacts = None
        self._heading_correction = np.eye(3)  # turns the IMU's heading onto the known one (set by reset)

    # --- the body in world axes, relative to the root origin --------------------------------------
    def _boxes(self, q: npt.ArrayLike, R_imu: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Box poses (k, 4, 4) relative to the root origin in world axes, and the root's world rotation."""
        q = joint_vector(q, self.robot.n_joints)
        R_imu = self._heading_correction @ rotation_matrix(R_imu, "IMU orientation")
        F = self.robot.body.fk_all(q)  # in the root frame
        R_root = R_imu @ F[self.imu_index, :3, :3].T
        B = F[self._boxed] @ self.robot.box_origins[self._boxed]
        W = np.empty_like(B)
        W[:, :3, :3] = R_root @ B[:, :3, :3]
        W[:, :3, 3] = B[:, :3, 3] @ R_root.T
        W[:, 3] = (0.0, 0.0, 0.0, 1.0)
        return W, R_root

    def _corners(self, W: np.ndarray) -> np.ndarray:
        return np.einsum("kij,kcj->kci", W[:, :3, :3], self._corners_local) + W[:, None, :3, 3]  # (k, 8, 3)

    def _contact_points(self, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The boxes that touch the ground: their indices (m,), contact points in their box frames (m, 3) and
        weights (m,) falling linearly from 1 on the ground to 0 at ``contact_height``."""
        low = corners[..., 2].min(axis=1)  # relative to the root origin
        above = low - low.min()
        touching = np.flatnonzero(above < self.contact_height)
        patch = corners[touching, :, 2] - low[touching, None] <= self.patch_height  # (m, 8)
        local = np.einsum("mc,mcj->mj", patch, self._corners_local[touching]) / patch.sum(axis=1)[:, None]
        return touching, local, 1.0 - above[touching] / self.contact_height

    def _world_points(self, W: np.ndarray, boxes: np.ndarray, local: np.ndarray) -> np.ndarray:
        return np.einsum("mij,mj->mi", W[boxes, :3, :3], local) + W[boxes, :3, 3]

    def _remember(self, W: np.ndarray, R_root: np.ndarray, origin: np.ndarray, corners: np.ndarray) -> None:
        self._W, self._R_root, self._origin = W, R_root, origin
        self._contacts = self._contact_points(corners)

    def pose(self) -> BodyPose:
        """The estimated pose now."""
        if self._W is None:
            raise RuntimeError("call reset() with the starting pose first")
        root = np.eye(4)
        root[:3, :3] = self._R_root
        root[:3, 3] = self._origin
        points = self._W[:, :3, 3] + self._origin
        self._chassis = virtual_chassis(points, self._chassis, points[-1] - points[0])
        return BodyPose(root=root, chassis=self._chassis)

    # --- the estimate ----------------------------------------------------------------------------------
    def reset(self, q: np.ndarray, R_imu: npt.ArrayLike, root_xy: npt.ArrayLike, root_yaw: float | None = None) -> BodyPose:
        """Start from joint angles q (n,), the IMU's world orientation (3, 3) and the root frame's known planar
        position (x, y) m; with ``root_yaw`` (rad, the known heading of the root frame's x-axis), the IMU's heading
        is corrected onto it from now on (a gyro's heading is only relative)."""
        root_xy = finite_array(root_xy, "root_xy", (2,))
        self._heading_correction = np.eye(3)
        if root_yaw is not None:
            _, R_root = self._boxes(q, R_imu)
            a = float(finite_array(root_yaw, "root_yaw", ())) - math.atan2(R_root[1, 0], R_root[0, 0])
            self._heading_correction = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0],
                                                 [0.0, 0.0, 1.0]])
        W, R_root = self._boxes(q, R_imu)
        corners = self._corners(W)
        self._chassis = None
        self._remember(W, R_root, np.array([root_xy[0], root_xy[1], -corners[..., 2].min()]), corners)
        return self.pose()

    def update(self, q: np.ndarray, R_imu: npt.ArrayLike) -> None:
        """The body moved to joint angles q (n,) with the IMU at world orientation R_imu (3, 3): move the estimate
        by the contact odometry (see the module; :meth:`pose` reads it)."""
        if self._W is None:
            raise RuntimeError("call reset() with the starting pose before update()")
        W, R_root = self._boxes(q, R_imu)
        corners = self._corners(W)
        boxes, local, weights = self._contacts
        origin = self._origin.copy()
        if boxes.size:
            shift = self._world_points(self._W, boxes, local) - self._world_points(W, boxes, local)
            if self.odometry == "friction":
                origin[:2] += balance_translation(shift[:, :2], weights * self._masses[boxes])
            else:
                origin[:2] += weights @ shift[:, :2] / weights.sum()
        origin[2] = -corners[..., 2].min()
        self._remember(W, R_root, origin, corners)
