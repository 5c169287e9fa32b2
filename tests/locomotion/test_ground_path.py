"""The body's route around obstacles (snakehead.locomotion.ground_path): A* against Dijkstra on the same graph
(scipy), the footprints' grid against the polygons, routes clear of the inflated obstacles (checked densely and
against the exact geometry of the straight body), and the shortcut never worse than the grid path."""
import math

import numpy as np
import pytest
from scipy.sparse import lil_matrix
from scipy.sparse.csgraph import dijkstra

from snakehead import BasePlacement, Infeasible, InputError, SnakeRobot
from snakehead.geometry.obstacles import BoxObstacle, WallWithHole
from snakehead.locomotion import ground_path as gp


def _dijkstra_cost(free, start, goal, weight=None):
    """The cheapest path's cost on the same 8-connected grid graph, by scipy's Dijkstra (brute force)."""
    H, W = free.shape
    idx = np.arange(H * W).reshape(H, W)
    G = lil_matrix((H * W, H * W))
    for i in range(H):
        for j in range(W):
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    n = (i + di, j + dj)
                    if (di or dj) and 0 <= n[0] < H and 0 <= n[1] < W and (free[n] or n == goal):
                        G[idx[i, j], idx[n]] = math.hypot(di, dj) * (1.0 if weight is None else weight[n])
    return dijkstra(G.tocsr(), indices=idx[start])[idx[goal]]


def _path_cost(path, weight=None):
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) * (1.0 if weight is None else weight[b])
               for a, b in zip(path, path[1:]))


def test_astar_is_shortest_against_dijkstra():
    rng = np.random.default_rng(0)
    for trial in range(12):
        free = rng.uniform(size=(14, 17)) > 0.3
        start, goal = (0, 0), (13, 16)
        free[start] = free[goal] = True
        weight = rng.uniform(1.0, 3.0, free.shape) if trial % 2 else None
        path = gp.astar(free, start, goal, weight)
        ref = _dijkstra_cost(free, start, goal, weight)
        if not np.isfinite(ref):
            assert path is None
            continue
        assert path[0] == start and path[-1] == goal
        assert all(free[c] for c in path[1:-1])
        assert all(max(abs(a[0] - b[0]), abs(a[1] - b[1])) == 1 for a, b in zip(path, path[1:]))
        assert _path_cost(path, weight) == pytest.approx(ref, rel=1e-12)


def test_footprint_grid_covers_the_obstacles():
    box = BoxObstacle.from_yaw([0.3, -0.2, 0.1], [0.4, 0.1, 0.2], 0.5)
    high = BoxObstacle([0.0, 1.0, 1.0], [0.2, 0.2, 0.2])  # floating above the body's reach
    grid = gp.clearance_grid([box, high], [[0.0, 0.0]], 0.3)
    assert len(gp.footprints([box, high])) == 1
    # every point inside the box's outline lies in an occupied cell; points 2 cells away from it are free
    rng = np.random.default_rng(1)
    R = box.rotation[:2, :2]
    inside = (rng.uniform(-0.5, 0.5, (500, 2)) * box.size[:2]) @ R.T + box.centre[:2]
    assert all(grid.occupied[grid.cell(p)] for p in inside)
    assert np.all(grid.clearance_at(inside) <= 0.0)
    far = box.centre[:2] + (np.array([0.2 + 3 * grid.resolution, 0.0]) @ R.T)
    assert not grid.occupied[grid.cell(far)]
    # the clearance field is a lower bound of the true distance to the box's outline
    extent = grid.resolution * (np.array(grid.occupied.shape[::-1]) - 1)
    pts = rng.uniform(grid.origin, grid.origin + extent, (300, 2))
    local = (pts - box.centre[:2]) @ R  # in the box's axes
    true = np.linalg.norm(np.maximum(np.abs(local) - 0.5 * box.size[:2], 0.0), axis=1)
    outside = true > 0
    assert np.all(grid.clearance_at(pts[outside]) <= true[outside] + 1e-9)
    assert np.all(grid.clearance_at(pts[outside]) >= true[outside] - 2 * math.sqrt(2) * grid.resolution - 1e-9)


@pytest.fixture(scope="module")
def robot():
    return SnakeRobot.default()


def _straight_body_distance(robot, middle, heading, obstacles):
    """The exact distance of the straight body lying with its middle at ``middle`` along ``heading`` to the
    obstacles (the geometry layer)."""
    from snakehead.collision import body_collisions as coll
    from snakehead.locomotion import goals as lc

    root = lc.compose(BasePlacement(middle[0], middle[1], heading), lc.inverse(lc.chassis_offset(robot)))
    return coll.collision_check(robot, np.zeros((1, robot.n_joints)), obstacles, root, exact_within=10.0).distance[0]


def test_route_around_a_wall_keeps_the_turning_disc_clear(robot):
    wall = WallWithHole.standing([0.2, 0.5, 0.4], [0, 1, 0], [0.7, 0.58, 0.01], 0.07)
    start = BasePlacement(-0.49, 1.4, math.pi)
    goal = BasePlacement(0.0, 0.287, 3.1248)
    route = gp.plan_route(robot, [wall], start, goal)
    assert route is not None and route.staging
    W = route.waypoints
    np.testing.assert_allclose(W[0], [start.x, start.y])
    np.testing.assert_allclose(W[-1], [goal.x, goal.y])
    assert len(W) <= 7  # a few legs, not the grid's steps
    R = route.clear_m
    assert R == pytest.approx(gp.swept_radius(robot) + gp.CLEARANCE_M)
    outlines = gp.footprints([wall])
    # every leg but the last keeps the turning disc's radius from the wall's outline (checked densely, exactly)
    for a, b in zip(W[:-2], W[1:-1]):
        for s in np.linspace(0, 1, 200):
            p = a + s * (b - a)
            assert min(_polygon_distance(p, poly) for poly in outlines) > R - 1e-9
    # the last leg: the straight body at the goal's heading, from the staging point to the goal, its sidewinding
    # band (the swept half width + EXECUTION_M about its axis) clear of the wall, or no nearer than at the goal
    _assert_straight_leg_keeps(robot, W[-1], W[-2], goal.yaw, [wall], gp.swept_half_width(robot) + gp.EXECUTION_M)
    # legs are square to the body's heading (the body sidewinds along them), but the staging leg's at the goal's
    for k, h in enumerate(route.headings[:-1]):
        d = W[k + 1] - W[k]
        assert abs(math.cos(h) * d[0] + math.sin(h) * d[1]) < 1e-9 * np.linalg.norm(d) + 1e-12
    assert route.headings[-1] == goal.yaw
    # nothing in the way: no route (the straight legs)
    assert gp.plan_route(robot, [wall], BasePlacement(-2.0, -1.0, 0.0), BasePlacement(-2.0, -2.0, 0.0)) is None
    assert gp.plan_route(robot, [], start, goal) is None


def _assert_straight_leg_keeps(robot, start, end, heading, obstacles, side):
    """The straight body's centre line, moved from ``start`` to ``end`` at ``heading``, keeps ``side`` from the
    obstacles or, where it lies nearer at ``start``, no nearer than there (the exact geometry; the grid's lower
    bound is conservative by at most two cell diagonals)."""
    w = gp.half_width(robot)
    keep = min(side, _straight_body_distance(robot, start, heading, obstacles) + w)
    for s in np.linspace(0, 1, 15)[1:]:
        p = start + s * (end - start)
        assert _straight_body_distance(robot, p, heading, obstacles) + w >= keep - 1e-6


def _polygon_distance(p, poly):
    """Distance from point p to a convex polygon (0 inside), brute force over its edges."""
    a, b = poly, np.roll(poly, -1, axis=0)
    e = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, e) / np.einsum("ij,ij->i", e, e), 0, 1)
    d = np.linalg.norm(a + t[:, None] * e - p, axis=1).min()
    cross = e[:, 0] * (p[1] - a[:, 1]) - e[:, 1] * (p[0] - a[:, 0])
    return 0.0 if np.all(cross >= 0) else d


def test_route_length_near_the_shortest_on_a_small_grid(robot):
    """Between two boxes: the route is no longer than the grid's cheapest path at the disc's clearance (A* on
    the same grid, unit weights, found by Dijkstra), within the detour's allowance."""
    boxes = [BoxObstacle([0.0, 0.0, 0.1], [0.3, 1.6, 0.2]), BoxObstacle([1.9, 1.0, 0.1], [0.3, 1.6, 0.2])]
    start, goal = BasePlacement(-1.2, 0.0, 0.0), BasePlacement(3.1, 0.9, 0.0)
    route = gp.plan_route(robot, boxes, start, goal)
    assert route is not None and not route.staging
    length = np.linalg.norm(np.diff(route.waypoints, axis=0), axis=1).sum()
    R = route.clear_m
    grid = gp.clearance_grid(boxes, [[start.x, start.y], [goal.x, goal.y]], R + gp.GRID_MARGIN_M)
    free = grid.distance - grid.resolution * math.sqrt(0.5) > R
    cells = gp.astar(free, grid.cell([start.x, start.y]), grid.cell([goal.x, goal.y]))
    shortest = _path_cost(cells) * grid.resolution
    assert length <= shortest * 1.15 + 0.2


def test_route_starts_by_sidestepping_when_the_body_cannot_turn_where_it_lies(robot):
    """A box beside the lying body, within its turning disc: the first leg sidewinds at the body's own heading,
    its straight footprint clear of the box, to where it can turn."""
    box = BoxObstacle([0.0, 0.45, 0.125], [0.25, 0.25, 0.25])
    start = BasePlacement(0.0, 0.0, 0.0)
    goal = BasePlacement(0.0, 2.5, 0.0)
    route = gp.plan_route(robot, [box], start, goal)
    assert route is not None
    W, R = route.waypoints, route.clear_m
    assert route.headings[0] == start.yaw and abs(W[1, 0] - W[0, 0]) < 1e-12  # square to the body: along y
    assert W[1, 1] < 0  # away from the box
    _assert_straight_leg_keeps(robot, W[0], W[1], start.yaw, [box], gp.swept_half_width(robot) + gp.EXECUTION_M)
    assert not route.creep
    box_outline = gp.footprints([box])
    for a, b in zip(W[1:-2], W[2:-1]):
        for s in np.linspace(0, 1, 100):
            assert min(_polygon_distance(a + s * (b - a), poly) for poly in box_outline) > R - 1e-9


def test_swept_extents_against_dense_sampling(robot):
    """The gaits' swept radius and half width: against the body's hull points sampled 4 times as densely over a
    cycle of each gait, in the frame of the link centres' principal axes found by an eigen-decomposition (not
    the SVD of virtual_chassis); the straight body's own reach is the smallest the radius can be."""
    from snakehead.locomotion.gaits import make_gait

    radius, half = gp.swept_extents(robot)
    ref_r = ref_w = 0.0
    for name in ("turning", "sidewinding"):
        for direction in (1, -1):
            g = make_gait(name, direction)
            t = g.ramp_s + np.linspace(0.0, g.period_s, 4 * gp.SWEEP_SAMPLES, endpoint=False)
            F = robot.frames_many(g.joint_angles(robot, t, 1.0))
            for c, pts in zip(robot.link_centres(F), robot.hull_points(F)):
                mid = c.mean(axis=0)
                w, v = np.linalg.eigh(np.cov((c - mid).T))
                x, y = v[:, 2], np.cross(v[:, 0] if v[2, 0] > 0 else -v[:, 0], v[:, 2])
                rel = pts.reshape(-1, 3) - mid
                ref_r = max(ref_r, float(np.hypot(rel @ x, rel @ y).max()))
                ref_w = max(ref_w, float(np.abs(rel @ y).max()))
    straight = robot.hull_points(robot.frames_many(np.zeros((1, robot.n_joints))))[0].reshape(-1, 3)
    centres = robot.link_centres(robot.frames_many(np.zeros((1, robot.n_joints))))[0]
    ref_r = max(ref_r, float(np.abs(straight[:, 0] - centres[:, 0].mean()).max()))
    assert radius == pytest.approx(ref_r, abs=0.003)
    assert half == pytest.approx(ref_w, abs=0.003)
    assert half > 3 * gp.half_width(robot)  # the sidewinding wave reaches far beyond the straight body's width


def _box_distance(box, pts):
    """Exact distance of points (P, 2) to a box's ground outline (closed form in the box's axes)."""
    R = box.rotation[:2, :2]
    local = (pts - box.centre[:2]) @ R
    return np.linalg.norm(np.maximum(np.abs(local) - 0.5 * box.size[:2], 0.0), axis=1)


def test_escape_along_the_axis_between_two_boxes(robot):
    """The body lying with its head between two boxes can neither turn nor sidewind: the route's first leg
    creeps back along its own axis (linear progression), its straight body no nearer the boxes than at the start
    (exact geometry), to where the turning disc is clear of their outlines."""
    from snakehead.locomotion import goals as lc

    boxes = [BoxObstacle([0.45, 0.3, 0.125], [0.25, 0.25, 0.25]), BoxObstacle([0.45, -0.3, 0.125], [0.25, 0.25, 0.25])]
    start = BasePlacement(0.0, 0.0, 0.0)  # the middle at the origin, the head towards +x between the boxes
    goal = BasePlacement(-0.5, 2.5, 0.0)
    route = gp.plan_route(robot, boxes, start, goal)
    W = route.waypoints
    assert route.creep and route.escape and route.headings[0] == start.yaw
    assert abs(W[1, 1]) < 1e-12 and W[1, 0] < 0  # back along the axis
    _assert_straight_leg_keeps(robot, W[0], W[1], start.yaw, boxes, gp.half_width(robot) + gp.EXECUTION_M)
    assert min(_box_distance(b, W[1][None])[0] for b in boxes) > route.clear_m - 2 * math.sqrt(2) * gp.RESOLUTION_M
    # the loop's step for that leg: linear progression towards the tail
    rates = lc.GaitRates.first_guess(robot)
    offset = lc.chassis_offset(robot)
    here = lc.compose(start, lc.inverse(offset))
    there = lc.compose(BasePlacement(W[1, 0], W[1, 1], start.yaw), lc.inverse(offset))
    step = lc.next_step(robot, here, there, rates, creep=True)
    assert (step.gait.name, step.gait.direction, step.leg) == ("linear_progression", -1, "along")
    # boxed in on every side: no route
    ring = boxes + [BoxObstacle([-0.95, 0.0, 0.125], [0.25, 1.0, 0.25]), BoxObstacle([1.1, 0.0, 0.125], [0.25, 1.0, 0.25]),
                    BoxObstacle([0.0, 0.6, 0.125], [2.5, 0.25, 0.25]), BoxObstacle([0.0, -0.6, 0.125], [2.5, 0.25, 0.25])]
    with pytest.raises(Infeasible, match="can neither turn nor leave by a straight leg"):
        gp.plan_route(robot, ring, start, goal)


def _run_outline(robot, gait: str, scale: float) -> np.ndarray:
    """(k, 2) m: the corners and edge midpoints of a ``gait`` run's shapes at ``scale`` (both directions, 24 phases,
    the ramps' half and full envelope) in each shape's virtual chassis (x forward, y left)."""
    from snakehead.locomotion.gaits import make_gait, virtual_chassis

    qs = [np.zeros((1, robot.n_joints))]
    for direction in (1, -1):
        g = make_gait(gait, direction)
        q = g.joint_angles(robot, g.ramp_s + np.linspace(0.0, g.period_s, 24, endpoint=False), 1.0)
        qs += [e * scale * q for e in (0.5, 1.0)]
    F = robot.frames_many(np.vstack(qs))
    local = []
    for c, p in zip(robot.link_centres(F), robot.hull_points(F)):
        T = virtual_chassis(c, forward=c[-1] - c[0])
        pts = np.concatenate([p, 0.5 * (p[:, :, None] + p[:, None, :]).reshape(len(p), -1, 3)], axis=1)
        local.append((pts.reshape(-1, 3) - T[:3, 3]) @ T[:3, :2])
    return np.concatenate(local)


def _swept_distance(robot, box, a, yaw, scale, moves, b=None):
    """The smallest exact distance to ``box`` of a sidewinding run's outline points (_run_outline) at ``scale``,
    the virtual chassis at ``moves`` points from ``a`` to ``b`` at heading ``yaw``."""
    b = a if b is None else b
    local = _run_outline(robot, "sidewinding", scale)
    R = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    return min(_box_distance(box, (a + s * (b - a)) + local @ R.T).min() for s in np.linspace(0.0, 1.0, moves))


def test_sweep_check_against_brute_force(robot):
    """sweep_clear against the exact distance of densely sampled swept points to a box: turning by half a turn or
    more (the disc of the swept radius about both ends; a smaller turn's sector: test_turn_slack_against_brute_force), sidewinding (its sweep profile, against the run's own shapes moved along) and
    linear progression (the straight body's band): sound (what it passes keeps the margin, or no less than its
    ends do) and not much stricter than the truth (a grid of two cell diagonals)."""
    box = BoxObstacle.from_yaw([0.0, 0.0, 0.125], [0.25, 0.25, 0.25], 0.3)
    radius, wave = gp.swept_extents(robot)
    straight, L, m = gp.half_width(robot), robot.body_length, gp.EXECUTION_M
    slack = 2 * math.sqrt(2) * gp.RESOLUTION_M
    rng = np.random.default_rng(3)
    seen = {True: 0, False: 0}
    for trial in range(60):
        gait = ("turning", "sidewinding", "linear_progression")[trial % 3]
        a = rng.uniform(-1.3, 1.3, 2)
        yaw = rng.uniform(-math.pi, math.pi)
        move = rng.uniform(-0.4, 0.4) * (np.array([-math.sin(yaw), math.cos(yaw)]) if gait == "sidewinding"
                                        else np.array([math.cos(yaw), math.sin(yaw)]))
        b = a + (move if gait != "turning" else 0.0)
        scale = rng.uniform(0.1, 1.0)
        grid = gp.clearance_grid([box], [a, b], 1.5)
        turn = 1.6 if gait == "turning" else 0.0  # a turn whose sector reaches half a turn: the disc alone
        ok = gp.sweep_clear(grid, robot, gait, BasePlacement(*a, yaw), BasePlacement(*b, yaw + turn), scale)
        seen[ok] += 1
        if gait == "turning":
            true = min(_box_distance(box, a[None])[0], _box_distance(box, b[None])[0])
            need = radius + m
        elif gait == "sidewinding":  # the run's shapes themselves, moved along: never touching, the margin where
            # both ends keep it (the profile's bins and samples: up to a few centimetres stricter than the truth)
            ends = [_swept_distance(robot, box, p, yaw, scale, 1) for p in (a, b)]
            true = _swept_distance(robot, box, a, yaw, scale, 12, b)
            if ok:
                assert true > 0.0, (trial, true)
                if min(ends) > m + 0.05:
                    assert true >= m - 1e-3, (trial, true)
            elif true > m + 0.06:
                pytest.fail(f"trial {trial}: sidewinding refused at {true:.3f} m")
            seen[ok] += 1
            continue
        else:
            axis = np.array([math.cos(yaw), math.sin(yaw)])
            width = straight + (scale * (wave - straight) if gait == "sidewinding" else 0.0)
            lines = [_box_distance(box, (a + s * (b - a))[None] + np.linspace(-0.5, 0.5, 300)[:, None] * L * axis).min()
                     for s in np.linspace(0, 1, 60)]
            true = min(lines)
            need = min(width + m, max(min(lines[0], lines[-1]), width))
        if ok:  # (the brute force samples the body every 4.6 mm: its minimum may be a millimetre high)
            assert true >= need - 1e-3, (trial, gait, true, need)
        elif true > need + slack + 0.01:
            pytest.fail(f"trial {trial}: {gait} refused at {true:.3f} m, {need:.3f} m needed")
    assert seen[True] > 5 and seen[False] > 5


def test_turn_slack_against_brute_force(robot):
    """turn_slack: a lower bound of the exact distance to a box of a turning run's own shapes (corners and edge
    midpoints; both directions, 24 phases, the ramps' half and full envelope) turned about the middle through the
    sector it bounds (TURN_OVERSHOOT times the predicted turn, TURN_SLACK_DEG either way), and not much below
    it; -inf where the sector reaches half a turn."""
    box = BoxObstacle.from_yaw([0.0, 0.0, 0.125], [0.25, 0.25, 0.25], 0.3)
    rng = np.random.default_rng(5)
    finite = 0
    for trial in range(12):
        a = rng.uniform(-1.2, 1.2, 2)
        yaw, turn, scale = rng.uniform(-math.pi, math.pi), rng.uniform(-0.8, 0.8), rng.uniform(0.1, 1.0)
        grid = gp.clearance_grid([box], [a], 1.5)
        slack = gp.turn_slack(grid, robot, BasePlacement(*a, yaw), BasePlacement(*a, yaw + turn), scale)
        lo = min(0.0, gp.TURN_OVERSHOOT * turn) - math.radians(gp.TURN_SLACK_DEG)
        hi = max(0.0, gp.TURN_OVERSHOOT * turn) + math.radians(gp.TURN_SLACK_DEG)
        if hi - lo >= math.pi:
            assert slack == -math.inf
            continue
        finite += 1
        local = _run_outline(robot, "turning", scale)
        true = min(_box_distance(box, a + local @ np.array([[math.cos(h), -math.sin(h)], [math.sin(h), math.cos(h)]]).T
                                 ).min() for h in yaw + np.linspace(lo, hi, 90))
        assert true >= slack - 1e-3, (trial, true, slack)
        if true > 0.0:  # (the exact distance stops at 0 inside the box)
            assert slack > true - 2 * math.sqrt(2) * gp.RESOLUTION_M - 0.02, (trial, true, slack)  # grid, bins
    assert finite >= 4


def test_staging_on_the_goal_axis_when_none_across(robot):
    """A goal whose across-axis runs beside a long wall (no point on it within MAX_STAGING_M lets the body turn
    with the whole clearance budget): the last leg comes from a staging point on the goal's own axis, away from the
    wall, where the turning disc keeps the budget; the body creeps from there at the goal's heading, its straight
    band no nearer the wall than at the goal (exact geometry)."""
    from snakehead.locomotion import goals as lc

    wall = BoxObstacle([0.85, 0.0, 0.15], [0.05, 6.0, 0.3])
    goal, start = BasePlacement(0.0, 0.0, 0.0), BasePlacement(-2.0, 1.0, 0.0)
    route = gp.plan_route(robot, [wall], start, goal)
    W = route.waypoints
    assert route.staging and route.staging_creep and not route.escape
    assert route.headings[-1] == goal.yaw
    assert abs(W[-2, 1]) < 1e-9 and W[-2, 0] < 0.0  # on the goal's axis, away from the wall
    assert _box_distance(wall, W[-2][None])[0] > route.clear_m
    assert route.clear_m == pytest.approx(gp.swept_radius(robot) + gp.CLEARANCE_M)
    _assert_straight_leg_keeps(robot, W[-2], W[-1], goal.yaw, [wall], gp.half_width(robot) + gp.EXECUTION_M)
    # the loop's step for it once the body faces the goal's way: linear progression towards the head
    rates = lc.GaitRates.first_guess(robot)
    offset = lc.chassis_offset(robot)
    here = lc.compose(BasePlacement(W[-2, 0], W[-2, 1], goal.yaw), lc.inverse(offset))
    step = lc.next_step(robot, here, lc.compose(goal, lc.inverse(offset)), rates, creep=True)
    assert (step.gait.name, step.gait.direction, step.leg) == ("linear_progression", 1, "along")


@pytest.mark.parametrize("gait, scale", [("rolling", 0.5), (None, 0.5), ("sidewinding", float("nan")),
                                         ("turning", -0.2), ("sidewinding", float("inf")), ("sidewinding", "big")])
def test_sweep_profile_refuses_bad_arguments(robot, gait, scale):
    with pytest.raises(InputError, match="gait|scale"):
        gp.sweep_profile(robot, gait, scale)
