"""Default gains and torque limits of the simulated servos, derived from each joint's load, so that a heavier or
longer snake tracks a plan as well as the default one does.

A joint's load (:func:`joint_gravity_torques`) is the gravity torque about its axis of everything beyond it held
straight out horizontally, tau_j = g sum_i m_i r_ij (r_ij the distance of link i's centre of mass from the axis,
body straight at q = 0). It bounds what the joint holds: a lifted neck and head, or the moment that a raised head
part sends through the base; on the ground, friction loads are this times the friction coefficient.

Gains (:func:`default_gains`), per joint:

    kp_j = max(tau_j / HOLD_DEFLECTION, armature / TIME_CONSTANT^2)      kd_j = TIME_CONSTANT kp_j

* stiffness: the joint's whole load would deflect it by at most 1 deg (the gravity compensation carries the
  known part of it; the PD part holds what the compensation misses);
* damping: every joint corrects an error with the same 15 ms time constant (kd / kp), whatever its size;
* at least stiff enough to move its own rotor with that time constant (the light head joints, whose loads are
  tiny).

With the damping integrated implicitly (MuJoCo's ``implicitfast``) the loop is stable at any kp when
kd / kp > timestep / 2, so the rule holds for any robot. Where the constants come from: uniform gains of
kp = 200 N m/rad and kd = 3 N m s/rad suit the default robot; 1 deg gives 207 N m/rad at its joint 10 (the head
part's first joint, the one that lifts it), and 15 ms is their kd / kp. On the default robot the rule gives kp from
4.4 N m/rad (joint 16) to 1170 N m/rad (joint 1). Why not uniform gains, nor softer head joints: bench/RESULTS.md.

Torque limits (:func:`default_torque_limits`): the URDF's effort where it gives one (the robot's servos), else
EFFORT_MARGIN x tau_j (the joint's load, with half again to accelerate it).
"""
from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import finite_array
from ..model.physics import GRAVITY
from ..model.robot import SnakeRobot, as_robot

__all__ = ["HOLD_DEFLECTION", "TIME_CONSTANT", "EFFORT_MARGIN", "gain_vector", "joint_gravity_torques", "default_gains",
           "default_torque_limits"]

#: How far a joint may give under its whole load (rad).
HOLD_DEFLECTION = math.radians(1.0)
#: The time constant kd / kp of every joint's loop (s).
TIME_CONSTANT = 0.015
#: Torque limit (x the joint's load) for joints whose URDF gives no effort.
EFFORT_MARGIN = 1.5


def gain_vector(x: npt.ArrayLike, n: int, name: str, allow_zero: bool) -> np.ndarray:
    """A gain given as a number or per joint, as (n,): finite, > 0 (>= 0 with ``allow_zero``, for a damping);
    InputError naming ``name`` otherwise."""
    a = finite_array(x, name)
    if a.ndim == 0:
        a = np.full(n, float(a))
    elif a.shape != (n,):
        raise InputError(f"{name} must be a number or shape ({n},), got shape {a.shape}")
    if np.any(a < 0) or (not allow_zero and np.any(a <= 0)):
        raise InputError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {a.tolist()}")
    return a


def joint_gravity_torques(robot: SnakeRobot) -> np.ndarray:
    """(n,) N m: for each joint, the gravity torque about its axis of every link beyond it, the body held straight
    out horizontally (q = 0): g sum_i m_i r_ij, r_ij the distance of link i's centre of mass from the axis."""
    robot = as_robot(robot)
    n = robot.n_joints
    F = np.linalg.inv(robot.body_in_root) @ robot.body.fk_all(np.zeros(n))  # frames in the body frame (joint_axes')
    child = np.asarray(robot.body.model.joint_child_links, int)
    masses = np.asarray(robot.masses, float)
    com = np.einsum("lij,lj->li", F[:, :3, :3], robot.coms) + F[:, :3, 3]
    tau = np.zeros(n)
    for j, c in enumerate(child):
        a = robot.joint_axes[j]
        r = com[c:] - F[c, :3, 3]
        lever = np.linalg.norm(r - np.outer(r @ a, a), axis=1)  # distance of each centre of mass from the axis
        tau[j] = GRAVITY * np.sum(masses[c:] * lever)
    return tau


def default_gains(robot: SnakeRobot, *, armature: float) -> tuple[np.ndarray, np.ndarray]:
    """kp (N m/rad) and kd (N m s/rad), (n,) each, for the robot's joints with servos of rotor inertia
    ``armature`` (kg m^2); the rule is in the module's docstring. ValueError for a joint that has neither a load
    nor a rotor to derive its gains from."""
    tau = joint_gravity_torques(robot)
    kp = np.maximum(tau / HOLD_DEFLECTION, float(armature) / TIME_CONSTANT**2)
    if np.any(kp <= 0):
        names = [robot.joint_names[j] for j in np.flatnonzero(kp <= 0)]
        raise InputError(f"joints {names} carry no mass and have no rotor (armature 0): their gains cannot be derived "
                         "from a load; give kp and kd")
    return kp, TIME_CONSTANT * kp


def default_torque_limits(robot: SnakeRobot) -> np.ndarray:
    """(n,) N m: the URDF's effort where it gives one, else EFFORT_MARGIN x the joint's gravity torque."""
    robot = as_robot(robot)
    effort = np.asarray(robot.effort, float)
    if np.all(effort > 0):
        return effort.copy()
    derived = EFFORT_MARGIN * joint_gravity_torques(robot)
    return np.where(effort > 0, effort, derived)
