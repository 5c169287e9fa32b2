"""Stability of the snake's whole-body motion: paper Section 3.1, Eqs. 23-40.

Everything is in the world frame (z up, ground at z = 0). Where the base lies is a parameter
``base`` (a :class:`~snakehead.robot.BasePlacement`, default ``BasePlacement()``: tail at the origin,
body along +x).

* :func:`center_of_mass` -- Eq. 23, for one configuration (16,) or a trajectory (T, 16).
* :func:`support_polygon` -- Eq. 24, convex hull of the base's ground contacts.
* :func:`static_margin`, :func:`is_statically_stable` -- signed distance of the CoM's ground
  projection to the polygon's edge (positive inside).
* :func:`momenta_from_velocities`, :func:`momenta` -- Eqs. 25-31, linear and angular momentum about the
  world origin along a trajectory.
* :func:`zmp`, :func:`dynamic_stability` -- Eqs. 36-40 with p_z = 0 and the ZMP's margin in the polygon.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull
from scipy.spatial import QhullError

from ._validate import finite_array, joint_vector, positive
from .robot import BasePlacement, SnakeRobot

#: Standard gravity (m/s^2); g in Eq. 38 is (0, 0, -GRAVITY).
GRAVITY = 9.80665

#: A base link counts as lying on the ground when the lowest corner of its collision box is below this
#: height (m). The default robot's flat base links sit at exactly 0.
CONTACT_TOLERANCE = 1e-3

#: Contact models of :func:`support_polygon`.
CONTACT_MODELS = ("endpoints", "footprint")


# ------------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------------
def _check_robot(robot) -> SnakeRobot:
    if not isinstance(robot, SnakeRobot):
        raise TypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return robot


def _check_base(base) -> BasePlacement:
    if base is None:
        return BasePlacement()
    if not isinstance(base, BasePlacement):
        raise TypeError(f"base must be a BasePlacement or None, got {type(base).__name__}")
    return base


def _joint_matrix(robot: SnakeRobot, q, name: str = "q") -> tuple[np.ndarray, bool]:
    """q as (T, n) and whether it was a single vector (n,)."""
    a = finite_array(q, name)
    n = robot.n_joints
    if a.ndim == 1:
        if a.shape != (n,):
            raise ValueError(f"{name} has shape {a.shape}; expected ({n},) or (T, {n})")
        return a[None, :], True
    if a.ndim != 2 or a.shape[1] != n:
        raise ValueError(f"{name} has shape {a.shape}; expected ({n},) or (T, {n})")
    if a.shape[0] < 1:
        raise ValueError(f"{name} has no samples")
    return a, False


def _mass_links(robot: SnakeRobot) -> np.ndarray:
    """Indices (into link_names) of the frames that carry mass."""
    return np.flatnonzero(robot.masses > 0.0)


def _box_links(robot: SnakeRobot) -> np.ndarray:
    """Indices (into link_names) of the frames that have a collision box."""
    return np.flatnonzero(np.all(robot.box_sizes > 0.0, axis=1))


def _base_link_range(robot: SnakeRobot) -> tuple[int, int]:
    """(first, end) indices into link_names: the base part's links are link_names[first:end - 1] and
    their endpoints are the origins of link_names[first:end] (the last one being the base_end marker)."""
    end = robot.body.link_index(robot.parts.base_end) + 1
    return 0, end


def _lowest_corner_z(frames: np.ndarray, robot: SnakeRobot, links: np.ndarray) -> np.ndarray:
    """Lowest z of the collision boxes of ``links`` (indices into link_names): (T, len(links)).

    A box of half-extents h with centre c and rotation R reaches down to c_z - sum_k |R[2, k]| h_k.
    """
    B = frames[:, links] @ robot.box_origins[links]  # (T, k, 4, 4) world pose of each box centre
    half = 0.5 * robot.box_sizes[links]  # (k, 3)
    return B[..., 2, 3] - np.einsum("tkj,kj->tk", np.abs(B[..., 2, :3]), half)


def _contact_points_many(robot: SnakeRobot, frames: np.ndarray, contact: str,
                         tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Ground contact points of the base part along a trajectory.

    Returns points (T, N, 2) (world x, y) and active (T, N) bool: which points touch the ground.
    """
    if contact not in CONTACT_MODELS:
        raise ValueError(f"contact must be one of {CONTACT_MODELS}, got {contact!r}")
    first, end = _base_link_range(robot)
    links = np.arange(first, end - 1)
    links = links[np.all(robot.box_sizes[links] > 0.0, axis=1)]
    if links.size == 0:
        raise ValueError("the base part has no links with a collision box; no support polygon")
    on_ground = _lowest_corner_z(frames, robot, links) <= tolerance  # (T, k)
    if contact == "endpoints":
        # Eq. 24: p_i are the endpoints of the base links, i.e. the origins of consecutive frames
        # (each link's frame is at its proximal joint; the next frame in chain order is at its distal end).
        prox = frames[:, links][..., :2, 3]
        dist = frames[:, links + 1][..., :2, 3]
        pts = np.concatenate([prox, dist], axis=1)  # (T, 2k, 2)
        active = np.concatenate([on_ground, on_ground], axis=1)
        return pts, active
    # footprint: the four bottom corners of each base box (its face nearest the ground).
    B = frames[:, links] @ robot.box_origins[links]  # (T, k, 4, 4)
    half = 0.5 * robot.box_sizes[links]  # (k, 3)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)
    local = signs[None, :, :] * half[:, None, :]  # (k, 8, 3)
    world = np.einsum("tkij,kcj->tkci", B[..., :3, :3], local) + B[..., None, :3, 3]  # (T, k, 8, 3)
    # keep the 4 lowest corners of each box (its bottom face when the link lies flat)
    order = np.argsort(world[..., 2], axis=2, kind="stable")[..., :4]
    low = np.take_along_axis(world, order[..., None], axis=2)  # (T, k, 4, 3)
    T = frames.shape[0]
    pts = low[..., :2].reshape(T, -1, 2)
    active = np.repeat(on_ground, 4, axis=1)
    return pts, active


def polygon_margin_many(points: np.ndarray, active: np.ndarray, xy: np.ndarray,
                        chunk: int = 4096) -> np.ndarray:
    """Signed distance (m) of ``xy`` to the convex hull of the active ``points``, positive inside.

    points (T, N, 2), active (T, N) bool, xy (T, 2) -> (T,). Vectorised over T without building hulls:
    an ordered pair (i, j) of distinct active points is an edge of the counter-clockwise hull exactly when
    every active point lies on or left of the line i -> j. Inside the hull the distance to its boundary is the
    smallest distance to those edges; outside, the distance to the hull is also the smallest distance to them
    (as segments). Inside means every signed distance to those edge lines is >= 0.
    A degenerate hull (collinear points) has zero area: the margin is then minus the distance to its segment
    (0 on it). Samples with no active point get -inf.
    """
    points = np.asarray(points, float)
    active = np.asarray(active, bool)
    xy = np.asarray(xy, float)
    T, N, _ = points.shape
    out = np.empty(T)
    ii, jj = np.nonzero(~np.eye(N, dtype=bool))  # all ordered pairs i != j
    for s in range(0, T, chunk):  # chunks bound memory: T * N^2 * N floats otherwise
        P = points[s:s + chunk]
        A = active[s:s + chunk]
        X = xy[s:s + chunk]
        a = P[:, ii]  # (t, m, 2)
        e = P[:, jj] - a  # (t, m, 2)
        elen = np.hypot(e[..., 0], e[..., 1])  # (t, m)
        scale = max(1.0, float(np.abs(P).max(initial=0.0)))
        eps = 1e-12 * scale
        # cross(e, p_k - a) for every point k: (t, m, N)
        d = P[:, None, :, :] - a[:, :, None, :]
        cross = e[..., 0, None] * d[..., 1] - e[..., 1, None] * d[..., 0]
        left = (cross >= -eps * np.maximum(elen, eps)[..., None]) | ~A[:, None, :]
        edge = left.all(axis=2) & A[:, ii] & A[:, jj] & (elen > eps)  # (t, m)
        single = A.sum(axis=1) == 1
        # distance of X to each candidate segment and signed distance to its line
        w = X[:, None, :] - a  # (t, m, 2)
        safe = np.where(elen > eps, elen, 1.0)
        u = np.clip((w * e).sum(-1) / safe ** 2, 0.0, 1.0)
        seg = np.hypot(w[..., 0] - u * e[..., 0], w[..., 1] - u * e[..., 1])
        line = (e[..., 0] * w[..., 1] - e[..., 1] * w[..., 0]) / safe  # positive on the left
        seg_min = np.where(edge, seg, np.inf).min(axis=1)
        inside = np.where(edge, line >= 0.0, True).all(axis=1)
        # a hull of zero area (all active points collinear or coincident) contains no interior point
        # (in a hull with interior no edge has every point on its line; in a degenerate one every edge does)
        on_line = ((np.abs(cross) <= eps * np.maximum(elen, eps)[..., None]) | ~A[:, None, :]).all(axis=2)
        degenerate = (edge & on_line).any(axis=1)
        inside &= ~degenerate
        m = np.where(inside, seg_min, -seg_min)
        # a single active point: the distance to it
        if single.any():
            k = np.argmax(A, axis=1)
            dpt = np.hypot(*(X - P[np.arange(len(P)), k]).T)
            m = np.where(single, -dpt, m)
        m = np.where(A.any(axis=1), m, -np.inf)
        out[s:s + chunk] = m
    return out


# ------------------------------------------------------------------------------------------------
# Eq. 23: centre of mass
# ------------------------------------------------------------------------------------------------
def link_coms_world(robot: SnakeRobot, frames: np.ndarray) -> np.ndarray:
    """World centres of mass of every frame of ``link_names``: frames (T, L, 4, 4) -> (T, L, 3)."""
    return frames[..., :3, 3] + np.einsum("tlij,lj->tli", frames[..., :3, :3], robot.coms)


def center_of_mass(robot: SnakeRobot, q, base: BasePlacement | None = None) -> np.ndarray:
    """Centre of mass of the whole robot in the world frame (m), Eq. 23: c = sum m_i P_i / sum m_i.

    q: (16,) -> (3,), or a trajectory (T, 16) -> (T, 3).
    """
    robot = _check_robot(robot)
    base = _check_base(base)
    qs, single = _joint_matrix(robot, q)
    frames = robot.frames_many(qs, base)
    c = np.einsum("l,tli->ti", robot.masses, link_coms_world(robot, frames)) / robot.total_mass
    return c[0] if single else c


# ------------------------------------------------------------------------------------------------
# Eq. 24: support polygon
# ------------------------------------------------------------------------------------------------
def _hull_ccw(pts: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull vertices of 2-D points; a 2-point segment or 1 point when degenerate."""
    uniq = np.unique(pts, axis=0)
    if len(uniq) == 1:
        return uniq
    centred = uniq - uniq.mean(axis=0)
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    if sv[-1] <= 1e-12 * max(1.0, sv[0]):  # collinear: the polygon degenerates to a segment
        s = centred @ vt[0]
        return uniq[[int(np.argmin(s)), int(np.argmax(s))]]
    try:
        hull = ConvexHull(uniq)
    except QhullError as exc:  # pragma: no cover - guarded by the rank test above
        raise ValueError(f"cannot build the support polygon: {exc}") from None
    v = uniq[hull.vertices]  # scipy orders 2-D hull vertices counter-clockwise
    # drop vertices lying on the line of their neighbours (collinear contact points along a straight edge)
    prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
    a, b = v - prev, nxt - v
    turn = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    return v[turn > 1e-9]


def support_polygon(robot: SnakeRobot, q, base: BasePlacement | None = None, *,
                    contact: str = "endpoints", tolerance: float = CONTACT_TOLERANCE) -> np.ndarray:
    """Support polygon of the base part on the ground, Eq. 24: (k, 2) world (x, y) vertices, counter-clockwise.

    ``contact`` selects the contact points p_i of Eq. 24:

    * ``"endpoints"`` (default, the paper): both endpoints of every base link (link_0 .. link_7 on the default
      robot: the origins of link_0 .. link_7 and of the ``base_end`` marker), projected on the ground.
      This is conservative: the true footprint of the 0.043 m wide modules is larger.
    * ``"footprint"``: the four bottom corners of every base link's collision box -- the physical contact
      footprint of the modules; use it for an (almost) straight base, whose endpoints are collinear.

    Only base links lying on the ground count (the lowest corner of their box below ``tolerance`` m); the
    neck and head never support the body in the paper's model, even when they touch the ground.
    If the contact points are collinear the "polygon" is the segment between the extreme points (2, 2): it
    has no interior, so :func:`static_margin` is <= 0 for it.
    """
    robot = _check_robot(robot)
    base = _check_base(base)
    q = joint_vector(q, robot.n_joints)
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    frames = robot.frames_many(q[None, :], base)
    pts, active = _contact_points_many(robot, frames, contact, tolerance)
    pts = pts[0][active[0]]
    if len(pts) == 0:
        raise ValueError("no base link touches the ground: there is no support polygon")
    return _hull_ccw(pts)


def static_margin(robot: SnakeRobot, q, base: BasePlacement | None = None, *,
                  contact: str = "endpoints", tolerance: float = CONTACT_TOLERANCE) -> float:
    """Signed distance (m) from the CoM's ground projection to the support polygon's edge; > 0 inside.

    Static stability (Section 3.1): the robot is statically stable if c is in C (Eq. 23, 24).
    Outside the polygon the value is minus the distance to the polygon.
    """
    robot = _check_robot(robot)
    base = _check_base(base)
    q = joint_vector(q, robot.n_joints)
    poly = support_polygon(robot, q, base, contact=contact, tolerance=tolerance)
    c = center_of_mass(robot, q, base)
    return float(polygon_margin_many(poly[None], np.ones((1, len(poly)), bool), c[None, :2])[0])


def is_statically_stable(robot: SnakeRobot, q, base: BasePlacement | None = None, *,
                         contact: str = "endpoints", tolerance: float = CONTACT_TOLERANCE,
                         margin: float = 0.0) -> bool:
    """True when the CoM's ground projection lies inside the support polygon by more than ``margin`` m."""
    return static_margin(robot, q, base, contact=contact, tolerance=tolerance) > float(margin)
