"""Reachability maps: the paper's Algorithm 1 (Section 2.2), the dexterous workspace and its centre (2.3).

The sweep runs in the C++ core (``workspace.hpp``; also the standalone ``workspace_gen``): random
configurations give a cloud of tip positions; voxels of a cube of side 2 * reach centred on the chain's
base that lie inside the cloud's boundary (the paper's ``boundary(P)``: an alpha shape chosen from a shrink
factor as MATLAB's ``boundary`` chooses it, ``alpha_shape.hpp``; or the convex hull) get the reachability index

    D = 100 * (points reached) / (points tried)

over N points spread evenly (a Fibonacci lattice) on the voxel's inscribed sphere. At each point a frame's
approach axis (the head's x-axis by default, or z as in the paper's Table 1) runs from the sphere's centre
to the point; the frame is rolled R times about it, and the point is reached when TRAC-IK solves one of the
rolled frames (the paper's rule; ``any_roll=False`` counts every frame instead), or with ``free_roll`` one
IK call leaves the roll free. Everything is in the chain's base frame (for the head, ``neck_end``: B0).

A map keeps which directions (or frames) of each voxel were reached, so that it answers whether poses are
reachable (:meth:`ReachabilityMap.reachable`) and where the head's base frame may be for a target
(:meth:`ReachabilityMap.inverse`; ``map_queries.py``).

A map file is an ``.npz`` that ``numpy.load`` reads (``allow_pickle=False``); see ``save`` for its keys. One
writer makes them all: the C++ core's (``save_npz``), for ``workspace_gen`` and :func:`save` alike.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Sequence

import numpy as np

from ... import _core, limits
from ... import sweep_defaults as defaults
from ..._errors import InputError, InputTypeError
from ..._executors import as_executor, run_tasks, worker_count
from ...model.chain import Chain

if TYPE_CHECKING:
    from ...model.robot import SnakeRobot
    from .map_queries import BaseFrameCandidates

import numpy.typing as npt

FORMAT = "snakehead-reachability-2"
#: Formats :func:`load` reads: the first lacks the per-direction results and the hull's kind (always convex).
FORMATS = ("snakehead-reachability-1", FORMAT)
#: What a map answers (its ``kind``): the head chain's reach (Algorithm 1: ``snakehead workspace``, in the head's base
#: frame) or the whole body's stable reach (``snakehead reach``, ``planning.whole_body_reach``: poses a stable, collision-free
#: whole-body pose reaches, in the world frame of a base starting at ``BasePlacement()``).
KIND_HEAD, KIND_WHOLE_BODY = "head", "whole-body"
MAP_KINDS = (KIND_HEAD, KIND_WHOLE_BODY)
_KIND_HINTS = {KIND_HEAD: "a head map (snakehead workspace)",
               KIND_WHOLE_BODY: "a whole-body stable reachability map (snakehead reach)"}
#: Table 2's bins of the reachability index: [0,20) [20,40) [40,60) [60,80) [80,100].
TABLE2_BINS = (0.0, 20.0, 40.0, 60.0, 80.0, 100.0)
#: How many voxels the dexterous band must hold at least, as a share of the map's voxels (see
#: :meth:`ReachabilityMap.dexterous_threshold`): the paper's dexterous workspace holds 3.69 % of its map's voxels.
DEXTEROUS_MIN_SHARE = 0.01

# The limits of a sweep's options, checked in Python before any work (an InputError naming the option, never a
# number handed to the bindings' 32- or 64-bit fields). The upper ones are the C++ core's (snakehead.limits, read from
# include/snakehead/limits.hpp); the others are this module's.
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
#: Voxels the dexterous centre G0 needs at least: its k-means++ makes three clusters (Section 2.3).
G0_MIN_VOXELS = 3
_MERGE_HINT = ("merge the shards (snakehead workspace --merge SHARD.npz ... --out MAP.npz, or "
               "snakehead.kinematics.reachability.reachability_map.merge) and use the merged map")

# Parameters that define a map (two maps, or shards, with the same values are parts of one computation).
_PARAMS = ("voxel_size", "directions", "rolls", "any_roll", "free_roll", "approach_axis", "timeout", "epsilon",
           "cloud_samples", "seed", "hull", "shrink")
_STATS = ("ik_calls", "cheap_exits", "seconds", "threads")


@dataclass
class Clusters:
    """k-means++ clusters of the dexterous voxels and the chosen centre G0 (Section 2.3)."""

    points: np.ndarray  # (m, 3) the dexterous voxel centres (m)
    labels: np.ndarray  # (m,) cluster of each point, 0..k-1, ordered by decreasing size
    centroids: np.ndarray  # (k, 3) (m, chain base frame)
    sizes: np.ndarray  # (k,) voxels per cluster
    chosen: int  # the cluster whose centroid is G0
    rule: str

    @property
    def center(self) -> np.ndarray:
        """G0: the chosen centroid, (3,) in the chain's base frame."""
        return self.centroids[self.chosen].copy()


@dataclass
class ReachabilityMap:
    """A reachability map (or one shard of it): the in-hull voxels, their centres and indices.

    Arrays are ordered by ``voxel_ids`` (the grid's linear index (i * n + j) * n + l, i along x).
    """

    centers: np.ndarray  # (M, 3) voxel centres in the chain base frame (m)
    solved: np.ndarray  # (M,) int: points reached per voxel
    voxel_ids: np.ndarray  # (M,) int64
    tried: int  # points (or frames) per voxel
    grid_origin: np.ndarray  # (3,) the grid's minimum corner (m)
    grid_size: float  # the grid's side (m)
    grid_shape: tuple  # (n, n, n)
    hull_voxels: int  # in-hull voxels of the whole map (all shards)
    chain_hash: str
    base: str
    tip: str
    params: dict  # voxel_size, directions, rolls, any_roll, free_roll, approach_axis, timeout, epsilon, ...
    shard: tuple = (0, 1)  # (i, N)
    command: str = ""  # how the map was made
    stats: dict = field(default_factory=dict)  # ik_calls, cheap_exits, seconds, threads, hull_facets, reach, alpha
    path: Path | None = None  # the file it was loaded from or saved to, when there is one
    # (M, ceil(tried / 8)) uint8: which units (directions, or frames) of each voxel were reached, bit u of unit u
    # (numpy.unpackbits(..., bitorder="little")); None for a map file that predates them.
    reached: np.ndarray | None = None
    lacks: tuple = ()  # what an older map file does not hold (e.g. "reached"), said by load
    kind: str = KIND_HEAD  # one of MAP_KINDS: what the map answers
    # a whole-body map's witnesses, per voxel and unit (NaN where not reached; None when not known): the base's
    # flat-shape joints (M, tried, k) (rad, the joints before the neck lifts) and its placement (M, tried, 3)
    # (x m, y m, yaw rad) with which the pose is reached
    base_joints: np.ndarray | None = None
    base_placements: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    # --- the index --------------------------------------------------------------------------------
    @property
    def indices(self) -> np.ndarray:
        """(M,) reachability index D in [0, 100]."""
        return 100.0 * self.solved / self.tried

    @property
    def voxel_size(self) -> float:
        return float(self.params["voxel_size"])

    def __len__(self) -> int:
        return len(self.voxel_ids)

    # --- what the map is, and whether it is what a caller needs ------------------------------------------
    def require_whole_for(self, chain: Chain | SnakeRobot | None = None, *, needs: Iterable[str] = (),
                          what: str | None = None, kind: str = KIND_HEAD) -> ReachabilityMap:
        """The one check of a map where it is accepted: returns the map, or raises :class:`InputError` (one line
        naming the map and what to do) when it is

        * a shard of a map: its G0, dexterous band and queries would be those of a part of the map (shards load, and
          :func:`merge` takes them as they are: the one place that does);
        * a map of another chain than ``chain`` (a :class:`Chain`, or a SnakeRobot's head chain), by the chains'
          kinematics hash;
        * lacking what the caller ``needs``: ``"voxels"`` (at least one), ``"G0"`` (the dexterous centre:
          :data:`G0_MIN_VOXELS` voxels for its k-means++ clusters), ``"poses"`` (pose queries, inverse reachability,
          base placements: per-direction results, of directions of the head's pointing axis x, in some voxel).

        * of another ``kind`` (:data:`MAP_KINDS`) than the caller takes: a head map where the whole body's stable
          reach is asked for, or the reverse (for a whole-body map, ``chain`` is the robot, checked by its body
          chain's hash).

        ``what``: how the caller names the map (e.g. ``"--map 'm.npz'"``; default: its file, when it has one)."""
        name = what or (f"map {os.fspath(self.path)!r}" if self.path is not None else "the map")
        if kind not in MAP_KINDS:
            raise InputError(f"kind must be one of {', '.join(map(repr, MAP_KINDS))}, got {kind!r}")
        if self.kind != kind:
            raise InputError(f"{name} is {_KIND_HINTS.get(self.kind, repr(self.kind))}, not "
                             f"{_KIND_HINTS[kind]}: give {_KIND_HINTS[kind]}")
        needs = tuple(needs)
        unknown = [n for n in needs if n not in ("voxels", "G0", "poses")]
        if unknown:
            raise InputError(f"needs may hold 'voxels', 'G0' and 'poses', got {unknown[0]!r}")
        if tuple(self.shard) != (0, 1):
            i, n = self.shard
            raise InputError(f"{name} is shard {i}/{n} of a map, not a whole map ({len(self)} of its "
                             f"{self.hull_voxels} voxels): {_MERGE_HINT}")
        if chain is not None and kind == KIND_WHOLE_BODY:
            _require_body(self, chain, name)
        elif chain is not None:
            from ...model.robot import SnakeRobot

            head = _resolve_chain(chain)
            if self.chain_hash != head.hash:
                mine = (f"{chain.parts.neck_end} -> {chain.parts.head_tip}" if isinstance(chain, SnakeRobot) else
                        f"{head.base} -> {head.tip}")
                raise InputError(f"{name} was made for another head chain ({self.base} -> {self.tip}, hash "
                                 f"{self.chain_hash}); this robot's head is {mine} (hash {head.hash}): compute its map "
                                 "(snakehead workspace --robot ROBOT.toml --out MAP.npz)")
        if needs and len(self) == 0:
            raise InputError(f"{name} holds no voxels (no voxel of its grid lies inside the chain's workspace): "
                             "compute it again with a smaller voxel")
        if "G0" in needs and len(self) < G0_MIN_VOXELS:
            raise InputError(f"{name} holds {len(self)} voxels; the dexterous centre G0 needs at least "
                             f"{G0_MIN_VOXELS} (its k-means++ clusters): compute it again with a smaller voxel")
        if "poses" in needs:
            if self.reached is None:
                raise InputError(f"{name} holds no per-direction results (a map file of the first format), which "
                                 "pose queries need: compute it again (snakehead workspace)")
            axis = self.params.get("approach_axis", "x")
            if axis != "x":
                raise InputError(f"{name} was swept with the approach axis {axis!r}, not the head's pointing axis x, "
                                 "which pose queries take the directions along: compute it again with "
                                 "approach_axis='x'")
        return self

    def histogram(self, bins: Sequence[float] = TABLE2_BINS) -> tuple[np.ndarray, np.ndarray]:
        """Voxel counts and percentages per bin, Table 2's bins by default; the last bin is closed ([80, 100])."""
        from ..._validate import finite_array

        edges = finite_array(bins, "bins", (None,))  # NaN edges passed the test below and gave negative counts
        if len(edges) < 2 or np.any(np.diff(edges) <= 0):
            raise InputError(f"bins must be an increasing sequence of at least two edges, got {edges.tolist()}")
        counts, _ = np.histogram(self.indices, bins=edges)  # numpy's last bin is closed
        pct = 100.0 * counts / max(len(self), 1)
        return counts, pct

    @property
    def sphere_directions(self) -> np.ndarray:
        """(N, 3) the unit directions of every voxel's sphere (the sweep's Fibonacci lattice)."""
        if "directions" not in self._cache:
            self._cache["directions"] = fibonacci_directions(int(self.params["directions"]))
        return self._cache["directions"]

    def reached_units(self) -> np.ndarray:
        """(M, tried) bool: which units of each voxel were reached (directions, or (direction, roll) frames
        when every roll counted on its own). InputError for a map file without them."""
        if self.reached is None:
            raise InputError("this map holds no per-direction results (a map file of the first format); "
                             "recompute it (workspace_gen or compute) to query poses")
        return np.unpackbits(self.reached, axis=1, count=self.tried, bitorder="little").astype(bool)

    def reachable(self, positions: npt.ArrayLike, directions: npt.ArrayLike, *,
                  interpolate: bool = True) -> np.ndarray | bool:
        """Whether the head's tip can be at each position pointing along each direction (any roll), by the map.

        positions, directions: (3,) or (K, 3) in the map's base frame (directions need not be unit); returns a
        bool, or (K,) bools. By default the neighbouring voxels and directions are blended
        (``map_queries.reachability``); ``interpolate=False``: the nearest voxel and direction. See
        ``map_queries.py``."""
        from .map_queries import reachable

        return reachable(self, positions, directions, interpolate=interpolate)

    def inverse(self, position: npt.ArrayLike, direction: npt.ArrayLike, **options: Any) -> BaseFrameCandidates:
        """Candidate poses of the map's base frame (B0) from which the head reaches a target; see
        ``map_queries.inverse``."""
        from .map_queries import inverse

        return inverse(self, position, direction, **options)

    def index_at(self, points: npt.ArrayLike) -> np.ndarray:
        """Index of the voxel containing each point (0 outside the map's voxels), (k,) for (k, 3) points. A shard
        is refused: the points of its other shards' voxels would read 0."""
        self.require_whole_for()
        p = np.atleast_2d(np.asarray(points, dtype=float))
        if p.shape[-1] != 3 or not np.all(np.isfinite(p)):
            raise InputError("points must be finite, shape (3,) or (k, 3)")
        n = self.grid_shape[0]
        ijk = np.floor((p - self.grid_origin) / self.voxel_size).astype(np.int64)
        inside = np.all((ijk >= 0) & (ijk < n), axis=1)
        ids = (ijk[:, 0] * n + ijk[:, 1]) * n + ijk[:, 2]
        pos = np.searchsorted(self.voxel_ids, ids)
        pos = np.clip(pos, 0, max(len(self) - 1, 0))
        found = inside & (len(self) > 0) & (self.voxel_ids[pos] == ids) if len(self) else np.zeros(len(p), bool)
        out = np.zeros(len(p))
        out[found] = self.indices[pos[found]]
        return out

    # --- Section 2.3 ---------------------------------------------------------------------------------
    def dexterous_threshold(self, min_voxels: int | None = None) -> float:
        """The index that bounds the dexterous workspace from below: 100 (the paper, Section 2.3) when enough
        voxels reach it, else the best band the map has.

        Returns the highest index level t such that at least ``min_voxels`` voxels have an index >= t (default:
        3, the paper's clusters, or 1 % of the map's voxels if more). A head that reaches no voxel at 100 (most
        6-DOF heads) thus still gets a dexterous workspace and a centre G0, in its most reachable band.
        """
        self.require_whole_for(needs=("voxels",))  # a shard's band and G0 are not the map's
        need = max(3, int(np.ceil(DEXTEROUS_MIN_SHARE * len(self)))) if min_voxels is None else int(min_voxels)
        if need < 1:
            raise InputError(f"min_voxels must be >= 1, got {min_voxels!r}")
        need = min(need, len(self))
        levels = np.sort(self.indices)[::-1]  # descending
        return float(min(100.0, levels[need - 1]))

    def quality_problem(self) -> str | None:
        """Why the map's dexterous band says little (None when it is fine): a best band of index 0 (the head reaches
        none of its directions from enough voxels; G0 is then the middle of every reached voxel), with what to do."""
        if len(self) == 0 or self.shard != (0, 1) or self.dexterous_threshold() > 0:
            return None
        hint = ("" if self.params.get("free_roll") else "; a head of fewer than 6 joints cannot turn about its own "
                "axis to the rolls tried: compute the map with free roll (snakehead workspace --free-roll)")
        return ("the map's best band has index 0: the head reaches none of its directions from enough voxels, so "
                f"its dexterous workspace is every voxel it reaches{hint}")

    def summary(self) -> str:
        """A few lines: the chain, the grid, Table 2's bands, the dexterous band and its centre G0."""
        _, pct = self.histogram()
        lines = [repr(self),
                 "Table 2 bands [0,20) [20,40) [40,60) [60,80) [80,100]: " + " ".join(f"{p:.2f} %" for p in pct)]
        if len(self) == 0:
            lines.append("no voxels")
            return "\n".join(lines)
        if self.shard != (0, 1):
            lines.append(f"shard {self.shard[0]}/{self.shard[1]}: the dexterous workspace and G0 are those of the "
                         f"whole map ({_MERGE_HINT})")
            return "\n".join(lines)
        t = self.dexterous_threshold()
        lines.append(f"max index {self.indices.max():.1f}; dexterous workspace: "
                     + ("index 100 (the paper's)" if t >= 100.0 else
                        f"no voxel reaches 100 in enough number, so the best band, index >= {t:.1f}")
                     + f" ({int(np.sum(self.indices >= t - 1e-9))} voxels)")
        if self.quality_problem():
            lines.append(f"note: {self.quality_problem()}")
        try:
            lines.append(f"G0 = {np.round(self.center(), 4).tolist()} m in the {self.base!r} frame")
        except ValueError as exc:
            lines.append(f"G0: {exc}")
        return "\n".join(lines)

    def dexterous(self, threshold: float | None = 100.0) -> np.ndarray:
        """Centres of the voxels whose index is at least ``threshold`` (100: the dexterous workspace; None: the
        best band, :meth:`dexterous_threshold`), (m, 3)."""
        t = self.dexterous_threshold() if threshold is None else float(threshold)
        if not 0.0 <= t <= 100.0:
            raise InputError(f"threshold must be within [0, 100], got {threshold}")
        return self.centers[self.indices >= t - 1e-9]

    def clusters(self, k: int = 3, threshold: float | None = None, rule: str = "largest",
                 random_state: int = 0) -> Clusters:
        """k-means++ clusters of the dexterous voxels (Eqs. 16-17) and the centre G0.

        ``threshold``: the dexterous workspace's lower index (default None: :meth:`dexterous_threshold`, 100
        whenever enough voxels reach it).

        The paper splits its dexterous workspace into three clusters and picks the centroid of one of
        them by eye. The rule here (``rule="largest"``) takes the centroid of the largest cluster: the
        most voxels of full reachability lie around it, so the head keeps the most room to reach
        targets in every direction when the neck puts a target there, and the choice is stable under
        small changes of the map. ``rule="index"`` takes the cluster whose centroid falls in the voxel
        of highest index (a centroid can fall between the voxels of a curved cluster), ties broken by size.
        """
        from .kmeans import kmeans

        self.require_whole_for()  # the clusters of a shard's voxels are not the map's (G0 moved by 37 cm)
        if not isinstance(k, (int, np.integer)) or k < 1:
            raise InputError(f"k must be a positive integer, got {k!r}")
        if rule not in ("largest", "index"):
            raise InputError(f"rule must be 'largest' or 'index', got {rule!r}")
        threshold = self.dexterous_threshold() if threshold is None else float(threshold)
        pts = self.dexterous(threshold)
        if len(pts) < k:
            raise InputError(f"{len(pts)} voxels have an index >= {threshold}; {k} clusters need at least {k}")
        km = kmeans(pts, int(k), n_init=10, random_state=random_state)  # scikit-learn's KMeans, without its import
        sizes = np.bincount(km.labels, minlength=k)
        # Order clusters by decreasing size (then by centroid coordinates) so that labels are stable.
        order = sorted(range(k), key=lambda c: (-sizes[c], *km.centers[c]))
        relabel = np.empty(k, dtype=int)
        relabel[order] = np.arange(k)
        centroids = km.centers[order]
        sizes = sizes[order]
        if rule == "largest":
            chosen = 0
        else:
            at = self.index_at(centroids)
            chosen = int(max(range(k), key=lambda c: (at[c], sizes[c])))
        return Clusters(pts, relabel[km.labels], centroids, sizes, chosen, rule)

    def center(self, k: int = 3, threshold: float | None = None, rule: str = "largest",
               random_state: int = 0) -> np.ndarray:
        """G0, the centre of the dexterous workspace (see ``clusters``), (3,) in the chain's base frame."""
        return self.clusters(k, threshold, rule, random_state).center

    # --- files -------------------------------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> None:
        save(self, path)

    def same_map_as(self, other: "ReachabilityMap") -> bool:
        """Same chain, parameters, grid and per-voxel results (statistics and command aside)."""
        return (
            self.chain_hash == other.chain_hash
            and self.kind == other.kind
            and all(_param_equal(self.params[p], other.params[p]) for p in _PARAMS)
            and self.tried == other.tried
            and self.grid_shape == other.grid_shape
            and np.array_equal(self.voxel_ids, other.voxel_ids)
            and np.array_equal(self.solved, other.solved)
            and (self.reached is None) == (other.reached is None)
            and (self.reached is None or (other.reached is not None and np.array_equal(self.reached, other.reached)))
            and np.allclose(self.centers, other.centers, rtol=0, atol=1e-12)
        )

    def __repr__(self) -> str:
        s = "" if self.shard == (0, 1) else f", shard {self.shard[0]}/{self.shard[1]}"
        lacks = f", lacks {', '.join(self.lacks)}" if self.lacks else ""
        lacks += "" if self.kind == KIND_HEAD else f", {self.kind}"
        return (f"ReachabilityMap({self.base!r} -> {self.tip!r}, {len(self)} voxels of {self.voxel_size} m "
                f"inside the {self.params.get('hull', 'convex')} hull, {self.params['directions']} directions{s}, "
                f"mean index {self.indices.mean() if len(self) else 0:.1f}{lacks})")


def _require_body(m: ReachabilityMap, robot: Any, name: str) -> None:
    """InputError unless the whole-body map ``m`` was made for ``robot``'s body (by its body chain's hash)."""
    from ...model.robot import SnakeRobot

    if not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"a whole-body map is checked against a SnakeRobot, got {type(robot).__name__}")
    if m.chain_hash != robot.body.hash:
        raise InputError(f"{name} was made for another robot (body chain hash {m.chain_hash}; this robot's is "
                         f"{robot.body.hash}): compute its map (snakehead reach --robot ROBOT.toml)")


def require_map(m: Any, chain: Chain | SnakeRobot | None = None, *, needs: Iterable[str] = (),
                what: str = "the map", kind: str = KIND_HEAD) -> ReachabilityMap:
    """``m`` where a map is accepted: InputTypeError unless a :class:`ReachabilityMap`, then
    :meth:`ReachabilityMap.require_whole_for` (a whole map of ``chain``'s head holding what the caller ``needs``).
    ``what`` names the argument; the map's file is added when it has one."""
    if not isinstance(m, ReachabilityMap):
        raise InputTypeError(f"{what} must be a ReachabilityMap (snakehead.load_map or compute_map), got "
                             f"{type(m).__name__}")
    return m.require_whole_for(chain, needs=needs, kind=kind,
                               what=f"{what} (map {os.fspath(m.path)!r})" if m.path is not None else what)


def _param_equal(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        return float(a) == float(b)
    return a == b


# --- computing -------------------------------------------------------------------------------------------
def _count(name: str, value: Any, least: int, most: int, hint: str = "") -> int:
    """``value`` as an int within [least, most]: InputTypeError unless an integer (not a bool), InputError beyond."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputTypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    if not least <= int(value) <= most:
        raise InputError(f"{name} must be between {least} and {most}{hint}, got {value}")
    return int(value)


def _real(name: str, value: Any) -> float:
    """``value`` as a float: InputTypeError unless a number (not a bool); its range is the caller's to check."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputTypeError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    try:
        return float(value)
    except OverflowError:  # an int beyond a float
        raise InputError(f"{name} must be a finite number, got {value}") from None


def _options(voxel: float, directions: int, rolls: int, any_roll: bool, free_roll: bool, approach_axis: str,
             timeout: float, epsilon: float, cloud_samples: int, seed: int | None, threads: int | None, shard: Any,
             hull: str = "boundary", shrink: float = 0.5) -> _core.WorkspaceOptions:
    """The core's options, every value checked against the limits above first (InputError naming it)."""
    o = _core.WorkspaceOptions()
    directions = _count("directions", directions, 1, MAX_DIRECTIONS)
    rolls = _count("rolls", rolls, 0 if free_roll else 1, MAX_ROLLS, "" if free_roll else " (or use free roll)")
    if not free_roll and directions * rolls > MAX_FRAMES_PER_VOXEL:
        raise InputError(f"directions x rolls (frames per voxel) must be at most {MAX_FRAMES_PER_VOXEL}, got "
                         f"{directions} x {rolls} = {directions * rolls}")
    cloud_samples = _count("cloud_samples", cloud_samples, MIN_CLOUD_SAMPLES, MAX_CLOUD_SAMPLES,
                           " (the hull needs a cloud)")
    seed = _count("seed", seed, 0, MAX_SEED)
    threads = 0 if threads is None else _count("threads", threads, 0, MAX_THREADS, " (0 = snakehead.core_threads())")
    voxel, timeout, epsilon = _real("voxel", voxel), _real("timeout", timeout), _real("epsilon", epsilon)
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
    shrink = _real("shrink", shrink)
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


def check_options(chain_or_robot: Chain | SnakeRobot, **options: Any) -> _core.WorkspaceOptions:
    """The checks :func:`compute` makes of its options before any work (``voxel``, ``directions``, ``rolls``,
    ``any_roll``, ``free_roll``, ``approach_axis``, ``timeout``, ``epsilon``, ``cloud_samples``, ``seed``, ``threads``,
    ``shard``, ``hull``, ``shrink``; compute's defaults for those not given), against the limits above and the chain's
    reach: InputError naming the first bad one. Returns the core's options."""
    import inspect

    chain = _resolve_chain(chain_or_robot)
    names = ("voxel", "directions", "rolls", "any_roll", "free_roll", "approach_axis", "timeout", "epsilon",
             "cloud_samples", "seed", "threads", "shard", "hull", "shrink")
    defaults = {k: v.default for k, v in inspect.signature(compute).parameters.items() if k in names}
    unknown = sorted(set(options) - set(defaults))
    if unknown:
        raise InputError(f"unknown option {unknown[0]!r} (the options are {', '.join(defaults)})")
    o = _options(**{**defaults, **options})
    _check_grid(chain, o.voxel_size)
    return o


def _check_grid(chain: Chain, voxel: float) -> None:
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


def _resolve_chain(chain_or_robot: Chain | SnakeRobot) -> Chain:
    from ...model.robot import SnakeRobot

    if isinstance(chain_or_robot, SnakeRobot):
        return chain_or_robot.head_chain
    if isinstance(chain_or_robot, Chain):
        return chain_or_robot
    if isinstance(chain_or_robot, _core.ChainModel):
        return Chain(chain_or_robot)
    raise InputTypeError(f"expected a Chain or a SnakeRobot (whose head chain is mapped), got "
                         f"{type(chain_or_robot).__name__}")


def _from_result(d: dict, o: _core.WorkspaceOptions, command: str) -> ReachabilityMap:
    params = {p: getattr(o, p) for p in _PARAMS}
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
    o = _options(shard=(index, count), **kwargs)
    d = _core.compute_reachability(chain.model, o)
    return _from_result(d, o, f"snakehead.workspace.compute(shard={index}/{count})")


def compute(chain_or_robot: Chain | SnakeRobot, *, voxel: float = defaults.HEAD_VOXEL_M,
            directions: int = defaults.HEAD_DIRECTIONS, rolls: int = defaults.HEAD_ROLLS, any_roll: bool = True,
            free_roll: bool = False, approach_axis: str = "x", timeout: float = defaults.HEAD_TIMEOUT_S,
            epsilon: float = defaults.HEAD_EPSILON, cloud_samples: int = defaults.HEAD_CLOUD_SAMPLES,
            seed: int = defaults.HEAD_SEED, hull: str = "boundary", shrink: float = defaults.HEAD_SHRINK, threads: int | None = None, shard: Any = None, executor: Any = None,
            shards: int | None = None,
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
    ``snakehead.core_threads()``; the map does not depend on it); shard: (i, N) or 'i/N' to compute only every N-th tile of voxels.

    executor: any ``concurrent.futures.Executor`` (a process pool, Dask's ``client.get_executor()``...) or a Dask
    ``distributed.Client`` (``snakehead._executors``, the one way work is spread):
    the map is split into ``shards`` shards (default 4 per worker thread the executor reports, else 8),
    each computed in a worker with ``threads`` threads (default 1) and merged; the result equals the
    one-process map. Workers rebuild the chain from the URDF: a SnakeRobot carries it; for a Chain pass
    ``urdf=``.
    progress: a tqdm progress bar on stderr. The sweep runs without the GIL; Ctrl-C stops it.
    """
    chain = _resolve_chain(chain_or_robot)
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
    executor = as_executor(executor)
    n = min(_default_shards(executor), MAX_SHARDS) if shards is None else _count("shards", shards, 1, MAX_SHARDS)
    text = _urdf_text(chain_or_robot, urdf)
    if Chain.from_urdf(text, chain.base, chain.tip).hash != chain.hash:
        raise InputError("the URDF given does not describe this chain (different kinematics hash)")
    if threads is None:
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
    workers = worker_count(executor)
    return 4 * workers if workers else 8


def _urdf_text(chain_or_robot: Chain | SnakeRobot, urdf: str | os.PathLike | None) -> str:
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
    if not progress:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, unit=unit, desc="reachability", leave=False)


def _compute_local(chain: Chain, options: Any, progress: bool) -> ReachabilityMap:
    bar = _bar(progress, 0, "voxel")

    def callback(done: int, total: int) -> bool:  # called about every 0.1 s; the binding checks for Ctrl-C before each call
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
    chain = _resolve_chain(chain_or_robot)
    c = np.ascontiguousarray(np.atleast_2d(np.asarray(centers, dtype=float)))
    if c.ndim != 2 or c.shape[1] != 3 or not np.all(np.isfinite(c)):
        raise InputError("centers must be finite, shape (k, 3)")
    o = _options(voxel, directions, rolls, any_roll, free_roll, approach_axis, timeout, epsilon, 100, seed, threads,
                 None)
    d = _core.evaluate_voxels(chain.model, o, c, list(range(len(c))))
    return 100.0 * np.asarray(d["solved"]) / d["tried"]


# --- files -----------------------------------------------------------------------------------------------
def save(m: ReachabilityMap, path: str | os.PathLike) -> None:
    """Write ``m`` as an uncompressed .npz, by the one map writer (the C++ core's, which ``workspace_gen`` uses).

    Keys: format, centers (M,3), indices (M,), solved (M,), voxel_ids (M,), reached (M, ceil(tried/8)) uint8
    (absent when unknown), tried, sphere_directions (N,3), grid_origin (3,), grid_size, grid_shape (3,),
    hull_voxels, hull_facets, hull ('boundary' or 'convex'), shrink (0 for the convex hull), alpha (m; inf for the
    convex hull), reach, the parameters (voxel_size, directions, rolls, any_roll, free_roll, approach_axis,
    timeout, epsilon, cloud_samples, seed), shard (2,), chain_hash, base, tip, command, and the run's statistics
    (ik_calls, cheap_exits, seconds, threads; -1 or NaN when not known), map_kind (:data:`MAP_KINDS`; a file
    without it is a head map) and, for a whole-body map, base_joints (M, tried, k) and base_placements (M, tried, 3)
    (NaN where not reached; absent when not known).
    """
    if not isinstance(m, ReachabilityMap):
        raise InputTypeError(f"expected a ReachabilityMap, got {type(m).__name__}")
    path = os.fspath(path)
    if not path.endswith(".npz"):
        raise InputError(f"a map file ends in .npz, got {path!r}")
    p = m.params
    o = _options(p["voxel_size"], p["directions"], max(int(p["rolls"]), 1), p["any_roll"], p["free_roll"],
                 p["approach_axis"], p["timeout"], p["epsilon"], p["cloud_samples"], p["seed"], None, m.shard,
                 p.get("hull", "convex"), p.get("shrink", 0.0))
    n = int(m.grid_shape[0])
    stats = m.stats
    _core.save_map(
        path, m.command, o, np.ascontiguousarray(m.centers, dtype=float), m.solved.astype(np.int32).tolist(),
        m.voxel_ids.astype(np.int64).tolist(), None if m.reached is None else np.ascontiguousarray(m.reached, dtype=np.uint8),
        int(m.tried), np.asarray(m.grid_origin, dtype=float), float(m.grid_size) / n, n, int(m.hull_voxels),
        int(stats.get("hull_facets", -1)), float(stats.get("alpha", math.inf if o.hull == "convex" else math.nan)),
        float(stats.get("reach", math.nan)), m.chain_hash, m.base, m.tip, int(stats.get("ik_calls", -1)),
        int(stats.get("cheap_exits", -1)), float(stats.get("seconds", math.nan)), int(stats.get("threads", -1)),
        m.kind, _witness(m.base_joints), _witness(m.base_placements))
    m.path = Path(path)


def _witness(a: np.ndarray | None) -> np.ndarray | None:
    return None if a is None else np.ascontiguousarray(a, dtype=float)


#: The largest map file read (bytes, as its archive declares them unpacked). A full grid of 256^3 voxels -- the C++
#: sweep's limit -- holds at most 16.8 million voxels of about 50 bytes each: 840 MB.
MAX_MAP_BYTES = 1 << 30

# What each key of a map file holds: "text", "int", "bool" or "float" scalars; arrays by (kind, shape) with "M"
# the voxel count. Keys of the second format (reached, sphere_directions, hull, shrink, alpha) are optional.
_MAP_SCALARS = {
    "format": "text", "chain_hash": "text", "base": "text", "tip": "text", "command": "text", "approach_axis": "text",
    "tried": "int", "hull_voxels": "int", "directions": "int", "rolls": "int", "cloud_samples": "int", "seed": "int",
    "any_roll": "bool", "free_roll": "bool", "grid_size": "float", "voxel_size": "float", "timeout": "float",
    "epsilon": "float",
}
_MAP_OPTIONAL_SCALARS = {"map_kind": "text", "hull": "text", "shrink": "float", "alpha": "float", "reach": "float", "seconds": "float",
                         "ik_calls": "int", "cheap_exits": "int", "threads": "int", "hull_facets": "int"}
_MAP_ARRAYS = {"centers": ("f", ("M", 3)), "indices": ("f", ("M",)), "solved": ("i", ("M",)),
               "voxel_ids": ("i", ("M",)), "grid_origin": ("f", (3,)), "grid_shape": ("i", (3,)), "shard": ("i", (2,))}
_KINDS = {"text": "U", "int": "iu", "bool": "b", "float": "fiu"}


def validate_map_arrays(arrays: dict[str, np.ndarray], where: str = "the map") -> None:
    """Check the arrays of a map file (as :func:`snakehead._files.read_npz` returns them) before a map is made of
    them: InputError naming the field for a missing key, metadata of the wrong type, shapes that disagree, indices
    outside [0, 100] or not 100 * solved / tried, solved counts outside [0, tried], NaN or non-positive sizes,
    voxel ids duplicated, out of order or outside the grid, voxel centres that are not their voxels' centres,
    per-direction results of the wrong shape, and parameters beyond the sweep's limits. Either format (1 or 2)."""
    scalars = _check_map_fields(arrays, where)
    value = {k: arrays[k][()] for k in scalars}
    M = len(arrays["voxel_ids"])
    n, tried, directions = _check_map_parameters(arrays, value, M, where)
    _check_map_voxels(arrays, float(value["voxel_size"]), n, M, where)
    _check_map_results(arrays, tried, directions, M, where)


def _map_error(where: str, field: str, what: str) -> InputError:
    return InputError(f"{where}: {field} {what}")


def _check_map_fields(arrays: dict[str, np.ndarray], where: str) -> dict:
    """The format, every scalar's and array's presence and type, and the arrays' shapes; returns the scalars'
    kinds."""
    if "format" not in arrays or arrays["format"].dtype.kind != "U" or str(arrays["format"][()]) not in FORMATS:
        raise InputError(f"{where} is not a snakehead reachability map (its format is not one of "
                         f"{', '.join(FORMATS)})")
    scalars = dict(_MAP_SCALARS)
    for key, kind in _MAP_OPTIONAL_SCALARS.items():
        if key in arrays:
            scalars[key] = kind
    for key, kind in scalars.items():
        if key not in arrays:
            raise _map_error(where, key, "is missing")
        a = arrays[key]
        if a.shape != () or a.dtype.kind not in _KINDS[kind]:
            raise _map_error(where, key, f"must be one {kind} value, got {a.dtype} of shape {a.shape}")
    for key, (kind, shape) in _MAP_ARRAYS.items():
        if key not in arrays:
            raise _map_error(where, key, "is missing")
        a = arrays[key]
        if a.dtype.kind not in ("fiu" if kind == "f" else "iu") or a.ndim != len(shape):
            raise _map_error(where, key, f"must be an array of {'numbers' if kind == 'f' else 'integers'} of "
                                         f"shape {tuple(shape)}, got {a.dtype} of shape {a.shape}")
    M = len(arrays["voxel_ids"])
    for key, (kind, shape) in _MAP_ARRAYS.items():
        want = tuple(M if d == "M" else d for d in shape)
        if arrays[key].shape != want:
            raise _map_error(where, key, f"has shape {arrays[key].shape}; the map's {M} voxels need {want}")
    return scalars


def _check_map_parameters(arrays: dict[str, np.ndarray], value: dict, M: int, where: str) -> tuple[int, int, int]:
    """The sweep's parameters and the grid's: within their limits and consistent; returns the voxels per axis, the
    frames tried per voxel and the directions."""
    for key in ("grid_size", "voxel_size", "timeout", "epsilon"):
        if not (math.isfinite(float(value[key])) and float(value[key]) > 0):
            raise _map_error(where, key, f"must be a positive finite number, got {value[key]}")
    for key in ("centers", "indices", "grid_origin"):
        if not np.all(np.isfinite(arrays[key])):
            raise _map_error(where, key, "holds NaN or inf")
    if str(value["approach_axis"]) not in ("x", "z"):
        raise _map_error(where, "approach_axis", f"must be 'x' or 'z', got {str(value['approach_axis'])!r}")
    if "map_kind" in value and str(value["map_kind"]) not in MAP_KINDS:
        raise _map_error(where, "map_kind", f"must be one of {', '.join(MAP_KINDS)}, got {str(value['map_kind'])!r}")
    if "hull" in value and str(value["hull"]) not in ("convex", "boundary"):
        raise _map_error(where, "hull", f"must be 'convex' or 'boundary', got {str(value['hull'])!r}")
    if "shrink" in value and not 0.0 <= float(value["shrink"]) <= 1.0:  # NaN too
        raise _map_error(where, "shrink", f"must be within [0, 1], got {value['shrink']}")
    directions, rolls, tried = int(value["directions"]), int(value["rolls"]), int(value["tried"])
    if not 1 <= directions <= MAX_DIRECTIONS or not 0 <= rolls <= MAX_ROLLS:
        raise _map_error(where, "directions/rolls", f"must be within [1, {MAX_DIRECTIONS}] / [0, {MAX_ROLLS}], "
                                                    f"got {directions} / {rolls}")
    if tried not in (directions, directions * max(rolls, 1)):
        raise _map_error(where, "tried", f"must be the directions ({directions}) or directions x rolls, got {tried}")
    grid_shape = arrays["grid_shape"]
    if not (grid_shape[0] == grid_shape[1] == grid_shape[2] and 1 <= int(grid_shape[0]) <= MAX_VOXELS_PER_AXIS):
        raise _map_error(where, "grid_shape",
                         f"must be (n, n, n) with 1 <= n <= {MAX_VOXELS_PER_AXIS}, got {grid_shape.tolist()}")
    n = int(grid_shape[0])
    voxel = float(value["voxel_size"])
    if not math.isclose(float(value["grid_size"]), n * voxel, rel_tol=1e-9):
        raise _map_error(where, "grid_size",
                         f"must be grid_shape x voxel_size ({n} x {voxel}), got {value['grid_size']}")
    i, count = (int(x) for x in arrays["shard"])
    if not 0 <= i < count:
        raise _map_error(where, "shard", f"must be (i, N) with 0 <= i < N, got {(i, count)}")
    if not M <= int(value["hull_voxels"]) <= n ** 3:
        raise _map_error(where, "hull_voxels", f"must be within [{M} (the map's voxels), {n ** 3} (the grid's)], "
                                               f"got {value['hull_voxels']}")
    return n, tried, directions


def _check_map_voxels(arrays: dict[str, np.ndarray], voxel: float, n: int, M: int, where: str) -> None:
    """The voxel ids: strictly increasing within the grid; the centres: those voxels' centres."""
    ids = arrays["voxel_ids"]
    if M and (ids[0] < 0 or ids[-1] >= n ** 3 or np.any(np.diff(ids) <= 0)):
        if M and np.any(np.diff(ids) == 0):
            raise _map_error(where, "voxel_ids",
                             f"holds duplicates (voxel {int(ids[np.flatnonzero(np.diff(ids) == 0)[0]])})")
        raise _map_error(where, "voxel_ids", f"must increase strictly within [0, {n ** 3}) (the grid's {n}^3 voxels)")
    ijk = np.stack([ids // (n * n), (ids // n) % n, ids % n], axis=1)
    expected = np.asarray(arrays["grid_origin"], float) + (ijk + 0.5) * voxel
    if M and not np.allclose(arrays["centers"], expected, rtol=0.0, atol=1e-6 * max(voxel, 1.0)):
        raise _map_error(where, "centers",
                         "are not the centres of the voxels voxel_ids names (grid_origin + (ijk + 1/2) voxel)")


def _check_map_results(arrays: dict[str, np.ndarray], tried: int, directions: int, M: int, where: str) -> None:
    """The solved counts, the indices, the per-direction results and the bases: within range and consistent."""
    solved = arrays["solved"]
    if M and (solved.min() < 0 or solved.max() > tried):
        raise _map_error(where, "solved", f"must be within [0, tried = {tried}]")
    indices = np.asarray(arrays["indices"], float)
    if M and (indices.min() < 0 or indices.max() > 100):
        raise _map_error(where, "indices", f"must be within [0, 100], got [{indices.min():g}, {indices.max():g}]")
    if not np.allclose(indices, 100.0 * solved / tried, rtol=0.0, atol=1e-9):
        raise _map_error(where, "indices", "disagree with 100 * solved / tried")
    if "reached" in arrays:
        r = arrays["reached"]
        if r.dtype != np.uint8 or r.shape != (M, (tried + 7) // 8):
            raise _map_error(where, "reached",
                             f"must be uint8 of shape ({M}, {(tried + 7) // 8}), got {r.dtype} {r.shape}")
        bits = np.unpackbits(r, axis=1, count=tried, bitorder="little") if M else np.zeros((0, tried), np.uint8)
        if not np.array_equal(bits.sum(axis=1), solved):
            raise _map_error(where, "reached", "(the per-direction results) disagree with the solved counts")
    for key, width in (("base_joints", None), ("base_placements", 3)):
        if key in arrays:
            a = arrays[key]
            if (a.dtype.kind != "f" or a.ndim != 3 or a.shape[:2] != (M, tried) or a.shape[2] < 1
                    or (width is not None and a.shape[2] != width)):
                raise _map_error(where, key,
                                 f"must be numbers of shape ({M}, {tried}, {width or 'k'}), got {a.dtype} {a.shape}")
            if M and not np.array_equal(np.isfinite(a).all(axis=2), np.unpackbits(
                    arrays["reached"], axis=1, count=tried, bitorder="little").astype(bool)
                    if "reached" in arrays else np.isfinite(a).all(axis=2)):
                raise _map_error(where, key, "must be finite exactly where a pose is reached (NaN elsewhere)")
    if "sphere_directions" in arrays:
        d = arrays["sphere_directions"]
        if d.dtype.kind != "f" or d.shape != (directions, 3) or not np.all(np.isfinite(d)):
            raise _map_error(where, "sphere_directions",
                             f"must be ({directions}, 3) finite numbers, got {d.dtype} {d.shape}")

def load(path: str | os.PathLike) -> ReachabilityMap:
    """Read a map written by ``save`` or ``workspace_gen`` (numpy alone reads the file; this only checks it).

    A map file of the first format loads too: its voxels were those of the convex hull, and it lacks the
    per-direction results (``m.lacks == ("reached",)``; queries then say so). InputError for a missing, foreign,
    damaged or inconsistent file (:func:`snakehead._files.read_npz`, :func:`validate_map_arrays`), naming what is
    wrong. A shard loads too, for :func:`merge`; everything that uses a map refuses it
    (:meth:`ReachabilityMap.require_whole_for`)."""
    from ..._files import read_npz

    z = read_npz(path, "the map", max_bytes=MAX_MAP_BYTES)  # a regular file; sizes checked before unpacking
    path = os.fspath(path)
    validate_map_arrays(z, f"map {path!r}")  # every field, before a map is made of them

    def scalar(k: str, cast: Callable[[Any], Any]) -> Any:
        return cast(z[k][()])

    casts = {"approach_axis": str, "hull": str, "any_roll": bool, "free_roll": bool, "voxel_size": float,
             "timeout": float, "epsilon": float, "shrink": float}
    old = {"hull": "convex", "shrink": 0.0}  # what the first format's maps were made with
    params = {p: scalar(p, casts.get(p, int)) if p in z else old[p] for p in _PARAMS}
    stats = {}
    for k, cast in (("ik_calls", int), ("cheap_exits", int), ("seconds", float), ("threads", int),
                    ("hull_facets", int), ("reach", float), ("alpha", float)):
        if k in z:
            v = scalar(k, cast)
            if not (v == -1 or (isinstance(v, float) and math.isnan(v))):  # -1 / NaN: not known
                stats[k] = v
    reached = np.array(z["reached"], dtype=np.uint8) if "reached" in z else None
    if reached is None and str(z["format"][()]) != FORMATS[0] and len(z["voxel_ids"]) == 0:
        # the writer leaves the per-direction results out when there are none (an empty shard): nothing is lacking,
        # and the shard merges with the others without losing theirs
        reached = np.zeros((0, (scalar("tried", int) + 7) // 8), np.uint8)
    m = ReachabilityMap(
        centers=np.array(z["centers"], dtype=float).reshape(-1, 3),
        solved=np.array(z["solved"], dtype=np.int32),
        voxel_ids=np.array(z["voxel_ids"], dtype=np.int64),
        tried=scalar("tried", int),
        grid_origin=np.array(z["grid_origin"], dtype=float),
        grid_size=scalar("grid_size", float),
        grid_shape=tuple(int(x) for x in z["grid_shape"]),
        hull_voxels=scalar("hull_voxels", int),
        chain_hash=scalar("chain_hash", str),
        base=scalar("base", str),
        tip=scalar("tip", str),
        params=params,
        shard=tuple(int(x) for x in z["shard"]),
        command=scalar("command", str),
        stats=stats,
        path=Path(path),
        reached=reached,
        lacks=() if reached is not None else ("reached",),
        kind=scalar("map_kind", str) if "map_kind" in z else KIND_HEAD,
        base_joints=np.array(z["base_joints"], dtype=float) if "base_joints" in z else None,
        base_placements=np.array(z["base_placements"], dtype=float) if "base_placements" in z else None,
    )
    return m


def merge(shards: Iterable[ReachabilityMap]) -> ReachabilityMap:
    """The exact union of the shards 0..N-1 of one map (any order): the one place shards are taken as they are
    (elsewhere :meth:`ReachabilityMap.require_whole_for` refuses them). InputError when they do not fit together."""
    parts = list(shards)
    if not parts:
        raise InputError("merge needs at least one shard")
    for p in parts:
        if not isinstance(p, ReachabilityMap):
            raise InputTypeError(f"merge takes ReachabilityMaps, got {type(p).__name__}")
    first = parts[0]
    if any(p.kind != KIND_HEAD for p in parts):
        raise InputError("merge takes the shards of a head map; a whole-body map is computed whole (snakehead reach)")
    n = first.shard[1]
    if len(parts) != n:
        missing = sorted(set(range(n)) - {p.shard[0] for p in parts})
        raise InputError(f"the map was split into {n} shards; got {len(parts)}"
                         + (f" (missing shard{'s' if len(missing) > 1 else ''} "
                            f"{', '.join(f'{i}/{n}' for i in missing[:5])}{' ...' if len(missing) > 5 else ''})"
                            if missing else ""))
    seen = set()
    for p in parts:
        if (p.chain_hash != first.chain_hash or p.shard[1] != n or p.tried != first.tried
                or p.grid_shape != first.grid_shape or p.hull_voxels != first.hull_voxels
                or not all(_param_equal(p.params[k], first.params[k]) for k in _PARAMS)):
            raise InputError("shards of different maps (chain, parameters or grid differ) cannot be merged")
        if p.shard[0] in seen:
            raise InputError(f"shard {p.shard[0]}/{n} given twice")
        seen.add(p.shard[0])
    ids = np.concatenate([p.voxel_ids for p in parts])
    if len(np.unique(ids)) != len(ids):
        raise InputError("a voxel appears in two shards")
    if len(ids) != first.hull_voxels:
        raise InputError(f"the shards hold {len(ids)} voxels; the map has {first.hull_voxels}")
    order = np.argsort(ids, kind="stable")
    stats = {k: sum(p.stats.get(k, 0) for p in parts) for k in ("ik_calls", "cheap_exits", "seconds")}
    stats.update({k: first.stats[k] for k in ("hull_facets", "reach", "alpha") if k in first.stats})
    with_bits = all(p.reached is not None for p in parts)
    return ReachabilityMap(
        centers=np.concatenate([p.centers for p in parts])[order],
        solved=np.concatenate([p.solved for p in parts])[order],
        voxel_ids=ids[order],
        tried=first.tried, grid_origin=first.grid_origin.copy(), grid_size=first.grid_size,
        grid_shape=first.grid_shape, hull_voxels=first.hull_voxels, chain_hash=first.chain_hash,
        base=first.base, tip=first.tip, params=dict(first.params), shard=(0, 1),
        command=f"snakehead.workspace.merge({n} shards)", stats=stats,
        reached=np.concatenate([p.reached for p in parts])[order] if with_bits else None,
        lacks=() if with_bits else ("reached",),
    )


def default_map_options(chain_or_robot: Chain | SnakeRobot) -> dict:
    """Options of :func:`compute` for a robot's head that has no map yet: :mod:`snakehead.sweep_defaults` (20
    directions x 4 rolls, 0.3 ms per IK call), with voxels scaled to the head (a twelfth of its reach, 0.045 m on
    the default robot's 7-DOF head, rounded to 5 mm) so that every head gets a grid of about the same size."""
    chain = _resolve_chain(chain_or_robot)
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
    from ...model.robot import SnakeRobot

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
    import hashlib

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


def fibonacci_directions(n: int) -> np.ndarray:
    """n unit vectors spread evenly over the sphere (the sweep's Fibonacci lattice), (n, 3)."""
    return _core.fibonacci_directions(_count("n (directions)", n, 1, MAX_DIRECTIONS))


def approach_frame(point: npt.ArrayLike, direction: npt.ArrayLike, roll: float = 0.0, axis: str = "x") -> np.ndarray:
    """The sweep's frame at ``point`` whose ``axis`` ('x' or 'z') is ``direction``, rolled by ``roll`` rad, (4, 4)."""
    from ..._validate import finite_array

    p = finite_array(point, "point", (3,))
    d = finite_array(direction, "direction", (3,))
    if not math.isfinite(float(roll)):
        raise InputError("roll must be finite")
    return _core.approach_frame(p, d, float(roll), axis)
