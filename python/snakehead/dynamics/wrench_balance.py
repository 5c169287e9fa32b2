"""Dynamic balance on contacts at many heights: is the gravito-inertial wrench inside the contact wrench cone?

The Newton-Euler equations of the whole body (Eqs. 32-34 with gravity, Eq. 38) say that the contacts must exert the
wrench w_c = -w_gi, where the gravito-inertial wrench about the world origin is

    w_gi = (m g - dP/dt, c x m g - dL/dt),   g = (0, 0, -GRAVITY),

P and L the linear and angular momenta (L about the world origin, Eqs. 25-31), c the CoM. With dP/dt = m c'' and
dL/dt = c x m c'' + dL_G/dt (L_G about the CoM) this is (m (g - c''), c x m (g - c'') - dL_G/dt). The motion is
feasible on the contacts (they can push, not pull, within their friction cones) iff w_c is in the contact wrench
cone (CWC) of :func:`~.contact_set.contact_wrench_cone`: A w_c <= 0.

* :func:`gravito_inertial_wrench` -- w_gi from the mass, CoM, CoM acceleration and the rate of angular momentum
  about the CoM.
* :func:`gravito_inertial_wrenches` -- w_gi along a robot's trajectory, from the momenta of
  :func:`~snakehead.dynamics.stability.momenta` (the ZMP's, Eqs. 33-34).
* :func:`cwc_margin` -- the face form's slack: positive inside the cone.
* :func:`is_balanced_lp` -- the same verdict from the span form by one feasibility LP (no face enumeration).
* :func:`zmp_on_plane` -- the ZMP of the contact wrench on a horizontal virtual plane z = h (Eqs. 39-40 with
  p_z = h); on flat ground and h = 0 it is :func:`~snakehead.dynamics.stability.zmp`.
* :func:`zmp_support_area` -- where that ZMP may lie for a given CoM (Caron, Pham and Nakamura, "ZMP support areas
  for multi-contact mobility under frictional constraints", IEEE T-RO 2017), with no rate of angular momentum about
  the CoM: on flat ground with high friction, the support polygon.

On flat ground with high friction the CWC test and the ZMP-in-support-polygon test of Section 3.1 agree: the cone's
horizontal-moment faces are those of the ZMP in the polygon, and friction bounds no wrench a slow motion asks for.
"""
from __future__ import annotations

import cdd  # pycddlib: the ZMP support area's vertices from its half-planes
import numpy as np
import numpy.typing as npt
from scipy.optimize import linprog

from .._errors import Infeasible, InputError
from .._validate import finite_array
from ..model.physics import GRAVITY  # g in Eq. 38 is (0, 0, -GRAVITY)
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .contact_set import ContactSet, contact_wrench_span, wrenches
from .equilibrium_region import REGION_RADIUS, convex_ccw
from .stability import center_of_mass, joint_velocities, momenta

__all__ = ["gravito_inertial_wrench", "gravito_inertial_wrenches", "cwc_margin", "is_balanced_lp", "zmp_on_plane",
           "zmp_support_area"]


def _gravity(mass: float) -> np.ndarray:
    """The weight m g (3,) N, g = (0, 0, -GRAVITY)."""
    return np.array([0.0, 0.0, -float(mass) * GRAVITY])


def gravito_inertial_wrench(mass: float, com: npt.ArrayLike, com_acceleration: npt.ArrayLike,
                            angular_momentum_rate: npt.ArrayLike) -> np.ndarray:
    """The gravito-inertial wrench about the world origin, (6,) or (T, 6): (m (g - c''), c x m (g - c'') - dL_G/dt).

    mass (kg); com c (3,) or (T, 3) m; com_acceleration c'' (m/s^2) and angular_momentum_rate dL_G/dt (N m: the rate
    of the angular momentum about the CoM), shaped as com. At rest it is the weight (0, 0, -m g) acting at c. The
    contacts must exert its opposite.
    """
    mass = float(finite_array(mass, "mass", ()))
    if mass <= 0.0:
        raise InputError(f"mass must be > 0, got {mass}")
    c = finite_array(com, "com")
    if c.shape[-1:] != (3,) or c.ndim > 2:
        raise InputError(f"com has shape {c.shape}; expected (3,) or (T, 3)")
    acc = finite_array(com_acceleration, "com_acceleration", c.shape)
    ldot = finite_array(angular_momentum_rate, "angular_momentum_rate", c.shape)
    f = _gravity(mass) - mass * acc
    return np.concatenate([f, np.cross(c, f) - ldot], axis=-1)


def gravito_inertial_wrenches(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike,
                              base: BasePlacement | None = None, qd: npt.ArrayLike | None = None) -> np.ndarray:
    """The gravito-inertial wrench about the world origin along a trajectory: t (T,) s, q (T, n) rad -> (T, 6).

    w_gi = (M g - dP/dt, c x M g - dL/dt) from the momenta P, L (about the world origin) of
    :func:`~snakehead.dynamics.stability.momenta` and the CoM of
    :func:`~snakehead.dynamics.stability.center_of_mass`, with dP/dt and dL/dt taken along the samples as
    :func:`~snakehead.dynamics.stability.zmp` takes them (np.gradient), so that the ZMP of its opposite on the plane
    z = 0 is the ZMP of Eqs. 39-40. ``qd``: the joint velocities when known (see :func:`~.stability.momenta`).
    """
    robot = as_robot(robot)
    base = as_base(base)
    P, L = momenta(robot, np.asarray(t, float), np.asarray(q, float), base, qd)
    t = np.asarray(t, float)
    Pdot = joint_velocities(t, P)  # the same np.gradient as the ZMP's dP/dt (Eq. 33)
    Ldot = joint_velocities(t, L)  # and dL/dt (Eq. 34)
    c = center_of_mass(robot, np.asarray(q, float), base)
    weight = _gravity(robot.total_mass)
    return np.concatenate([weight - Pdot, np.cross(c, weight) - Ldot], axis=1)


def cwc_margin(A: npt.ArrayLike, gravito_inertial: npt.ArrayLike) -> np.ndarray | float:
    """Margin of balance: min over the faces of -a_i . w_c with w_c = -w_gi the wrench the contacts must exert and
    A (m, 6) the unit-row face form of :func:`~.contact_set.contact_wrench_cone` (about the same point as w_gi).

    Positive inside the cone (balanced), negative outside, 0 on its boundary; inside it is the Euclidean distance of
    w_c to the cone's boundary in wrench space (N and N m mixed: moments about the world origin, so a unit of both
    counts alike). A cone of lower dimension has no inside: the margin is <= 0 everywhere. w_gi (6,) -> float,
    (T, 6) -> (T,).
    """
    A = finite_array(A, "A", (None, 6))
    w = wrenches(gravito_inertial, "gravito_inertial")
    m = np.min(w @ A.T, axis=-1, initial=np.inf)  # no face (the cone is all of R^6): +inf  # -a . w_c = a . w_gi
    return float(m) if np.ndim(m) == 0 else np.asarray(m)


def is_balanced_lp(contacts: ContactSet, gravito_inertial: npt.ArrayLike,
                   point: npt.ArrayLike = (0.0, 0.0, 0.0)) -> bool:
    """Whether contact forces in the linearised friction cones exert -w_gi (w_gi (6,) about ``point``, m): one
    feasibility LP on the span form (:func:`~.contact_set.contact_wrench_span`), S lambda = -w_gi, lambda >= 0. The
    verdict of :func:`cwc_margin` > 0 without enumerating the cone's faces."""
    w = wrenches(gravito_inertial, "gravito_inertial")
    if w.shape != (6,):
        raise InputError(f"gravito_inertial has shape {w.shape}; expected (6,)")
    S = contact_wrench_span(contacts, point)
    res = linprog(np.zeros(S.shape[1]), A_eq=S, b_eq=-w, bounds=(0.0, None), method="highs")
    return bool(res.status == 0)


def zmp_on_plane(gravito_inertial: npt.ArrayLike, height: float = 0.0) -> np.ndarray:
    """The ZMP (m) on the horizontal virtual plane z = ``height``: the point of the plane about which the contact
    wrench w_c = -w_gi (about the world origin) has no horizontal moment, (6,) -> (2,) or (T, 6) -> (T, 2).

    p_x = (h f_x - tau_y) / f_z, p_y = (h f_y + tau_x) / f_z with (f, tau) = w_c: Eqs. 39-40 with p_z = h. NaN where
    f_z <= 0 (the contacts would have to pull: no ZMP), as :func:`~snakehead.dynamics.stability.zmp`.
    """
    w = -wrenches(gravito_inertial, "gravito_inertial")
    h = float(finite_array(height, "height", ()))
    fz = np.where(w[..., 2] > 0.0, w[..., 2], np.nan)
    px = (h * w[..., 0] - w[..., 4]) / fz
    py = (h * w[..., 1] + w[..., 3]) / fz
    return np.stack([px, py], axis=-1)


def zmp_support_area(A: npt.ArrayLike, com: npt.ArrayLike, height: float = 0.0,
                     radius: float = REGION_RADIUS) -> np.ndarray:
    """The ZMP support area on the plane z = ``height`` (m) for the CoM at ``com`` (3,) m: the ZMPs p at which the
    contacts with the face form A (m, 6) (:func:`~.contact_set.contact_wrench_cone`, moments about the world origin)
    can exert the wrench of a motion with dL_G/dt = 0 (Caron, Pham and Nakamura 2017): (k, 2) counter-clockwise.

    With dL_G/dt = 0 the contact force passes through the CoM and, by the ZMP's definition, through p: it is
    a (c - p) with a > 0, its moment about the origin c x a (c - p), so p is in the area iff
    A (c - p, c x (c - p)) <= 0: half-planes in p, linear for a fixed c. Their intersection (cddlib, H to V form)
    is cut to the square of half-width ``radius`` about the CoM (friction may leave it unbounded). Infeasible when
    the area is empty (no such motion balances).
    """
    A = finite_array(A, "A", (None, 6))
    c = finite_array(com, "com", (3,))
    h = float(finite_array(height, "height", ()))
    cx = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])  # c x . as a matrix
    # A_f (c - p) + A_t cx (c - p) <= 0 with p = (x, y, h): M (c - p) <= 0, M = A_f + A_t cx
    M = A[:, :3] + A[:, 3:] @ cx
    # M (c - p) = M (c_x, c_y, c_z - h) - M[:, :2] (x, y) <= 0, i.e. G (x, y) <= b; then the square about c
    box = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    G = np.vstack([-M[:, :2], box])
    b = np.r_[-(M @ np.array([c[0], c[1], c[2] - h])), radius + box @ c[:2]]
    mat = cdd.matrix_from_array(np.column_stack([b, -G]).tolist(), rep_type=cdd.RepType.INEQUALITY)
    gens = np.array(cdd.copy_generators(cdd.polyhedron_from_matrix(mat)).array, float).reshape(-1, 3)
    pts = gens[gens[:, 0] > 0.5, 1:]
    if len(pts) == 0:
        raise Infeasible("the ZMP support area is empty: no ZMP balances a motion with this CoM")
    order = np.argsort(np.arctan2(*(pts - pts.mean(axis=0)).T[::-1]))
    return convex_ccw(pts[order])
