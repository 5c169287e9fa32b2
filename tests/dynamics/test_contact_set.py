"""Contact sets, linearised friction cones and the contact wrench cone: the face form (cddlib) against the span
form by LP feasibility on random wrenches, and the cone's edges against the Coulomb cone."""
import numpy as np
import pytest
from contact_reference import forces_exist

from snakehead._errors import InputError
from snakehead.dynamics.contact_set import (
    FRICTION_CONE_EDGES,
    ContactSet,
    contact_wrench_cone,
    contact_wrench_span,
    flat_contacts,
    friction_cone_generators,
    wrench_about,
)
from snakehead.model.physics import GROUND_FRICTION


def uneven(seed, k):
    rng = np.random.default_rng(seed)
    p = rng.uniform(-0.5, 0.5, (k, 3)) * [1, 1, 0.3]
    n = np.column_stack([rng.normal(0, 0.6, (k, 2)), np.ones(k)])
    return ContactSet(p, n, rng.uniform(0.3, 1.2))


def test_defaults_and_cone_edges():
    c = uneven(0, 5)
    assert flat_contacts([[0, 0]]).mu == GROUND_FRICTION and c.edges == FRICTION_CONE_EDGES
    np.testing.assert_allclose(np.linalg.norm(c.normals, axis=1), 1.0)
    u = friction_cone_generators(c)
    assert u.shape == (5, FRICTION_CONE_EDGES, 3)
    n_part = np.einsum("kej,kj->ke", u, c.normals)
    t_part = np.linalg.norm(u - n_part[..., None] * c.normals[:, None, :], axis=2)
    np.testing.assert_allclose(t_part, c.mu * n_part, rtol=1e-12)  # on the Coulomb cone's surface
    with pytest.raises(ValueError):
        c.points[0, 0] = 1.0  # read-only


def sample_wrenches(S, rng, n):
    """Half inside (nonnegative combinations of a few edges), half anywhere: then perturbed."""
    out = []
    for i in range(n):
        lam = rng.exponential(1.0, S.shape[1]) * (rng.random(S.shape[1]) < 0.1)
        w = S @ lam if i % 2 == 0 else rng.normal(0.0, 1.0, 6)
        out.append(w + rng.normal(0.0, 0.05, 6))
    return np.array(out)


@pytest.mark.parametrize("k", [1, 3, 10, 20])
def test_face_form_matches_span_form(k):
    contacts = uneven(k, k)
    A = contact_wrench_cone(contacts)
    S = contact_wrench_span(contacts)
    np.testing.assert_allclose(np.linalg.norm(A, axis=1), 1.0)
    assert np.max(A @ S, initial=0.0) <= 1e-9  # every edge of every cone is in the face form's cone
    rng = np.random.default_rng(k)
    agree = 0
    for w in sample_wrenches(S, rng, 60):
        slack = np.max(A @ w) if len(A) else -np.inf  # no face: the cone is all of R^6
        if abs(slack) < 1e-7:
            continue
        assert forces_exist(contacts, w[:3], w[3:]) == (slack < 0), w
        agree += 1
    assert agree > 50


def test_an_inconsistent_floating_point_run_is_redone_in_exact_arithmetic(monkeypatch):
    """When cddlib's floating-point run reports a numerical inconsistency (seen on ~40 contacts of a body lying on a
    slope in MuJoCo), the cone is found in exact rationals (GMP): the same cone as the floating-point run where that
    one succeeds (its faces hold every edge of the span, and the two face forms give one verdict on wrenches not on
    the boundary; the exact run keeps nearly parallel faces the floating-point one merges)."""
    import cdd

    contacts = uneven(4, 4)
    A_float = contact_wrench_cone(contacts)
    calls = []

    def inconsistent(*args, **kwargs):
        calls.append(1)
        raise RuntimeError("*Error: Numerical inconsistency is found.  Use the GMP exact arithmetic.")

    monkeypatch.setattr(cdd, "polyhedron_from_matrix", inconsistent)
    A_exact = contact_wrench_cone(contacts)
    assert calls
    S = contact_wrench_span(contacts)
    np.testing.assert_allclose(np.linalg.norm(A_exact, axis=1), 1.0)
    assert np.max(A_exact @ S) <= 1e-9
    agree = 0
    for w in sample_wrenches(S, np.random.default_rng(9), 60):
        a, b = np.max(A_exact @ w), np.max(A_float @ w)
        if min(abs(a), abs(b)) < 1e-7:
            continue
        assert (a < 0) == (b < 0), w
        agree += 1
    assert agree > 50


def test_lower_dimensional_cone_keeps_its_equalities():
    """Collinear contacts on flat ground: the CWC has no moment about their line; its face form says so with pairs
    of opposite rows (pypoman's face matrix drops them)."""
    contacts = flat_contacts([[0, 0], [1, 0], [2, 0]], mu=0.5)
    A = contact_wrench_cone(contacts)
    w = np.array([0.0, 0.0, 1.0, 0.1, -1.0, 0.0])  # tau_x = 0.1: a moment about the x-axis the line cannot give
    assert np.max(A @ w) > 1e-3 and not forces_exist(contacts, w[:3], w[3:])
    ok = np.array([0.0, 0.0, 1.0, 0.0, -1.0, 0.0])  # the weight over x = 1
    assert np.max(A @ ok) <= 1e-12 and forces_exist(contacts, ok[:3], ok[3:])


def test_moments_about_another_point():
    contacts = uneven(4, 6)
    point = np.array([0.3, -0.2, 0.5])
    A0, A1 = contact_wrench_cone(contacts), contact_wrench_cone(contacts, point)
    rng = np.random.default_rng(2)
    for w in sample_wrenches(contact_wrench_span(contacts), rng, 30):
        w1 = wrench_about(w, np.zeros(3), point)
        if min(abs(np.max(A0 @ w)), abs(np.max(A1 @ w1))) > 1e-7:
            assert (np.max(A0 @ w) < 0) == (np.max(A1 @ w1) < 0)


def test_bad_input():
    with pytest.raises(InputError):
        ContactSet(np.zeros((0, 3)), np.zeros((0, 3)))
    with pytest.raises(InputError):
        ContactSet(np.zeros((1, 3)), [[0, 0, 1]], edges=2)
    with pytest.raises(InputError):
        wrench_about(np.zeros(5), np.zeros(3), np.zeros(3))
