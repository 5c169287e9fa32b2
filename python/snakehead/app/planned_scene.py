"""One scene through the pipeline from the bending state: plan, the dynamics check in MuJoCo, and the outputs --
what needs only the plan drawn beside the simulation, the figures of the dynamics after it (:func:`start_scene`,
:func:`run_scene`)."""
from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..planning.planner import plan
from ..sim import simulate
from . import report as rep
from .beside import Beside
from .progress import Progress, outcome_line, plan_progress_line
from .scene_outputs import DYNAMICS_FIGURES, write_dynamics_figures, write_plan_outputs, write_ros_outputs
from .settings import FAST, NORMAL, Settings, mujoco_available

if TYPE_CHECKING:
    from ..scenes.scene import Scene
    from ..solve.head_controller import HeadController

__all__ = ["run_scene", "start_scene", "PendingScene"]


def _relocation_dict(result: Any) -> dict | None:
    """A plan's relocation of the base as its report has it; None when the base stayed."""
    return None if result.relocation is None else result.relocation.as_dict()


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
    drawing: list[Beside]

    def finish(self) -> dict:
        """Wait for the figures still being drawn; the scene's report entry with every file written."""
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
    # Beside), off the scene's critical path (plan -> MuJoCo -> the figures of the dynamics)
    parallel = settings.parallel and beside
    plan_outputs = Beside(lambda p: write_ros_outputs(name, out, p, result)
                          + (write_plan_outputs(scene, result, out, s, p, solution_figure, controller.map)
                             if settings.figures else []), progress, parallel=parallel)

    metrics, sim_result, notes = _check_in_mujoco(name, result, settings, progress)
    pending = [plan_outputs]
    if settings.figures:  # the two figures of the dynamics each in a process: they end the scene's work
        pending += [Beside(functools.partial(write_dynamics_figures, scene, result, sim_result, out, kinds=(kind,)),
                           progress, parallel=parallel) for kind in DYNAMICS_FIGURES]
    entry = rep.scenario_entry(result, metrics, extra={"files": files})
    entry["notes"] = list(entry["notes"]) + notes
    return PendingScene(entry, files, pending)


def _check_in_mujoco(name: str, result: Any, settings: Settings, progress: Progress) -> tuple[Any, Any, list[str]]:
    """The plan ``result`` simulated in MuJoCo (unless ``settings`` say not, or MuJoCo is not installed): its
    metrics and simulated result (None, None without a simulation), and the notes the report gets about it."""
    notes: list[str] = []
    if not settings.simulate:
        notes.append("dynamics check skipped (--no-sim)")
        return None, None, notes
    if not mujoco_available():
        notes.append("dynamics check skipped: MuJoCo is not installed (pip install snakehead[sim])")
        progress.say(f"{name}: MuJoCo is not installed; no dynamics check")
        return None, None, notes
    n_obstacles = len(result.obstacles)
    with progress.stage(f"{name}: MuJoCo simulation of {result.duration_s:.1f} s "
                        f"({n_obstacles} obstacle{'' if n_obstacles == 1 else 's'})"):
        try:
            checked = simulate(result)
        except RuntimeError as exc:
            notes.append(f"the simulation failed: {exc}")
            progress.say(f"{name}: the simulation failed: {exc}")
            return None, None, notes
    metrics = checked.metrics
    progress.say(f"{name}: simulated head error {1000 * metrics['position_error_m']:.2f} mm / "
                 f"{metrics['direction_error_deg']:.2f} deg; momentum errors "
                 f"{metrics['max_angular_momentum_error']:.4f} kg m^2/s, "
                 f"{metrics['max_linear_momentum_error']:.4f} kg m/s; ZMP inside: {metrics['zmp_inside']}")
    return metrics, checked.result, notes
