"""Figures of the dynamics check, after the paper's Figs. 18-20 (23-25): planned vs simulated momenta, ZMP.

matplotlib with the Agg backend (files only, no display). Each function saves one PNG and returns its path.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..model.robot import BasePlacement, SnakeRobot
from ..sim.tracking import SimResult, check_trajectory


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_momentum(planned_t, planned, result_t, simulated, which: str, path: str | os.PathLike) -> Path:
    """Three stacked panels (x, y, z components) of a planned and a simulated momentum, like Figs. 18-19.

    planned_t (T,) s, planned (T, 3); result_t (N,) s, simulated (N, 3); ``which``: "angular" (kg m^2/s) or
    "linear" (kg m/s).
    """
    if which not in ("angular", "linear"):
        raise ValueError(f"which must be 'angular' or 'linear', got {which!r}")
    planned = np.asarray(planned, float)
    simulated = np.asarray(simulated, float)
    if planned.shape != (len(planned_t), 3) or simulated.shape != (len(result_t), 3):
        raise ValueError("momenta must be (T, 3) arrays matching their times")
    unit = "kg·m²/s" if which == "angular" else "kg·m/s"
    sym = "L" if which == "angular" else "P"
    plt = _plt()
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for i, ax in enumerate(axes):
        ax.plot(planned_t, planned[:, i], "-", lw=2.0, color="tab:blue", label="planned")
        ax.plot(result_t, simulated[:, i], "--", lw=1.2, color="tab:red", label="simulated (MuJoCo)")
        ax.set_ylabel(f"{sym}{'xyz'[i]} ({unit})")
        ax.grid(alpha=0.3)
        ax.set_title(f"({'abc'[i]}) {'XYZ'[i]} component", fontsize=9, loc="left")
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle("Angular momentum about the world origin" if which == "angular" else "Linear momentum")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_zmp(polygon, result: SimResult, path: str | os.PathLike, planned_zmp=None, com=None) -> Path:
    """The simulated ZMP over the support polygon, like Fig. 20: polygon (k, 2) m, counter-clockwise.

    ``planned_zmp`` (T, 2) and ``com`` (T, 2 or 3) are drawn when given; the contact points of the last tick too.
    """
    polygon = np.asarray(polygon, float)
    if polygon.ndim != 2 or polygon.shape[1] != 2:
        raise ValueError(f"polygon must be (k, 2), got {polygon.shape}")
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 6))
    closed = np.vstack([polygon, polygon[:1]])
    ax.fill(closed[:, 0], closed[:, 1], color="tab:green", alpha=0.15, label="support polygon (plan)")
    ax.plot(closed[:, 0], closed[:, 1], "-", color="tab:green", lw=1.5)
    if planned_zmp is not None:
        pz = np.asarray(planned_zmp, float)
        ax.plot(pz[:, 0], pz[:, 1], "-", color="tab:blue", lw=2.0, label="ZMP planned (Eqs. 39-40)")
    z = result.zmp
    ax.plot(z[:, 0], z[:, 1], "-", color="tab:red", lw=1.0, label="ZMP simulated (contact forces)")
    ax.plot(z[0, 0], z[0, 1], "o", color="tab:red", ms=5)
    ax.plot(z[-1, 0], z[-1, 1], "s", color="tab:red", ms=5)
    if com is not None:
        c = np.asarray(com, float)
        ax.plot(c[:, 0], c[:, 1], ":", color="k", lw=1.0, label="CoM projection (sim)")
    cp = result.contact_points[-1]
    if len(cp):
        ax.plot(cp[:, 0], cp[:, 1], ".", color="gray", ms=4, label="contact points (last tick)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title("Zero-moment point on the ground")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_dynamics_check(robot: SnakeRobot, planned_t, planned_q, result: SimResult, out_dir: str | os.PathLike,
                        base: BasePlacement | None = None, prefix: str = "sim") -> list[Path]:
    """All three figures of a dynamics check into ``out_dir``: angular and linear momentum, ZMP.

    Planned momenta and ZMP from :mod:`snakehead.stability`; the polygon is the planned support polygon
    (footprint contact model) at the end of the plan. Returns the PNG paths.
    """
    from ..dynamics import stability

    planned_t, planned_q = check_trajectory(robot, planned_t, planned_q)
    base = result.base if base is None else base
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    P, L = stability.momenta(robot, planned_t, planned_q, base)
    zp = stability.zmp(robot, planned_t, planned_q, base)
    poly = stability.support_polygon(robot, planned_q[-1], base, contact="footprint")
    return [
        plot_momentum(planned_t, L, result.t, result.L, "angular", out / f"{prefix}_angular_momentum.png"),
        plot_momentum(planned_t, P, result.t, result.P, "linear", out / f"{prefix}_linear_momentum.png"),
        plot_zmp(poly, result, out / f"{prefix}_zmp.png", planned_zmp=zp, com=result.com),
    ]
