"""The options of a head map's sweep (Algorithm 1): their limits, their checks and the C++ core's options object.

Every value is checked in Python before any work: an InputError naming the option, never a number handed to the
bindings' 32- or 64-bit fields. The upper limits are the C++ core's (:mod:`snakehead.limits`, read from
``include/snakehead/limits.hpp``); the others are this module's.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ... import _core, limits
from ..._errors import InputError, InputTypeError
from ...model.chain import Chain
from ...model.robot import SnakeRobot

#: Points per voxel sphere (``directions``), and frames about the approach axis per point (``rolls``).
MAX_DIRECTIONS, MAX_ROLLS = limits.MAX_DIRECTIONS, limits.MAX_ROLLS
#: Frames per voxel: directions x rolls (unless free roll).
MAX_FRAMES_PER_VOXEL = limits.MAX_FRAMES_PER_VOXEL
#: Voxels per axis of the grid (whose side is 2 x the chain's reach): at most the core's 256 (256^3 = 16.8 million
#: voxels), at least 4, so a voxel is under a third of the grid's side (2/3 of the reach; a larger one gives a map of a
#: few voxels of index 0 and no dexterous workspace).
MAX_VOXELS_PER_AXIS, MIN_VOXELS_PER_AXIS = limits.MAX_VOXELS_PER_AXIS, 4
#: Random configurations sampled for the hull (``cloud_samples``).
MIN_CLOUD_SAMPLES, MAX_CLOUD_SAMPLES = 100, limits.MAX_CLOUD_SAMPLES
#: Worker threads (0 or None: snakehead.core_threads(), all cores by default).
MAX_THREADS = limits.MAX_THREADS
#: The seed is an unsigned 64-bit integer.
MAX_SEED = 2**64 - 1
#: Shards of one map: a shard is a set of tiles of 4 x 4 lines of voxels, and the largest grid has
#: (MAX_VOXELS_PER_AXIS / 4)^2 tiles (more shards than the grid's tiles are empty).
MAX_SHARDS = (MAX_VOXELS_PER_AXIS // 4) ** 2
#: TRAC-IK's budget per call (s): a day at most.
MAX_TIMEOUT_S = limits.MAX_TIMEOUT_S


def checked_count(name: str, value: Any, least: int, most: int, hint: str = "") -> int:
    """``value`` as an int within [least, most]: InputTypeError unless an integer (not a bool), InputError beyond
    (its message names ``name`` and adds ``hint`` after the range)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputTypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    if not least <= int(value) <= most:
        raise InputError(f"{name} must be between {least} and {most}{hint}, got {value}")
    return int(value)


def checked_real(name: str, value: Any) -> float:
    """``value`` as a float: InputTypeError unless a number (not a bool); its range is the caller's to check."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputTypeError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    try:
        return float(value)
    except OverflowError:  # an int beyond a float
        raise InputError(f"{name} must be a finite number, got {value}") from None


def core_options(voxel: float, directions: int, rolls: int, any_roll: bool, free_roll: bool, approach_axis: str,
                 timeout: float, epsilon: float, cloud_samples: int, seed: int | None, threads: int | None,
                 shard: Any, hull: str = "boundary", shrink: float = 0.5) -> _core.WorkspaceOptions:
    """The core's options of a sweep (:func:`~.sweep.compute`'s options, ``voxel`` the voxel's edge in m and
    ``timeout`` TRAC-IK's budget per call in s), every value checked against the limits above first (InputError
    naming it)."""
    o = _core.WorkspaceOptions()
    directions = checked_count("directions", directions, 1, MAX_DIRECTIONS)
    rolls = checked_count("rolls", rolls, 0 if free_roll else 1, MAX_ROLLS, "" if free_roll else " (or use free roll)")
    if not free_roll and directions * rolls > MAX_FRAMES_PER_VOXEL:
        raise InputError(f"directions x rolls (frames per voxel) must be at most {MAX_FRAMES_PER_VOXEL}, got "
                         f"{directions} x {rolls} = {directions * rolls}")
    cloud_samples = checked_count("cloud_samples", cloud_samples, MIN_CLOUD_SAMPLES, MAX_CLOUD_SAMPLES,
                                  " (the hull needs a cloud)")
    seed = checked_count("seed", seed, 0, MAX_SEED)
    threads = (0 if threads is None else
               checked_count("threads", threads, 0, MAX_THREADS, " (0 = snakehead.core_threads())"))
    voxel, timeout = checked_real("voxel", voxel), checked_real("timeout", timeout)
    epsilon = checked_real("epsilon", epsilon)
    if not (math.isfinite(voxel) and voxel > 0):
        raise InputError(f"voxel size must be a positive number of metres, got {voxel!r}")
    if not (math.isfinite(timeout) and timeout > 0):
        raise InputError(f"timeout must be a positive finite number of seconds, got {timeout!r}")
    if timeout > MAX_TIMEOUT_S:
        raise InputError(f"timeout must be at most {MAX_TIMEOUT_S:g} s (one day), got {timeout:g}")
    if not (math.isfinite(epsilon) and epsilon > 0):
        raise InputError(f"epsilon must be a positive number, got {epsilon!r}")
    if not isinstance(approach_axis, str) or approach_axis not in ("x", "z"):
        raise InputError(f"approach_axis must be 'x' or 'z', got {approach_axis!r}")
    if not isinstance(hull, str) or hull not in ("boundary", "convex"):
        raise InputError(f"hull must be 'boundary' (the paper's boundary(P)) or 'convex', got {hull!r}")
    shrink = checked_real("shrink", shrink)
    if not 0.0 <= shrink <= 1.0:  # NaN too
        raise InputError(f"shrink (the boundary's shrink factor) must be within [0, 1], got {shrink!r}")
    o.voxel_size = voxel
    o.directions = directions
    o.rolls = rolls
    o.any_roll = bool(any_roll)
    o.free_roll = bool(free_roll)
    o.approach_axis = approach_axis
    o.timeout = timeout
    o.epsilon = epsilon
    o.cloud_samples = cloud_samples
    o.hull = hull
    o.shrink = shrink
    o.seed = seed
    o.threads = threads
    o.shard_index, o.shard_count = parse_shard(shard)
    try:
        o.validate()  # the core's own check (the same limits): a ValueError naming the first bad field
    except ValueError as exc:
        raise InputError(str(exc)) from None
    return o


def parse_shard(shard: Any) -> tuple[int, int]:
    """``shard`` ('i/N' or (i, N)) as (i, N) with 0 <= i < N <= MAX_SHARDS; InputError otherwise."""
    if shard is None:
        return 0, 1
    bad = InputError(f"shard must be 'i/N' or (i, N) with integers 0 <= i < N <= {MAX_SHARDS}, got {shard!r}")
    if isinstance(shard, str):
        parts = shard.split("/")
        if len(parts) != 2 or not all(p.strip().isdecimal() and len(p) <= 20 for p in parts):
            raise bad  # (more than 20 digits is beyond any limit, and int() refuses thousands)
        i, n = (int(p) for p in parts)
    else:
        try:
            parts = list(shard)
        except TypeError:
            raise bad from None
        if len(parts) != 2 or any(isinstance(x, bool) or not isinstance(x, (int, np.integer)) for x in parts):
            raise bad
        i, n = (int(x) for x in parts)
    if not 0 <= i < n <= MAX_SHARDS:
        raise InputError(f"shard must be i/N with 0 <= i < N <= {MAX_SHARDS} (a shard is at least one tile of the "
                         f"grid), got {i}/{n}")
    return i, n


def check_grid(chain: Chain, voxel: float) -> None:
    """InputError unless the grid of side 2 x reach holds MIN_VOXELS_PER_AXIS to MAX_VOXELS_PER_AXIS voxels of edge
    ``voxel`` per axis (the core's count of them), so that a voxel is neither too small to allocate nor so large
    that the map has a few voxels of index 0."""
    side = 2.0 * chain.reach
    ratio = side / voxel
    cells = math.ceil(ratio - 1e-9) if math.isfinite(ratio) else math.inf
    if cells > MAX_VOXELS_PER_AXIS:
        raise InputError(f"voxel size {voxel:g} m is too small for the grid of side {side:.4g} m (2 x the chain's "
                         f"reach): {cells:.3g} voxels per axis, at most {MAX_VOXELS_PER_AXIS} (voxel size >= "
                         f"{side / MAX_VOXELS_PER_AXIS:.4g} m)")
    if cells < MIN_VOXELS_PER_AXIS:
        raise InputError(f"voxel size {voxel:g} m is too large for the grid of side {side:.4g} m (2 x the chain's "
                         f"reach): {max(cells, 1)} voxel{'s' if cells > 1 else ''} per axis, at least "
                         f"{MIN_VOXELS_PER_AXIS} (voxel size < {side / (MIN_VOXELS_PER_AXIS - 1):.4g} m)")


def mapped_chain(chain_or_robot: Chain | SnakeRobot) -> Chain:
    """The chain a head map is of: a :class:`Chain` as it is, a SnakeRobot's head chain, or the C++ core's
    ``ChainModel`` wrapped; InputTypeError for anything else."""
    if isinstance(chain_or_robot, SnakeRobot):
        return chain_or_robot.head_chain
    if isinstance(chain_or_robot, Chain):
        return chain_or_robot
    if isinstance(chain_or_robot, _core.ChainModel):
        return Chain(chain_or_robot)
    raise InputTypeError(f"expected a Chain or a SnakeRobot (whose head chain is mapped), got "
                         f"{type(chain_or_robot).__name__}")


__all__ = ["MAX_DIRECTIONS", "MAX_ROLLS", "MAX_FRAMES_PER_VOXEL", "MAX_VOXELS_PER_AXIS", "MIN_VOXELS_PER_AXIS",
           "MIN_CLOUD_SAMPLES", "MAX_CLOUD_SAMPLES", "MAX_THREADS", "MAX_SEED", "MAX_SHARDS", "MAX_TIMEOUT_S",
           "checked_count", "checked_real", "core_options", "parse_shard", "check_grid", "mapped_chain"]
