"""How the figures look: the colours of the body's parts and of the scenery, a figure made outside pyplot
(:func:`new_figure`), 3-D axes with equal scales over a box (:func:`setup_axes3d`) with the ground, flat or a slope
(:func:`ground_patch`), and text from the data made safe to show (:func:`literal`).

Figures are made with :class:`matplotlib.figure.Figure` directly, not with pyplot: no backend is chosen or needed
(a script, a server thread and a notebook all work), and nothing is left open in pyplot's registry, so there is
nothing to close. In a notebook a returned figure shows itself; anywhere, :func:`snakehead.viz.save` writes it.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .figure_files import DEFAULT_DPI

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from ..model.placement import GroundFrame

__all__ = ["BASE_COLOR", "NECK_COLOR", "HEAD_COLOR", "SPHERE_COLOR", "WALL_COLOR", "OBSTACLE_COLOR", "GROUND_COLOR",
           "PLANNED_COLOR", "SIMULATED_COLOR", "LINK_COLOR", "literal", "new_figure", "setup_axes3d", "plane_height",
           "ground_patch", "slope_text"]

# The parts of the body, as every figure, the animation and the 3-D viewer draw them.
BASE_COLOR = "#7f8c8d"
NECK_COLOR = "#e67e22"
HEAD_COLOR = "#2e86c1"
# Scenery and data series.
SPHERE_COLOR = "#c0392b"
WALL_COLOR = "#a1887f"
#: Colour of box and mesh obstacles.
OBSTACLE_COLOR = "#8d6e63"
GROUND_COLOR = "#8d6e63"
PLANNED_COLOR = "#1f77b4"
SIMULATED_COLOR = "#c0392b"
LINK_COLOR = "#333333"


def literal(text: str) -> str:
    """``text`` from the data (a scene's, a target's, a phase's or a frame's name; a message) made safe to show in
    any matplotlib text -- titles, legends, annotations, axis labels -- as it is: matplotlib reads text between two
    ``$`` as math (mathtext) and fails to draw a figure whose math is not valid (``$\\frac{$``). Every ``$`` is
    escaped, so no math is parsed and the text is drawn literally (backslashes included). Every figure of
    :mod:`snakehead.viz` passes names through it; text that is meant as math (``cm$^2$``) is never put in the same
    string as a name. Titles given by the caller are drawn as given."""
    return str(text).replace("$", r"\$")


def new_figure(**kwargs: Any) -> Figure:
    """A matplotlib Figure outside pyplot (``kwargs`` go to :class:`~matplotlib.figure.Figure`) on an Agg canvas
    from the start, so that a layout (``tight_layout``) and the drawing in :func:`.figure_files.save` share one
    renderer and its cache of text sizes (text layout is most of a figure's drawing time)."""
    figure = Figure(**{"dpi": DEFAULT_DPI, **kwargs})  # save()'s: one renderer for the layout and the drawing
    FigureCanvasAgg(figure)
    return figure


def setup_axes3d(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, elev: float, azim: float, *, labels: bool = True,
                 zoom: float = 1.0, ground: bool = True, plane: GroundFrame | None = None) -> None:
    """Equal scales on x, y, z (the body is not distorted) over the box [lo, hi] (m, world), the ground shaded: the
    plane z = 0, or on a slope the plane of the ground frame ``plane`` (a plan's ``base.ground``) over the box's x
    and y (the z limits widened to hold it)."""
    lo = np.array(lo, float)
    hi = np.array(hi, float)
    patch = ground_patch(plane, lo, hi) if plane is not None and not plane.is_world else None
    if patch is not None:
        lo[2], hi[2] = min(lo[2], float(patch[2].min())), max(hi[2], float(patch[2].max()))
    else:
        lo[2] = min(lo[2], 0.0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo), zoom=zoom)
    ax.view_init(elev=elev, azim=azim)
    if labels:
        ax.set_xlabel("x (m)", fontsize=8, labelpad=-2)
        ax.set_ylabel("y (m)", fontsize=8, labelpad=-2)
        ax.set_zlabel("z (m)", fontsize=8, labelpad=-2)
    ax.tick_params(labelsize=6, pad=-2)
    if ground and patch is not None:
        ax.plot_surface(*patch, color=GROUND_COLOR, alpha=0.18, linewidth=0, zorder=0)
    elif ground:
        X, Y = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
        ax.plot_surface(X, Y, np.zeros_like(X), color=GROUND_COLOR, alpha=0.12, linewidth=0, zorder=0)


def plane_height(plane: GroundFrame, x: npt.ArrayLike, y: npt.ArrayLike) -> np.ndarray:
    """The world z (m) of the ground frame's plane (its z = 0) above the world points (x, y)."""
    R, o = np.reshape(plane.rotation, (3, 3)), np.array(plane.origin)
    n = R[:, 2]  # the plane's upward normal
    x, y = np.asarray(x, float), np.asarray(y, float)
    return o[2] - (n[0] * (x - o[0]) + n[1] * (y - o[1])) / n[2]


def ground_patch(plane: GroundFrame, lo: npt.ArrayLike, hi: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray,
                                                                                   np.ndarray]:
    """The ground plane of ``plane`` over the world's box [lo, hi] (3,) m in x and y, as ``plot_surface`` takes it:
    the grids X, Y, Z (2, 2) m of its corners (Z = 0 on flat ground, the plane's height on a slope)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    X, Y = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
    return X, Y, (np.zeros_like(X) if plane.is_world else plane_height(plane, X, Y))


def slope_text(plane: GroundFrame | None) -> str:
    """How a figure names the ground: "" on flat ground, "5.0° slope" on a slope (its angle to the horizontal)."""
    return "" if plane is None or plane.is_world else f"{plane.slope_deg:.1f}\N{DEGREE SIGN} slope"
