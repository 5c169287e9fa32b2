"""Step 2 of :class:`snakehead.closed_loop.loop.ClosedLoop`, the locomotion: gait runs that take the straight body
to where the curl into the bending state must start, around the obstacles on a route of the body's middle
(:func:`snakehead.locomotion.ground_path.plan_route`) planned again from the estimate whenever the body drifts off it,
every run's predicted sweep checked before it runs (:func:`snakehead.locomotion.ground_path.sweep_clear`).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .._errors import Infeasible
from ..locomotion import goals as lc
from ..locomotion import ground_path as gp
from ..model.robot import BasePlacement, SnakeRobot
from ..sim.tracking import SimState
from .estimate import BodyPose
from .gait_runner import GaitRun, GaitSimulator
from .loop_run import placement_text

__all__ = ["WAYPOINT_TOLERANCE", "MAX_LEGS", "RouteFollower"]

#: How near the gaits bring the body to a waypoint of a route around obstacles (its middle off the leg's line, m,
#: and along it, m; its heading, deg): looser than the goal's, the next leg corrects what is left. Off the line it
#: is loosest: a turn square to the line and back to correct it shifts the middle by as much again (turning in
#: place moves the middle by up to 0.05 body lengths a cycle), and where being off the line matters the route is
#: planned again (RouteFollower._route_holds: the leg from where the body is must keep the clearance less
#: ground_path.EXECUTION_M).
WAYPOINT_TOLERANCE = lc.Tolerance(along_m=0.25, across_m=0.08, yaw_deg=8.0, align_deg=8.0)
#: The most legs of a route the locomotion follows (each at most max_gait_runs runs) before it gives up.
MAX_LEGS = 8


class RouteFollower:
    """The gait runs of one robot among ``obstacles`` (see the module): ``frequency`` the gaits' (Hz),
    ``max_gait_runs`` the most runs towards one waypoint (and to the goal); ``offset`` the body's middle (its
    virtual chassis when straight) in the root placement (:func:`snakehead.locomotion.goals.chassis_offset`)."""

    def __init__(self, robot: SnakeRobot, obstacles: list, *, frequency: float, max_gait_runs: int) -> None:
        self.robot, self.obstacles = robot, obstacles
        self.frequency, self.max_gait_runs = frequency, max_gait_runs
        self.offset = lc.chassis_offset(robot)

    def follow(self, sim: GaitSimulator, est: BodyPose, straight_goal: BasePlacement, tolerance: lc.Tolerance,
               rates: lc.GaitRates, routes: list[np.ndarray], say: Callable[[str], None],
               ground: Callable[[GaitRun, str, str], None], current_state: Callable[[], SimState]) -> str | None:
        """Step 2's gait runs from the estimate ``est`` to ``straight_goal`` within ``tolerance``, run by ``sim``
        from ``current_state()`` (the simulation's state now), ``rates`` learning from each: along the route
        (``_route``, recorded in ``routes``), planned again from the estimate whenever the body drifts off it
        (``_route_holds``, after every run), each run's sweep checked before it runs (``_sweep_failure``: a
        run that fails it is made smaller, one cycle at half its amplitude, until it passes or is as small as a run
        gets); ``ground`` records each run and moves the estimate, ``say`` tells. None when done (at the goal, or
        out of runs), else why the body cannot go on."""
        grid = self._grid(est.base, straight_goal) if self.obstacles else None
        route: gp.Route | None = None
        k = 0  # the route's waypoint the gaits go to
        planned = 0  # routes planned since the last run
        runs_here = 0  # gait runs towards the current waypoint
        for _ in range(self.max_gait_runs * MAX_LEGS):
            if grid is not None and (route is None or (not self._route_holds(route, k, est.base, grid)
                                                       and planned == 0)):
                # (a route just planned from here is followed even where its first leg does not keep the margin
                # on the grid's cells: each run's sweep is still checked)
                planned += 1
                try:  # the first, or the body drifted off its route: plan it again from the estimate
                    route, k, runs_here = self._route(est.base, straight_goal, grid, routes, say), 1, 0
                except Infeasible as exc:
                    return f"no route around the obstacles from {placement_text(est.base)}: {exc}"
            last = route is None or k == len(route.waypoints) - 1
            step = (None if runs_here >= self.max_gait_runs else
                    self._leg_step(est.base, route, k, straight_goal, tolerance, rates))
            if step is None:  # at the waypoint (or as near as max_gait_runs runs bring it): on to the next
                if last:
                    return None
                k, runs_here = k + 1, 0
                continue
            step, why = self._checked_step(est.base, step, rates, grid)
            if why is not None:
                return why
            before = est.base
            run = sim.run(current_state(), step.gait, step.cycles, start_estimate=est)
            direction = {1: "+", -1: "-"}[step.gait.direction]
            ground(run, f"{step.gait.name} {direction} ({'' if last else 'route, '}{step.leg}, {step.cycles:.0f} x "
                        f"{step.scale:.2f})", "gait")
            est, planned, runs_here = run.estimate, 0, runs_here + 1
            rates.update(step, before, est.base, self.offset)
        return None

    def _route(self, here: BasePlacement, straight_goal: BasePlacement, grid: gp.ClearanceGrid,
               routes: list[np.ndarray], say: Callable[[str], None]) -> gp.Route | None:
        """The route from ``here`` to ``straight_goal`` (root placements of the straight body):
        :func:`snakehead.locomotion.ground_path.plan_route` between their middles (None: the straight legs are clear),
        keeping CLEARANCE_M beyond the gaits' sweep, or where no such route exists EXECUTION_M alone; recorded in
        ``routes``. :class:`~snakehead.Infeasible` when there is none."""
        a, b = lc.compose(here, self.offset), lc.compose(straight_goal, self.offset)
        try:
            route = gp.plan_route(self.robot, self.obstacles, a, b, grid=grid)
        except Infeasible as exc:  # no room for the drift's budget: the execution margin alone, said so
            route = gp.plan_route(self.robot, self.obstacles, a, b, grid=grid, clearance=gp.EXECUTION_M)
            say(f"{exc}: the route keeps {1000 * gp.EXECUTION_M:.0f} mm beyond the gaits' sweep, without the dead "
                "reckoning's drift")
        if route is not None:
            routes.append(route.waypoints.copy())
            say(f"around the obstacles: {len(route.waypoints) - 1} legs of "
                f"{np.linalg.norm(np.diff(route.waypoints, axis=0), axis=1).sum():.2f} m")
        return route

    def _route_holds(self, route: gp.Route, k: int, here: BasePlacement, grid: gp.ClearanceGrid) -> bool:
        """Whether the body, its middle estimated at ``here``'s, can go on to waypoint ``k`` of ``route``: the
        leg from there keeps the route's clearance less EXECUTION_M (the waypoint tolerance) from the obstacles
        (``grid``: the route's). An escape or a staging leg holds (both run nearer than that by design; each run's
        sweep is checked)."""
        if (k == 1 and route.escape) or (route.staging and k == len(route.waypoints) - 1):
            return True
        m = lc.compose(here, self.offset)
        return gp.segment_clear(grid, np.array([m.x, m.y]), route.waypoints[k], route.clear_m - gp.EXECUTION_M)

    def _grid(self, here: BasePlacement, straight_goal: BasePlacement) -> gp.ClearanceGrid:
        """The obstacles' grid of one locomotion (:func:`snakehead.locomotion.ground_path.clearance_grid`): over the
        body's middle here and at the goal, reaching beyond the obstacles by the routes' clearance and more."""
        a, b = lc.compose(here, self.offset), lc.compose(straight_goal, self.offset)
        reach = gp.swept_radius(self.robot) + gp.CLEARANCE_M + gp.GRID_MARGIN_M
        return gp.clearance_grid(self.obstacles, [[a.x, a.y], [b.x, b.y]], reach)

    def _sweep_failure(self, here: BasePlacement, step: lc.LocomotionStep, rates: lc.GaitRates,
                       grid: gp.ClearanceGrid) -> str | None:
        """Why the gait run ``step`` from the estimated root placement ``here`` would sweep too near an obstacle
        (:func:`snakehead.locomotion.ground_path.sweep_clear` on its predicted end, on ``grid``), else None."""
        a = lc.compose(here, self.offset)
        b = rates.predicted(step, here, self.offset)
        if gp.sweep_clear(grid, self.robot, step.gait.name, a, b, step.scale):
            return None
        return (f"the {step.gait.name} run ({step.cycles:.0f} x {step.scale:.2f}) from {placement_text(a)} would "
                f"sweep within {1000 * gp.EXECUTION_M:.0f} mm of an obstacle")

    def _leg_step(self, here: BasePlacement, route: gp.Route | None, k: int, straight_goal: BasePlacement,
                  tolerance: lc.Tolerance, rates: lc.GaitRates) -> lc.LocomotionStep | None:
        """The next gait run from ``here`` towards waypoint ``k`` of ``route`` (the body's middle there, square
        to the leg that reaches it, within WAYPOINT_TOLERANCE; an escape along the axis creeps), or towards
        ``straight_goal`` within ``tolerance`` when it is the last (or there is no route); None when there."""
        if route is None or k == len(route.waypoints) - 1:
            creep = route is not None and route.staging_creep
            if creep and abs(math.degrees(math.remainder(straight_goal.yaw - here.yaw, 2 * math.pi))) \
                    > tolerance.yaw_deg:  # from a staging point on the goal's axis: turn to its heading first
                m = lc.compose(here, self.offset)
                facing = lc.compose(m.moved(m.x, m.y, straight_goal.yaw), lc.inverse(self.offset))
                return lc.next_step(self.robot, here, facing, rates, tolerance=tolerance, frequency=self.frequency)
            return lc.next_step(self.robot, here, straight_goal, rates, tolerance=tolerance, frequency=self.frequency,
                                creep=creep)
        w, h = route.waypoints[k], route.headings[k - 1]
        goal = lc.compose(here.moved(float(w[0]), float(w[1]), float(h)), lc.inverse(self.offset))
        return lc.next_step(self.robot, here, goal, rates, tolerance=WAYPOINT_TOLERANCE, frequency=self.frequency,
                            creep=route.creep and k == 1)

    def _checked_step(self, here: BasePlacement, step: lc.LocomotionStep, rates: lc.GaitRates,
                      grid: gp.ClearanceGrid | None) -> tuple[lc.LocomotionStep, str | None]:
        """``step`` when its sweep is clear (``_sweep_failure``), else one cycle at half its amplitude, and
        so on (a smaller run sweeps less: its waves are smaller, it goes less far; the next run goes on) down to
        MIN_AMPLITUDE_SCALE; and why the last tried is not clear (None when it is)."""
        if grid is None:
            return step, None
        why = self._sweep_failure(here, step, rates, grid)
        while why is not None and step.scale > lc.MIN_AMPLITUDE_SCALE:
            step = lc.gait_run(step.gait.name, step.gait.direction, 1.0, 1.0, max_cycles=1, frequency=self.frequency,
                               scale=0.5 * step.scale, leg=step.leg)
            why = self._sweep_failure(here, step, rates, grid)
        return step, why
