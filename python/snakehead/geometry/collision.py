"""Collisions of the body's collision boxes: with the ground, with itself and with obstacles.

* :func:`ground_clearance`, :func:`below_ground`, :func:`touching_ground` -- how high every link's box stays
  above the ground.
* :func:`self_clearance` -- the separating-axis gap between boxes of links that are not neighbours.
* :func:`collision_check` -- the links' boxes against :mod:`snakehead.geometry.obstacles`.
* :func:`box_box_sat`, :func:`box_box_distance`, :func:`box_wall_collision` -- the box tests they use.

Everything is vectorised over the time samples (numpy); Python loops run over links or box features. The
separating-axis test runs in the C++ core (``snakehead._core.box_pair_gaps`` and ``box_pair_min_gaps``,
include/snakehead/box_collision.hpp).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from .._validate import finite_array, positive
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .obstacles import BoxObstacle, WallWithHole

import numpy.typing as npt
from typing import Any, Sequence

#: A link whose box dips lower than this below the ground (m) is driven into it by the plan; a box within
#: this distance of the ground touches it (the base lies at exactly 0).
GROUND_TOLERANCE = 1e-3


def _trajectory(robot: SnakeRobot, qs: npt.ArrayLike) -> np.ndarray:
    a = finite_array(qs, "qs")
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != robot.n_joints or a.shape[0] < 1:
        raise ValueError(f"qs has shape {np.shape(qs)}; expected (T, {robot.n_joints}) or ({robot.n_joints},)")
    return a


def ground_clearance(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
    """Height (m) of the lowest corner of every link's collision box above the ground: (T, n_links).

    qs (T, n) (or (n,) -> (1, n_links)). Negative values are below the ground. The base links lying flat are
    at 0 (touching); frames without a box (markers) get +inf.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    frames = robot.frames_many(qs, base)
    out = np.full(frames.shape[:2], np.inf)
    links = robot.boxed_links
    out[:, links] = robot.lowest_box_z(frames, links)
    return out


def below_ground(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                 tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose boxes go deeper than ``tolerance`` m into the ground.

    The base links are never flagged (they lie on it). A box within ``tolerance`` of the ground merely touches.
    """
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = robot.lifted_links
    out[:, links] = clearance[:, links] < -tolerance
    return out


def touching_ground(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                    tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose boxes come within ``tolerance`` m of the ground (or
    below it). The base links, which lie on the ground, are never flagged."""
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = robot.lifted_links
    out[:, links] = clearance[:, links] < tolerance
    return out


# ------------------------------------------------------------------------------------------------
# obstacles
# ------------------------------------------------------------------------------------------------
_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)
_EDGES = np.array([(a, b) for a in range(8) for b in range(a + 1, 8)
                   if np.count_nonzero(_SIGNS[a] != _SIGNS[b]) == 1])  # (12, 2) vertex pairs


def _link_boxes(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """World collision boxes of the links along a trajectory: links (k,), centres (T, k, 3), rotations
    (T, k, 3, 3), half extents (k, 3)."""
    links = robot.boxed_links
    B = robot.frames_many(qs, base)[:, links] @ robot.box_origins[links]
    return links, B[..., :3, 3], B[..., :3, :3], 0.5 * robot.box_sizes[links]


def self_clearance(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
    """Self-collision of the body along a trajectory: (T,) the smallest separating-axis gap (m) between the
    collision boxes of any two links that are not neighbours in the chain (neighbours share a joint and
    always touch there). > 0: no two such boxes meet (and this is a lower bound of their distance); <= 0: some
    overlap. qs (T, n) or (n,) -> (1,).
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    links, c, R, h = _link_boxes(robot, qs, base)
    pairs = np.stack(np.triu_indices(len(links), k=2), axis=1)  # boxed links two or more apart in the chain
    return _core.box_pair_min_gaps(c, R, h, pairs)  # +inf with fewer than three boxed links: no pair can meet


def _broadcast_boxes(ca: np.ndarray, Ra: np.ndarray, ha: np.ndarray, cb: np.ndarray, Rb: np.ndarray, hb: np.ndarray) -> list[np.ndarray]:
    """Broadcast two batches of boxes (centres (..., 3), rotations (..., 3, 3), half extents (..., 3))."""
    arrs = [np.asarray(v, float) for v in (ca, Ra, ha, cb, Rb, hb)]
    core = [(3,), (3, 3), (3,), (3,), (3, 3), (3,)]
    for a, cs, name in zip(arrs, core, ("centre", "rotation", "half extents") * 2):
        if a.shape[a.ndim - len(cs):] != cs:
            raise ValueError(f"box {name} has shape {a.shape}; expected (..., {', '.join(map(str, cs))})")
    batch = np.broadcast_shapes(*(a.shape[:a.ndim - len(cs)] for a, cs in zip(arrs, core)))
    return [np.broadcast_to(a, batch + cs) for a, cs in zip(arrs, core)]


def box_box_sat(ca: np.ndarray, Ra: np.ndarray, ha: np.ndarray, cb: np.ndarray, Rb: np.ndarray, hb: np.ndarray
                ) -> np.ndarray:
    """Separating-axis test of boxes A (centres (..., 3), rotations (..., 3, 3), half extents (..., 3)) and B.

    Returns the largest gap (m) over the 15 candidate axes (3 + 3 face normals, 9 edge cross products): > 0 the
    boxes are apart (and this is a lower bound of their distance), <= 0 they intersect (and minus it is the
    penetration depth along the best axis). Worked in B's frame with C = Rb^T Ra (Gottschalk's OBB test, with
    each gap divided by its axis' length so that it is in metres).
    """
    ca, Ra, ha, cb, Rb, hb = _broadcast_boxes(ca, Ra, ha, cb, Rb, hb)
    batch = ca.shape[:-1]
    n = int(np.prod(batch))
    # The C++ core's batch entry: the n boxes A then the n boxes B as one sample of 2n boxes, paired (i, n + i).
    centres = np.concatenate([ca.reshape(n, 3), cb.reshape(n, 3)])[None]
    rotations = np.concatenate([Ra.reshape(n, 3, 3), Rb.reshape(n, 3, 3)])[None]
    half_extents = np.concatenate([ha.reshape(n, 3), hb.reshape(n, 3)])
    pairs = np.stack([np.arange(n), n + np.arange(n)], axis=1)
    return _core.box_pair_gaps(centres, rotations, half_extents, pairs).reshape(batch)


def _point_box_distance(p: np.ndarray, c: np.ndarray, R: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Distance (m) of points p (..., 3) to boxes (c (..., 3), R (..., 3, 3), h (..., 3)); 0 inside."""
    loc = np.einsum("...ik,...i->...k", R, p - c)
    return np.linalg.norm(np.maximum(np.abs(loc) - h, 0.0), axis=-1)


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


def _segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Distance between segments [p1, q1] and [p2, q2], arrays (..., 3)."""
    s, t = segment_closest(p1, q1, p2, q2)
    diff = (p1 + s[..., None] * (q1 - p1)) - (p2 + t[..., None] * (q2 - p2))
    return np.linalg.norm(diff, axis=-1)


def box_box_distance(ca: np.ndarray, Ra: np.ndarray, ha: np.ndarray, cb: np.ndarray, Rb: np.ndarray, hb: np.ndarray
                     ) -> np.ndarray:
    """Signed distance (m) between boxes A and B (shapes as :func:`box_box_sat`): exact when apart (the
    smallest of vertex-box and edge-edge distances, which covers every closest-feature pair of two convex
    polyhedra), minus the separating-axis penetration depth when they intersect."""
    ca, Ra, ha, cb, Rb, hb = _broadcast_boxes(ca, Ra, ha, cb, Rb, hb)
    sat = box_box_sat(ca, Ra, ha, cb, Rb, hb)
    va = ca[..., None, :] + np.einsum("...ik,...vk->...vi", Ra, _SIGNS * ha[..., None, :])  # (..., 8, 3)
    vb = cb[..., None, :] + np.einsum("...ik,...vk->...vi", Rb, _SIGNS * hb[..., None, :])
    d = np.minimum(  # vertices of one box against the other box
        _point_box_distance(va, cb[..., None, :], Rb[..., None, :, :], hb[..., None, :]).min(-1),
        _point_box_distance(vb, ca[..., None, :], Ra[..., None, :, :], ha[..., None, :]).min(-1))
    ea0, ea1 = va[..., _EDGES[:, 0], :], va[..., _EDGES[:, 1], :]  # (..., 12, 3)
    eb0, eb1 = vb[..., _EDGES[:, 0], :], vb[..., _EDGES[:, 1], :]
    dee = _segment_distance(ea0[..., :, None, :], ea1[..., :, None, :], eb0[..., None, :, :], eb1[..., None, :, :])
    d = np.minimum(d, dee.min(axis=(-1, -2)))
    return np.where(sat > 0.0, d, sat)


def box_wall_collision(c: np.ndarray, R: np.ndarray, h: np.ndarray, wall: WallWithHole) -> np.ndarray:
    """Exact intersection test of boxes (c (..., 3), R (..., 3, 3), h (..., 3)) with a wall's solid: (...) bool.

    The box meets the solid (slab minus the hole's cylinder) exactly when it meets the slab (separating axes)
    and its part inside the slab's infinite layer is not wholly inside the cylinder. That part is convex and
    the cylinder is convex, so it is enough to test its vertices: the box's vertices in the layer and the points
    where the box's edges cross the layer's two faces. (The hole lies inside the wall, so leaving the cylinder
    inside the layer means entering the solid.)
    """
    slab = wall.slab()
    meets = box_box_sat(c, R, h, slab.centre, slab.rotation, slab.size / 2) <= 0.0
    W = wall.rotation
    v = c[..., None, :] + np.einsum("...ik,...vk->...vi", R, _SIGNS * h[..., None, :])  # (..., 8, 3)
    loc = (v - wall.centre) @ W  # hole coordinates
    half_t = wall.size[2] / 2
    r2 = (wall.hole_diameter / 2) ** 2
    in_layer = np.abs(loc[..., 2]) <= half_t
    out_cyl = (loc[..., 0] ** 2 + loc[..., 1] ** 2) > r2
    bad = (in_layer & out_cyl).any(axis=-1)
    a, b = loc[..., _EDGES[:, 0], :], loc[..., _EDGES[:, 1], :]  # (..., 12, 3)
    for face in (-half_t, half_t):
        da, db = a[..., 2] - face, b[..., 2] - face
        cross = (da * db <= 0.0) & (da != db)
        s = np.where(cross, da / np.where(da != db, da - db, 1.0), 0.0)
        p = a + s[..., None] * (b - a)
        bad |= (cross & ((p[..., 0] ** 2 + p[..., 1] ** 2) > r2)).any(axis=-1)
    return meets & bad


def _box_surface_points(h: np.ndarray, spacing: float) -> np.ndarray:
    """Points on the surface of a box of half extents h (3,), in its frame, at most ``spacing`` m apart."""
    pts = []
    for k in range(3):
        i, j = [a for a in range(3) if a != k]
        ni = max(2, int(np.ceil(2 * h[i] / spacing)) + 1)
        nj = max(2, int(np.ceil(2 * h[j] / spacing)) + 1)
        gi, gj = np.meshgrid(np.linspace(-h[i], h[i], ni), np.linspace(-h[j], h[j], nj), indexing="ij")
        for sgn in (-1.0, 1.0):
            p = np.zeros((gi.size, 3))
            p[:, i], p[:, j], p[:, k] = gi.ravel(), gj.ravel(), sgn * h[k]
            pts.append(p)
    return np.unique(np.concatenate(pts), axis=0)


@dataclass(frozen=True)
class CollisionReport:
    """Result of :func:`collision_check` for T samples, k boxed links and the obstacles in the order given.

    distance (T,) m: the smallest distance between any link box and any obstacle (<= 0 on collision);
    collides (T,) bool; link_distance (T, k, n_obstacles) and link_collides (T, k, n_obstacles) per link and
    obstacle; links (k,) indices into ``robot.link_names``.
    """

    distance: np.ndarray
    collides: np.ndarray
    link_distance: np.ndarray
    link_collides: np.ndarray
    links: np.ndarray


def collision_check(robot: SnakeRobot, qs: np.ndarray, obstacles: Sequence[Any], base: BasePlacement | None = None, *,
                    exact_within: float = 0.05, spacing: float = 0.004) -> CollisionReport:
    """Collisions of every link's collision box with obstacles along a trajectory qs (T, n).

    The collision flags are exact. The distances are exact wherever they are below ``exact_within`` m; pairs
    that the separating-axis test already puts farther apart report that test's gap, a lower bound that is
    itself above ``exact_within`` (this keeps long trajectories fast).

    * :class:`BoxObstacle`: exact signed distance (:func:`box_box_distance`; minus the penetration depth when
      they intersect).
    * :class:`WallWithHole`: exact intersection test (:func:`box_wall_collision`); the distance of a nearby
      link that does not collide is the smallest exact distance from points on its box's surface, at most
      ``spacing`` m apart, to the wall's solid: an upper bound, too large by at most about spacing / sqrt(2).
      Colliding links get 0.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    if isinstance(obstacles, (BoxObstacle, WallWithHole)):
        obstacles = [obstacles]
    obstacles = list(obstacles)
    if not obstacles:
        raise ValueError("no obstacles given")
    for ob in obstacles:
        if not isinstance(ob, (BoxObstacle, WallWithHole)):
            raise TypeError(f"obstacles must be BoxObstacle or WallWithHole, got {type(ob).__name__}")
    spacing = positive(spacing, "spacing")
    try:
        exact_within = float(exact_within)
    except (TypeError, ValueError):
        raise ValueError(f"exact_within must be a number (m, may be inf), got {exact_within!r}") from None
    if np.isnan(exact_within):
        raise ValueError("exact_within is NaN")
    links, c, R, h = _link_boxes(robot, qs, base)
    T, k = c.shape[:2]
    hb = np.broadcast_to(h, (T, k, 3))
    dist = np.empty((T, k, len(obstacles)))
    hit = np.empty((T, k, len(obstacles)), bool)
    for o, ob in enumerate(obstacles):
        box = ob if isinstance(ob, BoxObstacle) else ob.slab()
        d = box_box_sat(c, R, hb, box.centre, box.rotation, box.size / 2)  # lower bound of the distance
        near = d <= exact_within
        if isinstance(ob, BoxObstacle):
            d[near] = box_box_distance(c[near], R[near], hb[near], box.centre, box.rotation, box.size / 2)
            collide = d <= 0.0
        else:
            collide = np.zeros((T, k), bool)
            collide[near] = box_wall_collision(c[near], R[near], hb[near], ob)
            for li in range(k):  # per link (its own surface samples), vectorised over the near samples
                rows = np.flatnonzero(near[:, li] & ~collide[:, li])
                if rows.size == 0:
                    continue
                s = _box_surface_points(h[li], spacing)  # (S, 3)
                p = c[rows, li, None, :] + np.einsum("tik,sk->tsi", R[rows, li], s)
                d[rows, li] = ob.distance_to_points(p).min(axis=1)
            d = np.where(collide, 0.0, d)
        dist[..., o], hit[..., o] = d, collide
    return CollisionReport(dist.min(axis=(1, 2)), np.asarray(hit.any(axis=(1, 2))), dist, hit, links)
