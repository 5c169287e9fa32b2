"""A reachability map's files: :func:`save` (by the one map writer, the C++ core's, which ``workspace_gen`` uses too),
:func:`load` with the checks of every field (:func:`validate_map_arrays`), and :func:`merge` of the shards of one map.

A map file is an uncompressed ``.npz`` that ``numpy.load`` reads (``allow_pickle=False``); see :func:`save` for its
keys.
"""
from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from ... import _core
from ..._errors import InputError, InputTypeError
from ..._files import read_npz
from .reachability_map import KIND_HEAD, MAP_KINDS, MAP_PARAMETERS, ReachabilityMap
from .sweep_options import MAX_DIRECTIONS, MAX_ROLLS, MAX_VOXELS_PER_AXIS, core_options

FORMAT = "snakehead-reachability-2"
#: Formats :func:`load` reads: the first lacks the per-direction results and the hull's kind (always convex).
FORMATS = ("snakehead-reachability-1", FORMAT)


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
    o = core_options(p["voxel_size"], p["directions"], max(int(p["rolls"]), 1), p["any_roll"], p["free_roll"],
                     p["approach_axis"], p["timeout"], p["epsilon"], p["cloud_samples"], p["seed"], None, m.shard,
                     p.get("hull", "convex"), p.get("shrink", 0.0))
    n = int(m.grid_shape[0])
    stats = m.stats
    _core.save_map(
        path, m.command, o, np.ascontiguousarray(m.centers, dtype=float), m.solved.astype(np.int32).tolist(),
        m.voxel_ids.astype(np.int64).tolist(),
        None if m.reached is None else np.ascontiguousarray(m.reached, dtype=np.uint8),
        int(m.tried), np.asarray(m.grid_origin, dtype=float), float(m.grid_size) / n, n, int(m.hull_voxels),
        int(stats.get("hull_facets", -1)), float(stats.get("alpha", math.inf if o.hull == "convex" else math.nan)),
        float(stats.get("reach", math.nan)), m.chain_hash, m.base, m.tip, int(stats.get("ik_calls", -1)),
        int(stats.get("cheap_exits", -1)), float(stats.get("seconds", math.nan)), int(stats.get("threads", -1)),
        m.kind, _witness(m.base_joints), _witness(m.base_placements))
    m.path = Path(path)


def _witness(a: np.ndarray | None) -> np.ndarray | None:
    """A whole-body map's witness array as the writer takes it (contiguous floats), or None."""
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
_MAP_OPTIONAL_SCALARS = {"map_kind": "text", "hull": "text", "shrink": "float", "alpha": "float", "reach": "float",
                         "seconds": "float", "ik_calls": "int", "cheap_exits": "int", "threads": "int",
                         "hull_facets": "int"}
_MAP_ARRAYS = {"centers": ("f", ("M", 3)), "indices": ("f", ("M",)), "solved": ("i", ("M",)),
               "voxel_ids": ("i", ("M",)), "grid_origin": ("f", (3,)), "grid_shape": ("i", (3,)), "shard": ("i", (2,))}
_KINDS = {"text": "U", "int": "iu", "bool": "b", "float": "fiu"}


def validate_map_arrays(arrays: dict[str, np.ndarray], where: str = "the map") -> None:
    """Check the arrays of a map file (as ``snakehead._files.read_npz`` returns them) before a map is made of
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
    """The InputError of a map file's bad ``field``: where, the field, what is wrong with it."""
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
    damaged or inconsistent file (``snakehead._files.read_npz``, :func:`validate_map_arrays`), naming what is
    wrong. A shard loads too, for :func:`merge`; everything that uses a map refuses it
    (:meth:`ReachabilityMap.require_whole_for`)."""
    z = read_npz(path, "the map", max_bytes=MAX_MAP_BYTES)  # a regular file; sizes checked before unpacking
    path = os.fspath(path)
    validate_map_arrays(z, f"map {path!r}")  # every field, before a map is made of them

    def scalar(k: str, cast: Callable[[Any], Any]) -> Any:
        return cast(z[k][()])

    reached = _read_reached(z)
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
        params=_read_parameters(z),
        shard=tuple(int(x) for x in z["shard"]),
        command=scalar("command", str),
        stats=_read_statistics(z),
        path=Path(path),
        reached=reached,
        lacks=() if reached is not None else ("reached",),
        kind=scalar("map_kind", str) if "map_kind" in z else KIND_HEAD,
        base_joints=np.array(z["base_joints"], dtype=float) if "base_joints" in z else None,
        base_placements=np.array(z["base_placements"], dtype=float) if "base_placements" in z else None,
    )
    return m


def _read_parameters(z: dict[str, np.ndarray]) -> dict:
    """The map's :data:`MAP_PARAMETERS` from a checked map file (those the first format lacks: what its maps were
    made with)."""
    casts = {"approach_axis": str, "hull": str, "any_roll": bool, "free_roll": bool, "voxel_size": float,
             "timeout": float, "epsilon": float, "shrink": float}
    old = {"hull": "convex", "shrink": 0.0}  # what the first format's maps were made with
    return {p: casts.get(p, int)(z[p][()]) if p in z else old[p] for p in MAP_PARAMETERS}


def _read_statistics(z: dict[str, np.ndarray]) -> dict:
    """The run's statistics a checked map file holds, leaving out those not known (-1 or NaN)."""
    stats = {}
    for k, cast in (("ik_calls", int), ("cheap_exits", int), ("seconds", float), ("threads", int),
                    ("hull_facets", int), ("reach", float), ("alpha", float)):
        if k in z:
            v = cast(z[k][()])
            if not (v == -1 or (isinstance(v, float) and math.isnan(v))):  # -1 / NaN: not known
                stats[k] = v
    return stats


def _read_reached(z: dict[str, np.ndarray]) -> np.ndarray | None:
    """The per-direction results of a checked map file; None when it lacks them (a file of the first format)."""
    if "reached" in z:
        return np.array(z["reached"], dtype=np.uint8)
    if str(z["format"][()]) != FORMATS[0] and len(z["voxel_ids"]) == 0:
        # the writer leaves the per-direction results out when there are none (an empty shard): nothing is lacking,
        # and the shard merges with the others without losing theirs
        return np.zeros((0, (int(z["tried"][()]) + 7) // 8), np.uint8)
    return None


def merge(shards: Iterable[ReachabilityMap]) -> ReachabilityMap:
    """The exact union of the shards 0..N-1 of one map (any order): the one place shards are taken as they are
    (elsewhere :meth:`ReachabilityMap.require_whole_for` refuses them). InputError when they do not fit together."""
    parts = list(shards)
    _check_shards(parts)
    first, n = parts[0], parts[0].shard[1]
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


def _check_shards(parts: list[ReachabilityMap]) -> None:
    """InputError unless ``parts`` are the shards 0..N-1 of one head map, each once."""
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
                or not p.same_parameters_as(first)):
            raise InputError("shards of different maps (chain, parameters or grid differ) cannot be merged")
        if p.shard[0] in seen:
            raise InputError(f"shard {p.shard[0]}/{n} given twice")
        seen.add(p.shard[0])


__all__ = ["FORMAT", "FORMATS", "MAX_MAP_BYTES", "save", "load", "merge", "validate_map_arrays"]
