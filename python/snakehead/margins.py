"""The margins every plan keeps, each defined once: how far the ZMP stays inside the support polygon, the static
margin of every planned configuration, and how far a solved configuration stays from the obstacles.

The planner (:mod:`snakehead.planning.planner`), the whole-body solve (:mod:`snakehead.solve.whole_body`) and the
retiming (:mod:`snakehead.retiming.timing`) read them from here.
"""
from __future__ import annotations

#: m: the least distance of the ZMP inside the support polygon a successful plan keeps (Eqs. 36-40), and the
#: margin the time-optimal retiming keeps it by.
ZMP_MARGIN = 0.005
#: m: the static margin every planned configuration keeps (the CoM inside the support polygon): twice the ZMP
#: margin, room for the motion's dynamic terms between the configurations.
DETOUR_MARGIN = 2 * ZMP_MARGIN
#: m: the least static margin of a whole-body solution (the CoM inside the support polygon): the ZMP's margin (a
#: configuration held still has its ZMP at its CoM).
SOLUTION_MARGIN = ZMP_MARGIN
#: m: the least distance a solved configuration keeps from every obstacle.
OBSTACLE_CLEARANCE = 0.002
#: m: the least gap a solved configuration keeps between two of its links that are not neighbours.
SELF_CLEARANCE = 0.002
#: m: obstacle distances up to this are computed exactly by the checks (``collision_check(exact_within=...)``);
#: beyond it a lower bound is enough for their verdict.
EXACT_DISTANCE_WITHIN = 0.005

__all__ = ["ZMP_MARGIN", "DETOUR_MARGIN", "SOLUTION_MARGIN", "OBSTACLE_CLEARANCE", "SELF_CLEARANCE",
           "EXACT_DISTANCE_WITHIN"]
