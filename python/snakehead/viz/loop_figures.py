"""Figures of a closed loop (:class:`snakehead.closed_loop.loop.LoopRun`): the body's path over the ground with its phases,
seen from above, and the animation of the whole sequence (gaits, curl, lift, moves).

Like every figure of :mod:`snakehead.viz`, each function returns a :class:`matplotlib.figure.Figure` made outside
pyplot (no backend chosen, nothing to close); :func:`animate_loop` returns a :class:`LoopAnimation`, whose
:meth:`~LoopAnimation.save` writes a GIF.

>>> from snakehead.viz.loop_figures import plot_ground_path, animate_loop
>>> plot_ground_path(run).savefig("path.png")                    # doctest: +SKIP
>>> animate_loop(run).save("loop.gif")                           # doctest: +SKIP
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Iterator

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from PIL import Image

from .._errors import InputError, InputTypeError
from .._files import atomic_open
from ..closed_loop.loop import LoopRun
from ..locomotion.ground_path import footprints
from .figure_geometry import body_drawing, body_faces, part_colors, shape_footprints
from .figure_style import BASE_COLOR, HEAD_COLOR, NECK_COLOR, literal

if TYPE_CHECKING:
    from ..model.robot import SnakeRobot

__all__ = ["KIND_COLORS", "PART_COLORS", "TARGET_COLOR", "OBSTACLE_COLOR", "ROUTE_COLOR", "plot_ground_path",
           "LoopAnimation", "animate_loop"]

#: Colours of the phases by kind, and of the body's parts (as the other figures draw them).
KIND_COLORS = {"gait": "#2e7d32", "curl": "#8e24aa", "lift": "#ef6c00", "move": "#1565c0", "hold": "#6d4c41",
               "servo": "#00838f"}
PART_COLORS = (BASE_COLOR, NECK_COLOR, HEAD_COLOR)
TARGET_COLOR = "#c0392b"
OBSTACLE_COLOR = "#9e9e9e"
ROUTE_COLOR = "#455a64"


def _obstacle_outlines(run: LoopRun) -> list[np.ndarray]:
    """The ground-level outlines of the scene's obstacles (walls, boxes) seen from above."""
    return footprints(run.scene.obstacles)

def _part_colors(robot: SnakeRobot, per_polygon: bool = False) -> list[str]:
    """A colour per collision shape (of ``robot.geometry``), or per polygon of
    :func:`~.figure_geometry.body_faces`: the colour of its link's part (:data:`PART_COLORS`)."""
    colors = part_colors(robot)
    d = body_drawing(robot)
    frame = d.shape_frames[d.polygon_shape] if per_polygon else d.shape_frames
    return [colors[i] for i in frame]


def _frames(robot: SnakeRobot, root: np.ndarray, q: np.ndarray) -> np.ndarray:
    """World frames (T, L, 4, 4) from root poses (T, 4, 4) and joints (T, n)."""
    return root[:, None] @ robot.body.fk_all_many(q)


def _footprint(robot: SnakeRobot, frames: np.ndarray) -> list[np.ndarray]:
    """The collision shapes' outlines seen from above: one (k, 2) polygon per shape."""
    return shape_footprints(robot, frames)


def _check(run: Any) -> None:
    """InputTypeError unless ``run`` is a LoopRun, InputError unless it ran a phase."""
    if not isinstance(run, LoopRun):
        raise InputTypeError(f"run must be a snakehead.closed_loop.loop.LoopRun (ClosedLoop.run), got {type(run).__name__}")
    if not run.phases:
        raise InputError("the loop ran no phase: nothing to draw")


def plot_ground_path(run: LoopRun, *, size: tuple[float, float] = (6.5, 6.0), title: str | None = None) -> Figure:
    """The top view: the tail's path over the ground (MuJoCo's) coloured by the kind of phase, and where the loop
    believed it was (dead reckoning, dashed; a fix is a jump of it); the body's footprint at the start, after every
    ground phase and at the end; the targets (crosses, their height written beside them). Phases are numbered
    along the path and listed in the legend with their times. Axes in m, equal scales. Names (the scene's, the
    targets', the phases') are shown as they are (``literal``); ``title`` replaces the
    title as given (matplotlib's mathtext applies to it)."""
    _check(run)
    robot = run.robot
    fig = Figure(figsize=size)
    ax = fig.add_subplot(1, 1, 1)
    ax.set_aspect("equal")
    colors = _part_colors(robot)
    t_all, roots, qs = run.timeline()

    def body(root: np.ndarray, q: np.ndarray, alpha: float, zorder: int = 2) -> None:
        fp = _footprint(robot, _frames(robot, root[None], q[None])[0])
        ax.add_collection(PolyCollection(list(fp), facecolors=colors, edgecolors="k", linewidths=0.3, alpha=alpha,
                                         zorder=zorder))

    legend: list[Any] = []
    walls = _obstacle_outlines(run)
    if walls:
        ax.add_collection(PolyCollection(walls, facecolors=OBSTACLE_COLOR, edgecolors="k", linewidths=0.4, alpha=0.7,
                                         zorder=1))
        legend.append(Patch(facecolor=OBSTACLE_COLOR, edgecolor="k", alpha=0.7, label="obstacles (on the ground)"))
    for route in run.routes:  # the body's middle, planned around the obstacles
        ax.plot(route[:, 0], route[:, 1], ":o", color=ROUTE_COLOR, lw=1.0, ms=3, zorder=2)
    if run.routes:
        legend.append(Line2D([], [], color=ROUTE_COLOR, ls=":", marker="o", ms=3, label="planned route (body's middle)"))
    if len(t_all):
        body(roots[0], qs[0], 0.35)
        ax.annotate("start", (roots[0, 0, 3], roots[0, 1, 3]), fontsize=7, xytext=(4, -10), textcoords="offset points")
    for k, ph in enumerate(run.phases, start=1):
        inside = (t_all >= ph.t0_s - 1e-9) & (t_all <= ph.t1_s + 1e-9)
        c = KIND_COLORS[ph.kind]
        if inside.any():
            xy = roots[inside, :2, 3]
            ax.plot(xy[:, 0], xy[:, 1], "-", color=c, lw=1.6, zorder=3)
            ax.annotate(str(k), (xy[-1, 0], xy[-1, 1]), fontsize=7, color=c, xytext=(3, 3), textcoords="offset points", zorder=5)
        if ph.run is not None:
            est = ph.run.root_estimate[:, :2, 3]
            ax.plot(est[:, 0], est[:, 1], "--", color=c, lw=0.9, alpha=0.8, zorder=3)
            body(ph.run.root_truth[-1], ph.run.q[-1], 0.15, zorder=1)
        legend.append(Line2D([], [], color=c, lw=1.6, label=f"{k} {literal(ph.name)} ({ph.t0_s:.1f}-{ph.t1_s:.1f} s)"))
    if len(t_all):
        body(roots[-1], qs[-1], 0.9, zorder=4)
    for f in run.fixes:  # where a fix (outside, or the head camera's) reset the estimate
        k = int(np.argmin(np.abs(t_all - f["t_s"])))
        ax.plot(*roots[k, :2, 3], "*", color="k", ms=9, zorder=6)
    for tg in run.scene.targets:
        ax.plot(tg.position[0], tg.position[1], "x", color=TARGET_COLOR, ms=8, mew=2, zorder=6)
        ax.annotate(f"{literal(tg.name)} (z {tg.position[2]:.2f} m)", (tg.position[0], tg.position[1]), fontsize=7,
                    color=TARGET_COLOR, xytext=(5, 5), textcoords="offset points", zorder=6)
    legend += [Line2D([], [], color="k", ls="--", lw=0.9, label="estimated (dead reckoning)"),
               Line2D([], [], color="k", marker="*", ls="", label="fix" if run.sensing == "onboard" else "outside fix"),
               Line2D([], [], color=TARGET_COLOR, marker="x", ls="", label="targets")]
    ax.autoscale_view()
    ax.margins(0.08)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    head = run.metrics
    err = (f"; head {1000 * head['position_error_m']:.2f} mm / {head['direction_error_deg']:.2f} deg off"
           if head else f"; {literal(run.failure)}" if run.failure else "")
    ax.set_title(title or f"{literal(run.scene.name)}: the tail's path from above, {run.base_travel_m:.2f} m in "
                          f"{run.total_time_s:.0f} s{err}", fontsize=9)
    ax.legend(handles=legend, fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    return fig


@dataclass
class LoopAnimation:
    """The whole sequence of a loop drawn frame by frame: ``figure``, ``times`` (F,) s of the simulation's clock,
    ``fps`` of the GIF. :meth:`save` writes the GIF."""

    figure: Figure
    times: np.ndarray
    fps: float
    _frames: np.ndarray = field(repr=False)
    _labels: list = field(repr=False)
    _artists: tuple = field(repr=False)
    _robot: SnakeRobot = field(repr=False)

    def __len__(self) -> int:
        return len(self.times)

    def images(self) -> Iterator[Image.Image]:
        """Each frame as an RGB :class:`PIL.Image.Image`."""
        canvas = FigureCanvasAgg(self.figure)
        body, clock = self._artists
        for k in range(len(self)):
            body.set_verts(body_faces(self._robot, self._frames[k])[0])
            clock.set_text(self._labels[k])
            canvas.draw()
            w, h = canvas.get_width_height()
            yield Image.frombuffer("RGBA", (w, h), bytes(canvas.buffer_rgba()), "raw", "RGBA", 0, 1).convert("RGB")

    def write_gif(self, file: IO[bytes]) -> None:
        """Write the frames as a looping GIF into an open binary file."""
        frames = list(self.images())
        frames[0].save(file, format="GIF", save_all=True, append_images=frames[1:], duration=int(1000 / self.fps),
                       loop=0)

    def save(self, path: str | os.PathLike) -> Path:
        """Write the GIF to ``path`` (whole or not at all); returns the path."""
        path = Path(path)
        if path.suffix.lower() != ".gif":
            raise InputError(f"an animation is written as .gif, got {path.name!r}")
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_open(path, "wb") as f:
            self.write_gif(f)
        return path


def animate_loop(run: LoopRun, *, max_frames: int = 100, fps: float = 10.0, size: tuple[float, float] = (6.0, 4.5),
                 dpi: int = 80) -> LoopAnimation:
    """The whole sequence as MuJoCo ran it, in 3-D: at most ``max_frames`` frames evenly spaced in time (so faster
    than real time: the title gives the factor), the tail's path on the ground, the targets, the phase and the
    clock in the title."""
    _check(run)
    fps = float(fps)
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be positive, got {fps!r}")
    if isinstance(max_frames, bool) or int(max_frames) != max_frames or max_frames < 2:
        raise InputError(f"max_frames must be an integer >= 2, got {max_frames!r}")
    robot = run.robot
    t, roots, qs = run.timeline()
    idx = np.unique(np.linspace(0, len(t) - 1, int(min(max_frames, len(t)))).round().astype(int))
    frames = _frames(robot, roots[idx], qs[idx])
    speedup = (t[-1] - t[0]) / max(len(idx) / fps, 1e-9)
    labels = []
    for k in idx:
        ph = next((p for p in run.phases if p.t0_s - 1e-9 <= t[k] <= p.t1_s + 1e-9), run.phases[-1])
        labels.append(f"{literal(run.scene.name)}: t = {t[k]:5.1f} s, {ph.kind}: {literal(ph.name)}  "
                      f"(x{speedup:.0f} speed)")
    # the scene's extent: every body position and the targets, the ground up to the highest point
    pts = robot.lowest_points(frames)[0].reshape(-1, 3)
    pts = np.vstack([pts, frames[:, :, :3, 3].reshape(-1, 3)])
    pts = np.vstack([pts] + [tg.position[None] for tg in run.scene.targets])
    lo, hi = pts.min(axis=0) - 0.05, pts.max(axis=0) + 0.05
    lo[2] = 0.0
    hi[2] = max(hi[2], 0.1)
    fig = Figure(figsize=size, dpi=dpi)
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo))
    ax.view_init(elev=35, azim=-60)
    ax.tick_params(labelsize=6, pad=-2)
    ax.set_xlabel("x (m)", fontsize=7, labelpad=-4)
    ax.set_ylabel("y (m)", fontsize=7, labelpad=-4)
    ax.set_zlabel("z (m)", fontsize=7, labelpad=-4)
    path = roots[:, :3, 3]
    ax.plot(path[:, 0], path[:, 1], np.zeros(len(path)), ":", color="k", lw=0.8)
    for tg in run.scene.targets:
        ax.scatter(*tg.position, color=TARGET_COLOR, s=12, depthshade=False)
    body = Poly3DCollection(body_faces(robot, frames[0])[0], facecolors=_part_colors(robot, per_polygon=True), edgecolors="k",
                            linewidths=0.2, alpha=0.95)
    ax.add_collection3d(body, autolim=False)  # the limits are set above
    clock = fig.text(0.5, 0.97, labels[0], ha="center", va="top", fontsize=7)
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.95)
    return LoopAnimation(figure=fig, times=t[idx], fps=fps, _frames=frames, _labels=labels, _artists=(body, clock),
                         _robot=robot)
