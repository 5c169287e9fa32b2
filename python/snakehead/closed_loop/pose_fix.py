"""The outside measurement that can close the loop instead of the robot's own senses (``sensing="outside fix"`` of
:class:`snakehead.closed_loop.loop.ClosedLoop`): the pose of the neck's base frame, the paper's P0 ("the pose of
the base frame of the neck part is obtained in time"), as a motion-capture system would give it, with noise.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import InputError
from .._validate import finite_float
from ..sim.mjcf import in_ground
from .estimate import BodyPose
from .gait_runner import GaitSimulator

__all__ = ["PoseFix"]


@dataclass(frozen=True)
class PoseFix:
    """The outside measurement that closes the loop (see the module): the world pose of one frame of the body,
    ``frame`` (default the neck's base frame, ``robot.parts.base_end``), in the ground plane (x, y and heading; on a
    slope the slope's plane, in its ground frame), with Gaussian noise of ``position_noise_m`` (m, per axis) and ``yaw_noise_deg`` (deg); ``seed`` for the noise."""

    frame: str | None = None
    position_noise_m: float = 0.0005
    yaw_noise_deg: float = 0.05
    seed: int | None = 0

    def __post_init__(self) -> None:
        for name in ("position_noise_m", "yaw_noise_deg"):
            v = finite_float(getattr(self, name), name)
            if v < 0:
                raise InputError(f"{name} must be >= 0, got {v!r}")
            object.__setattr__(self, name, v)

    def measure(self, simulator: GaitSimulator, rng: np.random.Generator) -> BodyPose:
        """The body's pose from the measured frame, the joint angles (encoders) and the IMU, as the estimator
        represents it."""
        robot = simulator.robot
        k = robot.link_index(self.frame or robot.parts.base_end)
        data = simulator.data
        body = simulator.sim.body_ids[k]
        W = np.eye(4)
        W[:3, :3], W[:3, 3] = data.xmat[body].reshape(3, 3), data.xpos[body]
        W = in_ground(simulator.ground, W)  # the frame in the ground frame (the world's on flat ground)
        R = W[:3, :3]
        p = W[:3, 3].copy()
        p[:2] += rng.normal(0.0, self.position_noise_m, 2)
        a = math.radians(rng.normal(0.0, self.yaw_noise_deg)) if self.yaw_noise_deg > 0 else 0.0
        Rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = Rz @ R, p
        q = simulator.joint_angles()
        body = T @ np.linalg.inv(robot.body.fk_all(q)[k]) @ robot.body_in_root  # the body frame's (ground frame)
        yaw = math.atan2(body[1, 0], body[0, 0])
        return simulator.estimator.reset(q, simulator.imu_orientation(), body[:2, 3], yaw)
