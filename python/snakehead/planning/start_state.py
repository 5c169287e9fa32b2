"""The state a plan starts from: the bending state (Figs. 17b, 22a: the base on its arc, the neck and head curled
flat on the ground inside it, :func:`bending_state`), found by :func:`ground_curl`.

Why the bending state: on the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg); lifted as a
cantilever beyond P0 they would tip the body, so they are curled over the base before they rise."""
from __future__ import annotations

from typing import Callable

import numpy as np

from .._errors import Infeasible
from ..collision import body_collisions as coll
from ..dynamics import stability
from ..model.robot import BasePlacement, SnakeRobot
from ..solve.head_controller import HeadController
from .plan_cache import plan_cache_of, shape_key
from .waypoints import Waypoints

LIFT_STEPS = 16  # waypoints of the lift from the bending state to the initial state
BENDING_GRID_DEG = 15.0  # deg: finest grid of the neck and head's yaw joints searched for the bending state
BENDING_COMBINATIONS = 30000  # the grid coarsens so that it never holds more curls than this
BENDING_CLEARANCE = 0.005  # m: least gap between non-neighbouring links of the bending state
#: m: bound on the difference between ground_curl's fast margins and the exhaustive ones (both the same sums
#: in double precision, ~1e-15 m apart on a robot of metres: a million times that)
CURL_MARGIN_SLACK = 1e-9
#: Curls spread over all of them whose composed centre of mass ground_curl checks against the robot's own (a chain
#: the composition does not model then falls back to the exhaustive search).
CURL_COM_SPREAD = 16
#: On a slope, when the initial state is not safe at the plan's base (its weight leans), the lift ends instead at the
#: safe configuration nearest it among LEAN_LIFT_TRIALS draws per spread of the neck and head joints around it (rad,
#: LEAN_LIFT_SPREADS, seeded: plans are reproducible): a lifted state from which the targets are moved to as on
#: flat ground, rather than a move from the curl on the ground straight to the target.
LEAN_LIFT_SPREADS = (0.1, 0.2, 0.35, 0.5, 0.7)
LEAN_LIFT_TRIALS = 128
LEAN_LIFT_SEED = 20231
#: the lifted states :func:`lean_lift_ends` hands out by default: those the lift is tried to by a whole-body move
#: (with its detours) when none of the LEAN_LIFT_SCREEN first is reached by a tracked path that passes its checks
LEAN_LIFT_TRIES = 3
LEAN_LIFT_SCREEN = 48


def shape_of(robot: SnakeRobot, q_shape: np.ndarray, q_rest: np.ndarray) -> np.ndarray:
    """``q_rest`` with the joints of the links lying on the ground (the base's, and the neck's before it lifts)
    taken from ``q_shape``."""
    q = np.asarray(q_rest, float).copy()
    q[:robot.lift_joints.start] = q_shape[:robot.lift_joints.start]
    return q


def bending_state(controller: HeadController, q_shape: np.ndarray | None = None,
                  base: BasePlacement | None = None) -> np.ndarray:
    """The bending state (Figs. 17b, 22a): the base on its arc and the neck and head curled flat on the ground
    inside it, so that lifting them keeps their mass over the base (n,).

    On the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg): lifted from a straight line
    beyond P0 they tip the body. Here the pitch joints are 0 (everything lies on the ground) and the neck and
    head's yaw joints are chosen on a grid (15 deg, coarser for many joints) for the largest static margin over the
    base's support polygon alone (the support left once they are lifted), among the curls in which no two non-neighbouring links
    overlap. Deterministic. ``q_shape``: a configuration whose base (and the neck's links that stay on the ground)
    give the shape on the ground (default: the controller's initial configuration). ``base``: where the base lies;
    on a slope the margin is that of the CoM's point below it along the leaning gravity (:func:`ground_curl`), and
    the curl is kept for that ground and heading only (on flat ground, or without ``base``, for the shape)."""
    robot = controller.robot
    shape = controller.q_initial if q_shape is None else np.asarray(q_shape, float)
    kept = plan_cache_of(controller).bending_states
    key = shape_key(shape, robot.lift_joints.start)
    lean = base is not None and not base.on_flat_ground
    if lean:  # a slope's curl is never reused at another heading or on another ground
        assert base is not None
        key += repr((base.ground, base.yaw)).encode()
    q = kept.get(key)
    if q is None:
        q = kept.put(key, ground_curl(robot, shape, base if lean else None))
    return q.copy()


def lift_ends_safe(controller: HeadController, q_shape: np.ndarray, base: BasePlacement | None = None) -> bool:
    """Whether the lift from the bending state ends in a safe state on a base of the flat shape of ``q_shape``: the
    initial state's neck and head on that base (``planning.planner._lift``'s end) above the ground, clear of itself
    and statically stable with DETOUR_MARGIN (``Waypoints.feasible``; the same at every placement on the flat
    ground; obstacles are the plan's to check). Without it the plan's first move goes from the curl on the ground
    straight to the target, for which there is often no safe path. ``base`` off flat ground: at its ground and
    heading, where the weight leans, the initial state or one of the lifted states near it that the plan then
    lifts to (:func:`lean_lift_ends`)."""
    q = shape_of(controller.robot, np.asarray(q_shape, float), controller.q_initial)
    at = _leaning(base)
    if at is None:
        return bool(Waypoints(controller.robot, BasePlacement()).feasible(q[None])[0])
    way = Waypoints(controller.robot, at)
    return bool(way.feasible(q[None])[0]) or bool(lean_lift_ends(way, q, way.feasible))


def lean_lift_ends(way: Waypoints, q: np.ndarray, safe: Callable[[np.ndarray], np.ndarray],
                   most: int = LEAN_LIFT_TRIES) -> list[np.ndarray]:
    """Safe lifted states near the initial state q (n,) on a slope (``way.base`` off flat ground), where q itself is
    not safe: configurations with q's joints before the lift (the base on the ground keeps its shape) and the neck
    and head joints drawn around q's (LEAN_LIFT_SPREADS, LEAN_LIFT_TRIALS each, seeded), which ``safe`` (m, n) -> (m,)
    bool passes (``Waypoints.feasible`` and the obstacles'), at most ``most`` of them, those of the smallest spread
    first, the steadiest first among them (their static margin); none when no draw passes."""
    robot = way.robot
    movable = np.arange(robot.lift_joints.start, robot.parts.head.stop)
    rng = np.random.default_rng(LEAN_LIFT_SEED)
    found: list[np.ndarray] = []
    for spread in LEAN_LIFT_SPREADS:
        W = np.tile(q, (LEAN_LIFT_TRIALS, 1))
        W[:, movable] += rng.normal(0.0, spread, (LEAN_LIFT_TRIALS, len(movable)))
        W = np.clip(W, robot.lower, robot.upper)
        ok = np.flatnonzero(safe(W))
        if ok.size:
            steady = ok[np.argsort(-way.static_margins(W[ok]), kind="stable")]
            found += [W[k] for k in steady[:most - len(found)]]
        if len(found) >= most:
            break
    return found


def ground_curl(robot: SnakeRobot, shape: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
    """:func:`bending_state` for the base shape of ``shape`` (n,), uncached. ``Infeasible`` when no curl is stable.
    ``base`` off flat ground: the margins are those of the CoM's point below it along that ground's gravity, the
    base at its heading (where it lies on the plane does not matter); else (default) on flat ground.

    The curl :func:`ground_curl_exhaustive` finds (the largest margin among the curls clear of themselves, every
    curl's margin from the robot's own kinematics), found without the kinematics of every curl: the margins from
    the chain's transforms composed joint by joint (``_curl_com``, ``_line_margins``: the same to
    round-off, far below CURL_MARGIN_SLACK); the curls are checked for self-clearance in that order until one
    passes, and the exhaustive margins then rank the curls whose fast margin is within twice the slack of that
    one's (every curl that can be ranked before the answer: the result is the exhaustive one's)."""
    q, yaw, values = _curl_grid(robot, shape)
    if len(yaw) == 0:
        return q
    at = _leaning(base)
    poly = stability.support_polygon(robot, q, at)  # the base's, placement-independent in its own frame
    com = _curl_com(robot, q, yaw, values, at)
    hull = poly[stability.hull_indices(poly)]
    if len(hull) < 3:  # no interior (collinear points): every margin is at most 0, no curl is stable
        raise Infeasible(_NO_CURL)
    fast = _line_margins(hull, com)
    order = np.argsort(-fast, kind="stable")
    order = order[fast[order] > -CURL_MARGIN_SLACK]  # every stable curl (exact margin > 0) is among these
    first, done, size = None, 0, 32
    while first is None and done < order.size:  # growing chunks: the first few pass on most shapes
        chunk = order[done:done + size]
        ok = coll.self_clearance(robot, _curl_configurations(q, yaw, values, chunk)) > BENDING_CLEARANCE
        first = chunk[np.argmax(ok)] if ok.any() else None
        done, size = done + size, min(2 * size, 1024)
    if first is None:
        raise Infeasible(_NO_CURL)
    near = order[fast[order] >= fast[first] - 2.0 * CURL_MARGIN_SLACK]
    # the robot's own centres of mass of those, and of a spread of all the curls, which the fast ones must equal
    rows = np.unique(np.concatenate([near, np.linspace(0, len(com) - 1, CURL_COM_SPREAD).astype(int)]))
    qs = _curl_configurations(q, yaw, values, rows)
    exact_com = _com_below(robot, qs, at)
    if np.abs(exact_com - com[rows]).max() > CURL_MARGIN_SLACK / 4:  # a chain the composition does not model
        if at is None:
            return ground_curl_exhaustive(robot, shape)
        qs = _curl_configurations(q, yaw, values, np.arange(values.shape[1] ** len(yaw)))  # every curl, exactly
        exact_com = _com_below(robot, qs, at)
    else:
        keep = np.isin(rows, near)
        qs, exact_com = qs[keep], exact_com[keep]
    margin = stability.polygon_margin_many(np.broadcast_to(poly, (len(qs),) + poly.shape),
                                           np.ones((len(qs), len(poly)), bool), exact_com)
    ranked = np.argsort(-margin, kind="stable")  # ties in curl order, as the exhaustive search ranks them (the
    ranked = ranked[margin[ranked] > 0]  # default sort orders ties by the CPU's vector width: AVX-512, AVX2)
    for chunk in np.array_split(ranked, max(1, ranked.size // 500 + 1)) if ranked.size else []:
        ok = coll.self_clearance(robot, qs[chunk]) > BENDING_CLEARANCE
        if ok.any():
            return qs[chunk[np.argmax(ok)]]
    raise Infeasible(_NO_CURL)


def _leaning(base: BasePlacement | None) -> BasePlacement | None:
    """The placement the curls are weighed at on a slope (``base``'s ground and heading, at the ground's origin);
    None on flat ground."""
    if base is None or base.on_flat_ground:
        return None
    return BasePlacement(0.0, 0.0, base.yaw, base.ground)


def _com_below(robot: SnakeRobot, qs: np.ndarray, at: BasePlacement | None) -> np.ndarray:
    """The (x, y) of the centres of mass of configurations qs (m, n): on flat ground (``at`` None) at the default
    placement; on a slope the ground points below them along the leaning gravity, the base at ``at``."""
    if at is None:
        return stability.center_of_mass(robot, qs)[:, :2]
    return at.below_along_gravity(stability.center_of_mass(robot, qs, at))


def ground_curl_exhaustive(robot: SnakeRobot, shape: np.ndarray) -> np.ndarray:
    """:func:`ground_curl` by the robot's kinematics at every curl of the grid (its reference; 28,561 curls on the
    default robot)."""
    q, yaw, values = _curl_grid(robot, shape)
    if len(yaw) == 0:
        return q
    qs = _curl_configurations(q, yaw, values, np.arange(values.shape[1] ** len(yaw)))
    poly = stability.support_polygon(robot, q)  # the base's, placement-independent in its own frame
    com = stability.center_of_mass(robot, qs)
    pts = np.broadcast_to(poly, (len(qs),) + poly.shape)
    margin = stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool), com[:, :2])
    order = np.argsort(-margin, kind="stable")  # ties in curl order, on any machine
    stable = order[margin[order] > 0]
    for chunk in np.array_split(stable, max(1, stable.size // 500 + 1)) if stable.size else []:
        ok = coll.self_clearance(robot, qs[chunk]) > BENDING_CLEARANCE
        if ok.any():
            return qs[chunk[np.argmax(ok)]]
    raise Infeasible(_NO_CURL)


_NO_CURL = ("no curl of the neck and head on the ground keeps their mass over the base (the base is too short or "
            "light for them: 'snakehead info --robot FILE' suggests a split of the parts that works)")


def _curl_grid(robot: SnakeRobot, shape: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The curls' common part q (n,): the base's shape, everything else 0; the yaw joints they bend (k,); each
    one's angles on the grid (k, p): the curls are every combination, the first joint's angle the slowest."""
    q = np.zeros(robot.n_joints)
    # the base, and the links before the first pitch joint of the neck, which cannot leave the ground: their yaw
    # joints keep the shape's angles, or the lift would sweep those links across the ground and the friction would
    # push the base
    first_pitch = robot.lift_joints.start
    q[:first_pitch] = shape[:first_pitch]
    up = np.arange(robot.parts.neck.start, robot.parts.head.stop)
    yaw = np.array([j for j in up if robot.joint_kinds[j] == "yaw" and j > first_pitch], int)  # bend when flat
    # the finest grid (at most BENDING_GRID_DEG) with at most BENDING_COMBINATIONS curls
    per_joint = max(3, min(int(round(180.0 / BENDING_GRID_DEG)) + 1,
                           int(np.floor(BENDING_COMBINATIONS ** (1.0 / max(len(yaw), 1)) + 1e-9))))
    lo, hi = np.maximum(robot.lower[yaw], -np.pi / 2), np.minimum(robot.upper[yaw], np.pi / 2)
    values = lo[:, None] + np.linspace(0.0, 1.0, per_joint)[None, :] * (hi - lo)[:, None]
    return q, yaw, values


def _curl_configurations(q: np.ndarray, yaw: np.ndarray, values: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The curls numbered ``rows`` of the grid (:func:`_curl_grid`) as configurations (len(rows), n)."""
    digits = np.unravel_index(np.asarray(rows, int), (values.shape[1],) * len(yaw))
    qs = np.tile(q, (len(digits[0]), 1))
    for j, d in enumerate(digits):
        qs[:, yaw[j]] = values[j, d]
    return qs


def _curl_com(robot: SnakeRobot, q: np.ndarray, yaw: np.ndarray, values: np.ndarray,
              at: BasePlacement | None = None) -> np.ndarray:
    """World (x, y) of the centre of mass of every curl of the grid (p**k, 2), the base at its default placement
    (``at``, on a slope: the ground point below it along the leaning gravity, the base at ``at``).

    The links turned by the i-th curl joint and by no later one move rigidly with its child link: their mass
    moment is that link's frame times a fixed vector, and that frame is the previous curl joint's child's times a
    fixed transform and the joint's own turn. Composed joint by joint, p + p**2 + ... + p**k products instead of
    every link's frame at every curl."""
    F0 = robot.body.fk_all(q)  # the curl joints at 0
    m, M = robot.masses, robot.masses.sum()
    moment = m[:, None] * np.einsum("lij,lj->li", F0[:, :3], np.c_[robot.coms, np.ones(len(m))])  # (L, 3)
    turns, moved = [], []
    for j, v in zip(yaw, values):
        qv = np.tile(q, (len(v), 1))
        qv[:, j] = v
        F = robot.body.fk_all_many(qv)
        links = np.flatnonzero(np.abs(F - F0).max(axis=(0, 2, 3)) > 0)
        turns.append(np.linalg.inv(F0[links[0]]) @ F[:, links[0]])  # (p, 4, 4): the child's own turn
        moved.append(links)
    total = moment[np.setdiff1d(np.arange(len(m)), moved[0])].sum(axis=0)[None]  # (1, 3)
    prev = np.eye(4)
    frames = np.eye(4)[None]  # the previous child link's frames at the curls so far
    for i, (links, turn) in enumerate(zip(moved, turns)):
        child = links[0]
        group = np.setdiff1d(links, moved[i + 1]) if i + 1 < len(moved) else links
        inv_child = np.linalg.inv(F0[child])
        local = inv_child[:3, :3] @ moment[group].sum(axis=0) + inv_child[:3, 3] * m[group].sum()
        frames = (frames[:, None] @ (np.linalg.inv(prev) @ F0[child] @ turn)[None]).reshape(-1, 4, 4)
        prev = F0[child]
        part = frames[:, :3, :3] @ local + frames[:, :3, 3] * m[group].sum()  # (p**(i+1), 3)
        total = (total[:, None] + part.reshape(len(total), -1, 3)).reshape(-1, 3)
    if at is not None:
        W = robot.root_pose(at)
        return at.below_along_gravity((total / M) @ W[:3, :3].T + W[:3, 3])
    W = robot.root_pose(stability.as_base(None))
    return (total / M) @ W[:2, :3].T + W[:2, 3]


def _line_margins(hull: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """(N,) least signed distance (m) of points xy (N, 2) to the lines of a convex polygon's edges (hull (k, 2)
    counter-clockwise), positive inside: inside, the distance to the boundary (the margin); outside, not above 0."""
    a, edge = hull, np.roll(hull, -1, axis=0) - hull
    cross = edge[:, 0] * (xy[:, None, 1] - a[:, 1]) - edge[:, 1] * (xy[:, None, 0] - a[:, 0])
    return (cross / np.hypot(edge[:, 0], edge[:, 1])).min(axis=1)


__all__ = ["shape_of", "bending_state", "lift_ends_safe", "lean_lift_ends", "LEAN_LIFT_SPREADS", "LEAN_LIFT_TRIALS",
           "LEAN_LIFT_SEED", "LEAN_LIFT_TRIES", "LEAN_LIFT_SCREEN", "ground_curl", "ground_curl_exhaustive", "CURL_MARGIN_SLACK", "CURL_COM_SPREAD", "LIFT_STEPS", "BENDING_GRID_DEG", "BENDING_COMBINATIONS",
           "BENDING_CLEARANCE"]
