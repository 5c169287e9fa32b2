"""The pipeline behind ``snakehead demo`` and ``snakehead plan``, as a library function: for each scene,
plan -> simulate (MuJoCo) -> compare -> figures -> animation, then one report (``report.json``, ``summary.md``).

>>> from snakehead.app.pipeline import run_scenes
>>> from snakehead.scenes import paper_scene
>>> report = run_scenes([paper_scene("spheres")], "out")          # doctest: +SKIP

:func:`run_scenes` deals the scenes into lanes, one a core, and writes the report. Its parts: one scene from the
bending state (:mod:`.planned_scene`) or from lying straight by the closed loop (:mod:`.loop_scene`), the files
written for a scene (:mod:`.scene_outputs`), work run in a process beside this one (:mod:`.beside`), the settings
(:mod:`.settings`) and the progress lines (:mod:`.progress`); their public names are re-exported here.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

from .._errors import InputError, InputTypeError
from .._validate import file_name_key, sequence
from ..kinematics import reachability
from ..model.robot import SnakeRobot
from ..scenes.scene import Scene
from ..solve.head_controller import HeadController
from . import report as rep
from .beside import FIGURE_PROCESS_TIMEOUT_S, LANE_PROCESS_TIMEOUT_S, STOP_GRACE_S, Beside
from .loop_scene import LOOP_ASSUMPTION, LOOP_ASSUMPTION_OUTSIDE_FIX, loop_entry, run_loop_scene
from .planned_scene import PendingScene, run_scene, start_scene
from .progress import Progress, outcome_line, plan_progress_line
from .scene_outputs import DYNAMICS_FIGURES
from .settings import FAST, NORMAL, PAPER_START, Settings, mujoco_available

if TYPE_CHECKING:
    from ..kinematics.reachability.reachability_map import ReachabilityMap
    from ..model.robot import BasePlacement

__all__ = [
    "run_scenes", "scene_lanes",
    # re-exported: the parts of the pipeline
    "Beside", "FIGURE_PROCESS_TIMEOUT_S", "LANE_PROCESS_TIMEOUT_S", "STOP_GRACE_S", "LOOP_ASSUMPTION",
    "LOOP_ASSUMPTION_OUTSIDE_FIX", "loop_entry", "run_loop_scene", "PendingScene", "run_scene", "start_scene",
    "Progress", "outcome_line", "plan_progress_line", "DYNAMICS_FIGURES", "FAST", "NORMAL", "PAPER_START", "Settings",
    "mujoco_available",
]


def run_scenes(scenes: Sequence, out: str | Path, *, controller: HeadController | None = None,
               robot: SnakeRobot | None = None, workspace_map: ReachabilityMap | None = None,
               settings: Settings | None = None, progress: Progress | None = None, command: str = "plan",
               notes: Sequence[str] = (), solution_figure: bool = False, on_controller: Callable | None = None,
               start: BasePlacement | str | None = None) -> dict:
    """Every scene through :func:`~.planned_scene.run_scene` with one controller; writes ``report.json`` and
    ``summary.md`` into ``out`` and returns the report. ``controller`` defaults to one for ``robot`` (default: the first scene's robot
    file, else the default robot) with ``workspace_map`` (default: the robot's, cached or computed). ``start``: run
    every scene from the body lying there instead (:func:`~.loop_scene.run_loop_scene`: a placement of the tail, or
    :data:`~.settings.PAPER_START`).

    With ``settings.parallel`` (Linux, more than one core and one scene, no ``controller``, ``on_controller`` or
    ``start`` given) the scenes run in lanes, one a core (:func:`scene_lanes`): the first in this process, the
    others each in a forked process with a controller of its own, made alike (the same map, method and seed: the
    same plans as one controller planning every scene in turn)."""
    scenes = _distinct_names(scenes)
    settings = settings or Settings()
    progress = progress or Progress()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lanes = [list(scenes)]
    beside: list[Beside] = []
    # (from the first lane's fork on: a Ctrl-C while this process still makes its controller stops them too)
    try:
        if controller is None:
            if robot is None:
                robot = scenes[0].load_robot() or SnakeRobot.default()
            if on_controller is None and start is None:
                lanes = scene_lanes(scenes, settings)
            with progress.stage("the head's reachability map and its dexterous centre G0"):
                workspace_map = _head_map(robot, workspace_map, progress)
                if len(lanes) > 1:  # forked before this process makes its controller (a TracIK: not fork-safe)
                    if settings.figures:
                        _preload_figures(progress)
                    for other in lanes[1:]:
                        beside.append(_lane_beside(other, robot, workspace_map, out, settings, progress,
                                                   solution_figure))
                controller = HeadController(robot, workspace_map, method=settings.method, seed=settings.seed)
            if controller.dexterous_threshold < 100.0:
                progress.say(controller.dexterous_note)
        if on_controller is not None:
            on_controller(controller)
        entries = _run_lane(lanes[0], controller, out, settings, progress, solution_figure, start,
                            figures_beside=len(lanes) < _cores())
        for lane in beside:
            entries.update(lane.result())
    except BaseException:  # interrupted or failed: the lanes beside stop too (they would run on, and be waited for)
        for lane in beside:
            lane.stop()
        raise
    report = _report(command, [scene.name for scene in scenes], entries, controller, settings, progress, notes)
    rep.write_json(report, out / "report.json")
    rep.write_summary(report, out / "summary.md")
    return report


def _report(command: str, names: Sequence[str], entries: dict, controller: HeadController, settings: Settings,
            progress: Progress, notes: Sequence[str]) -> dict:
    """The run's report: the scenes' entries in the scenes' order (``names``), the settings, the robot, the stages
    and notes, the paper's numbers and the environment."""
    robot = controller.robot
    return {"command": command, "scenarios": {name: entries[name] for name in names},
            "settings": {**settings.as_dict(), "map": _map_label(controller.map)},
            "robot": {"source": robot.source or "URDF", "joints": robot.n_joints,
                      "parts": {"base": robot.parts.base.stop - robot.parts.base.start,
                                "neck": robot.parts.neck.stop - robot.parts.neck.start,
                                "head": robot.parts.head.stop - robot.parts.head.start},
                      "dexterous_threshold": controller.dexterous_threshold},
            "run_time_s": progress.elapsed(), "stages": progress.stages, "notes": list(notes),
            "paper": rep.PAPER, **rep.environment()}


def scene_lanes(scenes: Sequence[Scene], settings: Settings) -> list[list[Scene]]:
    """The scenes dealt round-robin into lanes that run side by side, one a core (at most one a scene); one lane
    (every scene in this process) without ``settings.parallel``, off Linux (no fork) or on one core."""
    n = min(_cores(), len(scenes)) if settings.parallel and sys.platform.startswith("linux") else 1
    return [list(scenes[k::n]) for k in range(max(n, 1))]


def _cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _head_map(robot: SnakeRobot, workspace_map: ReachabilityMap | None, progress: Progress) -> ReachabilityMap:
    """``workspace_map``, else the robot's head map (cached, or computed and cached)."""
    if workspace_map is not None:
        return workspace_map
    if robot.map_path is None:
        progress.say("this robot has no map: computing one (cached for the next run)")
    workspace_map = reachability.map_for(robot, progress=not progress.quiet)
    if workspace_map.path is not None:
        progress.say(f"the head's map: {workspace_map.path}")
    return workspace_map


def _preload_figures(progress: Progress) -> None:
    """The figures' libraries (matplotlib, its Agg canvas and 3-D axes) in memory before the lanes and their figure
    processes are forked, so that none imports them again. The figure modules imported at this module's top have
    loaded them: the stage only keeps its place in the report's stages."""
    with progress.stage("the figures' libraries (matplotlib)"):
        pass


def _lane_beside(lane: list[Scene], robot: SnakeRobot, workspace_map: ReachabilityMap, out: Path,
                 settings: Settings, progress: Progress, solution_figure: bool) -> Beside:
    """A lane of scenes run in a forked process with a controller of its own; its result: their report entries."""

    def work(p: Progress) -> dict:
        controller = HeadController(robot, workspace_map, method=settings.method, seed=settings.seed)
        return _run_lane(lane, controller, out, settings, p, solution_figure, None, figures_beside=False)

    return Beside(work, progress, parallel=True, suffix="", daemon=False, timeout_s=LANE_PROCESS_TIMEOUT_S)


def _run_lane(scenes: Sequence[Scene], controller: HeadController, out: Path, settings: Settings,
              progress: Progress, solution_figure: bool, start: BasePlacement | str | None, *,
              figures_beside: bool = True) -> dict:
    """The scenes one after the other with ``controller``, each planned while the previous one's last figures are
    drawn (``figures_beside``: in processes beside this lane, see :func:`~.planned_scene.start_scene`); their
    report entries by name."""
    entries = {}
    drawing: PendingScene | None = None  # the previous scene, its last figures drawn while this one is planned
    for scene in scenes:
        if start is not None:
            entries[scene.name] = run_loop_scene(scene, controller, out, settings, progress, start,
                                                 solution_figure=solution_figure)
            continue
        pending = start_scene(scene, controller, out, settings, progress, solution_figure=solution_figure,
                              beside=figures_beside)
        if drawing is not None:
            drawing.finish()
        entries[scene.name], drawing = pending.entry, pending
    if drawing is not None:
        drawing.finish()
    return entries


def _distinct_names(scenes: Sequence) -> tuple:
    """InputError unless the scenes' names name distinct files: each scene's outputs are NAME_trajectory.csv,
    NAME.gif, ... and its report entry is under its name, so two scenes of one name (or of names that differ only in
    case or Unicode normalisation: one file on macOS and Windows) would overwrite each other's."""
    seen: dict[str, str] = {}
    scenes = sequence(scenes, "scenes")
    for k, scene in enumerate(scenes):
        if not isinstance(scene, Scene):
            raise InputTypeError(f"scenes[{k}] must be a Scene, got {type(scene).__name__}")
        key = file_name_key(scene.name)
        if key in seen:
            same = "the same name" if seen[key] == scene.name else "names that differ only in case or normalisation"
            raise InputError(f"two scenes have {same} ({seen[key]!r} and {scene.name!r}): their output files "
                             "(NAME_trajectory.csv, NAME.gif, ...) would overwrite each other; rename one")
        seen[key] = scene.name
    if not seen:
        raise InputError("scenes is empty: give at least one scene")
    return scenes


def _map_label(m: Any) -> str:
    """Where the report says the head's map came from: its file, or this run."""
    return str(m.path) if getattr(m, "path", None) is not None else "computed in this run"
