"""A sampled trajectory measured against :class:`~snakehead.retiming.retiming_limits.RetimingLimits`
(:func:`check_limits`): how close it comes to each limit and which ones bind. The retimed motion is checked at every
2 ms sample; the grid's refinement probes between gridpoints with the same ratios (:func:`limit_ratios`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputTypeError
from .._validate import finite_array
from ..dynamics.inverse_dynamics import InverseDynamics, newton_euler
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .retiming_limits import RetimingLimits
from .support_polygon import Support

__all__ = ["BINDING_SHARE", "BINDING_ZMP_M", "LimitCheck", "limit_ratios", "check_limits"]

#: How close (share of the limit) a sample must come to a limit to count as binding in :class:`LimitCheck`.
BINDING_SHARE = 0.97
#: m: how close the ZMP must come to its required margin to count as binding.
BINDING_ZMP_M = 0.001


@dataclass(frozen=True)
class LimitCheck:
    """How a sampled trajectory meets :class:`~snakehead.retiming.retiming_limits.RetimingLimits` (worst over its
    samples).

    velocity_ratio, acceleration_ratio, torque_ratio: max over samples and joints of |value| / limit (<= 1 keeps it).
    zmp_margin_m: the least signed distance (m) of the ZMP inside its sample's support polygon; zmp_slack_m: the
    least of that minus the required margin (>= 0 keeps it). friction_ratio: max |dP_xy/dt| / (mu (M g + dP_z/dt)).
    binding: for each of "velocity", "acceleration", "torque", "zmp", "friction", the share of the moving samples
    at which it is within BINDING_SHARE of its limit (the ZMP: within BINDING_ZMP_M of its margin).
    """

    velocity_ratio: float
    acceleration_ratio: float
    torque_ratio: float
    zmp_margin_m: float
    zmp_slack_m: float
    friction_ratio: float
    binding: dict = field(default_factory=dict)

    def within(self, tolerance: float = 1e-3, zmp_tolerance_m: float = 1e-4) -> bool:
        """Every limit kept, ratios up to 1 + ``tolerance`` and the ZMP's margin to ``zmp_tolerance_m`` m."""
        ratios = (self.velocity_ratio, self.acceleration_ratio, self.torque_ratio, self.friction_ratio)
        return max(ratios) <= 1.0 + tolerance and self.zmp_slack_m >= -zmp_tolerance_m


def limit_ratios(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, support: Support, q: np.ndarray,
                 qd: np.ndarray, qdd: np.ndarray, frames: np.ndarray | None = None,
                 dyn: InverseDynamics | None = None) -> dict[str, np.ndarray]:
    """Per sample (T,): the largest |value| / limit of the joint velocities, accelerations and torques, the friction
    used (|dP_xy/dt| / (mu (M g + dP_z/dt))), the ZMP's margin in ``support`` and its slack over the required one.
    ``dyn``: the samples' Newton-Euler pass when the caller has it."""
    if dyn is None:
        dyn = newton_euler(robot, q, qd, qdd, base, frames=frames)  # torques and exact momentum rates
    # in the core (where M g + dP_z/dt <= 0 the ground would have to pull: no ZMP)
    c = np.ascontiguousarray
    ratios = _core.limit_ratios(c(qd), c(qdd), c(dyn.tau), c(dyn.Pdot), c(dyn.Ldot), c(support.com), c(support.normal),
                                c(support.offset), c(limits.velocity, float), c(limits.acceleration, float),
                                c(limits.torque, float), robot.total_mass * base.gravity_across,
                                float(limits.friction), *(robot.total_mass * base.gravity[:2]))
    ratios["zmp_slack"] = ratios["zmp_margin"] - support.required
    return ratios


def check_limits(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike, base: BasePlacement | None,
                 limits: RetimingLimits) -> LimitCheck:
    """Measure samples q, qd, qdd (T, n) of a trajectory against ``limits``: joint velocities and accelerations, the
    torques of :func:`~snakehead.dynamics.inverse_dynamics.inverse_dynamics`, the ZMP of Eqs. 39-40 from the momentum
    rates of Newton-Euler in the ground support polygon of each sample, and the base's friction. (An independent
    check of the ZMP, from the paper's momenta of Eqs. 25-31 and their finite differences:
    ``stability.dynamic_stability``.)"""
    robot = as_robot(robot)
    base = as_base(base)
    if not isinstance(limits, RetimingLimits):
        raise InputTypeError(f"limits must be RetimingLimits, got {type(limits).__name__}")
    q = finite_array(q, "q", (None, robot.n_joints))
    qd = finite_array(qd, "qd", q.shape)
    qdd = finite_array(qdd, "qdd", q.shape)
    frames = robot.frames_many(q, base)
    r = limit_ratios(robot, base, limits, Support.of(robot, q, base, limits.zmp_margin, frames), q, qd, qdd, frames)
    moving = np.abs(qd).max(axis=1) > 0

    def share(hit: np.ndarray) -> float:
        return float(np.mean(hit[moving])) if moving.any() else 0.0

    binding = {key: share(r[key] >= BINDING_SHARE) for key in ("velocity", "acceleration", "torque", "friction")}
    binding["zmp"] = share(r["zmp_slack"] <= BINDING_ZMP_M)
    return LimitCheck(float(r["velocity"].max()), float(r["acceleration"].max()), float(r["torque"].max()),
                      float(r["zmp_margin"].min()), float(r["zmp_slack"].min()), float(r["friction"].max()), binding)
