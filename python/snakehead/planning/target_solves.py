"""One target of a plan solved with the base kept (the whole-body solve,
:func:`~snakehead.solve.whole_body.solve_checked_target`), remembered for the plan: the base's choice
(:func:`~snakehead.planning.base_choice.choose_base`) and the plan's own moves share the solves."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..margins import DETOUR_MARGIN
from ..model.robot import BasePlacement
from ..solve.head_controller import HeadController
from ..solve.whole_body import PlanSolves, solve_checked_target


def solve_kept(controller: HeadController, position: np.ndarray, direction: np.ndarray, q_prev: np.ndarray,
               base: BasePlacement, obstacles: Sequence[Any], solved: PlanSolves | None, near: bool = False) -> Any:
    """``solve.whole_body.solve_target`` with the base kept, kept in ``solved`` (one plan's: its obstacles are
    fixed) so that choose_base's solves of the chosen base are not repeated by the plan (the solve is
    deterministic: the same inputs give the same solution); its segmented solves and IK batches are shared there too."""
    key = (np.asarray(position, float).tobytes(), np.asarray(direction, float).tobytes(),
           np.asarray(q_prev, float).tobytes(), base, near)
    if solved is not None and key in solved.kept:
        return solved.kept[key]
    sol = solve_checked_target(controller, position, direction, q_prev=q_prev, base=base, obstacles=obstacles,
                               allow_base_move=False, problem=controller.body_problem, min_margin=DETOUR_MARGIN,
                               near=near, memo=solved)
    if solved is not None:
        solved.kept[key] = sol
    return sol


def solve_noted(controller: HeadController, position: np.ndarray, direction: np.ndarray, q_prev: np.ndarray,
           base: BasePlacement, obstacles: Sequence[Any], name: str, notes: list, near: bool = False,
           solved: PlanSolves | None = None) -> Any:
    """One target with the base kept (:func:`solve_kept`); a note when it fails."""
    sol = solve_kept(controller, position, direction, q_prev, base, obstacles, solved, near)
    if not sol.success:
        notes.append(f"{name}: {sol.message}")
    return sol


__all__ = ["PlanSolves", "solve_kept", "solve_noted"]
