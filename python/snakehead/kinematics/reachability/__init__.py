"""The head's reachability maps: the paper's Algorithm 1 inside its boundary (compute, load, save, merge), Table 2,
the dexterous workspace and its centre G0 (:mod:`.reachability_map`), the questions a map answers for many poses at
once (:mod:`.map_queries`) and the k-means++ of its clusters (:mod:`.kmeans`)."""
from .reachability_map import Clusters, ReachabilityMap, compute, load, map_for, merge, save

__all__ = ["ReachabilityMap", "Clusters", "compute", "load", "save", "merge", "map_for"]
