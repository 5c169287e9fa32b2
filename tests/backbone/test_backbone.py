"""Tests of snakehead.backbone: Eqs. 1-9 of the paper and the initial configuration of Section 3.3 (1).

Every equation is checked against an independent computation: closed forms (helix, circle), the robot's
forward kinematics, numerical integration / maximisation, scipy's convex hull.
"""
import math

import numpy as np
import pytest
from scipy import optimize
from scipy.spatial import ConvexHull

from snakehead import BasePlacement, SnakeRobot
from snakehead import backbone as bb
from snakehead._errors import Infeasible, InputError
from snakehead.dynamics import stability

L_BASE = 0.646  # tail end to P0 on the default robot (m)


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


@pytest.fixture(scope="module")
def default_backbone(robot):
    return bb.initial_backbone(robot)


def helix(a, b, with_derivatives):
    def r(t):
        return np.array([a * math.cos(t), a * math.sin(t), b * t])

    ders = (lambda t: np.array([-a * math.sin(t), a * math.cos(t), b]),
            lambda t: np.array([-a * math.cos(t), -a * math.sin(t), 0.0]),
            lambda t: np.array([a * math.sin(t), -a * math.cos(t), 0.0]))
    return r, (ders if with_derivatives else None)


def point_index(robot, name):
    return robot.body.link_index(name)


# ------------------------------------------------------------------------------------------------
# layout and interval mapping
# ------------------------------------------------------------------------------------------------
def test_joint_layout_of_default_robot(robot):
    expected = 0.0405 + 0.0865 * np.arange(16)
    np.testing.assert_allclose(robot.joint_arc_lengths, expected, atol=1e-12)
    assert robot.joint_kinds == tuple("yaw" if i % 2 == 0 else "pitch" for i in range(16))
    np.testing.assert_array_equal(robot.joint_signs, 1.0)
    assert robot.body_length == pytest.approx(1.384, abs=1e-12)
    assert robot.base_length == pytest.approx(L_BASE, abs=1e-12)
    assert bb.up_length(robot) == pytest.approx(0.738, abs=1e-12)


def test_joint_intervals_tile_the_curve_per_kind():
    s = np.array([0.0405, 0.127, 0.2135, 0.3, 0.3865, 0.473, 0.5595])
    kinds = ["yaw", "pitch"] * 3 + ["yaw"]
    iv = bb.joint_intervals(s, kinds, L_BASE)
    # yaw joints 1, 3, 5, 7 take [0, s2], [s2, s4], [s4, s6], [s6, P0]
    np.testing.assert_allclose(iv[0::2], [[0, 0.127], [0.127, 0.3], [0.3, 0.473], [0.473, L_BASE]], atol=1e-12)
    # pitch joints 2, 4, 6 take [0, s3], [s3, s5], [s5, P0]
    np.testing.assert_allclose(iv[1::2], [[0, 0.2135], [0.2135, 0.3865], [0.3865, L_BASE]], atol=1e-12)


# ------------------------------------------------------------------------------------------------
# the plane arc: Eqs. 1, 8, 9
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", [0.4, math.pi, 5.5])
@pytest.mark.parametrize("turn", [1, -1])
def test_exact_chords_put_the_base_joints_on_the_arc(robot, theta, turn):
    base = BasePlacement(0.3, -0.2, 0.7)
    q = np.zeros(16)
    q[:7] = bb.arc_joint_angles(L_BASE, theta, robot, chords="exact", turn=turn)
    F = robot.frames(q, base)
    arc = bb.base_arc(robot, theta, base, chords="exact", turn=turn)
    vertices = ["link_0", "link_1", "link_3", "link_5", "link_7", "base_end"]  # tail end, yaw joints, P0
    P = np.array([F[point_index(robot, n), :3, 3] for n in vertices])
    radial = np.linalg.norm(P[:, :2] - arc.center, axis=1) - arc.radius
    assert np.abs(radial).max() < 1e-9
    assert np.abs(P[:, 2] - 0.0215).max() < 1e-12
    np.testing.assert_allclose(P[0], arc.point(0.0), atol=1e-9)
    np.testing.assert_allclose(P[-1], arc.point(arc.length), atol=1e-9)
    # the vertices run monotonically along the arc, within its central angle
    ang = np.unwrap(np.arctan2(P[:, 1] - arc.center[1], P[:, 0] - arc.center[0]))
    sweep = turn * (ang - ang[0])
    assert np.all(np.diff(sweep) > 0) and sweep[-1] == pytest.approx(theta, abs=1e-9)
    # the straight pitch joints lie on the chords (midway: the two links are equal)
    for name, (a, b) in {"link_2": (1, 2), "link_4": (2, 3), "link_6": (3, 4)}.items():
        np.testing.assert_allclose(F[point_index(robot, name), :3, 3], 0.5 * (P[a] + P[b]), atol=1e-12)
    # the chord radius: every chord c subtends 2 asin(c / 2r) and they add up to theta
    c = np.linalg.norm(np.diff(P, axis=0), axis=1)
    assert np.sum(2 * np.arcsin(c / (2 * arc.radius))) == pytest.approx(theta, abs=1e-12)


@pytest.mark.parametrize("theta", [0.5, 2.0, math.pi])
def test_eq9_arclength_angles(robot, theta):
    q = bb.arc_joint_angles(L_BASE, theta, robot)
    r = L_BASE / theta  # Eq. 1
    np.testing.assert_allclose(q, [0.127 / r, 0, 0.173 / r, 0, 0.173 / r, 0, 0.173 / r], atol=1e-12)
    assert q.sum() == pytest.approx(theta, abs=1e-12)  # the base's yaw adds up to the central angle
    qq = np.zeros(16)
    qq[:7] = q
    F = robot.frames(qq)
    heading = math.atan2(F[point_index(robot, "base_end"), 1, 0], F[point_index(robot, "base_end"), 0, 0])
    assert math.remainder(heading - theta, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    # the joints lie near the arc (the discretisation error of Eq. 9 with 0.173 m between yaw joints)
    arc = bb.base_arc(robot, theta)
    names = ["link_0", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "link_7", "base_end"]
    P = np.array([F[point_index(robot, n), :3, 3] for n in names])
    radial = np.abs(np.linalg.norm(P[:, :2] - arc.center, axis=1) - arc.radius)
    assert radial.max() < 0.015


def test_arc_anchor_end_joins_the_robot_at_p0(robot):
    theta = 2.5
    q = np.zeros(16)
    q[:7] = bb.arc_joint_angles(L_BASE, theta, robot)
    T = robot.frame(q, "base_end")
    arc = bb.base_arc(robot, theta, anchor="end")
    np.testing.assert_allclose(arc.point(arc.length), T[:3, 3], atol=1e-12)
    np.testing.assert_allclose(arc.tangent(arc.length), T[:3, 0], atol=1e-12)


# ------------------------------------------------------------------------------------------------
# Eq. 2: the area and its maximum
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", [0.3, 1.5, math.pi, 4.5, 2 * math.pi])
def test_eq2_area_against_the_polygon_of_the_arc(theta):
    arc = bb.PlaneArc(radius=L_BASE / theta, central_angle=theta)
    pts = arc.point(np.linspace(0, arc.length, 20001))[:, :2]  # closed by the chord back to the start
    assert bb.arc_segment_area(L_BASE, theta) == pytest.approx(bb.polygon_area(pts), rel=1e-6)


def test_eq2_maximum_is_pi_for_a_fixed_length():
    res = optimize.minimize_scalar(lambda t: -bb.arc_segment_area(L_BASE, t), bounds=(1e-3, 2 * math.pi),
                                   method="bounded", options={"xatol": 1e-10})
    theta_star, s_star = bb.arc_area_maximum(L_BASE)
    assert res.x == pytest.approx(theta_star, abs=1e-6)
    assert theta_star == math.pi
    assert -res.fun == pytest.approx(s_star, rel=1e-12)
    r = L_BASE / math.pi
    assert s_star == pytest.approx(0.5 * math.pi * r * r, rel=1e-12)  # the paper's "1/2 pi r^2"
    # the derivative's sign: + below pi, - above (the calculus in arc_area_maximum's docstring)
    th = np.linspace(0.05, 2 * math.pi, 400)
    dS = np.gradient(bb.arc_segment_area(L_BASE, th), th)
    assert np.all(dS[th < math.pi - 0.05] > 0) and np.all(dS[th > math.pi + 0.05] < 0)
    # read with r fixed instead, S = r^2 (theta - sin theta) / 2 only grows: no interior maximum
    S_fixed_r = 0.5 * 0.2 ** 2 * (th - np.sin(th))
    assert np.all(np.diff(S_fixed_r) > 0)


# ------------------------------------------------------------------------------------------------
# Eqs. 3-7 on a general curve
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("exact", [True, False])
def test_helix_curvature_torsion_length_phase(exact):
    a, b = 0.3, 0.1
    r, ders = helix(a, b, exact)
    c = bb.SpaceCurve(r, 0.0, 4 * math.pi, derivatives=ders)
    t = np.linspace(0, 4 * math.pi, 7)
    k, tau = c.curvature_torsion(t)
    tol = 1e-12 if exact else 1e-7
    np.testing.assert_allclose(k, a / (a * a + b * b), rtol=tol)
    np.testing.assert_allclose(tau, b / (a * a + b * b), rtol=tol)
    speed = math.hypot(a, b)
    assert c.length == pytest.approx(4 * math.pi * speed, rel=1e-9)
    np.testing.assert_allclose(c.arc_length(t), t * speed, rtol=1e-9, atol=1e-12)
    s = np.array([0.0, 0.5, 1.7, 3.9])
    np.testing.assert_allclose(c.t_at(s), s / speed, atol=1e-9)
    kappa0, tau0 = a / (a * a + b * b), b / (a * a + b * b)
    np.testing.assert_allclose(c.phase(s, phi0=0.3), 0.3 + tau0 * s, rtol=1e-6, atol=1e-9)  # Eq. 3
    ky, kp = c.curvature_projections(s, phi0=0.3)  # Eq. 4
    np.testing.assert_allclose(ky, kappa0 * np.cos(0.3 + tau0 * s), atol=1e-5 * kappa0)
    np.testing.assert_allclose(kp, kappa0 * np.sin(0.3 + tau0 * s), atol=1e-5 * kappa0)
    # Eqs. 5-6 in closed form: int kappa cos(phi0 + tau s) ds = kappa/tau [sin phi]_s1^s2, etc.
    s1, s2 = np.array([0.1, 1.0, 2.0]), np.array([0.6, 1.9, 3.5])
    ty, tp = c.bending(s1, s2, phi0=0.3)
    p1, p2 = 0.3 + tau0 * s1, 0.3 + tau0 * s2
    atol = 1e-8 if exact else 1e-6
    np.testing.assert_allclose(ty, kappa0 / tau0 * (np.sin(p2) - np.sin(p1)), atol=atol)
    np.testing.assert_allclose(tp, -kappa0 / tau0 * (np.cos(p2) - np.cos(p1)), atol=atol)


def test_finite_differences_match_exact_derivatives():
    P = np.array([[0, 0, 0], [0.3, 0.1, 0.0], [0.2, 0.5, 0.4], [0.9, 0.7, 0.2]], dtype=float)
    exact = bb.cubic_bezier(P)
    fd = bb.SpaceCurve(exact.point, 0.0, 1.0)
    for t in (0.1, 0.5, 0.9):
        for de, dn in zip(exact.derivs(t), fd.derivs(t)):
            np.testing.assert_allclose(dn, de, atol=2e-7)


def test_general_discretisation_of_a_plane_arc_equals_eq9(robot):
    theta = 2.4
    arc = bb.base_arc(robot, theta)
    q_special = bb.arc_joint_angles(L_BASE, theta, robot)
    q_general = bb.curve_joint_angles(robot, arc.curve(), robot.parts.base, phi0=0.0)
    np.testing.assert_allclose(q_general, q_special, atol=1e-8)
    # the same arc given only as r(t), t not arc length, with finite-difference derivatives
    R, c = arc.radius, arc.center

    def r(t):  # counter-clockwise from the start, which sits at angle -pi/2 about the centre
        return np.array([c[0] + R * math.cos(t), c[1] + R * math.sin(t), 0.0215])

    fd_arc = bb.SpaceCurve(r, -math.pi / 2, -math.pi / 2 + theta)
    q_fd = bb.curve_joint_angles(robot, fd_arc, robot.parts.base, frame0=np.eye(3))
    np.testing.assert_allclose(q_fd, q_special, atol=1e-7)
    # a right turn: the normal points along -y, phi0 = pi, kappa_y = -kappa, negative yaw
    right = bb.base_arc(robot, theta, turn=-1).curve()
    assert right.initial_phase(np.eye(3)) == pytest.approx(math.pi, abs=1e-12)
    np.testing.assert_allclose(bb.curve_joint_angles(robot, right, robot.parts.base, frame0=np.eye(3)),
                               bb.arc_joint_angles(L_BASE, theta, robot, turn=-1), atol=1e-8)


def test_initial_phase_takes_a_frame_tilted_within_the_axis_tolerance():
    """A body frame whose x is tilted off the start tangent by less than AXIS_TOLERANCE_DEG (a bent base whose
    yaw axes a description writes 0.6 deg off) gives the phase of its projection; beyond it, an error."""
    from scipy.spatial.transform import Rotation

    from snakehead.model.body_frame import AXIS_TOLERANCE_DEG

    r, ders = helix(0.8, 0.25, True)
    c = bb.SpaceCurve(r, 0.0, 2.0, derivatives=ders)
    T, N, B = c.frenet(0.0).T
    y = math.cos(0.7) * N - math.sin(0.7) * B
    R0 = np.column_stack([T, y, np.cross(T, y)])
    for tilt_deg, ok in ((0.6 * AXIS_TOLERANCE_DEG, True), (1.5 * AXIS_TOLERANCE_DEG, False)):
        tilted = Rotation.from_rotvec(np.radians(tilt_deg) * R0[:, 2]).as_matrix() @ R0  # x turned about z
        if ok:
            assert c.initial_phase(tilted) == pytest.approx(0.7, abs=np.radians(tilt_deg))
        else:
            with pytest.raises(ValueError, match="not the curve's start tangent"):
                c.initial_phase(tilted)


def test_helix_gives_yaw_and_pitch_and_fk_follows_it(robot):
    """A helix discretised onto the whole body: both yaw and pitch joints bend, with the closed-form angles
    of Eqs. 5-6, and the robot's joints (FK) stay near the helix (a gentle one: 8.65 cm links)."""
    a, b = 0.8, 0.25
    r, ders = helix(a, b, True)
    c = bb.SpaceCurve(r, 0.0, 2.0, derivatives=ders)
    F0 = c.frenet(0.0)
    for phi0 in (0.0, 0.7):
        # the body's y-axis at the start is N rotated by -phi0 about T (so N = cos phi0 y + sin phi0 z)
        T, N, B = F0.T
        y = math.cos(phi0) * N - math.sin(phi0) * B
        R0 = np.column_stack([T, y, np.cross(T, y)])
        assert c.initial_phase(R0) == pytest.approx(phi0, abs=1e-12)
        q = bb.curve_joint_angles(robot, c, slice(0, 16), frame0=R0)
        assert np.abs(q[0::2]).min() > 1e-3 and np.abs(q[1::2]).min() > 1e-3  # yaw and pitch both bend
        # closed form of every joint's angle (Eqs. 5-6 with the intervals of joint_intervals)
        kappa0, tau0 = a / (a * a + b * b), b / (a * a + b * b)
        iv = bb.joint_intervals(robot.joint_arc_lengths, robot.joint_kinds, robot.body_length)  # cut at the tip
        p1, p2 = phi0 + tau0 * iv[:, 0], phi0 + tau0 * iv[:, 1]
        ty = kappa0 / tau0 * (np.sin(p2) - np.sin(p1))
        tp = -kappa0 / tau0 * (np.cos(p2) - np.cos(p1))
        np.testing.assert_allclose(q[0::2], ty[0::2], atol=1e-8)
        np.testing.assert_allclose(q[1::2], -tp[1::2], atol=1e-8)  # pitch joint = -theta_p (axis +y)
        # FK in the root frame against the helix expressed in the body frame at its start
        P = robot.body.fk_all(q)[:, :3, 3]
        lay_s = np.concatenate([[0.0], robot.joint_arc_lengths, [robot.body_length]])
        names = ["link_0"] + [robot.link_names[i] for i in robot.body.model.joint_child_links] + ["head_tip"]
        Pj = np.array([P[point_index(robot, n)] for n in names])
        H = np.array([R0.T @ (c.point(c.t_at(s)) - c.point(0.0)) for s in lay_s])
        assert np.linalg.norm(Pj - H, axis=1).max() < 0.01  # measured 7.7 mm, at the head tip


# ------------------------------------------------------------------------------------------------
# the optimised central angle
# ------------------------------------------------------------------------------------------------
def scipy_hull_area(robot, q):
    """Independent area: scipy's 2-D hull of the base's link endpoints (the paper's Eq. 24 contacts)."""
    F = robot.frames(q)
    names = ["link_0", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "link_7", "base_end"]
    return ConvexHull(np.array([F[point_index(robot, n), :2, 3] for n in names])).volume


def test_optimised_central_angle(robot, default_backbone):
    opt = default_backbone.optimum
    assert opt is not None and opt.central_angle == default_backbone.central_angle
    th = opt.central_angle
    q_up = opt.q[7:]

    def q_of(t):
        return np.concatenate([bb.arc_joint_angles(L_BASE, t, robot), q_up])

    assert opt.area == pytest.approx(scipy_hull_area(robot, opt.q), rel=1e-12)
    for d in (1e-3, 0.01, 0.05, 0.3):
        for t in (th - d, th + d):
            assert scipy_hull_area(robot, q_of(t)) < opt.area
    assert opt.margin > 0 and stability.static_margin(robot, opt.q) > 0
    assert opt.grid[:, 1].max() <= opt.area + 1e-15
    # against Eq. 2: the discretised polygon is smaller than the continuous arc's segment, and its best
    # angle lies near pi (within 0.3 rad) but not at it
    assert opt.eq2_angle == math.pi and opt.eq2_area == pytest.approx(L_BASE ** 2 / (2 * math.pi))
    assert opt.area < opt.eq2_area
    assert opt.area_at_eq2_angle < opt.area
    assert abs(th - math.pi) < 0.3
    assert np.all(np.abs(opt.q[:7]) <= math.pi / 2)


def test_optimised_angle_with_an_active_margin_constraint(robot, default_backbone):
    free = default_backbone.optimum
    need = free.margin + 0.01
    opt = bb.optimize_base_arc(robot, free.q[7:], min_margin=need)
    assert opt.margin == pytest.approx(need, abs=1e-6)  # on the constraint's boundary
    assert opt.central_angle > free.central_angle  # a rounder base holds the leaning neck better here
    assert opt.area < free.area


def test_joint_limit_bounds_the_central_angle(robot):
    lim = bb.arc_angle_limit(robot)
    assert lim == pytest.approx(math.pi / 2 * L_BASE / 0.173, rel=1e-12)
    assert np.abs(bb.arc_joint_angles(L_BASE, lim, robot)).max() == pytest.approx(math.pi / 2, rel=1e-12)


# ------------------------------------------------------------------------------------------------
# the initial configuration (Section 3.3 (1))
# ------------------------------------------------------------------------------------------------
def test_initial_configuration_follows_the_backbone(robot, default_backbone):
    ib = default_backbone
    q = ib.q
    assert q.shape == (16,)
    np.testing.assert_array_equal(bb.initial_configuration(robot), q)
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
    F = robot.frames(q)
    # G1 at P0: the Bezier starts where the arc ends, along the arc's end tangent, and so does the robot
    P = ib.control_points
    p0, t0 = ib.arc.point(ib.arc.length), ib.arc.tangent(ib.arc.length)
    np.testing.assert_allclose(ib.up_curve.point(0.0), p0, atol=1e-12)
    d1 = ib.up_curve.derivs(0.0)[0]
    np.testing.assert_allclose(d1 / np.linalg.norm(d1), t0, atol=1e-12)
    Tb = F[point_index(robot, "base_end")]
    np.testing.assert_allclose(Tb[:3, 3], p0, atol=1e-9)
    np.testing.assert_allclose(Tb[:3, 0], t0, atol=1e-9)
    # the Bezier lies in the vertical plane through P0 and T0, and so does the raised body
    normal = np.cross(t0, [0, 0, 1])
    assert np.abs((P - p0) @ normal).max() < 1e-12
    up = F[point_index(robot, "base_end"):, :3, 3]
    assert np.abs((up - p0) @ normal).max() < 1e-9
    np.testing.assert_allclose(q[8::2], 0.0, atol=1e-9)  # the neck and head's yaw joints stay straight
    assert np.all(q[7::2] < 0)  # the pitch joints raise the head (positive pitch turns down)
    # the curve is as long as the neck and head
    assert ib.up_curve.length == pytest.approx(bb.up_length(robot), abs=1e-9)
    # every frame of the neck and head lies within 2.5 cm of the Bezier (measured 2.1 cm, at link_9)
    C = np.array([ib.up_curve.point(t) for t in np.linspace(0, 1, 2001)])
    dist = np.linalg.norm(up[:, None, :] - C[None], axis=2).min(axis=1)
    assert dist.max() < 0.025
    # the head is raised and the base lies on the ground
    assert F[-1, 2, 3] > 0.4
    np.testing.assert_allclose(F[:point_index(robot, "base_end") + 1, 2, 3], 0.0215, atol=1e-12)
    assert stability.static_margin(robot, q) > 0


def test_initial_configuration_with_placement_and_fixed_angle(robot):
    base = BasePlacement(0.5, 0.2, -1.0)
    ib = bb.initial_backbone(robot, central_angle=2.0, base=base, turn=-1)
    assert ib.optimum is None and ib.central_angle == 2.0
    np.testing.assert_allclose(ib.q[:7], bb.arc_joint_angles(L_BASE, 2.0, robot, turn=-1), atol=1e-15)
    T = robot.frame(ib.q, "base_end", base)
    np.testing.assert_allclose(T[:3, 3], ib.arc.point(ib.arc.length), atol=1e-9)
    np.testing.assert_allclose(T[:3, 0], ib.arc.tangent(ib.arc.length), atol=1e-9)
    # the up part's angles do not depend on the base (the curve is rigidly attached at P0)
    np.testing.assert_allclose(ib.q[7:], bb.initial_configuration(robot, central_angle=3.0)[7:], atol=1e-12)


# ------------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("length", [0.0, -1.0, float("nan"), float("inf"), "abc"])
def test_bad_length(robot, length):
    with pytest.raises(TypeError if isinstance(length, str) else ValueError, match="length"):
        bb.arc_joint_angles(length, 1.0, robot)


@pytest.mark.parametrize("theta", [0.0, -0.5, 2 * math.pi + 0.01, float("nan"), None])
def test_bad_central_angle(robot, theta):
    with pytest.raises(TypeError if theta is None else ValueError, match="central_angle"):
        bb.arc_joint_angles(L_BASE, theta, robot)
    with pytest.raises(ValueError, match="central_angle"):
        bb.arc_segment_area(L_BASE, theta if theta is not None else float("nan"))


@pytest.mark.parametrize("kwargs, match", [
    (dict(radius=0.0, central_angle=1.0), "radius must be a positive finite number"),
    (dict(radius=0.2, central_angle=7.0), r"central_angle must be in \(0, 2\*pi\]"),
    (dict(radius=0.2, central_angle=1.0, turn=2), r"turn must be \+1"),
    (dict(radius=0.2, central_angle=1.0, start=[0.0, float("nan")]), "start contains NaN or inf")])
def test_bad_plane_arc(kwargs, match):
    with pytest.raises(InputError, match=match):
        bb.PlaneArc(**kwargs)


def test_other_bad_arc_input(robot):
    with pytest.raises(ValueError, match="chords"):
        bb.arc_joint_angles(L_BASE, 1.0, robot, chords="spline")
    with pytest.raises(ValueError, match="turn"):
        bb.arc_joint_angles(L_BASE, 1.0, robot, turn=0)
    with pytest.raises(ValueError, match="does not reach"):
        bb.arc_joint_angles(0.3, 1.0, robot)
    with pytest.raises(ValueError, match="min_margin"):
        bb.optimize_base_arc(robot, min_margin=-0.01)
    with pytest.raises(Infeasible, match="no central angle"):
        bb.optimize_base_arc(robot, min_margin=1.0)


@pytest.mark.parametrize("bad", [
    lambda t: np.array([t, 0.0]),  # wrong shape
    lambda t: np.array([[t, 0.0, 0.0]]),  # wrong shape
    lambda t: np.array([t, float("nan"), 0.0]),  # NaN
    lambda t: "curve",  # not numbers (TypeError)
    lambda t: 1 / 0,  # raises
])
def test_bad_curve_callable(bad):
    with pytest.raises((ValueError, TypeError), match=r"r\(0"):
        bb.SpaceCurve(bad, 0.0, 1.0)


def test_bad_curve_input():
    r, ders = helix(0.3, 0.1, True)
    with pytest.raises(ValueError, match="t1 > t0"):
        bb.SpaceCurve(r, 1.0, 1.0)
    with pytest.raises(ValueError, match="callable"):
        bb.SpaceCurve(np.zeros(3), 0.0, 1.0)
    with pytest.raises(ValueError, match="derivatives"):
        bb.SpaceCurve(r, 0.0, 1.0, derivatives=ders[:2])
    with pytest.raises(ValueError, match=r"dr\("):
        bb.SpaceCurve(r, 0.0, 1.0, derivatives=(lambda t: np.zeros(2), ders[1], ders[2]))
    with pytest.raises(ValueError, match="not regular"):
        bb.SpaceCurve(lambda t: np.array([t ** 3, t ** 2 * 0 + 0.1 * t ** 3, 0.0]), -1.0, 1.0)
    with pytest.raises(ValueError, match="inflection"):  # y = x^3: curvature changes sign at x = 0
        bb.SpaceCurve(lambda t: np.array([t, t ** 3, 0.0]), -1.0, 1.0)
    c = bb.SpaceCurve(r, 0.0, 1.0, derivatives=ders)
    with pytest.raises(ValueError, match="arc length"):
        c.t_at(c.length + 0.1)
    with pytest.raises(ValueError, match="tangent"):
        c.initial_phase(np.eye(3))
    with pytest.raises(ValueError, match="shorter"):
        bb.curve_joint_angles(SnakeRobot.default(), c, slice(0, 16))


def test_straight_curve_gives_zero_angles(robot):
    line = bb.SpaceCurve(lambda t: np.array([t, 0.0, 0.0215]), 0.0, 1.5)
    np.testing.assert_allclose(bb.curve_joint_angles(robot, line, slice(0, 16)), 0.0, atol=1e-12)


@pytest.mark.parametrize("kwargs, match", [
    (dict(height=0.0), "height"),
    (dict(height=float("nan")), "NaN"),
    (dict(tip_angle=0.0), "tip_angle"),
    (dict(tip_angle=math.pi), "tip_angle"),
    (dict(handle_ratio=-1.0), "handle_ratio"),
])
def test_bad_up_curve_shape(kwargs, match):
    with pytest.raises(ValueError, match=match):
        bb.UpCurveShape(**kwargs)


def test_unreachable_or_inflected_up_curve(robot):
    with pytest.raises(Infeasible, match="beyond"):
        bb.initial_configuration(robot, shape=bb.UpCurveShape(height=0.9, reach=0.0))
    with pytest.raises(Infeasible, match="inflection"):  # ends pointing forward: needs an S-bend
        bb.initial_configuration(robot, central_angle=2.0,
                                 shape=bb.UpCurveShape(height=0.3, reach=0.5, tip_angle=0.2))


def test_curve_that_starts_straight(robot):
    """z = x^3 in the x-z plane: kappa(0) = 0, no inflection on [0, 0.8]. With the body along +x and z up the
    normal is +z (phi0 = pi/2): only pitch joints bend, and their angles add up to minus the tangent's
    elevation at the part's end (Eq. 6 integrates kappa_p = d(elevation)/ds)."""
    c = bb.SpaceCurve(lambda t: np.array([t, 0.0, t ** 3]), 0.0, 0.8)
    assert c.initial_phase(np.eye(3)) == pytest.approx(math.pi / 2, abs=1e-9)
    q = bb.curve_joint_angles(robot, c, slice(0, 10), frame0=np.eye(3))
    np.testing.assert_allclose(q[0::2], 0.0, atol=1e-12)
    t_end = c.t_at(0.0405 + 10 * 0.0865)  # the part ends at joint 11
    assert q[1::2].sum() == pytest.approx(-math.atan(3 * t_end ** 2), abs=1e-8)
    assert np.all(q[1::2] < 0)  # bending up is negative pitch


def test_figures(tmp_path, default_backbone):
    from snakehead.viz import backbone_figures as bp
    from snakehead.viz import save

    figs = [bp.plot_arc_discretisation(central_angle=2.0), bp.plot_initial_configuration(default_backbone),
            bp.plot_area_vs_angle(default_backbone.optimum)]
    for fig, name in zip(figs, ("fig3.png", "fig14.png", "area.png")):
        assert save(fig, tmp_path / name).stat().st_size > 20_000
    assert len(figs[1].axes) == 2 and figs[1].axes[1].name == "3d"


def test_exact_chord_polygon_is_largest_on_a_semicircle(robot, default_backbone):
    """With exact chords the base polygon has fixed sides and a free closing side, so its area is largest when
    it is inscribed in a semicircle on that side (theta = pi): Eq. 2's maximiser, reached by the optimiser."""
    opt = bb.optimize_base_arc(robot, default_backbone.q[7:], chords="exact")
    assert opt.central_angle == pytest.approx(math.pi, abs=1e-5)
    assert opt.area == pytest.approx(scipy_hull_area(robot, opt.q), rel=1e-12)
    # the vertices (tail end, yaw joints, P0) then see the chord P0 - tail end at a right angle (Thales)
    F = robot.frames(opt.q)
    ends = F[point_index(robot, "link_0"), :2, 3], F[point_index(robot, "base_end"), :2, 3]
    for name in ("link_1", "link_3", "link_5", "link_7"):
        v = F[point_index(robot, name), :2, 3]
        assert np.dot(ends[0] - v, ends[1] - v) == pytest.approx(0.0, abs=1e-5)
    lim = bb.arc_angle_limit(robot, chords="exact")
    q = bb.arc_joint_angles(L_BASE, lim, robot, chords="exact")
    assert np.abs(q).max() == pytest.approx(math.pi / 2, abs=1e-9)
