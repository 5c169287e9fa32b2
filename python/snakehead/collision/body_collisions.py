"""Collisions of the body's collision shapes: with the ground, with itself and with obstacles.

* :func:`ground_clearance`, :func:`below_ground`, :func:`touching_ground` -- how high every link's shapes stay
  above the ground.
* :func:`self_clearance` -- the smallest signed distance between shapes of links two or more joints apart.
* :func:`collision_check` -- the links' shapes against :mod:`snakehead.geometry.obstacles`.
* :func:`segment_closest` -- closest points of segments (the whole-body solve's capsules).

All of it runs on :mod:`snakehead.geometry.shapes` (the C++ core on Debian's FCL, many samples per call).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import finite_array
from ..geometry.obstacles import OBSTACLE_TYPES
from ..geometry.shapes import ShapeSet, pair_distances, pair_min_distances
from ..ground_contact import GROUND_TOLERANCE
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot

__all__ = ["GROUND_TOLERANCE", "ground_clearance", "below_ground", "touching_ground", "self_clearance",
           "obstacle_shapes", "segment_closest", "CollisionReport", "collision_check"]


_WORLD = np.eye(4)[None, None]  # (1, 1, 4, 4): the one frame of the obstacles' shapes


def _trajectory(robot: SnakeRobot, qs: npt.ArrayLike) -> np.ndarray:
    a = finite_array(qs, "qs")
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != robot.n_joints or a.shape[0] < 1:
        raise InputError(f"qs has shape {np.shape(qs)}; expected (T, {robot.n_joints}) or ({robot.n_joints},)")
    return a


def ground_clearance(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
    """Height (m) of the lowest point of every link's collision shapes above the ground: (T, n_links).

    qs (T, n) (or (n,) -> (1, n_links)). Negative values are below the ground. The base links lying flat are
    at 0 (touching); frames without shapes (markers) get +inf.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    frames = robot.frames_many(qs, base)
    out = np.full(frames.shape[:2], np.inf)
    links = robot.shaped_links
    out[:, links] = robot.lowest_z(frames, links)
    return out


def below_ground(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                 tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose shapes go deeper than ``tolerance`` m into the ground.

    The base links are never flagged (they lie on it). A shape within ``tolerance`` of the ground merely touches.
    """
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = robot.lifted_links
    out[:, links] = clearance[:, links] < -tolerance
    return out


def touching_ground(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                    tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose shapes come within ``tolerance`` m of the ground (or
    below it). The base links, which lie on the ground, are never flagged."""
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = robot.lifted_links
    out[:, links] = clearance[:, links] < tolerance
    return out


def self_clearance(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                   cutoff: float = np.inf) -> np.ndarray:
    """Self-collision of the body along a trajectory: (T,) the smallest signed distance (m) between the collision
    shapes of any two links two or more joints apart (links one joint apart touch at it; the links of one rigid
    module never move apart). > 0: apart; <= 0: some overlap (minus the deepest penetration). Exact below
    ``cutoff``, a lower bound above it; +inf when no two links can meet. qs (T, n) or (n,) -> (1,).
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    frames = robot.frames_many(qs, base)
    return pair_min_distances(frames, robot.geometry, frames, robot.geometry, robot.self_collision_pairs, cutoff)


class _ObstacleSets:
    """The shape sets of obstacle lists already seen (a wall's 32 hulls are costly to build; the planner checks the
    same obstacles many times a plan), keyed by the obstacles' identities and holding them so that no id is reused
    while its entry lives. Obstacles are immutable. At most ``size`` entries; the oldest go first."""

    def __init__(self, size: int = 32) -> None:
        self.size = size
        self._sets: dict[tuple[int, ...], tuple[tuple, ShapeSet, np.ndarray]] = {}

    def get(self, obstacles: Sequence[Any]) -> tuple[ShapeSet, np.ndarray]:
        key = tuple(id(ob) for ob in obstacles)
        hit = self._sets.get(key)
        if hit is None:
            shapes, owner = [], []
            for o, ob in enumerate(obstacles):
                for shape in ob.shapes():
                    shapes.append(shape)
                    owner.append(o)
            hit = (tuple(obstacles), ShapeSet(tuple(shapes), 1), np.array(owner, dtype=np.int64))
            if len(self._sets) >= self.size:
                self._sets.pop(next(iter(self._sets)))
            self._sets[key] = hit
        return hit[1], hit[2]


_OBSTACLE_SETS = _ObstacleSets()


def obstacle_shapes(obstacles: Sequence[Any]) -> tuple[ShapeSet, np.ndarray]:
    """The obstacles' convex world shapes as one set (on one identity frame) and the obstacle (S,) of each."""
    return _OBSTACLE_SETS.get(list(obstacles))


# ------------------------------------------------------------------------------------------------
# segments (the whole-body solve's capsules)
# ------------------------------------------------------------------------------------------------
def segment_closest(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parameters (s, t) in [0, 1] of the closest points p1 + s (q1 - p1) and p2 + t (q2 - p2) of segments
    [p1, q1] and [p2, q2], arrays (..., 3) (Ericson, Real-Time Collision Detection, 5.1.9), vectorised,
    degenerate segments included."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.sum(d1 * d1, -1)
    e = np.sum(d2 * d2, -1)
    f = np.sum(d2 * r, -1)
    c = np.sum(d1 * r, -1)
    b = np.sum(d1 * d2, -1)
    eps = 1e-18
    den = a * e - b * b
    s = np.where(den > eps, np.clip((b * f - c * e) / np.where(den > eps, den, 1.0), 0.0, 1.0), 0.0)
    s = np.where(a <= eps, 0.0, s)
    t = np.where(e > eps, (b * s + f) / np.where(e > eps, e, 1.0), 0.0)
    # t outside [0, 1]: clamp it and recompute s
    t_c = np.clip(t, 0.0, 1.0)
    s_c = np.where(a > eps, np.clip((t_c * b - c) / np.where(a > eps, a, 1.0), 0.0, 1.0), 0.0)
    return np.where((t < 0.0) | (t > 1.0), s_c, s), t_c


@dataclass(frozen=True)
class CollisionReport:
    """Result of :func:`collision_check` for T samples, k links with shapes and the obstacles in the order given.

    distance (T,) m: the smallest signed distance between any link shape and any obstacle (<= 0 on collision);
    collides (T,) bool; link_distance (T, k, n_obstacles) and link_collides (T, k, n_obstacles) per link and
    obstacle; links (k,) indices into ``robot.link_names``.
    """

    distance: np.ndarray
    collides: np.ndarray
    link_distance: np.ndarray
    link_collides: np.ndarray
    links: np.ndarray


def collision_check(robot: SnakeRobot, qs: np.ndarray, obstacles: Sequence[Any], base: BasePlacement | None = None, *,
                    exact_within: float = 0.05) -> CollisionReport:
    """Collisions of every link's collision shapes with obstacles along a trajectory qs (T, n).

    Signed distances of convex shapes (an obstacle's ``shapes()``; a wall's hole as an inscribed polygon), exact
    wherever they are below ``exact_within`` m; pairs farther apart report a lower bound that is itself above
    ``exact_within`` (this keeps long trajectories fast). The collision flags are exact.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    if isinstance(obstacles, OBSTACLE_TYPES):
        obstacles = [obstacles]
    obstacles = list(obstacles)
    if not obstacles:
        raise InputError("no obstacles given")
    for ob in obstacles:
        if not isinstance(ob, OBSTACLE_TYPES):
            raise InputTypeError(f"obstacles must be {', '.join(t.__name__ for t in OBSTACLE_TYPES)}, "
                            f"got {type(ob).__name__}")
    try:
        exact_within = float(exact_within)
    except (TypeError, ValueError):
        raise InputError(f"exact_within must be a number (m, may be inf), got {exact_within!r}") from None
    if np.isnan(exact_within):
        raise InputError("exact_within is NaN")
    scene, owner = obstacle_shapes(obstacles)
    links = robot.shaped_links
    mine = robot.geometry.shapes_of(links)
    pairs = np.stack(np.meshgrid(mine, np.arange(len(owner)), indexing="ij"), axis=-1).reshape(-1, 2)
    frames = robot.frames_many(qs, base)
    d = pair_distances(frames, robot.geometry, _WORLD, scene, pairs, exact_within)  # (T, P)
    group = np.searchsorted(links, robot.geometry.shape_frames[pairs[:, 0]]) * len(obstacles) + owner[pairs[:, 1]]
    dist = np.full((len(qs), len(links) * len(obstacles)), np.inf)
    for g in np.unique(group):  # a link's distance to an obstacle: its closest pair of shapes
        dist[:, g] = d[:, group == g].min(axis=1)
    per_link = dist.reshape(len(qs), len(links), len(obstacles))
    hit = per_link <= 0.0
    return CollisionReport(per_link.min(axis=(1, 2)), np.asarray(hit.any(axis=(1, 2))), per_link, hit, links)
