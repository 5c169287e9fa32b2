"""The defaults of the robot's sweeps, defined once for the API, the command line and the docs.

* A head map (Algorithm 1: ``snakehead workspace``, :func:`snakehead.kinematics.reachability.sweep.compute`): the C++ core's
  ``WorkspaceOptions`` (``include/snakehead/workspace.hpp``), which ``workspace_gen`` uses too, read from the core;
  and how :func:`~snakehead.kinematics.reachability.map_cache.default_map_options` scales the voxel to a head that has no map.
* A whole-body stable reachability map (``snakehead reach``, :func:`snakehead.planning.whole_body_reach.compute_reach`).
"""
from __future__ import annotations

from ._core import WorkspaceOptions as _WorkspaceOptions

__all__ = ["HEAD_VOXEL_M", "HEAD_DIRECTIONS", "HEAD_ROLLS", "HEAD_TIMEOUT_S", "HEAD_EPSILON", "HEAD_CLOUD_SAMPLES",
           "HEAD_SEED", "HEAD_SHRINK", "HEAD_VOXEL_PER_REACH", "HEAD_VOXEL_STEP_M", "REACH_VOXEL_M",
           "REACH_DIRECTIONS"]

_HEAD = _WorkspaceOptions()  # the core's defaults

#: A head map: voxel edge (m), points per voxel sphere, frames about the approach axis per point, TRAC-IK's budget per
#: call (s), its tolerance, configurations sampled for the hull, the seed, the boundary's shrink factor.
HEAD_VOXEL_M: float = float(_HEAD.voxel_size)
HEAD_DIRECTIONS: int = int(_HEAD.directions)
HEAD_ROLLS: int = int(_HEAD.rolls)
HEAD_TIMEOUT_S: float = float(_HEAD.timeout)
HEAD_EPSILON: float = float(_HEAD.epsilon)
HEAD_CLOUD_SAMPLES: int = int(_HEAD.cloud_samples)
HEAD_SEED: int = int(_HEAD.seed)
HEAD_SHRINK: float = float(_HEAD.shrink)
#: The voxel of a head without a map: this share of its reach, rounded to HEAD_VOXEL_STEP_M (m), so that every head
#: gets a grid of about the same size (24 voxels across its side of 2 x the reach).
HEAD_VOXEL_PER_REACH = 1.0 / 12.0
HEAD_VOXEL_STEP_M = 0.005

#: A whole-body reach map: voxel edge (m) and directions per voxel (the issue's target: the default robot at 0.1 m and
#: 12 directions in under 10 minutes on 2 cores).
REACH_VOXEL_M = 0.1
REACH_DIRECTIONS = 12
