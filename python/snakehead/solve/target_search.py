"""The whole-body solve of one head target, in stages (:func:`solve_target`): the paper's segmented solve from
the base as it is, then the base kept (the lifted chain's IK candidates and the whole-body optimisation), then the
base moved (other placements and flat shapes of the base). The first pose that passes every exact check wins; else
the best attempt, with what it lacks (``REASONS``).
"""
from __future__ import annotations

import time
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InternalError
from .._validate import finite_float, integer, unit_vector3, vector3
from ..model.robot import BasePlacement
from . import neck as nk
from .body_problem import BodyProblem
from .head_controller import HeadController
from .plan_solves import PlanSolves
from .solution_checks import MIN_MARGIN, check_solutions, clear_of_obstacles
from .whole_body_refinement import SOLVE_BUDGET, refine
from .whole_body_solution import STAGES, WholeBodySolution, check_rank, solution_rank
from .whole_body_starts import base_shapes, continue_from, lifted_candidates, placements

__all__ = ["TargetSearch", "solve_checked_target", "solve_target"]


def solve_target(controller: HeadController, position: npt.ArrayLike, direction: npt.ArrayLike, *,
                 q_prev: npt.ArrayLike | None = None, base: BasePlacement | None = None, obstacles: Sequence[Any] = (),
                 allow_base_move: bool = True, min_margin: float = MIN_MARGIN, budget: int = SOLVE_BUDGET,
                 problem: BodyProblem | None = None, seed: int = 0, near: bool = False,
                 shape_ok: Callable[[np.ndarray], bool] | None = None) -> WholeBodySolution:
    """Every joint (and, when allowed, the base's placement and flat shape) for one head target.

    Stages, the first that passes every exact check wins:

    1. the paper's segmented solve (:meth:`~.head_controller.HeadController.solve`) from the base
       as it is;
    2. the base kept: the lifted chain's IK candidates (:func:`~.whole_body_starts.lifted_candidates`), then the
       whole-body optimisation over the lifted joints from the best of them and from the segmented solution;
    3. the base moved (when ``allow_base_move``): for the base's shape and other flat shapes
       (:func:`~.whole_body_starts.base_shapes`), the placement that brings the target into the neck's accepted
       range (Section 3.3 (3)), the segmented solution and the IK candidates from there, then the whole-body
       optimisation over the base's yaw joints, its placement and the lifted joints.

    With ``near`` (for poses close to the previous one, e.g. along a line), a first attempt continues from
    ``q_prev``: the lifted chain's IK started from its joints with the roll free, kept when it passes every check
    (stage "whole-body, base kept"), so that consecutive poses stay on one branch of solutions.

    ``shape_ok``: a test of a moved base's flat shape (called with a configuration; only its joints before the
    lift count) that a solution of stage 3 must pass, e.g. the planner's: the shape holds a stable curl of the
    neck and head on the ground to lift them from. Shapes that fail it are not started from, and solutions whose
    shape fails it are not accepted (the search goes on).

    The result says which stage solved it, or why the best attempt fails (``REASONS``).
    """
    return solve_checked_target(controller, vector3(position, "position"), unit_vector3(direction, "direction"),
                                q_prev=q_prev, base=base, obstacles=obstacles, allow_base_move=allow_base_move,
                                min_margin=finite_float(min_margin, "min_margin"),
                                budget=integer(budget, "budget", least=1), problem=problem, seed=seed, near=near,
                                shape_ok=shape_ok)


def solve_checked_target(controller: HeadController, position: np.ndarray, direction: np.ndarray, *,
                         q_prev: npt.ArrayLike | None = None, base: BasePlacement | None = None,
                         obstacles: Sequence[Any] = (), allow_base_move: bool = True, min_margin: float = MIN_MARGIN,
                         budget: int = SOLVE_BUDGET, problem: BodyProblem | None = None, seed: int = 0,
                         near: bool = False, shape_ok: Callable[[np.ndarray], bool] | None = None,
                         kept: WholeBodySolution | None = None, memo: PlanSolves | None = None
                         ) -> WholeBodySolution:
    """:func:`solve_target` of a target already checked where it entered (a :class:`~snakehead.scenes.Target`'s
    position (3,) and unit direction (3,)): the planner's entry, which does not check them again.

    ``kept``: this solve's result with the base kept (the same arguments with ``allow_base_move=False``), when the
    caller has it (:func:`~snakehead.planning.target_solves.solve_kept`): stages 1 and 2 are not repeated (they are
    deterministic: the same arguments give the same solution), and a solution among them is returned as it is.
    ``memo``: the plan's :class:`~.plan_solves.PlanSolves`, whose segmented solves this solve shares."""
    search = TargetSearch(controller, position, direction, q_prev, base, obstacles, min_margin, budget,
                          problem, seed, shape_ok, memo)
    if kept is not None:
        if kept.success:
            return kept
        search.best, search.segmented = kept, kept.segmented
        found = None
    else:
        found = search.base_kept(near and q_prev is not None)
    if found is None and allow_base_move:
        found = search.base_moved()
    return found if found is not None else _attempted(search.best)


class TargetSearch:
    """One whole-body solve of :func:`solve_checked_target`: the target, the body as it is, the limits, and the best
    attempt so far (:meth:`consider`); its stages are :meth:`base_kept` (the near continuation, stages 1 and 2)
    and :meth:`base_moved` (stage 3), each returning the first solution that passes every check, else None."""

    def __init__(self, controller: HeadController, position: np.ndarray, direction: np.ndarray,
                 q_prev: npt.ArrayLike | None, base: BasePlacement | None, obstacles: Sequence[Any],
                 min_margin: float, budget: int, problem: BodyProblem | None, seed: int,
                 shape_ok: Callable[[np.ndarray], bool] | None, memo: PlanSolves | None = None) -> None:
        self.t0 = time.perf_counter()
        self.controller, self.robot = controller, controller.robot
        self.position, self.direction = position, direction
        self.base = controller.base if base is None else base
        self.q_now = controller.q_initial.copy() if q_prev is None else np.asarray(q_prev, float).copy()
        self.prob = problem if problem is not None else BodyProblem(self.robot)
        self.obstacles = list(obstacles)
        self.min_margin, self.budget, self.seed, self.shape_ok = min_margin, budget, seed, shape_ok
        self.spent = 0  # the solves of stage 3 so far (SOLVE_BUDGET)
        self.memo = memo
        self.best: WholeBodySolution | None = None
        self.segmented: Any = None  # the segmented solution, once stage 1 has run
        self.rejected_shapes: set = set()  # shapes that failed shape_ok (its cost may be that of a search)

    def afford(self) -> bool:
        """Whether stage 3 may make one more solve (a segmented solve, a batch of IK, a refinement) within its
        ``budget``; counts it when it may."""
        if self.out_of_work():
            return False
        self.spent += 1
        return True

    def out_of_work(self) -> bool:
        """Whether stage 3 has made its ``budget`` of solves."""
        return self.spent >= self.budget

    def check(self, q: np.ndarray, b: BasePlacement) -> dict:
        """:meth:`check_many` of one configuration."""
        return self.check_many([q], b)[0]

    def check_many(self, qs: Sequence[np.ndarray], b: BasePlacement) -> list[dict]:
        """:func:`~.solution_checks.check_solutions` of configurations at one placement (one batch)."""
        if not len(qs):
            return []
        return check_solutions(self.robot, np.asarray(qs, float), b, self.position, self.direction, self.obstacles,
                               min_margin=self.min_margin, problem=self.prob)

    def consider(self, q: np.ndarray, b: BasePlacement, stage: str, starts: int,
                 chk: dict | None = None) -> WholeBodySolution | None:
        """Check a configuration (unless its check ``chk`` is given); keep the best attempt; return the solution
        when it passes."""
        chk = self.check(q, b) if chk is None else chk
        if chk["reason"] is not None and self.best is not None and check_rank(chk) <= solution_rank(self.best):
            return None  # neither a solution nor a better attempt
        sol = WholeBodySolution(q=q, base=b, stage=stage if chk["reason"] is None else None, reason=chk["reason"],
                                position_error_m=chk["position_error_m"],
                                direction_error_deg=chk["direction_error_deg"],
                                static_margin_m=chk["static_margin_m"], ground_clearance_m=chk["ground_clearance_m"],
                                self_clearance_m=chk["self_clearance_m"],
                                obstacle_clearance_m=chk["obstacle_clearance_m"], starts=starts,
                                seconds=time.perf_counter() - self.t0)
        sol.segmented = self.segmented
        sol.desired_frame = None if self.segmented is None else self.segmented.desired_frame
        if self.best is None or solution_rank(sol) > solution_rank(self.best):
            self.best = sol
        return sol if sol.success else None

    def beyond_reach(self) -> bool:
        """With the base kept, the frame the neck lifts from stays where it is: whether the target is out of the lifted
        chain's reach from there (:meth:`~.body_problem.BodyProblem.out_of_reach`), where stages 1 and 2 cannot succeed
        and their IK would spend its whole budget finding so. The segmented solve lifts the neck from the initial
        configuration's joints before the lift (``HeadController.solve_checked``): the target must be out of reach from
        that frame too."""
        q = self.q_now
        lift = self.robot.lift_joints.start
        neck = self.robot.parts.neck.start
        if not self.prob.out_of_reach(q, self.base, self.position, self.direction):
            return False
        if neck >= lift or np.array_equal(q[neck:lift], self.controller.q_initial[neck:lift]):
            return True
        q = q.copy()
        q[neck:lift] = self.controller.q_initial[neck:lift]
        return self.prob.out_of_reach(q, self.base, self.position, self.direction)

    def base_kept(self, near: bool) -> WholeBodySolution | None:
        """The base as it is: with ``near``, the lifted chain's IK continued from the current joints
        (:func:`~.whole_body_starts.continue_from`); 1. the paper's segmented solve; 2. the lifted chain's IK
        candidates, then the whole-body optimisation from the best attempt when it reached the head."""
        if self.beyond_reach():
            self.consider(self.q_now, self.base, STAGES[1], 0)  # the attempt to report: out of reach
        else:
            if near:
                q = continue_from(self.prob, self.q_now, self.base, self.position, self.direction, self.seed)
                if q is not None and (found := self.consider(q, self.base, STAGES[1], 1)):
                    return found
            if found := self.segmented_solve():
                return found
            candidates = self.candidates_at(self.q_now, self.base)
            for k, (q, chk) in enumerate(zip(candidates, self.check_many(candidates, self.base))):
                if found := self.consider(q, self.base, STAGES[1], k + 1, chk):
                    return found
        return self.refine_kept()

    def segmented_solve(self) -> WholeBodySolution | None:
        """Stage 1: the paper's segmented solve (:meth:`~.head_controller.HeadController.solve_checked`)
        from the base as it is, clear of the obstacles."""
        seg = self.segmented_at(self.q_now, self.base, clear=True)
        self.segmented = seg
        return self.consider(seg.q, seg.base, STAGES[0], 0)

    def candidates_at(self, q: np.ndarray, base: BasePlacement) -> list[np.ndarray]:
        """:func:`~.whole_body_starts.lifted_candidates` from ``q`` at ``base`` (copies), kept in the plan's
        :class:`~.plan_solves.PlanSolves`: the relocation's search and the solve with the base kept at the base it finds
        solve the same batch."""
        key = (self.position.tobytes(), self.direction.tobytes(), q.tobytes(), base, self.seed)
        found = None if self.memo is None else self.memo.candidates.get(key)
        if found is None:
            found = lifted_candidates(self.prob, q, base, self.position, self.direction, self.seed)
            if self.memo is not None:
                self.memo.candidates[key] = found
        return [c.copy() for c in found]

    def segmented_at(self, q_prev: np.ndarray, base: BasePlacement, clear: bool) -> Any:
        """The segmented solve (:meth:`~.head_controller.HeadController.solve_checked`, the base kept)
        from ``q_prev`` at ``base``, its solution required to clear the obstacles when ``clear``; kept in the plan's
        :class:`~.plan_solves.PlanSolves` (the relocation's search and the solve at the base it finds ask for the same
        one)."""
        clear = clear and bool(self.obstacles)
        key = (self.position.tobytes(), self.direction.tobytes(), np.asarray(q_prev, float).tobytes(), base, clear)
        if self.memo is not None and key in self.memo.segmented:
            return self.memo.segmented[key]
        accept = (lambda q, b: clear_of_obstacles(self.robot, q, self.obstacles, b)) if clear else None
        seg = self.controller.solve_checked(self.position, self.direction, q_prev=q_prev, base=base, accept=accept,
                                            allow_base_move=False)
        if self.memo is not None:
            self.memo.segmented[key] = seg
        return seg

    def refine_kept(self) -> WholeBodySolution | None:
        """The whole-body optimisation over the lifted joints from the best attempt, only when it reached the head
        and failed stability or clearance (a local optimisation can move the body from there; a target out of
        reach from this base is the placement's problem: stage 3)."""
        starts = [self.best.q] if self.best is not None and self.best.reason != "out of reach" else []
        for q0 in starts:  # (stages 1 and 2 make at most four solves: no budget)
            q, b = refine(self.prob, q0, self.base, self.position, self.direction, move_base=False,
                          obstacles=self.obstacles, min_margin=self.min_margin)
            if found := self.consider(np.clip(q, self.robot.lower, self.robot.upper), b, STAGES[1], len(starts)):
                return found
        return None

    def shape_passes(self, q: np.ndarray) -> bool:
        """Whether the flat shape of q (its joints before the lift) passes ``shape_ok`` (remembered when not)."""
        key = q[:self.robot.lift_joints.start].tobytes()
        if key in self.rejected_shapes:
            return False
        if self.shape_ok is not None and not self.shape_ok(q):
            self.rejected_shapes.add(key)
            return False
        return True

    def moved(self, q: np.ndarray, b: BasePlacement, starts: int, chk: dict | None = None
              ) -> WholeBodySolution | None:
        """:meth:`consider` for a moved base, whose shape must pass ``shape_ok`` too (asked only of a configuration
        that passes every other check; one whose shape fails is not kept as the best attempt either). ``chk``: its
        check, when made already."""
        chk = self.check(q, b) if chk is None else chk
        if self.shape_ok is not None and chk["reason"] is None and not self.shape_passes(q):
            return None
        return self.consider(q, b, STAGES[2], starts, chk)

    def base_moved(self) -> WholeBodySolution | None:
        """Stage 3: for the base's shape and other flat shapes (:func:`~.whole_body_starts.base_shapes`), placements
        that bring the target into reach (:meth:`from_shape`), then the whole-body optimisation over the base's yaw
        joints, its placement and the lifted joints from the segmented solutions found there."""
        moved_starts: list[tuple[np.ndarray, BasePlacement]] = []
        for qb in [self.q_now[self.robot.parts.base]] + base_shapes(self.controller):
            if found := self.from_shape(qb, moved_starts):
                return found
            if self.out_of_work():
                break
        for q0, b0 in moved_starts:
            if not self.afford():
                break
            q, b = refine(self.prob, q0, b0, self.position, self.direction, move_base=True, obstacles=self.obstacles,
                          min_margin=self.min_margin)
            if found := self.moved(np.clip(q, self.robot.lower, self.robot.upper), b, len(moved_starts)):
                return found
        return None

    def from_shape(self, qb: np.ndarray, moved_starts: list[tuple[np.ndarray, BasePlacement]]
                   ) -> WholeBodySolution | None:
        """The base with base joints qb: the placement that brings the target into the neck's accepted range (Section
        3.3 (3)) and its segmented solution (added to ``moved_starts``), then the lifted chain's IK candidates there and
        at the other candidate placements (:func:`~.whole_body_starts.placements`), while the shape passes and the
        budget lasts (:meth:`afford`)."""
        robot, controller, base = self.robot, self.controller, self.base
        q = self.q_now.copy()
        q[robot.parts.base] = qb
        P0_local = np.linalg.inv(robot.body_pose(base)) @ robot.frame(q, robot.lift_frame, base)
        placed = None if controller.neck_length <= 0 else nk.base_move_into_range(
            self.position, P0_local, base, controller.Lc, controller.neck_length, controller.slack,
            robot.body_axis_height)
        if placed is not None and self.afford():
            s = self.segmented_at(q, placed, clear=False)
            if s.success and (found := self.moved(s.q, placed, 0)):
                return found
            moved_starts.append((s.q, placed))
        moved = [base.moved(p.x, p.y, p.yaw) for p in placements(self.prob, P0_local, self.position, self.direction)]
        for b in ([placed] if placed is not None else []) + moved:  # on base's ground
            if q[:robot.lift_joints.start].tobytes() in self.rejected_shapes or not self.afford():
                break
            candidates = self.candidates_at(q, b)
            for qc, chk in zip(candidates, self.check_many(candidates, b)):
                if found := self.moved(qc, b, 0, chk):
                    return found
        return None


def _attempted(best: WholeBodySolution | None) -> WholeBodySolution:
    """The best attempt of :func:`solve_checked_target` (every path through it tries at least one pose)."""
    if best is None:
        raise InternalError("the whole-body solve tried no pose")
    return best
