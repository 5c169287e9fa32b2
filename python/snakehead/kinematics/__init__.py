"""Kinematic solvers of the C++ core: :class:`TracIK` (inverse kinematics, :mod:`.ik`), the head's reachability maps
(:mod:`.reachability`) and where a robot's base may lie for a target (:mod:`.base_placement`)."""
from .ik import TracIK
from .reachability import Clusters, ReachabilityMap

__all__ = ["TracIK", "ReachabilityMap", "Clusters"]
