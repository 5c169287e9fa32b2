"""Many plans at once: :func:`plan_many` plans each scene (or list of targets) with :func:`snakehead.plan`, here or
over an executor (a thread or process pool, Dask: ``snakehead._executors``, as maps are computed).

What travels to a worker is picklable: the scene and a :class:`RobotRecipe` (how to build the robot again from its
description), never a live robot or controller (their C++ objects do not pickle). Each worker thread builds the robot
and its :class:`~snakehead.solve.HeadController` once and reuses them for the plans it makes
(:class:`WorkerControllers`); the plan comes back without its robot, and the caller's robot is put back in it.
"""
from __future__ import annotations

import inspect
import os
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from .._errors import Infeasible, InputError, InputTypeError, MotionTooLong
from .._executors import as_executor, run_tasks
from .._validate import integer
from ..model.robot import BasePlacement, SnakeRobot
from ..scenes.scene import Scene
from ..solve.head_controller import HeadController
from .plan_bounds import TIMING_OPTIONS
from .plan_result import Plan, PlanProgress, ProgressCallback
from .planner import as_scene, plan

__all__ = ["plan_many", "plan_one", "PlanError", "RobotRecipe", "WorkerControllers", "WORKERS", "KEPT_CONTROLLERS"]

#: Controllers a worker thread keeps (one per robot, method and seed): the least recently used is dropped.
KEPT_CONTROLLERS = 4


@dataclass(frozen=True)
class RobotRecipe:
    """How to build a :class:`SnakeRobot` again (in another process): its description's arguments, the frames
    that bound its parts and its head's map file. Picklable; ``key`` names the robot it builds."""

    arguments: tuple  # sorted (name, value) pairs of SnakeRobot's description arguments
    frames: tuple  # (base_end, neck_end, head_tip) as the user named them
    map_path: str | None

    @classmethod
    def of(cls, robot: SnakeRobot) -> RobotRecipe:
        args: dict[str, Any] = {k: (os.fspath(v) if isinstance(v, os.PathLike) else v)
                                for k, v in robot.description_arguments.items()}
        for k in ("packages", "limits", "xacro_args"):  # mappings: as sorted pairs, so that the recipe hashes
            if args.get(k) is not None:
                args[k] = tuple(sorted((str(n), os.fspath(v) if isinstance(v, os.PathLike) else v)
                                       for n, v in dict(args[k]).items()))
        f = robot.user_frames
        return cls(tuple(sorted(args.items())), (f["base_end"], f["neck_end"], f["head_tip"]),
                   None if robot.map_path is None else os.fspath(robot.map_path))

    def build(self) -> SnakeRobot:
        args = dict(self.arguments)
        for k in ("packages", "limits", "xacro_args"):
            if args.get(k) is not None:
                args[k] = dict(args[k])
        base_end, neck_end, head_tip = self.frames
        return SnakeRobot(**args, base_end=base_end, neck_end=neck_end, head_tip=head_tip, map_path=self.map_path)


class WorkerControllers:
    """The robots and controllers of one process's worker threads, built once each and reused: per thread (a
    controller is not shared between threads: plans set its base), at most :data:`KEPT_CONTROLLERS` per thread,
    keyed by the robot (its recipe, or a scene's robot file, or the default robot), the method and the seed."""

    def __init__(self) -> None:
        self._local = threading.local()

    def get(self, recipe: RobotRecipe | None, robot_file: str | None, method: str, seed: int | None,
            inside: Path | None = None) -> HeadController:
        """The thread's controller for these (``inside``: the folder a scene's robot file may read from)."""
        kept: OrderedDict = self._local.__dict__.setdefault("kept", OrderedDict())
        key = (recipe, robot_file, method, seed, inside)
        if key in kept:
            kept.move_to_end(key)
            return kept[key]
        if recipe is not None:
            robot = recipe.build()
        else:
            robot = (SnakeRobot.from_file(robot_file, inside=inside) if robot_file is not None
                     else SnakeRobot.default())
        controller = HeadController(robot, method=method, seed=seed)
        kept[key] = controller
        while len(kept) > KEPT_CONTROLLERS:
            kept.popitem(last=False)
        return controller


#: This process's worker controllers (each process of a pool has its own).
WORKERS = WorkerControllers()


@dataclass
class PlanError:
    """A plan that ended in an error instead of a :class:`~snakehead.planning.plan_result.Plan` (a per-plan failure is a
    result of :func:`plan_many`): ``name`` (the scene's), ``error`` (the exception's type, e.g. ``"Infeasible"``,
    ``"MotionTooLong"``), ``message``. ``success`` is False and ``failure`` the message, as a failed plan's."""

    name: str
    error: str
    message: str
    planning_time_s: float = 0.0

    @property
    def success(self) -> bool:
        return False

    @property
    def failure(self) -> str:
        return f"{self.error}: {self.message}"


#: plan()'s options that plan_many takes (besides ``progress``, which is its own, and ``controller``, only without an
#: executor: a controller does not travel to workers).
_PLAN_OPTIONS = tuple(k for k in inspect.signature(plan).parameters if k not in ("targets", "progress"))


def _check_options(options: dict, executor: Any) -> None:
    """InputError for plan options plan_many does not take, or values plan() would refuse, before any work."""
    unknown = sorted(set(options) - set(_PLAN_OPTIONS))
    if unknown:
        raise InputError(f"plan_many has no option {unknown[0]!r}; plan's options are {', '.join(_PLAN_OPTIONS)}"
                         " (and plan_many's progress and executor)")
    if executor is not None and options.get("controller") is not None:
        raise InputError("controller= does not travel to workers: give robot= (and method=, seed=), and each worker "
                         "builds its controller once")
    robot = options.get("robot")
    if robot is not None and not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    method = options.get("method", "rotated")
    if not isinstance(method, str) or method not in ("rotated", "free_roll"):
        raise InputError(f"method must be 'rotated' or 'free_roll', got {method!r}")
    if options.get("seed", 1) is not None:
        integer(options.get("seed", 1), "seed", least=0, most=2**64 - 1)
    base = options.get("base")
    if base is not None and not isinstance(base, BasePlacement):
        raise InputTypeError(f"base must be a BasePlacement, got {type(base).__name__}")
    timing = options.get("timing")
    if timing is not None:
        if not isinstance(timing, dict):
            raise InputTypeError(f"timing must be a dict of retime's options, got {type(timing).__name__}")
        bad = [k for k in timing if k not in TIMING_OPTIONS]
        if bad:
            raise InputError(f"timing has no option {bad[0]!r}; its options are {', '.join(TIMING_OPTIONS)}")
    if not isinstance(options.get("allow_relocation", True), bool):
        raise InputTypeError("allow_relocation must be True or False")


def _scenes(target_sets: Any, obstacles: Any) -> list[Scene]:
    """Every target set as a Scene (InputError naming the first bad one), before any work."""
    if isinstance(target_sets, (str, os.PathLike, Scene)) or not isinstance(target_sets, Sequence):
        raise InputTypeError("target_sets must be a sequence (a list) of what plan() takes: scenes, scene files or "
                             f"lists of (position, direction) pairs; got {type(target_sets).__name__}")
    scenes = []
    for i, item in enumerate(target_sets):
        try:
            scenes.append(as_scene(item, obstacles=obstacles))
        except InputError as exc:
            raise type(exc)(f"target_sets[{i}]: {exc}") from None
    return scenes


def plan_one(recipe: RobotRecipe | None, scene: Scene, options: dict, keep_robot: bool = False
             ) -> Plan | PlanError:
    """One plan in a worker (module level, so that executors can pickle it): the worker's controller for the robot
    (:data:`WORKERS`), the plan without its robot unless ``keep_robot`` (the caller puts it back). Infeasible and MotionTooLong (and an
    InputError of the scene's content) are results (a :class:`PlanError`)."""
    options = dict(options)
    t0 = time.perf_counter()
    controller = options.pop("controller", None)
    if controller is None:
        robot_file = None if scene.robot_file is None else os.fspath(scene.robot_file)
        controller = WORKERS.get(recipe, robot_file, options.pop("method", "rotated"), options.pop("seed", 1),
                                 scene.robot_folder)
        options.pop("robot", None)
        if options.get("base") is None:  # the controller is reused: its base is set by every plan
            options["base"] = scene.base if scene.base is not None else BasePlacement()
    try:
        result: Plan | PlanError = plan(scene, controller=controller, **options)
    except (Infeasible, MotionTooLong, InputError) as exc:
        return PlanError(scene.name, type(exc).__name__, str(exc), time.perf_counter() - t0)
    if not keep_robot and isinstance(result, Plan):
        result.robot = None  # type: ignore[assignment]  # (its C++ chains do not pickle; the caller's is put back)
    return result


def plan_many(target_sets: Sequence[Any], *, executor: Any = None, progress: ProgressCallback | None = None,
              **plan_options: Any) -> list[Plan | PlanError]:
    """Plan each of ``target_sets`` (what :func:`snakehead.plan` takes as its first argument: a Scene, a scene
    file's path, or (position, direction) pairs) with ``plan_options`` (plan's keyword options, e.g. ``robot``,
    ``method``, ``seed``, ``timing``, ``obstacles``, ``allow_relocation``); the results in the order given.

    executor: None (here, one after the other), any ``concurrent.futures.Executor`` (a thread or process pool) or a
    Dask ``distributed.Client`` (or its ``get_executor()``). Each worker thread builds the robot and its controller
    once and reuses them (:class:`WorkerControllers`); the plans equal :func:`snakehead.plan`'s of each set.
    ``controller=`` is taken only without an executor.

    progress: called here as ``progress(record)`` with a :class:`~snakehead.planning.planner.PlanProgress` of kind
    ``"plan"`` as each plan finishes (in the order they finish): ``index`` plans done of ``count``, ``name`` (the
    scene's), ``solved`` (its success), ``seconds`` (its planning time), ``message`` (its failure, "" on success).

    Bad arguments raise :class:`~snakehead.InputError` before any plan is made (every target set is read and
    checked first). A plan that fails is a result: a :class:`~snakehead.planning.plan_result.Plan` whose ``success`` is
    False, or a :class:`PlanError` when plan() raised Infeasible, MotionTooLong or an InputError of its scene.
    """
    if progress is not None and not callable(progress):
        raise InputTypeError(f"progress must be a function of a PlanProgress (or None), got {type(progress).__name__}")
    _check_options(plan_options, executor)
    scenes = _scenes(target_sets, plan_options.pop("obstacles", ()))
    pool = None if executor is None else as_executor(executor)
    robot = plan_options.get("robot")
    recipe = RobotRecipe.of(robot) if robot is not None else None
    sent = {k: v for k, v in plan_options.items() if k != "robot"}  # the recipe stands for the robot
    robots: dict = {}  # the robots put back in plans that come back without theirs, by robot file
    t0 = time.perf_counter()
    finished = [0]

    def done(i: int, result: Plan | PlanError) -> None:
        if isinstance(result, Plan) and (result.robot is None or robot is not None):
            result.robot = robot if robot is not None else _robot_of(scenes[i], robots)
        finished[0] += 1
        if progress is not None:
            progress(PlanProgress("plan", scenes[i].name, finished[0], len(scenes), bool(result.success),
                                  float(result.planning_time_s), time.perf_counter() - t0,
                                  "" if result.success else str(result.failure)))

    if pool is None:  # here: the plans keep their robot
        results = []
        for i, scene in enumerate(scenes):
            results.append(plan_one(recipe, scene, sent, keep_robot=True))
            done(i, results[-1])
        return results
    return run_tasks(pool, plan_one, [(recipe, scene, sent) for scene in scenes], done)


def _robot_of(scene: Scene, robots: dict) -> SnakeRobot:
    """The robot of a scene planned without ``robot=``: its robot file's, else the default (built once per call)."""
    key = (None if scene.robot_file is None else os.fspath(scene.robot_file), scene.robot_folder)
    if key not in robots:
        robots[key] = scene.load_robot() or SnakeRobot.default()  # a scene file's: confined to its folder
    return robots[key]
