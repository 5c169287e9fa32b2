"""Whether the head phases succeed with the base at a goal, and where else to put it (steps 1 and 4 of
:class:`snakehead.closed_loop.loop.ClosedLoop`): a plan from the goal checked as the pipeline checks every plan, in
dynamics too; the straight body before the curl and the curling body kept clear of the obstacles; placements near a
goal that fails.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..collision import body_collisions as coll
from ..dynamics.sliding import predict_slide
from ..locomotion import goals as lc
from ..locomotion import ground_path as gp
from ..model.robot import BasePlacement
from ..planning.plan_result import Plan
from ..planning.planner import plan
from ..scenes.scene import Scene
from ..sim.compare import check_plan_span, compare
from ..sim.tracking import simulate_trajectory
from ..solve.head_controller import HeadController
from .loop_run import placement_text

__all__ = ["CURL_CHECKS", "CHECK_ZMP_OUTSIDE", "CHECK_BASE_LIFT", "NEARBY_STEP_M", "NEARBY_STEP_DEG", "GoalChecks"]

#: Every this many steps of the curl's path (of locomotion.CURL_STEPS) the goal's check puts the curling body
#: against the obstacles.
CURL_CHECKS = 4
#: The dynamics check of the head phases fails when the simulated ZMP leaves the planned support polygon by more
#: than this (m) or a base frame rises more than CHECK_BASE_LIFT (m): the body tips (a plan that tips goes out by
#: tens of millimetres and lifts its base by centimetres; the ZMP grazing the edge at the first tick does not).
CHECK_ZMP_OUTSIDE = 0.002
CHECK_BASE_LIFT = 0.005
#: When the body is as close to its goal as the gaits bring it and the head phases still fail, the loop looks for
#: another goal this far from it (m along and across, deg turned).
NEARBY_STEP_M = 0.08
NEARBY_STEP_DEG = 8.0


class GoalChecks:
    """The checks of a goal of the loop (where the base must lie for the head phases): ``scene`` and ``controller``
    plan the head phases (with the retiming options ``timing``, :func:`snakehead.plan`'s), ``obstacles`` are the
    scene's; ``dynamics_check``: simulate a plan from its own start (on the ground ``ground_options``, the
    :class:`~snakehead.closed_loop.gait_runner.GaitSimulator`'s) before it counts as succeeding."""

    def __init__(self, scene: Scene, controller: HeadController, *, timing: dict[str, Any] | None,
                 obstacles: list, dynamics_check: bool, ground_options: dict[str, Any]) -> None:
        self.scene, self.controller, self.robot = scene, controller, controller.robot
        self.timing, self.obstacles = timing, obstacles
        self.dynamics_check, self.ground_options = dynamics_check, ground_options

    def dynamics_failure(self, p: Plan) -> str | None:
        """The dynamics check of a plan, as the pipeline checks every plan: simulated from its own start (the base
        where the loop believes it lies, the joints as planned), not from the truth. None when the body does not
        tip in it (CHECK_ZMP_OUTSIDE, CHECK_BASE_LIFT), else why."""
        robot = self.robot
        checked = simulate_trajectory(robot, p.t, p.q, p.base, obstacles=self.obstacles, **self.ground_options)
        check_plan_span(p.t, [tg.time_s for tg in p.targets], checked)
        check = compare(robot, p.t, p.q, checked, base=p.base,
                        targets=[(tg.time_s, tg.position, tg.direction) for tg in p.targets] or None)
        if check["zmp_min_margin_m"] < -CHECK_ZMP_OUTSIDE or check["base_lift_m"] > CHECK_BASE_LIFT:
            return (f"in its dynamics check the simulated ZMP leaves the support polygon by "
                    f"{1000 * -check['zmp_min_margin_m']:.1f} mm and the base lifts "
                    f"{1000 * check['base_lift_m']:.1f} mm")
        return None

    def goal_failure(self, p: Plan) -> str | None:
        """Why the head phases planned at a candidate goal would fail: the plan's own failure, else its dynamics
        check (when ``dynamics_check``); None when they pass."""
        if p.failure is not None:
            return p.failure
        return self.dynamics_failure(p) if self.dynamics_check else None

    def straight_failure(self, goal: BasePlacement, q_bend: np.ndarray) -> str | None:
        """Why the body cannot lie straight where the curl into ``q_bend`` must start to reach ``goal``, or cannot
        curl from there: the straight body, or the body at any CURL_CHECKS-th step of the curl where the friction
        model slides it (:func:`snakehead.dynamics.sliding.predict_slide`), would come within GOAL_CLEARANCE_M
        of an obstacle (the gaits bring it there within their execution margin, its estimate off by the drift);
        else None."""
        if not self.obstacles:
            return None
        robot = self.robot
        straight = lc.straight_pose_for(robot, goal, q_bend)
        path = lc.curl_path(np.zeros(robot.n_joints), q_bend)
        slide = predict_slide(robot, path, straight)
        for k in list(range(0, len(path), CURL_CHECKS)) + [len(path) - 1]:
            d = coll.collision_check(robot, path[k][None], self.obstacles, slide[k], exact_within=1.0).distance[0]
            if d < gp.GOAL_CLEARANCE_M:
                where = "lie straight" if k == 0 else f"pass, {100 * k // (len(path) - 1)} % into its curl,"
                return (f"the body would {where} at {placement_text(slide[k])} {1000 * d:.0f} mm from an obstacle "
                        f"(straight at {placement_text(straight)} before its curl)")
        return None

    def nearby_goal(self, goal: BasePlacement, q_bend: np.ndarray, rings: int = 1) -> BasePlacement | None:
        """A placement near ``goal`` (NEARBY_STEP_M along and across, NEARBY_STEP_DEG turned; ``rings`` times
        that at the most) from which the head phases are planned successfully and pass the dynamics check, and
        whose straight pose and curl keep clear of the obstacles (:meth:`straight_failure`), the nearest first;
        None if there is none."""
        d, a = NEARBY_STEP_M, math.radians(NEARBY_STEP_DEG)
        for offset in [(f * x, f * y, f * t) for f in range(1, rings + 1)
                       for x, y, t in ((d, 0, 0), (-d, 0, 0), (0, d, 0), (0, -d, 0), (0, 0, a), (0, 0, -a))]:
            candidate = lc.compose(goal, BasePlacement(*offset))
            if self.straight_failure(candidate, q_bend) is not None:
                continue
            p = plan(self.scene, controller=self.controller, base=candidate, allow_relocation=False,
                     base_shape=q_bend, timing=self.timing)
            if self.goal_failure(p) is None:
                return candidate
        return None
