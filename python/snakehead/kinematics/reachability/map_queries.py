"""Questions a reachability map answers from its per-direction results, for many poses at once.

* :func:`reachable`: can the head's tip be at a position, pointing along a direction (its roll free)?
  The map tried, for each voxel, N directions at the points of its inscribed sphere: the pose
  (``c_v + r d_k``, ``d_k``) for voxel centre ``c_v``, sphere radius ``r`` (half a voxel) and direction ``d_k``.
  :func:`reachability` blends the map's samples around a query (p, d): trilinearly over the 8 voxels whose sphere
  points in a direction surround p, weighted over the directions nearest d; a score in [0, 1], which
  :func:`reachable` thresholds at 1/2 (the default: it agrees best with TRAC-IK, ``bench/RESULTS.md``). With
  ``interpolate=False`` the nearest sample answers: the direction ``d_k`` nearest d, and the voxel whose sphere
  point in that direction is nearest p (the voxel holding ``p - r d_k``).
* :func:`inverse`: inverse reachability. For a target (position, direction) of the head in the world, the
  poses of the map's base frame (for the head, B0 = ``neck_end``) from which one of the map's reached poses is
  the target, ranked by the map's index of their voxel. Each reached (voxel, direction) gives one such pose up
  to a turn about the target direction (the head's roll is free); ``rolls`` samples that turn.

Everything is numpy; the map's frame is the chain's base frame. Placing a robot's base from these is
``base_placement.py``'s (the part that depends on the robot).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..._errors import InputError
from ..._validate import finite_float
from ..._validate import position_direction_pairs as _poses
from .reachability_map import KIND_HEAD, ReachabilityMap, require_map

#: Directions blended by :func:`reachability`.
BLENDED_DIRECTIONS = 3


def _usable(m: ReachabilityMap, any_kind: bool = False) -> ReachabilityMap:
    """The map if pose queries can be asked of it: a whole map (a shard would answer False for its other shards'
    voxels) with per-direction results along the head's x-axis, a head map unless ``any_kind`` (whether a pose is
    reachable is asked of a whole-body map too); InputError otherwise (the one check of maps)."""
    kind = m.kind if any_kind and isinstance(m, ReachabilityMap) else KIND_HEAD
    return require_map(m, needs=("poses",), kind=kind)


def direction_bits(m: ReachabilityMap) -> np.ndarray:
    """(M, N) bool: direction k of voxel v was reached with some roll (its units OR-ed over the rolls when
    every roll counted on its own). Cached on the map."""
    _usable(m, any_kind=True)
    if "direction_bits" not in m.cache:
        units = m.reached_units()
        n = int(m.params["directions"])
        if units.shape[1] != n:  # each roll counted: units are (direction, roll) frames, direction-major
            units = np.asarray(units.reshape(len(m), n, -1).any(axis=2))
        m.cache["direction_bits"] = units
    return m.cache["direction_bits"]


def _table(m: ReachabilityMap) -> np.ndarray:
    """The direction bits of every grid voxel, in a dense flat table over the grid padded by one voxel on each
    side (False there and outside the map's voxels): a lookup is one array access (cached on the map)."""
    if "table" not in m.cache:
        n = int(m.grid_shape[0])
        bits = direction_bits(m)
        table = np.zeros((n + 2, n + 2, n + 2, bits.shape[1]), dtype=bool)
        i, j, l = m.voxel_ids // (n * n), (m.voxel_ids // n) % n, m.voxel_ids % n
        table[i + 1, j + 1, l + 1] = bits
        m.cache["table"] = table.reshape(-1)
    return m.cache["table"]


#: Cells per cube face edge, and candidate directions per cell, of the directions' lookup table.
_CUBE_CELLS, _CANDIDATES = 32, 7


def _cube_cell(d: np.ndarray) -> np.ndarray:
    """The cube-map cell (face, u, v) of each unit direction (K, 3), as a flat index."""
    major = np.argmax(np.abs(d), axis=1)
    rows = np.arange(len(d))
    face = 2 * major + (d[rows, major] < 0)
    big = np.abs(d[rows, major])
    u = d[rows, (major + 1) % 3] / big
    v = d[rows, (major + 2) % 3] / big
    return (face * _CUBE_CELLS + _cell(u)) * _CUBE_CELLS + _cell(v)


def _cell(x: np.ndarray) -> np.ndarray:
    """The cell of each coordinate in [-1, 1] along a cube face's edge."""
    return np.clip(((x + 1.0) * 0.5 * _CUBE_CELLS).astype(np.int64), 0, _CUBE_CELLS - 1)


def _direction_candidates(m: ReachabilityMap) -> np.ndarray:
    """(6 * cells^2, C): for each cube-map cell, the map's directions nearest its centre (cached on the map). A
    cell spans under 3 degrees; the map's directions are tens of degrees apart, so the few nearest to any
    direction in the cell are among them."""
    if "candidates" not in m.cache:
        dirs = m.sphere_directions
        g = (np.arange(_CUBE_CELLS) + 0.5) / _CUBE_CELLS * 2.0 - 1.0
        u, v = np.meshgrid(g, g, indexing="ij")
        faces = []
        for face in range(6):
            major, sign = face // 2, -1.0 if face % 2 else 1.0
            c = np.zeros((_CUBE_CELLS, _CUBE_CELLS, 3))
            c[..., major], c[..., (major + 1) % 3], c[..., (major + 2) % 3] = sign, u, v
            faces.append(c.reshape(-1, 3))
        centres = np.concatenate(faces)
        centres /= np.linalg.norm(centres, axis=1, keepdims=True)
        keep = min(_CANDIDATES, len(dirs))
        # the cosines written out, not a BLAS product (whose kernel rounds them), and ties kept in direction order
        # (the default sort orders them by the CPU's vector extensions): the same candidates on any machine
        cos = centres[:, :1] * dirs[:, 0] + centres[:, 1:2] * dirs[:, 1] + centres[:, 2:] * dirs[:, 2]
        m.cache["candidates"] = np.argsort(-cos, axis=1, kind="stable")[:, :keep]
    return m.cache["candidates"]


def _padded(m: ReachabilityMap, ijk: np.ndarray) -> np.ndarray:
    """Grid indices (..., 3) to the padded table's voxel number; anything off the grid lands on the padding."""
    n = int(m.grid_shape[0])
    a = np.clip(ijk, -1, n) + 1
    return (a[..., 0] * (n + 2) + a[..., 1]) * (n + 2) + a[..., 2]


def reachable(m: ReachabilityMap, positions: npt.ArrayLike, directions: npt.ArrayLike, *,
              interpolate: bool = True) -> np.ndarray | bool:
    """Whether each pose is reachable by the map (see the module's doc). positions, directions: (3,) or (K, 3);
    a bool for one pose, else (K,) bools. ``interpolate``: :func:`reachability` >= 1/2 (default), else the
    nearest sample."""
    _usable(m, any_kind=True)
    p, d, single = _poses(positions, directions)
    if interpolate:
        out = _reachability(m, p, d) >= 0.5
    else:
        dirs = m.sphere_directions
        candidates = _direction_candidates(m)[_cube_cell(d)]  # the nearest direction is among them
        k = np.take_along_axis(candidates, np.argmax(np.einsum("kcj,kj->kc", dirs[candidates], d), axis=1)[:, None],
                               axis=1)[:, 0]
        r = 0.5 * m.voxel_size
        voxel = _padded(m, np.floor((p - r * dirs[k] - m.grid_origin) / m.voxel_size).astype(np.int64))
        out = _table(m)[voxel * len(dirs) + k]
    return bool(out[0]) if single else out


def reachability(m: ReachabilityMap, positions: npt.ArrayLike, directions: npt.ArrayLike) -> np.ndarray | float:
    """A score in [0, 1] per pose: the map's reached/not-reached samples around it, blended trilinearly over the
    8 voxels whose sphere points surround the position, and over the BLENDED_DIRECTIONS nearest directions
    (weights falling linearly with the angle to zero at the next direction's). Voxels outside the map count 0."""
    _usable(m, any_kind=True)
    p, d, single = _poses(positions, directions)
    s = _reachability(m, p, d)
    return float(s[0]) if single else s


def _reachability(m: ReachabilityMap, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """:func:`reachability`'s scores of the checked poses p, d (K, 3)."""
    dirs = m.sphere_directions
    h, r = m.voxel_size, 0.5 * m.voxel_size
    n = int(m.grid_shape[0])
    # The BLENDED_DIRECTIONS + 1 nearest directions, nearest first: among a few candidates looked up by the
    # direction's cell on a cube map (the nearest ones of the cell's centre, and then some).
    candidates = _direction_candidates(m)[_cube_cell(d)]  # (K, C)
    cos = np.einsum("kcj,kj->kc", dirs[candidates], d)
    order = np.argsort(-cos, axis=1, kind="stable")[:, :BLENDED_DIRECTIONS + 1]  # ties in candidate order
    nearest = np.take_along_axis(candidates, order, axis=1)
    near_cos = np.take_along_axis(cos, order, axis=1)
    angles = np.arccos(np.clip(near_cos, -1.0, 1.0))
    # Weights: 1 - angle / (angle of the first direction left out), so a direction as far as that one gets 0.
    weights = np.clip(1.0 - angles[:, :-1] / np.maximum(angles[:, -1:], 1e-12), 0.0, None)
    weights /= np.maximum(weights.sum(axis=1, keepdims=True), 1e-12)
    k = nearest[:, :-1]  # (K, B)
    # Trilinear over the 8 points of each direction's lattice of sphere points around the position.
    f = (p[:, None, :] - r * dirs[k] - m.grid_origin) / h - 0.5  # (K, B, 3) fractional lattice index
    base = np.floor(f).astype(np.int64)
    t = f - base
    axis = [(np.clip(base[..., a], -1, n) + 1, np.clip(base[..., a] + 1, -1, n) + 1) for a in range(3)]
    frac = [(1.0 - t[..., a], t[..., a]) for a in range(3)]
    table = _table(m)
    blend = np.zeros(k.shape)
    for cx in (0, 1):
        for cy in (0, 1):
            for cz in (0, 1):
                voxel = (axis[0][cx] * (n + 2) + axis[1][cy]) * (n + 2) + axis[2][cz]
                blend += frac[0][cx] * frac[1][cy] * frac[2][cz] * table[voxel * len(dirs) + k]
    score = np.sum(weights * blend, axis=1)
    return np.clip(score, 0.0, 1.0)  # rounding can leave a hair above 1


@dataclass
class BaseFrameCandidates:
    """Poses of a map's base frame from which the head reaches one target, best first (see :func:`inverse`)."""

    poses: np.ndarray  # (K, 4, 4) world poses of the base frame (B0 for the head)
    index: np.ndarray  # (K,) reachability index of the voxel that holds the target, seen from each pose
    voxels: np.ndarray  # (K,) the map's row of that voxel
    directions: np.ndarray  # (K,) the map's direction that is the target's direction, seen from each pose
    turns: np.ndarray  # (K,) rad, the turn of the pose about the target direction (the head's free roll)

    def __len__(self) -> int:
        return len(self.index)


def _rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(K, 3, 3) the smallest rotations taking unit vectors a (K, 3) to unit vector b (3,)."""
    v = np.cross(a, b)
    c = a @ b
    out = np.empty((len(a), 3, 3))
    for i in range(len(a)):
        if c[i] < -1.0 + 1e-12:  # opposite: a half turn about any axis perpendicular to a
            axis = np.cross(a[i], np.eye(3)[np.argmin(np.abs(a[i]))])
            axis /= np.linalg.norm(axis)
            out[i] = 2.0 * np.outer(axis, axis) - np.eye(3)
            continue
        vx = np.array([[0.0, -v[i, 2], v[i, 1]], [v[i, 2], 0.0, -v[i, 0]], [-v[i, 1], v[i, 0], 0.0]])
        out[i] = np.eye(3) + vx + vx @ vx / (1.0 + c[i])
    return out


def _turn_about(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """(T, 3, 3) rotations by ``angles`` about the unit ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def inverse(m: ReachabilityMap, position: npt.ArrayLike, direction: npt.ArrayLike, *, rolls: int = 8,
            min_index: float = 0.0, limit: int | None = 200) -> BaseFrameCandidates:
    """Inverse reachability: poses of the map's base frame in the world from which the head reaches the target
    (``position`` (3,) m, ``direction`` (3,), world), ranked by the index of the voxel holding the target.

    For every reached (voxel v, direction k) of the map, the base frame pose T with T (c_v + r d_k) = position and
    T's rotation taking d_k to ``direction``, turned about ``direction`` by ``rolls`` evenly spaced angles.
    ``min_index``: only voxels of at least this index; ``limit``: the best ``limit`` (voxel, direction) pairs
    (None: all) before the turns. Ties in the index keep the map's order."""
    _usable(m)
    p, d, single = _poses(position, direction)
    if not single:
        raise InputError("inverse takes one target: position and direction of shape (3,)")
    if isinstance(rolls, bool) or not isinstance(rolls, (int, np.integer)) or rolls < 1:
        raise InputError(f"rolls must be a positive integer, got {rolls!r}")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, (int, np.integer)) or limit < 1):
        raise InputError(f"limit must be a positive integer or None, got {limit!r}")
    t = finite_float(min_index, "min_index")
    p, d = p[0], d[0]
    bits = direction_bits(m)
    index = m.indices
    rows, ks = np.nonzero(bits & (index >= t - 1e-9)[:, None])
    order = np.argsort(-index[rows], kind="stable")
    if limit is not None:
        order = order[:int(limit)]
    rows, ks = rows[order], ks[order]
    dirs = m.sphere_directions
    tips = m.centers[rows] + 0.5 * m.voxel_size * dirs[ks]  # the reached poses' points, map frame
    align = _rotation_between(dirs[ks], d)  # (L, 3, 3): d_k -> direction
    turns = 2.0 * np.pi * np.arange(int(rolls)) / int(rolls)
    spin = _turn_about(d, turns)  # (R, 3, 3) about the target direction
    rot = np.einsum("rij,ljk->lrik", spin, align).reshape(-1, 3, 3)  # (L * R, 3, 3)
    tip_world = np.einsum("nij,nj->ni", rot, np.repeat(tips, len(turns), axis=0))
    poses = np.tile(np.eye(4), (len(rot), 1, 1))
    poses[:, :3, :3] = rot
    poses[:, :3, 3] = p - tip_world
    return BaseFrameCandidates(poses=poses, index=np.repeat(index[rows], len(turns)),
                               voxels=np.repeat(rows, len(turns)), directions=np.repeat(ks, len(turns)),
                               turns=np.tile(turns, len(rows)))


__all__ = ["BLENDED_DIRECTIONS", "direction_bits", "reachable", "reachability", "BaseFrameCandidates", "inverse"]
