"""The limits a retimed motion keeps (:class:`RetimingLimits`) and their defaults: per joint velocity, acceleration
and torque, the ZMP's margin inside the support polygon, the friction the ground gives the base.

:func:`resolve_limits` turns :func:`~snakehead.retiming.timing.retime`'s keywords into them: a number or one value
per joint, defaults from the URDF (a share of its velocity and effort limits) where the caller gives none.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import finite_float, positive
from ..margins import ZMP_MARGIN
from ..model.physics import GROUND_FRICTION
from ..model.robot import SnakeRobot, as_robot

__all__ = ["VELOCITY_SHARE", "ACCELERATION_LIMIT", "TORQUE_SHARE", "FRICTION", "RetimingLimits", "resolve_limits"]

#: Share of the URDF's joint velocity limits used by default.
VELOCITY_SHARE = 0.5
#: rad/s^2: joint acceleration limit by default (URDFs give none): the paper's scenarios keep their durations and
#: the simulated ZMP stays inside the base's polygon (bench/timing.py sweeps it).
ACCELERATION_LIMIT = 2.0
#: Share of the URDF's joint effort limits used by default: room for the PD controller's corrections.
TORQUE_SHARE = 0.8
#: Friction coefficient the retiming allows the base by default: half the simulated ground's (GROUND_FRICTION, the
#: MuJoCo model's), since the contacts are unevenly loaded and some slide before the total reaches mu times the load.
FRICTION = 0.5 * GROUND_FRICTION


@dataclass(frozen=True)
class RetimingLimits:
    """The limits a retimed motion keeps: per joint velocity (rad/s), acceleration (rad/s^2) and torque (N m),
    (n,) each (inf: none); the ZMP's margin (m) inside the support polygon; the friction coefficient."""

    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    zmp_margin: float
    friction: float


def _joint_limit(value: npt.ArrayLike | None, n: int, name: str, default: np.ndarray | None = None) -> np.ndarray:
    """A per-joint limit from a number or (n,) array; zeros in ``default`` (URDF gives none) become inf."""
    if value is None:
        assert default is not None, name
        limit = np.where(default > 0, default, np.inf)
    else:
        try:
            limit = np.asarray(value, float)
        except (TypeError, ValueError):
            raise InputTypeError(f"{name} must be a number or an array of {n} numbers, "
                                 f"got {type(value).__name__}") from None
        if limit.ndim == 0:
            limit = np.full(n, float(limit))
        if limit.shape != (n,):
            raise InputError(f"{name} must be a number or shape ({n},), got shape {limit.shape}")
    if np.any(np.isnan(limit)) or np.any(limit <= 0):
        raise InputError(f"{name} must be positive (inf for none), got {np.asarray(limit).tolist()}")
    return limit


def resolve_limits(robot: SnakeRobot, *, velocity_limit: npt.ArrayLike | None = None,
                   acceleration_limit: npt.ArrayLike | None = ACCELERATION_LIMIT,
                   torque_limit: npt.ArrayLike | None = None, zmp_margin: float = ZMP_MARGIN,
                   friction: float = FRICTION) -> RetimingLimits:
    """The limits :func:`~snakehead.retiming.timing.retime` uses, from its keywords (see there); ValueError/TypeError
    for bad ones."""
    robot = as_robot(robot)
    n = robot.n_joints
    vel = _joint_limit(velocity_limit, n, "velocity_limit", VELOCITY_SHARE * robot.velocity_limit)
    if acceleration_limit is None:
        raise InputError("acceleration_limit is needed (URDFs give none); e.g. "
                         f"{ACCELERATION_LIMIT} rad/s^2, the default")
    acc = _joint_limit(acceleration_limit, n, "acceleration_limit")
    tau = _joint_limit(torque_limit, n, "torque_limit", TORQUE_SHARE * robot.effort)
    margin = finite_float(zmp_margin, "zmp_margin")
    if margin < 0:
        raise InputError(f"zmp_margin must be >= 0 m, got {zmp_margin!r}")
    mu = positive(friction, "friction")
    return RetimingLimits(vel, acc, tau, margin, mu)
