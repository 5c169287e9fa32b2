"""The files the pipeline writes for a scene besides its trajectory: the ROS 2 bag and the joint trajectory for
controllers, the figures and the animation of the plan, its 3-D viewer's scene and page, the figures of its
dynamics (momenta, ZMP), and a closed loop's path and animation. Each returns the names of the files it wrote."""
from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

from ..viz import animation, body, save, viewer
from ..viz import dynamics_figures as dynamics
from ..viz import loop_figures as loop_plots
from ..viz.figure_style import literal
from . import report as rep
from . import ros_bag
from .progress import Progress

if TYPE_CHECKING:
    from ..closed_loop.loop import LoopRun
    from ..kinematics.reachability.reachability_map import ReachabilityMap
    from ..scenes.scene import Scene

__all__ = ["DYNAMICS_FIGURES", "write_ros_outputs", "write_loop_figures", "write_plan_outputs",
           "write_dynamics_figures"]

#: The figures of a scene's dynamics: the momenta (Figs. 18-19) and the ZMP (Fig. 20).
DYNAMICS_FIGURES = ("momenta", "zmp")


def write_ros_outputs(name: str, out: Path, progress: Progress, plan: Any, run: LoopRun | None = None) -> list[str]:
    """``NAME.mcap``, the ROS 2 bag of the plan (of the loop's whole run when ``run`` is given and simulated
    anything), and ``NAME_joint_trajectory.yaml``, the plan for controllers (:mod:`snakehead.app.ros_bag`); the
    names of those written (none without a plan or a run)."""
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


def write_loop_figures(scene: Scene, run: LoopRun, out: Path, s: dict, progress: Progress) -> list[str]:
    """The path from above and the animation of the whole sequence (``s``: :data:`~.settings.FAST` or
    :data:`~.settings.NORMAL`)."""
    name = scene.name
    with progress.stage(f"{name}: the path from above and the animation of the whole sequence"):
        files = [save(loop_plots.plot_ground_path(run), out / f"{name}_path.png").name]
        files.append(loop_plots.animate_loop(run, max_frames=s["max_frames"]).save(out / f"{name}_loop.gif").name)
    return files


def write_plan_outputs(scene: Scene, result: Any, out: Path, s: dict, progress: Progress, solution_figure: bool,
                  workspace_map: ReachabilityMap | None = None) -> list[str]:
    """What needs only the plan: the solution figure (plan), the snapshots, the GIF, the 3-D viewer's files."""
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


def write_dynamics_figures(scene: Scene, result: Any, sim_result: Any, out: Path, progress: Progress,
                      kinds: Sequence[str] = DYNAMICS_FIGURES) -> list[str]:
    """The momenta and the ZMP (``kinds`` of :data:`DYNAMICS_FIGURES`), planned and (with ``sim_result``)
    simulated."""
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
