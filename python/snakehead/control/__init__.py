"""Segmented head control (paper Sections 2.3-3.3): the neck by Eqs. 18-22, the head by TRAC-IK towards a position
and a direction (Fig. 9), and the :class:`HeadController` that strings them together for one target."""
from .controller import HeadController, HeadSolution
from .head import HeadIKResult, angle_between_deg, frame_from_direction
from .neck import NeckGoal, NeckSolution

__all__ = ["HeadController", "HeadSolution", "HeadIKResult", "NeckGoal", "NeckSolution", "angle_between_deg",
           "frame_from_direction"]
