"""The C++ core's limits on what callers may ask for (``include/snakehead/limits.hpp``), under their Python names.

Defined once, in C++, and read here from the core (``snakehead._core.Limits``): Python checks its arguments against
the same numbers before any work (an :class:`~snakehead.InputError` naming the argument), so that no value reaches the
core that it would refuse. Each is far above any sensible use and far below what would overflow, exhaust memory or
crash.
"""
from __future__ import annotations

from ._core import Limits as _Core

__all__ = ["MAX_TIMEOUT_S", "MAX_URDF_BYTES", "MAX_URDF_DEPTH", "MAX_IK_JOINTS", "MAX_VOXELS_PER_AXIS",
           "MAX_DIRECTIONS", "MAX_ROLLS", "MAX_FRAMES_PER_VOXEL", "MAX_CLOUD_SAMPLES", "MAX_THREADS", "MAX_TERRAIN_CELLS",
           "MAX_TERRAIN_TRIANGLES", "CORE_LIMITS"]

#: s: the longest timeout or duration (one day; a steady-clock deadline overflows beyond ~292 years).
MAX_TIMEOUT_S: float = float(_Core.MAX_TIMEOUT_S)
#: The largest robot description (URDF) read, in bytes, and its deepest element nesting.
MAX_URDF_BYTES: int = int(_Core.MAX_URDF_BYTES)
MAX_URDF_DEPTH: int = int(_Core.MAX_URDF_DEPTH)
#: The most joints of a chain TRAC-IK solves (its SQP half needs memory growing with their square).
MAX_IK_JOINTS: int = int(_Core.MAX_IK_JOINTS)
#: A workspace sweep: voxels per axis of its grid, points per voxel sphere, frames about the approach axis per point,
#: frames per voxel (directions x rolls), configurations sampled for the hull, worker threads.
MAX_VOXELS_PER_AXIS: int = int(_Core.MAX_VOXELS_PER_AXIS)
MAX_DIRECTIONS: int = int(_Core.MAX_DIRECTIONS)
MAX_ROLLS: int = int(_Core.MAX_ROLLS)
MAX_FRAMES_PER_VOXEL: int = int(_Core.MAX_FRAMES_PER_VOXEL)
MAX_CLOUD_SAMPLES: int = int(_Core.MAX_CLOUD_SAMPLES)
MAX_THREADS: int = int(_Core.MAX_THREADS)
#: A terrain: the most cells of a heightfield's grid (two triangles each) and triangles of a mesh.
MAX_TERRAIN_CELLS: int = int(_Core.MAX_TERRAIN_CELLS)
MAX_TERRAIN_TRIANGLES: int = int(_Core.MAX_TERRAIN_TRIANGLES)

#: Every name above: the core's name (a class attribute of ``_core.Limits``) is the same.
CORE_LIMITS = ("MAX_TIMEOUT_S", "MAX_URDF_BYTES", "MAX_URDF_DEPTH", "MAX_IK_JOINTS", "MAX_VOXELS_PER_AXIS",
               "MAX_DIRECTIONS", "MAX_ROLLS", "MAX_FRAMES_PER_VOXEL", "MAX_CLOUD_SAMPLES", "MAX_THREADS",
               "MAX_TERRAIN_CELLS", "MAX_TERRAIN_TRIANGLES")
