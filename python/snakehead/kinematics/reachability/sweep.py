"""Computing a head's reachability map: the paper's Algorithm 1 (Section 2.2), run by the C++ core
(``workspace.hpp``; also the standalone ``workspace_gen``).

Random configurations give a cloud of tip positions; voxels of a cube of side 2 * reach centred on the chain's base
that lie inside the cloud's boundary (the paper's ``boundary(P)``: an alpha shape chosen from a shrink factor as
MATLAB's ``boundary`` chooses it, ``alpha_shape.hpp``; or the convex hull) get the reachability index over N points
spread evenly on the voxel's inscribed sphere (:mod:`.voxel_sphere`). At each point a frame's approach axis (the
head's x-axis by default, or z as in the paper's Table 1) runs from the sphere's centre to the point; the frame is
rolled R times about it, and the point is reached when TRAC-IK solves one of the rolled frames (the paper's rule;
``any_roll=False`` counts every frame instead), or with ``free_roll`` one IK call leaves the roll free. Everything
is in the chain's base frame (for the head, ``neck_end``: B0).

:func:`compute` runs the sweep here (with a progress bar) or spreads its shards over an executor and merges them;
:func:`evaluate` checks voxels one by one, as Algorithm 1 states it.
"""
from __future__ import annotations

import inspect
import os
from typing import Any

import numpy as np
import numpy.typing as npt

from ... import _core
from ... import sweep_defaults as defaults
from ..._errors import InputError, InputTypeError
from ..._executors import as_executor, run_tasks, worker_count
from ...model.chain import Chain
from ...model.robot import SnakeRobot
from .map_io import merge
from .reachability_map import MAP_PARAMETERS, ReachabilityMap
from .sweep_options import MAX_SHARDS, check_grid, checked_count, core_options, mapped_chain


def check_options(chain_or_robot: Chain | SnakeRobot, **options: Any) -> _core.WorkspaceOptions:
    """The checks :func:`compute` makes of its options before any work (``voxel``, ``directions``, ``rolls``,
    ``any_roll``, ``free_roll``, ``approach_axis``, ``timeout``, ``epsilon``, ``cloud_samples``, ``seed``, ``threads``,
    ``shard``, ``hull``, ``shrink``; compute's defaults for those not given), against the limits above and the chain's
    reach: InputError naming the first bad one. Returns the core's options."""
    chain = mapped_chain(chain_or_robot)
    names = ("voxel", "directions", "rolls", "any_roll", "free_roll", "approach_axis", "timeout", "epsilon",
             "cloud_samples", "seed", "threads", "shard", "hull", "shrink")
    given = {k: v.default for k, v in inspect.signature(compute).parameters.items() if k in names}
    unknown = sorted(set(options) - set(given))
    if unknown:
        raise InputError(f"unknown option {unknown[0]!r} (the options are {', '.join(given)})")
    o = core_options(**{**given, **options})
    check_grid(chain, o.voxel_size)
    return o


def _from_result(d: dict, o: _core.WorkspaceOptions, command: str) -> ReachabilityMap:
    """The map (or shard) of the core's sweep result ``d``, made with the options ``o``."""
    params = {p: getattr(o, p) for p in MAP_PARAMETERS}
    params["rolls"] = 0 if o.free_roll else o.rolls
    params["shrink"] = o.map_shrink  # 0 for the convex hull
    return ReachabilityMap(
        centers=np.asarray(d["centers"], dtype=float).reshape(-1, 3),
        solved=np.asarray(d["solved"], dtype=np.int32),
        voxel_ids=np.asarray(d["voxel_ids"], dtype=np.int64),
        tried=int(d["tried"]),
        grid_origin=np.asarray(d["grid_origin"], dtype=float),
        grid_size=float(d["grid_size"]),
        grid_shape=tuple(int(x) for x in d["grid_shape"]),
        hull_voxels=int(d["hull_voxels"]),
        chain_hash=str(d["chain_hash"]),
        base=str(d["base"]),
        tip=str(d["tip"]),
        params=params,
        shard=(o.shard_index, o.shard_count),
        command=command,
        stats={"ik_calls": int(d["ik_calls"]), "cheap_exits": int(d["cheap_exits"]), "seconds": float(d["seconds"]),
               "threads": int(d["threads"]), "hull_facets": int(d["hull_facets"]), "reach": float(d["reach"]),
               "alpha": float(d["alpha"])},
        reached=np.asarray(d["reached"], dtype=np.uint8),
    )


def _compute_shard(urdf: str, base: str, tip: str, kwargs: dict, index: int, count: int) -> ReachabilityMap:
    """One shard in a worker (module level, so that executors can pickle it)."""
    chain = Chain.from_urdf(urdf, base, tip)
    o = core_options(shard=(index, count), **kwargs)
    d = _core.compute_reachability(chain.model, o)
    return _from_result(d, o, f"snakehead.workspace.compute(shard={index}/{count})")


def compute(chain_or_robot: Chain | SnakeRobot, *, voxel: float = defaults.HEAD_VOXEL_M,
            directions: int = defaults.HEAD_DIRECTIONS, rolls: int = defaults.HEAD_ROLLS, any_roll: bool = True,
            free_roll: bool = False, approach_axis: str = "x", timeout: float = defaults.HEAD_TIMEOUT_S,
            epsilon: float = defaults.HEAD_EPSILON, cloud_samples: int = defaults.HEAD_CLOUD_SAMPLES,
            seed: int = defaults.HEAD_SEED, hull: str = "boundary", shrink: float = defaults.HEAD_SHRINK,
            threads: int | None = None, shard: Any = None, executor: Any = None, shards: int | None = None,
            urdf: str | os.PathLike | None = None, progress: bool = True) -> ReachabilityMap:
    """Compute a reachability map (Algorithm 1) of a chain, or of a SnakeRobot's head chain.

    hull: which voxels are evaluated: those inside the cloud's ``"boundary"`` (the paper's boundary(P): the
    alpha shape MATLAB's ``boundary`` chooses for the shrink factor ``shrink``, 0.5 being MATLAB's default) or
    inside its ``"convex"`` hull.

    voxel: voxel edge (m); directions: points per voxel sphere; rolls: frames about the approach axis per
    point; any_roll: a point counts when one of its rolls is solved (the paper) rather than each frame on its
    own; free_roll: one IK call per point with the roll free; approach_axis: 'x' (the head's direction) or
    'z'; timeout: TRAC-IK budget per call (s; seeded, so an evaluation budget: the map does not depend on
    the machine's load); seed: the map is a function of it; threads: worker threads (None:
    ``snakehead.core_threads()``; the map does not depend on it); shard: (i, N) or 'i/N' to compute only every
    N-th tile of voxels.

    executor: any ``concurrent.futures.Executor`` (a process pool, Dask's ``client.get_executor()``...) or a Dask
    ``distributed.Client`` (``snakehead._executors``, the one way work is spread):
    the map is split into ``shards`` shards (default 4 per worker thread the executor reports, else 8),
    each computed in a worker with ``threads`` threads (default 1) and merged; the result equals the
    one-process map. Workers rebuild the chain from the URDF: a SnakeRobot carries it; for a Chain pass
    ``urdf=``.
    progress: a tqdm progress bar on stderr. The sweep runs without the GIL; Ctrl-C stops it.
    """
    chain = mapped_chain(chain_or_robot)
    kwargs = dict(voxel=voxel, directions=directions, rolls=rolls, any_roll=any_roll, free_roll=free_roll,
                  approach_axis=approach_axis, timeout=timeout, epsilon=epsilon, cloud_samples=cloud_samples,
                  seed=seed, threads=threads, hull=hull, shrink=shrink)
    options = check_options(chain, shard=shard, **kwargs)  # everything, before any work
    if executor is None:
        if shards is not None:
            raise InputError("shards= needs an executor; use shard=(i, N) to compute one shard here")
        return _compute_local(chain, options, progress)
    if shard is not None:
        raise InputError("give either shard= (one shard here) or executor= (all shards there), not both")
    return _compute_distributed(chain_or_robot, urdf, kwargs, executor, shards, progress)


def _compute_distributed(chain_or_robot: Chain | SnakeRobot, urdf: str | os.PathLike | None, kwargs: dict,
                         executor: Any, shards: int | None, progress: bool) -> ReachabilityMap:
    """The map as ``shards`` shards computed by ``executor``'s workers from the URDF (:func:`urdf_text`), merged."""
    chain = mapped_chain(chain_or_robot)
    executor = as_executor(executor)
    n = (min(_default_shards(executor), MAX_SHARDS) if shards is None else
         checked_count("shards", shards, 1, MAX_SHARDS))
    text = urdf_text(chain_or_robot, urdf)
    if Chain.from_urdf(text, chain.base, chain.tip).hash != chain.hash:
        raise InputError("the URDF given does not describe this chain (different kinematics hash)")
    if kwargs["threads"] is None:
        kwargs["threads"] = 1  # each shard is one task; the executor provides the parallelism
    bar = _bar(progress, int(n), "shards")
    try:
        parts = run_tasks(executor, _compute_shard, [(text, chain.base, chain.tip, kwargs, i, int(n))
                                                     for i in range(int(n))],
                          None if bar is None else lambda i, part: bar.update(1))
    finally:
        if bar is not None:
            bar.close()
    merged = merge(parts)
    merged.command = f"snakehead.workspace.compute(executor={type(executor).__name__}, shards={n})"
    return merged


def _default_shards(executor: Any) -> int:
    """4 shards per worker thread the executor reports, else 8."""
    workers = worker_count(executor)
    return 4 * workers if workers else 8


def urdf_text(chain_or_robot: Chain | SnakeRobot, urdf: str | os.PathLike | None) -> str:
    """The URDF (XML text) the workers of :func:`compute` rebuild the chain from: ``urdf`` (a path or the XML) or
    else the robot's or chain's own; a file is read with :meth:`Chain.from_urdf`'s checks (InputError unless a
    regular file of bounded size)."""
    source = urdf if urdf is not None else getattr(chain_or_robot, "urdf", None)
    if source is None:
        raise InputError("compute(..., executor=...) rebuilds the chain in the workers from its URDF: "
                         "pass a SnakeRobot or a Chain made by Chain.from_urdf, or urdf= (a path or the XML)")
    source = os.fspath(source) if isinstance(source, os.PathLike) else source
    if not isinstance(source, str):
        raise InputTypeError("urdf must be a path or an XML string")
    if source.lstrip().startswith("<"):
        return source
    return _core.read_urdf_file(source)  # InputError unless a regular file of bounded size, as Chain.from_urdf


def _bar(progress: bool, total: int, unit: str) -> Any:
    """A tqdm progress bar on stderr of ``total`` ``unit``s, or None without progress."""
    if not progress:
        return None
    from tqdm.auto import tqdm  # (0.1 s to import: only when a bar is shown)

    return tqdm(total=total, unit=unit, desc="reachability", leave=False)


def _compute_local(chain: Chain, options: Any, progress: bool) -> ReachabilityMap:
    """The map (or one shard) computed here by the core's sweep, with a progress bar of voxels."""
    bar = _bar(progress, 0, "voxel")

    # called about every 0.1 s; the binding checks for Ctrl-C before each call
    def callback(done: int, total: int) -> bool:
        return True

    if bar is not None:
        def callback(done: int, total: int) -> bool:
            if bar.total != total:
                bar.total = total
                bar.refresh()
            bar.update(done - bar.n)
            return True
    try:
        d = _core.compute_reachability(chain.model, options, callback)
    finally:
        if bar is not None:
            bar.close()
    return _from_result(d, options, "snakehead.workspace.compute")


def evaluate(chain_or_robot: Chain | SnakeRobot, centers: npt.ArrayLike, *, voxel: float = defaults.HEAD_VOXEL_M,
             directions: int = defaults.HEAD_DIRECTIONS, rolls: int = defaults.HEAD_ROLLS, any_roll: bool = True,
             free_roll: bool = False, approach_axis: str = "x", timeout: float = defaults.HEAD_TIMEOUT_S,
             epsilon: float = defaults.HEAD_EPSILON, seed: int = defaults.HEAD_SEED,
             threads: int | None = None) -> np.ndarray:
    """Reachability index of voxels at arbitrary centres, each on its own and as Algorithm 1 states it (every
    frame from a random initial guess with the full budget: none of the sweep's shortcuts).

    An independent check of a map (e.g. with a long timeout on a sample of its voxels), (k,) for (k, 3).
    """
    chain = mapped_chain(chain_or_robot)
    c = np.ascontiguousarray(np.atleast_2d(np.asarray(centers, dtype=float)))
    if c.ndim != 2 or c.shape[1] != 3 or not np.all(np.isfinite(c)):
        raise InputError("centers must be finite, shape (k, 3)")
    o = core_options(voxel, directions, rolls, any_roll, free_roll, approach_axis, timeout, epsilon, 100, seed, threads,
                     None)
    d = _core.evaluate_voxels(chain.model, o, c, list(range(len(c))))
    return 100.0 * np.asarray(d["solved"]) / d["tried"]


__all__ = ["compute", "evaluate", "check_options", "urdf_text"]
