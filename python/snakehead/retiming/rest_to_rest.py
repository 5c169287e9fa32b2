"""One rest-to-rest piece of a retimed motion (:class:`Piece`): the path through a run of waypoints, timed by TOPP-RA
on a grid refined where the limits break between gridpoints, with clear errors where no timing can follow it."""
from __future__ import annotations

import numpy as np

from .._errors import Infeasible
from ..model.robot import BasePlacement, SnakeRobot
from .grid_refinement import REFINE_EXTRA_POINTS, REFINE_GROWTH, REFINE_ROUNDS, refined_grid, stage_keys, stages_over
from .gridpoints import GridPoints, first_grid, solve_grid
from .joint_path import path_function
from .retiming_limits import RetimingLimits

__all__ = ["Piece"]


class Piece:
    """One rest-to-rest piece of the motion: the path f(s) through waypoints i0..i1 (s: its length in joint space,
    rad, with the waypoints at ``knots``), timed by TOPP-RA on a grid refined where the limits break between
    gridpoints."""

    def __init__(self, robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, W: np.ndarray, i0: int,
                 i1: int, interpolation: str) -> None:
        self.robot, self.base, self.limits, self.i0, self.i1 = robot, base, limits, i0, i1
        pts = W[i0:i1 + 1]
        self.knots = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        self.f = path_function(self.knots, pts, interpolation)
        self.interpolation = interpolation

    def near(self, k: int, grid: np.ndarray) -> int:
        """The waypoint at or before gridpoint k."""
        return self.i0 + int(np.searchsorted(self.knots, grid[k], side="right")) - 1

    def first_grid(self, grid_step: float) -> np.ndarray:
        """Gridpoints at most ``grid_step`` rad apart, at least MIN_GRID_PER_SEGMENT per segment, on every knot."""
        return first_grid(self.knots, grid_step)

    def time(self, grid_step: float, notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """The grid and the path speeds s' at its points; Infeasible where no timing keeps the limits."""
        points = GridPoints.of(self.robot, self.base, self.f, self.first_grid(grid_step), self.limits.zmp_margin)
        self._precheck(points)
        support, grid = points.support, points.s
        if np.any(support.required < self.limits.zmp_margin):
            k = int(np.argmin(support.static))
            notes.append(f"the CoM is only {1000 * support.static[k]:.1f} mm inside the support polygon near waypoint "
                         f"{self.near(k, grid)}: the ZMP keeps {1000 * support.required[k]:.1f} mm there instead of "
                         f"{1000 * self.limits.zmp_margin:.1f} mm")
        return self._refine(points, notes)

    def _refine(self, points: GridPoints, notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """Solve; cut the stages that break a limit between their gridpoints; again, up to REFINE_ROUNDS times
        (the constraints computed once per gridpoint)."""
        first_size = len(points.s)
        kept = stage_keys(np.zeros(0), np.zeros(0))  # stages (s_i, s_i+1, x_i, x_i+1) probed within the limits
        for refinement in range(REFINE_ROUNDS + 1):
            solution = solve_grid(self.robot, points, self.limits)
            if solution.sd is None:
                raise Infeasible(f"no motion along the path keeps every limit near waypoint "
                                 f"{self.near(max(solution.failed_at, 0), points.s)} (between waypoints {self.i0} and "
                                 f"{self.i1}); loosen the limits or the ZMP margin there")
            if refinement == REFINE_ROUNDS:
                break
            # a stage that is the same as one probed within the limits in an earlier round (same ends, same
            # speeds: the profile there did not change) is within them again: only the others are probed
            x = solution.sd ** 2
            stages = stage_keys(points.s, x)
            todo = ~np.isin(stages, kept)
            split = stages_over(self.robot, self.base, self.limits, self.f, points.s, solution.sd, points.support,
                                only=todo)
            kept = np.concatenate([kept, stages[todo & ~split]])
            if not split.any():
                break
            refined = refined_grid(points.s, split)
            # a grid that would grow beyond that is not a local defect: say so rather than grow on
            if len(refined) > REFINE_GROWTH * first_size + REFINE_EXTRA_POINTS:
                notes.append(f"waypoints {self.i0}..{self.i1}: {split.sum()} of {len(split)} stages still break a "
                             "limit between gridpoints after refining; see check")
                break
            added = GridPoints.of(self.robot, self.base, self.f, np.setdiff1d(refined, points.s),
                                  self.limits.zmp_margin)
            points = points.merged(added)
        assert solution.sd is not None  # the loop raised otherwise
        return points.s, solution.sd

    def _precheck(self, points: GridPoints) -> None:
        """Clear errors for paths no timing can follow: the spline leaves the joint limits, or holding still already
        breaks a limit."""
        robot, grid, support = self.robot, points.s, points.support
        if self.interpolation == "spline":
            over = np.maximum(robot.lower - points.q, points.q - robot.upper).max()
            if over > 1e-9:
                raise Infeasible(f"the spline through waypoints {self.i0}..{self.i1} overshoots a joint limit by "
                                 f"{np.degrees(over):.2f} deg; use interpolation='monotone'")
        if np.any(support.static <= 0):
            k = int(np.argmin(support.static))
            raise Infeasible(f"the centre of mass is {-1000 * support.static[k]:.1f} mm outside the support polygon "
                             f"near waypoint {self.near(k, grid)}: no motion along this path is stable there")
        hold = np.abs(points.tau_hold) / self.limits.torque
        if hold.max() > 1.0:
            k, j = (int(i) for i in np.unravel_index(int(np.argmax(hold)), hold.shape))
            raise Infeasible(f"joint {robot.joint_names[j]} needs {hold[k, j] * self.limits.torque[j]:.2f} N m to hold "
                             f"the body still near waypoint {self.near(k, grid)}; its torque limit is "
                             f"{self.limits.torque[j]:.2f} N m")
