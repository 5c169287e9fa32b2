"""One scene from the body lying straight, by the closed loop in MuJoCo (gaits, the curl into the bending state,
the head phases): :func:`run_loop_scene`, and its report entry (:func:`loop_entry`)."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Sequence

from .._errors import InputError
from ..closed_loop.loop import ClosedLoop
from ..sim import sensors
from . import report as rep
from .progress import Progress
from .scene_outputs import write_dynamics_figures, write_loop_figures, write_plan_outputs, write_ros_outputs
from .settings import FAST, NORMAL, PAPER_START, Settings

if TYPE_CHECKING:
    from ..closed_loop.loop import LoopRun
    from ..model.robot import BasePlacement
    from ..scenes.scene import Scene
    from ..solve.head_controller import HeadController

__all__ = ["run_loop_scene", "loop_entry", "LOOP_ASSUMPTION", "LOOP_ASSUMPTION_OUTSIDE_FIX"]


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
    """One scene from the body lying straight at ``start`` (a placement of its tail, or
    :data:`~.settings.PAPER_START`) by the closed loop (:class:`snakehead.closed_loop.loop.ClosedLoop`): gaits, the
    curl, the head phases, all in MuJoCo. Its report entry has what :func:`~.planned_scene.run_scene`'s has for the
    head phases, and ``phases``, ``sim.base_travel_m``, ``estimate``, ``start``, ``total_time_s``; the files add
    ``NAME_path.png`` (the path from above) and ``NAME_loop.gif`` (the whole sequence)."""
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
    files += write_ros_outputs(name, out, progress, run.plan, run)
    if settings.figures:
        if run.phases:  # a loop that failed before its first phase has no path to draw
            files += write_loop_figures(scene, run, out, s, progress)
        if run.plan is not None:
            files += write_plan_outputs(scene, run.plan, out, s, progress, solution_figure, controller.map)
            files += write_dynamics_figures(scene, run.plan, run.head, out, progress)  # both, here
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
    entry["notes"] = list(entry.get("notes") or []) + list(run.notes) + [_assumption(run)]
    entry["files"] = list(files)
    return rep.jsonable(entry)


def _assumption(run: LoopRun) -> str:
    """What the report says about how the loop closed: :data:`LOOP_ASSUMPTION` with the head camera's noise, or
    :data:`LOOP_ASSUMPTION_OUTSIDE_FIX` with the fix's."""
    if run.sensing == "onboard":
        camera = (f"{1000 * sensors.HEAD_POSITION_NOISE_M:g} mm and {sensors.HEAD_DIRECTION_NOISE_DEG:g} deg of noise "
                  f"per frame, {2 * sensors.HEAD_HALF_FOV_DEG:g} deg field of view, occluded by the obstacles")
        return LOOP_ASSUMPTION.format(camera=camera)
    noise = ("no fix" if run.fix is None else
             f"{1000 * run.fix.position_noise_m:g} mm and {run.fix.yaw_noise_deg:g} deg of noise")
    return LOOP_ASSUMPTION_OUTSIDE_FIX.format(noise=noise)
