"""The separating-axis box test of the C++ core (``snakehead._core.box_pair_gaps``, behind
``collision.box_box_sat`` and ``collision.self_clearance``) against the numpy reference in tests/sat_reference.py
and against plain corner projections: random pairs (apart, overlapping, touching, parallel and nearly parallel
edges, flat and point boxes), robot trajectories (the default robot and a generated snake), closed forms, bad
input and concurrent calls."""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import sat_reference as ref
from conftest import pitch_first
from snakehead import BasePlacement, SnakeRobot, _core
from snakehead.geometry import collision as coll

TOL = 1e-12  # m: C++ against the numpy reference (the same formulas; only rounding differs)


def random_boxes(rng, n, scale=0.25):
    c = rng.normal(scale=scale, size=(n, 3))
    R = Rotation.random(n, random_state=rng).as_matrix()
    h = rng.uniform(0.02, 0.2, (n, 3))
    return c, R, h


def about_z(angles):
    return Rotation.from_rotvec(np.outer(angles, [0.0, 0.0, 1.0])).as_matrix()


def check_against_reference(ca, Ra, ha, cb, Rb, hb):
    got = coll.box_box_sat(ca, Ra, ha, cb, Rb, hb)
    np.testing.assert_allclose(got, ref.box_box_sat(ca, Ra, ha, cb, Rb, hb), rtol=0, atol=TOL)
    return got


def test_random_pairs_apart_and_overlapping():
    rng = np.random.default_rng(0)
    ca, Ra, ha = random_boxes(rng, 20000)
    cb, Rb, hb = random_boxes(rng, 20000)
    got = check_against_reference(ca, Ra, ha, cb, Rb, hb)
    assert (got > 0).sum() > 2000 and (got <= 0).sum() > 2000  # both cases exercised
    # every pair is also right by plain corner projection
    for k in range(0, 20000, 200):
        assert got[k] == pytest.approx(ref.box_box_sat_by_projection(ca[k], Ra[k], ha[k], cb[k], Rb[k], hb[k]),
                                       abs=TOL)


def test_touching_pairs():
    """B stands on A's face z = +h_a with any turn about that normal and any offset in the face: gap 0."""
    rng = np.random.default_rng(1)
    n = 2000
    ca, Ra, ha = random_boxes(rng, n)
    hb = rng.uniform(0.02, 0.2, (n, 3))
    Rb = Ra @ about_z(rng.uniform(-np.pi, np.pi, n))
    offset = rng.uniform(-1, 1, (n, 2)) * ha[:, :2]  # B's centre above a point of A's face
    local = np.c_[offset, ha[:, 2] + hb[:, 2]]
    cb = ca + np.einsum("nij,nj->ni", Ra, local)
    got = check_against_reference(ca, Ra, ha, cb, Rb, hb)
    np.testing.assert_allclose(got, 0.0, atol=1e-12)


def test_parallel_and_nearly_parallel_edges():
    """Same orientation, a turn about one shared axis, quarter turns (edges exactly parallel), and rotations
    composed so that they are parallel up to rounding: these axes are skipped, the face normals decide, and
    boxes that overlap report their real depth (not a near-zero gap from dividing rounding noise)."""
    rng = np.random.default_rng(2)
    n = 5000
    ca, Ra, ha = random_boxes(rng, n, scale=0.05)  # close together: mostly overlapping
    _, _, hb = random_boxes(rng, n)
    cb = ca + rng.normal(scale=0.15, size=(n, 3))
    a = rng.uniform(-np.pi, np.pi, n)
    quarter = Rotation.from_euler("xyz", rng.integers(0, 4, (n, 3)) * 90, degrees=True).as_matrix()
    for Rb in (Ra, Ra @ about_z(a), Ra @ quarter, Ra @ about_z(a) @ about_z(-a)):
        got = check_against_reference(ca, Ra, ha, cb, Rb, hb)
        assert np.isfinite(got).all()
        assert (got > 0).sum() > 200 and (got <= 0).sum() > 200
        for k in range(0, n, 100):
            assert got[k] == pytest.approx(ref.box_box_sat_by_projection(ca[k], Ra[k], ha[k], cb[k], Rb[k], hb[k]),
                                           abs=TOL)
    # equal concentric boxes (orientations equal up to rounding): the shallowest way out is their thinnest side
    got = coll.box_box_sat(ca, Ra, ha, ca, Ra @ about_z(a) @ about_z(-a), ha)
    np.testing.assert_allclose(got, -2 * ha.min(axis=1), atol=1e-12)


def test_flat_and_point_boxes():
    """Zero half extents: plates, sticks and points, against each other and full boxes."""
    rng = np.random.default_rng(3)
    n = 5000
    ca, Ra, ha = random_boxes(rng, n)
    cb, Rb, hb = random_boxes(rng, n)
    ha[rng.uniform(size=(n, 3)) < 0.4] = 0.0
    hb[rng.uniform(size=(n, 3)) < 0.4] = 0.0
    got = check_against_reference(ca, Ra, ha, cb, Rb, hb)
    assert np.isfinite(got).all()
    for k in range(0, n, 100):
        assert got[k] == pytest.approx(ref.box_box_sat_by_projection(ca[k], Ra[k], ha[k], cb[k], Rb[k], hb[k]),
                                       abs=TOL)
    # a point 0.3 m above a unit cube's top face
    assert coll.box_box_sat([0, 0, 0.8], np.eye(3), np.zeros(3), np.zeros(3), np.eye(3), np.full(3, 0.5)) == \
        pytest.approx(0.3, abs=1e-15)


def test_closed_form_axis_aligned_gap_and_overlap():
    # boxes 0.2 x 0.1 x 0.06 and 0.1 x 0.3 x 0.04 m, side by side along y, 0.037 m apart
    I = np.eye(3)
    ha, hb = np.array([0.1, 0.05, 0.03]), np.array([0.05, 0.15, 0.02])
    ca = np.array([0.3, -0.2, 0.1])
    for dx, gap in [(0.0, 0.037), (0.12, 0.037), (0.0, -0.011)]:
        cb = ca + [dx, 0.05 + 0.15 + gap, 0.01]
        assert coll.box_box_sat(ca, I, ha, cb, I, hb) == pytest.approx(gap, abs=1e-15)
        assert coll.box_box_sat(cb, I, hb, ca, I, ha) == pytest.approx(gap, abs=1e-15)


def test_broadcasting_like_numpy():
    rng = np.random.default_rng(4)
    c, R, h = random_boxes(rng, 12)
    c, R = c.reshape(3, 4, 3), R.reshape(3, 4, 3, 3)
    h = h.reshape(3, 4, 3)
    other = ([0.1, 0.0, 0.0], np.eye(3), [0.05, 0.05, 0.05])
    got = coll.box_box_sat(c, R, h, *other)
    assert got.shape == (3, 4)
    np.testing.assert_allclose(got, ref.box_box_sat(c, R, h, *other), atol=TOL)
    # one half-extent row for all; a single pair gives a 0-d result
    got = coll.box_box_sat(c, R, h[0, 0], *other)
    np.testing.assert_allclose(got, ref.box_box_sat(c, R, h[0, 0], *other), atol=TOL)
    single = coll.box_box_sat(c[0, 0], R[0, 0], h[0, 0], *other)
    assert np.shape(single) == () and single == pytest.approx(got[0, 0], abs=0)
    assert coll.box_box_sat(c[:0], R[:0], h[:0], *other).shape == (0, 4)


def test_box_box_distance_and_collision_check_still_use_it():
    """box_box_distance returns the SAT gap (minus the depth) for overlapping boxes."""
    I = np.eye(3)
    h = np.full(3, 0.5)
    assert coll.box_box_distance([0, 0, 0], I, h, [0.9, 0.2, 0], I, h) == pytest.approx(-0.1, abs=1e-15)


@pytest.fixture(scope="module", params=["default", "pitch_first"])
def robot(request):
    return SnakeRobot.default() if request.param == "default" else pitch_first()


def test_self_clearance_on_random_configurations(robot):
    rng = np.random.default_rng(5)
    qs = np.array([robot.body.random_configuration(rng) for _ in range(400)])
    base = BasePlacement(x=0.3, y=-0.2, yaw=0.7)
    for b in (None, base):
        got = coll.self_clearance(robot, qs, b)
        np.testing.assert_allclose(got, ref.self_clearance(robot, qs, b), rtol=0, atol=TOL)
        assert (got > 0).sum() > 300 and (got <= 0).sum() >= 3  # free and (a few) self-colliding configurations
    # placing the base elsewhere moves every box alike
    np.testing.assert_allclose(coll.self_clearance(robot, qs, base), coll.self_clearance(robot, qs), atol=1e-12)


def test_self_clearance_along_a_smooth_trajectory(robot):
    """A joint-space sweep from straight to a tight curl: links turn through parallel, touching and overlapping."""
    s = np.linspace(0.0, 1.0, 301)[:, None]
    q_end = np.where(np.arange(robot.n_joints) % 2 == 0, 1.2, 0.3)
    qs = s * q_end
    got = coll.self_clearance(robot, qs)
    np.testing.assert_allclose(got, ref.self_clearance(robot, qs), rtol=0, atol=TOL)
    assert got[0] > 0 and got.min() < 0  # starts straight and clear, curls into itself
    # one configuration alone gives its row
    assert coll.self_clearance(robot, qs[150]) == pytest.approx(got[150:151], abs=0)


def test_min_gaps_equal_the_smallest_of_all_gaps():
    """box_pair_min_gaps (used by self_clearance) stops testing pairs that cannot be the closest: the same
    numbers, bit for bit, as the minimum over box_pair_gaps; +inf without pairs."""
    rng = np.random.default_rng(7)
    T, k = 300, 15
    c = rng.normal(scale=0.3, size=(T, k, 3))
    R = Rotation.random(T * k, random_state=rng).as_matrix().reshape(T, k, 3, 3)
    h = rng.uniform(0.0, 0.1, (k, 3))
    pairs = np.stack(np.triu_indices(k, 1), axis=1)[rng.permutation(k * (k - 1) // 2)]
    all_gaps = _core.box_pair_gaps(c, R, h, pairs)
    np.testing.assert_array_equal(_core.box_pair_min_gaps(c, R, h, pairs), all_gaps.min(axis=1))
    assert (all_gaps.min(axis=1) > 0).sum() > 10 and (all_gaps.min(axis=1) <= 0).sum() > 10
    np.testing.assert_array_equal(_core.box_pair_min_gaps(c, R, h, pairs[:0]), np.full(T, np.inf))


def test_box_pair_gaps_bad_input():
    c = np.zeros((2, 3, 3))
    R = np.broadcast_to(np.eye(3), (2, 3, 3, 3))
    h = np.full((3, 3), 0.1)
    pairs = np.array([[0, 2], [1, 2]])
    assert _core.box_pair_gaps(c, R, h, pairs).shape == (2, 2)
    with pytest.raises(ValueError, match=r"centres must have shape \(T, k, 3\)"):
        _core.box_pair_gaps(c[..., :2], R, h, pairs)
    with pytest.raises(ValueError, match="rotations must have shape"):
        _core.box_pair_gaps(c, R[:1], h, pairs)
    with pytest.raises(ValueError, match="half_extents must have shape"):
        _core.box_pair_gaps(c, R, h[:2], pairs)
    with pytest.raises(ValueError, match=r"pairs must have shape \(P, 2\)"):
        _core.box_pair_gaps(c, R, h, pairs.ravel())
    with pytest.raises(ValueError, match="names box 3; there are 3 boxes"):
        _core.box_pair_gaps(c, R, h, np.array([[0, 3]]))
    with pytest.raises(ValueError, match="names box -1"):
        _core.box_pair_gaps(c, R, h, np.array([[-1, 0]]))
    with pytest.raises(ValueError, match="half extents must be finite and >= 0"):
        _core.box_pair_gaps(c, R, -h, pairs)
    with pytest.raises(ValueError, match="centres must be finite"):
        _core.box_pair_gaps(np.full_like(c, np.nan), R, h, pairs)
    with pytest.raises(ValueError, match="rotations must be finite"):
        _core.box_pair_gaps(c, np.full_like(R, np.inf), h, pairs)
    with pytest.raises(TypeError):  # a fractional index is not silently truncated
        _core.box_pair_gaps(c, R, h, pairs + 0.5)
    # the per-sample minimum checks alike
    with pytest.raises(ValueError, match="rotations must have shape"):
        _core.box_pair_min_gaps(c, R[:1], h, pairs)
    with pytest.raises(ValueError, match="names box 3"):
        _core.box_pair_min_gaps(c, R, h, np.array([[0, 3]]))
    with pytest.raises(ValueError, match="centres must be finite"):
        _core.box_pair_min_gaps(np.full_like(c, np.nan), R, h, pairs)


def test_box_box_sat_bad_input():
    I = np.eye(3)
    with pytest.raises(ValueError, match="rotation has shape"):
        coll.box_box_sat(np.zeros(3), np.eye(2), np.ones(3), np.zeros(3), I, np.ones(3))
    with pytest.raises(ValueError):  # shapes that do not broadcast
        coll.box_box_sat(np.zeros((2, 3)), I, np.ones(3), np.zeros((3, 3)), I, np.ones(3))
    with pytest.raises(ValueError, match="finite"):
        coll.box_box_sat([np.nan, 0, 0], I, np.ones(3), np.zeros(3), I, np.ones(3))
    with pytest.raises(ValueError, match=">= 0"):
        coll.box_box_sat(np.zeros(3), I, -np.ones(3), np.zeros(3), I, np.ones(3))


def test_concurrent_calls_agree():
    """The batch releases the GIL; calls from several threads give the same gaps as one call."""
    rng = np.random.default_rng(6)
    T, k = 200, 12
    c = rng.normal(scale=0.2, size=(T, k, 3))
    R = Rotation.random(T * k, random_state=rng).as_matrix().reshape(T, k, 3, 3)
    h = rng.uniform(0.01, 0.1, (k, 3))
    pairs = np.stack(np.triu_indices(k, 2), axis=1)
    expected = _core.box_pair_gaps(c, R, h, pairs)
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: _core.box_pair_gaps(c, R, h, pairs), range(16)))
    for r in results:
        np.testing.assert_array_equal(r, expected)
