"""Figures and animations of a planned scenario (``snakehead.scenarios.ScenarioResult``), after the paper's
Section 4 (matplotlib, Agg backend: files only, no windows).

* :func:`plot_snapshots` -- Figs. 17 and 22: the whole body in 3-D at the scenario's key states, with the
  spheres or the wall and its hole, one panel per state.
* :func:`plot_momenta` -- Figs. 18-19 and 23-24: planned (and simulated) angular and linear momenta, drawn by
  :func:`snakehead.plots.plot_momenta`.
* :func:`plot_zmp` -- Figs. 20 and 25: the planned ZMP (and the simulated one) inside the support polygon of the
  scenario's contact model, and both margins over time.
* :func:`animate` -- the whole motion as a GIF (``FuncAnimation`` with the Pillow writer).

Positions in m, times in s, world frame z up with the ground at z = 0. Every function returns the written path
(``pathlib.Path``).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import numpy as np

from . import figures as plots
from ..dynamics import stability as st
from ..geometry.obstacles import WallWithHole
from ..model.robot import SnakeRobot

_BASE = "#7f8c8d"
_NECK = "#e67e22"
_HEAD = "#2e86c1"
_SPHERE = "#c0392b"
_WALL = "#a1887f"
_PLANNED = "#1f77b4"
_SIMULATED = "#c0392b"

# unit cube corners (8, 3) and its faces (6, 4) as corner indices
_CORNERS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
_FACES = np.array([[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]])


def _plt():
    return plots._plt()


# ----------------------------------------------------------------------------------------------
# geometry helpers
# ----------------------------------------------------------------------------------------------
def _link_colors(robot: SnakeRobot) -> list[str]:
    """A colour per frame of ``robot.link_names``: base grey, neck orange, head blue."""
    names = robot.link_names
    base_end = names.index(robot.parts.base_end)
    neck_end = names.index(robot.parts.neck_end)
    return [_BASE if i <= base_end else _NECK if i <= neck_end else _HEAD for i in range(len(names))]


def body_faces(robot: SnakeRobot, frames: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """The faces of every collision box: (B * 6, 4, 3) world corners (m) and one colour per face.

    frames (L, 4, 4): world poses of ``robot.link_names`` (``robot.frames``); frames without a box are skipped.
    """
    boxed = np.flatnonzero(np.all(robot.box_sizes > 0, axis=1))
    B = frames[boxed] @ robot.box_origins[boxed]  # (B, 4, 4)
    corners = B[:, None, :3, 3] + np.einsum("bij,bkj->bki", B[:, :3, :3], _CORNERS[None] * robot.box_sizes[boxed, None])
    faces = corners[:, _FACES].reshape(-1, 4, 3)
    colors = _link_colors(robot)
    return faces, [colors[i] for i in boxed for _ in range(6)]


def wall_faces(wall: WallWithHole, n: int = 64) -> np.ndarray:
    """The wall's mid-plane as quads tiling the rectangle minus the hole: (K, 4, 3) world corners (m).

    Each quad joins two neighbouring points of the hole's rim to the points where the same rays from the hole's
    centre leave the rectangle; the rays include the rectangle's corners, so the tiling is exact up to the rim's
    ``n``-gon.
    """
    R = wall.rotation
    half = wall.size[:2] / 2
    off = wall.hole_offset
    r = wall.hole_diameter / 2
    corners = np.array([[sx, sy] for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]) * half + off
    angles = np.sort(np.r_[np.linspace(0, 2 * np.pi, n, endpoint=False), np.arctan2(corners[:, 1], corners[:, 0]) % (2 * np.pi)])
    d = np.column_stack([np.cos(angles), np.sin(angles)])
    # distance along each ray to the rectangle [off - half, off + half] (the hole's centre is inside it)
    with np.errstate(divide="ignore"):
        tx = np.where(d[:, 0] > 0, (off[0] + half[0]) / d[:, 0], np.where(d[:, 0] < 0, (off[0] - half[0]) / d[:, 0], np.inf))
        ty = np.where(d[:, 1] > 0, (off[1] + half[1]) / d[:, 1], np.where(d[:, 1] < 0, (off[1] - half[1]) / d[:, 1], np.inf))
    outer = d * np.minimum(tx, ty)[:, None]
    inner = d * r
    nxt = np.roll(np.arange(len(angles)), -1)
    quads = np.stack([inner, inner[nxt], outer[nxt], outer], axis=1)  # (K, 4, 2) in (width, height)
    return wall.centre + quads @ R[:, :2].T


def _sphere_mesh(centre, diameter: float, n: int = 14):
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2 + 1))
    r = diameter / 2
    return (centre[0] + r * np.cos(u) * np.sin(v), centre[1] + r * np.sin(u) * np.sin(v), centre[2] + r * np.cos(v))


def _scene_box(robot: SnakeRobot, result, spheres, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (3,) of a box holding the body over the whole motion, the scenery and the ground."""
    step = max(1, len(result.q) // 200)
    pts = robot.frames_many(result.q[::step], result.base)[..., :3, 3].reshape(-1, 3)
    extra = [pts, np.zeros((1, 3))]
    extra += [np.asarray(c, float)[None] for c, _ in spheres]
    extra += [tg.position[None] for tg in result.targets]
    for ob in result.obstacles:
        if isinstance(ob, WallWithHole):
            R = ob.rotation
            half = ob.size[:2] / 2
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half + ob.hole_offset
            extra.append(ob.centre + corners @ R[:, :2].T)
    allp = np.vstack(extra)
    return allp.min(axis=0) - margin, allp.max(axis=0) + margin


def _setup_axes(ax, lo, hi, elev: float, azim: float, labels: bool = True, zoom: float = 1.0):
    """Equal scales on x, y, z (the body is not distorted), ground at z = 0."""
    lo = lo.copy()
    lo[2] = min(lo[2], 0.0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo, zoom=zoom)
    ax.view_init(elev=elev, azim=azim)
    if labels:
        ax.set_xlabel("x (m)", fontsize=8, labelpad=-2)
        ax.set_ylabel("y (m)", fontsize=8, labelpad=-2)
        ax.set_zlabel("z (m)", fontsize=8, labelpad=-2)
    ax.tick_params(labelsize=6, pad=-2)
    X, Y = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
    ax.plot_surface(X, Y, np.zeros_like(X), color=plots._GROUND, alpha=0.12, linewidth=0, zorder=0)


def _draw_scenery(ax, result, spheres, *, arrows: bool = True):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    for centre, diameter in spheres:
        ax.plot_surface(*_sphere_mesh(np.asarray(centre, float), diameter), color=_SPHERE, alpha=0.55, linewidth=0)
    for ob in result.obstacles:
        if isinstance(ob, WallWithHole):
            ax.add_collection3d(Poly3DCollection(wall_faces(ob), facecolor=_WALL, edgecolor="none", alpha=0.35))
            th = np.linspace(0, 2 * np.pi, 65)
            rim = ob.centre + (ob.hole_diameter / 2) * (np.outer(np.cos(th), ob.rotation[:, 0])
                                                        + np.outer(np.sin(th), ob.rotation[:, 1]))
            ax.plot(rim[:, 0], rim[:, 1], rim[:, 2], "-", color="k", lw=1.0)
    if arrows:
        for tg in result.targets:
            p, d = tg.position, 0.08 * tg.direction
            ax.quiver(p[0], p[1], p[2], d[0], d[1], d[2], color="k", lw=1.0, arrow_length_ratio=0.3)


def _draw_body(ax, robot: SnakeRobot, frames: np.ndarray, alpha: float = 0.95):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    faces, colors = body_faces(robot, frames)
    coll = Poly3DCollection(faces, facecolors=colors, edgecolors="k", linewidths=0.15, alpha=alpha)
    ax.add_collection3d(coll)
    return coll


def _view(result) -> tuple[float, float]:
    """(elevation, azimuth) in degrees: from behind and to the side of the head's approach."""
    return (18.0, -58.0) if result.obstacles else (22.0, -62.0)


# ----------------------------------------------------------------------------------------------
# Figs. 17 / 22
# ----------------------------------------------------------------------------------------------
def snapshot_states(result, n_panels: int = 12) -> list[tuple[str, float, np.ndarray]]:
    """Up to ``n_panels`` of the scenario's states (label, time s, q (16,)) in time order: the first and last,
    every target, then the waypoints nearest to evenly spaced times. Holds are left out."""
    states = [s for s in result.states if not s[0].endswith("(hold)")]
    if not states:
        raise ValueError("the scenario has no states")
    times = np.array([s[1] for s in states])
    chosen = {0, len(states) - 1}
    for tg in result.targets:
        chosen.add(int(np.argmin(np.abs(times - tg.time_s))))
    for want in np.linspace(times[0], times[-1], max(n_panels, 2)):
        if len(chosen) >= n_panels:
            break
        order = np.argsort(np.abs(times - want))
        for k in order:
            if int(k) not in chosen:
                chosen.add(int(k))
                break
    return [states[k] for k in sorted(chosen)][:max(n_panels, len(result.targets) + 2)]


def plot_snapshots(robot: SnakeRobot, result, path: str | os.PathLike, *, spheres: Sequence = (),
                   n_panels: int = 12, columns: int = 4, title: str = "") -> Path:
    """Figs. 17 / 22: the body in 3-D at up to ``n_panels`` states of ``result`` (see :func:`snapshot_states`),
    base grey, neck orange, head blue (collision boxes), with the scenery: ``spheres`` [(centre (3,) m, diameter
    m)], the result's wall obstacles, and each head target as an arrow along its direction. Equal axis scales."""
    picks = snapshot_states(result, n_panels)
    rows = -(-len(picks) // columns)
    plt = _plt()
    fig = plt.figure(figsize=(3.0 * columns, 3.8 * rows + 0.6))
    lo, hi = _scene_box(robot, result, spheres)
    elev, azim = _view(result)
    for k, (label, time, q) in enumerate(picks):
        ax = fig.add_subplot(rows, columns, k + 1, projection="3d", computed_zorder=False)
        _setup_axes(ax, lo, hi, elev, azim, labels=False, zoom=1.2)
        _draw_scenery(ax, result, spheres, arrows=not spheres and not result.obstacles)
        _draw_body(ax, robot, robot.frames(q, result.base))
        tip = robot.head_pose(q, result.base)[:3, 3]
        ax.scatter(*tip, color="k", s=6)
        ax.set_title(f"({chr(ord('a') + k)}) {label}\nt = {time:.1f} s", fontsize=8)
    from matplotlib.patches import Patch

    handles = [Patch(color=_BASE, label="base part"), Patch(color=_NECK, label="neck part"),
               Patch(color=_HEAD, label="head part")]
    if spheres:
        handles.append(Patch(color=_SPHERE, alpha=0.55, label=f"spheres ({1000 * spheres[0][1]:.0f} mm)"))
    if any(isinstance(o, WallWithHole) for o in result.obstacles):
        wall = next(o for o in result.obstacles if isinstance(o, WallWithHole))
        handles.append(Patch(color=_WALL, alpha=0.35, label=f"wall, hole {1000 * wall.hole_diameter:.0f} mm"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=9, frameon=False)
    fig.suptitle(title or f"{result.name}: the body at the scenario's states (axes in m, equal scales)", fontsize=11)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.5 / fig.get_figheight(), top=1 - 0.5 / fig.get_figheight(),
                        wspace=0.12, hspace=0.12)
    return plots._save(fig, path)


# ----------------------------------------------------------------------------------------------
# Figs. 18-19 / 23-24 and 20 / 25
# ----------------------------------------------------------------------------------------------
def plot_momenta(result, path: str | os.PathLike, *, sim_result=None, figures: tuple = (18, 19),
                 title: str = "") -> Path:
    """Figs. 18-19 (23-24): the planned angular and linear momenta about the world origin (from the scenario's
    dynamic stability check) and, with ``sim_result`` (``snakehead.sim.SimResult``), the simulated ones."""
    other = None if sim_result is None else (sim_result.t, sim_result.P, sim_result.L)
    return plots.plot_momenta(result.t, result.stability.P, result.stability.L, path, other=other,
                              labels=("planned", "simulated (MuJoCo)"), figures=figures,
                              title=title or f"{result.name}: momenta about the world origin")


def plot_zmp(robot: SnakeRobot, result, path: str | os.PathLike, *, sim_result=None, figure: int | None = 20,
             contact: str = "ground", title: str = "") -> Path:
    """Figs. 20 / 25: left, the planned ZMP (Eqs. 39-40, coloured by time) and the centre of mass's ground
    projection over the support polygon(s) of ``contact`` (the model the scenario was checked with), the base's
    footprint in grey, and the simulated ZMP (centre of pressure of MuJoCo's contact forces) with
    ``sim_result``; right, the signed distance of each to the polygon's edge over time (mm, > 0 inside)."""
    dyn = result.stability
    t, q, base = result.t, result.q, result.base
    plt = _plt()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 5.4), gridspec_kw=dict(width_ratios=[1.15, 1]))
    frames = robot.frames(q[-1], base)
    end = robot.link_names.index(robot.parts.base_end)
    for li in range(end):
        if not np.all(robot.box_sizes[li] > 0):
            continue
        B = frames[li] @ robot.box_origins[li]
        h = robot.box_sizes[li] / 2
        xy = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * h[:2] @ B[:2, :2].T + B[:2, 3]
        ax.fill(xy[:, 0], xy[:, 1], color="0.85", ec="0.6", lw=0.8, zorder=1)
    # every distinct support polygon along the motion (few: the base keeps its shape)
    step = max(1, len(q) // 400)
    seen: list[np.ndarray] = []
    for i in range(0, len(q), step):
        poly = st.support_polygon(robot, q[i], base, contact=contact)
        if not any(p.shape == poly.shape and np.allclose(p, poly, atol=1e-6) for p in seen):
            seen.append(poly)
    for k, poly in enumerate(seen[:6]):
        closed = np.vstack([poly, poly[:1]])
        ax.plot(closed[:, 0], closed[:, 1], "-", color="k", lw=1.5 if k == 0 else 0.8,
                label=f"support polygon ({contact} contact)" if k == 0 else None, zorder=2)
    sc = ax.scatter(dyn.zmp[::step, 0], dyn.zmp[::step, 1], c=t[::step], cmap="viridis", s=5, zorder=3,
                    label="ZMP planned")
    ax.plot(dyn.com[:, 0], dyn.com[:, 1], "--", color="k", lw=1.0, label="CoM ground projection", zorder=4)
    ax.plot(*dyn.zmp[dyn.argmin], "x", color=_SIMULATED, ms=10, mew=2, label="smallest planned margin", zorder=6)
    margins_sim = None
    if sim_result is not None:
        from ..sim import zmp_margins

        z = sim_result.zmp
        ax.plot(z[:, 0], z[:, 1], "-", color=_SIMULATED, lw=0.7, alpha=0.8, label="ZMP simulated (MuJoCo)", zorder=5)
        margins_sim = zmp_margins(robot, sim_result, t, q, base)
    fig.colorbar(sc, ax=ax, label="t (s)", shrink=0.8)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title((f"Fig. {figure}: " if figure else "") + "ZMP (Eqs. 39-40) in the support polygon (Eq. 24)",
                 fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax2.plot(t, 1000 * dyn.margin, color=_PLANNED, lw=1.8, label="planned ZMP")
    if margins_sim is not None:
        ax2.plot(sim_result.t, 1000 * margins_sim, color=_SIMULATED, lw=0.8,
                 label="simulated ZMP (footprint polygon)")
    ax2.axhline(0, color="k", lw=1)
    ax2.set_xlabel("t (s)")
    ax2.set_ylabel("distance to the polygon's edge (mm, > 0 inside)")
    verdict = "inside" if dyn.stable else "NOT inside"
    ax2.set_title(f"planned ZMP {verdict} throughout; min margin {1000 * dyn.min_margin:.1f} mm", fontsize=10)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=9)
    fig.suptitle(title or f"{result.name}: zero-moment point", fontsize=11)
    fig.tight_layout()
    return plots._save(fig, path)


# ----------------------------------------------------------------------------------------------
# animation
# ----------------------------------------------------------------------------------------------
def animate(robot: SnakeRobot, result, path: str | os.PathLike, *, spheres: Sequence = (), fps: float = 12.0,
            max_frames: int = 150, size: tuple[float, float] = (5.0, 4.0), dpi: int = 80) -> Path:
    """The planned motion as a GIF (matplotlib ``FuncAnimation``, Pillow writer): at most ``max_frames`` frames
    evenly spaced in time, played at ``fps`` frames/s (so faster than real time for long scenarios: the title
    shows the factor), ``size`` inches at ``dpi``. The head tip's path so far is traced."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    fps = float(fps)
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be positive, got {fps!r}")
    if int(max_frames) != max_frames or max_frames < 2:
        raise ValueError(f"max_frames must be an integer >= 2, got {max_frames!r}")
    t = result.t
    n = int(min(max_frames, len(t)))
    idx = np.unique(np.linspace(0, len(t) - 1, n).round().astype(int))
    frames = robot.frames_many(result.q[idx], result.base)
    tip = frames[:, robot.link_names.index(robot.parts.head_tip), :3, 3]
    speedup = (t[-1] - t[0]) / max(len(idx) / fps, 1e-9)
    plt = _plt()
    fig = plt.figure(figsize=size)
    ax = fig.add_subplot(1, 1, 1, projection="3d", computed_zorder=False)
    lo, hi = _scene_box(robot, result, spheres)
    _setup_axes(ax, lo, hi, *_view(result), zoom=0.92)
    _draw_scenery(ax, result, spheres)
    body = _draw_body(ax, robot, frames[0])
    (trace,) = ax.plot(tip[:1, 0], tip[:1, 1], tip[:1, 2], ":", color="k", lw=1.0)
    title = fig.text(0.5, 0.98, "", ha="center", va="top", fontsize=9)

    def update(k):
        body.set_verts(body_faces(robot, frames[k])[0])
        trace.set_data_3d(tip[: k + 1, 0], tip[: k + 1, 1], tip[: k + 1, 2])
        title.set_text(f"{result.name}: t = {t[idx[k]]:5.1f} s  (x{speedup:.1f} speed)")
        return body, trace, title

    fig.subplots_adjust(left=0.0, right=0.96, bottom=0.02, top=0.98)
    anim = FuncAnimation(fig, update, frames=len(idx), blit=False)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    anim.save(path, writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------------------------
# one head solution: the robot in 3-D and the neck geometry of Fig. 8
# ----------------------------------------------------------------------------------------------
def plot_head_solution(robot: SnakeRobot, solution, path: str | os.PathLike) -> Path:
    """A ``HeadController`` solution: the body in 3-D (left) and the neck geometry of Fig. 8 (right).

    Right: in the vertical plane through P0 and the target, P0 (end of the base), G0 (where the dexterous
    centre should go: the target), P_d and r_d (Eqs. 19-20: the desired neck end), and the neck end B0 and its
    x-axis r_a that Eq. 22 reached; the neck and head drawn as their joint chain. Lengths in m.
    """
    plt = _plt()
    frames = robot.frames(solution.q, solution.base)
    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    _draw_body(ax, robot, frames)
    p, d = solution.desired_frame[:3, 3], 0.08 * solution.desired_frame[:3, 0]
    ax.quiver(p[0], p[1], p[2], d[0], d[1], d[2], color="k", lw=1.2, arrow_length_ratio=0.3)
    pts = frames[:, :3, 3]
    lo = np.minimum(pts.min(axis=0), p) - 0.08
    hi = np.maximum(pts.max(axis=0), p) + 0.08
    _setup_axes(ax, lo, hi, elev=22.0, azim=-60.0)
    ax.set_title(f"head at the target: {1000 * solution.position_error_m:.4f} mm, {solution.direction_error_deg:.4f} deg\n"
                 f"static margin {1000 * solution.static_margin_m:.1f} mm", fontsize=9)

    ax2 = fig.add_subplot(1, 2, 2)
    g = solution.neck_goal
    if g is not None and solution.neck is not None:
        # the plane through P0 spanned by the horizontal direction to G0 and the vertical
        u = g.G0 - g.P0
        u[2] = 0.0
        u = u / np.linalg.norm(u) if np.linalg.norm(u) > 1e-9 else np.array([1.0, 0.0, 0.0])

        def plane(x):
            x = np.atleast_2d(np.asarray(x, float)) - g.P0
            return np.column_stack([x @ u, x[:, 2]])

        start = robot.link_names.index(robot.parts.base_end)
        chain = plane(pts[start:])
        ax2.plot(chain[:, 0], chain[:, 1], "-o", color=_HEAD, ms=3, lw=1.5, label="neck and head joints (projected)")
        neck_end = robot.link_names.index(robot.parts.neck_end)
        ax2.plot(*plane(pts[start:neck_end + 1]).T, "-o", color=_NECK, ms=4, lw=2.5, label="neck")
        P0, G0, Pd = plane(g.P0)[0], plane(g.G0)[0], plane(g.P_d)[0]
        ax2.plot(*np.vstack([P0, G0]).T, ":", color="k", lw=1)
        ax2.plot(*P0, "s", color=_BASE, ms=8, label="P0 (end of the base)")
        ax2.plot(*G0, "*", color=_SPHERE, ms=14, label="G0 = target (Eq. 19)")
        ax2.plot(*Pd, "D", color="k", ms=6, mfc="none", label="P_d (Eq. 20)")
        B0 = plane(solution.neck.frame[:3, 3])[0]
        ra = solution.neck.frame[:3, 0]
        rd_dir = plane(g.P0 + g.r_d)[0] - P0
        ra_dir = plane(g.P0 + ra)[0] - P0
        ax2.plot(*B0, "o", color=_NECK, ms=8, mfc="white", label="B0 reached (Eq. 22)")
        ax2.quiver(*Pd, *(0.08 * rd_dir), angles="xy", scale_units="xy", scale=1, color="k", width=0.004,
                   label="r_d")
        ax2.quiver(*B0, *(0.08 * ra_dir), angles="xy", scale_units="xy", scale=1, color=_NECK, width=0.004,
                   label="r_a")
        ax2.axhline(-g.P0[2], color=plots._GROUND, lw=2)
        ax2.set_aspect("equal")
        ax2.set_xlabel("horizontal distance from P0 towards the target (m)")
        ax2.set_ylabel("height above P0 (m)")
        ax2.set_title(f"Fig. 8: the neck end frame; L_c = {g.Lc:.3f} m; |P_a - P_d| = "
                      f"{1000 * solution.neck.position_error_m:.1f} mm, angle(r_a, r_d) = "
                      f"{solution.neck.direction_error_deg:.1f} deg", fontsize=9)
        ax2.legend(fontsize=7, loc="lower right")
        ax2.grid(alpha=0.3)
    else:
        ax2.text(0.5, 0.5, "no neck goal: " + solution.message, ha="center", va="center", wrap=True)
        ax2.set_axis_off()
    fig.suptitle("HeadController solution (Section 2.4, Fig. 8)")
    return plots._save(fig, path)
