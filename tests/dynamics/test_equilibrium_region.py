"""The static-equilibrium region (Bretl and Lall 2008) against brute force: a grid of CoM positions, each tested by
its own LP over the contact forces (tests/contact_reference.py), on a step, a slope, a V-shaped trench and random
contacts; on flat ground it is the support polygon of Eq. 24 (vertices and margins)."""
import numpy as np
import pytest
from contact_reference import statically_balanced
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as hs

from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import Infeasible, InputError
from snakehead.dynamics import stability as st
from snakehead.dynamics.contact_set import ContactSet, flat_contacts
from snakehead.dynamics.equilibrium_region import region_margin, static_equilibrium_lp, static_equilibrium_region
from snakehead.model.physics import GROUND_FRICTION

#: Grid points nearer the region's boundary than this (m) are not compared (the LPs' tolerances decide them).
BAND = 1e-5


def step():
    """A body over a 0.1 m step: contacts on the floor, on the step's edge (a 45-degree normal) and on top."""
    floor = [[0.0, 0.0, 0.0], [0.2, 0.1, 0.0], [0.35, -0.05, 0.0]]
    top = [[0.6, 0.05, 0.1], [0.8, -0.1, 0.1], [0.9, 0.15, 0.1]]
    edge = [[0.45, 0.0, 0.1]]
    s = np.sqrt(0.5)
    normals = [[0, 0, 1]] * 3 + [[0, 0, 1]] * 3 + [[-s, 0, s]]
    return ContactSet(np.array(floor + top + edge), np.array(normals, float), GROUND_FRICTION)


def slope(angle=np.radians(20.0), mu=GROUND_FRICTION):
    """Contacts on a plane slope rising along x by ``angle``."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(-0.4, 0.4, (6, 2))
    z = xy[:, 0] * np.tan(angle)
    n = np.tile([-np.sin(angle), 0.0, np.cos(angle)], (6, 1))
    return ContactSet(np.column_stack([xy, z]), n, mu)


def trench(mu=0.5):
    """A V-shaped trench along y: contacts on its two walls (45 degrees), none on the bottom."""
    s = np.sqrt(0.5)
    pts = [[-0.1, 0.0, 0.1], [-0.1, 0.5, 0.1], [-0.05, 0.25, 0.05], [0.1, 0.1, 0.1], [0.1, 0.6, 0.1]]
    n = [[s, 0, s]] * 3 + [[-s, 0, s]] * 2
    return ContactSet(np.array(pts), np.array(n), mu)


def random_contacts(seed, k=8):
    rng = np.random.default_rng(seed)
    p = rng.uniform(-0.5, 0.5, (k, 3)) * [1, 1, 0.2]
    n = np.column_stack([rng.normal(0, 0.5, (k, 2)), np.ones(k)])
    return ContactSet(p, n, rng.uniform(0.2, 1.0))


CASES = {"step": step, "slope": slope, "trench": trench, "random": lambda: random_contacts(3),
         "random-low-friction": lambda: random_contacts(4, 12)}


def grid_check(contacts, region, n=13):
    """Inside/outside of the region against the brute-force LP on an n x n grid over the outer polygon's box."""
    lo, hi = region.outer.min(axis=0) - 0.1, region.outer.max(axis=0) + 0.1
    xs, ys = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n))
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    margins = region_margin(region.vertices, pts)
    compared = 0
    for p, m in zip(pts, margins):
        if abs(m) < BAND:
            continue
        assert statically_balanced(contacts, p) == (m > 0), (p, m)
        compared += 1
    return compared


@pytest.mark.parametrize("name", sorted(CASES))
def test_region_matches_brute_force(name):
    contacts = CASES[name]()
    region = static_equilibrium_region(contacts)
    assert region.bounded and region.area_gap <= 1e-8
    assert len(region.vertices) >= 3
    assert grid_check(contacts, region) > 100
    # the outer polygon holds the inner one, and every inner vertex balances
    assert np.all(region_margin(region.outer, region.vertices) >= -1e-9)
    assert all(static_equilibrium_lp(contacts, v + 1e-7 * (region.vertices.mean(axis=0) - v))
               for v in region.vertices)


def test_region_does_not_depend_on_mass_or_height():
    contacts = step()
    region = static_equilibrium_region(contacts)
    rng = np.random.default_rng(0)
    for p in rng.uniform(region.outer.min(axis=0), region.outer.max(axis=0), (30, 2)):
        m = region_margin(region.vertices, p)
        if abs(m) > BAND:
            assert statically_balanced(contacts, p, mass=50.0, com_z=2.0) == (m > 0)


def test_slope_steeper_than_friction_has_no_equilibrium():
    with pytest.raises(Infeasible):
        static_equilibrium_region(slope(np.radians(40.0), mu=0.5))  # tan 40 = 0.84 > 0.5


@pytest.mark.parametrize("mu", [1e-3, 0.3, GROUND_FRICTION, 5.0])
def test_flat_ground_region_is_the_support_polygon(mu):
    rng = np.random.default_rng(int(mu * 1000))
    xy = rng.uniform(-0.6, 0.6, (12, 2))
    region = static_equilibrium_region(flat_contacts(xy, mu))
    hull = xy[st.hull_indices(xy)]
    np.testing.assert_allclose(region.vertices, hull, atol=1e-9)
    probe = rng.uniform(-0.8, 0.8, (200, 2))
    ours = region_margin(region.vertices, probe)
    ref = st.polygon_margin_many(np.broadcast_to(xy, (200, 12, 2)).copy(), np.ones((200, 12), bool), probe)
    np.testing.assert_allclose(ours, ref, atol=1e-9)


def test_flat_ground_region_is_the_robots_support_polygon():
    robot = SnakeRobot.default()
    q = np.zeros(robot.n_joints)
    q[0:7:2] = 0.4  # the base in a plane arc
    base = BasePlacement(0.2, -0.1, 0.5)
    poly = st.support_polygon(robot, q, base, contact="footprint")
    region = static_equilibrium_region(flat_contacts(poly))
    np.testing.assert_allclose(region.vertices, poly, atol=1e-9)
    com = st.center_of_mass(robot, q, base)
    assert region_margin(region.vertices, com[:2]) == pytest.approx(
        st.static_margin(robot, q, base, contact="footprint"), abs=1e-9)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(hs.lists(hs.tuples(hs.floats(-1, 1), hs.floats(-1, 1)), min_size=3, max_size=15),
       hs.floats(0.05, 2.0))
def test_flat_ground_any_points(points, mu):
    xy = np.round(np.array(points), 3)  # a millimetre grid: no near-collinear slivers below the LPs' tolerance
    region = static_equilibrium_region(flat_contacts(xy, mu))
    hull = xy[st.hull_indices(xy)]
    if len(hull) >= 3:
        np.testing.assert_allclose(region.vertices, hull, atol=1e-9)
    else:  # a segment or a point: the region is it, with no inside
        assert np.all(region_margin(hull, region.vertices) >= -1e-9) if len(hull) == 2 else True
        assert region_margin(region.vertices, xy.mean(axis=0)) <= 1e-9


def test_collinear_flat_contacts_give_a_segment():
    region = static_equilibrium_region(flat_contacts([[0, 0], [1, 0], [2, 0]]))
    np.testing.assert_allclose(region.vertices, [[0, 0], [2, 0]], atol=1e-12)
    assert region_margin(region.vertices, [1, 0]) == pytest.approx(0.0, abs=1e-12)


def test_bad_input():
    with pytest.raises(InputError):
        ContactSet(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(InputError):
        ContactSet(np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(InputError):
        flat_contacts([[0, 0]], mu=-1)
    with pytest.raises(InputError):
        static_equilibrium_region(step(), tolerance=-1)
    with pytest.raises(InputError):
        region_margin([[0, 0], [1, 0], [0, 1]], [1, 2, 3])
