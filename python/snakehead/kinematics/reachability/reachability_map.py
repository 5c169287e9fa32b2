"""A head's reachability map (the paper's Section 2.2) and what it answers about itself: Table 2's bands of the
reachability index, the dexterous workspace and its centre G0 (Section 2.3).

A map holds the voxels of a grid, in the chain's base frame (for the head, ``neck_end``: B0), that lie inside the
boundary of the chain's cloud of tip positions, each with its reachability index

    D = 100 * (points reached) / (points tried)

over the points of the voxel's inscribed sphere (:mod:`.voxel_sphere`), and which directions (or frames) of each
voxel were reached, so that it answers whether poses are reachable (:meth:`ReachabilityMap.reachable`) and where the
head's base frame may be for a target (:meth:`ReachabilityMap.inverse`; :mod:`.map_queries`). The sweep that makes a
map is :mod:`.sweep`; its files are :mod:`.map_io`'s.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Sequence

import numpy as np
import numpy.typing as npt

from ..._errors import InputError, InputTypeError
from ..._validate import finite_array
from ...model.chain import Chain
from ...model.robot import SnakeRobot
from .kmeans import kmeans
from .sweep_options import mapped_chain
from .voxel_sphere import fibonacci_directions

if TYPE_CHECKING:
    from .map_queries import BaseFrameCandidates

#: What a map answers (its ``kind``): the head chain's reach (Algorithm 1: ``snakehead workspace``, in the head's base
#: frame) or the whole body's stable reach (``snakehead reach``, ``planning.whole_body_reach``: poses a stable,
#: collision-free whole-body pose reaches, in the world frame of a base starting at ``BasePlacement()``).
KIND_HEAD, KIND_WHOLE_BODY = "head", "whole-body"
MAP_KINDS = (KIND_HEAD, KIND_WHOLE_BODY)
_KIND_HINTS = {KIND_HEAD: "a head map (snakehead workspace)",
               KIND_WHOLE_BODY: "a whole-body stable reachability map (snakehead reach)"}
#: Table 2's bins of the reachability index: [0,20) [20,40) [40,60) [60,80) [80,100].
TABLE2_BINS = (0.0, 20.0, 40.0, 60.0, 80.0, 100.0)
#: How many voxels the dexterous band must hold at least, as a share of the map's voxels (see
#: :meth:`ReachabilityMap.dexterous_threshold`): the paper's dexterous workspace holds 3.69 % of its map's voxels.
DEXTEROUS_MIN_SHARE = 0.01

#: Voxels the dexterous centre G0 needs at least: its k-means++ makes three clusters (Section 2.3).
G0_MIN_VOXELS = 3
_MERGE_HINT = ("merge the shards (snakehead workspace --merge SHARD.npz ... --out MAP.npz, or "
               "snakehead.kinematics.reachability.merge) and use the merged map")

#: The parameters that define a map (two maps, or shards, with the same values are parts of one computation).
MAP_PARAMETERS = ("voxel_size", "directions", "rolls", "any_roll", "free_roll", "approach_axis", "timeout",
                  "epsilon", "cloud_samples", "seed", "hull", "shrink")
#: What a map's caller may need of it (:meth:`ReachabilityMap.require_whole_for`).
_NEEDS = ("voxels", "G0", "poses")


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
    # arrays derived from the map, computed once on first use (its sphere's directions, map_queries' tables)
    cache: dict = field(default_factory=dict, repr=False, compare=False)

    # --- the index --------------------------------------------------------------------------------
    @property
    def indices(self) -> np.ndarray:
        """(M,) reachability index D in [0, 100]."""
        return 100.0 * self.solved / self.tried

    @property
    def voxel_size(self) -> float:
        """The voxels' edge (m)."""
        return float(self.params["voxel_size"])

    def __len__(self) -> int:
        return len(self.voxel_ids)

    # --- what the map is, and whether it is what a caller needs ------------------------------------------
    def require_whole_for(self, chain: Chain | SnakeRobot | None = None, *, needs: Iterable[str] = (),
                          what: str | None = None, kind: str = KIND_HEAD) -> ReachabilityMap:
        """The one check of a map where it is accepted: returns the map, or raises :class:`InputError` (one line
        naming the map and what to do) when it is

        * a shard of a map: its G0, dexterous band and queries would be those of a part of the map (shards load, and
          :func:`~snakehead.kinematics.reachability.map_io.merge` takes them as they are: the one place that does);
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
        self._require_kind(kind, name)
        needs = tuple(needs)
        unknown = [n for n in needs if n not in _NEEDS]
        if unknown:
            raise InputError(f"needs may hold 'voxels', 'G0' and 'poses', got {unknown[0]!r}")
        if tuple(self.shard) != (0, 1):
            i, n = self.shard
            raise InputError(f"{name} is shard {i}/{n} of a map, not a whole map ({len(self)} of its "
                             f"{self.hull_voxels} voxels): {_MERGE_HINT}")
        if chain is not None and kind == KIND_WHOLE_BODY:
            _require_body(self, chain, name)
        elif chain is not None:
            _require_head(self, chain, name)
        self._require_contents(needs, name)
        return self

    def _require_kind(self, kind: str, name: str) -> None:
        """InputError unless ``kind`` is one of MAP_KINDS and the map's."""
        if kind not in MAP_KINDS:
            raise InputError(f"kind must be one of {', '.join(map(repr, MAP_KINDS))}, got {kind!r}")
        if self.kind != kind:
            raise InputError(f"{name} is {_KIND_HINTS.get(self.kind, repr(self.kind))}, not "
                             f"{_KIND_HINTS[kind]}: give {_KIND_HINTS[kind]}")

    def _require_contents(self, needs: tuple[str, ...], name: str) -> None:
        """InputError unless the map holds what ``needs`` names (see :meth:`require_whole_for`)."""
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

    def histogram(self, bins: Sequence[float] = TABLE2_BINS) -> tuple[np.ndarray, np.ndarray]:
        """Voxel counts and percentages per bin, Table 2's bins by default; the last bin is closed ([80, 100])."""
        edges = finite_array(bins, "bins", (None,))  # finite: a NaN edge would pass the test below
        if len(edges) < 2 or np.any(np.diff(edges) <= 0):
            raise InputError(f"bins must be an increasing sequence of at least two edges, got {edges.tolist()}")
        counts, _ = np.histogram(self.indices, bins=edges)  # numpy's last bin is closed
        pct = 100.0 * counts / max(len(self), 1)
        return counts, pct

    @property
    def sphere_directions(self) -> np.ndarray:
        """(N, 3) the unit directions of every voxel's sphere (the sweep's Fibonacci lattice)."""
        if "directions" not in self.cache:
            self.cache["directions"] = fibonacci_directions(int(self.params["directions"]))
        return self.cache["directions"]

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
        from .map_queries import reachable  # (map_queries builds on this module)

        return reachable(self, positions, directions, interpolate=interpolate)

    def inverse(self, position: npt.ArrayLike, direction: npt.ArrayLike, **options: Any) -> BaseFrameCandidates:
        """Candidate poses of the map's base frame (B0) from which the head reaches a target; see
        ``map_queries.inverse``."""
        from .map_queries import inverse  # (map_queries builds on this module)

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
        self.require_whole_for()  # the clusters of a shard's voxels are not the map's
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

    # --- files and comparisons ---------------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> None:
        """Write the map to ``path`` (an .npz): :func:`.map_io.save`."""
        from .map_io import save  # (map_io builds on this module)

        save(self, path)

    def same_parameters_as(self, other: ReachabilityMap) -> bool:
        """Whether the two maps' :data:`MAP_PARAMETERS` are equal (then they, or shards, are parts of one
        computation)."""
        return all(_param_equal(self.params[p], other.params[p]) for p in MAP_PARAMETERS)

    def same_map_as(self, other: ReachabilityMap) -> bool:
        """Same chain, parameters, grid and per-voxel results (statistics and command aside)."""
        return (
            self.chain_hash == other.chain_hash
            and self.kind == other.kind
            and self.same_parameters_as(other)
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


def _require_head(m: ReachabilityMap, chain: Chain | SnakeRobot, name: str) -> None:
    """InputError unless the head map ``m`` was made for ``chain`` (a Chain, or a SnakeRobot's head chain), by the
    chains' kinematics hash."""
    head = mapped_chain(chain)
    if m.chain_hash != head.hash:
        mine = (f"{chain.parts.neck_end} -> {chain.parts.head_tip}" if isinstance(chain, SnakeRobot) else
                f"{head.base} -> {head.tip}")
        raise InputError(f"{name} was made for another head chain ({m.base} -> {m.tip}, hash "
                         f"{m.chain_hash}); this robot's head is {mine} (hash {head.hash}): compute its map "
                         "(snakehead workspace --robot ROBOT.toml --out MAP.npz)")


def _require_body(m: ReachabilityMap, robot: Any, name: str) -> None:
    """InputError unless the whole-body map ``m`` was made for ``robot``'s body (by its body chain's hash)."""
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
    """Equal parameter values, a float equal to an int of its value (as a map file may store either)."""
    if isinstance(a, float) or isinstance(b, float):
        return float(a) == float(b)
    return a == b


__all__ = ["KIND_HEAD", "KIND_WHOLE_BODY", "MAP_KINDS", "TABLE2_BINS", "DEXTEROUS_MIN_SHARE", "G0_MIN_VOXELS",
           "MAP_PARAMETERS", "Clusters", "ReachabilityMap", "require_map"]
