"""The body's path over the ground around the scene's obstacles, for the closed loop's locomotion
(:mod:`snakehead.motion.locomotion`): where the straight body's middle (its virtual chassis,
:func:`~snakehead.motion.locomotion.chassis_offset`) passes on its way from where it lies to where the curl into
the bending state must start.

Why the body's middle as a disc: the gaits are turning in place (the straight body sweeps the disc of half its
length about its middle) and sidewinding (it sweeps the band of its length, square to its axis, along the way).
Both stay inside the disc of radius L / 2 swept along the middle's path. So the middle's path is planned on a grid
(:data:`RESOLUTION_M`) over the free space of the obstacles' footprints (the ground-level outline of their convex
shapes) inflated by L / 2 plus a clearance: grid A* (8-connected, octile heuristic: :func:`astar`), then shortcut
by line of sight (:func:`shortcut`). The body then turns at each waypoint square to the next leg and sidewinds
along it.

The goal itself usually lies nearer an obstacle than that (the bending state stands beside the wall whose hole
the head goes through): the last leg comes from a *staging point* on the goal's own across-axis
(:func:`plan_route`), where the body can turn, then sidewinds at the goal's heading to the goal, its straight
footprint (the body's centre line inflated by half its width plus the clearance) kept clear on the way.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from ..model.robot import BasePlacement, SnakeRobot, as_robot

#: Grid resolution (m).
RESOLUTION_M = 0.025
#: Clearance (m) kept from every obstacle beyond the body's own extent (the gaits' execution errors: a sidewinding
#: run goes a few centimetres off its line, a turn shifts the middle by a few).
CLEARANCE_M = 0.08
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
        from scipy.ndimage import distance_transform_edt

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
    from scipy.spatial import ConvexHull

    from ..geometry.shapes import shape_points

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


def body_clear(grid: ClearanceGrid, middle: np.ndarray, heading: float, length: float, radius: float) -> bool:
    """Whether the straight body (its centre line of ``length`` m about ``middle`` along ``heading`` rad) keeps
    ``radius`` m from the obstacles."""
    a = np.array([math.cos(heading), math.sin(heading)])
    return segment_clear(grid, middle - 0.5 * length * a, middle + 0.5 * length * a, radius)


@dataclass
class Route:
    """The middle's way to the goal: ``waypoints`` (K, 2) m (the start's middle first, the goal's last), each
    leg's body heading ``headings`` (K - 1,) rad (square to the leg; the last leg's is the goal's heading, from the
    staging point), ``staging``: whether the last leg comes from a staging point; ``clear_m``: the turning disc's
    radius the path keeps from the obstacles (L / 2 + clearance)."""

    waypoints: np.ndarray
    headings: np.ndarray
    staging: bool
    clear_m: float


def half_width(robot: SnakeRobot) -> float:
    """Half the straight body's width seen from above (m): the farthest its shapes reach from its axis."""
    robot = as_robot(robot)
    frames = robot.frames(np.zeros(robot.n_joints), BasePlacement())[None]  # the body frame: x along the body
    return float(np.abs(robot.hull_points(frames)[..., 1]).max())


def _sidestep(grid: ClearanceGrid, middle: BasePlacement, length: float, radius: float, side: float
              ) -> np.ndarray | None:
    """Where the body lying straight with its middle at ``middle`` can turn (``radius`` clear), reached by
    sidewinding square to its axis at its own heading with its centre line ``side`` clear all the way: the middle
    itself when it can turn there, else the nearest such point along its across-axis (MAX_STAGING_M at most), or
    None."""
    m = np.array([middle.x, middle.y])
    if grid.clearance_at(m)[0] > radius:
        return m
    n = np.array([-math.sin(middle.yaw), math.cos(middle.yaw)])
    step = grid.resolution
    for s in np.arange(step, MAX_STAGING_M, step):
        for sign in (1.0, -1.0):
            p = m + sign * s * n
            if grid.clearance_at(p)[0] > radius and all(
                    body_clear(grid, m + sign * t * n, middle.yaw, length, side) for t in np.arange(0.0, s + 1e-9, step)):
                return p
    return None


def plan_route(robot: SnakeRobot, obstacles: Sequence[Any], start_middle: BasePlacement, goal_middle: BasePlacement,
               *, clearance: float = CLEARANCE_M, resolution: float = RESOLUTION_M) -> Route | None:
    """The route of the straight body's middle from ``start_middle`` to ``goal_middle`` (placements of the virtual
    chassis: x, y m and the body's heading rad) around ``obstacles`` (see the module), or None when the straight
    legs of :func:`snakehead.motion.locomotion.next_step` are already clear of them (no obstacle within the turning
    disc of the start or along the way) or no route exists."""
    robot = as_robot(robot)
    L = robot.body_length
    R = 0.5 * L + clearance
    side = half_width(robot) + clearance
    a, g = np.array([start_middle.x, start_middle.y]), np.array([goal_middle.x, goal_middle.y])
    if not obstacles:
        return None
    grid = clearance_grid(obstacles, [a, g], 0.5 * L + clearance + GRID_MARGIN_M, resolution)
    # next_step's own legs (turn at the start, sidewind along the goal's axis to the corner, turn there, sidewind
    # across to the goal) swept within the discs along them: clear, no route needed
    axis = np.array([math.cos(goal_middle.yaw), math.sin(goal_middle.yaw)])
    corner = g + ((a - g) @ (axis[::-1] * [-1.0, 1.0])) * (axis[::-1] * [-1.0, 1.0])
    if segment_clear(grid, a, corner, R) and segment_clear(grid, corner, g, R):
        return None
    # the last leg: from a staging point on the goal's across-axis, the body at the goal's heading; the first, when
    # the body cannot turn where it lies: sidewinding at its own heading to where it can
    staging = _sidestep(grid, goal_middle, L, R, side)
    escape = _sidestep(grid, start_middle, L, R, side)
    if staging is None or escape is None:
        return None
    staged, escaped = not np.array_equal(staging, g), not np.array_equal(escape, a)
    # the grid path kept DETOUR_M farther out where it costs little, so that its shortcuts (chords of the rounded
    # corners, each a turn and a run) are few
    clear = grid.clearance
    cells = astar(clear > R, grid.cell(escape), grid.cell(staging), np.where(clear > R + DETOUR_M, 1.0, DETOUR_COST))
    if cells is None:
        return None
    points = [escape] + [grid.point(c) for c in cells[1:-1]] + [staging]
    points = shortcut(grid, points, R)
    if escaped:
        points.insert(0, a)
    # a leg shorter than MIN_LEG_M (the grid's snap next to the staging point) is no leg: its turn costs a run
    keep = {0, len(points) - 1} | ({1} if escaped else set())
    points = [p for k, p in enumerate(points) if k in keep or float(np.linalg.norm(points[k + 1] - p)) >= MIN_LEG_M]
    if staged:
        points.append(g)
    waypoints = np.array(points)
    headings = []
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
    return Route(waypoints, np.array(headings), staged, R)
