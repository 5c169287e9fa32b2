"""Stability (Eqs. 23-40): CoM and momenta against pinocchio, support polygon and margins against closed
forms, ZMP at rest and against an independent finite-difference computation; bad input."""
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial import ConvexHull

import snakehead
from snakehead import BasePlacement, SnakeRobot
from snakehead import stability as st

SNAKE = str(snakehead.default_urdf_path())


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def pin_model():
    model = pin.buildModelFromUrdf(SNAKE)  # fixed root: pinocchio's world is link_0's frame
    return model, model.createData()


def to_world(base: BasePlacement) -> pin.SE3:
    M = base.matrix()
    return pin.SE3(M[:3, :3], M[:3, 3])


def arc_base(robot, angle=0.35):
    """A configuration whose base bends in a plane arc (yaw joints), neck and head flat."""
    q = np.zeros(robot.n_joints)
    q[0:7:2] = angle  # joints 1, 3, 5, 7: yaw
    return q


# ---------------------------------------------------------------- Eq. 23
def test_center_of_mass_matches_pinocchio(robot, pin_model):
    model, data = pin_model
    rng = np.random.default_rng(1)
    base = BasePlacement(0.3, -0.2, 0.7)
    qs = rng.uniform(robot.lower, robot.upper, (20, robot.n_joints))
    ours = st.center_of_mass(robot, qs, base)
    assert ours.shape == (20, 3)
    W = to_world(base)
    root = model.inertias[0]  # pinocchio leaves the fixed root link (link_0, on the universe) out of its CoM
    for q, c in zip(qs, ours):
        moving = pin.centerOfMass(model, data, q)
        whole = (data.mass[0] * moving + root.mass * root.lever) / (data.mass[0] + root.mass)
        ref = W.act(whole)
        np.testing.assert_allclose(c, ref, atol=1e-12)
    np.testing.assert_allclose(st.center_of_mass(robot, qs[3], base), ours[3], atol=1e-15)


def test_center_of_mass_straight_closed_form(robot):
    # straight robot: CoM on the axis at the length-weighted middle; default base puts the tail at x = 0
    c = st.center_of_mass(robot, np.zeros(16))
    lengths = np.r_[0.0405, np.full(15, 0.0865), 0.046]
    mids = np.cumsum(lengths) - lengths / 2
    np.testing.assert_allclose(c, [np.sum(lengths * mids) / lengths.sum(), 0.0, 0.0215], atol=1e-12)


# ---------------------------------------------------------------- Eq. 24 and the static margin
def test_support_polygon_is_ccw_hull_of_base_endpoints(robot):
    base = BasePlacement(0.1, 0.2, -0.4)
    q = arc_base(robot)
    poly = st.support_polygon(robot, q, base)
    F = robot.frames(q, base)
    names = robot.link_names
    ends = np.array([F[names.index(n), :2, 3] for n in [f"link_{i}" for i in range(8)] + ["base_end"]])
    hull = ConvexHull(ends)
    # same vertex set as an independent hull, counter-clockwise (positive shoelace area)
    assert {tuple(np.round(p, 9)) for p in poly} == {tuple(np.round(p, 9)) for p in ends[hull.vertices]}
    x, y = poly[:, 0], poly[:, 1]
    area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    assert area == pytest.approx(hull.volume, rel=1e-12) and area > 0


def test_footprint_polygon_of_straight_base_is_rectangle(robot):
    poly = st.support_polygon(robot, np.zeros(16), contact="footprint")
    np.testing.assert_allclose(np.sort(poly[:, 0]), [0, 0, 0.646, 0.646], atol=1e-12)
    np.testing.assert_allclose(np.sort(poly[:, 1]), [-0.0215, -0.0215, 0.0215, 0.0215], atol=1e-12)
    # endpoints of a straight base are collinear: a segment with no interior
    seg = st.support_polygon(robot, np.zeros(16))
    np.testing.assert_allclose(seg, [[0, 0], [0.646, 0]], atol=1e-12)


def test_static_margin_closed_form(robot):
    # straight robot: CoM at x = 0.692 > 0.646 (end of the base): outside by 0.046 m
    assert st.static_margin(robot, np.zeros(16)) == pytest.approx(-(0.692 - 0.646), abs=1e-12)
    assert not st.is_statically_stable(robot, np.zeros(16))
    # fold the neck back over the base (joint_9 yaw +90 deg, joint_11 yaw +90 deg) -> compare with a
    # direct point-in-polygon distance computed from the polygon's edges
    q = arc_base(robot, 0.5)
    q[8] = q[10] = np.pi / 2
    poly = st.support_polygon(robot, q)
    c = st.center_of_mass(robot, q)[:2]
    d = []
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        e = b - a
        d.append((e[0] * (c[1] - a[1]) - e[1] * (c[0] - a[0])) / np.linalg.norm(e))
    assert min(d) > 0  # inside: the inside margin is the nearest edge line's distance
    assert st.static_margin(robot, q) == pytest.approx(min(d), abs=1e-12)
    assert st.is_statically_stable(robot, q)


def test_com_outside_polygon_is_unstable(robot):
    q = arc_base(robot, 0.4)
    q[7] = -np.pi / 2  # joint_8 (pitch): raise the whole neck and head straight up
    q[8] = -np.pi / 2  # joint_9 (yaw) swings the head out sideways -> CoM outside
    assert st.static_margin(robot, q) < 0
    assert not st.is_statically_stable(robot, q)


def test_polygon_margin_against_brute_force():
    rng = np.random.default_rng(7)
    T, N = 300, 9
    pts = rng.normal(size=(T, N, 2))
    active = rng.random((T, N)) < 0.85
    active[:, :3] = True
    xy = rng.normal(scale=1.2, size=(T, 2))
    m = st.polygon_margin_many(pts, active, xy, chunk=64)
    for t in range(T):
        p = pts[t][active[t]]
        hull = ConvexHull(p)
        v = p[hull.vertices]
        e = np.roll(v, -1, axis=0) - v
        w = xy[t] - v
        line = (e[:, 0] * w[:, 1] - e[:, 1] * w[:, 0]) / np.linalg.norm(e, axis=1)
        u = np.clip((w * e).sum(1) / (e * e).sum(1), 0, 1)
        seg = np.linalg.norm(w - u[:, None] * e, axis=1).min()
        ref = seg if line.min() >= 0 else -seg
        assert m[t] == pytest.approx(ref, abs=1e-12)


def test_support_polygon_only_counts_base_links_on_the_ground(robot):
    q = arc_base(robot, 0.3)
    q[5] = -0.5  # joint_6 pitches link_6, link_7 (and everything after) up off the ground
    poly = st.support_polygon(robot, q)
    F = robot.frames(q)
    lifted = F[robot.link_names.index("base_end"), :2, 3]
    assert not np.any(np.all(np.isclose(poly, lifted, atol=1e-9), axis=1))


def test_stability_bad_input(robot):
    with pytest.raises(ValueError, match="shape"):
        st.center_of_mass(robot, np.zeros(15))
    with pytest.raises(ValueError, match="shape"):
        st.center_of_mass(robot, np.zeros((4, 3)))
    with pytest.raises(ValueError, match="NaN"):
        st.static_margin(robot, np.full(16, np.nan))
    with pytest.raises(ValueError, match="contact"):
        st.support_polygon(robot, np.zeros(16), contact="feet")
    with pytest.raises(TypeError):
        st.center_of_mass(robot, np.zeros(16), base=(0, 0, 0))
    q = np.zeros(16)
    q[0] = np.nan
    with pytest.raises(ValueError):
        st.support_polygon(robot, q)
