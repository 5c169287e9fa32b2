"""Brute-force references for the support polygon's margins (tests of dynamics.stability and solve.whole_body):
SciPy's Qhull for the hull, each edge's distance in plain numpy, the centre of mass summed link by link."""
from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError


def hull_vertices(points: np.ndarray) -> np.ndarray | None:
    """The counter-clockwise hull vertices (k, 2) of 2-D points by Qhull; None when they are collinear (or fewer
    than three distinct)."""
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError):
        return None
    return points[hull.vertices]


def margin_to_hull(points: np.ndarray, xy: np.ndarray) -> float:
    """Signed distance of xy to the convex hull of points (N, 2), positive inside: inside, the distance to the
    nearest edge line; outside, minus the distance to the polygon (its edge segments). Collinear points: minus the
    distance to the segment between the extremes. No point: -inf."""
    if len(points) == 0:
        return -np.inf
    v = hull_vertices(points)
    if v is None:  # a segment (or a point): its extremes along the points' main direction
        d = points - points.mean(axis=0)
        axis = np.linalg.svd(d)[2][0] if np.abs(d).max() > 0 else np.array([1.0, 0.0])
        s = d @ axis
        v = points[[int(np.argmin(s)), int(np.argmax(s))]]
    e = np.roll(v, -1, axis=0) - v
    w = xy - v
    length = np.linalg.norm(e, axis=1)
    u = np.clip((w * e).sum(1) / np.maximum((e * e).sum(1), 1e-300), 0, 1)
    seg = float(np.linalg.norm(w - u[:, None] * e, axis=1).min())
    if len(v) < 3:
        return -seg
    line = (e[:, 0] * w[:, 1] - e[:, 1] * w[:, 0]) / length
    return float(line.min()) if line.min() >= 0 else -seg


def com_reference(robot, frames: np.ndarray) -> np.ndarray:
    """Eq. 23 summed link by link from one configuration's world frames (n_links, 4, 4): (3,)."""
    total, weighted = 0.0, np.zeros(3)
    for F, m, c in zip(frames, robot.masses, robot.coms):
        weighted += m * (F[:3, :3] @ c + F[:3, 3])
        total += m
    return weighted / total
