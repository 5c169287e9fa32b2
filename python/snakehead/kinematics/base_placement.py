"""Where to put a robot's base so that its head reaches a target: the head map's inverse reachability, on the
ground.

:func:`~snakehead.kinematics.reachability.map_queries.inverse` gives the poses of the head's base frame B0 from which the head reaches a target
(position, direction). A robot cannot put B0 anywhere: its base lies on the ground (a planar placement: x, y,
yaw) and its neck moves B0 relative to the base. :func:`base_placements` intersects the two:

* the robot part (:func:`neck_frames`, the only function here that knows the robot): B0's pose relative to the
  base's placement frame for a grid of neck joint values, the base joints kept (default: the initial
  configuration of Section 3.3);
* the map part (:func:`placements_from_frames`): for each such neck pose, a placement turns B0 about the
  vertical and shifts it horizontally, so the target seen from B0 has a fixed height over a plane fixed in
  B0 and a direction on a cone fixed in B0. The map's reached (voxel, direction) samples on that plane and
  cone, one per sampled yaw, give placements directly (x, y from the position, yaw from the direction),
  ranked by the map's index of the voxel.

So any robot whose model gives B0 for a neck configuration works here; nothing else depends on the robot.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from .._validate import joint_vector, position_direction_pairs
from ..backbone.initial import initial_configuration
from ..model.robot import BasePlacement, SnakeRobot
from .reachability.map_queries import direction_bits
from .reachability.reachability_map import ReachabilityMap, require_map


@dataclass
class PlacementCandidates:
    """Base placements from which the head reaches one target, best first."""

    x: np.ndarray  # (K,) m, world
    y: np.ndarray  # (K,) m
    yaw: np.ndarray  # (K,) rad
    neck_q: np.ndarray  # (K, n_neck) the neck joints that put B0 where the map needs it
    index: np.ndarray  # (K,) the map's index of the voxel holding the target, seen from B0
    target_in_b0: np.ndarray  # (K, 3) the target position in B0's frame (on the map's sample plane)
    direction_in_b0: np.ndarray  # (K, 3) the target direction in B0's frame

    def __len__(self) -> int:
        return len(self.index)

    def placements(self) -> list[BasePlacement]:
        """The candidates as :class:`~snakehead.model.robot.BasePlacement` objects."""
        return [BasePlacement(float(a), float(b), float(c)) for a, b, c in zip(self.x, self.y, self.yaw)]


def neck_frames(robot: SnakeRobot, base_configuration: npt.ArrayLike | None = None, samples: int = 7
                ) -> tuple[np.ndarray, np.ndarray]:
    """B0's world poses (J, 4, 4) with the base at the origin placement (x = y = yaw = 0), for a grid of
    ``samples`` values per neck joint within its limits, and those neck joint values (J, n_neck).

    base_configuration: the whole-body joints whose base part is kept (default: ``backbone.initial_configuration``).
    The one function of inverse reachability that asks the robot model anything."""
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise InputError(f"samples must be a positive integer, got {samples!r}")
    if base_configuration is None:
        base_configuration = initial_configuration(robot)
    q0 = joint_vector(base_configuration, robot.n_joints, "base_configuration")
    neck = robot.parts.neck
    lo, hi = robot.lower[neck], robot.upper[neck]
    axes = [np.linspace(a, b, int(samples)) if samples > 1 else np.array([0.5 * (a + b)]) for a, b in zip(lo, hi)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(axes))
    qs = np.tile(q0, (len(grid), 1))
    qs[:, neck] = grid
    frames = robot.frames_many(qs, BasePlacement())[:, robot.link_index(robot.parts.neck_end)]
    return frames, grid


def placements_from_frames(workspace_map: ReachabilityMap, frames: npt.ArrayLike, neck_q: npt.ArrayLike,
                           position: npt.ArrayLike, direction: npt.ArrayLike, *, yaw_samples: int = 72,
                           min_index: float = 0.0, limit: int = 20) -> PlacementCandidates:
    """Base placements (planar moves of the origin placement) that put one of ``frames`` (J, 4, 4), B0's poses at
    the origin placement, where the map (in B0's frame) reaches the target ``position``, ``direction`` (world).

    For each frame and each of ``yaw_samples`` yaws: the target direction seen from B0, its nearest map direction
    k, and the map voxels whose sphere point in direction k lies within half a voxel of the height plane of the
    target; the target position seen from B0 is that point moved onto the plane, which fixes x, y. Kept: the
    best voxel per (frame, yaw) when its index is at least ``min_index``; returned: the ``limit`` best."""
    m = require_map(workspace_map, needs=("poses",), what="workspace_map")  # whole, with per-direction results
    p, d, single = position_direction_pairs(position, direction)
    if not single:
        raise InputError("placements take one target: position and direction of shape (3,)")
    for name, v in (("yaw_samples", yaw_samples), ("limit", limit)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise InputError(f"{name} must be a positive integer, got {v!r}")
    frames = np.asarray(frames, dtype=float)
    neck_q = np.asarray(neck_q, dtype=float)
    if frames.ndim != 3 or frames.shape[1:] != (4, 4) or len(frames) != len(neck_q):
        raise InputError("frames must be (J, 4, 4), one per row of neck_q")
    p, d = p[0], d[0]
    bits = direction_bits(m)
    index = np.where(m.indices >= float(min_index) - 1e-9, m.indices, -1.0)
    dirs = m.sphere_directions
    r = 0.5 * m.voxel_size
    yaws = 2.0 * np.pi * np.arange(int(yaw_samples)) / int(yaw_samples)
    c, s = np.cos(yaws), np.sin(yaws)
    # The target direction with the placement's yaw undone: Rz(-yaw) d, (Y, 3).
    d_unyawed = np.stack([c * d[0] + s * d[1], -s * d[0] + c * d[1], np.full_like(c, d[2])], axis=1)
    best = []  # (score, j, yaw index, voxel row, a (3,))
    for j, T in enumerate(frames):
        R, t = T[:3, :3], T[:3, 3]
        up = R[2]  # the world's z-axis in B0's frame: (T a).z = up . a + t_z
        d_local = d_unyawed @ R  # (Y, 3): R^T Rz(-yaw) d
        ks = np.argmax(d_local @ dirs.T, axis=1)
        slack = r * np.abs(up).sum()  # a cube of half-side r around a point reaches this far along `up`
        for k in np.unique(ks):
            points = m.centers + r * dirs[k]  # the map's samples of direction k, B0 frame
            offset = points @ up + t[2] - p[2]  # height of each sample above the target's plane
            near = np.nonzero(bits[:, k] & (np.abs(offset) <= slack) & (index >= 0))[0]
            if len(near) == 0:
                continue
            # The best voxel (highest index, then nearest the plane), the same for every yaw with this k.
            v = near[np.lexsort((np.abs(offset[near]), -index[near]))[0]]
            a = points[v] - offset[v] * up  # onto the plane (|up| = 1)
            for y in np.nonzero(ks == k)[0]:
                best.append((index[v], -abs(offset[v]), j, y, v, a))
    if not best:
        empty = np.zeros((0, 3))
        return PlacementCandidates(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros((0, neck_q.shape[1])),
                                   np.zeros(0), empty, empty)
    best.sort(key=lambda e: (-e[0], -e[1], e[2], e[3]))
    best = best[:int(limit)]
    js = np.array([e[2] for e in best])
    ys = np.array([e[3] for e in best])
    a = np.array([e[5] for e in best])
    world_a = np.einsum("nij,nj->ni", frames[js, :3, :3], a) + frames[js, :3, 3]  # at the origin placement
    cy, sy = np.cos(yaws[ys]), np.sin(yaws[ys])
    x = p[0] - (cy * world_a[:, 0] - sy * world_a[:, 1])
    y = p[1] - (sy * world_a[:, 0] + cy * world_a[:, 1])
    return PlacementCandidates(x=x, y=y, yaw=np.remainder(yaws[ys] + np.pi, 2 * np.pi) - np.pi,
                               neck_q=neck_q[js], index=np.array([e[0] for e in best]),
                               target_in_b0=a, direction_in_b0=np.einsum("nji,nj->ni", frames[js, :3, :3], d_unyawed[ys]))


def base_placements(robot: SnakeRobot, workspace_map: ReachabilityMap, position: npt.ArrayLike,
                    direction: npt.ArrayLike, *, base_configuration: npt.ArrayLike | None = None,
                    neck_samples: int = 7, yaw_samples: int = 72, min_index: float = 0.0, limit: int = 20
                    ) -> PlacementCandidates:
    """Candidate placements of ``robot``'s base on the ground from which its head reaches ``position`` (3,) m,
    pointing along ``direction`` (3,) (world), by the head's reachability map: best index first.

    The base keeps the base joints of ``base_configuration`` (default: the initial configuration); the neck
    joints take ``neck_samples`` values each; yaws are sampled every 360 / ``yaw_samples`` degrees. See the
    module's doc. The result says, for each placement, the neck joints and the target as seen from B0."""
    require_map(workspace_map, robot, needs=("poses",), what="workspace_map")  # also: a map of this robot's head
    frames, neck_q = neck_frames(robot, base_configuration, neck_samples)
    return placements_from_frames(workspace_map, frames, neck_q, position, direction, yaw_samples=yaw_samples,
                                  min_index=min_index, limit=limit)


__all__ = ["PlacementCandidates", "neck_frames", "placements_from_frames", "base_placements"]
