"""The segmented solve of one target (paper Sections 2.3-3.3): the neck by Eqs. 18-22 (:mod:`.neck`), the head by
TRAC-IK towards a position and a direction (:mod:`.head`, Fig. 9), the :class:`HeadController` that strings them
together (:mod:`.head_controller`), the stability-aware whole-body solve (:mod:`.whole_body`) with its necessary
conditions (:mod:`.pose_bounds`), and the initial state held on the body's actual contacts (:mod:`.initial_state`)."""
from .head import HeadIKResult, angle_between_deg, frame_from_direction
from .head_controller import HeadController, HeadSolution
from .neck import NeckGoal, NeckSolution

__all__ = ["HeadController", "HeadSolution", "HeadIKResult", "NeckGoal", "NeckSolution", "angle_between_deg",
           "frame_from_direction"]
