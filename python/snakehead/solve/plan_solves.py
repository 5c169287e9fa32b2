"""The solves of one plan's targets that its steps share (:class:`PlanSolves`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from .whole_body_solution import WholeBodySolution

__all__ = ["PlanSolves"]


class PlanSolves:
    """The solves of one plan's targets that its steps share (the base's choice, the relocation's search and the
    targets' solves ask for the same ones): the whole-body solves with the base kept (``kept``: the planner's
    :func:`~snakehead.planning.target_solves.solve_kept` keys them), and the segmented solves
    (:meth:`HeadController.solve_checked <snakehead.solve.head_controller.HeadController.solve_checked>`) and the
    lifted chain's IK candidates (:func:`~.whole_body_starts.lifted_candidates`) of
    :func:`~.target_search.solve_checked_target`. Every one is deterministic (the same arguments give
    the same solution: the IK is seeded, its searches bounded by counts), so an entry stands for a solve again.
    Owned by one plan: its controller and obstacles are fixed for its life, and it is dropped with the plan (no bound
    on its size: a plan solves a bounded number of targets)."""

    def __init__(self) -> None:
        self.kept: dict[tuple, WholeBodySolution] = {}
        self.segmented: dict[tuple, Any] = {}
        self.candidates: dict[tuple, list[np.ndarray]] = {}
