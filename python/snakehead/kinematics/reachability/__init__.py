"""The head's reachability maps: the map and what it answers about itself (Table 2, the dexterous workspace and its
centre G0: :mod:`.reachability_map`), the sweep that computes it (the paper's Algorithm 1 inside its boundary:
:mod:`.sweep`, its options :mod:`.sweep_options`, the poses it tries :mod:`.voxel_sphere`), its files (save, load,
merge: :mod:`.map_io`), a robot's map computed once and cached (:mod:`.map_cache`), the questions a map answers for
many poses at once (:mod:`.map_queries`) and the k-means++ of its clusters (:mod:`.kmeans`)."""
from .map_cache import cache_dir, default_map_options, map_for
from .map_io import FORMAT, FORMATS, MAX_MAP_BYTES, load, merge, save, validate_map_arrays
from .reachability_map import (
                               DEXTEROUS_MIN_SHARE,
                               G0_MIN_VOXELS,
                               KIND_HEAD,
                               KIND_WHOLE_BODY,
                               MAP_KINDS,
                               MAP_PARAMETERS,
                               TABLE2_BINS,
                               Clusters,
                               ReachabilityMap,
                               require_map,
)
from .sweep import check_options, compute, evaluate, urdf_text
from .sweep_options import (
                               MAX_CLOUD_SAMPLES,
                               MAX_DIRECTIONS,
                               MAX_FRAMES_PER_VOXEL,
                               MAX_ROLLS,
                               MAX_SEED,
                               MAX_SHARDS,
                               MAX_THREADS,
                               MAX_TIMEOUT_S,
                               MAX_VOXELS_PER_AXIS,
                               MIN_CLOUD_SAMPLES,
                               MIN_VOXELS_PER_AXIS,
                               check_grid,
                               checked_count,
                               checked_real,
                               core_options,
                               mapped_chain,
                               parse_shard,
)
from .voxel_sphere import approach_frame, fibonacci_directions

__all__ = [
    # the map
    "ReachabilityMap", "Clusters", "require_map", "KIND_HEAD", "KIND_WHOLE_BODY", "MAP_KINDS", "MAP_PARAMETERS",
    "TABLE2_BINS", "DEXTEROUS_MIN_SHARE", "G0_MIN_VOXELS",
    # computing it
    "compute", "evaluate", "check_options", "urdf_text", "fibonacci_directions", "approach_frame",
    # its options and their limits
    "core_options", "parse_shard", "check_grid", "checked_count", "checked_real", "mapped_chain", "MAX_DIRECTIONS",
    "MAX_ROLLS", "MAX_FRAMES_PER_VOXEL", "MAX_VOXELS_PER_AXIS", "MIN_VOXELS_PER_AXIS", "MIN_CLOUD_SAMPLES",
    "MAX_CLOUD_SAMPLES", "MAX_THREADS", "MAX_SEED", "MAX_SHARDS", "MAX_TIMEOUT_S",
    # its files
    "save", "load", "merge", "validate_map_arrays", "FORMAT", "FORMATS", "MAX_MAP_BYTES",
    # a robot's map
    "map_for", "default_map_options", "cache_dir",
]
