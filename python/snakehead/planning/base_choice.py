"""Where the base lies for a plan: the start's placement and flat shape when every target is solved from there,
else another (:func:`choose_base`), reached by locomotion before the plan (a :class:`Relocation`, at most
:data:`MAX_RELOCATION_M` away)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import Infeasible
from .._validate import joint_vector
from ..margins import DETOUR_MARGIN
from ..model.robot import BasePlacement, SnakeRobot
from ..solve.head_controller import HeadController
from ..solve.whole_body import PlanSolves, clear_of_obstacles, solve_checked_target
from .plan_cache import plan_cache_of, shape_key
from .start_state import bending_state, lift_ends_safe, shape_of
from .target_solves import solve_kept

#: The farthest (m) the planner moves the base by locomotion before a plan (a relocation). A target farther than
#: this plus the body's length from where the base lies is out of range: the plan fails at once and says so.
MAX_RELOCATION_M = 10.0


def out_of_range(robot: SnakeRobot, start: BasePlacement, targets: Sequence[Any]) -> str | None:
    """Why no relocation can reach ``targets`` from ``start`` (None: every one is in range)."""
    for t in targets:
        d = float(np.hypot(t.position[0] - start.x, t.position[1] - start.y))
        if d > MAX_RELOCATION_M + robot.body_length:
            return (f"out of range: it is {d:.4g} m from the base; a relocation moves the base at most "
                    f"{MAX_RELOCATION_M:g} m (snakehead.planning.base_choice.MAX_RELOCATION_M) and the body is "
                    f"{robot.body_length:.3g} m long")
    return None


@dataclass(frozen=True)
class Relocation:
    """A change of base that the targets need, carried out before the plan by locomotion (the paper's rolling gait
    or turning in place, Section 3.3 (3)): from placement ``start`` to ``base``, with the base's flat shape changed
    when ``shape_changed``; ``reason`` says why (what failed from the start)."""
    start: BasePlacement
    base: BasePlacement
    shape_changed: bool
    reason: str

    def as_dict(self) -> dict:
        return {"from": {"x_m": self.start.x, "y_m": self.start.y, "yaw_rad": self.start.yaw},
                "to": {"x_m": self.base.x, "y_m": self.base.y, "yaw_rad": self.base.yaw},
                "distance_m": float(np.hypot(self.base.x - self.start.x, self.base.y - self.start.y)),
                "shape_changed": self.shape_changed, "reason": self.reason}


def choose_base(controller: HeadController, targets: Any, obstacles: Sequence[Any] = (),
                allow_relocation: bool = True, base_shape: npt.ArrayLike | None = None, *,
                solved: PlanSolves | None = None
                ) -> tuple[BasePlacement, np.ndarray, Relocation | None, list[str]]:
    """One base (placement and flat shape) for a whole scene: the controller's when every target is solved from it
    (:func:`~snakehead.solve.whole_body.solve_target` with the base kept) and the body starts clear of the
    obstacles; else the first base that the whole-body solve with the base moved finds for a target (the failing
    one first) from which every target is solved, among the bases whose flat shape holds a stable curl of the neck
    and head (:func:`~snakehead.planning.start_state.bending_state`: the plan lifts them from it; a straight base,
    e.g., may hold none). ``base_shape``: a configuration whose base joints (and those of
    the neck's links that stay on the ground) give the base's flat shape at the controller's placement (default:
    the controller's initial configuration's). Returns the placement, a configuration with the base's shape
    (the initial configuration's otherwise), the relocation (None when the base stays) and notes. ``solved``: the
    plan's :class:`~snakehead.solve.whole_body.PlanSolves`, which keeps the solves (:func:`solve_kept`, and the
    segmented solves and IK batches of the relocation's search) for the plan to reuse (default: one for this call,
    shared by its own steps)."""
    solved = PlanSolves() if solved is None else solved
    robot = controller.robot
    obstacles = list(obstacles)
    targets = list(targets)
    start, q0 = controller.base, controller.q_initial
    if base_shape is not None:
        q0 = shape_of(robot, joint_vector(base_shape, robot.n_joints, "base_shape"), q0)
    first, why = _first_failure(controller, start, q0, targets, obstacles, solved)
    if first is None:
        return start, q0.copy(), None, []
    reason = ("the start state touches an obstacle" if first == "the start" else
              "no curl of the neck and head on the ground is stable on the start's base" if first == "no curl" else
              f"target {first.name!r} is not reached from the start ({why.reason})")
    if not allow_relocation:
        return start, q0.copy(), None, [f"the base is kept (no relocation allowed): {reason}"]
    far = out_of_range(robot, start, targets)
    if far is not None:
        return start, q0.copy(), None, [f"no relocation: a target is {far}"]
    order = ([first] if first not in ("the start", "no curl") else []) + [t for t in targets if t is not first]
    for t in order:
        found = _relocated_for(controller, t, q0, targets, obstacles, solved)
        if found is not None:
            base, q_shape = found
            changed = not np.allclose(q_shape[:robot.lift_joints.start], q0[:robot.lift_joints.start])
            return base, q_shape, Relocation(start, base, changed, reason), [
                f"the base is relocated to {base}" + (" with another flat shape" if changed else "")
                + f" (by locomotion, before the plan): {reason}"]
    return start, q0.copy(), None, [f"no single base reaches every target: {reason}"]


def _first_failure(controller: HeadController, base: BasePlacement, q_shape: np.ndarray, targets: Sequence[Any],
                   obstacles: Sequence[Any], solved: PlanSolves | None) -> tuple[Any, Any]:
    """The first of ``targets`` not solved (with the base kept, :func:`solve_kept`) from the base at ``base`` with
    the flat shape of ``q_shape``, and its solution; (None, None) when all are; ("no curl", None) when the base's
    shape holds no stable curl of the neck and head, ("the start", None) when the start state is in an obstacle."""
    try:
        q_bend = bending_state(controller, q_shape, base)
    except Infeasible:
        return "no curl", None
    if not clear_of_obstacles(controller.robot, q_bend, obstacles, base):
        return "the start", None
    for t in targets:
        sol = solve_kept(controller, t.position, t.direction, q_shape, base, obstacles, solved)
        if not sol.success:
            return t, sol
    return None, None


def has_curl(controller: HeadController, q: np.ndarray) -> bool:
    """Whether the flat shape of q (its joints before the lift) holds a stable curl of the neck and head (a
    bending state) from which the lift ends in a safe state (:func:`~snakehead.planning.start_state.lift_ends_safe`);
    the shapes that do not are kept in ``plan_cache_of(controller).shapes_without_curl``. On a slope both are
    judged at the controller's base's ground and heading (the weight leans), and kept for those only."""
    no_curl = plan_cache_of(controller).shapes_without_curl
    key = shape_key(q, controller.robot.lift_joints.start, 12)
    base = controller.base if not controller.base.on_flat_ground else None  # on a slope: at its ground and heading
    if base is not None:  # (a slope's answer is never reused at another heading or on another ground)
        key += repr((base.ground, base.yaw)).encode()
    if key in no_curl:
        return False
    try:
        bending_state(controller, q, base)
    except Infeasible:
        no_curl.put(key, True)
        return False
    if not lift_ends_safe(controller, q, base):
        no_curl.put(key, True)
        return False
    return True


def _relocated_for(controller: HeadController, target: Any, q0: np.ndarray, targets: Sequence[Any],
                   obstacles: Sequence[Any], solved: PlanSolves | None
                   ) -> tuple[BasePlacement, np.ndarray] | None:
    """The base (placement, a configuration with its flat shape) that the whole-body solve with the base moved
    finds for ``target`` from the controller's base and the shape of ``q0``, when it is another base, at most
    MAX_RELOCATION_M away, whose shape holds a stable curl of the neck and head (the bending state the plan lifts
    them from: the solve is told so, and looks further than a shape, e.g. a straight base, that holds none) and
    from which every target is solved; else None."""
    robot, start = controller.robot, controller.base
    # the solve with the base kept is the first failure's (or, for a later target, made once and kept in solved)
    kept = solve_kept(controller, target.position, target.direction, q0, start, obstacles, solved)
    sol = solve_checked_target(controller, target.position, target.direction, q_prev=q0, base=start,
                               obstacles=obstacles, allow_base_move=True, problem=controller.body_problem,
                               min_margin=DETOUR_MARGIN, shape_ok=lambda q: has_curl(controller, q), kept=kept,
                               memo=solved)
    if not sol.success or (sol.base == start and np.array_equal(sol.q[:robot.lift_joints.start],
                                                               q0[:robot.lift_joints.start])):
        return None
    if np.hypot(sol.base.x - start.x, sol.base.y - start.y) > MAX_RELOCATION_M:
        return None
    q_shape = shape_of(robot, sol.q, q0)
    if _first_failure(controller, sol.base, q_shape, targets, obstacles, solved)[0] is not None:
        return None
    return sol.base, q_shape


__all__ = ["MAX_RELOCATION_M", "Relocation", "choose_base", "out_of_range", "shape_of", "has_curl"]
