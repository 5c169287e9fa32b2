"""Head targets for measuring a planner: reachable by construction, or random around the robot.

A target is *reachable by construction* when it is the head pose of a whole-body configuration that the robot
can hold: statically stable (the centre of mass inside the support polygon of the links on the ground by
``min_margin``, and inside the base's own: a neck or head link resting on the ground does not hold the body up),
every neck and head link above the ground (those after the first link the neck lifts, which pivots on its edge,
by ``TARGET_GROUND_CLEARANCE``), no two links touching. The base's own support is that of the links
lying on the ground whatever the pose (``solve.whole_body.BodyProblem.ground_links``: the base's, and on a neck
that begins with yaw joints the links before it lifts), as the whole-body solve checks its solutions
(``check_solution(problem=)``). Three kinds (``KINDS``):

* ``"same"`` -- the base keeps the planner's initial configuration (its optimised arc) at the planner's
  placement; the neck and head joints are drawn uniformly within their limits;
* ``"shape"`` -- the base lies in another flat shape (its yaw joints drawn uniformly, its pitch joints flat);
* ``"place"`` -- the base as in ``"same"`` but placed elsewhere (x, y uniform in +-``reach`` m, any yaw).

``random_targets`` draws positions uniformly in a box around the robot and directions uniformly on the sphere:
some are out of reach, which is what they are for (the planner must say why it fails).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._errors import Infeasible, InputError
from ..collision import body_collisions as coll
from ..dynamics import stability
from ..model.robot import BasePlacement
from ..solve.whole_body import MIN_MARGIN

if TYPE_CHECKING:
    from ..solve.head_controller import HeadController

KINDS = ("same", "shape", "place")

#: How far (m) the links after the first one the neck lifts (which pivots on its edge on the ground) keep above the
#: ground in a target's pose: a head resting on the ground is a contact the plan does not count on. (The planner's
#: own solutions may still let a lifted link touch the ground, within GROUND_TOLERANCE: not changed here.)
TARGET_GROUND_CLEARANCE = 0.002


@dataclass(frozen=True)
class ReachableTarget:
    """A head target (position (3,) m, unit direction (3,)) and the configuration and placement it comes from."""

    position: np.ndarray
    direction: np.ndarray
    q: np.ndarray
    base: BasePlacement
    kind: str


def reachable_targets(controller: HeadController, kind: str, count: int, rng: np.random.Generator | None = None, *,
                      min_margin: float = MIN_MARGIN, reach: float = 1.0, max_draws: int = 200000) -> list[ReachableTarget]:
    """``count`` targets reachable by construction of the given ``kind`` (see the module's docstring) for the
    controller's robot, from its initial configuration and placement."""
    if kind not in KINDS:
        raise InputError(f"kind must be one of {KINDS}, got {kind!r}")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 0:
        raise InputError(f"count must be an integer >= 0, got {count!r}")
    robot = controller.robot
    prob = controller.body_problem
    rng = np.random.default_rng() if rng is None else rng
    lift = np.arange(robot.lift_joints.start, robot.n_joints)
    ground_yaw = np.array([j for j in range(robot.lift_joints.start) if robot.joint_kinds[j] == "yaw"], int)
    lifted = robot.lifted_links
    pivot = int(robot.joint_frames[robot.lift_joints.start]) if robot.lift_joints.start < robot.n_joints else -1
    out: list[ReachableTarget] = []
    for _ in range(int(max_draws)):
        if len(out) >= count:
            break
        q = controller.q_initial.copy()
        q[lift] = rng.uniform(robot.lower[lift], robot.upper[lift])
        base = controller.base
        if kind == "shape" and len(ground_yaw):
            q[ground_yaw] = rng.uniform(robot.lower[ground_yaw], robot.upper[ground_yaw])
        if kind == "place":
            x, y = rng.uniform(-reach, reach, 2)
            base = controller.base.moved(float(controller.base.x + x), float(controller.base.y + y),
                                         float(rng.uniform(-np.pi, np.pi)))  # on the controller's ground
        # stable on the links that lie on the ground whatever the pose (the base's, and the neck's before it
        # lifts: the body problem's ground links, as the whole-body solve's check takes them): a neck or head link
        # resting on the ground does not count (the pose must keep them above it)
        if min(stability.static_margin(robot, q, base, contact="ground"),
               prob.margin_and_gradient(prob.frames(q, base), base)[0]) <= min_margin:
            continue
        clear = coll.ground_clearance(robot, q, base)[0]
        # the pivot link rests on its edge: within the ground tolerance (a description's 1.57 tilts a yaw joint's
        # axis 0.05 deg, enough to press a bent base's links some micrometres into the ground)
        if clear[lifted].min() < -coll.GROUND_TOLERANCE \
                or clear[lifted[lifted > pivot]].min(initial=np.inf) < TARGET_GROUND_CLEARANCE:
            continue
        if coll.self_clearance(robot, q, base)[0] <= 0.0:
            continue
        H = robot.head_pose(q, base)
        out.append(ReachableTarget(H[:3, 3].copy(), H[:3, 0].copy(), q, base, kind))
    if len(out) < count:
        raise Infeasible(f"only {len(out)} of {count} reachable targets in {max_draws} draws")
    return out


def random_targets(controller: HeadController, count: int, rng: np.random.Generator | None = None, *, half_width: float | None = None,
                   height: float | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` (position, direction) pairs: positions uniform in the box of +-``half_width`` m around the base's
    placement (default: the body's length) and 0 .. ``height`` m high (default: the neck and head's length),
    directions uniform on the sphere."""
    robot = controller.robot
    rng = np.random.default_rng() if rng is None else rng
    w = robot.body_length if half_width is None else float(half_width)
    h = robot.neck_length + robot.head_length if height is None else float(height)
    out = []
    for _ in range(int(count)):
        p = np.array([controller.base.x, controller.base.y, 0.0]) + rng.uniform([-w, -w, 0.0], [w, w, h])
        d = rng.normal(size=3)
        out.append((p, d / np.linalg.norm(d)))
    return out
