"""What the planner tries before it gives up on a path whose motion fails its checks (issue 34, item 8).

A plan's path is built of waypoints that are each checked statically (``planning.waypoints``); the motion along it is
then timed (``retiming.timing.retime``) and checked at every 2 ms sample. When every target was solved but the timed
motion fails for its dynamics -- no timing keeps the limits, or the ZMP comes within ZMP_MARGIN of its support
polygon's edge at a sample -- the path itself may be fine and only its timing too bold: the planner times it again,
slower (:data:`SLOWER_TIMINGS`: the ZMP kept further inside, then the joints accelerating less, then both), and
keeps the first motion that passes. A failure then says what was tried (:func:`tried_message`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..margins import ZMP_MARGIN
from ..retiming.timing import ACCELERATION_LIMIT

if TYPE_CHECKING:
    from .plan_result import Plan


@dataclass(frozen=True)
class SlowerTiming:
    """A retiming kept further from the edge: the ZMP margin ``extra_m`` m more, the joints' acceleration limits
    times ``acceleration_share``."""

    extra_m: float
    acceleration_share: float

    def describe(self) -> str:
        parts = []
        if self.extra_m > 0:
            parts.append(f"the ZMP {1000 * self.extra_m:g} mm further inside")
        if self.acceleration_share < 1:
            parts.append(f"{self.acceleration_share:g} x the acceleration limits")
        return "timed with " + " and ".join(parts)

    def options(self, timing: dict[str, Any] | None) -> dict[str, Any]:
        """The retiming's options ``timing`` (the caller's; defaults where absent) made slower."""
        out = dict(timing or {})
        out["zmp_margin"] = float(out.get("zmp_margin", ZMP_MARGIN)) + self.extra_m
        acceleration = out.get("acceleration_limit", ACCELERATION_LIMIT)
        if acceleration is not None:  # None: no acceleration limit asked for; the ZMP's margin still slows it
            out["acceleration_limit"] = np.asarray(acceleration, float) * self.acceleration_share
        return out


#: Tried in order on a path whose timed motion fails its dynamics. Measured on a ReU-like snake written as
#: published (1 kg joint links with 1 kg m^2 inertias, bench/_robots.py ``reu_as_written``): the ZMP 2 mm further
#: inside fixed most of its "within 5.0 mm" samples; a heavy lift needed the acceleration halved.
SLOWER_TIMINGS = (SlowerTiming(0.002, 1.0), SlowerTiming(0.0, 0.5), SlowerTiming(0.005, 0.25))


def fails_on_dynamics(plan: Plan) -> bool:
    """Whether ``plan`` solved every target and failed only because its timed motion is not dynamically stable (no
    timing kept the limits, or the ZMP left its margin): a slower timing of the same path may pass."""
    if plan.success or any(not tg.solved for tg in plan.targets):
        return False
    return plan.timing_failure is not None or plan.min_zmp_margin_m < ZMP_MARGIN


def retime_slower(finish: Callable[[dict[str, Any] | None], Plan], timing: dict[str, Any] | None,
                  first: Plan) -> Plan:
    """``first`` (the plan of ``finish(timing)``), or when it fails on its dynamics (:func:`fails_on_dynamics`) the
    first plan of ``finish(slower)`` over :data:`SLOWER_TIMINGS` that succeeds, with a note of what it took; else
    the last one tried, its ``attempts`` saying what was tried and why each failed."""
    if not fails_on_dynamics(first):
        return first
    attempts = [f"the time-optimal motion: {first.failure}"]
    plan = first
    for slower in SLOWER_TIMINGS:
        plan = finish(slower.options(timing))
        if plan.success:
            plan.notes.append(f"the time-optimal motion failed ({first.failure}); {slower.describe()} it passes")
            return plan
        attempts.append(f"{slower.describe()}: {plan.failure}")
        if not fails_on_dynamics(plan):  # something else failed: a slower timing is not what it needs
            break
    plan.attempts = attempts
    return plan


def tried_message(failure: str, attempts: list[str]) -> str:
    """A failure and what was tried before it (one line)."""
    if len(attempts) <= 1:
        return failure
    return f"{failure} (tried: " + "; ".join(f"{k + 1}) {a}" for k, a in enumerate(attempts)) + ")"


__all__ = ["SlowerTiming", "SLOWER_TIMINGS", "fails_on_dynamics", "retime_slower", "tried_message"]
