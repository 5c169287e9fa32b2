"""Simulate a :class:`~snakehead.planning.plan_result.Plan` in MuJoCo and compare it with the plan: the dynamics check of
the paper's Section 4, in one call."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._errors import InputTypeError, entry_point, inputs_checked
from ..planning.plan_result import Plan
from .compare import check_plan_span, compare
from .tracking import SimResult, simulate_trajectory

__all__ = ["PlanSimulation", "simulate"]


@dataclass
class PlanSimulation:
    """The dynamics check of a plan.

    position_error_m / direction_error_deg: the simulated head's worst errors over the plan's targets (at the
    times the plan reaches them); zmp_inside: every simulated ZMP inside the planned support polygon; metrics:
    every number of :func:`snakehead.sim.compare`; result: the raw :class:`SimResult`.
    """

    plan: Plan
    result: SimResult
    metrics: dict

    @property
    def position_error_m(self) -> float:
        return float(self.metrics["position_error_m"])

    @property
    def direction_error_deg(self) -> float:
        return float(self.metrics["direction_error_deg"])

    @property
    def zmp_inside(self) -> bool:
        return bool(self.metrics["zmp_inside"])


@entry_point
def simulate(plan: Any, **options: Any) -> PlanSimulation:
    """Track ``plan`` (a :class:`~snakehead.planning.plan_result.Plan`) in MuJoCo with PD control and gravity
    compensation at 2 ms, its obstacles included, and compare with the plan at its targets.

    ``options`` go to :func:`snakehead.sim.simulate_trajectory` (gains, torque limits, friction, hole_slices...).
    Needs MuJoCo (``pip install snakehead[sim]``).
    """
    if not isinstance(plan, Plan):
        raise InputTypeError(f"plan must be a snakehead Plan (from snakehead.plan), got {type(plan).__name__}")
    options.setdefault("obstacles", list(plan.obstacles))
    result = simulate_trajectory(plan.robot, plan.t, plan.q, plan.base, **options)  # it checks the options
    inputs_checked()  # the rest compares the plan with its own simulation: an InputError there is a bug
    check_plan_span(plan.t, [tg.time_s for tg in plan.targets], result)
    targets = [(tg.time_s, tg.position, tg.direction) for tg in plan.targets] or None
    metrics = compare(plan.robot, plan.t, plan.q, result, targets=targets, base=plan.base)
    return PlanSimulation(plan=plan, result=result, metrics=metrics)
