"""Figures of the body's dynamics (paper Section 3.1, Figs. 18-20 and 23-25): momenta and the zero-moment point.

* :func:`plot_momenta` -- Figs. 18-19 (23-24): angular and linear momentum about the world origin over time,
  planned and, optionally, simulated.
* :func:`plot_zmp` -- Figs. 20 (25): the ZMP (Eqs. 39-40) and the centre of mass's ground projection inside the
  support polygon (Eq. 24), over the base's footprint, and the ZMP's margin over time.

Every function returns a :class:`matplotlib.figure.Figure`; write it with :func:`snakehead.viz.save`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence, Union

import numpy as np
import numpy.typing as npt
from matplotlib.figure import Figure

from .._errors import InputError
from ..dynamics import stability as st
from ..model.robot import BasePlacement, SnakeRobot
from ..sim.compare import zmp_margins
from .figure_geometry import shape_footprints
from .figure_style import PLANNED_COLOR, SIMULATED_COLOR, new_figure, slope_text

if TYPE_CHECKING:
    from ..sim.tracking import SimResult

__all__ = ["Momenta", "plot_momenta", "MOMENTA_LAYOUT", "ZMP_LAYOUT", "distinct_support_polygons", "plot_zmp"]

#: A second run to draw beside the planned one: a simulation result (``t``, ``P``, ``L``) or (t, P, L) arrays.
Momenta = Union["SimResult", tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike]]


def _as_momenta(run: Momenta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if isinstance(run, tuple):
        t, P, L = run
    else:
        t, P, L = run.t, run.P, run.L
    return np.asarray(t, float), np.asarray(P, float), np.asarray(L, float)


def plot_momenta(t: npt.ArrayLike, P: npt.ArrayLike, L: npt.ArrayLike, *, simulated: Momenta | None = None,
                 labels: tuple[str, str] = ("planned", "simulated (MuJoCo)"),
                 figures: Sequence[int | None] = (18, 19), title: str = "") -> Figure:
    """Figs. 18-19: angular momentum L (kg m^2/s, top row) and linear momentum P (kg m/s, bottom row) about the
    world origin, x, y, z components against time t (T,) s; P, L (T, 3). ``simulated`` overlays a second run
    (a :class:`~snakehead.sim.SimResult` or (t, P, L)). ``figures``: the paper's figure numbers of the two rows,
    for the panel titles ((23, 24) for the hole; None for none)."""
    t = np.asarray(t, float)
    P, L = np.asarray(P, float), np.asarray(L, float)
    if P.shape != (len(t), 3) or L.shape != (len(t), 3):
        raise InputError(f"P and L must be (T, 3) arrays matching t ({len(t)} samples), got {P.shape} and {L.shape}")
    other = None if simulated is None else _as_momenta(simulated)
    fig = new_figure(figsize=(13, 6))
    axes = fig.subplots(2, 3, sharex=True)
    rows = [(L, "L", "kg m$^2$/s", figures[0]), (P, "P", "kg m/s", figures[1])]
    for row, (X, name, unit, fig_no) in enumerate(rows):
        for c, comp in enumerate("xyz"):
            ax = axes[row, c]
            ax.plot(t, X[:, c], color=PLANNED_COLOR, lw=1.8, label=labels[0])
            if other is not None:
                t2, P2, L2 = other
                Y = L2 if row == 0 else P2
                ax.plot(t2, Y[:, c], color=SIMULATED_COLOR, lw=1.0, ls="--", label=labels[1])
            ax.set_title((f"Fig. {fig_no}({'abc'[c]}): " if fig_no else "") + f"${name}_{comp}$", fontsize=10)
            ax.set_ylabel(f"${name}_{comp}$ ({unit})")
            ax.grid(alpha=0.3)
            ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
            if row == 1:
                ax.set_xlabel("t (s)")
    axes[0, 0].legend(fontsize=9)
    if title:
        fig.suptitle(title)
    fig.subplots_adjust(**MOMENTA_LAYOUT, top=0.89 if title else 0.943)
    return fig


# The figures' margins and gaps (fractions of the figure, as subplots_adjust takes them): what tight_layout chose on
# the paper's scenes, widened to the widest seen, set at once -- tight_layout measures every tick label by drawing
# the figure, a third of the figure's time. Tick labels of any magnitude fit (the momenta's in scientific notation
# have at most 5 characters; tests/viz/test_viz.py checks that no text leaves the figure or overlaps another panel).
MOMENTA_LAYOUT = dict(left=0.067, right=0.9885, bottom=0.097, wspace=0.32, hspace=0.19)
ZMP_LAYOUT = dict(left=0.052, right=0.9885, bottom=0.108, top=0.881, wspace=0.13)


def _base_footprint(ax: Any, robot: SnakeRobot, frames: np.ndarray) -> None:
    """The base's collision shapes seen from above (grey)."""
    for xy in shape_footprints(robot, frames, robot.base_links):
        ax.fill(xy[:, 0], xy[:, 1], color="0.85", ec="0.6", lw=0.8, zorder=1)


def distinct_support_polygons(robot: SnakeRobot, q: np.ndarray, base: BasePlacement, contact: str,
                              samples: int = 400) -> list[np.ndarray]:
    """The distinct support polygons (k, 2) m along a trajectory q (T, n), checked at about ``samples`` samples
    (few: the base keeps its shape), in the order they first occur; two are the same when their vertices agree
    to a micrometre. Samples without a support polygon (no link on the ground) are left out."""
    step = max(1, len(q) // samples)
    vertices, count = st.support_polygons(robot, q[::step], base, contact=contact)  # one batch, not one per sample
    seen: dict[bytes, np.ndarray] = {}
    for poly in (v[:c] for v, c in zip(vertices, count) if c > 0):
        seen.setdefault((np.round(poly, 6) + 0.0).tobytes() + bytes([len(poly)]), poly)  # dicts keep insertion order
    return list(seen.values())


def plot_zmp(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike, *, base: BasePlacement | None = None,
             stability: st.DynamicStability | None = None, contact: str = "ground",
             simulated: SimResult | None = None, figure: int | None = 20, title: str = "") -> Figure:
    """Fig. 20 (25): left, the ZMP along the motion t (T,) s, q (T, n) rad (Eqs. 39-40, coloured by time) and the
    centre of mass's ground projection over the distinct support polygons of ``contact`` (the model the motion
    was checked with), the base's footprint in grey, and the simulated ZMP (centre of pressure of MuJoCo's contact
    forces) of ``simulated``; right, the signed distance of each to the polygon's edge over time (mm, > 0
    inside). ``stability``: the motion's :func:`~snakehead.dynamics.dynamic_stability` if already computed (a
    plan's ``stability``)."""
    base = BasePlacement() if base is None else base
    t = np.asarray(t, float)
    q = np.asarray(q, float)
    dyn = st.dynamic_stability(robot, t, q, base, contact=contact) if stability is None else stability
    fig = new_figure(figsize=(13, 5.4))
    ax, ax2 = fig.subplots(1, 2, gridspec_kw=dict(width_ratios=[1.15, 1]))
    _base_footprint(ax, robot, robot.frames(q[-1], base))
    step = max(1, len(q) // 400)
    for k, poly in enumerate(distinct_support_polygons(robot, q, base, contact)[:6]):
        closed = np.vstack([poly, poly[:1]])
        ax.plot(closed[:, 0], closed[:, 1], "-", color="k", lw=1.5 if k == 0 else 0.8,
                label=f"support polygon ({contact} contact)" if k == 0 else None, zorder=2)
    sc = ax.scatter(dyn.zmp[::step, 0], dyn.zmp[::step, 1], c=t[::step], cmap="viridis", s=5, zorder=3,
                    label="ZMP planned")
    ax.plot(dyn.com[:, 0], dyn.com[:, 1], "--", color="k", lw=1.0, label="CoM ground projection", zorder=4)
    ax.plot(*dyn.zmp[dyn.argmin], "x", color=SIMULATED_COLOR, ms=10, mew=2, label="smallest planned margin",
            zorder=6)
    margins_sim = None
    if simulated is not None:
        z = simulated.zmp
        ax.plot(z[:, 0], z[:, 1], "-", color=SIMULATED_COLOR, lw=0.7, alpha=0.8, label="ZMP simulated (MuJoCo)",
                zorder=5)
        margins_sim = zmp_margins(robot, simulated, t, q, base, contact=contact)
    fig.colorbar(sc, ax=ax, label="t (s)", shrink=0.8)
    ax.set_aspect("equal", adjustable="datalim")
    slope = slope_text(base.ground)  # on a slope: x and y of the ground frame, in the sloping plane
    ax.set_xlabel("x in the ground plane (m)" if slope else "x (m)")
    ax.set_ylabel("y in the ground plane (m)" if slope else "y (m)")
    ax.set_title((f"Fig. {figure}: " if figure else "") + "ZMP (Eqs. 39-40) in the support polygon (Eq. 24)"
                 + (f", on a {slope}" if slope else ""), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax2.plot(t, 1000 * dyn.margin, color=PLANNED_COLOR, lw=1.8, label="planned ZMP")
    if simulated is not None and margins_sim is not None:
        ax2.plot(simulated.t, 1000 * margins_sim, color=SIMULATED_COLOR, lw=0.8,
                 label=f"simulated ZMP ({contact} polygon)")
    ax2.axhline(0, color="k", lw=1)
    ax2.set_xlabel("t (s)")
    ax2.set_ylabel("distance to the polygon's edge (mm, > 0 inside)")
    verdict = "inside" if dyn.stable else "NOT inside"
    ax2.set_title(f"planned ZMP {verdict} throughout; min margin {1000 * dyn.min_margin:.1f} mm", fontsize=10)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=9)
    fig.suptitle(title or "zero-moment point", fontsize=11)
    fig.subplots_adjust(**ZMP_LAYOUT)
    return fig
