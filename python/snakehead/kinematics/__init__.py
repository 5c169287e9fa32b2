"""Kinematic solvers of the C++ core: :class:`TracIK` (inverse kinematics) and the head's reachability maps
(Algorithm 1: compute, load, save, merge; Table 2; the dexterous workspace and its centre G0)."""
from .ik import TracIK
from .workspace import Clusters, ReachabilityMap

__all__ = ["TracIK", "ReachabilityMap", "Clusters"]
