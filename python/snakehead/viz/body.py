"""Figures of the body in 3-D: its collision shapes coloured by part, with the scene's targets and obstacles.

* :func:`plot_snapshots` -- Figs. 17 and 22: the whole body at a plan's key states, one panel per state
  (:func:`save_snapshots` writes the same picture faster).
* :func:`plot_head_solution` -- one :class:`~snakehead.solve.HeadController` solution: the robot at it and the
  neck geometry of Fig. 8.
* :func:`plot_interpolation_comparison` -- Fig. 11 against Fig. 13: a joint-space interpolation that drives the
  head into the ground beside the Cartesian interpolation of Eqs. 41-44 that does not.
* :func:`draw_body` and :func:`draw_scenery`: the body and the scenery on 3-D axes (the animation's too).

The geometry they draw (faces, footprints, obstacles, spheres, bounds) is in :mod:`.figure_geometry`, re-exported
here. Every function returns a :class:`matplotlib.figure.Figure`; write it with :func:`snakehead.viz.save`.
Positions in m, times in s, drawn in the world frame (z up). A plan on a slope holds its body, targets and obstacles
in its ground frame (``plan.base.ground``): they are drawn turned into the world, on the tilted ground, and the
slope's angle is in the legend (the animation's: its title line).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from .._errors import InputError
from .._files import atomic_open
from ..collision import body_collisions as coll
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..model.robot import BasePlacement, SnakeRobot
from ..trajectory.cartesian import cartesian_interpolation
from .figure_files import DEFAULT_DPI, crop_and_write_png, ink_mask, save
from .figure_geometry import (
    FIGURE_SEGMENTS,
    BodyDrawing,
    Sphere,
    body_drawing,
    body_faces,
    body_points,
    box_faces,
    convex_facets,
    hole_rim,
    mesh_obstacle_faces,
    part_colors,
    plan_spheres,
    scene_bounds,
    shape_footprints,
    terrain_mesh,
    view_angles,
    wall_faces,
    world_frames,
)
from .figure_style import (
    BASE_COLOR,
    GROUND_COLOR,
    HEAD_COLOR,
    NECK_COLOR,
    OBSTACLE_COLOR,
    SPHERE_COLOR,
    WALL_COLOR,
    literal,
    new_figure,
    setup_axes3d,
    slope_text,
)

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from ..planning.plan_result import Plan
    from ..solve.head_controller import HeadSolution

__all__ = [
    "SNAPSHOT_SIDE_IN", "draw_scenery", "draw_body", "snapshot_states", "plot_snapshots", "save_snapshots",
    "plot_head_solution", "plot_interpolation_comparison",
    # re-exported: the geometry (figure_geometry) and the colours (figure_style) the figures draw with
    "FIGURE_SEGMENTS", "BodyDrawing", "Sphere", "body_drawing", "body_faces", "body_points", "box_faces",
    "convex_facets", "hole_rim", "mesh_obstacle_faces", "part_colors", "plan_spheres", "scene_bounds",
    "shape_footprints", "view_angles", "wall_faces", "BASE_COLOR", "NECK_COLOR", "HEAD_COLOR", "OBSTACLE_COLOR",
]

#: in: blank figure on either side of the snapshots' panels, for the tick labels that reach beyond them.
SNAPSHOT_SIDE_IN = 0.5
#: Colours of the two interpolations of Figs. 11 and 13.
_JOINT_SPACE = "#c0392b"
_CARTESIAN = "#1f77b4"


def _sphere_mesh(centre: np.ndarray, diameter: float, n: int = 14) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A sphere as ``plot_surface`` takes it: the grids X, Y, Z (n // 2 + 1, n) m."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2 + 1))
    r = diameter / 2
    return (centre[0] + r * np.cos(u) * np.sin(v), centre[1] + r * np.sin(u) * np.sin(v), centre[2] + r * np.cos(v))


def _in_world(plan: Plan) -> tuple[Callable[[Any], Any], Callable[[Any], Any]]:
    """Functions that turn points and directions (..., 3) of the plan's ground frame into the world (on flat ground:
    the arrays as they are)."""
    ground = plan.base.ground
    if ground.is_world:
        return (lambda p: p), (lambda d: d)
    return ground.to_world, ground.direction_to_world


def draw_scenery(ax: Axes3D, plan: Plan, spheres: Sequence[Sphere], *, arrows: bool = True) -> None:
    """The spheres, the plan's obstacles (boxes; walls with the hole's rim), its scene's terrain (a heightfield, a
    mesh, a staircase; over the axes' limits, set first) and, with ``arrows``, each target as an arrow along its
    direction ending at the target; in the world (``spheres`` in the plan's ground frame, as its targets)."""
    point, direction = _in_world(plan)
    for centre, diameter in spheres:
        ax.plot_surface(*_sphere_mesh(point(np.asarray(centre, float)), diameter), color=SPHERE_COLOR, alpha=0.55,
                        linewidth=0)
    for ob in plan.obstacles:
        if isinstance(ob, WallWithHole):
            ax.add_collection3d(Poly3DCollection(point(wall_faces(ob)), facecolor=WALL_COLOR, edgecolor="none",
                                                 alpha=0.35))
            rim = point(hole_rim(ob))
            ax.plot(rim[:, 0], rim[:, 1], rim[:, 2], "-", color="k", lw=1.0)
        elif isinstance(ob, (BoxObstacle, MeshObstacle)):
            faces = box_faces(ob) if isinstance(ob, BoxObstacle) else mesh_obstacle_faces(ob)
            ax.add_collection3d(Poly3DCollection([point(f) for f in faces], facecolor=OBSTACLE_COLOR, edgecolor="k",
                                                 linewidths=0.3, alpha=0.45), autolim=False)  # no autoscale
    _draw_terrain(ax, getattr(getattr(plan, "scene", None), "terrain", None))
    if arrows and len(plan.targets):  # one collection of arrows: one per target made the figure grow per target
        d = 0.08 * direction(np.array([tg.direction for tg in plan.targets], float))
        p = point(np.array([tg.position for tg in plan.targets], float)) - d  # each arrow ends at its target
        ax.quiver(p[:, 0], p[:, 1], p[:, 2], d[:, 0], d[:, 1], d[:, 2], color="k", lw=1.0, arrow_length_ratio=0.3)


#: Heights per side of the grid a scene's terrain is drawn on in a figure (over the axes' x and y).
FIGURE_TERRAIN_SIDE = 41


def _draw_terrain(ax: Axes3D, terrain: Any) -> None:
    """A scene's terrain (a heightfield, a mesh, a staircase: what :func:`.figure_geometry.terrain_mesh` draws; not
    flat ground or a plane) over the axes' x and y: its heights (``terrain.height``) on a grid of
    :data:`FIGURE_TERRAIN_SIDE` per side, a quad per cell whose corners all have a surface within the z limits (3-D
    axes do not clip what reaches beyond them)."""
    if not len(terrain_mesh(terrain, 2)[1]):
        return
    (x0, x1), (y0, y1), (z0, z1) = ax.get_xlim(), ax.get_ylim(), ax.get_zlim()
    X, Y = np.meshgrid(np.linspace(x0, x1, FIGURE_TERRAIN_SIDE), np.linspace(y0, y1, FIGURE_TERRAIN_SIDE),
                       indexing="ij")
    Z = terrain.height(np.stack([X, Y], axis=-1))
    P = np.stack([X, Y, Z], axis=-1)
    quads = np.stack([P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]], axis=2).reshape(-1, 4, 3)
    keep = np.all(np.isfinite(quads[..., 2]) & (quads[..., 2] >= z0) & (quads[..., 2] <= z1), axis=1)
    if keep.any():
        ax.add_collection3d(Poly3DCollection(quads[keep], facecolor=GROUND_COLOR, edgecolor="none", alpha=0.3),
                            autolim=False)


def draw_body(ax: Axes3D, robot: SnakeRobot, frames: np.ndarray, alpha: float = 0.95) -> Poly3DCollection:
    """The collision shapes at ``frames`` (L, 4, 4) as one collection of polygons (returned, so that it can be
    moved: ``set_verts(body_faces(robot, frames)[0])``)."""
    faces, colors = body_faces(robot, frames)
    shapes = Poly3DCollection(faces, facecolors=colors, edgecolors="k", linewidths=0.15, alpha=alpha)
    ax.add_collection3d(shapes, autolim=False)  # polygons of several sizes (NaN-padded): the caller sets the limits
    return shapes


def _part_legend(fig: Figure, plan: Plan, spheres: Sequence[Sphere]) -> None:
    """The legend under the snapshots: the parts, the spheres, the wall, the obstacles."""
    handles = [Patch(color=BASE_COLOR, label="base part"), Patch(color=NECK_COLOR, label="neck part"),
               Patch(color=HEAD_COLOR, label="head part")]
    if spheres:
        handles.append(Patch(color=SPHERE_COLOR, alpha=0.55, label=f"spheres ({1000 * spheres[0][1]:.0f} mm)"))
    wall = next((o for o in plan.obstacles if isinstance(o, WallWithHole)), None)
    if wall is not None:
        handles.append(Patch(color=WALL_COLOR, alpha=0.35, label=f"wall, hole {1000 * wall.hole_diameter:.0f} mm"))
    if any(isinstance(o, (BoxObstacle, MeshObstacle)) for o in plan.obstacles):
        handles.append(Patch(color=OBSTACLE_COLOR, alpha=0.45, label="obstacles"))
    if slope_text(plan.base.ground):
        handles.append(Patch(color=GROUND_COLOR, alpha=0.3, label=f"ground: {slope_text(plan.base.ground)}"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=9, frameon=False)


# ----------------------------------------------------------------------------------------------
# Figs. 17 / 22
# ----------------------------------------------------------------------------------------------
def snapshot_states(plan: Plan, n_panels: int = 12) -> list[tuple[str, float, np.ndarray]]:
    """Up to ``n_panels`` of the plan's states (label, time s, q (n,)) in time order: the first and last, every
    target (evenly spread ones when more than ``n_panels - 2``: the figure's size does not grow with the targets),
    then the waypoints nearest to evenly spaced times. Holds are left out."""
    states = [s for s in plan.states if not s[0].endswith("(hold)")]
    if not states:
        raise InputError("the plan has no states")
    times = np.array([s[1] for s in states])
    chosen = {0, len(states) - 1}
    targets = list(plan.targets)
    if len(targets) > max(n_panels - 2, 1):
        targets = [targets[int(k)] for k in np.unique(np.round(np.linspace(0, len(targets) - 1,
                                                                           max(n_panels - 2, 1))))]
    for tg in targets:
        chosen.add(int(np.argmin(np.abs(times - tg.time_s))))
    for want in np.linspace(times[0], times[-1], max(n_panels, 2)):
        if len(chosen) >= n_panels:
            break
        order = np.argsort(np.abs(times - want))
        for k in order:
            if int(k) not in chosen:
                chosen.add(int(k))
                break
    return [states[k] for k in sorted(chosen)][:max(n_panels, len(targets) + 2)]


def plot_snapshots(plan: Plan, *, spheres: Sequence[Sphere] | None = None, n_panels: int = 12, columns: int = 4,
                   title: str = "") -> Figure:
    """Figs. 17 / 22: the body in 3-D at up to ``n_panels`` states of ``plan`` (see :func:`snapshot_states`),
    base grey, neck orange, head blue (collision shapes), with the scenery: ``spheres`` [(centre (3,) m, diameter
    m)] (default: the plan's scene's, :func:`plan_spheres`), the plan's obstacles (boxes and walls), and each head
    target as an arrow along its direction. Equal axis scales. (:func:`save_snapshots` writes the same picture
    faster.)"""
    layout = _SnapshotLayout(plan, spheres, n_panels, columns, title)
    for k in range(len(layout.picks)):
        ax = layout.panel(k)
        layout.draw_state(ax, k)
    return layout.figure


def save_snapshots(plan: Plan, path: str | os.PathLike, *, spheres: Sequence[Sphere] | None = None,
                   n_panels: int = 12, columns: int = 4, title: str = "") -> Path:
    """:func:`plot_snapshots`' figure written as a PNG (cropped as :func:`snakehead.viz.save` crops), drawn in a
    fraction of the time: every panel shows the same axes, ground and scenery, so one panel's still picture is
    drawn once and copied into the others, and only what differs -- the body, the head tip, the panel's title and
    the scenery drawn over the body -- is drawn per panel (as :func:`snakehead.viz.animation.animate` draws its
    frames). The panels sit on whole pixels (they move by less than half a pixel)."""
    path = Path(path)
    layout = _SnapshotLayout(plan, spheres, n_panels, columns, title)
    fig = layout.figure
    ax = layout.panel(0)
    moving = layout.draw_state(ax, 0)
    for artist in moving:
        artist.set_animated(True)  # left out of the still picture
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    pixels = np.asarray(canvas.buffer_rgba())
    height = pixels.shape[0]
    still = _PanelPicture(pixels, ax.get_tightbbox(renderer), height)
    first = np.array(ax.get_position(original=True).p0)
    original, active = ax.get_position(original=True), ax.get_position()
    title_at = ax.title.get_position()  # where the drawing put it (set_title on 3-D axes puts it lower)
    for k in range(len(layout.picks)):
        # the offset of panel k from panel (a), to whole pixels
        shift = np.round((np.array(layout.cell(k).p0) - first) * fig.bbox.size) if k else np.zeros(2)
        if k:
            still.paste(pixels, int(shift[0]), int(shift[1]))
            moving = layout.draw_state(ax, k)
            ax.title.set_position(title_at)
        move = shift / fig.bbox.size
        ax.set_position(original.translated(*move), which="original")
        ax.set_position(active.translated(*move), which="active")
        for artist in moving:
            if hasattr(artist, "do_3d_projection"):
                artist.do_3d_projection()
            ax.draw_artist(artist)
        for artist in moving[:2]:  # the body and the tip are the state's own; the rest is still
            artist.remove()
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_open(path, "wb") as f:
        if crop_and_write_png(fig, pixels, f, DEFAULT_DPI):
            return path
    return save(plot_snapshots(plan, spheres=spheres, n_panels=n_panels, columns=columns, title=title), path)


class _PanelPicture:
    """One panel's still picture, cut from a drawing (its axes' tight box): laid over another place of the drawing,
    only its ink (what differs from the figure's background) covers what is there, as a full drawing lays one
    panel's tick labels that reach beyond its box over its neighbour's."""

    def __init__(self, pixels: np.ndarray, tight: Any, height: int) -> None:
        self.left, self.top = max(int(np.floor(tight.x0)), 0), max(int(np.floor(height - tight.y1)), 0)
        right, bottom = int(np.ceil(tight.x1)), int(np.ceil(height - tight.y0))
        self.image = pixels[self.top:bottom, self.left:right].copy()
        self.ink = ink_mask(self.image, pixels[0, 0])  # the figure's corner: its background

    def paste(self, pixels: np.ndarray, dx: int, dy: int) -> None:
        """Lay the picture over ``pixels`` moved by (dx, dy) pixels (y up), clipped to the canvas."""
        h, w = self.image.shape[:2]
        top, left = self.top - dy, self.left + dx
        r0, c0 = max(top, 0), max(left, 0)
        r1, c1 = min(top + h, pixels.shape[0]), min(left + w, pixels.shape[1])
        if r1 <= r0 or c1 <= c0:
            return
        part = (slice(r0 - top, r1 - top), slice(c0 - left, c1 - left))
        if pixels.dtype == np.uint8 and pixels.shape[2] == 4 and pixels.flags.c_contiguous:  # a pixel as one word
            np.copyto(pixels.view(np.uint32)[r0:r1, c0:c1, 0], np.ascontiguousarray(self.image).view(np.uint32)[
                part + (0,)], where=self.ink[part])
        else:
            np.copyto(pixels[r0:r1, c0:c1], self.image[part], where=self.ink[part][..., None])


class _SnapshotLayout:
    """The snapshots' figure: its states, the panels' grid, the legend and the title; :meth:`panel` makes panel k
    (axes, ground and scenery), :meth:`draw_state` puts state k's body, head tip and title on an axes."""

    def __init__(self, plan: Plan, spheres: Sequence[Sphere] | None, n_panels: int, columns: int,
                 title: str) -> None:
        self.plan = plan
        self.spheres = plan_spheres(plan) if spheres is None else list(spheres)
        self.picks = snapshot_states(plan, n_panels)
        self.rows = -(-len(self.picks) // columns)
        self.columns = columns
        # The panels span 0.97 of 3 in a column; the 3-D axes' tick labels reach up to ~0.3 in beyond them, so the
        # figure has SNAPSHOT_SIDE_IN on either side (the saved figure is cropped to what is drawn: a margin only
        # keeps everything on the canvas, which save() then draws once)
        panels_in = 3.0 * columns
        fig = new_figure(figsize=(panels_in + 2 * SNAPSHOT_SIDE_IN, 3.8 * self.rows + 0.6))
        self.lo, self.hi = scene_bounds(plan, self.spheres)
        self.elev, self.azim = view_angles(plan)
        _part_legend(fig, plan, self.spheres)
        fig.suptitle(title or f"{literal(plan.name)}: the body at the scenario's states (axes in m, equal scales)",
                     fontsize=11)
        width = fig.get_figwidth()
        fig.subplots_adjust(left=SNAPSHOT_SIDE_IN / width, right=(SNAPSHOT_SIDE_IN + 0.97 * panels_in) / width,
                            bottom=0.5 / fig.get_figheight(), top=1 - 0.5 / fig.get_figheight(), wspace=0.12,
                            hspace=0.12)
        self.figure = fig
        self.grid = fig.add_gridspec(self.rows, columns)  # at the figure's subplot parameters, set above

    def cell(self, k: int) -> Any:
        """Panel k's place in the figure (a Bbox in figure fractions)."""
        return self.grid[k].get_position(self.figure)

    def panel(self, k: int) -> Axes3D:
        """Panel k: its 3-D axes over the scene's box, with the ground and the scenery."""
        ax = self.figure.add_subplot(self.grid[k], projection="3d", computed_zorder=False)
        setup_axes3d(ax, self.lo, self.hi, self.elev, self.azim, labels=False, zoom=1.2, plane=self.plan.base.ground)
        draw_scenery(ax, self.plan, self.spheres)
        return ax

    def draw_state(self, ax: Axes3D, k: int) -> list[Any]:
        """State k on ``ax``: its body, its head tip and its title; returns what a full drawing draws of them and
        after them, in order: the body, the tip, the still artists of a higher zorder than the body's, the title."""
        robot, plan = self.plan.robot, self.plan
        label, time, q = self.picks[k]
        frames = world_frames(plan.base.ground, robot.frames(q, plan.base))
        body = draw_body(ax, robot, frames)
        tip = ax.scatter(*frames[robot.link_index(robot.parts.head_tip), :3, 3], color="k", s=6)
        ax.set_title(f"({chr(ord('a') + k)}) {literal(label)}\nt = {time:.1f} s", fontsize=8)
        children = ax.get_children()
        over = sorted([a for a in (*ax.collections, *ax.lines, *ax.patches, *ax.texts)
                       if a not in (body, tip) and a.get_zorder() > body.get_zorder()],
                      key=lambda a: (a.get_zorder(), children.index(a)))
        return [body, tip, *over, ax.title]


# ----------------------------------------------------------------------------------------------
# one head solution: the robot in 3-D and the neck geometry of Fig. 8
# ----------------------------------------------------------------------------------------------
def plot_head_solution(robot: SnakeRobot, solution: HeadSolution) -> Figure:
    """A ``HeadController`` solution: the body in 3-D (left) and the neck geometry of Fig. 8 (right).

    Right: in the vertical plane through P0 and the target, P0 (end of the base), G0 (where the dexterous
    centre should go: the target), P_d and r_d (Eqs. 19-20: the desired neck end), and the neck end B0 and its
    x-axis r_a that Eq. 22 reached; the neck and head drawn as their joint chain. Lengths in m.
    """
    ground = solution.base.ground
    frames = robot.frames(solution.q, solution.base)  # in the ground frame (the right panel's), drawn in the world
    fig = new_figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    drawn = world_frames(ground, frames)
    draw_body(ax, robot, drawn)
    desired = world_frames(ground, solution.desired_frame)
    p, d = desired[:3, 3], 0.08 * desired[:3, 0]
    ax.quiver(p[0], p[1], p[2], d[0], d[1], d[2], color="k", lw=1.2, arrow_length_ratio=0.3)
    shown = drawn[:, :3, 3]
    lo = np.minimum(shown.min(axis=0), p) - 0.08
    hi = np.maximum(shown.max(axis=0), p) + 0.08
    setup_axes3d(ax, lo, hi, elev=22.0, azim=-60.0, plane=ground)
    slope = f"; on a {slope_text(ground)}" if slope_text(ground) else ""
    ax.set_title(f"head at the target: {1000 * solution.position_error_m:.4f} mm, "
                 f"{solution.direction_error_deg:.4f} deg\nstatic margin {1000 * solution.static_margin_m:.1f} mm"
                 f"{slope}", fontsize=9)
    pts = frames[:, :3, 3]

    ax2 = fig.add_subplot(1, 2, 2)
    g = solution.neck_goal
    if g is not None and solution.neck is not None:
        # the plane through P0 spanned by the horizontal direction to G0 and the vertical
        u = g.G0 - g.P0
        u[2] = 0.0
        u = u / np.linalg.norm(u) if np.linalg.norm(u) > 1e-9 else np.array([1.0, 0.0, 0.0])

        def plane(x: Any) -> np.ndarray:
            x = np.atleast_2d(np.asarray(x, float)) - g.P0
            return np.column_stack([x @ u, x[:, 2]])

        start = robot.link_index(robot.parts.base_end)
        chain = plane(pts[start:])
        ax2.plot(chain[:, 0], chain[:, 1], "-o", color=HEAD_COLOR, ms=3, lw=1.5,
                 label="neck and head joints (projected)")
        neck_end = robot.link_index(robot.parts.neck_end)
        ax2.plot(*plane(pts[start:neck_end + 1]).T, "-o", color=NECK_COLOR, ms=4, lw=2.5, label="neck")
        P0, G0, Pd = plane(g.P0)[0], plane(g.G0)[0], plane(g.P_d)[0]
        ax2.plot(*np.vstack([P0, G0]).T, ":", color="k", lw=1)
        ax2.plot(*P0, "s", color=BASE_COLOR, ms=8, label="P0 (end of the base)")
        ax2.plot(*G0, "*", color=SPHERE_COLOR, ms=14, label="G0 = target (Eq. 19)")
        ax2.plot(*Pd, "D", color="k", ms=6, mfc="none", label="P_d (Eq. 20)")
        B0 = plane(solution.neck.frame[:3, 3])[0]
        ra = solution.neck.frame[:3, 0]
        rd_dir = plane(g.P0 + g.r_d)[0] - P0
        ra_dir = plane(g.P0 + ra)[0] - P0
        ax2.plot(*B0, "o", color=NECK_COLOR, ms=8, mfc="white", label="B0 reached (Eq. 22)")
        ax2.quiver(*Pd, *(0.08 * rd_dir), angles="xy", scale_units="xy", scale=1, color="k", width=0.004,
                   label="r_d")
        ax2.quiver(*B0, *(0.08 * ra_dir), angles="xy", scale_units="xy", scale=1, color=NECK_COLOR, width=0.004,
                   label="r_a")
        ax2.axhline(-g.P0[2], color=GROUND_COLOR, lw=2)
        ax2.set_aspect("equal")
        ax2.set_xlabel("horizontal distance from P0 towards the target (m)")
        ax2.set_ylabel("height above P0 (m)")
        ax2.set_title(f"Fig. 8: the neck end frame; L_c = {g.Lc:.3f} m; |P_a - P_d| = "
                      f"{1000 * solution.neck.position_error_m:.1f} mm, angle(r_a, r_d) = "
                      f"{solution.neck.direction_error_deg:.1f} deg", fontsize=9)
        ax2.legend(fontsize=7, loc="lower right")
        ax2.grid(alpha=0.3)
    else:
        ax2.text(0.5, 0.5, "no neck goal: " + literal(solution.message), ha="center", va="center", wrap=True)
        ax2.set_axis_off()
    fig.suptitle("HeadController solution (Section 2.4, Fig. 8)")
    return fig


# ----------------------------------------------------------------------------------------------
# Fig. 11 against Fig. 13
# ----------------------------------------------------------------------------------------------
def _draw_snapshots(ax: Axes3D, robot: SnakeRobot, qs: np.ndarray, base: BasePlacement, color: str,
                    k: int = 6) -> np.ndarray:
    """The body at ``k`` of the configurations ``qs`` (its axis, the base's and the lowest point's marks) in
    ``color``, and the shape points in the ground over the whole motion; the indices of the configurations drawn."""
    frames = robot.frames_many(qs, base)
    pts = body_points(robot, frames)
    n_base = robot.parts.base.stop + 1  # points 0 .. n_base: the root, the base's joints and P0 (the neck's first)
    clear = coll.ground_clearance(robot, qs, base)
    links = robot.lifted_links
    worst = clear[:, links].min(axis=1)
    picks = np.unique(np.r_[np.linspace(0, len(qs) - 1, k).round().astype(int), np.argmin(worst)])
    b = pts[-1, : n_base + 1]
    ax.plot(b[:, 0], b[:, 1], b[:, 2], "-", color="0.35", lw=4, solid_capstyle="round", label="base")
    for n, i in enumerate(picks):
        alpha = min(1.0, 0.2 + 0.8 * n / max(1, len(picks) - 1))
        p = pts[i, n_base:]
        ax.plot(p[:, 0], p[:, 1], p[:, 2], "-o", color=color, lw=2.2, ms=2.5, alpha=alpha)
    for i, label in ((0, "State 1"), (len(qs) - 1, "State 2")):
        ax.text(*pts[i, -1] + [0, 0, 0.03], label, fontsize=9, color="k")
    tip = pts[:, -1]
    ax.plot(tip[:, 0], tip[:, 1], tip[:, 2], ":", color="k", lw=1.2, label="head tip path")
    worst_i = int(np.argmin(worst))
    p = pts[worst_i, n_base:]
    ax.plot(p[:, 0], p[:, 1], p[:, 2], "-", color=color, lw=3.5, label=f"lowest ({1000 * worst[worst_i]:.0f} mm)")
    # the shapes' lowest points below the ground, over the whole motion
    below = clear < -coll.GROUND_TOLERANCE
    if below.any():
        ti = np.unique(np.nonzero(below)[0])
        points, _ = robot.lowest_points(frames[ti])
        points = points.reshape(-1, 3)
        points = points[points[:, 2] < -coll.GROUND_TOLERANCE]
        ax.scatter(points[:, 0], points[:, 1], points[:, 2], s=2, color="k", alpha=0.3,
                   label="shape points in the ground")
    return picks


def plot_interpolation_comparison(robot: SnakeRobot, q_start: npt.ArrayLike, q_end: npt.ArrayLike, *,
                                  base: BasePlacement | None = None, n: int = 200) -> Figure:
    """Fig. 11 vs Fig. 13: the same start and end (n,) rad, interpolated in joint space (left) and by Eqs. 41-44
    (middle) in ``n`` steps; right: the lowest point of the neck's and head's collision shapes over the motion."""
    base = BasePlacement() if base is None else base
    q_start = np.asarray(q_start, float)
    q_end = np.asarray(q_end, float)
    s = np.linspace(0.0, 1.0, n)
    q_joint = q_start + (q_end - q_start) * s[:, None]
    res = cartesian_interpolation(robot, q_start, q_end, n, base, full_output=True)
    q_cart = res.q
    links = robot.lifted_links
    cj = coll.ground_clearance(robot, q_joint, base)[:, links].min(axis=1)
    cc = coll.ground_clearance(robot, q_cart, base)[:, links].min(axis=1)
    fig = new_figure(figsize=(17, 6.2))
    allp = body_points(robot, robot.frames_many(np.vstack([q_joint, q_cart]), base)).reshape(-1, 3)
    lo, hi = allp.min(axis=0) - 0.05, allp.max(axis=0) + 0.05
    span = (hi - lo).max()
    for k, (qs, color, title) in enumerate([
            (q_joint, _JOINT_SPACE, f"Fig. 11: joint-space interpolation\nlowest shape point {1000 * cj.min():.0f} mm"),
            (q_cart, _CARTESIAN, f"Fig. 13: Cartesian interpolation (Eqs. 41-44)\nlowest shape point "
                                 f"{1000 * cc.min():.1f} mm, joints stray <= {1000 * res.max_deviation:.0f} mm")]):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d", computed_zorder=False)
        X, Y = np.meshgrid(np.linspace(lo[0], lo[0] + span, 2), np.linspace(lo[1], lo[1] + span, 2))
        ax.plot_surface(X, Y, np.zeros_like(X), color=GROUND_COLOR, alpha=0.15, linewidth=0)
        _draw_snapshots(ax, robot, qs, base, color)
        ax.set_xlim(lo[0], lo[0] + span)
        ax.set_ylim(lo[1], lo[1] + span)
        ax.set_zlim(-0.08, -0.08 + 0.5 * span)
        ax.set_box_aspect((1, 1, 0.5), zoom=1.15)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_zlabel("z (m)")
        ax.view_init(elev=14, azim=-125)
        ax.set_title(title, fontsize=10)
        ax.legend(loc="upper left", fontsize=8)
    ax = fig.add_subplot(1, 3, 3)
    ax.plot(s, 1000 * cj, color=_JOINT_SPACE, lw=2, label="joint space")
    ax.plot(s, 1000 * cc, color=_CARTESIAN, lw=2, label="Cartesian (Eqs. 41-44)")
    ax.axhline(0, color=GROUND_COLOR, lw=1.5)
    ax.fill_between(s, 1000 * np.minimum(cj, 0), 0, color=_JOINT_SPACE, alpha=0.2, label="in the ground")
    ax.set_xlabel("interpolation parameter $t_j$ (Eq. 41)")
    ax.set_ylabel("lowest point of neck and head shapes (mm)")
    ax.set_title("clearance of the neck and head above the ground", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9)
    fig.tight_layout()
    return fig


__all__ = ["part_colors", "body_faces", "convex_facets", "shape_footprints", "box_faces", "mesh_obstacle_faces",
           "wall_faces", "hole_rim", "plan_spheres", "scene_bounds", "view_angles", "draw_scenery", "draw_body",
           "body_points", "snapshot_states", "plot_snapshots", "save_snapshots", "plot_head_solution", "plot_interpolation_comparison"]
