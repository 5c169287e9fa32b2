"""The body's path over the ground around the scene's obstacles, for the closed loop's locomotion
(:mod:`snakehead.locomotion.goals`): where the straight body's middle (its virtual chassis,
:func:`~snakehead.locomotion.goals.chassis_offset`) passes on its way from where it lies to where the curl into
the bending state must start.

Why the body's middle as a disc: the gaits are turning in place and sidewinding, and each keeps the body within
:func:`swept_radius` of its middle (the virtual chassis) and within :func:`swept_half_width` of its axis,
measured on the gaits' own shapes over a cycle. So the middle's path is planned on a grid (:data:`RESOLUTION_M`)
over the free space of the obstacles' footprints (the ground-level outline of their convex shapes) inflated by that
radius plus :data:`CLEARANCE_M`: grid A* (8-connected, octile heuristic: :func:`astar`), then shortcut by line of
sight (:func:`shortcut`). The body then turns at each waypoint square to the next leg and sidewinds along it.

The clearance is a budget, stated once: :data:`EXECUTION_M` (how far a gait leg ends off its line: the loop's
waypoint tolerance) plus :data:`DRIFT_M` (how far the dead reckoning drifts over a route between fixes).

The goal itself usually lies nearer an obstacle than that (the bending state stands beside the wall whose hole
the head goes through): the last leg comes from a *staging point* on the goal's own across-axis
(:func:`plan_route`), where the body can turn, then sidewinds at the goal's heading to the goal, its swept band
(the axis inflated by :func:`swept_half_width` plus EXECUTION_M) nowhere nearer an obstacle than the goal's own;
where no point across has room to turn with the whole budget (a goal between two boxes), from one on the goal's
axis, the body creeping from there along it (linear progression: the straight body's band).
Likewise a start too near an obstacle to turn is left first by an *escape* leg: sidewinding across its axis, or,
when that is blocked too (the body lying between two boxes), creeping along its axis
(:func:`~snakehead.locomotion.gaits.linear_progression`, whose sweep is the straight body's outline). Each gait run is
checked before it runs (:func:`sweep_clear`): its predicted sweep must keep EXECUTION_M from the obstacles.
"""
from __future__ import annotations

import heapq
import math
import weakref
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt
from scipy.ndimage import distance_transform_edt
from scipy.spatial import ConvexHull

from .._errors import Infeasible, InputError
from .._validate import non_negative
from ..geometry.shapes import shape_points
from ..model.robot import BasePlacement, SnakeRobot, as_robot
from .gaits import make_gait, virtual_chassis

__all__ = ["RESOLUTION_M", "EXECUTION_M", "DRIFT_M", "CLEARANCE_M", "GOAL_CLEARANCE_M", "SWEEP_SAMPLES",
           "GROUND_HEIGHT_M", "GRID_MARGIN_M", "DETOUR_M", "DETOUR_COST", "MIN_LEG_M", "MAX_STAGING_M", "ClearanceGrid",
           "footprints", "clearance_grid", "astar", "segment_clear", "shortcut", "Route", "half_width",
           "swept_extents", "swept_radius", "swept_half_width", "PROFILE_STEPS", "PROFILE_RAMP_STEPS", "SWEPT_GAITS",
           "PROFILE_SEGMENT_SAMPLES", "SweepProfile", "sweep_profile", "profile_slack", "band_clearance", "plan_route",
           "TURN_OVERSHOOT", "TURN_SLACK_DEG", "turn_slack", "sweep_clear"]

#: Grid resolution (m).
RESOLUTION_M = 0.025
#: The execution margin (m): how much of a route's clearance the body may lose off its line before the route is
#: planned again from where it is (snakehead.closed_loop.loop: a sidewinding run drifts a few centimetres along the
#: body's axis, a turn shifts the middle by a few), and what every gait run's predicted sweep keeps from the
#: obstacles.
EXECUTION_M = 0.06
#: How far the dead reckoning drifts over a route (m): the onboard estimate drifts a few per cent of the distance the
#: body travels (bench/RESULTS.md).
DRIFT_M = 0.12
#: Clearance (m) a route keeps from every obstacle beyond the gaits' swept extent: the budget of both.
CLEARANCE_M = EXECUTION_M + DRIFT_M
#: The straight pose before the curl (the goal of the locomotion) must keep this from every obstacle (m): the gaits
#: bring the body there within EXECUTION_M, and its last leg sweeps the band of swept_half_width about its axis.
GOAL_CLEARANCE_M = 0.08
#: Samples per gait cycle of the swept extents.
SWEEP_SAMPLES = 60
#: Obstacle shapes whose lowest point is above this height (m) do not stand in the body's way on the ground.
GROUND_HEIGHT_M = 0.1
#: Margin of the grid around the start, the goal and the obstacles (m, beyond half the body's length).
GRID_MARGIN_M = 0.5
#: How much farther out than it must (m) the grid path goes where it can (see :func:`plan_route`).
DETOUR_M = 0.15
#: Cost per step (times its length) of the grid path within DETOUR_M of the disc's bound.
DETOUR_COST = 3.0
#: The shortest leg of a route (m).
MIN_LEG_M = 0.1
#: Farthest a staging point lies from the goal along its across-axis (m).
MAX_STAGING_M = 2.0


@dataclass
class ClearanceGrid:
    """The obstacles' footprints on a grid: ``origin`` (2,) m the centre of cell (0, 0), ``resolution`` m,
    ``occupied`` (H, W) bool (row i at y = origin[1] + i res, column j at x = origin[0] + j res), ``distance``
    (H, W) m from each cell's centre to the nearest occupied cell's centre (0 inside; inf without obstacles);
    ``clearance`` (H, W) m: a lower bound of the distance from any point of each cell to the obstacles (a cell is
    occupied when its centre is within half a diagonal d of a footprint, so the distance less 2 d)."""

    origin: np.ndarray
    resolution: float
    occupied: np.ndarray
    distance: np.ndarray = field(init=False)
    clearance: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        if self.occupied.any():
            self.distance = distance_transform_edt(~self.occupied) * self.resolution
        else:
            self.distance = np.full(self.occupied.shape, np.inf)
        self.clearance = self.distance - self.resolution * math.sqrt(2.0)

    def cell(self, xy: npt.ArrayLike) -> tuple[int, int]:
        """The (row, column) of the cell holding the point ``xy``, clipped to the grid."""
        x, y = np.asarray(xy, float).reshape(2)
        j = int(round((x - self.origin[0]) / self.resolution))
        i = int(round((y - self.origin[1]) / self.resolution))
        return min(max(i, 0), self.occupied.shape[0] - 1), min(max(j, 0), self.occupied.shape[1] - 1)

    def point(self, cell: tuple[int, int]) -> np.ndarray:
        return self.origin + self.resolution * np.array([cell[1], cell[0]], float)

    def clearance_at(self, xy: np.ndarray) -> np.ndarray:
        """A lower bound of the distance (m) to the nearest obstacle of points ``xy`` (P, 2): their cells'
        ``clearance`` (inf outside the grid, which reaches beyond every obstacle by its margin)."""
        xy = np.atleast_2d(xy)
        j = np.clip(np.round((xy[:, 0] - self.origin[0]) / self.resolution).astype(int), 0, self.occupied.shape[1] - 1)
        i = np.clip(np.round((xy[:, 1] - self.origin[1]) / self.resolution).astype(int), 0, self.occupied.shape[0] - 1)
        inside = ((xy[:, 0] >= self.origin[0] - self.resolution) & (xy[:, 1] >= self.origin[1] - self.resolution)
                  & (xy[:, 0] <= self.origin[0] + self.resolution * self.occupied.shape[1])
                  & (xy[:, 1] <= self.origin[1] + self.resolution * self.occupied.shape[0]))
        return np.where(inside, self.clearance[i, j], np.inf)


def footprints(obstacles: Sequence[Any], below: float = GROUND_HEIGHT_M) -> list[np.ndarray]:
    """The ground-level outlines (convex polygons (V, 2), counter-clockwise) of the obstacles' convex shapes whose
    lowest point is below ``below`` m."""
    out = []
    for ob in obstacles:
        for shape in ob.shapes():
            pts = shape_points(shape)
            if pts[:, 2].min() > below:
                continue
            hull = ConvexHull(pts[:, :2])
            out.append(pts[hull.vertices, :2])
    return out


def _inside_convex(poly: np.ndarray, xy: np.ndarray, grow: float = 0.0) -> np.ndarray:
    """Whether points ``xy`` (P, 2) lie inside the counter-clockwise convex polygon ``poly`` (V, 2) with its edges
    moved ``grow`` m outwards."""
    a, b = poly, np.roll(poly, -1, axis=0)
    edge = b - a
    rel = xy[:, None, :] - a[None]
    cross = edge[None, :, 0] * rel[..., 1] - edge[None, :, 1] * rel[..., 0]
    return np.all(cross >= -grow * np.linalg.norm(edge, axis=1)[None], axis=1)


def clearance_grid(obstacles: Sequence[Any], points: npt.ArrayLike, margin: float,
                   resolution: float = RESOLUTION_M) -> ClearanceGrid:
    """The grid over ``points`` (the start, the goal) and the obstacles' footprints, ``margin`` m beyond them."""
    polys = footprints(obstacles)
    allxy = np.vstack([np.asarray(points, float).reshape(-1, 2)] + polys)
    lo, hi = allxy.min(axis=0) - margin, allxy.max(axis=0) + margin
    shape = (int(math.ceil((hi[1] - lo[1]) / resolution)) + 1, int(math.ceil((hi[0] - lo[0]) / resolution)) + 1)
    occupied = np.zeros(shape, bool)
    for poly in polys:
        j0, i0 = np.floor((poly.min(axis=0) - lo) / resolution).astype(int) - 1
        j1, i1 = np.ceil((poly.max(axis=0) - lo) / resolution).astype(int) + 1
        i0, j0 = max(i0, 0), max(j0, 0)
        ii, jj = np.mgrid[i0:i1 + 1, j0:j1 + 1]
        xy = lo + resolution * np.stack([jj.ravel(), ii.ravel()], axis=1)
        # a cell is occupied when the footprint reaches into it: its centre within half a diagonal (conservative)
        inside = _inside_convex(poly, xy, resolution * math.sqrt(0.5)).reshape(ii.shape)
        occupied[ii[inside], jj[inside]] = True
    return ClearanceGrid(lo, resolution, occupied)


_MOVES = [(di, dj, math.hypot(di, dj)) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]


def astar(free: np.ndarray, start: tuple[int, int], goal: tuple[int, int], weight: np.ndarray | None = None
          ) -> list[tuple[int, int]] | None:
    """The cheapest 8-connected path of cells from ``start`` to ``goal`` through ``free`` (H, W) cells (steps of 1
    and sqrt 2, times ``weight`` (H, W) >= 1 of the cell stepped into, default 1; the start and the goal need not be
    free), or None. A* with the octile distance (admissible and consistent for weights >= 1, so the path is a
    cheapest one)."""
    H, W = free.shape

    def h(c: tuple[int, int]) -> float:
        di, dj = abs(c[0] - goal[0]), abs(c[1] - goal[1])
        return max(di, dj) + (math.sqrt(2.0) - 1.0) * min(di, dj)

    best = {start: 0.0}
    parent: dict[tuple[int, int], tuple[int, int]] = {}
    heap = [(h(start), 0.0, start)]
    done = set()
    while heap:
        _, g, c = heapq.heappop(heap)
        if c in done:
            continue
        if c == goal:
            path = [c]
            while c in parent:
                c = parent[c]
                path.append(c)
            return path[::-1]
        done.add(c)
        for di, dj, cost in _MOVES:
            n = (c[0] + di, c[1] + dj)
            if not (0 <= n[0] < H and 0 <= n[1] < W) or (n != goal and not free[n]):
                continue
            ng = g + cost * (1.0 if weight is None else float(weight[n]))
            if ng < best.get(n, math.inf):
                best[n] = ng
                parent[n] = c
                heapq.heappush(heap, (ng + h(n), ng, n))
    return None


def segment_clear(grid: ClearanceGrid, a: np.ndarray, b: np.ndarray, radius: float) -> bool:
    """Whether every point of the segment a-b (2,) m is farther than ``radius`` from the obstacles."""
    n = max(int(math.ceil(float(np.linalg.norm(b - a)) / (0.5 * grid.resolution))), 1)
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    return bool(np.all(grid.clearance_at(a + s * (b - a)) > radius))


def shortcut(grid: ClearanceGrid, points: list[np.ndarray], radius: float) -> list[np.ndarray]:
    """The path ``points`` with every waypoint dropped that the line of sight from an earlier one passes (greedy,
    farthest first), keeping ``radius`` from the obstacles."""
    out = [points[0]]
    k = 0
    while k < len(points) - 1:
        nxt = k + 1
        for m in range(len(points) - 1, k + 1, -1):
            if segment_clear(grid, points[k], points[m], radius):
                nxt = m
                break
        out.append(points[nxt])
        k = nxt
    return out


@dataclass
class Route:
    """The middle's way to the goal: ``waypoints`` (K, 2) m (the start's middle first, the goal's last), each
    leg's body heading ``headings`` (K - 1,) rad (square to the leg; the last leg's is the goal's heading, from the
    staging point; an escape leg's the start's), ``staging``: whether the last leg comes from a staging point;
    ``clear_m``: the turning disc's radius the path keeps from the obstacles (swept radius + clearance);
    ``escape``: whether the first leg is an escape (at the start's heading, nearer the obstacles than clear_m);
    ``creep``: whether it is one along the body's axis (linear progression); ``staging_creep``: whether the staging
    point lies on the goal's own axis (the body turns to the goal's heading there and creeps to the goal)."""

    waypoints: np.ndarray
    headings: np.ndarray
    staging: bool
    clear_m: float
    creep: bool = False
    escape: bool = False
    staging_creep: bool = False


def half_width(robot: SnakeRobot) -> float:
    """Half the straight body's width seen from above (m): the farthest its shapes reach from its axis."""
    robot = as_robot(robot)
    frames = robot.frames(np.zeros(robot.n_joints), BasePlacement())[None]  # the body frame: x along the body
    return float(np.abs(robot.hull_points(frames)[..., 1]).max())


def _chassis_extents(robot: SnakeRobot, q: np.ndarray) -> tuple[float, float]:
    """The largest distance (m) in the ground plane of the body's hull points from its virtual chassis' origin, and
    across its axis, over the shapes ``q`` (T, n)."""
    F = robot.frames_many(q)
    pts, centres = robot.hull_points(F), robot.link_centres(F)
    radius = across = 0.0
    for c, p in zip(centres, pts):
        T = virtual_chassis(c, forward=c[-1] - c[0])
        local = (p.reshape(-1, 3) - T[:3, 3]) @ T[:3, :3]
        radius = max(radius, float(np.hypot(local[:, 0], local[:, 1]).max()))
        across = max(across, float(np.abs(local[:, 1]).max()))
    return radius, across


#: swept_extents of each robot met so far (a robot's shapes do not change).
_SWEPT: "weakref.WeakKeyDictionary[SnakeRobot, tuple[float, float]]" = weakref.WeakKeyDictionary()


def swept_extents(robot: SnakeRobot) -> tuple[float, float]:
    """(radius, half width) m: how far from its middle and from its axis the body reaches while lying straight
    or in any shape of a full-amplitude cycle of turning or sidewinding (SWEEP_SAMPLES shapes a cycle; the
    smaller-amplitude runs stay within them)."""
    robot = as_robot(robot)
    if robot in _SWEPT:
        return _SWEPT[robot]
    shapes = [np.zeros((1, robot.n_joints))]
    for name in ("turning", "sidewinding"):
        for direction in (1, -1):
            g = make_gait(name, direction)
            t = g.ramp_s + np.linspace(0.0, g.period_s, SWEEP_SAMPLES, endpoint=False)
            shapes.append(g.joint_angles(robot, t, 1.0))
    _SWEPT[robot] = _chassis_extents(robot, np.vstack(shapes))
    return _SWEPT[robot]


def swept_radius(robot: SnakeRobot) -> float:
    """How far from its middle the body reaches in the gaits (m; :func:`swept_extents`)."""
    return swept_extents(robot)[0]


def swept_half_width(robot: SnakeRobot) -> float:
    """How far from its axis the body reaches in the gaits (m; :func:`swept_extents`)."""
    return swept_extents(robot)[1]


#: Amplitude steps of the sweep profiles (:func:`sweep_profile`): a run at amplitude scale k is bounded by the shapes
#: of every amplitude up to the step at or above k.
PROFILE_STEPS = 8
#: Amplitude envelope steps of a run's ramps within each profile step (the ramps scale the wave at any phase).
PROFILE_RAMP_STEPS = 4

#: sweep_profile's answers per robot, by (gait, amplitude step).
_PROFILES: "weakref.WeakKeyDictionary[SnakeRobot, dict]" = weakref.WeakKeyDictionary()
#: The gaits whose runs sweep_profile outlines.
SWEPT_GAITS = ("sidewinding", "turning")


#: Samples along each segment between two hull points of a link (sweep_profile): the silhouette of a link's convex
#: shape seen from above is made of such segments (its edges').
PROFILE_SEGMENT_SAMPLES = 16


@dataclass(frozen=True)
class SweepProfile:
    """The body's outline over a gait run, seen from above in its virtual chassis frame (:func:`sweep_profile`):
    ``points`` (P, 2) m such that every point of the body lies within ``pad`` m of one of them."""

    points: np.ndarray
    pad: float


def _slabs(robot: SnakeRobot, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(lo (J,), hi (J,), pad): the body in the shapes ``q`` (T, n), seen from above in each shape's virtual
    chassis frame, sampled along every segment between two hull points of a link (its silhouette's edges are
    among them) PROFILE_SEGMENT_SAMPLES times, each sample counted in the slab of its nearest axis point u_j (half
    a cell apart): the samples' y from lo_j to hi_j (lo_j > hi_j: none); every point of the body within ``pad``
    of a sample (its edges') or between two on one line across the axis (its inside)."""
    F = robot.frames_many(q)
    pts, centres = robot.hull_points(F), robot.link_centres(F)  # (T, k, M, 3), (T, k, 3)
    ia, ib = np.triu_indices(pts.shape[2], 1)
    f = np.linspace(0.0, 1.0, PROFILE_SEGMENT_SAMPLES)
    local_pts = robot.link_points[1]
    pad = 0.5 * float(np.linalg.norm(local_pts[:, ia] - local_pts[:, ib], axis=-1).max()) / (
        PROFILE_SEGMENT_SAMPLES - 1)
    h = float(u[1] - u[0])
    lo, hi = np.full(len(u), np.inf), np.full(len(u), -np.inf)
    for c, p in zip(centres, pts):
        T = virtual_chassis(c, forward=c[-1] - c[0])
        local = (p - T[:3, 3]) @ T[:3, :2]  # (k, M, 2)
        xy = (local[:, ia, None, :] + f[None, None, :, None] * (local[:, ib] - local[:, ia])[:, :, None, :]
              ).reshape(-1, 2)
        j = np.clip(np.round((xy[:, 0] - u[0]) / h).astype(int), 0, len(u) - 1)
        np.minimum.at(lo, j, xy[:, 1])
        np.maximum.at(hi, j, xy[:, 1])
    return lo, hi, pad


def sweep_profile(robot: SnakeRobot, gait: str, scale: float = 1.0) -> SweepProfile:
    """The outline of a run of ``gait`` ("sidewinding" or "turning") at amplitude ``scale`` in its virtual
    chassis frame: the straight body's shapes and a cycle's at every amplitude up to the PROFILE_STEPS step at or
    above ``scale`` (the ramps' too: PROFILE_RAMP_STEPS envelopes a step), both directions, SWEEP_SAMPLES a
    cycle; per slab across the axis (half a grid cell wide, out to the swept radius) the samples' extent across
    it (``_slabs``), filled with points half a cell apart. Every point of those shapes lies within ``pad`` of
    one: the samples' spacing along the edges, and half a cell either way. Tighter than the band of
    :func:`swept_half_width` over the whole length: near the ends the wave stays nearer the axis, and a slab
    holds only the side the body reaches."""
    robot = as_robot(robot)
    if gait not in SWEPT_GAITS:
        raise InputError(f"gait must be one of {', '.join(SWEPT_GAITS)}, got {gait!r}")
    scale = non_negative(scale, "scale")  # 0: the straight body (the first step covers it)
    k = min(max(int(math.ceil(scale * PROFILE_STEPS - 1e-9)), 1), PROFILE_STEPS)
    cache = _PROFILES.setdefault(robot, {})
    if (gait, k) in cache:
        return cache[(gait, k)][0]
    h = 0.5 * RESOLUTION_M
    n = int(math.ceil(swept_radius(robot) / h)) + 1
    u = h * np.arange(-n, n + 1)
    if k == 1:
        lo, hi, pad = _slabs(robot, np.zeros((1, robot.n_joints)), u)
    else:
        sweep_profile(robot, gait, (k - 1) / PROFILE_STEPS)
        lo, hi, pad = cache[(gait, k - 1)][1]
    shapes = []
    for direction in (1, -1):
        g = make_gait(gait, direction)
        t = g.ramp_s + np.linspace(0.0, g.period_s, SWEEP_SAMPLES, endpoint=False)
        q = g.joint_angles(robot, t, 1.0)  # full amplitude: each wave's offset is 0, so amplitude scales q
        for e in np.arange(1, PROFILE_RAMP_STEPS + 1) / PROFILE_RAMP_STEPS:
            shapes.append(q * ((k - 1 + e) / PROFILE_STEPS))
    lo2, hi2, _ = _slabs(robot, np.vstack(shapes), u)
    lo, hi = np.minimum(lo, lo2), np.maximum(hi, hi2)
    points = [np.column_stack([np.full(m, x), np.linspace(a, b, m)])
              for x, a, b in zip(u, lo, hi) if a <= b for m in [int(math.ceil((b - a) / h)) + 1]]
    profile = SweepProfile(np.vstack(points), math.hypot(0.5 * h + pad, 0.5 * h + pad))
    cache[(gait, k)] = (profile, (lo, hi, pad))
    return profile


def profile_slack(grid: ClearanceGrid, middle: np.ndarray, heading: float, profile: SweepProfile) -> float:
    """A lower bound of the distance (m) to the obstacles of every point the ``profile`` (:func:`sweep_profile`)
    bounds, its virtual chassis at ``middle`` (2,) m along ``heading`` rad."""
    c, s = math.cos(heading), math.sin(heading)
    xy = middle + profile.points @ np.array([[c, s], [-s, c]])
    return float(grid.clearance_at(xy).min()) - profile.pad


def band_clearance(grid: ClearanceGrid, middle: np.ndarray, heading: float, length: float) -> float:
    """A lower bound of the distance (m) of the straight body's centre line (``length`` m about ``middle`` along
    ``heading`` rad) to the obstacles."""
    a = np.array([math.cos(heading), math.sin(heading)])
    n = max(int(math.ceil(length / (0.5 * grid.resolution))), 1)
    s = np.linspace(-0.5, 0.5, n + 1)[:, None] * length
    return float(grid.clearance_at(middle + s * a).min())


def _sidestep(grid: ClearanceGrid, middle: BasePlacement, length: float, radius: float, side: float,
              along: bool = False) -> np.ndarray | None:
    """Where the body lying straight with its middle at ``middle`` can turn (``radius`` clear), reached by a
    straight leg at its own heading: across its axis (sidewinding; ``along``: along it, creeping), its centre line
    keeping ``side`` from the obstacles all the way, or, where it already lies nearer, no nearer than it lies at
    ``middle``: the middle itself when it can turn there, else the nearest such point (MAX_STAGING_M at most), or
    None."""
    m = np.array([middle.x, middle.y])
    if grid.clearance_at(m)[0] > radius:
        return m
    n = (np.array([math.cos(middle.yaw), math.sin(middle.yaw)]) if along
         else np.array([-math.sin(middle.yaw), math.cos(middle.yaw)]))
    keep = min(side, band_clearance(grid, m, middle.yaw, length))
    step = grid.resolution
    for s in np.arange(step, MAX_STAGING_M, step):
        for sign in (1.0, -1.0):
            p = m + sign * s * n
            if grid.clearance_at(p)[0] > radius and all(
                    band_clearance(grid, m + sign * t * n, middle.yaw, length) >= keep
                    for t in np.arange(step, s + 1e-9, step)):
                return p
    return None


def _escape(grid: ClearanceGrid, start: BasePlacement, length: float, radius: float, side_across: float,
            side_along: float) -> tuple[np.ndarray, bool] | None:
    """The escape from the start (see the module): (where, creeping along the axis?) or None."""
    across = _sidestep(grid, start, length, radius, side_across)
    if across is not None:
        return across, False
    along = _sidestep(grid, start, length, radius, side_along, along=True)
    return None if along is None else (along, True)


def _drop_short_legs(grid: ClearanceGrid, points: list[np.ndarray], radius: float, first: int) -> list[np.ndarray]:
    """``points`` without the waypoints (from index ``first`` on, never the last) whose leg to the next is shorter
    than MIN_LEG_M (the grid's snap next to the staging point: its turn costs a run), where the leg that replaces
    both keeps ``radius`` from the obstacles."""
    out = points[:first]
    for k in range(first, len(points) - 1):
        if float(np.linalg.norm(points[k + 1] - points[k])) < MIN_LEG_M \
                and segment_clear(grid, out[-1], points[k + 1], radius):
            continue
        out.append(points[k])
    return out + [points[-1]]


def plan_route(robot: SnakeRobot, obstacles: Sequence[Any], start_middle: BasePlacement, goal_middle: BasePlacement,
               *, clearance: float = CLEARANCE_M, resolution: float = RESOLUTION_M,
               grid: ClearanceGrid | None = None) -> Route | None:
    """The route of the straight body's middle from ``start_middle`` to ``goal_middle`` (placements of the virtual
    chassis: x, y m and the body's heading rad) around ``obstacles`` (see the module), or None when the straight
    legs of :func:`snakehead.locomotion.goals.next_step` are already clear of them (no obstacle within the turning
    disc of the start or along the way). :class:`~snakehead.Infeasible` when there is no route. ``grid``: the
    obstacles' (:func:`clearance_grid`, reaching the swept radius plus the clearance beyond them; default: one
    over the start, the goal and the obstacles at ``resolution``), so that other checks see the same cells."""
    robot = as_robot(robot)
    L = robot.body_length
    reach, wave = swept_extents(robot)
    R = reach + clearance
    side, straight_side = wave + EXECUTION_M, half_width(robot) + EXECUTION_M
    a, g = np.array([start_middle.x, start_middle.y]), np.array([goal_middle.x, goal_middle.y])
    if not obstacles:
        return None
    if grid is None:
        grid = clearance_grid(obstacles, [a, g], R + GRID_MARGIN_M, resolution)
    # next_step's own legs (turn at the start, sidewind along the goal's axis to the corner, turn there, sidewind
    # across to the goal) swept within the discs along them: clear, no route needed
    axis = np.array([math.cos(goal_middle.yaw), math.sin(goal_middle.yaw)])
    corner = g + ((a - g) @ (axis[::-1] * [-1.0, 1.0])) * (axis[::-1] * [-1.0, 1.0])
    if segment_clear(grid, a, corner, R) and segment_clear(grid, corner, g, R):
        return None
    # the last leg: from a staging point on the goal's across-axis, the body at the goal's heading; the first, when
    # the body cannot turn where it lies: sidewinding or creeping at its own heading to where it can
    staging = _sidestep(grid, goal_middle, L, R, side)
    staging_creep = False
    if staging is None:  # none across: one along the goal's axis, the body creeping from there at its heading
        staging = _sidestep(grid, goal_middle, L, R, straight_side, along=True)
        staging_creep = staging is not None
    escape = _escape(grid, start_middle, L, R, side, straight_side)
    if staging is None:
        raise Infeasible(f"no staging point within {MAX_STAGING_M} m of the goal's middle ({g[0]:.2f}, {g[1]:.2f}) "
                         f"m lets the body turn {R:.2f} m clear of the obstacles")
    if escape is None:
        raise Infeasible(f"the body lying with its middle at ({a[0]:.2f}, {a[1]:.2f}) m can neither turn nor leave "
                         f"by a straight leg {R:.2f} m clear of the obstacles")
    escape_point, creep = escape
    staged, escaped = not np.array_equal(staging, g), not np.array_equal(escape_point, a)
    # the grid path kept DETOUR_M farther out where it costs little, so that its shortcuts (chords of the rounded
    # corners, each a turn and a run) are few
    clear = grid.clearance
    cells = astar(clear > R, grid.cell(escape_point), grid.cell(staging),
                  np.where(clear > R + DETOUR_M, 1.0, DETOUR_COST))
    if cells is None:
        raise Infeasible(f"no way {R:.2f} m clear of the obstacles from ({a[0]:.2f}, {a[1]:.2f}) m to "
                         f"({g[0]:.2f}, {g[1]:.2f}) m")
    points = [escape_point] + [grid.point(c) for c in cells[1:-1]] + [staging]
    points = shortcut(grid, points, R)
    if escaped:
        points.insert(0, a)
    points = _drop_short_legs(grid, points, R, 2 if escaped else 1)
    if staged:
        points.append(g)
    waypoints = np.array(points)
    headings: list[float] = []
    for k in range(1, len(waypoints)):
        d = waypoints[k] - waypoints[k - 1]
        if staged and k == len(waypoints) - 1:
            headings.append(goal_middle.yaw)
            continue
        if escaped and k == 1:
            headings.append(start_middle.yaw)
            continue
        square = math.atan2(d[1], d[0]) + 0.5 * math.pi  # the body square to the leg: either of two headings
        prev = headings[-1] if headings else start_middle.yaw
        options = (square, square + math.pi)
        headings.append(min(options, key=lambda h: abs(math.remainder(h - prev, 2 * math.pi))))
    return Route(waypoints, np.array(headings), staged, R, creep and escaped, escaped, staging_creep and staged)


#: A turning run is taken to turn by up to TURN_OVERSHOOT times what the rates predict (bench/RESULTS.md, "Gaits"),
#: and by TURN_SLACK_DEG more either way (a cycle's own sway).
TURN_OVERSHOOT = 2.0
TURN_SLACK_DEG = 5.0


def turn_slack(grid: ClearanceGrid, robot: SnakeRobot, start_middle: BasePlacement, end_middle: BasePlacement,
               scale: float = 1.0) -> float:
    """A lower bound of the distance (m) to the obstacles of a turning run at amplitude ``scale`` whose middle
    stays at ``start_middle`` and ``end_middle`` (predicted) and turns from the start's heading by up to
    TURN_OVERSHOOT times the predicted turn (the end's heading less the start's) and TURN_SLACK_DEG either way:
    the turning :func:`sweep_profile` at headings through that sector, so close that no point of the body moves
    more than ``pad`` between two (which the bound takes off); -inf when the sector reaches half a turn (then
    only the disc of :func:`swept_radius` bounds it)."""
    turn = math.remainder(end_middle.yaw - start_middle.yaw, 2.0 * math.pi)
    slack = math.radians(TURN_SLACK_DEG)
    lo, hi = min(0.0, TURN_OVERSHOOT * turn) - slack, max(0.0, TURN_OVERSHOOT * turn) + slack
    if hi - lo >= math.pi:
        return -math.inf
    reach = swept_radius(robot)
    step = 0.25 * grid.resolution / reach
    angles = start_middle.yaw + np.linspace(lo, hi, int(math.ceil((hi - lo) / step)) + 1)
    pad = reach * 0.5 * float(angles[1] - angles[0]) if len(angles) > 1 else 0.0
    profile = sweep_profile(robot, "turning", scale)
    middles = [np.array([start_middle.x, start_middle.y]), np.array([end_middle.x, end_middle.y])]
    return min(profile_slack(grid, m, float(h), profile) for m in middles for h in angles) - pad


def sweep_clear(grid: ClearanceGrid, robot: SnakeRobot, gait: str, start_middle: BasePlacement,
                end_middle: BasePlacement, scale: float = 1.0, margin: float = EXECUTION_M) -> bool:
    """Whether a gait run (``gait`` at amplitude ``scale``) that takes the body's middle from ``start_middle`` to
    ``end_middle`` (predicted) stays clear of the obstacles: turning, the disc of :func:`swept_radius` about the
    middle at both ends, or the sector it may turn through (:func:`turn_slack`), ``margin`` clear; sidewinding, its
    :func:`sweep_profile` at ``scale`` moved from start to end at the start's heading, and linear progression, the
    band of the straight body's half width about its axis, likewise: ``margin`` clear, or, where the run starts or
    ends nearer than that, no nearer than the nearer of its two ends and never touching."""
    robot = as_robot(robot)
    reach = swept_radius(robot)
    a = np.array([start_middle.x, start_middle.y])
    b = np.array([end_middle.x, end_middle.y])
    if gait == "turning":
        disc = min(grid.clearance_at(a)[0], grid.clearance_at(b)[0]) > reach + margin
        return bool(disc or turn_slack(grid, robot, start_middle, end_middle, scale) > margin)
    n = max(int(math.ceil(float(np.linalg.norm(b - a)) / (0.5 * grid.resolution))), 1)
    middles = [a + s * (b - a) for s in np.linspace(0.0, 1.0, n + 1)]
    if gait == "sidewinding":  # the slack beyond the profile's reach
        profile = sweep_profile(robot, gait, scale)
        slack = [profile_slack(grid, m, start_middle.yaw, profile) for m in middles]
    else:
        straight, L = half_width(robot), robot.body_length
        slack = [band_clearance(grid, m, start_middle.yaw, L) - straight for m in middles]
    need = min(margin, max(min(slack[0], slack[-1]), 1e-9))
    return bool(min(slack) >= need)
