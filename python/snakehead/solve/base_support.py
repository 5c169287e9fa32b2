"""The base's own support (Eqs. 23-24 over the links that lie on the ground whatever the pose): which links they
are, the points of their shapes that touch the ground, and the static margin of the body's centre of mass in their
support polygon, for many configurations at once.

A pose that stands only because a lifted link rests on the ground cannot be reached from the air (the body tips
just before the link touches down): the whole-body solve's checks take the smaller of this margin and the one over
every contact (:func:`~.solution_checks.check_solutions`).
"""
from __future__ import annotations

import numpy as np

from .. import _core
from ..ground_contact import GROUND_TOLERANCE
from ..model.robot import BasePlacement, SnakeRobot

__all__ = ["contact_points", "first_lifted_link", "ground_links", "link_coms", "static_margins"]



def first_lifted_link(robot: SnakeRobot) -> int:
    """Index (``link_names``) of the first link the lifted joints move; past every link when no joint lifts."""
    child = np.asarray(robot.body.model.joint_child_links)
    start = robot.lift_joints.start
    return int(child[start]) if start < robot.n_joints else len(child) + 10**6


def ground_links(robot: SnakeRobot) -> np.ndarray:
    """The links with shapes before the first lifted one (ascending indices into ``link_names``): they lie on the
    ground whatever the pose."""
    shaped = robot.shaped_links
    return shaped[shaped < first_lifted_link(robot)]


def contact_points(robot: SnakeRobot, F: np.ndarray, links: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World (P, 3) bottom points of the shapes of ``links`` (within GROUND_TOLERANCE of each link's lowest: a box's
    bottom corners, a cylinder's bottom line) and their links (P,), from the frames (n_links, 4, 4)."""
    pts, owner = robot.lowest_points(F[None], links)
    pts = pts[0]
    lowest = np.full(len(robot.link_names), np.inf)
    np.minimum.at(lowest, owner, pts[:, 2])
    keep = pts[:, 2] <= lowest[owner] + GROUND_TOLERANCE
    return pts[keep], owner[keep]


def link_coms(robot: SnakeRobot, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The links that have a mass (k,) and their centres of mass (..., k, 3), world, from frames
    (..., n_links, 4, 4)."""
    heavy = np.flatnonzero(robot.masses > 0)
    G = F[..., heavy, :, :]
    return heavy, G[..., :3, 3] + np.einsum("...lij,lj->...li", G[..., :3, :3], robot.coms[heavy])


def static_margins(robot: SnakeRobot, frames: np.ndarray, links: np.ndarray, base: BasePlacement | None = None
                   ) -> np.ndarray:
    """Static margin (m, > 0 inside) of the body's centre of mass in the support polygon of ``links``, for many
    configurations from their world frames (K, n_links, 4, 4): (K,). The contacts of each
    (:func:`contact_points`) are masked, and every polygon's margin is taken in one call of the core's hull
    (``hull_margins``); a polygon of fewer than three vertices (collinear contacts) has no interior: -inf."""
    m = robot.masses
    pts, owner = robot.lowest_points(frames, links)  # (K, P, 3), (P,)
    z = pts[..., 2]
    lowest = np.empty_like(z)
    for link in np.unique(owner):
        mine = owner == link
        lowest[:, mine] = z[:, mine].min(axis=1, keepdims=True)
    keep = z <= lowest + GROUND_TOLERANCE
    heavy, c_i = link_coms(robot, frames)
    c = (m[heavy, None] * c_i).sum(-2) / m[heavy].sum()
    xy = np.ascontiguousarray(pts[..., :2])
    below = c[:, :2] if base is None else base.below_along_gravity(c)  # along gravity on a slope
    margins = _core.hull_margins(xy, np.ascontiguousarray(keep), np.ascontiguousarray(below))
    # a degenerate hull's margin (minus the distance to its segment) is <= 0: only those samples are looked at
    for k in np.flatnonzero(margins <= 0):
        if len(_core.convex_hull_2d(np.ascontiguousarray(xy[k, keep[k]]))) < 3:
            margins[k] = -np.inf
    return margins
