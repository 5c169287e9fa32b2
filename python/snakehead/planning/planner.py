"""The planner: head targets (a scene) -> a checked whole-body motion sampled at the 2 ms control period.

It strings the control process of Section 3.3 together on any snake robot. The body starts in the bending state
(Figs. 17b, 22a: the base on its optimised arc, the neck and head curled flat on the ground inside it:
:func:`bending_state`) and lifts the head to the initial state of Section 3.3 (1) (the base arc joined to the
neck-and-head Bezier: ``backbone.initial_configuration``). Each target is solved by the
:class:`~snakehead.solve.HeadController` and reached by a whole-body move (Section 3.2: the Cartesian
interpolation of Eqs. 41-44 where it is valid, else joint space through a stable detour when needed; see
``Waypoints.move``), or, for targets approached along a line, by the head's poses solved every few millimetres
along it. The waypoints are joined by the multi-segment interpolation at 2 ms, and the result is checked at every
sample: the ZMP inside the support polygon (Eqs. 36-40), every neck and head link above the ground, no link
touching an obstacle.

Getting from an arbitrary lying state into the bending state is a reconfiguration on the ground (the paper's rolling
gait or turning in place) that is not part of these plans.

The path through the waypoints is timed at the end by the time-optimal retiming (``retiming.timing.retime``:
TOPP-RA under joint velocity, acceleration and torque limits, the ZMP inside the support polygon by a margin and
the ground's friction); the motion rests at every target.

The planner's parts, by concern: what a plan returns (:mod:`.plan_result`), the bounds checked before anything is
solved (:mod:`.plan_bounds`), the start state (:mod:`.start_state`), the base's choice and relocation
(:mod:`.base_choice`), the targets' solves (:mod:`.target_solves`), the path and its checks (:mod:`.waypoints`),
and what a controller keeps from one plan for the next (:mod:`.plan_cache`).
"""
from __future__ import annotations

import dataclasses
import math
import os
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import Infeasible, InputError, InputTypeError, MotionTooLong, entry_point, inputs_checked
from .._validate import integer, joint_vector, sequence
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..model.placement import GroundFrame
from ..model.robot import BasePlacement, SnakeRobot
from ..retiming.timing import resolve_limits
from ..scenes.ground_scene import base_on_slope, scene_in_ground_frame
from ..scenes.scene import Scene, Target, load_scene
from ..solve.head_controller import HeadController
from ..solve.whole_body import PlanSolves, clear_of_obstacles
from . import plan_bounds
from .base_choice import choose_base, out_of_range, shape_of
from .fallbacks import retime_slower
from .plan_bounds import check_size, check_timing
from .plan_cache import plan_cache_of
from .plan_result import Plan, PlanProgress, ProgressCallback, TargetResult
from .start_state import LEAN_LIFT_SCREEN, LEAN_LIFT_TRIES, LIFT_STEPS, bending_state, lean_lift_ends
from .target_solves import solve_noted
from .waypoints import NO_DETOUR, TRACKED, Waypoints


def as_scene(targets: Any, *, obstacles: Sequence[Any] = (), base: BasePlacement | None = None) -> Scene:
    """A :class:`Scene` from a scene, a scene file's path, or (position, direction) pairs (with ``obstacles``), in
    the frame it is planned in: on a plane terrain the plane's ground frame (``scenes.ground_scene``; its base
    placement then holds the frame), else as it is. InputError for a terrain that cannot be planned on yet."""
    if isinstance(targets, Scene):
        scene = targets
        obstacles = sequence(obstacles, "obstacles")
        if obstacles:
            scene = dataclasses.replace(scene, obstacles=tuple(scene.obstacles) + obstacles)
        return scene_in_ground_frame(scene)[0]
    if isinstance(targets, (str, os.PathLike)):
        return as_scene(load_scene(targets), obstacles=obstacles, base=base)
    return Scene.from_targets(targets, obstacles=obstacles, base=base)


@entry_point
def plan(targets: Scene | str | os.PathLike[str] | Sequence[tuple[npt.ArrayLike, npt.ArrayLike]], *,
         robot: SnakeRobot | None = None, controller: HeadController | None = None,
         obstacles: Sequence[BoxObstacle | WallWithHole | MeshObstacle] = (), base: BasePlacement | None = None,
         method: str = "rotated", seed: int | None = 1, allow_relocation: bool = True,
         timing: dict[str, Any] | None = None, base_shape: npt.ArrayLike | None = None,
         start_q: npt.ArrayLike | None = None, progress: ProgressCallback | None = None) -> Plan:
    """Plan the head through ``targets`` and check the motion (the control process of Section 3.3).

    Parameters
    ----------
    targets : a :class:`~snakehead.scenes.Scene`, a scene file's path, or (position, direction) pairs (m, world;
        the direction is the head's x-axis), each then held 1 s.
    robot : the snake (default: the scene's robot file, else ``SnakeRobot.default()``).
    controller : a :class:`~snakehead.solve.HeadController` to solve the head with (default: one for ``robot``
        with its head's map, ``method`` and ``seed``).
    obstacles : more obstacles (``geometry.BoxObstacle``, ``geometry.WallWithHole``) besides the scene's.
    base : where the base lies at first (default: the scene's, else ``BasePlacement()``); when a target cannot be
        reached from there, the planner chooses another placement (and flat shape) that reaches every target: the
        plan starts there and ``relocation`` says what locomotion must do first (unless ``allow_relocation`` is
        False: then the base stays and the plan fails on the targets it cannot reach).
    method : the head IK: "rotated" (the paper's Fig. 9) or "free_roll".
    seed : the head TRAC-IK's seed (the plan is a function of it); None for unseeded.
    timing : options of the time-optimal retiming (``retiming.timing.retime``: ``acceleration_limit`` rad/s^2,
        ``velocity_limit`` rad/s, ``torque_limit`` N m, ``zmp_margin`` m, ``friction``); its defaults otherwise.
    base_shape : a configuration (n,) whose base joints (and those of the neck's links that stay on the ground) give
        the base's flat shape at ``base`` (default: the controller's initial configuration's): a closed loop that
        curled the body into a relocation's shape plans on from it (``snakehead.closed_loop.loop``).
    start_q : the configuration (n,) the plan starts from instead of the bending state it would choose: the body as
        it lies (measured) in a bending state on the ground, so that the plan starts where the robot is (a closed
        loop, ``snakehead.closed_loop.loop``). Its base shape is ``base_shape``'s default. Used when the base stays (no
        relocation); a note says so otherwise.
    progress : called as ``progress(record)`` with a :class:`PlanProgress` after each target is solved (in the
        scene's order) and when each stage over the whole plan begins (choosing the base, the timing, the checks);
        an exception it raises stops the plan.

    Bounds, checked before anything is solved (``snakehead.InputError`` naming the scene): at most
    ``scenes.MAX_TARGETS`` (1000) targets; the targets' holds at most
    :data:`~snakehead.planning.plan_bounds.MAX_MOTION_S` (2000 s: MAX_SAMPLES samples at 2 ms) together; at most
    :data:`~snakehead.planning.plan_bounds.MAX_POSES` poses solved in all (the targets and the poses along their line
    approaches). The motion's length is checked again after each target is solved (the holds and the least
    time the joints' velocity limits allow for the moves so far) and while the path is timed, before it is sampled.

    Memory grows with the motion's 2 ms samples, not with the targets: the plan keeps t, q, qd and the checks'
    results, ~370 bytes per sample on the 16-joint default robot (8 + 2 x 128 for t, q, qd; ~105 for the ZMP, its
    margin, the momenta, the CoM and the ground clearance); the world frames of the samples (2.5 kB each) are made
    and dropped a chunk at a time (``dynamics.stability.SAMPLE_CHUNK``). Measured peak of ``snakehead plan --no-sim``
    (bench/many_targets.py, figures included): ~300 MiB + ~0.75 kB per sample, e.g. 100 targets, 556 s of motion,
    277,699 samples: 498 MiB; at MAX_SAMPLES (2000 s) about 1 GiB.

    Returns a :class:`Plan` (``success``, ``failure``, ``t``, ``q``, ``targets`` with their errors,
    ``min_zmp_margin_m``, ``min_ground_clearance_m``, ``duration_s``, ``planning_time_s``).

    On a slope (a scene whose ``[terrain]`` is a plane) the plan is made in the plane's ground frame
    (:class:`~snakehead.model.placement.GroundFrame`: the slope is z = 0 there and gravity leans) and returned in
    it: ``plan.base.ground.matrix`` takes its poses to the world. The scene's targets, obstacles and base (and
    ``base``) are given in the world. A slope steeper than the friction holds (tan > mu) is ``Infeasible``.
    """
    t_start = time.perf_counter()
    scene = as_scene(targets, obstacles=obstacles, base=base)
    if base is not None and scene.base is not None:  # a base given in the world, on the scene's slope
        base = base_on_slope(base, scene.base.ground)
    if progress is not None and not callable(progress):
        raise InputTypeError(f"progress must be a function of a PlanProgress (or None), got {type(progress).__name__}")
    lines = check_size(scene)  # before anything is solved
    _check_options(timing, method, seed, allow_relocation)
    controller = _controller_for(scene, robot, controller, base, method, seed)
    robot = controller.robot
    if timing:  # checked before anything is planned: a bad option is the caller's, found at once
        check_timing(robot, timing)
    check_slope(scene.name, controller.base.ground, resolve_limits(robot, **(timing or {})).friction)
    start_q, base_shape = _start_shapes(robot, start_q, base_shape)
    inputs_checked()  # from here on an InputError would be a bug of the planner's (the entry point says so)
    obstacles = list(scene.obstacles)
    notes: list[str] = [controller.dexterous_note] if controller.dexterous_threshold < 100.0 else []
    report = _Progress(progress, scene, t_start, robot, timing)
    solved = PlanSolves()  # the plan's solves, shared by choose_base and the targets below
    reported = len(scene.reported)
    report.stage("base", f"solving the {reported} target{'' if reported == 1 else 's'} from the start to choose the "
                         "base")
    chosen, q_shape, relocation, base_notes = choose_base(controller, scene.reported, obstacles, allow_relocation,
                                                          base_shape, solved=solved)
    notes += base_notes
    way = Waypoints(robot, chosen, obstacles)
    if start_q is not None and relocation is not None:
        notes.append("start_q is not used: the plan starts at the relocated base, in its bending state")
        start_q = None
    way.start("bending state", bending_state(controller, q_shape, chosen) if start_q is None else start_q)
    q = _lift(way, controller, q_shape)
    run = _Run(controller, scene, lines, chosen, obstacles, way, notes, solved, report)
    run.reach_targets(q)
    reached_at = [tg.time_s for tg in run.results]  # waypoint indices: _finish turns them into times

    def finish(options: dict[str, Any] | None) -> Plan:
        for tg, k in zip(run.results, reached_at):
            tg.time_s = k
        way.timing_failure = None
        return _finish(scene.name, way, run.results, t_start, obstacles=obstacles, notes=notes, scene=scene,
                       timing=options, stage=report.stage)

    try:
        plan = retime_slower(finish, timing, finish(timing))
    except MotionTooLong as exc:
        raise MotionTooLong(f"scene {scene.name!r}: {exc}: split the scene into scenes planned one after the other"
                            ) from None
    plan.relocation = relocation
    if allow_relocation and relocation is None:
        plan.out_of_range = out_of_range(robot, chosen, scene.reported)
    return plan


def check_slope(name: str, ground: GroundFrame, friction: float) -> None:
    """Infeasible when the ground ``ground`` is steeper than ``friction`` holds a body lying still on it
    (tan(slope) > mu: the weight's pull along the slope exceeds what friction gives)."""
    slope = math.radians(ground.slope_deg)
    if math.tan(slope) > friction:
        raise Infeasible(f"scene {name!r}: its ground slopes {ground.slope_deg:.1f} deg, steeper than the friction "
                         f"holds a body lying on it (tan {ground.slope_deg:.1f} deg = {math.tan(slope):.3f} > "
                         f"mu = {friction:g}): the base would slide")


def _check_options(timing: Any, method: Any, seed: Any, allow_relocation: Any) -> None:
    """InputError/InputTypeError for a bad ``timing`` (not a dict), ``method``, ``seed`` or ``allow_relocation`` of
    :func:`plan` (checked even when a controller, with its own method and seed, is given: a bad value is a mistake
    either way)."""
    if timing is not None and not isinstance(timing, dict):
        raise InputTypeError(f"timing must be a dict of retime's options, got {type(timing).__name__}")
    if not isinstance(method, str) or method not in ("rotated", "free_roll"):
        raise InputError(f"method must be 'rotated' or 'free_roll', got {method!r}")
    if seed is not None:
        integer(seed, "seed", least=0, most=2**64 - 1)
    if not isinstance(allow_relocation, (bool, np.bool_)):  # "False" or None would pass a truth test
        raise InputTypeError(f"allow_relocation must be True or False, got {type(allow_relocation).__name__} "
                             f"{allow_relocation!r}")


def _controller_for(scene: Scene, robot: Any, controller: Any, base: BasePlacement | None, method: str,
                    seed: int | None) -> HeadController:
    """The controller :func:`plan` solves with: the one given (placed at ``base``, else at the scene's base, when
    either is given), else a new one for ``robot`` (default: the scene's robot file, else the default robot)."""
    if controller is not None:
        if not isinstance(controller, HeadController):
            raise InputTypeError(f"controller must be a HeadController, got {type(controller).__name__}")
        if robot is not None and robot is not controller.robot:
            raise InputError("give a robot or a controller (whose robot is used), not both")
        chosen = base if base is not None else scene.base
        if chosen is not None:
            controller.base = chosen
        return controller
    if robot is None:
        robot = scene.load_robot() or SnakeRobot.default()
    elif not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return HeadController(robot, base_pose=base if base is not None else scene.base, method=method, seed=seed)


def _start_shapes(robot: SnakeRobot, start_q: npt.ArrayLike | None, base_shape: npt.ArrayLike | None
                  ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """:func:`plan`'s ``start_q`` and ``base_shape`` checked (joint vectors of the robot); the base's shape is the
    start's when only ``start_q`` is given."""
    start = joint_vector(start_q, robot.n_joints, "start_q") if start_q is not None else None
    if start is not None and base_shape is None:
        base_shape = start
    shape = joint_vector(base_shape, robot.n_joints, "base_shape") if base_shape is not None else None
    return start, shape


class _Progress:
    """What :func:`plan` tells its ``progress`` callback (stages and targets), and the check of the motion's length
    after each target (the moves so far at the joints' velocity limits ``timing`` allows, and the holds)."""

    def __init__(self, progress: ProgressCallback | None, scene: Scene, t_start: float, robot: SnakeRobot,
                 timing: dict[str, Any] | None) -> None:
        self.progress, self.scene, self.t_start = progress, scene, t_start
        self.count = len(scene.targets)
        self.velocity = resolve_limits(robot, **(timing or {})).velocity  # for the least duration of the moves

    def stage(self, what: str, message: str) -> None:
        """A stage over the whole plan begins (see :class:`PlanProgress`)."""
        if self.progress is not None:
            self.progress(PlanProgress("stage", what, count=self.count,
                                       elapsed_s=time.perf_counter() - self.t_start, message=message))

    def target(self, k: int, sol: Any, seconds: float, way: Waypoints) -> None:
        """Target k (0-based) is solved and the move to it planned: tell progress; MotionTooLong once the motion
        so far cannot fit in MAX_MOTION_S (the scene's input was valid: its moves only turn out too long)."""
        tg, count = self.scene.targets[k], self.count
        if self.progress is not None:
            self.progress(PlanProgress("target", tg.name, k + 1, count, bool(sol.success), seconds,
                                       time.perf_counter() - self.t_start,
                                       "" if sol.success else str(sol.message)))
        least = way.least_duration(self.velocity)
        if least > plan_bounds.MAX_MOTION_S:
            raise MotionTooLong(f"scene {self.scene.name!r}: the motion to its target {k + 1} of {count} "
                                f"({tg.name!r}) lasts at least {least:.0f} s (the moves at the joints' velocity "
                                f"limits and the holds); a plan lasts at most {plan_bounds.MAX_MOTION_S:g} s "
                                "(MAX_MOTION_S): split the scene into scenes planned one after the other")


def _lift(way: Waypoints, controller: HeadController, q_shape: np.ndarray) -> np.ndarray:
    """The lift from the start state (``way``'s last waypoint) to the initial state of Section 3.3 (1) (the head
    lifted on its Bezier, with the base's shape ``q_shape``), when that is a safe state at the base (it is then a
    stop: the lift comes to rest there, Fig. 17c-d); its configuration, or the start's when it is not safe (the
    first move then goes straight to the first target). The lift's path and timing are the same for every plan from
    a base of this shape wherever it lies: they are kept in ``plan_cache_of(controller)`` (the path only without
    obstacles: with them it is checked again)."""
    robot, obstacles = controller.robot, way.obstacles
    q = shape_of(robot, q_shape, controller.q_initial)
    if not (way.feasible(q[None])[0] and clear_of_obstacles(robot, q, obstacles, way.base)):
        return way.qs[-1] if way.base.on_flat_ground else _lean_lift(way, controller, q)
    lifts = plan_cache_of(controller).lift_paths
    key = (np.round(way.qs[-1], 9).tobytes(), np.round(q, 9).tobytes())
    keep = not obstacles and way.base.on_flat_ground  # on a slope a lift safe at one heading may not be at another
    kept = lifts.get(key) if keep else None
    if kept is not None:
        way.append_path("initial state (head lifted)", *kept)
    else:
        first = len(way.qs) - 1
        marks = len(way.qs), len(way.methods)
        method = way.move("initial state (head lifted)", q, n=LIFT_STEPS)
        if method == NO_DETOUR and not way.base.on_flat_ground:  # a leaning lift that a checked path reaches
            del way.qs[marks[0]:], way.labels[marks[0]:], way.methods[marks[1]:]
            return _lean_lift(way, controller, q)
        if keep:
            lifts.put(key, (np.array(way.qs[first:]), method))
    way.lift_index = way.stop()
    if way.base.on_flat_ground:  # on a slope the lift's timing and checks depend on the heading: nothing is kept
        way.lift_cache = plan_cache_of(controller).timed_lifts
        way.checked_lifts = plan_cache_of(controller).checked_lifts
    return q


def _lean_lift(way: Waypoints, controller: HeadController, q: np.ndarray) -> np.ndarray:
    """On a slope, where the initial state q is not safe at the plan's base (its weight leans): the lift to a safe
    lifted state near it (:func:`~snakehead.planning.start_state.lean_lift_ends`): the first of LEAN_LIFT_SCREEN
    that a tracked path from the bending state reaches, else the first of LEAN_LIFT_TRIES that a whole-body move
    reaches with a checked path (not ``NO_DETOUR``); a stop, as the lift is. The start's configuration when none
    does (the first move then goes straight to the first target, as :func:`_lift`'s)."""
    robot, obstacles = controller.robot, way.obstacles

    def safe(qs: np.ndarray) -> np.ndarray:
        ok = way.feasible(qs)
        for k in np.flatnonzero(ok) if obstacles else ():
            ok[k] = clear_of_obstacles(robot, qs[k], obstacles, way.base)
        return ok

    ends = lean_lift_ends(way, q, safe, LEAN_LIFT_SCREEN)
    for end in ends:  # the first reached by a checked tracked path (cheap: no detour searched)
        path = way.tracked_path(end, LIFT_STEPS)
        if path is not None:
            way.append_path("initial state (head lifted, leaning)", path, TRACKED)
            way.lift_index = way.stop()
            return end
    for end in ends[:LEAN_LIFT_TRIES]:
        marks = len(way.qs), len(way.methods)
        if way.move("initial state (head lifted, leaning)", end, n=LIFT_STEPS) != NO_DETOUR:
            way.lift_index = way.stop()
            return end
        del way.qs[marks[0]:], way.labels[marks[0]:], way.methods[marks[1]:]
    return way.qs[-1]


@dataclass
class _Run:
    """The targets of one plan being reached in the scene's order, from the chosen base: each solved (with the base
    kept, :func:`~snakehead.planning.target_solves.solve_noted`) and moved to on ``way``; ``results`` the reported
    targets (their ``time_s`` the waypoint's index until the path is timed, :func:`_finish`)."""

    controller: HeadController
    scene: Scene
    lines: dict[int, list[np.ndarray]]  # the poses along each line approach (check_size)
    base: BasePlacement
    obstacles: list[Any]
    way: Waypoints
    notes: list[str]
    solved: PlanSolves  # the plan's solves, shared with choose_base
    report: _Progress
    results: list[TargetResult] = field(default_factory=list)

    def reach_targets(self, q: np.ndarray) -> np.ndarray:
        """Every target from configuration q, a run at a time (a target and the following ones approached along a
        line from it); the last configuration."""
        targets = self.scene.targets
        k = 0
        while k < len(targets):
            end = k
            while end + 1 < len(targets) and targets[end + 1].approach == "line":
                end += 1
            q = self.reach_target(k, q) if end == k else self.reach_line_run(k, end, q)
            k = end + 1
        return q

    def arrive(self, target: Target, sol: Any) -> None:
        """The motion rests at the last waypoint, ``target`` reached by ``sol``: reported (unless a via target),
        then held."""
        if not target.via:  # time_s holds the waypoint's index until the path is timed (_finish)
            self.results.append(TargetResult(target.name, target.position, target.direction, self.way.stop(), sol))
        if target.hold_s > 0:
            self.way.hold(target.hold_s)

    def reach_target(self, k: int, q: np.ndarray) -> np.ndarray:
        """Target k solved from q and reached by a whole-body move; the configuration it is solved at."""
        tg = self.scene.targets[k]
        clock = time.perf_counter()
        sol = solve_noted(self.controller, tg.position, tg.direction, q, self.base, self.obstacles, tg.name,
                          self.notes, solved=self.solved)
        self.way.move(tg.name, sol.q)
        self.arrive(tg, sol)
        self.report.target(k, sol, time.perf_counter() - clock, self.way)
        return sol.q

    def line_run_poses(self, k: int, end: int) -> tuple[list[tuple[str, np.ndarray, np.ndarray, Target | None]],
                                                         list[int]]:
        """The poses of the run of targets k..end (k's, then those along each line up to and including its
        target): (label, position, direction, the scene's target when the pose is one), and the index of the
        target each leads to."""
        targets = self.scene.targets
        poses: list[tuple[str, np.ndarray, np.ndarray, Target | None]] = [
            (targets[k].name, targets[k].position, targets[k].direction, targets[k])]
        owner = [k]
        for j in range(k + 1, end + 1):
            line = self.lines[j]
            for m, p in enumerate(line):
                last = m == len(line) - 1
                label = targets[j].name if last else f"{targets[j].name} ({m + 1}/{len(line)})"
                poses.append((label, p, targets[j].direction, targets[j] if last else None))
                owner.append(j)
        return poses, owner

    def reach_line_run(self, k: int, end: int, q: np.ndarray) -> np.ndarray:
        """Targets k..end, each after k approached along a line from the one before: the poses along the lines
        solved backwards from the deepest (the most constrained, e.g. only the head link in a hole) out to target
        k, each from the previous joints (a branch of solutions that clears an obstacle deep in it also clears it
        further out, while one chosen from the outside may run into it); then a whole-body move to the first and
        joint-space steps along the rest. The last pose's configuration."""
        poses, owner = self.line_run_poses(k, end)
        seconds = dict.fromkeys(range(k, end + 1), 0.0)  # each target's share of the run's solves and moves
        sols: list = [None] * len(poses)
        q_back = q
        for m in range(len(poses) - 1, -1, -1):
            clock = time.perf_counter()
            label, p, d, _ = poses[m]
            sols[m] = solve_noted(self.controller, p, d, q_back, self.base, self.obstacles, label, self.notes,
                                  near=m < len(poses) - 1)
            if sols[m].success:
                q_back = sols[m].q
            seconds[owner[m]] += time.perf_counter() - clock
        for m, (label, _, _, line_target) in enumerate(poses):
            clock = time.perf_counter()
            if m == 0:
                self.way.move(label, sols[m].q)
            else:
                self.way.move_joint(label, sols[m].q)
            if line_target is not None:
                self.arrive(line_target, sols[m])
            seconds[owner[m]] += time.perf_counter() - clock
            if line_target is not None:
                self.report.target(owner[m], sols[m], seconds[owner[m]], self.way)
        return sols[-1].q


def _finish(name: str, plan: Waypoints, targets: Any, t_start: float, obstacles: Sequence[Any] = (),
            notes: Sequence[str] = (), scene: Scene | None = None, timing: dict[str, Any] | None = None,
            stage: Callable[[str, str], None] | None = None) -> Plan:
    robot, base = plan.robot, plan.base
    notes = list(notes)
    stage = stage or (lambda what, message: None)
    stage("timing", f"timing the motion through {len(plan.qs)} waypoints (TOPP-RA under the robot's limits)")
    traj = plan.sample(notes, timing or {})
    t, q, qd = traj.t, traj.q, traj.qd
    del traj  # its accelerations (unused) are freed before the checks
    stage("checks", f"checking the {len(t)} samples of {float(t[-1] - t[0]):.1f} s of motion (ZMP, ground"
                    + (", obstacles)" if obstacles else ")"))
    for tg in targets:  # the waypoint each target was reached at -> when
        tg.time_s = plan.times[tg.time_s]
    # the ZMP and the ground at every sample, the ground, self and obstacles proven between them, in C++
    # (Waypoints.finish_checks: planning.motion_checks.finish_checks)
    dyn, clearance, distance, proof = plan.finish_checks(t, q, qd)
    states = [(lab, float(when), qk) for lab, when, qk in zip(plan.labels, plan.times, plan.qs)]
    return Plan(name=name, robot=robot, base=base, t=t, q=q, qd=qd, states=states, targets=targets,
                stability=dyn, ground_clearance=clearance, obstacles=list(obstacles), obstacle_distance=distance,
                planning_time_s=time.perf_counter() - t_start, notes=notes, segments=list(plan.methods), scene=scene,
                timing_failure=plan.timing_failure, motion_proof=proof)


__all__ = ["plan", "as_scene", "check_slope"]
