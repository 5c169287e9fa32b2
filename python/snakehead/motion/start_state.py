"""The state a plan starts from: the bending state (Figs. 17b, 22a: the base on its arc, the neck and head curled
flat on the ground inside it, :func:`bending_state`), found by :func:`ground_curl`.

Why the bending state: on the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg); lifted as a
cantilever beyond P0 they would tip the body, so they are curled over the base before they rise."""
from __future__ import annotations

import numpy as np

from .._errors import Infeasible
from ..control.controller import HeadController
from ..dynamics import stability
from ..geometry import collision as coll
from ..model.robot import SnakeRobot
from .plan_cache import shape_key

LIFT_STEPS = 16  # waypoints of the lift from the bending state to the initial state
BENDING_GRID_DEG = 15.0  # deg: finest grid of the neck and head's yaw joints searched for the bending state
BENDING_COMBINATIONS = 30000  # the grid coarsens so that it never holds more curls than this
BENDING_CLEARANCE = 0.005  # m: least gap between non-neighbouring links of the bending state


def bending_state(controller: HeadController, q_shape: np.ndarray | None = None) -> np.ndarray:
    """The bending state (Figs. 17b, 22a): the base on its arc and the neck and head curled flat on the ground
    inside it, so that lifting them keeps their mass over the base (n,).

    On the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg): lifted from a straight line
    beyond P0 they tip the body. Here the pitch joints are 0 (everything lies on the ground) and the neck and
    head's yaw joints are chosen on a grid (15 deg, coarser for many joints) for the largest static margin over the
    base's support polygon alone (the support left once they are lifted), among the curls in which no two non-neighbouring links
    overlap. Deterministic. ``q_shape``: a configuration whose base (and the neck's links that stay on the ground)
    give the shape on the ground (default: the controller's initial configuration)."""
    robot = controller.robot
    shape = controller.q_initial if q_shape is None else np.asarray(q_shape, float)
    kept = controller.plan_cache.bending_states
    key = shape_key(shape, robot.lift_joints.start)
    q = kept.get(key)
    if q is None:
        q = kept.put(key, ground_curl(robot, shape))
    return q.copy()


def ground_curl(robot: SnakeRobot, shape: np.ndarray) -> np.ndarray:
    """:func:`bending_state` for the base shape of ``shape`` (n,), uncached. ValueError when no curl is stable."""
    q = np.zeros(robot.n_joints)
    # the base, and the links before the first pitch joint of the neck, which cannot leave the ground: their yaw
    # joints keep the shape's angles, or the lift would sweep those links across the ground and the friction would
    # push the base
    first_pitch = robot.lift_joints.start
    q[:first_pitch] = shape[:first_pitch]
    up = np.arange(robot.parts.neck.start, robot.parts.head.stop)
    yaw = np.array([j for j in up if robot.joint_kinds[j] == "yaw" and j > first_pitch], int)  # bend when flat
    if len(yaw) == 0:
        return q
    # the finest grid (at most BENDING_GRID_DEG) with at most BENDING_COMBINATIONS curls
    per_joint = max(3, min(int(round(180.0 / BENDING_GRID_DEG)) + 1,
                           int(np.floor(BENDING_COMBINATIONS ** (1.0 / len(yaw)) + 1e-9))))
    combos = np.stack(np.meshgrid(*[np.linspace(0.0, 1.0, per_joint)] * len(yaw), indexing="ij"), -1)
    combos = combos.reshape(-1, len(yaw))
    lo, hi = np.maximum(robot.lower[yaw], -np.pi / 2), np.minimum(robot.upper[yaw], np.pi / 2)
    qs = np.tile(q, (len(combos), 1))
    qs[:, yaw] = lo + combos * (hi - lo)
    poly = stability.support_polygon(robot, q)  # the base's, placement-independent in its own frame
    com = stability.center_of_mass(robot, qs)
    pts = np.broadcast_to(poly, (len(qs),) + poly.shape)
    margin = stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool), com[:, :2])
    order = np.argsort(-margin)
    stable = order[margin[order] > 0]
    for chunk in np.array_split(stable, max(1, stable.size // 500 + 1)) if stable.size else []:
        ok = coll.self_clearance(robot, qs[chunk]) > BENDING_CLEARANCE
        if ok.any():
            return qs[chunk[np.argmax(ok)]]
    raise Infeasible("no curl of the neck and head on the ground keeps their mass over the base (the base is too "
                     "short or light for them: 'snakehead info --robot FILE' suggests a split of the parts that works)")


__all__ = ["bending_state", "ground_curl", "LIFT_STEPS", "BENDING_GRID_DEG", "BENDING_COMBINATIONS",
           "BENDING_CLEARANCE"]
