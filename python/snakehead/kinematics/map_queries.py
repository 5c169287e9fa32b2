"""Questions a reachability map answers from its per-direction results, for many poses at once.

* :func:`reachable`: can the head's tip be at a position, pointing along a direction (its roll free)?
  The map tried, for each voxel, N directions at the points of its inscribed sphere: the pose
  (``c_v + r d_k``, ``d_k``) for voxel centre ``c_v``, sphere radius ``r`` (half a voxel) and direction ``d_k``.
  A query (p, d) is answered by the nearest of those poses: the direction ``d_k`` nearest d, and the voxel
  whose sphere point in that direction is nearest p (the voxel holding ``p - r d_k``). :func:`reachability`
  blends the neighbouring poses instead (trilinear over the voxels, weighted over the nearest directions), a
  score in [0, 1]; ``reachable(..., interpolate=True)`` thresholds it at 1/2.
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

from .._validate import finite_float, position_direction_pairs as _poses

#: Directions blended by :func:`reachability`.
BLENDED_DIRECTIONS = 3


def direction_bits(m) -> np.ndarray:
    """(M, N) bool: direction k of voxel v was reached with some roll (its units OR-ed over the rolls when
    every roll counted on its own). Cached on the map."""
    if "direction_bits" not in m._cache:
        units = m.reached_units()
        n = int(m.params["directions"])
        if units.shape[1] != n:  # each roll counted: units are (direction, roll) frames, direction-major
            units = units.reshape(len(m), n, -1).any(axis=2)
        m._cache["direction_bits"] = units
    return m._cache["direction_bits"]


def _rows(m, ijk: np.ndarray) -> np.ndarray:
    """Row of the map holding each grid voxel (i, j, l), -1 where the map has none, for (..., 3) indices."""
    n = int(m.grid_shape[0])
    inside = np.all((ijk >= 0) & (ijk < n), axis=-1)
    ids = (ijk[..., 0] * n + ijk[..., 1]) * n + ijk[..., 2]
    if len(m) == 0:
        return np.full(ids.shape, -1)
    pos = np.clip(np.searchsorted(m.voxel_ids, ids), 0, len(m) - 1)
    return np.where(inside & (m.voxel_ids[pos] == ids), pos, -1)


def reachable(m, positions, directions, *, interpolate: bool = False):
    """Whether each pose is reachable by the map (see the module's doc). positions, directions: (3,) or (K, 3);
    a bool for one pose, else (K,) bools. ``interpolate``: :func:`reachability` >= 1/2 instead of the nearest
    sample."""
    p, d, single = _poses(positions, directions)
    if interpolate:
        out = _reachability(m, p, d) >= 0.5
    else:
        bits = direction_bits(m)
        dirs = m.sphere_directions
        k = np.argmax(d @ dirs.T, axis=1)
        r = 0.5 * m.voxel_size
        ijk = np.floor((p - r * dirs[k] - m.grid_origin) / m.voxel_size).astype(np.int64)
        rows = _rows(m, ijk)
        out = np.zeros(len(p), dtype=bool)
        found = rows >= 0
        out[found] = bits[rows[found], k[found]]
    return bool(out[0]) if single else out


def reachability(m, positions, directions) -> np.ndarray:
    """A score in [0, 1] per pose: the map's reached/not-reached samples around it, blended trilinearly over the
    8 voxels whose sphere points surround the position, and over the BLENDED_DIRECTIONS nearest directions
    (weights falling linearly with the angle to zero at the next direction's). Voxels outside the map count 0."""
    p, d, single = _poses(positions, directions)
    s = _reachability(m, p, d)
    return float(s[0]) if single else s


def _reachability(m, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    bits = direction_bits(m)
    dirs = m.sphere_directions
    h, r = m.voxel_size, 0.5 * m.voxel_size
    cos = np.clip(d @ dirs.T, -1.0, 1.0)
    nearest = np.argsort(-cos, axis=1)[:, :BLENDED_DIRECTIONS + 1]
    angles = np.arccos(np.take_along_axis(cos, nearest, axis=1))
    # Weights: 1 - angle / (angle of the first direction left out), so a direction as far as that one gets 0.
    weights = np.clip(1.0 - angles[:, :-1] / np.maximum(angles[:, -1:], 1e-12), 0.0, None)
    weights /= np.maximum(weights.sum(axis=1, keepdims=True), 1e-12)
    score = np.zeros(len(p))
    corners = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    for j in range(nearest.shape[1] - 1):
        k = nearest[:, j]
        f = (p - r * dirs[k] - m.grid_origin) / h - 0.5  # fractional index of the sphere points' lattice
        base = np.floor(f).astype(np.int64)
        t = f - base
        ijk = base[:, None, :] + corners[None]  # (K, 8, 3)
        w = np.prod(np.where(corners[None] == 1, t[:, None, :], 1.0 - t[:, None, :]), axis=2)  # (K, 8)
        rows = _rows(m, ijk)
        hit = np.zeros(rows.shape, dtype=bool)
        ok = rows >= 0
        hit[ok] = bits[rows[ok], np.broadcast_to(k[:, None], rows.shape)[ok]]
        score += weights[:, j] * np.sum(w * hit, axis=1)
    return score


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


def inverse(m, position, direction, *, rolls: int = 8, min_index: float = 0.0, limit: int | None = 200
            ) -> BaseFrameCandidates:
    """Inverse reachability: poses of the map's base frame in the world from which the head reaches the target
    (``position`` (3,) m, ``direction`` (3,), world), ranked by the index of the voxel holding the target.

    For every reached (voxel v, direction k) of the map, the base frame pose T with T (c_v + r d_k) = position and
    T's rotation taking d_k to ``direction``, turned about ``direction`` by ``rolls`` evenly spaced angles.
    ``min_index``: only voxels of at least this index; ``limit``: the best ``limit`` (voxel, direction) pairs
    (None: all) before the turns. Ties in the index keep the map's order."""
    p, d, single = _poses(position, direction)
    if not single:
        raise ValueError("inverse takes one target: position and direction of shape (3,)")
    if isinstance(rolls, bool) or not isinstance(rolls, (int, np.integer)) or rolls < 1:
        raise ValueError(f"rolls must be a positive integer, got {rolls!r}")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, (int, np.integer)) or limit < 1):
        raise ValueError(f"limit must be a positive integer or None, got {limit!r}")
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
