"""The separating-axis box test in numpy: the independent reference the C++ core (``snakehead._core.box_pair_gaps``,
behind :func:`snakehead.geometry.collision.box_box_sat` and ``self_clearance``) is tested against, and that
bench/collision.py times it against. This was the package's implementation before the test moved to C++.

Gottschalk's OBB test in B's frame with C = Rb^T Ra: 15 candidate axes (3 + 3 face normals, 9 edge cross products),
each edge-edge gap divided by its axis' length so that all are in metres; parallel edges (axis shorter than 1e-9)
give no axis. > 0: apart (a lower bound of the distance); <= 0: overlap (minus the penetration along the best axis).
"""
from __future__ import annotations

import numpy as np


def box_box_sat(ca, Ra, ha, cb, Rb, hb):
    """Gap (m) of boxes A (centres (..., 3), rotations (..., 3, 3), half extents (..., 3)) and B, broadcast."""
    ca, Ra, ha, cb, Rb, hb = (np.asarray(v, float) for v in (ca, Ra, ha, cb, Rb, hb))
    RbT = np.swapaxes(Rb, -1, -2)
    C = RbT @ Ra  # column i: A's axis i in B's frame
    t = (RbT @ (ca - cb)[..., None])[..., 0]  # A's centre in B's frame
    absC = np.abs(C)
    gaps = []
    for j in range(3):  # B's face normals
        gaps.append(np.abs(t[..., j]) - hb[..., j] - (absC[..., j, :] * ha).sum(-1))
    for i in range(3):  # A's face normals
        gaps.append(np.abs((C[..., :, i] * t).sum(-1)) - ha[..., i] - (absC[..., :, i] * hb).sum(-1))
    for i in range(3):  # A's edge i x B's edge j
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            length = np.hypot(C[..., j1, i], C[..., j2, i])  # |b_j x a_i|, consistent with proj and rb
            proj = np.abs(t[..., j2] * C[..., j1, i] - t[..., j1] * C[..., j2, i])
            ra = ha[..., i1] * absC[..., j, i2] + ha[..., i2] * absC[..., j, i1]
            rb = hb[..., j1] * absC[..., j2, i] + hb[..., j2] * absC[..., j1, i]
            ok = length > 1e-9  # parallel edges give no axis
            gaps.append(np.where(ok, (proj - ra - rb) / np.where(ok, length, 1.0), -np.inf))
    return np.max(np.stack(gaps, axis=-1), axis=-1)


def self_clearance(robot, qs, base=None):
    """(T,) the smallest gap between the boxes of links two or more apart in the chain, from the robot's own
    link frames and boxes (not the package's collision module)."""
    qs = np.atleast_2d(np.asarray(qs, float))
    links = robot.boxed_links
    B = robot.frames_many(qs, base)[:, links] @ robot.box_origins[links]
    c, R, h = B[..., :3, 3], B[..., :3, :3], 0.5 * robot.box_sizes[links]
    i, j = np.triu_indices(len(links), k=2)
    return box_box_sat(c[:, i], R[:, i], h[i], c[:, j], R[:, j], h[j]).min(axis=1)


def box_corners(c, R, h):
    """The 8 corners (8, 3) of one box."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    return c + (signs * h) @ R.T


def box_box_sat_by_projection(ca, Ra, ha, cb, Rb, hb):
    """The same 15-axis test for one pair of boxes computed the plain way: project both boxes' corners on each
    unit axis (np.cross for the edge pairs, skipped when shorter than 1e-9) and take the largest gap."""
    axes = [Ra[:, i] for i in range(3)] + [Rb[:, j] for j in range(3)]
    axes += [np.cross(Ra[:, i], Rb[:, j]) for i in range(3) for j in range(3)]
    va, vb = box_corners(ca, Ra, ha), box_corners(cb, Rb, hb)
    gaps = []
    for axis in axes:
        length = np.linalg.norm(axis)
        if length < 1e-9:
            continue
        pa, pb = va @ (axis / length), vb @ (axis / length)
        gaps.append(max(pb.min() - pa.max(), pa.min() - pb.max()))
    return max(gaps)
