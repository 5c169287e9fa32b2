"""A robot's head map where none is given: the robot file's map, else one computed once with options scaled to the
head (:func:`default_map_options`) and cached on disk (:func:`cache_dir`)."""
from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

from ... import sweep_defaults as defaults
from ..._errors import InputError, InputTypeError
from ...model.chain import Chain
from ...model.robot import SnakeRobot
from .map_io import load, save
from .reachability_map import ReachabilityMap
from .sweep import compute
from .sweep_options import mapped_chain


def default_map_options(chain_or_robot: Chain | SnakeRobot) -> dict:
    """Options of :func:`~.sweep.compute` for a robot's head that has no map yet: the head's sweep defaults
    (:mod:`snakehead.sweep_defaults`), with voxels scaled to the head (``HEAD_VOXEL_PER_REACH`` of its reach, rounded
    to ``HEAD_VOXEL_STEP_M``) so that every head gets a grid of about the same size."""
    chain = mapped_chain(chain_or_robot)
    step = defaults.HEAD_VOXEL_STEP_M
    voxel = max(step, round(chain.reach * defaults.HEAD_VOXEL_PER_REACH / step) * step)
    return dict(voxel=voxel, directions=defaults.HEAD_DIRECTIONS, rolls=defaults.HEAD_ROLLS,
                timeout=defaults.HEAD_TIMEOUT_S, seed=defaults.HEAD_SEED)


def cache_dir() -> Path:
    """Where computed maps are cached: ``$SNAKEHEAD_CACHE`` or ``$XDG_CACHE_HOME/snakehead`` (``~/.cache``)."""
    env = os.environ.get("SNAKEHEAD_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "snakehead"


def map_for(robot: SnakeRobot, *, progress: bool = True, cache: bool = True, **options: Any) -> ReachabilityMap:
    """The reachability map of a robot's head: the robot file's map when it has one; else a map computed earlier
    for this head chain and these options (cached under :func:`cache_dir`); else one computed now (with a
    progress bar; :func:`default_map_options` unless ``options`` say otherwise) and cached. The map's ``path``
    says which file it is."""
    if not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    if "shard" in options or "executor" in options:
        raise InputError("map_for gives a robot's whole map: compute shards with compute(shard=...) or "
                         "compute(executor=...)")
    chain = robot.head_chain
    if robot.map_path is not None and not options:
        m = load(robot.map_path)  # what the map is: whole, and this head's; what it must hold is the caller's check
        return m.require_whole_for(robot, what=f"the robot file's map {os.fspath(robot.map_path)!r}")
    opts = {**default_map_options(chain), **options}
    key = ",".join(f"{k}={opts[k]!r}" for k in sorted(opts))
    digest = hashlib.sha1(f"{chain.hash}|{key}".encode()).hexdigest()[:16]
    path = cache_dir() / f"map-{chain.base}-{chain.tip}-{digest}.npz"
    if cache and path.is_file():
        try:
            return load(path).require_whole_for(robot)
        except InputError:
            pass  # a damaged cache entry (or a file that is not this head's whole map) is recomputed
    m = compute(chain, progress=progress, **opts)
    if cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        save(m, path)
        m.path = path
    return m


__all__ = ["default_map_options", "cache_dir", "map_for"]
