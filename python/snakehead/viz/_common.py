"""What the figure modules share: the figure factory, the colours, 3-D axes with equal scales, and :func:`save`.

Figures are made with :class:`matplotlib.figure.Figure` directly, not with pyplot: no backend is chosen or needed
(a script, a server thread and a notebook all work), and nothing is left open in pyplot's registry, so there is
nothing to close. In a notebook a returned figure shows itself; anywhere, :func:`save` writes it.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import numpy as np
from matplotlib.figure import Figure

from .._files import atomic_open
from .._errors import InputError, InputTypeError

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from .animation import BodyAnimation

# The parts of the body, as every figure, the animation and the 3-D viewer draw them.
BASE_COLOR = "#7f8c8d"
NECK_COLOR = "#e67e22"
HEAD_COLOR = "#2e86c1"
# Scenery and data series.
SPHERE_COLOR = "#c0392b"
WALL_COLOR = "#a1887f"
GROUND_COLOR = "#8d6e63"
PLANNED_COLOR = "#1f77b4"
SIMULATED_COLOR = "#c0392b"
LINK_COLOR = "#333333"

#: Resolution of saved figures (dots per inch) unless save() is told otherwise.
DEFAULT_DPI = 150

PathLike = Union[str, "os.PathLike[str]"]


def literal(text: str) -> str:
    """``text`` from the data (a scene's, a target's, a phase's or a frame's name; a message) made safe to show in
    any matplotlib text -- titles, legends, annotations, axis labels -- as it is: matplotlib reads text between two
    ``$`` as math (mathtext) and fails to draw a figure whose math is not valid (``$\\frac{$``). Every ``$`` is
    escaped, so no math is parsed and the text is drawn literally (backslashes included). Every figure of
    :mod:`snakehead.viz` passes names through it; text that is meant as math (``cm$^2$``) is never put in the same
    string as a name. Titles given by the caller are drawn as given."""
    return str(text).replace("$", r"\$")


def new_figure(**kwargs: Any) -> Figure:
    """A matplotlib Figure outside pyplot (``kwargs`` go to :class:`~matplotlib.figure.Figure`)."""
    return Figure(**kwargs)


def save(figure: Figure | BodyAnimation, path: PathLike, *, dpi: float | None = None) -> Path:
    """Write a figure (PNG, PDF, SVG, ... by the suffix) or an animation (``.gif``) to ``path``; returns the path.

    The file appears whole or not at all: it is written under a temporary name in the same folder and renamed
    (:func:`snakehead._files.atomic_open`). Missing parent folders are created. Figures are cropped to what is
    drawn (``bbox_inches="tight"``) at ``dpi`` (default :data:`DEFAULT_DPI`); an animation has its own size.
    """
    from .animation import BodyAnimation

    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    if isinstance(figure, BodyAnimation):
        if suffix != "gif":
            raise InputError(f"an animation is written as .gif, got {path.name!r}")
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_open(path, "wb") as f:
            figure.write_gif(f)
        return path
    if not isinstance(figure, Figure):
        raise InputTypeError(f"save() takes a matplotlib Figure or a BodyAnimation, got {type(figure).__name__}")
    if not suffix:
        raise InputError(f"the file name {path.name!r} has no suffix to choose the format by (.png, .pdf, .svg, ...)")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_open(path, "wb") as f:
        figure.savefig(f, format=suffix, dpi=DEFAULT_DPI if dpi is None else dpi, bbox_inches="tight")
    return path


def setup_axes3d(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, elev: float, azim: float, *, labels: bool = True,
                 zoom: float = 1.0, ground: bool = True) -> None:
    """Equal scales on x, y, z (the body is not distorted) over the box [lo, hi] (m), the ground (z = 0) shaded."""
    lo = np.array(lo, float)
    hi = np.asarray(hi, float)
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
    if ground:
        X, Y = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
        ax.plot_surface(X, Y, np.zeros_like(X), color=GROUND_COLOR, alpha=0.12, linewidth=0, zorder=0)
