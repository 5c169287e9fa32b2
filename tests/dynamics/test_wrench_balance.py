"""Dynamic balance in the contact wrench cone: the gravito-inertial wrench from the robot's momenta, its ZMP on the
plane z = 0 against Eqs. 39-40 (stability.zmp), and on flat ground with high friction the CWC verdict against the
ZMP-in-support-polygon verdict of Section 3.1; the face form's margin against the span form's LP; the ZMP support area.

Still to come with the terrain simulation: the contact forces MuJoCo finds for the robot resting and moving on uneven
terrain, checked against these cones (a balanced motion's contact wrench inside the CWC, a tipping one outside)."""
import numpy as np
import pytest

from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import InputError
from snakehead.dynamics import stability as st
from snakehead.dynamics.contact_set import ContactSet, contact_wrench_cone, flat_contacts
from snakehead.dynamics.equilibrium_region import region_margin
from snakehead.dynamics.wrench_balance import (
    cwc_margin,
    gravito_inertial_wrench,
    gravito_inertial_wrenches,
    is_balanced_lp,
    zmp_on_plane,
    zmp_support_area,
)
from snakehead.model.physics import GRAVITY

#: ZMPs nearer the polygon's edge than this (m) are not compared (the linearised cones' friction decides them).
BAND = 1e-3


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def lift(robot, T=400, duration=2.0):
    """A quintic motion over a bent base (its joints still): from the neck and head folded back over the base (the
    CoM inside the support polygon) to them lifted and swung out sideways (outside)."""
    q0 = np.zeros(robot.n_joints)
    q0[0:7:2] = 0.5
    q1 = q0.copy()
    q0[8] = q0[10] = np.pi / 2
    q1[7] = q1[8] = -np.pi / 2
    t = np.linspace(0.0, duration, T)
    s = (t / duration) ** 3 * (10 - 15 * t / duration + 6 * (t / duration) ** 2)
    return t, q0 + (q1 - q0) * s[:, None]


def test_at_rest_the_wrench_is_the_weight():
    c = np.array([0.3, -0.2, 0.1])
    w = gravito_inertial_wrench(3.2, c, np.zeros(3), np.zeros(3))
    weight = np.array([0.0, 0.0, -3.2 * GRAVITY])
    np.testing.assert_allclose(w, np.r_[weight, np.cross(c, weight)])
    np.testing.assert_allclose(zmp_on_plane(w, 0.0), c[:2])
    np.testing.assert_allclose(zmp_on_plane(w, 0.7), c[:2])  # at rest every plane's ZMP is under the CoM


def test_robot_wrench_matches_the_centroidal_form_and_the_zmp(robot):
    t, q = lift(robot)
    base = BasePlacement(0.2, 0.1, 0.4)
    w = gravito_inertial_wrenches(robot, t, q, base)
    np.testing.assert_allclose(zmp_on_plane(w, 0.0), st.zmp(robot, t, q, base), atol=1e-12)
    # the same wrench from the CoM acceleration and the rate of angular momentum about the CoM
    P, L = st.momenta(robot, t, q, base)
    Pdot, Ldot = np.gradient(P, t, axis=0, edge_order=2), np.gradient(L, t, axis=0, edge_order=2)
    c = st.center_of_mass(robot, q, base)
    M = robot.total_mass
    centroidal = gravito_inertial_wrench(M, c, Pdot / M, Ldot - np.cross(c, Pdot))
    np.testing.assert_allclose(w, centroidal, atol=1e-9)


def test_robot_lift_cwc_agrees_with_zmp_in_polygon(robot):
    t, q = lift(robot)
    poly = st.support_polygon(robot, q[0], contact="footprint")
    res = st.dynamic_stability(robot, t, q, contact="footprint")
    A = contact_wrench_cone(flat_contacts(poly, mu=10.0))
    m = cwc_margin(A, gravito_inertial_wrenches(robot, t, q))
    far = np.abs(res.margin) > BAND
    assert far.sum() > 0.9 * len(t) and 0 < (res.margin > 0).sum() < len(t)  # both verdicts occur
    np.testing.assert_array_equal(m[far] > 0, res.margin[far] > 0)


def test_flat_ground_high_friction_cwc_agrees_with_zmp_in_polygon():
    rng = np.random.default_rng(7)
    compared = 0
    for trial in range(6):
        xy = rng.uniform(-0.5, 0.5, (8, 2))
        A = contact_wrench_cone(flat_contacts(xy, mu=50.0))
        n = 200
        M = 3.2
        com = np.column_stack([rng.uniform(-0.6, 0.6, (n, 2)), rng.uniform(0.02, 0.4, n)])
        Pdot = M * rng.normal(0.0, 1.0, (n, 3))
        Ldot = rng.normal(0.0, 2.0, (n, 3))
        w = np.concatenate([[0, 0, -M * GRAVITY] - Pdot, np.cross(com, [0, 0, -M * GRAVITY]) - Ldot], axis=1)
        zmp = st._zmp_from(com, Pdot, Ldot, M)
        np.testing.assert_allclose(zmp_on_plane(w, 0.0), zmp, atol=1e-12)
        ref = st.polygon_margin_many(np.broadcast_to(xy, (n, 8, 2)).copy(), np.ones((n, 8), bool), zmp)
        ours = cwc_margin(A, w)
        far = np.abs(ref) > BAND
        np.testing.assert_array_equal(ours[far] > 0, ref[far] > 0)
        compared += far.sum()
    assert compared > 1000


def test_margin_and_lp_agree_on_uneven_contacts():
    rng = np.random.default_rng(3)
    p = rng.uniform(-0.4, 0.4, (6, 3)) * [1, 1, 0.3]
    n = np.column_stack([rng.normal(0, 0.3, (6, 2)), np.ones(6)])
    contacts = ContactSet(p, n, 0.7)
    A = contact_wrench_cone(contacts)
    compared = 0
    for _ in range(80):
        c = np.r_[rng.uniform(-0.5, 0.5, 2), rng.uniform(0.0, 0.4)]
        w = gravito_inertial_wrench(3.2, c, rng.normal(0, 1.5, 3), rng.normal(0, 0.5, 3))
        m = cwc_margin(A, w)
        if abs(m) > 1e-6:
            assert is_balanced_lp(contacts, w) == (m > 0)
            compared += 1
    assert compared > 70


def test_pulling_ground_has_no_zmp_and_is_not_balanced():
    contacts = flat_contacts([[0, 0], [1, 0], [0, 1]], mu=1.0)
    w = gravito_inertial_wrench(1.0, [0.2, 0.2, 0.1], [0, 0, -2 * GRAVITY], np.zeros(3))  # falling faster than g
    assert np.all(np.isnan(zmp_on_plane(w)))
    assert cwc_margin(contact_wrench_cone(contacts), w) < 0 and not is_balanced_lp(contacts, w)


def test_bad_input():
    with pytest.raises(InputError):
        gravito_inertial_wrench(0.0, np.zeros(3), np.zeros(3), np.zeros(3))
    with pytest.raises(InputError):
        gravito_inertial_wrench(1.0, np.zeros(3), np.zeros(2), np.zeros(3))
    with pytest.raises(InputError):
        cwc_margin(np.zeros((3, 5)), np.zeros(6))
    with pytest.raises(InputError):
        zmp_on_plane(np.zeros(4))


def test_zmp_support_area_on_flat_ground_with_high_friction_is_the_support_polygon():
    rng = np.random.default_rng(9)
    xy = rng.uniform(-0.5, 0.5, (9, 2))
    A = contact_wrench_cone(flat_contacts(xy, mu=50.0))
    for com in ([0.0, 0.0, 0.3], [0.2, -0.1, 0.05]):
        area = zmp_support_area(A, com)
        np.testing.assert_allclose(area, xy[st.hull_indices(xy)], atol=1e-9)


def test_zmp_support_area_against_the_span_lp():
    """Points of the area are balanced (the force through the CoM and the ZMP, by LP), points outside are not."""
    rng = np.random.default_rng(4)
    p = rng.uniform(-0.4, 0.4, (6, 3)) * [1, 1, 0.3]
    n = np.column_stack([rng.normal(0, 0.3, (6, 2)), np.ones(6)])
    contacts = ContactSet(p, n, 0.6)
    A = contact_wrench_cone(contacts)
    com, h = np.array([0.05, 0.0, 0.35]), 0.05
    area = zmp_support_area(A, com, h)
    lo, hi = area.min(axis=0) - 0.1, area.max(axis=0) + 0.1
    compared = 0
    for xy in rng.uniform(lo, hi, (150, 2)):
        m = region_margin(area, xy)
        if abs(m) < 1e-6:
            continue
        f = com - np.r_[xy, h]  # the contact force through the ZMP and the CoM (any positive scale)
        assert is_balanced_lp(contacts, -np.r_[f, np.cross(com, f)]) == (m > 0)
        compared += 1
    assert compared > 140
