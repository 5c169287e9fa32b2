"""Kinematic solvers of the C++ core: :class:`TracIK` (inverse kinematics) and the head's reachability maps
(``workspace``: Algorithm 1 inside the paper's boundary, compute, load, save, merge; Table 2; the dexterous workspace
and its centre G0), the questions a map answers (``map_queries``: reachable poses, inverse reachability) and
where a robot's base may lie for a target (``base_placement``)."""
from .ik import TracIK
from .workspace import Clusters, ReachabilityMap

__all__ = ["TracIK", "ReachabilityMap", "Clusters"]
