"""Stability of the snake's whole-body motion: paper Section 3.1, Eqs. 23-40.

Everything is in the world frame (z up, ground at z = 0). Where the base lies is a parameter
``base`` (a :class:`~snakehead.model.robot.BasePlacement`, default ``BasePlacement()``: tail at the origin,
body along +x).

* :func:`center_of_mass` -- Eq. 23, for one configuration (n,) or a trajectory (T, n).
* :func:`support_polygon` -- Eq. 24, convex hull of the base's ground contacts; :func:`support_polygons` the same
  for every configuration of a trajectory at once.
* :func:`static_margin`, :func:`is_statically_stable` -- signed distance of the CoM's ground
  projection to the polygon's edge (positive inside).
* :func:`momenta_from_velocities`, :func:`momenta` -- Eqs. 25-31, linear and angular momentum about the
  world origin along a trajectory.
* :func:`zmp`, :func:`dynamic_stability` -- Eqs. 36-40 with p_z = 0 and the ZMP's margin in the polygon.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Literal

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import Infeasible, InputError
from .._validate import finite_array, joint_vector
from ..collision.path_proof import checker
from ..ground_contact import GROUND_TOLERANCE
from ..model.physics import GRAVITY  # g in Eq. 38 is (0, 0, -GRAVITY)
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot

__all__ = ["CONTACT_MODELS", "SAMPLE_CHUNK", "polygon_margin_many", "center_of_mass",
           "hull_indices", "support_polygon", "static_margin", "static_margins_of_frames", "is_statically_stable",
           "joint_velocities", "momenta_from_velocities", "momenta", "zmp", "DynamicStability", "dynamic_stability",
           "CORE_CONTACT_MODELS", "KeptSamples", "dynamic_stability_with_clearance", "dynamic_stability_in_core",
           "dynamic_stability_in_python", "support_margins", "support_polygons", "contact_configurations"]


#: Contact models of :func:`support_polygon`.
CONTACT_MODELS = ("endpoints", "footprint", "ground")

#: Samples of a trajectory whose world frames :func:`dynamic_stability` holds at once (~10 MB on the default robot's
#: 20 frames): the memory of a check grows with the trajectory's samples by what it returns only.
SAMPLE_CHUNK = 4096


# ------------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------------


def _joint_matrix(robot: SnakeRobot, q: npt.ArrayLike, name: str = "q") -> tuple[np.ndarray, bool]:
    """q as (T, n) and whether it was a single vector (n,)."""
    a = finite_array(q, name)
    n = robot.n_joints
    if a.ndim == 1:
        if a.shape != (n,):
            raise InputError(f"{name} has shape {a.shape}; expected ({n},) or (T, {n})")
        return a[None, :], True
    if a.ndim != 2 or a.shape[1] != n:
        raise InputError(f"{name} has shape {a.shape}; expected ({n},) or (T, {n})")
    if a.shape[0] < 1:
        raise InputError(f"{name} has no samples")
    return a, False


def _contact_points_many(robot: SnakeRobot, frames: np.ndarray, contact: str,
                         tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Ground contact points of the base part along a trajectory.

    Returns points (T, N, 2) (world x, y) and active (T, N) bool: which points touch the ground.
    """
    if contact not in CONTACT_MODELS:
        raise InputError(f"contact must be one of {CONTACT_MODELS}, got {contact!r}")
    # the base part's links (the robot's own: those before base_end), or with "ground" every link
    # (every shaped link is ascending and unique: with "ground", they are the links)
    links = robot.shaped_base_links if contact != "ground" else robot.shaped_links
    if links.size == 0:
        raise InputError("the base part has no links with collision shapes; no support polygon")
    if contact == "endpoints":
        # Eq. 24: p_i are the endpoints of the base links, i.e. the origins of consecutive frames (each
        # link's frame is at its proximal joint; the next frame in chain order is at its distal end). A point
        # touches the ground when a link it ends lies on the ground.
        on_ground = robot.lowest_z(frames, links) <= tolerance  # (T, k)
        idx = np.unique(np.r_[links, links + 1])
        pts = frames[:, idx][..., :2, 3]  # (T, N, 2)
        active = np.zeros((frames.shape[0], len(idx)), bool)
        active[:, np.searchsorted(idx, links)] |= on_ground
        active[:, np.searchsorted(idx, links + 1)] |= on_ground
        return pts, active
    if contact == "ground":  # only the links that touch in some sample can give a contact point
        keep: np.ndarray = np.asarray((robot.lowest_z(frames, links) <= tolerance).any(axis=0))
        keep[0] |= not keep.any()  # (one link, none of its points active: no polygon, but the shapes stay)
        links = links[keep]
    # footprint / ground: each shape's lowest candidate points (box corners, cylinder rims, sphere bottoms, hull
    # vertices; the C++ core picks them by height). A point supports only where it touches: a link tilted up off
    # the ground (a neck link rising from it) rests on its lowest edge, not on the points it holds in the air
    # (counting those would move the polygon's edge out by the link's length and make it jump as the link lifts)
    pts, _ = robot.lowest_points(frames, links)
    return np.ascontiguousarray(pts[..., :2]), pts[..., 2] <= tolerance


def polygon_margin_many(points: npt.ArrayLike, active: npt.ArrayLike, xy: npt.ArrayLike) -> np.ndarray:
    """Signed distance (m) of ``xy`` to the convex hull of the active ``points``, positive inside.

    points (T, N, 2), active (T, N) bool, xy (T, 2) -> (T,). Inside a convex polygon the distance to its
    boundary is the smallest distance to its edges; outside, the distance to the polygon is also the smallest
    distance to its edges (as segments). A degenerate hull (collinear points) has no interior: the margin is
    minus the distance to it (0 on it). Samples with no active point get -inf. One hull per sample (the C++
    core's monotone chain), without the GIL.
    """
    points = finite_array(points, "points", (None, None, 2))
    active = np.asarray(active, bool)
    xy = finite_array(xy, "xy", (points.shape[0], 2))
    if active.shape != points.shape[:2]:
        raise InputError(f"active has shape {active.shape}; expected {points.shape[:2]}")
    return _core.hull_margins(np.ascontiguousarray(points), np.ascontiguousarray(active), np.ascontiguousarray(xy))


# ------------------------------------------------------------------------------------------------
# Eq. 23: centre of mass
# ------------------------------------------------------------------------------------------------
def center_of_mass(robot: SnakeRobot, q: np.ndarray, base: BasePlacement | None = None, *,
                   frames: np.ndarray | None = None) -> np.ndarray:
    """Centre of mass of the whole robot in the world frame (m), Eq. 23: c = sum m_i P_i / sum m_i.

    q: (n,) -> (3,), or a trajectory (T, n) -> (T, 3). ``frames``: the world frames of q (T, n_links, 4, 4) when
    the caller has them.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs, single = _joint_matrix(robot, q)
    world = frames is not None and np.shape(frames) == (qs.shape[0], len(robot.link_names), 4, 4)
    if not world:
        frames = robot.body.fk_all_many(qs)  # root frame; only the CoM is moved to the world
    assert frames is not None
    # sum_i m_i P_i / M with P_i = p_i + R_i cbar_i, in the core: link by link in a fixed order, no BLAS (whose
    # kernels and blocking round a matrix product differently from machine to machine and from one batch size to
    # another), so that a configuration's centre of mass is the same numbers in any batch, on any machine
    c = _core.center_of_mass(np.ascontiguousarray(frames, dtype=float), robot.masses, robot.coms)
    if not world:
        W = robot.root_pose(base)
        # c @ W[:3, :3].T + W[:3, 3], written out (a BLAS product of (T, 3) by (3, 3) rounds as its kernel does)
        c = c[:, :1] * W[:3, 0] + c[:, 1:2] * W[:3, 1] + c[:, 2:] * W[:3, 2] + W[:3, 3]
    return c[0] if single else c


# ------------------------------------------------------------------------------------------------
# Eq. 24: support polygon
# ------------------------------------------------------------------------------------------------
def hull_indices(pts: npt.ArrayLike) -> list[int]:
    """Indices of the counter-clockwise convex hull vertices of 2-D points (N, 2), collinear points on edges left
    out (the C++ core's monotone chain): one index for coincident points, the two extremes for collinear points."""
    return list(_core.convex_hull_2d(finite_array(pts, "points", (None, 2))))


def _hull_ccw(pts: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull vertices of 2-D points; a 2-point segment or 1 point when degenerate."""
    return np.asarray(pts, float)[hull_indices(pts)]


def support_polygon(robot: SnakeRobot, q: npt.ArrayLike, base: BasePlacement | None = None, *,
                    contact: str = "endpoints", tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """Support polygon of the base part on the ground, Eq. 24: (k, 2) world (x, y) vertices, counter-clockwise.

    ``contact`` selects the contact points p_i of Eq. 24:

    * ``"endpoints"`` (default, the paper): both endpoints of every base link (link_0 .. link_7 on the default
      robot: the origins of link_0 .. link_7 and of the ``base_end`` marker), projected on the ground.
      This is conservative: the true footprint of the 0.043 m wide modules is larger.
    * ``"footprint"``: the lowest points of every base link's collision shapes that touch the ground (a box's
      bottom corners, a cylinder's bottom line, a sphere's lowest point, a mesh hull's lowest vertices) -- the
      physical contact footprint of the modules; use it for an (almost) straight base, whose endpoints are
      collinear.
    * ``"ground"``: the same for every link that lies on the ground, the neck's and head's included -- the
      physical support of a robot that still lies (partly) flat, e.g. before the head is lifted.

    Only links lying on the ground count (the lowest point of their shapes below ``tolerance`` m). In the paper's
    model (the first two) only the base supports the body, even when the neck and head touch the ground.
    If the contact points are collinear the "polygon" is the segment between the extreme points (2, 2): it
    has no interior, so :func:`static_margin` is <= 0 for it.
    """
    robot = as_robot(robot)
    base = as_base(base)
    q = joint_vector(q, robot.n_joints)
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    frames = robot.frames_many(q[None, :], base)
    pts, active = _contact_points_many(robot, frames, contact, tolerance)
    pts = pts[0][active[0]]
    if len(pts) == 0:
        raise Infeasible("no base link touches the ground: there is no support polygon")
    return _hull_ccw(pts)


def static_margin(robot: SnakeRobot, q: npt.ArrayLike, base: BasePlacement | None = None, *,
                  contact: str = "endpoints", tolerance: float = GROUND_TOLERANCE) -> float:
    """Signed distance (m) from the CoM's ground projection to the support polygon's edge; > 0 inside.

    Static stability (Section 3.1): the robot is statically stable if c is in C (Eq. 23, 24).
    Outside the polygon the value is minus the distance to the polygon.
    """
    robot = as_robot(robot)
    base = as_base(base)
    q = joint_vector(q, robot.n_joints)
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    frames = robot.frames_many(q[None, :], base)
    return float(static_margins_of_frames(robot, frames, center_of_mass(robot, q[None, :], base, frames=frames),
                                          contact, tolerance, base)[0])


def static_margins_of_frames(robot: SnakeRobot, frames: np.ndarray, com: np.ndarray, contact: str = "endpoints",
                             tolerance: float = GROUND_TOLERANCE, base: BasePlacement | None = None) -> np.ndarray:
    """:func:`static_margin` of many configurations at once from their world frames (T, n_links, 4, 4)
    (:meth:`SnakeRobot.frames_many`) and centres of mass (T, 3) (:func:`center_of_mass`): (T,) m. Each sample's
    support polygon is the hull of its own touching contact points (the C++ core's hull, one per sample, without
    the GIL). The arrays are taken as they are (for the library's inner loops, e.g. the whole-body solve's checks of
    a batch of candidates); ``base``: the placement the frames are at, whose ground's gravity leans the CoM's
    projection on a slope (:meth:`~snakehead.model.placement.BasePlacement.below_along_gravity`; default: flat ground). ``Infeasible`` when a sample has no base
    link on the ground."""
    pts, active = _contact_points_many(robot, frames, contact, tolerance)
    if not active.any(axis=1).all():
        raise Infeasible("no base link touches the ground: there is no support polygon")
    return _core.hull_margins(np.ascontiguousarray(pts, dtype=np.float64), np.ascontiguousarray(active),
                              np.ascontiguousarray(as_base(base).below_along_gravity(com), dtype=np.float64))


def is_statically_stable(robot: SnakeRobot, q: np.ndarray, base: BasePlacement | None = None, *,
                         contact: str = "endpoints", tolerance: float = GROUND_TOLERANCE,
                         margin: float = 0.0) -> bool:
    """True when the CoM's ground projection lies inside the support polygon by more than ``margin`` m."""
    return static_margin(robot, q, base, contact=contact, tolerance=tolerance) > float(margin)


# ------------------------------------------------------------------------------------------------
# Eqs. 25-31: momenta
# ------------------------------------------------------------------------------------------------
def _check_times(t: npt.ArrayLike, name: str = "t") -> np.ndarray:
    t = finite_array(t, name, (None,))
    if t.shape[0] < 2:
        raise InputError(f"{name} needs at least two samples, got {t.shape[0]}")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"{name} must increase strictly")
    return t


def _check_trajectory(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    t = _check_times(t)
    q = finite_array(q, "q", (None, robot.n_joints))
    if q.shape[0] != t.shape[0]:
        raise InputError(f"q has {q.shape[0]} samples but t has {t.shape[0]}")
    return t, q


def joint_velocities(t: np.ndarray, q: npt.ArrayLike) -> np.ndarray:
    """Joint velocities (rad/s) of a sampled trajectory by finite differences: (T,) and (T, n) -> (T, n).

    ``np.gradient``: central differences inside (second order on non-uniform steps too), second-order
    one-sided differences at the ends (first order with only two samples).
    """
    t = _check_times(t)
    return _time_derivative(t, finite_array(q, "q", (t.shape[0], None)))


def _time_derivative(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """d/dt of samples x (T, ...) at times t (T,) by ``np.gradient`` along the samples (see joint_velocities)."""
    edge: Literal[1, 2] = 2 if len(t) > 2 else 1
    return np.asarray(np.gradient(x, t, axis=0, edge_order=edge))


def _momenta(robot: SnakeRobot, q: np.ndarray, qd: np.ndarray, base: BasePlacement, frames: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eqs. 25-31 for q, qd (T, n): P (T, 3), L about the world origin (T, 3) and the CoM (T, 3), world.

    Each massive link's CoM velocity is the sum over the joints before it of (z_i qdot_i) x (c_j - o_i)
    (Eqs. 25, 27), i.e. omega_j x c_j - sum_i (z_i qdot_i) x o_i; P sums m_j cdot_j (Eqs. 28-29), L sums
    c_j x m_j cdot_j + R_j Ibar_j R_j^T omega_j (Eqs. 30-31). The sums run in the C++ core, sample by sample, on
    the world frames (``frames`` when the caller has them), so P, L and c come out in the world directly.
    """
    if frames is None or np.shape(frames) != (q.shape[0], len(robot.link_names), 4, 4):
        frames = robot.frames_many(q, base)
    model = robot.body.model
    return _core.momenta(frames, qd, list(model.joint_child_links), model.joint_axes, robot.masses, robot.coms,
                         robot.inertias)


def momenta_from_velocities(robot: SnakeRobot, q: np.ndarray, qd: np.ndarray, base: BasePlacement | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Linear momentum P (kg m/s) and angular momentum L about the world origin (kg m^2/s), Eqs. 25-31.

    q, qd: joint positions (rad) and velocities (rad/s), (T, n) each (or (n,) each -> (3,), (3,)).
    The root link is fixed to the ground at ``base`` (it does not move).
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs, single = _joint_matrix(robot, q)
    qds, _ = _joint_matrix(robot, qd, "qd")
    if qds.shape != qs.shape:
        raise InputError(f"qd has shape {np.shape(qd)}; expected that of q, {np.shape(q)}")
    P, L, _ = _momenta(robot, qs, qds, base)
    return (P[0], L[0]) if single else (P, L)


def momenta(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, base: BasePlacement | None = None,
            qd: npt.ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Momenta along a sampled trajectory, Eqs. 25-31: t (T,) s, q (T, n) rad -> P (T, 3), L (T, 3).

    P in kg m/s; L in kg m^2/s about the world origin. The joint velocities are ``qd`` when given (e.g. a
    spline's exact derivative), otherwise :func:`joint_velocities` of the samples (np.gradient).
    """
    robot = as_robot(robot)
    base = as_base(base)
    t, q = _check_trajectory(robot, t, q)
    qd = joint_velocities(t, q) if qd is None else finite_array(qd, "qd", q.shape)
    P, L, _ = _momenta(robot, q, qd, base)
    return P, L


# ------------------------------------------------------------------------------------------------
# Eqs. 32-40: zero-moment point
# ------------------------------------------------------------------------------------------------
def _zmp_from(com: np.ndarray, Pdot: np.ndarray, Ldot: np.ndarray, M: float, pz: float = 0.0,
              gravity: np.ndarray | None = None) -> np.ndarray:
    """Eqs. 39-40: (T, 2) ZMP on the plane z = pz from the CoM (T, 3) and the momentum rates (T, 3); ``gravity``
    (3,) in the ground frame (default (0, 0, -GRAVITY)): on a slope the weight's moment adds M g_xy (c_z - pz)."""
    G = GRAVITY if gravity is None else float(-gravity[2])
    den = M * G + Pdot[:, 2]
    # the ground cannot pull: where M g + dP_z/dt <= 0 the robot leaves the ground and there is no ZMP (NaN)
    den = np.where(den > 0.0, den, np.nan)
    mx, my = M * G * com[:, 0], M * G * com[:, 1]
    if gravity is not None and (gravity[0] != 0.0 or gravity[1] != 0.0):
        mx = mx + M * gravity[0] * (com[:, 2] - pz)
        my = my + M * gravity[1] * (com[:, 2] - pz)
    px = (mx + pz * Pdot[:, 0] - Ldot[:, 1]) / den  # Eq. 39
    py = (my + pz * Pdot[:, 1] + Ldot[:, 0]) / den  # Eq. 40
    return np.stack([px, py], axis=1)


def _zmp(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, base: BasePlacement, qd: npt.ArrayLike | None,
         frames: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    t, q = _check_trajectory(robot, t, q)
    qd = joint_velocities(t, q) if qd is None else finite_array(qd, "qd", q.shape)
    P, L, com = _momenta(robot, q, qd, base, frames)
    Pdot = _time_derivative(t, P)  # Eq. 33's dP/dt
    Ldot = _time_derivative(t, L)  # Eq. 34's dL/dt
    return _zmp_from(com, Pdot, Ldot, robot.total_mass, gravity=base.gravity), P, L, com, q


def zmp(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, base: BasePlacement | None = None, qd: np.ndarray | None = None
        ) -> np.ndarray:
    """Zero-moment point on the ground along a trajectory, Eqs. 36-40 with p_z = 0: (T, 2) world (x, y), m.

    The time derivatives of P and L (Eqs. 33, 34) are taken numerically along the samples (np.gradient);
    the joint velocities are ``qd`` when given, else finite differences of q (see :func:`momenta`).
    At rest the ZMP is the ground projection of the centre of mass. Samples where the ground would have to
    pull (M g + dP_z/dt <= 0: the body would take off) have no ZMP: NaN.
    """
    robot = as_robot(robot)
    base = as_base(base)
    return _zmp(robot, t, q, base, qd)[0]


@dataclass(frozen=True)
class DynamicStability:
    """Verdict of :func:`dynamic_stability` along a trajectory of T samples.

    zmp (T, 2) m; margin (T,) signed distance of the ZMP to its sample's support polygon edge (m, > 0 inside);
    inside (T,) bool; min_margin (m) and the index where it occurs; stable: inside everywhere; P, L the momenta;
    com (T, 3).
    """

    zmp: np.ndarray
    margin: np.ndarray
    inside: np.ndarray
    min_margin: float
    argmin: int
    stable: bool
    P: np.ndarray
    L: np.ndarray
    com: np.ndarray


def dynamic_stability(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike, base: BasePlacement | None = None,
                      qd: npt.ArrayLike | None = None, *, contact: str = "endpoints",
                      tolerance: float = GROUND_TOLERANCE, frames: np.ndarray | None = None,
                      with_frames: Callable[[slice, np.ndarray], None] | None = None) -> DynamicStability:
    """Dynamic stability of a trajectory (Section 3.1): is the ZMP inside the support polygon at every sample?

    The support polygon (see :func:`support_polygon` for ``contact`` and ``tolerance``) is rebuilt for every
    distinct contact configuration along the trajectory (the base joints may move, e.g. into the initial arc;
    with ``contact="ground"`` the neck and head may lie down or lift off).

    ``frames``: the world frames of ``q`` (T, n_links, 4, 4), when the caller has them; else they are computed
    :data:`SAMPLE_CHUNK` samples at a time and never held for the whole trajectory (they take n_links x 128 bytes
    per sample, 2.5 kB on the default robot: more than everything else together). ``with_frames(rows, frames)``:
    called with each chunk of samples (a slice of the trajectory) and its frames, so that a caller computes what
    else it needs from them (e.g. the ground clearance) in the same pass.
    """
    robot = as_robot(robot)
    base = as_base(base)
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    t, q = _check_trajectory(robot, t, q)
    qd = joint_velocities(t, q) if qd is None else finite_array(qd, "qd", q.shape)
    if frames is None and with_frames is None and contact in CORE_CONTACT_MODELS:
        return dynamic_stability_in_core(robot, t, q, base, qd, contact, tolerance)[0]
    return dynamic_stability_in_python(robot, t, q, base, qd, contact, tolerance, frames, with_frames)


#: The contact models whose dynamic stability runs in the C++ core in one call (``_core.zmp_check``); "endpoints"
#: runs in Python.
CORE_CONTACT_MODELS = ("ground", "footprint")


@dataclass
class KeptSamples:
    """The per-sample part of a C++ dynamic-stability check over a motion's first ``samples`` samples
    (``_core.ZmpPrefix``: momenta, CoM, clearance, contact runs and their polygons), kept by the caller so that a later
    check of a motion that begins with the same samples (a plan's lift from the bending state, the same for every
    target from a base of one shape and placement) takes it over instead of computing it again
    (:func:`dynamic_stability_with_clearance`'s ``kept``). ``core`` is None until a check has filled it; ``resumed``:
    how many samples the last check took over (0 when the motion did not begin with them: the core compares them bit
    for bit, with the robot and contact model, and computes everything otherwise). At the placement it was made at,
    the result is the same as without it to the bit; at another placement on the ground (the base turned about z and
    moved in x, y; include/snakehead/zmp_check.hpp, ZmpPrefix) its momenta, CoM and polygons are moved there: the
    same up to round-off (~1e-15 m), the contact runs and clearances to the bit."""

    samples: int
    core: _core.ZmpPrefix | None = None
    resumed: int = 0


def dynamic_stability_with_clearance(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike,
                                     base: BasePlacement | None = None, qd: npt.ArrayLike | None = None, *,
                                     contact: str = "ground", tolerance: float = GROUND_TOLERANCE,
                                     made: _core.PathChecker | None = None, kept: KeptSamples | None = None
                                     ) -> tuple[DynamicStability, np.ndarray]:
    """:func:`dynamic_stability` (contact "ground" or "footprint") and, from the same frames in the same C++ pass,
    the lowest point of the neck and head links above the ground at each sample (T,) m (as
    ``collision.body_collisions.ground_clearance`` over ``robot.lifted_links``). ``made``: the
    ``collision.path_proof.checker`` of the robot at ``base``, when the caller keeps one. ``kept``: the first samples'
    part of an earlier check to take over (filled by this check when empty; see :class:`KeptSamples`): the result is
    the same, to the bit."""
    robot = as_robot(robot)
    base = as_base(base)
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    t, q = _check_trajectory(robot, t, q)
    qd = joint_velocities(t, q) if qd is None else finite_array(qd, "qd", q.shape)
    if contact not in CORE_CONTACT_MODELS:
        raise InputError(f"contact must be one of {CORE_CONTACT_MODELS}, got {contact!r}")
    return dynamic_stability_in_core(robot, t, q, base, qd, contact, tolerance, made, kept)


def dynamic_stability_in_core(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, base: BasePlacement,
                              qd: np.ndarray, contact: str, tolerance: float, made: _core.PathChecker | None = None,
                              kept: KeptSamples | None = None) -> tuple[DynamicStability, np.ndarray]:
    """:func:`dynamic_stability` of arguments already checked, in one call of the C++ core (``_core.zmp_check``: the
    same momenta, np.gradient's differences, ZMP, contact runs, chunks of SAMPLE_CHUNK samples and hulls as
    :func:`dynamic_stability_in_python`) and the neck and head's lowest point per sample; ``made`` and ``kept`` as
    :func:`dynamic_stability_with_clearance`'s."""
    g = robot.geometry
    if contact == "ground":
        links, key_joints = robot.shaped_links, []
    else:
        links = np.asarray(robot.base_links, int)
        links = links[np.isin(links, robot.shaped_links)]
        key_joints = list(range(robot.n_joints))[robot.parts.base]
    if len(links) == 0:
        raise InputError("the base part has no links with collision shapes; no support polygon")
    resume = kept.core if kept is not None else None
    keep = kept.samples if kept is not None and resume is None else 0
    made = made if made is not None else checker(robot, base)
    out = _core.zmp_check(made, t, np.ascontiguousarray(q), np.ascontiguousarray(qd, float), g.shapes_of(links),
                          g.contact_points_per_shape, g.shapes_of(robot.lifted_links), contact == "ground",
                          key_joints, tolerance, SAMPLE_CHUNK, base.gravity, resume, max(0, keep))
    if kept is not None:
        kept.resumed = int(out["resumed"])
        if out["kept"] is not None:
            kept.core = out["kept"]
    margin = out["margin"]
    inside = margin > 0.0
    k = int(np.argmin(margin))
    dyn = DynamicStability(out["zmp"], margin, inside, float(margin[k]), k, bool(inside.all()), out["P"], out["L"],
                           out["com"])
    return dyn, out["clearance"]


def dynamic_stability_in_python(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, base: BasePlacement,
                                qd: np.ndarray, contact: str, tolerance: float, frames: np.ndarray | None,
                                with_frames: Callable[[slice, np.ndarray], None] | None) -> DynamicStability:
    """:func:`dynamic_stability` of arguments already checked, in Python over the core's frames, momenta and hulls,
    :data:`SAMPLE_CHUNK` samples at a time (the reference of the C++ path, and the path for contact "endpoints",
    given frames or ``with_frames``)."""
    if frames is not None and np.shape(frames) != (q.shape[0], len(robot.link_names), 4, 4):
        frames = None
    n = len(t)
    P, L, com = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    chunks = []  # (rows, the distinct contact polygons in them and which each sample has)
    for start in range(0, n, SAMPLE_CHUNK):
        rows = slice(start, min(n, start + SAMPLE_CHUNK))
        f = robot.frames_many(q[rows], base) if frames is None else frames[rows]
        P[rows], L[rows], com[rows] = _momenta(robot, q[rows], qd[rows], base, f)
        chunks.append((rows, contact_configurations(robot, q[rows], base, contact, tolerance, f)))
        if with_frames is not None:
            with_frames(rows, f)
        del f
    Pdot = _time_derivative(t, P)  # Eq. 33's dP/dt
    Ldot = _time_derivative(t, L)  # Eq. 34's dL/dt
    p = _zmp_from(com, Pdot, Ldot, robot.total_mass, gravity=base.gravity)
    del Pdot, Ldot
    flying = ~np.all(np.isfinite(p), axis=1)
    xy = np.where(flying[:, None], 0.0, p)
    margin = np.empty(n)
    for rows, (pts, active, inv) in chunks:
        margin[rows] = polygon_margin_many(pts[inv], active[inv], xy[rows])
    margin[flying] = -np.inf  # no ZMP: the body would leave the ground
    inside = margin > 0.0
    k = int(np.argmin(margin))
    return DynamicStability(p, margin, inside, float(margin[k]), k, bool(inside.all()), P, L, com)


def support_margins(robot: SnakeRobot, q: npt.ArrayLike, xy: npt.ArrayLike, base: BasePlacement | None = None, *,
                    contact: str = "endpoints", tolerance: float = GROUND_TOLERANCE,
                    frames: np.ndarray | None = None) -> np.ndarray:
    """Signed distance (m, > 0 inside) of points ``xy`` (T, 2) to the support polygon of configuration ``q[k]``
    (T, n) at each sample (see :func:`support_polygon` for ``contact``): e.g. a ZMP along a trajectory.

    The polygons are those of :func:`support_polygons`, built once per run of samples with one contact
    configuration.
    ``frames``: the world frames of ``q`` (T, n_links, 4, 4), when the caller has them.
    """
    robot = as_robot(robot)
    base = as_base(base)
    q, _ = _joint_matrix(robot, q)
    xy = finite_array(xy, "xy", (q.shape[0], 2))
    pts, active, inv = contact_configurations(robot, q, base, contact, tolerance, frames)
    return polygon_margin_many(pts[inv], active[inv], xy)


def support_polygons(robot: SnakeRobot, q: npt.ArrayLike, base: BasePlacement | None = None, *,
                     contact: str = "endpoints", tolerance: float = GROUND_TOLERANCE,
                     frames: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The support polygon of every configuration of a trajectory at once (see :func:`support_polygon` for
    ``contact`` and ``tolerance``): q (T, n) -> vertices (T, N, 2) world (x, y) and count (T,).

    Row k holds its polygon's ``count[k]`` vertices counter-clockwise first (the rest is padding): 0 where no link
    touches the ground, 1 for a point, 2 for a segment (collinear contacts). The polygons are built once per run
    of consecutive samples with one contact configuration (joints rounded to 1e-12 rad, so that a spline's
    round-off in a still base does not split it): the base joints decide the base's contacts; with contact="ground"
    also the joints before the last link on the ground (those after it move nothing that touches). ``frames``: the
    world frames of ``q`` (T, n_links, 4, 4), when the caller has them.
    """
    robot = as_robot(robot)
    base = as_base(base)
    q, _ = _joint_matrix(robot, q)
    pts, active, inv = contact_configurations(robot, q, base, contact, tolerance, frames)
    vertex, count = _core.convex_hulls(np.ascontiguousarray(pts), np.ascontiguousarray(active))
    width = max(1, int(count.max()))
    vertices = np.take_along_axis(pts, np.maximum(vertex[:, :width], 0)[..., None], axis=1)
    vertices[np.arange(width)[None, :] >= count[:, None]] = 0.0
    return vertices[inv], count[inv].astype(int)


def contact_configurations(robot: SnakeRobot, q: np.ndarray, base: BasePlacement, contact: str, tolerance: float,
                           frames: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The distinct contact configurations of q (T, n) (one per run of samples; see :func:`support_polygons`): their
    contact points (U, N, 2) and which touch (U, N), and which of them each sample has (T,). ``frames``: q's world
    frames when the caller has them."""
    if frames is None or frames.shape != (q.shape[0], len(robot.link_names), 4, 4):
        frames = None
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    if contact == "ground":
        lowest = np.full((len(q), len(robot.link_names)), np.inf)
        shaped = robot.shaped_links
        frames = robot.frames_many(q, base) if frames is None else frames
        lowest[:, shaped] = robot.lowest_z(frames, shaped)
        touching = lowest <= tolerance
        last = np.where(touching.any(axis=1), len(robot.link_names) - 1 - np.argmax(touching[:, ::-1], axis=1), -1)
        child = np.asarray(robot.body.model.joint_child_links)
        key = np.where(child[None, :] <= last[:, None], np.round(q, 12), 0.0)
        key = np.column_stack([key, last])
    else:
        key = np.round(q[:, robot.parts.base], 12)
    # runs of samples with the same contact configuration (a trajectory changes it rarely; a configuration that
    # comes back later is built again, which costs less than sorting the samples to find it)
    change = np.r_[True, np.any(key[1:] != key[:-1], axis=1)]
    first = np.flatnonzero(change)  # the first sample of each run
    inv = np.cumsum(change) - 1
    sample_frames = robot.frames_many(q[first], base) if frames is None else frames[first]
    pts, active = _contact_points_many(robot, sample_frames, contact, tolerance)
    return pts, active, inv
