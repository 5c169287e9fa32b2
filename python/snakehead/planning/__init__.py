"""The planner: head targets (a scene) -> a checked whole-body motion at the 2 ms control period (:func:`plan`).

Its parts, by concern: the state a plan starts from (:mod:`.start_state`), where the base lies (:mod:`.base_choice`),
each target's solve (:mod:`.target_solves`), the path of checked moves (:mod:`.waypoints`, :mod:`.motion_checks`),
what it tries before giving up (:mod:`.fallbacks`), what it may be asked for (:mod:`.plan_bounds`), what it returns
(:mod:`.plan_result`), what a controller keeps between plans (:mod:`.plan_cache`); many plans at once
(:mod:`.plan_many`) and the whole body's stable reach (:mod:`.whole_body_reach`)."""
from .plan_many import PlanError
from .plan_result import Plan, PlanProgress, TargetResult
from .planner import plan

__all__ = ["plan", "PlanError", "Plan", "PlanProgress", "TargetResult"]
