"""Compare a simulation with its plan, as the paper does in Section 4 (Figs. 18-20, 23-25)."""
from __future__ import annotations

from typing import Any

import numpy as np

from .._errors import InputError, InputTypeError, invariant
from .._validate import finite_array
from ..dynamics import stability
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from ..solve.head import angle_between_deg
from .tracking import SimResult, check_trajectory

__all__ = ["SPAN_TOLERANCE", "in_span", "check_plan_span", "compare", "zmp_margins"]


#: How far (s) a time may lie outside a simulated span and still be compared (floating-point rounding).
SPAN_TOLERANCE = 1e-9


def in_span(result: SimResult, time: float) -> bool:
    """Whether ``time`` (s) lies within the simulated span of ``result`` (to SPAN_TOLERANCE)."""
    return bool(result.t[0] - SPAN_TOLERANCE <= time <= result.t[-1] + SPAN_TOLERANCE)


def check_plan_span(plan_t: np.ndarray, times: Any, result: SimResult) -> None:
    """The invariant of a plan simulated from its own trajectory: every target time of the plan lies within the
    plan's motion [t[0], t[-1]], and :func:`snakehead.sim.simulate_trajectory` records through the motion's end,
    so within the simulated span. A failure is a bug in the planner or the simulation (InternalError)."""
    for time in times:
        invariant(plan_t[0] - SPAN_TOLERANCE <= time <= plan_t[-1] + SPAN_TOLERANCE,
                  f"a plan's target time {time!r} s is outside its motion [{plan_t[0]!r}, {plan_t[-1]!r}] s")
        invariant(in_span(result, time), f"a plan's target time {time!r} s is outside the span simulated from the "
                  f"plan [{result.t[0]!r}, {result.t[-1]!r}] s")


def _targets(robot: SnakeRobot, planned_t: np.ndarray, planned_q: np.ndarray, base: BasePlacement | None, targets: Any) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """[(time, desired position (3,), desired unit direction (3,))]."""
    if targets is None:
        targets = [float(planned_t[-1])]
    out = []
    for k, tg in enumerate(targets):
        if isinstance(tg, (int, float, np.integer, np.floating)) or (isinstance(tg, np.ndarray) and tg.ndim == 0):
            time, pos, dirn = float(tg), None, None
        else:
            if not isinstance(tg, (tuple, list)) or len(tg) != 3:
                raise InputError(f"targets[{k}] must be a time or (time, position, direction), got {tg!r}")
            time, pos, dirn = tg
            time = float(finite_array(time, f"targets[{k}] time", ()))
        if not np.isfinite(time):
            raise InputError(f"targets[{k}] time is not finite")
        if pos is None or dirn is None:
            qk = np.array([np.interp(time, planned_t, planned_q[:, j]) for j in range(planned_q.shape[1])])
            H = robot.head_pose(qk, base)
            pos = H[:3, 3] if pos is None else pos
            dirn = H[:3, 0] if dirn is None else dirn
        pos = finite_array(pos, f"targets[{k}] position", (3,))
        dirn = finite_array(dirn, f"targets[{k}] direction", (3,))
        nd = np.linalg.norm(dirn)
        if nd < 1e-12:
            raise InputError(f"targets[{k}] direction has zero length")
        out.append((time, pos, dirn / nd))
    return out


def compare(robot: SnakeRobot, planned_t: np.ndarray, planned_q: np.ndarray, result: SimResult, targets: Any = None,
            base: BasePlacement | None = None) -> dict:
    """Compare a simulation with its plan, as the paper does in Section 4.

    ``targets``: a sequence whose items are a time (s; the desired head pose is then the planned one at that
    time) or (time, position (3,) m, direction (3,)) with either of position/direction None for the planned
    one; default: the end of the plan. The simulated head at each target time is interpolated between ticks.
    ``base`` defaults to the result's. On a slope everything (the targets, the plan's and the simulation's poses,
    momenta and ZMP) is in the ground frame of ``base``, as the plan and :func:`snakehead.sim.simulate_trajectory`
    give them: "world" and "horizontal" below are that frame's.

    Returns a dict of floats (SI units) and lists:

    * ``position_error_m`` / ``direction_error_deg``: the largest over the targets of |p_sim - p_des| and of the
      angle between the head's x-axis and the desired direction; per target in ``position_errors_m`` /
      ``direction_errors_deg``;
    * ``max_linear_momentum_error`` (kg m/s) / ``max_angular_momentum_error`` (kg m^2/s): max over the ticks of
      |P_sim - P_plan| and |L_sim - L_plan| (vector difference, about the world origin; planned from
      :func:`snakehead.dynamics.stability.momenta`); ``..._magnitude_error``: max ||P_sim| - |P_plan|| (the paper's wording);
    * ``zmp_inside``: whether every simulated ZMP lay inside the support polygon of the planned configuration
      (:func:`zmp_margins`: the footprint of the links lying on the ground in the plan -- the physical contact area
      of the boxes); ``zmp_min_margin_m`` the smallest signed distance (positive inside);
    * ``base_slide_m``, ``base_lift_m``, ``max_torque_nm``, ``torque_saturation_fraction``.
    """
    robot = as_robot(robot)
    if not isinstance(result, SimResult):
        raise InputTypeError(f"result must be a SimResult, got {type(result).__name__}")
    base = result.base if base is None else as_base(base)
    planned_t, planned_q = check_trajectory(robot, planned_t, planned_q)

    pos_err, dir_err = _head_errors(result, _targets(robot, planned_t, planned_q, base, targets))
    dP, dL, dPm, dLm = _momentum_errors(robot, planned_t, planned_q, base, result)
    margins = zmp_margins(robot, result, planned_t, planned_q, base)
    ok = np.isfinite(margins)
    return {
        "position_error_m": float(max(pos_err)),
        "direction_error_deg": float(max(dir_err)),
        "position_errors_m": pos_err,
        "direction_errors_deg": dir_err,
        "max_linear_momentum_error": float(dP.max()),
        "max_angular_momentum_error": float(dL.max()),
        "max_linear_momentum_magnitude_error": float(dPm.max()),
        "max_angular_momentum_magnitude_error": float(dLm.max()),
        "zmp_inside": bool(ok.all() and np.all(margins > 0)),
        "zmp_min_margin_m": float(margins[ok].min()) if ok.any() else float("nan"),
        "base_slide_m": result.base_slide_m,
        "base_lift_m": result.base_lift_m,
        "max_torque_nm": float(np.abs(result.tau).max()),
        "torque_saturation_fraction": result.saturation_fraction,
    }


def _head_errors(result: SimResult, targets: list) -> tuple[list[float], list[float]]:
    """The simulated head's position errors (m) and direction errors (deg) at ``targets``' (time, position,
    direction), the head interpolated between ticks."""
    pos_err, dir_err = [], []
    for time, pos, dirn in targets:
        if not in_span(result, time):  # the caller's targets and result do not go together
            raise InputError(f"target time {time} s is outside the simulated span [{result.t[0]}, {result.t[-1]}]")
        p = np.array([np.interp(time, result.t, result.head_position[:, i]) for i in range(3)])
        x = np.array([np.interp(time, result.t, result.head_direction[:, i]) for i in range(3)])
        x /= np.linalg.norm(x)
        pos_err.append(float(np.linalg.norm(p - pos)))
        dir_err.append(angle_between_deg(x, dirn))
    return pos_err, dir_err


def _momentum_errors(robot: SnakeRobot, planned_t: np.ndarray, planned_q: np.ndarray, base: BasePlacement,
                     result: SimResult) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """On the simulated ticks within the plan: |P_sim - P_plan|, |L_sim - L_plan| and the differences of their
    magnitudes, (T,) each (the planned momenta interpolated to the ticks)."""
    inside = result.t <= planned_t[-1] + 1e-9
    ts = result.t[inside]
    Pp, Lp = stability.momenta(robot, planned_t, planned_q, base)
    Pp = np.column_stack([np.interp(ts, planned_t, Pp[:, i]) for i in range(3)])
    Lp = np.column_stack([np.interp(ts, planned_t, Lp[:, i]) for i in range(3)])
    Ps, Ls = result.P[inside], result.L[inside]
    dP = np.linalg.norm(Ps - Pp, axis=1)
    dL = np.linalg.norm(Ls - Lp, axis=1)
    dPm = np.abs(np.linalg.norm(Ps, axis=1) - np.linalg.norm(Pp, axis=1))
    dLm = np.abs(np.linalg.norm(Ls, axis=1) - np.linalg.norm(Lp, axis=1))
    return dP, dL, dPm, dLm


def zmp_margins(robot: SnakeRobot, result: SimResult, planned_t: np.ndarray, planned_q: np.ndarray,
                base: BasePlacement | None = None, contact: str = "ground") -> np.ndarray:
    """Signed distance (m, positive inside) of each simulated ZMP to the planned support polygon at that tick.

    The polygon is :func:`snakehead.dynamics.stability.support_polygon` of the planned configuration interpolated
    to the tick, with ``contact="ground"`` by default: the footprint of every link lying on the ground in the plan
    (the one the planner checks its own ZMP against). Ticks without ground load get NaN.
    """
    base = result.base if base is None else as_base(base)
    n = robot.n_joints
    out = np.full(len(result.t), np.nan)
    loaded = np.flatnonzero(np.all(np.isfinite(result.zmp), axis=1))
    if loaded.size == 0:
        return out
    ts = result.t[loaded]
    q_ticks = np.column_stack([np.interp(ts, planned_t, planned_q[:, j]) for j in range(n)])
    out[loaded] = stability.support_margins(robot, q_ticks, result.zmp[loaded], base, contact=contact)
    return out
