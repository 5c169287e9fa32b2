"""The head's final approach closed on the head camera (:class:`snakehead.sim.sensors.HeadSensor`): what the loop
does with a measurement of a target relative to the head, so that the head's accuracy does not depend on where the
body believes it is.

* :func:`root_from_head_reading` -- the fix: a marker at a known world pose seen from the head, with the joint
  angles (encoders), gives the root frame's world pose: T_root = T_marker (T_head<-marker)^-1 (T_root<-head)^-1.
* :func:`head_error` -- how far the head tip is from a target measured in the head's own frame (mm and deg: the
  position of the target's origin and the angle between the head's x-axis and the target's).
* :func:`servo_step` -- the joint correction of the head chain (the neck's lifting joints and the head's,
  :attr:`~snakehead.model.robot.SnakeRobot.lift_joints`: the base's joints stay, so the body's support does not
  change) that removes a measured error to first order: damped least squares on the head tip's Jacobian in its own
  frame (position, and the rotation about the head's y and z axes: the roll about its own axis is free), computed
  by finite differences of the forward kinematics. Iterated on fresh measurements it converges to the camera's
  noise: visual servoing with the camera on the end effector (Chaumette and Hutchinson, IEEE RAM 2006, position-based).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..model.robot import SnakeRobot
from ..sim.sensors import HeadReading, mean_pose, so3_log

__all__ = ["HEAD_FRAMES", "SERVO_POSITION_TOL_M", "SERVO_DIRECTION_TOL_DEG", "SERVO_ITERATIONS", "SERVO_MAX_POSITION_M",
           "SERVO_MAX_DIRECTION_DEG", "SERVO_MOVE_S", "SERVO_HOLD_S", "SERVO_DAMPING", "DIRECTION_WEIGHT_M",
           "JACOBIAN_STEP", "servo_joints", "root_from_head_reading", "head_error", "head_jacobian", "servo_step"]

#: Frames of the head camera averaged per measurement (a 30 Hz camera for under a second).
HEAD_FRAMES = 25
#: The final approach stops when the measured error is below these (m, deg), or after SERVO_ITERATIONS moves: about
#: twice the averaged measurement's own noise (HEAD_POSITION_NOISE_M / 5 per axis, HEAD_DIRECTION_NOISE_DEG / 5
#: per axis), below which a correction chases the noise.
SERVO_POSITION_TOL_M = 0.0008
SERVO_DIRECTION_TOL_DEG = 0.3
SERVO_ITERATIONS = 4
#: A measured error beyond these (m, deg) is not the final approach's to correct (a first-order step of the head
#: chain alone would swing the body): the loop reports it instead.
SERVO_MAX_POSITION_M = 0.03
SERVO_MAX_DIRECTION_DEG = 5.0
#: Each correction: a move of SERVO_MOVE_S, then SERVO_HOLD_S still before the next look (s).
SERVO_MOVE_S = 0.6
SERVO_HOLD_S = 0.6
#: Damping of the least squares (m): keeps a correction small where the head chain is near a singularity.
SERVO_DAMPING = 1e-3
#: Weight of the direction rows against the position rows (m per rad: a radian of direction weighs as 0.1 m).
DIRECTION_WEIGHT_M = 0.1
#: Finite-difference step of the Jacobian (rad).
JACOBIAN_STEP = 1e-6


def servo_joints(robot: SnakeRobot) -> np.ndarray:
    """The joints the final approach moves: the neck's lifting joints and the head's."""
    lift, head = robot.lift_joints, robot.parts.head
    return np.r_[np.arange(lift.start, lift.stop), np.arange(head.start, head.stop)].astype(np.intp)


def root_from_head_reading(robot: SnakeRobot, readings: Sequence[HeadReading], marker: np.ndarray,
                           q: np.ndarray) -> np.ndarray:
    """The root frame's world pose (4, 4) from camera frames of one marker (world pose ``marker`` (4, 4)) taken
    with the joints at ``q`` (n,) (the encoders' reading)."""
    head_to_marker = mean_pose([r.pose for r in readings])
    head_in_root = robot.body.fk_all(q)[robot.link_index(robot.parts.head_tip)]
    return marker @ np.linalg.inv(head_to_marker) @ np.linalg.inv(head_in_root)


def head_error(target_in_head: np.ndarray) -> tuple[float, float]:
    """(m, deg): the target's distance from the head tip and the angle between their x-axes, from the target's
    pose (4, 4) in the head tip frame."""
    x = target_in_head[:3, 0]
    return float(np.linalg.norm(target_in_head[:3, 3])), math.degrees(math.acos(float(np.clip(x[0], -1.0, 1.0))))


def _head_twist(target_in_head: np.ndarray) -> np.ndarray:
    """The error (5,): the target's position in the head frame, and the rotation about the head's y and z axes
    that turns its x-axis onto the target's (x cross x_target; its x-component is 0)."""
    x = target_in_head[:3, 0]
    w = np.cross([1.0, 0.0, 0.0], x)
    angle = math.atan2(float(np.linalg.norm(w)), float(x[0]))
    axis = w / np.linalg.norm(w) * angle if angle > 1e-12 else w
    return np.r_[target_in_head[:3, 3], DIRECTION_WEIGHT_M * axis[1:]]


def head_jacobian(robot: SnakeRobot, q: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """(5, m): how the head tip moves in its own frame per radian of each of ``joints`` at ``q``: position (3)
    and the rotation about its y and z axes (weighted by DIRECTION_WEIGHT_M), by central differences."""
    k = robot.link_index(robot.parts.head_tip)
    T0 = robot.body.fk_all(q)[k]
    J = np.zeros((5, len(joints)))
    for c, j in enumerate(joints):
        dq = np.zeros_like(q)
        dq[j] = JACOBIAN_STEP
        plus = np.linalg.solve(T0, robot.body.fk_all(q + dq)[k])
        minus = np.linalg.solve(T0, robot.body.fk_all(q - dq)[k])
        dp = (plus[:3, 3] - minus[:3, 3]) / (2 * JACOBIAN_STEP)
        dw = (so3_log(plus[:3, :3]) - so3_log(minus[:3, :3])) / (2 * JACOBIAN_STEP)
        J[:, c] = np.r_[dp, DIRECTION_WEIGHT_M * dw[1:]]
    return J


def servo_step(robot: SnakeRobot, q: np.ndarray, target_in_head: np.ndarray,
               joints: np.ndarray | None = None) -> np.ndarray:
    """The joint correction (n,) that brings the head tip onto the target measured at ``target_in_head`` (4, 4) in
    the head tip frame, the joints at ``q`` (n,), moving only ``joints`` (default :func:`servo_joints`):
    dq = J^T (J J^T + lambda^2 I)^-1 e."""
    joints = servo_joints(robot) if joints is None else np.asarray(joints, np.intp)
    J = head_jacobian(robot, q, joints)
    e = _head_twist(target_in_head)
    dq = np.zeros_like(q)
    dq[joints] = J.T @ np.linalg.solve(J @ J.T + SERVO_DAMPING ** 2 * np.eye(5), e)
    return dq
