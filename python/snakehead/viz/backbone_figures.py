"""Figures of the backbone curves and the links that discretise them (paper Figs. 2, 3 and 14).

Every function returns a :class:`matplotlib.figure.Figure`; write it with :func:`snakehead.viz.save`. Lengths are
in m, world frame (z up).

* :func:`plot_arc_discretisation` -- Figs. 2-3: the base's plane arc, its discretised links (Eq. 9 and
  exact chords) and the support polygon, top view.
* :func:`plot_initial_configuration` -- Fig. 14: the base arc and the neck-and-head Bezier with the links
  of the initial configuration, top view and 3-D.
* :func:`plot_area_vs_angle` -- the support polygon's area against the central angle, with Eq. 2 and
  the optimum of :func:`snakehead.backbone.optimize_base_arc`.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Sequence

import numpy as np
import numpy.typing as npt
from matplotlib.figure import Figure

from .. import backbone as bb
from ..dynamics import stability
from ..model.robot import BasePlacement, SnakeRobot
from .figure_geometry import body_points
from .figure_style import LINK_COLOR, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_arc_discretisation", "plot_initial_configuration", "plot_area_vs_angle"]

_BC = "#1f77b4"  # backbone curves
_UP = "#d62728"  # the up curve


def _body_points(robot: SnakeRobot, q: npt.ArrayLike, base: BasePlacement | None) -> tuple[np.ndarray, np.ndarray]:
    """(points along the body: tail end, every joint, head tip (n+2, 3); indices of the joints in it)."""
    return body_points(robot, robot.frames(q, base)), np.arange(1, robot.n_joints + 1)


def _draw_links_2d(ax: Axes, P: np.ndarray, joints: np.ndarray, kinds: Sequence[str], label: str,
                   color: str = LINK_COLOR, lw: float = 3.0) -> None:
    ax.plot(P[:, 0], P[:, 1], "-", color=color, lw=lw, alpha=0.75, label=label, solid_capstyle="round")
    yaw = [j for j, k in zip(joints, kinds) if k == "yaw"]
    pitch = [j for j, k in zip(joints, kinds) if k == "pitch"]
    ax.plot(P[yaw, 0], P[yaw, 1], "o", ms=6, mfc="white", mec=color, mew=1.5)
    ax.plot(P[pitch, 0], P[pitch, 1], "s", ms=4, color=color)


def plot_arc_discretisation(robot: SnakeRobot | None = None, central_angle: float = math.pi) -> Figure:
    """Figs. 2-3: the base arc (central angle in rad) and its discretisations, top view.

    Left: Eq. 9 (``"arclength"``): links as pieces of the arc, the body leaves along the arc's end tangent.
    Right: exact chords: the tail end, yaw joints (circles) and P0 on the arc; pitch joints (squares) on the
    chords. Each panel shows the support polygon (Eq. 24, ``stability.support_polygon``) and Eq. 2's area.
    """
    robot = SnakeRobot.default() if robot is None else robot
    l = robot.base_length
    nb = robot.parts.base.stop
    fig = new_figure(figsize=(11, 5.2))
    axes = fig.subplots(1, 2)
    for ax, chords, title in zip(axes, ("arclength", "exact"), ("Eq. 9: links as arc pieces", "exact chords")):
        q = np.zeros(robot.n_joints)
        q[robot.parts.base] = bb.arc_joint_angles(l, central_angle, robot, chords=chords)
        arc = bb.base_arc(robot, central_angle, chords=chords)
        A = arc.point(np.linspace(0, arc.length, 300))
        ax.plot(A[:, 0], A[:, 1], "-", color=_BC, lw=1.5, label="bc (plane arc)")
        ax.plot(*arc.center, "+", color=_BC, ms=8)
        poly = stability.support_polygon(robot, q)
        closed = np.vstack([poly, poly[:1]])
        ax.fill(closed[:, 0], closed[:, 1], color="#2ca02c", alpha=0.15, label="sp (support polygon)")
        ax.plot(closed[:, 0], closed[:, 1], "--", color="#2ca02c", lw=1)
        P, joints = _body_points(robot, q, None)
        k0 = nb + 1  # points up to P0: tail end, joints 1..nb, joint nb+1 at P0
        _draw_links_2d(ax, P[:k0 + 1], joints[:nb + 1], robot.joint_kinds[:nb + 1], "base links")
        ax.plot(*P[k0, :2], "*", ms=12, color="k", label="P0")
        ax.set_title(f"{title}\n theta = {math.degrees(central_angle):.1f} deg, r = {arc.radius * 100:.1f} cm: "
                     f"area {bb.polygon_area(poly) * 1e4:.0f} cm$^2$ (Eq. 2: "
                     f"{bb.arc_segment_area(l, central_angle) * 1e4:.0f} cm$^2$)", fontsize=10)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)
    fig.tight_layout()
    return fig


def plot_initial_configuration(backbone: bb.InitialBackbone | None = None,
                               robot: SnakeRobot | None = None) -> Figure:
    """Fig. 14: the initial configuration of Section 3.3 (1) -- the base arc ("bc of base part"), the
    neck-and-head Bezier ("bc of up part") with its control points, the links, the support polygon and the
    centre of mass -- in a top view (left) and in 3-D (right)."""
    robot = SnakeRobot.default() if robot is None else robot
    ib = bb.initial_backbone(robot) if backbone is None else backbone
    A = ib.arc.point(np.linspace(0, ib.arc.length, 300))
    U = np.array([ib.up_curve.point(t) for t in np.linspace(0, 1, 300)])
    P, joints = _body_points(robot, ib.q, ib.base)
    poly = stability.support_polygon(robot, ib.q, ib.base)
    com = stability.center_of_mass(robot, ib.q, ib.base)
    C = ib.control_points

    fig = new_figure(figsize=(13, 5.8))
    ax = fig.add_subplot(1, 2, 1)
    closed = np.vstack([poly, poly[:1]])
    ax.fill(closed[:, 0], closed[:, 1], color="#2ca02c", alpha=0.15, label="support polygon")
    ax.plot(A[:, 0], A[:, 1], "-", color=_BC, lw=1.5, label="bc of base part (arc)")
    ax.plot(U[:, 0], U[:, 1], "-", color=_UP, lw=1.5, label="bc of up part (Bezier, projected)")
    _draw_links_2d(ax, P, joints, robot.joint_kinds, "links")
    margin = stability.static_margin(robot, ib.q, ib.base)
    ax.plot(*com[:2], "X", ms=10, color="m", label=f"CoM (margin {margin * 100:.1f} cm)")
    ax.plot(*P[robot.parts.base.stop + 1, :2], "*", ms=12, color="k", label="P0")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"top view: base arc theta = {math.degrees(ib.central_angle):.1f} deg", fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)

    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    ax3.plot(A[:, 0], A[:, 1], A[:, 2], "-", color=_BC, lw=1.5, label="bc of base part")
    ax3.plot(U[:, 0], U[:, 1], U[:, 2], "-", color=_UP, lw=1.5, label="bc of up part")
    ax3.plot(C[:, 0], C[:, 1], C[:, 2], ":o", color=_UP, ms=4, lw=1, alpha=0.7, label="Bezier control points")
    ax3.plot(P[:, 0], P[:, 1], P[:, 2], "-", color=LINK_COLOR, lw=3, alpha=0.75, label="links")
    ax3.plot(P[1:-1, 0], P[1:-1, 1], P[1:-1, 2], "o", ms=3.5, color=LINK_COLOR)
    ax3.plot(closed[:, 0], closed[:, 1], np.zeros(len(closed)), "--", color="#2ca02c", lw=1)
    ax3.plot([com[0]], [com[1]], [0.0], "X", ms=8, color="m")
    lo = np.minimum(P.min(axis=0), A.min(axis=0))
    hi = np.maximum(P.max(axis=0), U.max(axis=0))
    mid, half = 0.5 * (lo + hi), 0.5 * float((hi - lo).max())
    ax3.set_xlim(mid[0] - half, mid[0] + half)
    ax3.set_ylim(mid[1] - half, mid[1] + half)
    ax3.set_zlim(0.0, 2 * half)
    ax3.set_box_aspect((1, 1, 1))
    ax3.view_init(elev=22, azim=-60)
    ax3.set_xlabel("x (m)")
    ax3.set_ylabel("y (m)")
    ax3.set_zlabel("z (m)")
    ax3.set_title("3-D: head raised on the Bezier, G1 at P0", fontsize=10)
    ax3.legend(loc="upper center", bbox_to_anchor=(0.5, -0.02), ncol=2, fontsize=8)
    fig.tight_layout()
    return fig


def plot_area_vs_angle(optimum: bb.ArcOptimum | None = None, robot: SnakeRobot | None = None) -> Figure:
    """The discretised support polygon's area and the CoM's static margin against the base arc's central
    angle (the optimiser's scan), with Eq. 2's continuous area and both maxima."""
    robot = SnakeRobot.default() if robot is None else robot
    opt = bb.optimize_base_arc(robot) if optimum is None else optimum
    l = robot.base_length
    g = opt.grid
    th = np.linspace(g[0, 0], g[-1, 0], 400)
    fig = new_figure(figsize=(7.5, 4.5))
    ax = fig.subplots()
    ax.plot(np.degrees(th), bb.arc_segment_area(l, th) * 1e4, "-", color=_BC, label="Eq. 2 (continuous arc)")
    ax.plot(np.degrees(g[:, 0]), g[:, 1] * 1e4, ".-", color="k", label="discretised support polygon")
    ax.plot(math.degrees(opt.eq2_angle), opt.eq2_area * 1e4, "o", color=_BC,
            label=f"Eq. 2 max: 180 deg, {opt.eq2_area * 1e4:.0f} cm$^2$")
    ax.plot(math.degrees(opt.central_angle), opt.area * 1e4, "*", ms=14, color=_UP,
            label=f"optimum: {math.degrees(opt.central_angle):.1f} deg, {opt.area * 1e4:.0f} cm$^2$")
    ax.set_xlabel("central angle theta (deg)")
    ax.set_ylabel("area (cm$^2$)")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(np.degrees(g[:, 0]), g[:, 2] * 100, "--", color="m", label="static margin of the CoM")
    ax2.set_ylabel("static margin (cm)", color="m")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="lower center", fontsize=8)
    ax.set_title(f"base arc (l = {l:.3f} m): area against central angle "
                 f"(joint limits: theta <= {math.degrees(opt.angle_limit):.0f} deg)", fontsize=10)
    fig.tight_layout()
    return fig
