"""Figures of the paper that snakehead can redraw (matplotlib, Agg backend: files, no windows).

Whole-body motion and stability (Sections 3.1, 3.2):

* :func:`plot_interpolation_comparison` -- Fig. 11 against Fig. 13: joint-space interpolation that drives the
  head into the ground beside the Cartesian interpolation (Eqs. 41-44) that does not, with the lowest link
  clearance along both.
* :func:`plot_momenta` -- Figs. 18-19: angular and linear momentum about the world origin over time.
* :func:`plot_zmp` -- Fig. 20: the ZMP and the CoM's ground projection inside the support polygon.
* :func:`lift_head_figures` -- all three for the lift-the-head motions of :func:`lift_head_motion` and
  :func:`stable_lift_motion`.

Every function returns the written path (pathlib.Path).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..dynamics import stability as st
from ..geometry import collision as coll
from ..motion.cartesian import cartesian_interpolation, cartesian_trajectory
from ..model.robot import BasePlacement, SnakeRobot

_JOINT_SPACE = "#c0392b"
_CARTESIAN = "#1f77b4"
_GROUND = "#8d6e63"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150, bbox_inches="tight")
    _plt().close(fig)
    return path


def lift_head_motion(robot: SnakeRobot | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Start and end of a lift-the-head motion like Fig. 11 (default robot): the base bent in an arc, the neck and
    head curled on the ground (State 1); at the end the neck stands up and the head bends forward and down.
    Joint-space interpolation between them drives the head into the ground; Eqs. 41-44 do not."""
    robot = SnakeRobot.default() if robot is None else robot
    q_start = np.zeros(robot.n_joints)
    q_start[0:7:2] = 0.65  # base arc (yaw joints 1, 3, 5, 7)
    q_end = q_start.copy()
    q_start[8:16:2] = 0.5  # neck and head curled on the ground (yaw joints 9, 11, 13, 15)
    q_end[7], q_end[8] = -1.5, 1.5  # joint 8 raises the neck, joint 9 turns the head
    q_end[[9, 11, 13, 15]] = [0.5, 0.5, 0.4, 0.3]  # the head's pitch joints bend it forward and down
    return q_start, q_end


def stable_lift_motion(robot: SnakeRobot | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A lift-the-head motion that stays dynamically stable (default robot): the base curled in a tight arc,
    the neck and head curled on the ground inside it, lifted to stand over the arc (found by maximising the
    static margin of the raised configuration)."""
    robot = SnakeRobot.default() if robot is None else robot
    q_start = np.zeros(robot.n_joints)
    q_start[0:7:2] = 0.9
    q_end = q_start.copy()
    q_start[8:16:2] = 0.9
    q_end[7:] = [-1.57, 0.266, -0.285, 0.451, -0.173, -0.021, 0.322, 0.051, 0.027]
    return q_start, q_end


def _chain_points(robot: SnakeRobot, frames: np.ndarray) -> np.ndarray:
    """Joint positions along the body, tail to head tip: (..., k, 3) from frames (..., L, 4, 4)."""
    names = robot.link_names
    idx = [i for i, n in enumerate(names) if n.startswith("link_")] + [names.index(robot.parts.head_tip)]
    return np.take(frames, idx, axis=-3)[..., :3, 3]


def _draw_snapshots(ax, robot: SnakeRobot, qs: np.ndarray, base: BasePlacement, color: str, k: int = 6):
    frames = robot.frames_many(qs, base)
    pts = _chain_points(robot, frames)
    n_base = robot.body.link_index(robot.parts.base_end)  # joint points 0 .. n_base belong to the base
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
    # box corners below the ground, over the whole motion
    below = clear < -coll.GROUND_TOLERANCE
    if below.any():
        B = (frames[:, :, None] @ robot.box_origins[None])[:, :, 0]
        half = 0.5 * robot.box_sizes
        signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], float)
        ti, li = np.nonzero(below)
        corners = B[ti, li, None, :3, 3] + np.einsum("nij,nkj->nki", B[ti, li, :3, :3], signs[None] * half[li, None])
        corners = corners.reshape(-1, 3)
        corners = corners[corners[:, 2] < 0]
        ax.scatter(corners[:, 0], corners[:, 1], corners[:, 2], s=2, color="k", alpha=0.3,
                   label="box corners in the ground")
    return picks


def _ground(ax, xlim, ylim):
    X, Y = np.meshgrid(np.linspace(*xlim, 2), np.linspace(*ylim, 2))
    ax.plot_surface(X, Y, np.zeros_like(X), color=_GROUND, alpha=0.15, linewidth=0)


def plot_interpolation_comparison(robot: SnakeRobot | None = None, q_start=None, q_end=None, path="fig11_13.png", *,
                                  base: BasePlacement | None = None, n: int = 200) -> Path:
    """Fig. 11 vs Fig. 13: the same start and end, interpolated in joint space (left) and by Eqs. 41-44
    (middle); right: the lowest point of the neck's and head's collision boxes over the motion (m)."""
    robot = SnakeRobot.default() if robot is None else robot
    if q_start is None or q_end is None:
        q_start, q_end = lift_head_motion(robot)
    base = BasePlacement() if base is None else base
    s = np.linspace(0.0, 1.0, n)
    q_joint = q_start + (q_end - q_start) * s[:, None]
    res = cartesian_interpolation(robot, q_start, q_end, n, base, full_output=True)
    q_cart = res.q
    links = robot.lifted_links
    cj = coll.ground_clearance(robot, q_joint, base)[:, links].min(axis=1)
    cc = coll.ground_clearance(robot, q_cart, base)[:, links].min(axis=1)
    plt = _plt()
    fig = plt.figure(figsize=(17, 6.2))
    allp = _chain_points(robot, robot.frames_many(np.vstack([q_joint, q_cart]), base)).reshape(-1, 3)
    lo, hi = allp.min(axis=0) - 0.05, allp.max(axis=0) + 0.05
    span = (hi - lo).max()
    for k, (qs, color, title) in enumerate([
            (q_joint, _JOINT_SPACE, f"Fig. 11: joint-space interpolation\nlowest box point {1000 * cj.min():.0f} mm"),
            (q_cart, _CARTESIAN, f"Fig. 13: Cartesian interpolation (Eqs. 41-44)\nlowest box point "
                                 f"{1000 * cc.min():.1f} mm, joints stray <= {1000 * res.max_deviation:.0f} mm")]):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d", computed_zorder=False)
        _ground(ax, (lo[0], lo[0] + span), (lo[1], lo[1] + span))
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
    ax.axhline(0, color=_GROUND, lw=1.5)
    ax.fill_between(s, 1000 * np.minimum(cj, 0), 0, color=_JOINT_SPACE, alpha=0.2, label="in the ground")
    ax.set_xlabel("interpolation parameter $t_j$ (Eq. 41)")
    ax.set_ylabel("lowest point of neck and head boxes (mm)")
    ax.set_title("clearance of the neck and head above the ground", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9)
    fig.tight_layout()
    return _save(fig, path)


def plot_momenta(t, P, L, path="fig18_19_momenta.png", *, other=None, labels=("planned", "simulated"),
                 title: str = "", figures: tuple[int, int] = (18, 19)) -> Path:
    """Figs. 18-19: angular momentum L (kg m^2/s, top row) and linear momentum P (kg m/s, bottom row) about the
    world origin, x, y, z components against time t (s). ``other`` = (t2, P2, L2) overlays a second run.
    ``figures``: the paper's figure numbers of the two rows in the panel titles ((23, 24) for the hole)."""
    t = np.asarray(t, float)
    P, L = np.asarray(P, float), np.asarray(L, float)
    plt = _plt()
    fig, axes = plt.subplots(2, 3, figsize=(13, 6), sharex=True)
    for row, (X, name, unit, fig_no) in enumerate([(L, "L", "kg m$^2$/s", figures[0]), (P, "P", "kg m/s", figures[1])]):
        for c, comp in enumerate("xyz"):
            ax = axes[row, c]
            ax.plot(t, X[:, c], color=_CARTESIAN, lw=1.8, label=labels[0])
            if other is not None:
                t2, P2, L2 = other
                Y = np.asarray(L2 if row == 0 else P2, float)
                ax.plot(t2, Y[:, c], color=_JOINT_SPACE, lw=1.0, ls="--", label=labels[1])
            ax.set_title((f"Fig. {fig_no}({'abc'[c]}): " if fig_no else "") + f"${name}_{comp}$", fontsize=10)
            ax.set_ylabel(f"${name}_{comp}$ ({unit})")
            ax.grid(alpha=0.3)
            ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
            if row == 1:
                ax.set_xlabel("t (s)")
    axes[0, 0].legend(fontsize=9)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def plot_zmp(robot: SnakeRobot, t, q, path="fig20_zmp.png", *, base: BasePlacement | None = None,
             contact: str = "endpoints", title: str = "") -> Path:
    """Fig. 20: the ZMP along the motion (Eqs. 39-40) and the CoM's ground projection, inside the support
    polygon (Eq. 24) of the last configuration (and of the first, if the base moves), over the base's footprint."""
    base = BasePlacement() if base is None else base
    res = st.dynamic_stability(robot, t, q, base, contact=contact)
    q = np.asarray(q, float)
    plt = _plt()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 5.6), gridspec_kw=dict(width_ratios=[1.2, 1]))
    # the base's boxes seen from above
    frames = robot.frames(q[-1], base)
    first, end = 0, robot.body.link_index(robot.parts.base_end)
    for li in range(first, end):
        if not np.all(robot.box_sizes[li] > 0):
            continue
        B = frames[li] @ robot.box_origins[li]
        h = robot.box_sizes[li] / 2
        corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * h[:2]
        xy = corners @ B[:2, :2].T + B[:2, 3]
        ax.fill(xy[:, 0], xy[:, 1], color="0.85", ec="0.6", lw=0.8, zorder=1)
    polys = [(q[-1], "support polygon (end)", "-")]
    if not np.allclose(q[0, robot.parts.base], q[-1, robot.parts.base]):
        polys.insert(0, (q[0], "support polygon (start)", ":"))
    for qq, label, ls in polys:
        poly = st.support_polygon(robot, qq, base, contact=contact)
        closed = np.vstack([poly, poly[:1]])
        ax.plot(closed[:, 0], closed[:, 1], ls, color="k", lw=1.6, label=label, zorder=2)
    sc = ax.scatter(res.zmp[:, 0], res.zmp[:, 1], c=t, cmap="viridis", s=6, label="ZMP", zorder=3)
    ax.plot(res.com[:, 0], res.com[:, 1], "--", color="k", lw=1.0, label="CoM ground projection", zorder=4)
    ax.plot(*res.zmp[res.argmin], "x", color=_JOINT_SPACE, ms=10, mew=2, label="smallest margin", zorder=5)
    fig.colorbar(sc, ax=ax, label="t (s)", shrink=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Fig. 20: ZMP (Eqs. 39-40, $p_z$ = 0) in the support polygon (Eq. 24)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax2.plot(t, 1000 * res.margin, color=_CARTESIAN, lw=1.8, label="ZMP margin")
    static = np.array([st.static_margin(robot, q[i], base, contact=contact) for i in (0, -1)])
    ax2.plot(np.asarray(t)[[0, -1]], 1000 * static, "o", color="k", label="static margin (CoM), ends")
    ax2.axhline(0, color=_JOINT_SPACE, lw=1)
    ax2.set_xlabel("t (s)")
    ax2.set_ylabel("distance to the polygon's edge (mm, > 0 inside)")
    verdict = "stable" if res.stable else "NOT stable"
    ax2.set_title(f"dynamic stability: {verdict}, min margin {1000 * res.min_margin:.1f} mm", fontsize=10)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=9)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def lift_head_figures(out_dir: str | os.PathLike = ".", robot: SnakeRobot | None = None, *,
                      duration: float = 5.0) -> list[Path]:
    """Write the three figures for the lift-the-head motions to ``out_dir``: Figs. 11/13 for
    :func:`lift_head_motion`; momenta and ZMP for :func:`stable_lift_motion` timed by
    :func:`~snakehead.trajectory.cartesian_trajectory` over ``duration`` s at 2 ms."""
    robot = SnakeRobot.default() if robot is None else robot
    out = Path(out_dir)
    paths = [plot_interpolation_comparison(robot, *lift_head_motion(robot), out / "fig11_13_interpolation.png")]
    q0, q1 = stable_lift_motion(robot)
    traj = cartesian_trajectory(robot, q0, q1, duration)
    P, L = st.momenta(robot, traj.t, traj.q)
    title = f"lifting the head by Eqs. 41-44 in {duration:g} s (2 ms samples)"
    paths.append(plot_momenta(traj.t, P, L, out / "fig18_19_momenta.png", title=title))
    paths.append(plot_zmp(robot, traj.t, traj.q, out / "fig20_zmp.png", title=title))
    return paths
