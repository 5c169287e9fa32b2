"""Static equilibrium on contacts at many heights: the region of centre-of-mass ground positions (x, y) at which the
contacts can hold the robot still (Bretl and Lall, "Testing static equilibrium for legged robots", IEEE T-RO 24(4),
2008).

At rest the contact forces f_i (inside the linearised friction cones of a :class:`~.contact_set.ContactSet`) must
balance gravity: sum f_i = m g_up and sum p_i x f_i = c x m g_up, g_up = (0, 0, GRAVITY) (Eq. 38 with zero momentum
rates). Divided by m g, the unknowns are the cone multipliers lambda >= 0 and the CoM's (x, y); the z of the CoM
drops out (gravity is along z), so the region is a vertical cylinder and only its cross-section is computed: the
projection onto (x, y) of the polytope {(lambda, x, y)}, by Bretl and Lall's incremental algorithm.

* :func:`static_equilibrium_region` -- the region as a counter-clockwise convex polygon, with its outer bound.
* :func:`region_margin` -- signed distance (m) of CoM positions to the region's boundary, positive inside.

On flat ground the moments of the horizontal forces have no horizontal part, so the region is the convex hull of the
contacts for every mu >= 0: the support polygon of Eq. 24 (:func:`~snakehead.dynamics.stability.support_polygon`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.optimize import linprog

from .._errors import Infeasible, InputError, invariant
from .._validate import finite_array
from .contact_set import ContactSet, contact_wrench_span
from .stability import polygon_margin_many

__all__ = ["REGION_AREA_TOLERANCE", "REGION_RADIUS", "REGION_MAX_LPS", "EquilibriumRegion",
           "static_equilibrium_region", "region_margin", "static_equilibrium_lp", "convex_ccw"]

#: Default stop of :func:`static_equilibrium_region` (m^2): the outer and inner polygons' areas agree within this (a square
#: of 0.1 mm sides). A region that is an exact polygon ends earlier, when no direction finds a new vertex.
REGION_AREA_TOLERANCE = 1e-8
#: Half-width (m) of the square about the contacts' centroid that bounds the CoM in the LPs: opposing contacts with
#: friction (a trench's walls) can squeeze and hold the CoM arbitrarily far away; such a region is cut there and
#: reported unbounded.
REGION_RADIUS = 10.0
#: Most LPs one region may take (each finds one support point).
REGION_MAX_LPS = 500

#: Relative tolerance of "the LP found no point beyond the edge" (of the contacts' extent, m).
_EDGE_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class EquilibriumRegion:
    """The result of :func:`static_equilibrium_region`.

    vertices (k, 2) m: the inner polygon (the hull of the support points found, counter-clockwise; every point of it
    is in static equilibrium); outer (j, 2) m: the outer polygon (the intersection of the supporting half-planes
    found; no point outside it is); area_gap (m^2) the difference of their areas; lps the LPs solved; bounded False
    when the region reached :data:`REGION_RADIUS` (it is cut there).
    """

    vertices: np.ndarray
    outer: np.ndarray
    area_gap: float
    lps: int
    bounded: bool


class _SupportLP:
    """The LP of one direction d: maximise d . (x, y) over lambda >= 0, |x - x0|, |y - y0| <= R, subject to
    S lambda = (0, 0, 1, y - y0, -(x - x0), 0) (unit weight; moments about the centroid (x0, y0, z0) of the
    contacts, which keeps the numbers of the size of the contacts' extent)."""

    def __init__(self, contacts: ContactSet, radius: float) -> None:
        self.centre = contacts.points.mean(axis=0)
        span = contact_wrench_span(contacts, self.centre)
        n = span.shape[1]
        coupling = np.zeros((6, 2))
        coupling[3, 1] = -1.0  # tau_x = y - y0
        coupling[4, 0] = 1.0  # tau_y = -(x - x0)
        self.A_eq = np.hstack([span, coupling])
        self.b_eq = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        self.bounds = [(0.0, None)] * n + [(-radius, radius)] * 2
        self.radius = radius
        self.solved = 0

    def support(self, d: np.ndarray) -> np.ndarray:
        """The point (x, y) of the region farthest along d (2,) (world m); Infeasible when the region is empty."""
        c = np.zeros(self.A_eq.shape[1])
        c[-2:] = -d
        res = linprog(c, A_eq=self.A_eq, b_eq=self.b_eq, bounds=self.bounds, method="highs")
        self.solved += 1
        if res.status == 2:
            raise Infeasible("no centre-of-mass position is in static equilibrium on these contacts")
        invariant(res.status == 0, f"the support LP of the equilibrium region failed: {res.message}")
        return np.asarray(res.x[-2:], float) + self.centre[:2]


def _cross2(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _outer_corner(p: np.ndarray, dp: np.ndarray, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Where the supporting lines d_p . x = d_p . p and d_q . x = d_q . q meet (they are not parallel: the
    directions of consecutive support points are less than pi apart)."""
    M = np.array([dp, dq])
    if abs(np.linalg.det(M)) < 1e-14:  # the same line (an LP's round-off): no corner beyond the edge
        return np.asarray(0.5 * (p + q))
    return np.asarray(np.linalg.solve(M, [dp @ p, dq @ q]))


def _gap(p: np.ndarray, dp: np.ndarray, q: np.ndarray, dq: np.ndarray) -> float:
    """Area (m^2) of the triangle between the inner edge p-q and the outer corner over it: what the next LP in the
    edge's normal direction may still add."""
    if np.allclose(p, q, rtol=0.0, atol=1e-15):
        return 0.0
    w = _outer_corner(p, dp, q, dq)
    return 0.5 * abs(_cross2(w - p, q - p))


def _initial(lp: _SupportLP) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Three support points, in directions 2 pi / 3 apart (so that consecutive directions are less than pi apart and
    every outer corner exists), in counter-clockwise order of their directions."""
    dirs = [np.array([np.cos(a), np.sin(a)]) for a in (0.0, 2 * np.pi / 3, 4 * np.pi / 3)]
    return [lp.support(d) for d in dirs], dirs


def _refine(lp: _SupportLP, pts: list[np.ndarray], dirs: list[np.ndarray], closed: list[bool], tolerance: float,
            max_lps: int, scale: float) -> float:
    """Bretl and Lall's loop: the edge whose outer triangle is largest gets an LP in its outward normal; its new
    support point splits it in two (or closes it when none lies beyond). Ends when the triangles' total area (the
    outer minus the inner polygon's area) is at most ``tolerance`` or after ``max_lps`` LPs; returns that area."""
    while True:
        k = len(pts)
        gaps = [0.0 if closed[i] else _gap(pts[i], dirs[i], pts[(i + 1) % k], dirs[(i + 1) % k]) for i in range(k)]
        total = float(sum(gaps))
        i = int(np.argmax(gaps))
        if total <= tolerance or lp.solved >= max_lps:
            return total
        p, q = pts[i], pts[(i + 1) % k]
        edge = q - p
        d = np.array([edge[1], -edge[0]]) / np.linalg.norm(edge)  # outward normal of a counter-clockwise edge
        new = lp.support(d)
        if d @ (new - p) <= _EDGE_TOLERANCE * scale:
            closed[i] = True  # the edge is on the region's boundary
            continue
        pts.insert(i + 1, new)
        dirs.insert(i + 1, d)
        closed.insert(i + 1, False)


def convex_ccw(points: npt.ArrayLike, eps: float = 1e-12) -> np.ndarray:
    """The vertices of a convex polygon given as a closed counter-clockwise sequence of its boundary points (k, 2):
    repeated points (within ``eps`` m) and points on an edge (turn below ``eps`` of the edges' lengths) removed,
    starting at the lowest x (then lowest y), as :func:`~snakehead.dynamics.stability.support_polygon` starts. Two
    points for a segment, one for a point. The support points of :func:`static_equilibrium_region` come in this order
    already, so no hull is taken (a hull of the nearly collinear points an LP's round-off makes is fragile)."""
    v = [np.asarray(p, float) for p in finite_array(points, "points", (None, 2))]
    changed = True
    while changed and len(v) > 1:
        changed = False
        for i in range(len(v)):
            a, b, c = v[i - 1], v[i], v[(i + 1) % len(v)]
            ab, bc = b - a, c - b
            # b repeats c, or lies on the way from a to c (a turn back, as at a segment's end, keeps b)
            straight = len(v) > 2 and ab @ bc > 0.0 and _cross2(ab, bc) <= eps * np.linalg.norm(ab) * np.linalg.norm(bc)
            if np.abs(bc).max() <= eps or straight:
                del v[i]
                changed = True
                break
    if len(v) == 2 and np.abs(v[1] - v[0]).max() <= eps:
        v = v[:1]
    out = np.array(v).reshape(-1, 2)
    low = np.flatnonzero(out[:, 0] <= out[:, 0].min() + 1e-9 * max(1.0, float(np.abs(out).max())))
    start = int(low[np.argmin(out[low, 1])])  # the lowest x, then y, blind to an LP's round-off in x
    return np.roll(out, -start, axis=0)


def _outer_polygon(pts: list[np.ndarray], dirs: list[np.ndarray]) -> np.ndarray:
    """The outer polygon: each support point, then the corner of its supporting line with the next one."""
    out = []
    k = len(pts)
    for i in range(k):
        p, q = pts[i], pts[(i + 1) % k]
        out.append(p)
        if not np.allclose(p, q, rtol=0.0, atol=1e-15):
            out.append(_outer_corner(p, dirs[i], q, dirs[(i + 1) % k]))
    return convex_ccw(out)


def static_equilibrium_region(contacts: ContactSet, *, tolerance: float = REGION_AREA_TOLERANCE,
                       radius: float = REGION_RADIUS, max_lps: int = REGION_MAX_LPS) -> EquilibriumRegion:
    """The static-equilibrium region of the centre of mass on ``contacts``: the (x, y) positions (m, world) of the
    CoM at which forces inside the linearised friction cones hold the robot at rest (Bretl and Lall 2008).

    The incremental projection: support points of the region in chosen directions (one LP each, scipy's HiGHS),
    the inner polygon their hull and the outer polygon the intersection of their supporting half-planes; the edge
    with the largest outer triangle is refined next, until the two polygons' areas agree within ``tolerance`` m^2.
    The returned ``vertices`` are the inner polygon's (:func:`convex_ccw`: collinear and repeated points removed, two
    points for a segment, one for a point). The region does not depend on the mass nor on the CoM's height. ``radius`` (m) bounds
    the CoM about the contacts' centroid (see :data:`REGION_RADIUS`). Infeasible when no CoM position balances
    (e.g. every normal horizontal and mu = 0).
    """
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    radius = float(finite_array(radius, "radius", ()))
    if tolerance < 0.0 or radius <= 0.0 or max_lps < 3:
        raise InputError("tolerance must be >= 0, radius > 0 and max_lps >= 3")
    lp = _SupportLP(contacts, radius)
    scale = max(1.0, float(np.ptp(contacts.points, axis=0).max()))
    pts, dirs = _initial(lp)
    closed = [False] * len(pts)
    gap = _refine(lp, pts, dirs, closed, tolerance, max_lps, scale)
    hull = convex_ccw(pts)
    reach = np.abs(np.array(pts) - lp.centre[:2]).max()
    return EquilibriumRegion(hull, _outer_polygon(pts, dirs), gap, lp.solved, bool(reach < radius * (1 - 1e-9)))


def region_margin(vertices: npt.ArrayLike, xy: npt.ArrayLike) -> np.ndarray | float:
    """Signed distance (m) of CoM positions ``xy`` (2,) or (T, 2) to the boundary of a convex polygon ``vertices``
    (k, 2) (an :class:`EquilibriumRegion`'s), positive inside: the static margin of uneven ground, the same measure
    as :func:`~snakehead.dynamics.stability.static_margin`'s on flat ground (the C++ core's
    :func:`~snakehead.dynamics.stability.polygon_margin_many`). A segment or a point has no inside: minus the
    distance to it."""
    v = finite_array(vertices, "vertices", (None, 2))
    p = finite_array(xy, "xy")
    single = p.ndim == 1
    p = np.atleast_2d(p)
    if p.ndim != 2 or p.shape[1] != 2:
        raise InputError(f"xy has shape {np.shape(xy)}; expected (2,) or (T, 2)")
    pts = np.ascontiguousarray(np.broadcast_to(v, (len(p), *v.shape)))
    m = polygon_margin_many(pts, np.ones(pts.shape[:2], bool), p)
    return float(m[0]) if single else m


def static_equilibrium_lp(contacts: ContactSet, com_xy: npt.ArrayLike) -> bool:
    """Whether the CoM at ``com_xy`` (2,) m is in static equilibrium on ``contacts``: one feasibility LP (the
    definition the region is the set of). For one or a few points this costs less than the region."""
    xy = finite_array(com_xy, "com_xy", (2,))
    lp = _SupportLP(contacts, np.inf)
    rel = xy - lp.centre[:2]
    A = lp.A_eq[:, :-2]
    b = lp.b_eq.copy()
    b[3], b[4] = rel[1], -rel[0]
    res = linprog(np.zeros(A.shape[1]), A_eq=A, b_eq=b, bounds=(0.0, None), method="highs")
    return bool(res.status == 0)
