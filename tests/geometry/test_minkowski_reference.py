"""tests/minkowski_reference.py (the independent signed distance test_shape_set.py holds the kernel's penetration
depths to) against closed forms, apart and in penetration: two spheres, two boxes with parallel axes, a sphere
and a rotated box, a sphere and a rotated cylinder; and a box against the convex hull of its own corners."""
import numpy as np
import pytest
from minkowski_reference import Shape, signed_distance, support
from shape_reference import SIGNS
from test_shape_set import random_poses


def point_box(p, half):
    """Signed distance of point p to the box of these half extents about the origin."""
    q = np.abs(p) - half
    return np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0)


def translation(t):
    pose = np.eye(4)
    pose[:3, 3] = t
    return pose


def check(a, b, closed):
    """The computation's interval holds the closed form and is as narrow as asked."""
    found = signed_distance(a, b, tolerance=1e-7)
    assert found.lower - 1e-12 <= closed <= found.upper + 1e-12, (found, closed)
    assert found.upper - found.lower <= 1.001e-7
    # the direction it reports has the gap it reports
    gap = -(support(a, found.direction[None])[0] + support(b, -found.direction[None])[0])[0]
    assert gap == pytest.approx(found.lower, abs=1e-12)
    return closed


def test_two_spheres():
    rng = np.random.default_rng(0)
    depths = []
    for _ in range(20):
        ra, rb = rng.uniform(0.01, 0.05, 2)
        ca, cb = rng.uniform(-0.04, 0.04, (2, 3))
        closed = np.linalg.norm(ca - cb) - ra - rb
        depths.append(check(Shape("sphere", np.array([ra]), translation(ca)),
                            Shape("sphere", np.array([rb]), translation(cb)), closed))
    assert min(depths) < -0.01 and max(depths) > 0.01  # both regimes


def test_two_boxes_with_parallel_axes():
    """Their Minkowski difference is a box of the summed half extents about the centres' difference."""
    rng = np.random.default_rng(1)
    R = random_poses(rng, 1, 0.0)[0]  # the same rotation for both
    depths = []
    for _ in range(20):
        sa, sb = rng.uniform(0.01, 0.1, (2, 3))
        ta, tb = rng.uniform(-0.06, 0.06, (2, 3))
        pa, pb = R.copy(), R.copy()
        pa[:3, 3], pb[:3, 3] = ta, tb
        closed = point_box(R[:3, :3].T @ (tb - ta), (sa + sb) / 2)
        depths.append(check(Shape("box", sa, pa), Shape("box", sb, pb), closed))
    assert min(depths) < -0.01 and max(depths) > 0.01


def test_sphere_and_rotated_box():
    rng = np.random.default_rng(2)
    depths = []
    for pose in random_poses(rng, 20, 0.05):
        size, r, c = rng.uniform(0.01, 0.1, 3), rng.uniform(0.005, 0.04), rng.uniform(-0.05, 0.05, 3)
        closed = point_box(pose[:3, :3].T @ (c - pose[:3, 3]), size / 2) - r
        depths.append(check(Shape("box", size, pose), Shape("sphere", np.array([r]), translation(c)), closed))
    assert min(depths) < -0.01 and max(depths) > 0.01


def test_sphere_and_rotated_cylinder():
    """A point's signed distance to a cylinder: that to a rectangle (radius x half length) in the plane of the
    axis and the point."""
    rng = np.random.default_rng(3)
    depths = []
    for pose in random_poses(rng, 20, 0.05):
        size, r, c = rng.uniform(0.01, 0.1, 2), rng.uniform(0.005, 0.04), rng.uniform(-0.05, 0.05, 3)
        local = pose[:3, :3].T @ (c - pose[:3, 3])
        closed = point_box(np.array([np.hypot(local[0], local[1]), local[2]]), np.array([size[0], size[1] / 2])) - r
        depths.append(check(Shape("cylinder", size, pose), Shape("sphere", np.array([r]), translation(c)), closed))
    assert min(depths) < -0.01 and max(depths) > 0.01


def test_a_box_is_the_hull_of_its_corners():
    rng = np.random.default_rng(4)
    poses = random_poses(rng, 40, 0.05)
    for pa, pb in zip(poses[:20], poses[20:]):
        sa, sb = rng.uniform(0.01, 0.1, (2, 3))
        as_box = signed_distance(Shape("box", sa, pa), Shape("box", sb, pb))
        as_hull = signed_distance(Shape("box", sa, pa), Shape("convex", np.zeros(3), pb, SIGNS * sb / 2))
        assert as_hull.lower == pytest.approx(as_box.lower, abs=1e-7)
