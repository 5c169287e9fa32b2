"""The result of a whole-body solve (:class:`WholeBodySolution`): the configuration and placement, which stage
solved it or what the best attempt lacks, and its checks; and how two attempts compare (:func:`solution_rank`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model.robot import BasePlacement

__all__ = ["REASONS", "STAGES", "WholeBodySolution", "check_rank", "solution_rank"]

#: The stages of the whole-body solve, in the order they are tried.
STAGES = ("segmented", "whole-body, base kept", "whole-body, base moved")
#: Why an attempt fails, from the worst: the head is not at the target, the body does not stand, it is not clear.
REASONS = ("out of reach", "no stable pose", "no clear pose")


@dataclass
class WholeBodySolution:
    """A whole-body solution (or the best attempt).

    q (n,) rad and base: the configuration and the base placement. stage: which of ``STAGES`` solved it (None
    when unsolved). reason: None when solved, else one of ``REASONS`` (what the best attempt lacked).
    position_error_m, direction_error_deg: of the head; static_margin_m (support polygon of the links on the
    ground), ground_clearance_m (lowest lifted box corner), self_clearance_m (separating-axis gap),
    obstacle_clearance_m (None without obstacles). starts: how many starts were tried; seconds: solve time.
    """

    q: np.ndarray
    base: BasePlacement
    stage: str | None
    reason: str | None
    position_error_m: float
    direction_error_deg: float
    static_margin_m: float
    ground_clearance_m: float
    self_clearance_m: float
    obstacle_clearance_m: float | None
    starts: int = 0
    seconds: float = 0.0
    notes: list = field(default_factory=list)
    #: the paper's segmented solution (a ``HeadSolution``) tried first, when there was one
    segmented: object | None = None
    #: the desired head frame (4, 4) (x-axis the direction)
    desired_frame: np.ndarray | None = None

    @property
    def success(self) -> bool:
        """Whether every check passed."""
        return self.reason is None

    @property
    def message(self) -> str:
        """One line: the stage that solved it, or the reason and the checks' values."""
        if self.success:
            return f"solved ({self.stage})"
        return (f"{self.reason}: head {1000 * self.position_error_m:.1f} mm / {self.direction_error_deg:.2f} deg off, "
                f"static margin {1000 * self.static_margin_m:.1f} mm, ground clearance "
                f"{1000 * self.ground_clearance_m:.1f} mm, self clearance {1000 * self.self_clearance_m:.1f} mm")

    @property
    def neck_goal(self) -> Any:
        """Eqs. 18-20's goal of the segmented solve, when that solve is the solution (for Fig. 8)."""
        return getattr(self.segmented, "neck_goal", None) if self.stage == STAGES[0] else None

    @property
    def neck(self) -> Any:
        """The neck's solution (Eq. 22) of the segmented solve, when that solve is the solution."""
        return getattr(self.segmented, "neck", None) if self.stage == STAGES[0] else None


_ORDER = {None: 3, "no clear pose": 2, "no stable pose": 1, "out of reach": 0}


def solution_rank(s: WholeBodySolution) -> tuple:
    """How good an attempt is, for comparing attempts (larger is better): solved, then the reason's order, then its
    margin (or, out of reach, how near)."""
    return _ORDER[s.reason], s.static_margin_m if s.reason != "out of reach" else -s.position_error_m


def check_rank(chk: dict) -> tuple:
    """:func:`solution_rank` of a check (``solution_checks.check_solutions``) before it is made a solution."""
    reason = chk["reason"]
    return _ORDER[reason], chk["static_margin_m"] if reason != "out of reach" else -chk["position_error_m"]
