"""How a backbone curve becomes joint angles: paper Eqs. 3-6 on a snake with yaw and pitch joints.

* :func:`joint_intervals` -- the arc-length interval [s1, s2] of Eqs. 5-6 that each joint integrates.
* :func:`discretize` -- Eqs. 3-6: the bending angle of each joint.
* :func:`curve_joint_angles` -- the URDF joint angles that lay a part of the robot along a curve.

Where the joints sit along the body and which way they bend come from the robot model
(:attr:`snakehead.SnakeRobot.joint_arc_lengths`, :attr:`~snakehead.SnakeRobot.joint_kinds`,
:attr:`~snakehead.SnakeRobot.joint_signs`).

Conventions
-----------
SI units (m, rad). Arc length ``s`` of a curve is measured from the curve's start. A joint's *body arc
length* is its distance from the tail end along the straight body (q = 0). The discretisation's body frame
at arc length s is (x, y, z) = (T, M1, M2): T the unit tangent, and (M1, M2) the normal plane's axes that
the phase of Eq. 3 is measured from, so that the Frenet normal is N = cos(phi) M1 + sin(phi) M2.
Then kappa_y = kappa cos(phi) is the bending about the body's z-axis (towards +y) and kappa_p =
kappa sin(phi) the bending about its y-axis (towards +z). (M1, M2) is the rotation-minimising (Bishop)
frame: d phi / ds = tau is exactly Eq. 3.

Joint signs. The URDF's yaw joints turn about the local +z axis, so a yaw joint's angle is +theta_y
(Eq. 5; positive turns the body left, towards +y). The pitch joints turn about the local +y axis, and a
positive rotation about +y turns the body's x-axis towards -z (down); bending towards +z (kappa_p > 0,
Eq. 6) is therefore the joint angle -theta_p. Joints whose axis is -z or -y flip sign accordingly.

Joint intervals (the mapping of Eqs. 5-6 onto an alternating yaw/pitch snake)
-----------------------------------------------------------------------------
A yaw joint can only make yaw bending and a pitch joint only pitch bending, so each kind of joint must
carry *all* the bending of its kind: the yaw joints' intervals tile the curve, and so do the pitch joints'.
Joint i (at arc length s_i on the curve) takes the interval [s1, s2] of Eqs. 5-6 bounded by the midpoints
between it and the previous / next joint *of the same kind*; the first joint of a kind starts its
interval at the curve's start and the last one ends it at the curve's end. For an alternating snake with
equal modules the midpoint between two yaw joints is the pitch joint between them, so a yaw joint takes
the yaw bending from the pitch joint before it to the pitch joint after it (2 module lengths, centred on
the joint) and a pitch joint the pitch bending between its two yaw neighbours. On the default robot the
base's yaw joints 1, 3, 5, 7 take [0, s_2], [s_2, s_4], [s_4, s_6], [s_6, P0]; the neck's pitch joint 8
sits exactly at P0 and starts the up curve's pitch intervals. The sum of the yaw angles is therefore the
total yaw bending of the curve (for the plane arc: its central angle), so the last link leaves along the
curve's end tangent when the first lies along its start tangent.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import finite_array, finite_float, positive
from ..model.robot import PITCH, YAW, SnakeRobot, as_robot
from .curves import SpaceCurve

__all__ = ["curve_joint_angles", "discretize", "joint_intervals"]


def joint_intervals(s_joints: npt.ArrayLike, kinds: Sequence[str], curve_length: float) -> np.ndarray:
    """The [s1, s2] of Eqs. 5-6 for each joint (see the module notes, "Joint intervals"): (m, 2) m.

    s_joints (m,) arc lengths of the joints on the curve (increasing, within [0, curve_length]);
    kinds (m,) ``"yaw"``/``"pitch"``. A joint's interval runs from the midpoint with the previous joint of
    its kind (or the curve's start) to the midpoint with the next one (or the curve's end).
    """
    s = finite_array(s_joints, "s_joints", (None,))
    L = positive(curve_length, "curve_length")
    if len(kinds) != len(s):
        raise InputError(f"kinds has {len(kinds)} entries for {len(s)} joints")
    if np.any(np.diff(s) <= 0) or s[0] < -1e-12 or s[-1] > L + 1e-12:
        raise InputError(f"joint arc lengths must increase within [0, {L:.6g}] m, got {s.tolist()}")
    out = np.empty((len(s), 2))
    for kind in set(kinds):
        if kind not in (YAW, PITCH):
            raise InputError(f"joint kind must be 'yaw' or 'pitch', got {kind!r}")
        idx = [i for i, k in enumerate(kinds) if k == kind]
        sk = s[idx]
        mids = 0.5 * (sk[1:] + sk[:-1])
        out[idx, 0] = np.concatenate([[0.0], mids])
        out[idx, 1] = np.concatenate([mids, [L]])
    return out


def discretize(curve: SpaceCurve, s_joints: np.ndarray, kinds: Sequence[str], *, phi0: float = 0.0,
               end: float | None = None) -> np.ndarray:
    """Eqs. 3-6: the bending angle theta (rad) of each joint, theta_y for yaw joints and theta_p for pitch
    joints, integrated over :func:`joint_intervals` of the stretch [0, end] of the curve (default: all of
    it; m). s_joints (m,) arc lengths on the curve (m), kinds (m,) "yaw"/"pitch", phi0 the phase at s = 0.
    Returns (m,) in the curve's sign convention (URDF joint angles: :func:`curve_joint_angles`)."""
    if not isinstance(curve, SpaceCurve):
        raise InputTypeError(f"curve must be a SpaceCurve, got {type(curve).__name__}")
    end = curve.length if end is None else min(positive(end, "end"), curve.length)
    iv = joint_intervals(s_joints, kinds, end)
    ty, tp = curve.bending(iv[:, 0], iv[:, 1], phi0=phi0)
    return np.where(np.array(kinds) == YAW, ty, tp)


def curve_joint_angles(robot: SnakeRobot, curve: SpaceCurve, joints: slice, *, s_start: float | None = None,
                       phi0: float | None = None, frame0: npt.ArrayLike | None = None) -> np.ndarray:
    """URDF joint angles (rad) of ``robot.joints[joints]`` that lay the body along ``curve``.

    Parameters
    ----------
    robot : the snake.
    curve : the backbone; its start (s = 0) lies at body arc length ``s_start``.
    joints : slice into the joint vector, e.g. ``robot.parts.base``.
    s_start : body arc length (m) where the curve starts; default: the tail end (0) for a slice starting
        at joint 0, else the position of the slice's first joint.
    phi0 / frame0 : the phase at the curve's start, either directly (rad) or from the body frame's rotation
        (3, 3) there (see :meth:`SpaceCurve.initial_phase`); default 0 (the curve's normal along the body's y).

    Returns (len(joints),) joint angles: +theta_y (Eq. 5) at +z yaw joints, -theta_p (Eq. 6) at +y pitch
    joints, over the intervals of :func:`joint_intervals` on the part's stretch of the curve: from its start
    to the first joint after the slice (or the body's last frame); a longer curve is cut there. Raises
    ValueError if the curve is too short for the joints, or both phi0 and frame0 are given.
    """
    if not isinstance(curve, SpaceCurve):
        raise InputTypeError(f"curve must be a SpaceCurve, got {type(curve).__name__}")
    robot = as_robot(robot)
    s_joint, body_kinds = robot.joint_arc_lengths, robot.joint_kinds
    idx = np.arange(robot.n_joints)[joints]
    if len(idx) == 0:
        raise InputError("joints selects no joint")
    if s_start is None:
        s_start = 0.0 if idx[0] == 0 else float(s_joint[idx[0]])
    s_start = finite_float(s_start, "s_start")
    if phi0 is not None and frame0 is not None:
        raise InputError("give phi0 or frame0, not both")
    if frame0 is not None:
        phi0 = curve.initial_phase(np.asarray(frame0, dtype=np.float64)[:3, :3])
    phi0 = 0.0 if phi0 is None else finite_float(phi0, "phi0")
    s_on = s_joint[idx] - s_start
    if s_on[0] < -1e-12:
        raise InputError(f"the curve starts at body arc length {s_start:.6g} m, after the first joint")
    if s_on[-1] > curve.length + 1e-12:
        raise InputError(f"the curve ({curve.length:.6g} m) is shorter than the body it must cover "
                         f"({s_on[-1]:.6g} m to the last joint)")
    # the part ends where the next joint begins (or at the body's last frame); a longer curve is cut there
    part_end = (s_joint[idx[-1] + 1] if idx[-1] + 1 < robot.n_joints else robot.body_length) - s_start
    kinds = [body_kinds[i] for i in idx]
    theta = discretize(curve, np.maximum(s_on, 0.0), kinds, phi0=phi0, end=part_end)
    sign = np.where(np.array(kinds) == YAW, 1.0, -1.0) * robot.joint_signs[idx]
    return sign * theta
