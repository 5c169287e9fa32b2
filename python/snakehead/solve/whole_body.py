"""The stability-aware whole-body solve: every joint and the base's placement at once.

The paper's segmented solve (:class:`~.head_controller.HeadController`: the base on its arc, the neck
by Eqs. 18-22, the head by TRAC-IK) reaches many targets in milliseconds, but it checks stability instead of
seeking it and keeps the base where it is. When it fails, leaves the centre of mass outside the support polygon,
puts a link in the ground or into an obstacle, the whole-body solve maximises the static margin (Eqs. 23-24) over
the base's flat shape, the neck and head joints and the base's placement, with the head at the target and the body
clear of the ground, itself and the obstacles, from several starts: the segmented solution, the current
configuration, and the segmented solutions from base placements that bring the target into the neck's accepted
range and from other base arcs. Every solution is then checked exactly.

Its parts, one module each (every name is importable from here too):

* :mod:`.target_search` -- the staged solve of one target (:func:`solve_target`, :func:`solve_checked_target`);
* :mod:`.whole_body_starts` -- its starts (the lifted chain's IK candidates, other base shapes, placements);
* :mod:`.whole_body_refinement` -- the SLSQP optimisation from a start and its constraints
  (:func:`refine`, :func:`solve_whole_body`);
* :mod:`.solution_checks` -- the exact checks of a solution and the obstacle clearance test;
* :mod:`.whole_body_solution` -- the result (:class:`WholeBodySolution`) and how attempts compare;
* :mod:`.body_problem` -- what the solve needs of one robot, computed once (:class:`BodyProblem`), and
  :mod:`.base_support`, the margin over the links that lie on the ground whatever the pose;
* :mod:`.plan_solves` -- the solves one plan's steps share (:class:`PlanSolves`).
"""
from __future__ import annotations

from ..margins import EXACT_DISTANCE_WITHIN, OBSTACLE_CLEARANCE, SELF_CLEARANCE
from .body_problem import LIFTED_IK_TIMEOUT_S, BodyProblem
from .plan_solves import PlanSolves
from .solution_checks import (
                                    DIRECTION_TOLERANCE,
                                    MIN_MARGIN,
                                    POSITION_TOLERANCE,
                                    check_solution,
                                    check_solutions,
                                    clear_of_obstacles,
)
from .target_search import TargetSearch, solve_checked_target, solve_target
from .whole_body_refinement import MAX_ITERATIONS, PAIR_RANGE, SOLVE_BUDGET, RefinementProblem, refine, solve_whole_body
from .whole_body_solution import REASONS, STAGES, WholeBodySolution, check_rank, solution_rank
from .whole_body_starts import (
                                    CANDIDATE_ROLLS,
                                    CANDIDATE_SEEDS,
                                    base_shapes,
                                    continue_from,
                                    lifted_candidates,
                                    placements,
                                    rolled_frames,
                                    rolls_reached,
)

__all__ = ["BodyProblem", "CANDIDATE_ROLLS", "CANDIDATE_SEEDS", "DIRECTION_TOLERANCE",
           "EXACT_DISTANCE_WITHIN", "LIFTED_IK_TIMEOUT_S", "MAX_ITERATIONS", "MIN_MARGIN", "OBSTACLE_CLEARANCE",
           "PAIR_RANGE", "POSITION_TOLERANCE", "PlanSolves", "REASONS", "RefinementProblem", "SELF_CLEARANCE",
           "SOLVE_BUDGET", "STAGES", "TargetSearch", "WholeBodySolution", "base_shapes", "check_rank",
           "check_solution", "check_solutions", "clear_of_obstacles", "continue_from", "lifted_candidates",
           "placements", "refine", "rolled_frames", "rolls_reached", "solution_rank", "solve_checked_target",
           "solve_target", "solve_whole_body"]
