"""A plan's motion as an animated GIF: the body's collision shapes moving through the scene.

:func:`animate` returns a :class:`BodyAnimation`; :func:`snakehead.viz.save` writes it (``NAME.gif``).

Why not ``matplotlib.animation.FuncAnimation``: saving one redraws the whole 3-D figure (axes, ticks, grid, walls)
twice per frame. Here the still part of the picture is drawn once and every frame draws only what moves -- the
body, the head tip's trace and the clock -- over a copy of it (blitting), followed by the still artists that a full
draw puts over the body (higher ``zorder``, e.g. the rim of a wall's hole), so that each frame is the picture a full
draw would make (``computed_zorder=False``: artists are drawn by zorder, then in the order they were added).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING, Any, Iterator, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.transforms import IdentityTransform
from PIL import Image

from .._errors import InputError
from .body import draw_body, draw_scenery
from .figure_geometry import Sphere, body_faces, plan_spheres, scene_bounds, view_angles, world_frames
from .figure_style import literal, new_figure, setup_axes3d, slope_text

if TYPE_CHECKING:
    from matplotlib.text import Text
    from mpl_toolkits.mplot3d.art3d import Line3D, Poly3DCollection

    from ..planning.plan_result import Plan


__all__ = ["BodyAnimation", "PALETTE_FRAMES", "gif_palette", "animate", "clock_time"]

@dataclass
class BodyAnimation:
    """Frames of a plan's motion drawn on one figure. ``figure``: the Matplotlib figure (showing the first frame
    once drawn); ``times`` (F,) s: the plan's time of each frame; ``fps``: frames per second of the GIF;
    ``frames`` (F, L, 4, 4): the world frames of the body's links at each frame (on a slope: the plan's ground-frame
    poses turned into the world); ``plan``: the plan drawn."""

    figure: Figure
    times: np.ndarray
    fps: float
    frames: np.ndarray = field(repr=False)
    plan: Plan = field(repr=False)
    _artists: tuple[Poly3DCollection, Line3D, Text] = field(repr=False)  # what moves: body, tip trace, clock time
    _speedup: float = 1.0

    def __len__(self) -> int:
        return len(self.times)

    def images(self) -> Iterator[Image.Image]:
        """Each frame as an RGBA :class:`PIL.Image.Image` (the figure's size at its dpi)."""
        fig, plan = self.figure, self.plan
        robot = plan.robot
        canvas = FigureCanvasAgg(fig)
        ax = fig.axes[0]
        body, trace, clock = self._artists
        tip = self.frames[:, robot.link_index(robot.parts.head_tip), :3, 3]
        # what a full draw puts after the body: the trace and any still artist of a higher zorder, in draw order
        added = [a for a in ax.get_children() if a in (*ax.collections, *ax.lines, *ax.patches, *ax.texts)]
        over = sorted([a for a in added if a is not body and (a is trace or a.get_zorder() > body.get_zorder())],
                      key=lambda a: a.get_zorder())  # stable: equal zorders keep the order they were added in
        moving = [body, *over, clock]
        for artist in moving:
            artist.set_animated(True)  # left out of the full draw: the background is everything else
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        width, height = canvas.get_width_height()
        for k in range(len(self)):
            canvas.restore_region(background)
            body.set_verts(body_faces(robot, self.frames[k])[0])
            body.do_3d_projection()
            trace.set_data_3d(tip[: k + 1, 0], tip[: k + 1, 1], tip[: k + 1, 2])
            clock.set_text(clock_time(self.times[k]))
            for artist in (body, *over):
                ax.draw_artist(artist)
            fig.draw_artist(clock)
            yield Image.frombuffer("RGBA", (width, height), bytes(canvas.buffer_rgba()), "raw", "RGBA", 0, 1)
        for artist in moving:
            artist.set_animated(False)

    def write_gif(self, file: IO[bytes]) -> None:
        """Write the frames as a looping GIF into an open binary file (:func:`snakehead.viz.save` names one), every
        frame in one palette (:func:`gif_palette`; each pixel its nearest colour, not dithered): faster than a
        palette per frame, a smaller file, and it keeps the light grey of the 3-D axes' panes."""
        frames = [im.convert("RGB") for im in self.images()]  # (opaque: the figure's background is)
        palette = gif_palette(frames)
        frames = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in frames]
        frames[0].save(file, format="GIF", save_all=True, append_images=frames[1:], duration=int(1000 / self.fps),
                       loop=0)


#: How many frames, evenly spread, :func:`gif_palette` chooses the GIF's colours from.
PALETTE_FRAMES = 10


def gif_palette(frames: Sequence[Image.Image]) -> Image.Image:
    """One 256-colour palette (a "P" image) for RGB ``frames`` of one size: median cut over PALETTE_FRAMES of them,
    evenly spread, side by side (the still background is in all, the body in its poses along the motion)."""
    picks = [frames[k] for k in np.unique(np.linspace(0, len(frames) - 1, PALETTE_FRAMES).round().astype(int))]
    width, height = picks[0].size
    strip = Image.new("RGB", (width, height * len(picks)))
    for k, im in enumerate(picks):
        strip.paste(im, (0, height * k))
    return strip.quantize(256, method=Image.Quantize.MEDIANCUT)


def animate(plan: Plan, *, spheres: Sequence[Sphere] | None = None, fps: float = 12.0, max_frames: int = 150,
            size: tuple[float, float] = (5.0, 4.0), dpi: int = 80) -> BodyAnimation:
    """The planned motion as an animation: at most ``max_frames`` frames evenly spaced in time, played at ``fps``
    frames/s (so faster than real time for long plans: the title shows the factor), ``size`` inches at ``dpi``.
    The head tip's path so far is traced. ``spheres``: as :func:`~snakehead.viz.body.plot_snapshots`. On a slope
    the motion is drawn in the world on the tilted ground, the slope's angle beside the speed."""
    fps = float(fps)
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be positive, got {fps!r}")
    if int(max_frames) != max_frames or max_frames < 2:
        raise InputError(f"max_frames must be an integer >= 2, got {max_frames!r}")
    robot = plan.robot
    spheres = plan_spheres(plan) if spheres is None else list(spheres)
    t = plan.t
    n = int(min(max_frames, len(t)))
    idx = np.unique(np.linspace(0, len(t) - 1, n).round().astype(int))
    ground = plan.base.ground
    frames = world_frames(ground, robot.frames_many(plan.q[idx], plan.base))
    tip = frames[:, robot.link_index(robot.parts.head_tip), :3, 3]
    speedup = (t[-1] - t[0]) / max(len(idx) / fps, 1e-9)
    fig = new_figure(figsize=size, dpi=dpi)
    ax = fig.add_subplot(1, 1, 1, projection="3d", computed_zorder=False)
    lo, hi = scene_bounds(plan, spheres)
    setup_axes3d(ax, lo, hi, *view_angles(plan), zoom=0.92, plane=ground)
    draw_scenery(ax, plan, spheres)
    body = draw_body(ax, robot, frames[0])
    (trace,) = ax.plot(tip[:1, 0], tip[:1, 1], tip[:1, 2], ":", color="k", lw=1.0)
    slope = f", {slope_text(ground)}" if slope_text(ground) else ""
    clock = _clock(fig, f"{literal(plan.name)}: t = ", t[idx], f" s  (x{speedup:.1f} speed{slope})")
    fig.subplots_adjust(left=0.0, right=0.96, bottom=0.02, top=0.98)
    return BodyAnimation(figure=fig, times=t[idx], fps=fps, frames=frames, plan=plan,
                         _artists=(body, trace, clock), _speedup=speedup)


def clock_time(t: float) -> str:
    """The clock's time as the animation writes it: s with one decimal."""
    return f"{t:.1f}"


def _clock(fig: Figure, before: str, times: np.ndarray, after: str) -> Text:
    """The clock at the top, centred: "NAME: t = 12.3 s  (x2.4 speed)". Only the time changes from frame to frame,
    so it is the only text drawn anew per frame (the returned artist, right-aligned in the room of the longest
    time); the words around it are still (drawn once, with the background). Text is most of a frame's drawing."""
    style: dict[str, Any] = dict(va="top", fontsize=9, transform=IdentityTransform())  # in pixels, once measured
    y = 0.98 * fig.bbox.height
    parts = [fig.text(0, y, before, ha="left", **style),
             fig.text(0, y, max((clock_time(v) for v in (times[0], times[-1])), key=len), ha="right", **style),
             fig.text(0, y, after, ha="left", **style)]
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    renderer = canvas.get_renderer()
    widths = [part.get_window_extent(renderer).width for part in parts]
    x = 0.5 * (fig.bbox.width - sum(widths))
    parts[0].set_x(x)
    parts[1].set_x(x + widths[0] + widths[1])
    parts[2].set_x(x + widths[0] + widths[1])
    parts[1].set_text(clock_time(times[0]))
    return parts[1]

