"""A robot's geometry: the collision shapes of its links, built from the description's ``<collision>`` elements, and
what the planner reads from them (the capsules inside them, their hull points, their lowest points, the pairs that
self-collision checks, the height of the body's axis when the base lies on the ground).

Free functions of a :class:`~snakehead.model.robot.SnakeRobot`; the robot's properties and methods of the same names
call them and keep what they build.
"""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from .._errors import InputError
from ..geometry.meshes import convex_hull_vertices
from ..geometry.shapes import Shape, ShapeSet, shape_points
from .body_frame import STRAIGHT_TOLERANCE
from .chain import Chain
from .description import MeshResolver
from .robot_parts import joints_before

if TYPE_CHECKING:  # robot.py delegates to this module
    from .robot import SnakeRobot

__all__ = ["collision_shapes", "shaped_base_links", "body_axis_height", "half_section", "link_points",
           "distal_points", "link_capsules", "self_collision_pairs", "lowest_z", "lowest_points", "hull_points",
           "link_centres", "lowest_point_per_link"]


def collision_shapes(body: Chain, meshes: MeshResolver) -> ShapeSet:
    """The collision shapes of the body's links (every URDF <collision> element: boxes, cylinders, spheres, meshes
    as their convex hulls, found through ``meshes``), on the frames of ``body.link_names``."""
    shapes = []
    for k, elements in enumerate(body.model.link_collisions):
        for kind, origin, size, filename in elements:
            where = f"link {body.link_names[k]!r} <collision>"
            if kind == "mesh":
                path = meshes.resolve(filename, where)
                shapes.append(Shape("convex", k, origin, size, convex_hull_vertices(path, size, where),
                                    source=os.fspath(path)))
            else:
                shapes.append(Shape(kind, k, origin, size))
    return ShapeSet(tuple(shapes), len(body.link_names))


def shaped_base_links(robot: SnakeRobot) -> np.ndarray:
    """Indices (link_names) of the base part's links that have collision shapes, ascending."""
    links = np.asarray(robot.base_links, int)
    return links[np.isin(links, robot.shaped_links)]


def body_axis_height(robot: SnakeRobot) -> float:
    """Height (m) of the body axis above the ground when the base lies on it: the base links' collision shapes
    rest on the ground (their lowest points at z = 0) with every joint at zero."""
    return float(-robot.geometry.lowest_z(robot.straight_frames[None], robot.base_links)[0].min())


def half_section(robot: SnakeRobot) -> float:
    """The base's narrowest half-width across the body (m): the thinnest module's radius."""
    radii = robot.link_capsules[1][robot.shaped_base_links]
    return float(radii.min()) if len(radii) else 0.0


def link_points(robot: SnakeRobot) -> tuple[np.ndarray, np.ndarray]:
    """The shaped links (k,) and points (k, M, 3, read-only) in each link's frame whose convex hull is the link's
    shapes (cylinders and spheres as polygons of 16 sides; padded by repetition)."""
    links = robot.shaped_links
    pts = [np.concatenate([shape_points(s) for s in robot.geometry.shapes if s.frame == k]) for k in links]
    width = max(len(p) for p in pts)
    out = np.array([np.concatenate([p, np.repeat(p[:1], width - len(p), axis=0)]) for p in pts])
    out.setflags(write=False)
    return links, out


def distal_points(robot: SnakeRobot) -> tuple[np.ndarray, np.ndarray]:
    """The shaped links (k,) and, in each link's frame, the points (k, M, 3, read-only) of its shapes farthest
    along the body at q = 0 (a box's distal face, a cylinder's distal rim; padded by repetition): where a link pitched
    up about its proximal joint leaves the ground last."""
    links, local = robot.link_points
    F = robot.straight_frames
    chosen = []
    for k, pts in zip(links, local):
        axial = pts @ (F[k, :3, :3].T @ np.array([1.0, 0.0, 0.0]))
        chosen.append(np.unique(pts[axial >= axial.max() - STRAIGHT_TOLERANCE], axis=0))
    width = max(len(c) for c in chosen)
    out = np.array([c[np.arange(width) % len(c)] for c in chosen])
    out.setflags(write=False)
    return links, out


def link_capsules(robot: SnakeRobot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame of ``link_names``, a capsule inside its collision shapes along the body's direction at q = 0: end
    points (n_links, 2, 3) in the link frame, radius (n_links,) m (the shapes' smallest half-width across the body,
    so that the capsule stays inside a box) and excess (n_links,) m (how far the shapes stick out of the capsule: a
    box's corners). Zeros for frames without shapes. The whole-body solve's smooth collision terms use them; a box's
    capsule is its x-axis segment shortened by the radius at both ends."""
    n = len(robot.link_names)
    ends, radii, excess = np.zeros((n, 2, 3)), np.zeros(n), np.zeros(n)
    links, local = robot.link_points
    F = robot.straight_frames
    across = np.array([[0.0, np.cos(a), np.sin(a)] for a in np.linspace(0, np.pi, 16, endpoint=False)])
    for k, pts in zip(links, local):
        R = F[k, :3, :3]
        axis = R.T @ np.array([1.0, 0.0, 0.0])  # the body's direction in the link frame
        centre = 0.5 * (pts.max(axis=0) + pts.min(axis=0))
        t = (pts - centre) @ axis
        radial = (pts - centre) - np.outer(t, axis)
        support = np.abs(radial @ (R.T @ across.T)).max(axis=0)  # half-widths across the body
        r_in = float(support.min())
        half = max(0.5 * (t.max() - t.min()) - r_in, 0.0)
        mid = centre + 0.5 * (t.max() + t.min()) * axis
        ends[k] = [mid - half * axis, mid + half * axis]
        radii[k] = r_in
        excess[k] = float(np.linalg.norm(radial, axis=1).max()) - r_in
    return ends, radii, excess


def self_collision_pairs(robot: SnakeRobot) -> np.ndarray:
    """(P, 2, read-only) the pairs of shapes (indices into ``geometry.shapes``) that self-collision checks: on links
    two or more joints apart (links one joint apart touch at it; links of one rigid module never move apart)."""
    segment = np.array([joints_before(robot.body, int(f)) for f in robot.geometry.shape_frames], dtype=np.int64)
    i, j = np.triu_indices(len(segment), k=1)
    keep = np.abs(segment[i] - segment[j]) >= 2
    pairs = np.stack([i[keep], j[keep]], axis=1).astype(np.int64)
    pairs.setflags(write=False)
    return pairs


def lowest_z(robot: SnakeRobot, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
    """Lowest world z (m) of the collision shapes of ``links`` (default every shaped link): (T, k), from frames
    (T, n_links, 4, 4)."""
    links = robot.shaped_links if links is None else np.asarray(links)
    frames = np.asarray(frames, float)
    if frames.ndim != 4 or frames.shape[1:] != (len(robot.link_names), 4, 4):
        raise InputError(f"frames has shape {frames.shape}; expected (T, {len(robot.link_names)}, 4, 4)")
    return robot.geometry.lowest_z(frames, links)


def lowest_points(robot: SnakeRobot, frames: np.ndarray, links: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The lowest candidate ground-contact points of the shapes of ``links`` (default every shaped link): world
    points (T, N, 3) and the link (N,) of each (:meth:`ShapeSet.lowest_points`)."""
    links = robot.shaped_links if links is None else np.asarray(links)
    return robot.geometry.lowest_points(np.asarray(frames, float), links)


def hull_points(robot: SnakeRobot, frames: np.ndarray) -> np.ndarray:
    """World points (T, k, M, 3) of :func:`link_points` for frames (T, n_links, 4, 4)."""
    links, local = robot.link_points
    F = np.asarray(frames)[:, links]
    return np.einsum("tkij,kmj->tkmi", F[..., :3, :3], local) + F[:, :, None, :3, 3]


def link_centres(robot: SnakeRobot, frames: np.ndarray) -> np.ndarray:
    """World centres (T, k, 3) of the shaped links' capsules (their shapes' middle along the body)."""
    links = robot.shaped_links
    ends = robot.link_capsules[0][links]
    mid = 0.5 * (ends[:, 0] + ends[:, 1])
    F = np.asarray(frames)[:, links]
    return np.einsum("tkij,kj->tki", F[..., :3, :3], mid) + F[..., :3, 3]


def lowest_point_per_link(robot: SnakeRobot, frames: np.ndarray, links: np.ndarray) -> np.ndarray:
    """The lowest world point (k, 3) of each link's shapes, from the frames (n_links, 4, 4) of one configuration
    (box corner, cylinder rim point, sphere bottom, hull vertex)."""
    links = np.asarray(links, dtype=np.int64)
    pts, owner = robot.geometry.lowest_points(np.asarray(frames)[None], links, per_shape=1)  # each shape's lowest
    pts = pts[0]
    if np.array_equal(owner, links):  # one shape per link (the common case)
        return pts
    out = np.empty((len(links), 3))
    for c, k in enumerate(links):
        mine = pts[owner == k]
        out[c] = mine[np.argmin(mine[:, 2])]
    return out
