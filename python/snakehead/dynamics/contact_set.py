"""Point contacts at many heights with their own normals, their linearised friction cones and the contact wrench
cone (CWC): the support of a body lying on uneven ground, where the flat support polygon of Eq. 24
(:func:`~snakehead.dynamics.stability.support_polygon`) no longer describes what the ground can push.

* :class:`ContactSet` -- k point contacts: positions (k, 3) m, unit normals (k, 3), Coulomb coefficient mu, and the
  number of edges of each linearised friction cone.
* :func:`friction_cone_generators` -- the edges of each contact's linearised cone (an inscribed pyramid: a force
  inside it is inside the true cone, so every verdict built on it is conservative).
* :func:`contact_wrench_span` -- the CWC in span (V-) form: the wrenches w = (f, tau) the contacts can exert,
  w = S lambda with lambda >= 0, tau about a stated point (the world origin by default).
* :func:`contact_wrench_cone` -- the same cone in face (H-) form, A w <= 0, by cone duality (span to face: the
  double-description method of cddlib, through pycddlib).

A wrench is the force (N) and the moment (N m) about the stated point, stacked: (6,). The contact forces act on the
robot (the ground pushes it).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import cdd  # pycddlib: cddlib's double-description method (span to face form of the CWC)
import cdd.gmp  # its exact rational arithmetic, when the floating-point run is inconsistent
import numpy as np
import numpy.typing as npt

from .._errors import InputError, invariant
from .._validate import finite_array
from ..model.physics import GROUND_FRICTION

__all__ = ["FRICTION_CONE_EDGES", "ContactSet", "flat_contacts", "friction_cone_generators", "contact_wrench_span",
           "contact_wrench_cone", "wrench_about", "wrenches"]

#: Edges of each contact's linearised friction cone (an inscribed regular pyramid). Eight edges keep
#: cos(pi / 8) = 92 % of the true cone's friction in the worst direction; more edges cost LP columns (and CWC facets)
#: in proportion.
FRICTION_CONE_EDGES = 8


@dataclass(frozen=True, eq=False)
class ContactSet:
    """k point contacts of the robot with the ground.

    points (k, 3) m world; normals (k, 3) unit, pointing out of the ground into the robot (normalised here); mu the
    Coulomb friction coefficient (default the ground's, :data:`~snakehead.model.physics.GROUND_FRICTION`); edges the
    number of edges of each linearised friction cone (:data:`FRICTION_CONE_EDGES`). The arrays are read-only copies;
    two sets are equal only when they are the same object (arrays have no single truth value).
    """

    points: np.ndarray
    normals: np.ndarray
    mu: float = GROUND_FRICTION
    edges: int = FRICTION_CONE_EDGES

    def __post_init__(self) -> None:
        points = finite_array(self.points, "points", (None, 3)).copy()
        normals = finite_array(self.normals, "normals", (points.shape[0], 3)).copy()
        if points.shape[0] < 1:
            raise InputError("a contact set needs at least one contact")
        length = np.linalg.norm(normals, axis=1)
        if np.any(length < 1e-9):
            raise InputError("every contact normal must be a nonzero vector")
        normals /= length[:, None]
        mu = float(finite_array(self.mu, "mu", ()))
        if mu < 0.0:
            raise InputError(f"mu must be >= 0, got {mu}")
        if int(self.edges) != self.edges or self.edges < 3:
            raise InputError(f"edges must be an integer >= 3, got {self.edges}")
        points.flags.writeable = False
        normals.flags.writeable = False
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "normals", normals)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "edges", int(self.edges))

    def __len__(self) -> int:
        return int(self.points.shape[0])


def flat_contacts(xy: npt.ArrayLike, mu: float = GROUND_FRICTION, edges: int = FRICTION_CONE_EDGES) -> ContactSet:
    """Contacts on the flat ground z = 0 (normal +z) at the points ``xy`` (k, 2) m: the setting of Eq. 24."""
    xy = finite_array(xy, "xy", (None, 2))
    points = np.column_stack([xy, np.zeros(len(xy))])
    return ContactSet(points, np.tile([0.0, 0.0, 1.0], (len(xy), 1)), mu, edges)


def _tangent_bases(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents t1, t2 (k, 3) per unit normal, with (t1, t2, n) right-handed."""
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(helper, normals)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return t1, np.cross(normals, t1)


def friction_cone_generators(contacts: ContactSet) -> np.ndarray:
    """Edges of the linearised friction cones: (k, edges, 3) unit vectors u_ij = (n_i + mu (cos a_j t1 + sin a_j
    t2)) / norm, a_j = 2 pi j / edges. The pyramid they span is inscribed in the Coulomb cone |f_t| <= mu f_n, so a
    force inside it is a force the contact can exert. With mu = 0 every edge is the normal."""
    t1, t2 = _tangent_bases(contacts.normals)
    a = 2.0 * np.pi * np.arange(contacts.edges) / contacts.edges
    u = (contacts.normals[:, None, :] + contacts.mu * (np.cos(a)[None, :, None] * t1[:, None, :]
                                                        + np.sin(a)[None, :, None] * t2[:, None, :]))
    return np.asarray(u / np.linalg.norm(u, axis=2)[..., None])


def contact_wrench_span(contacts: ContactSet, point: npt.ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The contact wrench cone in span form: S (6, k * edges) whose columns are the wrenches (u_ij, (p_i - point) x
    u_ij) of the cone edges; the wrenches the contacts can exert on the robot are S lambda, lambda >= 0. Moments
    about ``point`` (3,) m, the world origin by default."""
    point = finite_array(point, "point", (3,))
    u = friction_cone_generators(contacts)  # (k, e, 3)
    arm = (contacts.points - point)[:, None, :]
    tau = np.cross(np.broadcast_to(arm, u.shape), u)
    return np.ascontiguousarray(np.concatenate([u, tau], axis=2).reshape(-1, 6).T)


def wrenches(w: npt.ArrayLike, name: str = "wrench") -> np.ndarray:
    """``w`` as a finite float64 array of wrenches, (6,) or (..., 6); InputError otherwise."""
    a = finite_array(w, name)
    if a.ndim < 1 or a.shape[-1] != 6:
        raise InputError(f"{name} has shape {a.shape}; expected (6,) or (..., 6)")
    return a


def wrench_about(wrench: npt.ArrayLike, point: npt.ArrayLike, new_point: npt.ArrayLike) -> np.ndarray:
    """The same wrench (..., 6) (force, moment about ``point``) with its moment taken about ``new_point``:
    tau' = tau + (point - new_point) x f."""
    w = wrenches(wrench)
    shift = finite_array(point, "point", (3,)) - finite_array(new_point, "new_point", (3,))
    out = w.copy()
    out[..., 3:] += np.cross(np.broadcast_to(shift, w[..., :3].shape), w[..., :3])
    return out


def _faces_of_generators(gens: np.ndarray) -> tuple[np.ndarray, set[int]]:
    """cddlib's face form (H (m, 7) rows [b, -A], the linearity rows) of the cone of generator rows ``gens``: in
    floating point, and in exact rationals (GMP; the floats taken exactly) when cddlib finds the floating-point run
    numerically inconsistent (many nearly coplanar contacts, e.g. a body lying on a plane)."""
    try:
        mat = cdd.matrix_from_array(gens.tolist(), rep_type=cdd.RepType.GENERATOR)
        faces = cdd.copy_inequalities(cdd.polyhedron_from_matrix(mat))
        return np.array(faces.array, float).reshape(-1, 7), set(faces.lin_set)
    except RuntimeError:  # "Numerical inconsistency is found. Use the GMP exact arithmetic."
        exact = [[Fraction(x) for x in row] for row in gens.tolist()]
        mat_q = cdd.gmp.matrix_from_array(exact, rep_type=cdd.RepType.GENERATOR)
        faces_q = cdd.gmp.copy_inequalities(cdd.gmp.polyhedron_from_matrix(mat_q))
        return (np.array([[float(x) for x in row] for row in faces_q.array], float).reshape(-1, 7),
                set(faces_q.lin_set))


def contact_wrench_cone(contacts: ContactSet, point: npt.ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The contact wrench cone in face form: A (m, 6) with a wrench w = (f, tau about ``point``) inside the cone iff
    A w <= 0; each row has unit norm.

    Cone duality, span to face (Weyl-Minkowski): the rows of A are the extreme rays of the polar cone, found from the
    span :func:`contact_wrench_span` by cddlib's double-description method (pycddlib, floating point). A cone of
    lower dimension (collinear contacts on flat ground, or mu = 0) has linearities: each equality a w = 0 comes out as
    two rows a w <= 0 and -a w <= 0. The number of faces grows fast with the contacts (see bench/RESULTS.md,
    "Contact wrench cone"): for a test of one wrench the span form and an LP cost less from some tens of contacts.
    """
    span = contact_wrench_span(contacts, point)
    scale = np.max(np.linalg.norm(span, axis=0))
    gens = np.hstack([np.zeros((span.shape[1], 1)), span.T / scale])  # rays: first column 0
    gens = np.vstack([gens, np.r_[1.0, np.zeros(6)]])  # the apex, the origin
    H, lin = _faces_of_generators(gens)  # rows [b, -A]: b - A x >= 0, b = 0 for a cone
    rows = []
    for i, h in enumerate(H):
        a = -h[1:]
        norm = float(np.linalg.norm(a))
        if norm < 1e-12:
            continue  # the trivial row 1 >= 0 of the apex
        invariant(abs(h[0]) <= 1e-9 * max(1.0, norm), "a face of a cone passes through its apex")
        rows.append(a / norm)
        if i in lin:
            rows.append(-a / norm)
    return np.array(rows, float).reshape(-1, 6)
