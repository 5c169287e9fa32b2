"""Stability (Eqs. 23-40): CoM and momenta against pinocchio, support polygon and margins against closed
forms, ZMP at rest and against an independent finite-difference computation; bad input."""
import numpy as np
import pytest
from scipy.spatial import ConvexHull
from shape_reference import box_corners, lowest_z_by_sampling

import snakehead
from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import InputError, InputTypeError
from snakehead.dynamics import stability as st
from snakehead.ground_contact import GROUND_TOLERANCE


def _pin():
    """pinocchio, the reference of the CoM and momenta tests (skipped without it, a failure in CI)."""
    return pytest.importorskip("pinocchio")

#: The default robot's body axis lies half its 0.043 m section above the ground.
AXIS_HEIGHT = 0.0215

SNAKE = str(snakehead.default_urdf_path())


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def pin_model():
    model = _pin().buildModelFromUrdf(SNAKE)  # fixed root: pinocchio's world is link_0's frame
    return model, model.createData()


def test_body_axis_height_from_the_boxes(robot):
    assert robot.body_axis_height == pytest.approx(AXIS_HEIGHT, abs=1e-15)
    np.testing.assert_allclose(robot.root_pose(BasePlacement(0.1, 0.2, 0.3)), BasePlacement(0.1, 0.2, 0.3).matrix(AXIS_HEIGHT))


def to_world(base: BasePlacement):  # -> pinocchio.SE3
    M = base.matrix(AXIS_HEIGHT)
    return _pin().SE3(M[:3, :3], M[:3, 3])


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
        moving = _pin().centerOfMass(model, data, q)
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


def test_ground_contact_model_counts_every_link_lying_down(robot):
    # the straight robot lying flat: the whole body's footprint, 1.384 m x 0.043 m; CoM in the middle
    poly = st.support_polygon(robot, np.zeros(16), contact="ground")
    np.testing.assert_allclose(np.sort(poly[:, 0]), [0, 0, 1.384, 1.384], atol=1e-12)
    np.testing.assert_allclose(np.sort(poly[:, 1]), [-0.0215, -0.0215, 0.0215, 0.0215], atol=1e-12)
    assert st.static_margin(robot, np.zeros(16), contact="ground") == pytest.approx(0.0215, abs=1e-12)
    # raising the neck lifts the neck and head off the ground: back to the base's footprint
    q = np.zeros(16)
    q[7] = -0.5
    np.testing.assert_allclose(st.support_polygon(robot, q, contact="ground"),
                               st.support_polygon(robot, q, contact="footprint"), atol=1e-12)


@pytest.mark.parametrize("pitch", [-0.005, -0.01, -0.02, -0.05])
def test_ground_contact_counts_only_the_corners_that_touch(robot, pitch):
    """A link tilted up off the ground rests on its lowest edge: the corners it holds in the air do not support the
    body (counting them moved the polygon's edge out by a link's length and made it jump as the link lifted).
    Independent: scipy's convex hull of every box corner within the contact tolerance of the ground."""
    from scipy.spatial import ConvexHull

    q = np.zeros(16)
    q[7] = pitch  # the neck's first pitch joint lifts the neck and head a little
    corners = box_corners(robot, robot.frames(q)[None], robot.shaped_links)[0]
    touching = corners[corners[:, 2] <= GROUND_TOLERANCE, :2]
    hull = touching[ConvexHull(touching).vertices]
    poly = st.support_polygon(robot, q, contact="ground")
    assert len(poly) == len(hull)
    for v in hull:
        assert np.min(np.linalg.norm(poly - v, axis=1)) < 1e-9
    # a tilted link's far corners are in the air: the polygon ends before the lifted link's far end
    far_end = robot.frames(q)[-1, 0, 3]
    assert poly[:, 0].max() < far_end - 0.1


@pytest.mark.parametrize("which", ["default", "generated", "sea", "head6", "mesh", "rsnake"])
def test_lowest_points_against_sampled_surfaces(robot, which, tmp_path):
    """The core's lowest z and lowest candidate points (the ground contacts) of every shape kind against densely
    sampled surfaces in numpy, on random configurations at a random placement: boxes (the default robot, a generated
    snake), cylinders and a mesh tail (sea), spheres (head6), STL/OBJ hulls (mesh), offset cylinders (rsnake)."""
    from snakehead.model.generate import SnakeSpec, snake_urdf
    from snakehead.samples import published

    if which == "generated":
        spec = SnakeSpec(n_joints=11, module_length=0.09, section=0.06, first_axis="pitch", markers={"p0": 5, "b0": 7},
                         tip_name="tip", name="gen11")
        robot = snakehead.SnakeRobot.from_urdf(snake_urdf(spec), base_end="p0", neck_end="b0", head_tip="tip")
    elif which != "default":
        robot = snakehead.SnakeRobot.from_file(published.write_robot(which, tmp_path))
    rng = np.random.default_rng(5)
    qs = np.array([robot.random_configuration(rng) for _ in range(20)])
    frames = robot.frames_many(qs, snakehead.BasePlacement(0.3, -0.2, 1.1))
    links = robot.shaped_links
    low = robot.lowest_z(frames, links)
    cylinders = any(s.kind in ("cylinder", "sphere") for s in robot.geometry.shapes)
    for c, k in enumerate(links):
        sampled = lowest_z_by_sampling(robot, frames, k)
        assert np.all(low[:, c] <= sampled + 1e-12)  # never above a point of the surface
        np.testing.assert_allclose(low[:, c], sampled, atol=2e-3 if cylinders else 1e-12)
    pts, owner = robot.lowest_points(frames, links)
    for c, k in enumerate(links):  # each link's lowest candidate is its lowest point
        np.testing.assert_allclose(pts[:, owner == k, 2].min(axis=1), low[:, c], atol=1e-12)


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
    m = st.polygon_margin_many(pts, active, xy)
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
    with pytest.raises(InputTypeError, match="base must be a BasePlacement or None, got tuple"):
        st.center_of_mass(robot, np.zeros(16), base=(0, 0, 0))
    q = np.zeros(16)
    q[0] = np.nan
    with pytest.raises(InputError, match="q contains NaN or inf"):
        st.support_polygon(robot, q)


def test_polygon_margin_with_collinear_and_duplicate_points():
    # integer grid points: many collinear and repeated points, the worst case for a hull
    rng = np.random.default_rng(3)
    T, N = 200, 12
    pts = rng.integers(0, 4, size=(T, N, 2)).astype(float)
    active = np.ones((T, N), bool)
    xy = rng.uniform(-1, 4, size=(T, 2))
    m = st.polygon_margin_many(pts, active, xy)
    for t in range(T):
        p = np.unique(pts[t], axis=0)
        if np.linalg.matrix_rank(p - p[0]) < 2:
            continue
        v = p[ConvexHull(p).vertices]
        e = np.roll(v, -1, axis=0) - v
        w = xy[t] - v
        line = (e[:, 0] * w[:, 1] - e[:, 1] * w[:, 0]) / np.linalg.norm(e, axis=1)
        u = np.clip((w * e).sum(1) / (e * e).sum(1), 0, 1)
        seg = np.linalg.norm(w - u[:, None] * e, axis=1).min()
        assert m[t] == pytest.approx(seg if line.min() >= 0 else -seg, abs=1e-12)


# ---------------------------------------------------------------- Eqs. 25-31: momenta
def smooth_trajectory(robot, rng, T=400, dt=0.002):
    """q(t) = q0 + sum_k a_k sin(w_k t + phi_k) with its exact first and second derivatives."""
    t = np.arange(T) * dt
    n = robot.n_joints
    q0 = rng.uniform(-0.8, 0.8, n)
    a = rng.uniform(-0.4, 0.4, (3, n))
    w = rng.uniform(0.5, 4.0, (3, n))
    phi = rng.uniform(0, 2 * np.pi, (3, n))
    arg = w[None] * t[:, None, None] + phi[None]
    q = q0 + (a * np.sin(arg)).sum(1)
    qd = (a * w * np.cos(arg)).sum(1)
    qdd = (-a * w ** 2 * np.sin(arg)).sum(1)
    return t, q, qd, qdd


def pin_world_momenta(model, data, base, q, v):
    """pinocchio's centroidal momentum moved to our world origin: (P, L_O) with L_O = L_G + c x P."""
    h = _pin().computeCentroidalMomentum(model, data, q, v)  # about the moving bodies' CoM, root-frame axes
    c = data.com[0]
    P, L = h.linear, h.angular + np.cross(c, h.linear)
    M = base.matrix(AXIS_HEIGHT)
    Pw = M[:3, :3] @ P
    return Pw, M[:3, :3] @ L + np.cross(M[:3, 3], Pw)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_momenta_match_pinocchio_centroidal_momentum(robot, pin_model, seed):
    model, data = pin_model
    rng = np.random.default_rng(seed)
    base = BasePlacement(*rng.uniform(-1, 1, 2), rng.uniform(-np.pi, np.pi))
    t, q, qd, _ = smooth_trajectory(robot, rng, T=60)
    P, L = st.momenta_from_velocities(robot, q, qd, base)
    assert P.shape == L.shape == (60, 3)
    for k in range(len(t)):
        Pr, Lr = pin_world_momenta(model, data, base, q[k], qd[k])
        np.testing.assert_allclose(P[k], Pr, atol=1e-9, rtol=0)
        np.testing.assert_allclose(L[k], Lr, atol=1e-9, rtol=0)
    # the trajectory form with exact velocities is the same function
    P2, L2 = st.momenta(robot, t, q, base, qd=qd)
    np.testing.assert_array_equal(P2, P)
    np.testing.assert_array_equal(L2, L)
    # single sample form
    P1, L1 = st.momenta_from_velocities(robot, q[5], qd[5], base)
    np.testing.assert_allclose(P1, P[5], atol=1e-15)
    np.testing.assert_allclose(L1, L[5], atol=1e-15)


def test_linear_momentum_is_mass_times_com_velocity(robot):
    rng = np.random.default_rng(5)
    t, q, qd, _ = smooth_trajectory(robot, rng, T=200, dt=0.001)
    P, _ = st.momenta_from_velocities(robot, q, qd)
    c = st.center_of_mass(robot, q)
    cdot = np.gradient(c, t, axis=0, edge_order=2)
    np.testing.assert_allclose(P[2:-2], robot.total_mass * cdot[2:-2], atol=1e-5)


def test_momenta_from_samples_converge_to_exact(robot):
    rng = np.random.default_rng(6)
    t, q, qd, _ = smooth_trajectory(robot, rng, T=500, dt=0.002)
    P, L = st.momenta(robot, t, q)  # qd by np.gradient
    Pe, Le = st.momenta_from_velocities(robot, q, qd)
    assert np.abs(P - Pe).max() < 1e-4 and np.abs(L - Le).max() < 1e-4


# ---------------------------------------------------------------- Eqs. 36-40: ZMP
def test_zmp_at_rest_is_com_projection(robot):
    q = arc_base(robot, 0.4)
    q[7] = -0.8
    q[9] = 0.6
    t = np.arange(50) * 0.002
    qs = np.tile(q, (50, 1))
    base = BasePlacement(0.5, -0.3, 1.0)
    p = st.zmp(robot, t, qs, base)
    c = st.center_of_mass(robot, q, base)
    np.testing.assert_allclose(p, np.tile(c[:2], (50, 1)), atol=1e-12)


def test_zmp_matches_pinocchio_momentum_rate(robot, pin_model):
    """ZMP from numerical derivatives of our momenta vs Eqs. 39-40 fed with pinocchio's exact momentum rate."""
    model, data = pin_model
    rng = np.random.default_rng(11)
    base = BasePlacement(0.1, 0.4, 0.3)
    t, q, qd, qdd = smooth_trajectory(robot, rng, T=300, dt=0.002)
    ours = st.zmp(robot, t, q, base, qd=qd)
    M = robot.root_pose(base)
    R0, p0 = M[:3, :3], M[:3, 3]
    mass = robot.total_mass
    com = st.center_of_mass(robot, q, base)
    ref = np.empty((len(t), 2))
    for k in range(len(t)):
        dh = _pin().computeCentroidalMomentumTimeVariation(model, data, q[k], qd[k], qdd[k])
        c = data.com[0]
        Pdot = dh.linear
        Ldot = dh.angular + np.cross(c, Pdot)  # d/dt(c x P) = cdot x P + c x Pdot, and cdot x P = 0
        Pdot_w = R0 @ Pdot
        Ldot_w = R0 @ Ldot + np.cross(p0, Pdot_w)
        den = mass * st.GRAVITY + Pdot_w[2]
        ref[k] = [(mass * st.GRAVITY * com[k, 0] - Ldot_w[1]) / den, (mass * st.GRAVITY * com[k, 1] + Ldot_w[0]) / den]
    # central differences are O(dt^2) inside; one-sided second order at the ends
    np.testing.assert_allclose(ours[1:-1], ref[1:-1], atol=2e-5)
    np.testing.assert_allclose(ours, ref, atol=2e-4)


def test_dynamic_stability_verdict(robot):
    q0 = arc_base(robot, 0.5)
    q0[8] = q0[10] = np.pi / 2  # neck and head folded back over the base: stable
    q1 = arc_base(robot, 0.4)
    q1[7] = q1[8] = -np.pi / 2  # neck up, head swung out sideways: CoM outside
    t = np.linspace(0, 4, 2001)
    s = (t / 4) ** 3 * (10 - 15 * t / 4 + 6 * (t / 4) ** 2)
    qs = q0 + (q1 - q0) * s[:, None]
    res = st.dynamic_stability(robot, t, qs)
    assert res.inside[0] and not res.inside[-1] and not res.stable
    assert res.min_margin == pytest.approx(res.margin.min()) and res.margin[res.argmin] == res.min_margin
    # at the (resting) ends the margin equals the static margin, up to the one-sided difference's error
    assert res.margin[0] == pytest.approx(st.static_margin(robot, q0), abs=1e-4)
    assert res.margin[-1] == pytest.approx(st.static_margin(robot, q1), abs=1e-4)
    # a slow, stable motion is stable throughout
    res2 = st.dynamic_stability(robot, t, np.tile(q0, (len(t), 1)))
    assert res2.stable and res2.min_margin == pytest.approx(st.static_margin(robot, q0), abs=1e-12)


def test_dynamic_stability_with_moving_base_matches_per_sample_polygons(robot):
    rng = np.random.default_rng(2)
    T = 40
    t = np.arange(T) * 0.05
    qs = np.zeros((T, 16))
    qs[:, 0:7:2] = np.linspace(0.1, 0.6, T)[:, None]  # the base curls up along the way
    qs[:, 8] = qs[:, 10] = np.pi / 2
    qs[:, 7] = np.where(np.arange(T) < T // 2, 0.0, np.linspace(0.0, -0.6, T))  # the neck lifts off halfway
    qs[:, 8] = np.pi / 2 * (np.arange(T) < T // 2)
    for contact in ("endpoints", "footprint", "ground"):
        res = st.dynamic_stability(robot, t, qs, contact=contact)
        for k in np.r_[rng.choice(T, 8, replace=False), T // 2 - 1, T // 2]:
            poly = st.support_polygon(robot, qs[k], contact=contact)
            ref = st.polygon_margin_many(poly[None], np.ones((1, len(poly)), bool), res.zmp[k][None])[0]
            assert res.margin[k] == pytest.approx(ref, abs=1e-12)


def test_trajectory_bad_input(robot):
    t = np.arange(10) * 0.002
    q = np.zeros((10, 16))
    with pytest.raises(ValueError, match="increase"):
        st.zmp(robot, t[::-1], q)
    with pytest.raises(ValueError, match="samples"):
        st.momenta(robot, t[:9], q)
    with pytest.raises(ValueError, match="at least two"):
        st.momenta(robot, t[:1], q[:1])
    with pytest.raises(ValueError, match="shape"):
        st.momenta(robot, t, q[:, :15])
    bad = q.copy()
    bad[3, 4] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        st.dynamic_stability(robot, t, bad)
    with pytest.raises(ValueError, match="shape"):
        st.momenta_from_velocities(robot, q, q[:, :3])
    with pytest.raises(ValueError, match="NaN"):
        st.zmp(robot, t, q, qd=np.full((10, 16), np.inf))


def test_zmp_undefined_when_the_ground_would_pull(robot):
    """A violent flick of the raised neck: the CoM accelerates downwards faster than gravity at times, so
    M g + dP_z/dt < 0 there; those samples have no ZMP and the motion is not stable."""
    t = np.arange(500) * 0.002
    q = np.tile(arc_base(robot, 0.5), (500, 1))
    q[:, 7] = -0.8 + 0.6 * np.sin(2 * np.pi * 12 * t)  # joint 8, 12 Hz
    P, _ = st.momenta(robot, t, q)
    Pdot_z = np.gradient(P[:, 2], t, edge_order=2)
    pulls = robot.total_mass * st.GRAVITY + Pdot_z <= 0
    assert pulls.any() and not pulls.all()
    p = st.zmp(robot, t, q)
    assert np.array_equal(np.isnan(p).any(axis=1), pulls)
    res = st.dynamic_stability(robot, t, q)
    assert np.all(res.margin[pulls] == -np.inf) and not res.stable and res.min_margin == -np.inf


@pytest.mark.parametrize("contact", ["ground", "footprint"])
def test_static_margins_of_a_batch_match_qhull(robot, contact):
    """static_margins_of_frames (one call for a batch, the core's hull per sample) against Qhull's hull of each
    sample's box corners on the ground and the centre of mass summed link by link; static_margin (one
    configuration) gives the same. The batch mixes flat shapes and lifted poses whose neck or head touch the
    ground, so that the samples' contacts differ."""
    from hull_reference import com_reference, margin_to_hull
    from shape_reference import box_corners

    rng = np.random.default_rng(11)
    base = BasePlacement(0.3, -0.2, 0.7)
    qs = np.zeros((30, 16))
    qs[:, :7] = rng.uniform(-0.6, 0.6, (30, 7)) * (robot.joint_kinds[0] == "yaw")
    qs[:, 7:] = rng.normal(0.0, 0.3, (30, 9))
    qs[::3, 7:] = 0.0  # lying flat: the neck and head support the body too ("ground")
    qs = np.clip(qs, robot.lower, robot.upper)
    qs[:, [k for k in range(7) if robot.joint_kinds[k] != "yaw"]] = 0.0
    frames = robot.frames_many(qs, base)
    com = st.center_of_mass(robot, qs, base)
    got = st.static_margins_of_frames(robot, frames, com, contact)
    links = robot.shaped_links if contact == "ground" else np.intersect1d(robot.base_links, robot.shaped_links)
    # each box's lowest corners (as many as the contact model takes per shape: its lowest face, or the edge a tilted
    # box rests on) that are on the ground
    corners = box_corners(robot, frames, links).reshape(len(qs), -1, 8, 3)
    order = np.argsort(corners[..., 2], axis=-1, kind="stable")[..., :robot.geometry.contact_points_per_shape]
    corners = np.take_along_axis(corners, order[..., None], axis=2).reshape(len(qs), -1, 3)
    for k in range(len(qs)):
        touching = corners[k][corners[k][:, 2] <= GROUND_TOLERANCE, :2]
        ref = margin_to_hull(touching, com_reference(robot, frames[k])[:2])
        assert got[k] == pytest.approx(ref, abs=1e-9)
        assert st.static_margin(robot, qs[k], base, contact=contact) == pytest.approx(ref, abs=1e-9)


@pytest.mark.parametrize("rows", [1, 2, 272, 273, 545, 1001, 5000])
def test_center_of_mass_is_the_same_in_any_batch(robot, rows):
    """center_of_mass sums each configuration's links in the core, in a fixed order and without BLAS (whose kernels
    round a product of many rows otherwise than the same rows in blocks: OpenBLAS's AVX-512 kernel did from 273 rows
    of 320), so a configuration's centre of mass is the same numbers, bit for bit, in a batch of any size, alone, in
    any thread, on any machine. Against numpy's matrix products link by link (whose rounding is the BLAS kernel's),
    equal to round-off: at most 3.3e-16 m measured on each of OpenBLAS's x86-64 kernels, 1e-14 m allowed."""
    from hull_reference import com_reference

    rng = np.random.default_rng(rows)
    base = BasePlacement(0.3, -0.2, 0.7)
    qs = rng.uniform(robot.lower, robot.upper, (rows, robot.n_joints))
    com = st.center_of_mass(robot, qs, base)
    blocks = [st.center_of_mass(robot, part, base) for part in np.array_split(qs, min(rows, 7))]
    np.testing.assert_array_equal(np.concatenate(blocks), com)
    np.testing.assert_array_equal(st.center_of_mass(robot, qs[-1], base), com[-1])
    frames = robot.frames_many(qs[-50:], base)
    ref = np.array([com_reference(robot, F) for F in frames])
    np.testing.assert_allclose(com[-50:], ref, rtol=0, atol=1e-14)
    np.testing.assert_allclose(st.center_of_mass(robot, qs[-50:], base, frames=frames), ref, rtol=0, atol=1e-14)
