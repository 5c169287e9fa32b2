"""The pipeline behind ``snakehead demo`` and ``snakehead plan``, as a library function: for each scene,
plan -> simulate (MuJoCo) -> compare -> figures -> animation, then one report (``report.json``, ``summary.md``).

>>> from snakehead.app.pipeline import run_scenes
>>> from snakehead.scenes import paper_scene
>>> report = run_scenes([paper_scene("spheres")], "out")          # doctest: +SKIP
"""
from __future__ import annotations

import contextlib
import functools
import gc
import importlib.util
import os
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator, Sequence

from . import report as rep
from .._errors import Infeasible, InputError, InputTypeError, InternalError


if TYPE_CHECKING:
    from ..solve.head_controller import HeadController
    from ..kinematics.reachability.reachability_map import ReachabilityMap
    from ..model.robot import BasePlacement, SnakeRobot
    from ..planning.plan_result import PlanProgress
    from ..scenes.scene import Scene
    from ..closed_loop.loop import LoopRun

#: What ``fast`` changes: joints planned twice as fast with shorter segments (so half the 2 ms samples to check
#: and simulate), and animations with fewer frames.
FAST = {"max_frames": 30}
NORMAL = {"max_frames": 100}


class Progress:
    """Stage lines on stderr (``[  12.3 s] what ...`` / ``... done in 1.2 s``) and a record of the stage times."""

    def __init__(self, quiet: bool = False, stream: Any = None) -> None:
        self.t0 = time.perf_counter()
        self.quiet = quiet
        self.stream = stream
        self.stages: list[dict] = []

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def say(self, text: str) -> None:
        if not self.quiet:
            print(f"[{self.elapsed():7.1f} s] {text}", file=self.stream or sys.stderr, flush=True)

    @contextlib.contextmanager
    def stage(self, what: str) -> Iterator[None]:
        self.say(f"{what} ...")
        start = time.perf_counter()
        yield
        dt = time.perf_counter() - start
        self.stages.append({"stage": what, "seconds": dt})
        self.say(f"{what}: done in {dt:.1f} s")


def mujoco_available() -> bool:
    return importlib.util.find_spec("mujoco") is not None


@dataclass
class Settings:
    """How the pipeline runs. method/seed: the head IK's; fast: see FAST; simulate: run the MuJoCo check;
    figures: write figures, the animation and the 3-D viewer's page; parallel: draw what needs only the plan in a
    second process while MuJoCo simulates (Linux); relocation: let the plan move the base (by locomotion, first)
    when the targets need it; sensing: the closed loop's (:data:`snakehead.closed_loop.loop.SENSING`, with ``--start``)."""

    method: str = "rotated"
    seed: int | None = 1
    fast: bool = False
    simulate: bool = True
    figures: bool = True
    parallel: bool = True
    relocation: bool = True
    sensing: str = "onboard"

    def as_dict(self) -> dict:
        s = FAST if self.fast else NORMAL
        return {"method": self.method, "seed": self.seed, "fast": bool(self.fast), "animation_frames": s["max_frames"],
                "relocation": bool(self.relocation), "sensing": self.sensing,
                "simulation": bool(self.simulate and mujoco_available())}


def _relocation_dict(result: Any) -> dict | None:
    return None if result.relocation is None else result.relocation.as_dict()


def outcome_line(success: bool, failure: str | None, relocation: dict | None) -> str:
    """A scenario's outcome in a few words: success (saying so when the base had to move first) or the failure."""
    if not success:
        return f"NOT successful: {failure}"
    if relocation is None:
        return "success"
    return (f"success after relocating the base {relocation['distance_m']:.2f} m "
            f"({relocation['reason']}; --no-relocation forbids it)")


def plan_progress_line(record: PlanProgress) -> str:
    """One line for a ``plan(progress=...)`` record: "target 3/100 'name': solved in 0.21 s" (or why it was not
    solved), or the stage that begins."""
    if record.kind == "target":
        what = (f"solved in {record.seconds:.2f} s" if record.solved else
                f"NOT solved in {record.seconds:.2f} s: {record.message}")
        return f"target {record.index}/{record.count} {record.name!r}: {what}"
    return f"{record.message} ..."


def run_scene(scene: Scene, controller: HeadController, out: Path, settings: Settings, progress: Progress, *,
              solution_figure: bool = False) -> dict:
    """One scene through the pipeline; its report entry (``report.scenario_entry``) with the files written."""
    return start_scene(scene, controller, out, settings, progress, solution_figure=solution_figure).finish()


@dataclass
class PendingScene:
    """A scene whose last figures are still being drawn beside the caller (:func:`start_scene`): :meth:`finish`
    waits for them and returns the scene's report entry with every file written."""

    entry: dict
    files: list[str]
    drawing: list[_Beside]

    def finish(self) -> dict:
        for beside in self.drawing:
            self.files += beside.files()
        self.drawing = []
        self.entry["files"] = list(self.files)
        return self.entry


def start_scene(scene: Scene, controller: HeadController, out: Path, settings: Settings, progress: Progress, *,
                solution_figure: bool = False, beside: bool = True) -> PendingScene:
    """:func:`run_scene` up to its last figures (the momenta and the ZMP, drawn beside the caller once MuJoCo is
    done), so that the next scene is planned while they are drawn. ``beside``: the figures (and the ROS outputs)
    are made in processes beside this one when ``settings.parallel`` (False: here, in turn -- when every core
    already runs a lane of scenes, more processes would only share the cores and copy the memory they touch)."""
    from ..planning.planner import plan

    s = FAST if settings.fast else NORMAL
    robot = controller.robot
    name = scene.name
    label = scene.description or name
    with progress.stage(f"{name}: planning {label}"):
        result = plan(scene, controller=controller, allow_relocation=settings.relocation,
                      progress=lambda record: progress.say(f"{name}: {plan_progress_line(record)}"))
    progress.say(f"{name}: {outcome_line(result.success, result.failure, _relocation_dict(result))}, "
                 f"{result.duration_s:.1f} s of motion, {len(result.t)} samples; targets: "
                 + "; ".join(f"{tg.name} {1000 * tg.position_error_m:.3f} mm / {tg.direction_error_deg:.3f} deg"
                             for tg in result.targets))
    files = [rep.write_trajectory_csv(result, out / f"{name}_trajectory.csv", robot.joint_names).name]
    # what needs only the plan (its figures, the ROS outputs) is made while MuJoCo simulates (forked first: see
    # _Beside), off the scene's critical path (plan -> MuJoCo -> the figures of the dynamics)
    parallel = settings.parallel and beside
    plan_outputs = _Beside(lambda p: _ros_outputs(name, out, p, result)
                           + (_plan_outputs(scene, result, out, s, p, solution_figure, controller.map)
                              if settings.figures else []), progress, parallel=parallel)

    metrics, notes, sim_result = None, [], None
    if not settings.simulate:
        notes.append("dynamics check skipped (--no-sim)")
    elif not mujoco_available():
        notes.append("dynamics check skipped: MuJoCo is not installed (pip install snakehead[sim])")
        progress.say(f"{name}: MuJoCo is not installed; no dynamics check")
    else:
        from ..sim import simulate

        n_obstacles = len(result.obstacles)
        with progress.stage(f"{name}: MuJoCo simulation of {result.duration_s:.1f} s "
                            f"({n_obstacles} obstacle{'' if n_obstacles == 1 else 's'})"):
            try:
                checked = simulate(result)
            except RuntimeError as exc:
                notes.append(f"the simulation failed: {exc}")
                progress.say(f"{name}: the simulation failed: {exc}")
                checked = None
        if checked is not None:
            metrics, sim_result = checked.metrics, checked.result
            progress.say(f"{name}: simulated head error {1000 * metrics['position_error_m']:.2f} mm / "
                         f"{metrics['direction_error_deg']:.2f} deg; momentum errors "
                         f"{metrics['max_angular_momentum_error']:.4f} kg m^2/s, "
                         f"{metrics['max_linear_momentum_error']:.4f} kg m/s; ZMP inside: {metrics['zmp_inside']}")

    pending = [plan_outputs]
    if settings.figures:  # the two figures of the dynamics each in a process: they end the scene's work
        pending += [_Beside(functools.partial(_dynamics_figures, scene, result, sim_result, out, kinds=(kind,)),
                            progress, parallel=parallel) for kind in DYNAMICS_FIGURES]
    entry = rep.scenario_entry(result, metrics, extra={"files": files})
    entry["notes"] = list(entry["notes"]) + notes
    return PendingScene(entry, files, pending)


#: ``start`` of :func:`run_scenes` for the paper's "current state": lying straight where the curl into the bending
#: state alone brings the base to the scene's placement (Fig. 17a before 17b).
PAPER_START = "paper"

#: What every report of a closed loop says about how it closes (snakehead.closed_loop.loop, step 5), by its sensing.
LOOP_ASSUMPTION = ("closed loop on the robot's own sensors (snakehead.sim.sensors): gaits and curls are steered by dead "
                   "reckoning from 12-bit joint encoders, one MEMS IMU (gyro noise and bias random walk, "
                   "accelerometer noise; an attitude filter) and friction-balance contact odometry; a head camera "
                   "that sees a fiducial marker 0.15 m ahead of each target ({camera}) fixes the body's pose once "
                   "the head, on its way up, faces one, and the head's final approach is corrected on its "
                   "measurement of the last target; nothing outside the robot tells it where it is")
LOOP_ASSUMPTION_OUTSIDE_FIX = (
    "closed loop with an outside fix (sensing 'outside fix'): gaits and curls are steered by dead reckoning (perfect "
    "joint angles, one perfect IMU, friction-balance contact odometry); once the body rests in the bending state, an "
    "outside measurement of the pose of the neck's base frame (the paper's 'obtained in time'; here MuJoCo's, with "
    "{noise}) fixes the base's placement before the head phases are planned")


def run_loop_scene(scene: Scene, controller: HeadController, out: Path, settings: Settings, progress: Progress,
                   start: BasePlacement | str, *, solution_figure: bool = False) -> dict:
    """One scene from the body lying straight at ``start`` (a placement of its tail, or :data:`PAPER_START`) by the
    closed loop (:class:`snakehead.closed_loop.loop.ClosedLoop`): gaits, the curl, the head phases, all in MuJoCo. Its report
    entry has what :func:`run_scene`'s has for the head phases, and ``phases``, ``sim.base_travel_m``,
    ``estimate``, ``start``, ``total_time_s``; the files add ``NAME_path.png`` (the path from above) and
    ``NAME_loop.gif`` (the whole sequence)."""
    from ..closed_loop.loop import ClosedLoop

    s = FAST if settings.fast else NORMAL
    name = scene.name
    loop = ClosedLoop(scene, controller=controller, sensing=settings.sensing)
    if isinstance(start, str):
        if start != PAPER_START:
            raise InputError(f"start must be a BasePlacement or {PAPER_START!r}, got {start!r}")
        begin = loop.straight_start()
    else:
        begin = start
    with progress.stage(f"{name}: closed loop from lying straight, tail at ({begin.x:.3f}, {begin.y:.3f}) m, "
                        f"heading {begin.yaw:.3f} rad"):
        run = loop.run(begin, progress=lambda text: progress.say(f"{name}: {text}"))
    if run.metrics is not None:
        m = run.metrics
        final = ("" if "final_position_error_m" not in m else
                 f"; after the final approach {1000 * m['final_position_error_m']:.2f} mm / "
                 f"{m['final_direction_error_deg']:.2f} deg")
        progress.say(f"{name}: simulated head error {1000 * m['position_error_m']:.2f} mm / "
                     f"{m['direction_error_deg']:.2f} deg{final}; ZMP inside: {m['zmp_inside']}; the tail travelled "
                     f"{run.base_travel_m:.2f} m in {run.total_time_s:.1f} s")
    else:
        progress.say(f"{name}: the loop did not reach the head phases: {run.failure}")
    files: list[str] = []
    if run.plan is not None:
        files.append(rep.write_trajectory_csv(run.plan, out / f"{name}_trajectory.csv", controller.robot.joint_names)
                     .name)
    files += _ros_outputs(name, out, progress, run.plan, run)
    if settings.figures:
        if run.phases:  # a loop that failed before its first phase has no path to draw
            files += _loop_figures(scene, run, out, s, progress)
        if run.plan is not None:
            files += _plan_outputs(scene, run.plan, out, s, progress, solution_figure, controller.map)
            files += _dynamics_figures(scene, run.plan, run.head, out, progress)  # both, here
    return loop_entry(run, files)


def loop_entry(run: LoopRun, files: Sequence[str] = ()) -> dict:
    """The report entry of a closed loop (see :func:`run_loop_scene`)."""
    part = run.report()
    if run.plan is not None:
        entry = rep.scenario_entry(run.plan, run.metrics)
    else:  # the loop never got to plan the head phases
        entry = {"success": False, "failure": run.failure, "targets": [], "min_zmp_margin_m": None,
                 "min_ground_clearance_m": None, "planning_time_s": run.planning_time_s, "sim": None,
                 "duration_s": None, "samples": 0, "control_period_s": None,
                 "base": part["start"], "notes": []}
    entry["sim"] = {**(entry.get("sim") or {}), **part.pop("sim")}
    entry.update(part)
    entry["success"] = bool(entry["success"] and run.success)
    entry["failure"] = run.failure or entry.get("failure")
    if run.sensing == "onboard":
        from ..sim import sensors

        camera = (f"{1000 * sensors.HEAD_POSITION_NOISE_M:g} mm and {sensors.HEAD_DIRECTION_NOISE_DEG:g} deg of noise "
                  f"per frame, {2 * sensors.HEAD_HALF_FOV_DEG:g} deg field of view, occluded by the obstacles")
        assumption = LOOP_ASSUMPTION.format(camera=camera)
    else:
        noise = ("no fix" if run.fix is None else
                 f"{1000 * run.fix.position_noise_m:g} mm and {run.fix.yaw_noise_deg:g} deg of noise")
        assumption = LOOP_ASSUMPTION_OUTSIDE_FIX.format(noise=noise)
    entry["notes"] = list(entry.get("notes") or []) + list(run.notes) + [assumption]
    entry["files"] = list(files)
    return rep.jsonable(entry)


def _ros_outputs(name: str, out: Path, progress: Progress, plan: Any, run: LoopRun | None = None) -> list[str]:
    """``NAME.mcap``, the ROS 2 bag of the plan (of the loop's whole run when ``run`` is given and simulated
    anything), and ``NAME_joint_trajectory.yaml``, the plan for controllers (:mod:`snakehead.app.ros_bag`); the
    names of those written (none without a plan or a run)."""
    from . import ros_bag

    written: list[tuple[Path, float]] = []
    with progress.stage(f"{name}: ROS 2 bag and joint trajectory"):
        start = time.perf_counter()
        bag = out / f"{name}.mcap"
        if run is not None:
            if run.phases:  # a loop that failed before its first phase simulated nothing
                written.append((ros_bag.write_loop_bag(run, bag), time.perf_counter() - start))
        elif plan is not None:
            written.append((ros_bag.write_plan_bag(plan, bag), time.perf_counter() - start))
        if plan is not None:
            start = time.perf_counter()
            written.append((ros_bag.write_joint_trajectory(plan, out / f"{name}_joint_trajectory.yaml"),
                            time.perf_counter() - start))
    if written:
        progress.say(f"{name}: " + "; ".join(f"{p.name} {p.stat().st_size / 1e6:.1f} MB in {dt:.2f} s"
                                             for p, dt in written))
    return [p.name for p, _ in written]


def _loop_figures(scene: Scene, run: LoopRun, out: Path, s: dict, progress: Progress) -> list[str]:
    """The path from above and the animation of the whole sequence."""
    from ..viz import loop_figures as loop_plots
    from ..viz import save

    name = scene.name
    with progress.stage(f"{name}: the path from above and the animation of the whole sequence"):
        files = [save(loop_plots.plot_ground_path(run), out / f"{name}_path.png").name]
        files.append(loop_plots.animate_loop(run, max_frames=s["max_frames"]).save(out / f"{name}_loop.gif").name)
    return files


def _plan_outputs(scene: Scene, result: Any, out: Path, s: dict, progress: Progress, solution_figure: bool,
                  workspace_map: ReachabilityMap | None = None) -> list[str]:
    """What needs only the plan: the solution figure (plan), the snapshots, the GIF, the 3-D viewer's files."""
    from ..viz import animation, body, save, viewer
    from ..viz._common import literal

    robot = result.robot
    name = scene.name
    snap = rep.PAPER.get(name, {}).get("figures", (None, None, None))[0]
    label = literal(scene.description or name)  # shown as it is in the titles (a "$" is not math)
    files = []
    with progress.stage(f"{name}: figures"):
        # the figure draws the paper's segmented solve (Fig. 8); a target solved by another stage of the whole-body
        # solve (e.g. continued from the previous joints) has none to draw
        if solution_figure and result.targets and getattr(result.targets[0].solution, "desired_frame", None) is not None:
            files.append(save(body.plot_head_solution(robot, result.targets[0].solution),
                              out / f"{name}_solution.png").name)
        cols = 4 if len(result.targets) + 2 > 9 or len(body.plan_spheres(result)) else 3
        n_panels = 12 if cols == 4 else 9
        files.append(body.save_snapshots(result, out / f"{name}_snapshots.png", n_panels=n_panels, columns=cols,
                                         title=f"{label}{f' (cf. the paper Fig. {snap})' if snap else ''}: "
                                               "the body at its states (collision shapes; axes in m, equal scales)")
                     .name)
    with progress.stage(f"{name}: animation"):
        files.append(save(animation.animate(result, max_frames=s["max_frames"]), out / f"{name}.gif").name)
    with progress.stage(f"{name}: 3-D viewer page"):
        data = viewer.viewer_scene(result, workspace_map=workspace_map, title=scene.description or name)
        files.append(viewer.save_viewer_scene(data, out / f"{name}{viewer.SCENE_SUFFIX}").name)
        files.append(viewer.write_html(data, out / f"{name}.html").name)
    return files


#: The figures of a scene's dynamics: the momenta (Figs. 18-19) and the ZMP (Fig. 20).
DYNAMICS_FIGURES = ("momenta", "zmp")


def _dynamics_figures(scene: Scene, result: Any, sim_result: Any, out: Path, progress: Progress,
                      kinds: Sequence[str] = DYNAMICS_FIGURES) -> list[str]:
    """The momenta and the ZMP (``kinds`` of :data:`DYNAMICS_FIGURES`), planned and (with ``sim_result``)
    simulated."""
    from ..viz import dynamics_figures as dynamics, save
    from ..viz._common import literal

    name = scene.name
    _, mom, zmp = rep.PAPER.get(name, {}).get("figures", (None, None, None))
    label = literal(scene.description or name)  # shown as it is in the titles (a "$" is not math)
    simulated = " and simulated" if sim_result is not None else ""
    draw = {
        "momenta": lambda: dynamics.plot_momenta(result.t, result.stability.P, result.stability.L,
                                                 simulated=sim_result, figures=mom or (None, None),
                                                 title=f"{label}: momenta about the world origin, planned{simulated}"),
        "zmp": lambda: dynamics.plot_zmp(result.robot, result.t, result.q, base=result.base,
                                         stability=result.stability, simulated=sim_result, figure=zmp,
                                         title=f"{label}: zero-moment point"),
    }
    what = " and ".join({"momenta": "momenta", "zmp": "ZMP"}[kind] for kind in kinds)
    with progress.stage(f"{name}: {what} figure{'s' if len(kinds) > 1 else ''}"):
        return [save(draw[kind](), out / f"{name}_{kind}.png").name for kind in kinds]


#: s: the longest the forked figure process may take before it is taken for hung (the paper's scenes take ~10 s,
#: 1000 targets ~60 s on a loaded 2-core machine); the figures are then drawn in the main process.
FIGURE_PROCESS_TIMEOUT_S = 900.0
#: s: the same for a lane of scenes (:func:`run_scenes`), which plans and simulates them as well.
LANE_PROCESS_TIMEOUT_S = 4 * FIGURE_PROCESS_TIMEOUT_S
#: s a process beside this one has to stop after a Ctrl-C before it is killed.
STOP_GRACE_S = 5.0


class _Beside:
    """Runs ``work(progress)`` beside the caller: in a forked child process on Linux, so that it runs on the second
    core (the figures that need only the plan while MuJoCo simulates; a lane of scenes, :func:`run_scenes`); at once
    elsewhere, or with ``parallel=False``. :meth:`result` waits for its value (pickled back); the child's stage
    times join ``progress``, their names ending in ``suffix``. ``daemon=False`` lets the child fork children of its
    own (a lane draws its figures beside it)."""

    def __init__(self, work: Callable[[Progress], Any], progress: Progress, parallel: bool = True, *,
                 suffix: str = " [in a second process]", daemon: bool = True,
                 timeout_s: float | None = None) -> None:
        import multiprocessing

        self.progress = progress
        self.work = work
        self.suffix = suffix
        self.timeout_s = FIGURE_PROCESS_TIMEOUT_S if timeout_s is None else timeout_s  # read now: tests shorten it
        self.proc = None
        if not (parallel and sys.platform.startswith("linux")):
            self._value = work(progress)
            return
        ctx = multiprocessing.get_context("fork")  # the child inherits the plan: nothing to pickle
        self.recv, send = ctx.Pipe(duplex=False)
        self.proc = ctx.Process(target=_child, args=(work, progress, send), name="snakehead-beside", daemon=daemon)
        # Every object alive now is moved out of the collector's reach before the fork, so that the child's
        # collections neither walk nor write the parent's objects (their pages stay shared, not copied). (It once also
        # kept the child from destroying a TracIK, whose destructor joined threads a forked child does not have; the
        # core is fork-safe now: tests/test_trac_ik_fork.py.)
        gc.freeze()
        try:
            self.proc.start()
        finally:
            gc.unfreeze()
        send.close()

    def stop(self) -> None:
        """Stop the child if it still runs (the caller was interrupted or failed): a Ctrl-C to it first, so that it
        stops its own children as this process does, then a kill after STOP_GRACE_S."""
        if self.proc is None or not self.proc.is_alive():
            return
        if self.proc.pid is not None:  # (started: it has one)
            os.kill(self.proc.pid, signal.SIGINT)
        self.proc.join(STOP_GRACE_S)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()

    def files(self) -> list[str]:
        """:meth:`result` of work that returns the names of the files it wrote."""
        return list(self.result())

    def result(self) -> Any:
        if self.proc is None:
            return self._value
        try:
            answer: tuple[bool, Any, list[dict]] | None = (
                self.recv.recv() if self.recv.poll(self.timeout_s) else None)
        except EOFError:  # the forked child died (a fork of a process with threads can crash): run it here instead
            self.proc.join()
            self.progress.say(f"the process beside this one died (exit code {self.proc.exitcode}); doing its work "
                              "in this process instead")
            return self.work(self.progress)
        if answer is None:  # hung (a lock another thread held at the fork): stop it and run it here
            self.proc.kill()
            self.proc.join()
            self.progress.say(f"the process beside this one gave no answer in {self.timeout_s:g} s; doing its work "
                              "in this process instead")
            return self.work(self.progress)
        ok, value, stages = answer
        self.proc.join()
        self.progress.stages += [{**st, "stage": st["stage"] + self.suffix} for st in stages]
        if not ok:
            kind, message, error = value
            if isinstance(error, (Infeasible, InternalError, InputTypeError)):
                raise error  # snakehead's own fault, e.g. from planning in a lane: as this process would raise it
            if kind == "InputError":  # e.g. an output that could not be written: the same fault as in this process
                raise InputError(message)
            raise RuntimeError(f"the work beside this process failed: {message}")
        return value


def _child(work: Callable[[Progress], Any], progress: Progress, send: Any) -> None:
    import pickle
    import traceback

    progress.stages = []
    try:
        send.send((True, work(progress), progress.stages))
    except BaseException as exc:  # noqa: BLE001 -- reported to the parent, which raises
        kind = "InputError" if isinstance(exc, InputError) else type(exc).__name__
        text = str(exc) if kind == "InputError" else f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"
        try:  # the error itself when it pickles (snakehead's do): the parent raises what this process raised
            error: BaseException | None = pickle.loads(pickle.dumps(exc)) if isinstance(exc, Exception) else None
        except Exception:  # noqa: BLE001 -- any error of pickling: the text then
            error = None
        send.send((False, (kind, text, error), progress.stages))
    finally:
        send.close()


def run_scenes(scenes: Sequence, out: str | Path, *, controller: HeadController | None = None,
               robot: SnakeRobot | None = None, workspace_map: ReachabilityMap | None = None,
               settings: Settings | None = None, progress: Progress | None = None, command: str = "plan",
               notes: Sequence[str] = (), solution_figure: bool = False, on_controller: Callable | None = None,
               start: BasePlacement | str | None = None) -> dict:
    """Every scene through :func:`run_scene` with one controller; writes ``report.json`` and ``summary.md`` into
    ``out`` and returns the report. ``controller`` defaults to one for ``robot`` (default: the first scene's robot
    file, else the default robot) with ``workspace_map`` (default: the robot's, cached or computed). ``start``: run
    every scene from the body lying there instead (:func:`run_loop_scene`: a placement of the tail, or
    :data:`PAPER_START`).

    With ``settings.parallel`` (Linux, more than one core and one scene, no ``controller``, ``on_controller`` or
    ``start`` given) the scenes run in lanes, one a core (:func:`scene_lanes`): the first in this process, the
    others each in a forked process with a controller of its own, made alike (the same map, method and seed: the
    same plans as one controller planning every scene in turn)."""
    from ..solve.head_controller import HeadController
    from ..model.robot import SnakeRobot

    scenes = _distinct_names(scenes)
    settings = settings or Settings()
    progress = progress or Progress()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lanes = [list(scenes)]
    beside: list[_Beside] = []
    # (from the first lane's fork on: a Ctrl-C while this process still makes its controller stops them too)
    try:
        if controller is None:
            if robot is None:
                first = scenes[0].robot_file
                robot = SnakeRobot.from_file(first) if first is not None else SnakeRobot.default()
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
    entries = {scene.name: entries[scene.name] for scene in scenes}
    robot = controller.robot
    report = {"command": command, "scenarios": entries,
              "settings": {**settings.as_dict(), "map": _map_label(controller.map)},
              "robot": {"source": robot.source or "URDF", "joints": robot.n_joints,
                        "parts": {"base": robot.parts.base.stop - robot.parts.base.start,
                                  "neck": robot.parts.neck.stop - robot.parts.neck.start,
                                  "head": robot.parts.head.stop - robot.parts.head.start},
                        "dexterous_threshold": controller.dexterous_threshold},
              "run_time_s": progress.elapsed(), "stages": progress.stages, "notes": list(notes),
              "paper": rep.PAPER, **rep.environment()}
    rep.write_json(report, out / "report.json")
    rep.write_summary(report, out / "summary.md")
    return report


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
    from ..kinematics import reachability as workspace

    if workspace_map is not None:
        return workspace_map
    if robot.map_path is None:
        progress.say("this robot has no map: computing one (cached for the next run)")
    workspace_map = workspace.map_for(robot, progress=not progress.quiet)
    if workspace_map.path is not None:
        progress.say(f"the head's map: {workspace_map.path}")
    return workspace_map


def _preload_figures(progress: Progress) -> None:
    """Import what the figures draw with (matplotlib, its 3-D axes, the viewer's page) once, before the lanes and
    their figure processes are forked: each would import it again (~0.4 s apiece)."""
    with progress.stage("the figures' libraries (matplotlib)"):
        from matplotlib.backends import backend_agg  # noqa: F401
        from mpl_toolkits.mplot3d import Axes3D  # noqa: F401

        from ..viz import animation, body, dynamics_figures, viewer  # noqa: F401


def _lane_beside(lane: list[Scene], robot: SnakeRobot, workspace_map: ReachabilityMap, out: Path,
                 settings: Settings, progress: Progress, solution_figure: bool) -> _Beside:
    """A lane of scenes run in a forked process with a controller of its own; its result: their report entries."""

    def work(p: Progress) -> dict:
        from ..solve.head_controller import HeadController

        controller = HeadController(robot, workspace_map, method=settings.method, seed=settings.seed)
        return _run_lane(lane, controller, out, settings, p, solution_figure, None, figures_beside=False)

    return _Beside(work, progress, parallel=True, suffix="", daemon=False, timeout_s=LANE_PROCESS_TIMEOUT_S)


def _run_lane(scenes: Sequence[Scene], controller: HeadController, out: Path, settings: Settings,
              progress: Progress, solution_figure: bool, start: BasePlacement | str | None, *,
              figures_beside: bool = True) -> dict:
    """The scenes one after the other with ``controller``, each planned while the previous one's last figures are
    drawn (``figures_beside``: in processes beside this lane, see :func:`start_scene`); their report entries by
    name."""
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
    from .._errors import InputError, InputTypeError
    from .._validate import file_name_key, sequence
    from ..scenes.scene import Scene

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
    return str(m.path) if getattr(m, "path", None) is not None else "computed in this run"
