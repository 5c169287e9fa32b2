"""What the figure modules share: the figure factory, the colours, 3-D axes with equal scales, and :func:`save`.

Figures are made with :class:`matplotlib.figure.Figure` directly, not with pyplot: no backend is chosen or needed
(a script, a server thread and a notebook all work), and nothing is left open in pyplot's registry, so there is
nothing to close. In a notebook a returned figure shows itself; anywhere, :func:`save` writes it.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Union

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
#: zlib's level for the PNGs save() draws once: figures' PNGs come out as small as at the default 6 (within 1 %),
#: in half the time.
PNG_COMPRESS_LEVEL = 3

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
    """A matplotlib Figure outside pyplot (``kwargs`` go to :class:`~matplotlib.figure.Figure`) on an Agg canvas
    from the start, so that a layout (``tight_layout``) and the drawing in :func:`save` share one renderer and its
    cache of text sizes (text layout is most of a figure's drawing time)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = Figure(**{"dpi": DEFAULT_DPI, **kwargs})  # save()'s: one renderer for the layout and the drawing
    FigureCanvasAgg(figure)
    return figure


def save(figure: Figure | BodyAnimation, path: PathLike, *, dpi: float | None = None) -> Path:
    """Write a figure (PNG, PDF, SVG, ... by the suffix) or an animation (``.gif``) to ``path``; returns the path.

    The file appears whole or not at all: it is written under a temporary name in the same folder and renamed
    (``snakehead._files.atomic_open``). Missing parent folders are created. Figures are cropped to what is
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
    dpi = DEFAULT_DPI if dpi is None else dpi
    with atomic_open(path, "wb") as f:
        if suffix != "png" or not _write_png_drawn_once(figure, f, dpi):
            figure.savefig(f, format=suffix, dpi=dpi, bbox_inches="tight")
    return path


def _write_png_drawn_once(figure: Figure, file: IO[bytes], dpi: float) -> bool:
    """Write the figure as a PNG cropped to what is drawn with matplotlib's padding around it (as
    ``savefig(bbox_inches="tight")``), drawing it once. ``savefig`` draws a figure twice for a tight box -- once to
    measure every artist's extent, once at the cropped size, where every text is measured again -- and that was
    most of the time of the pipeline's figures. Here the figure is drawn once on its canvas and cut by
    :func:`crop_and_write_png`. False (nothing written) when the drawing touches the canvas's edge."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    old_dpi = figure.dpi
    figure.set_dpi(dpi)
    try:
        canvas = figure.canvas if isinstance(figure.canvas, FigureCanvasAgg) else FigureCanvasAgg(figure)
        canvas.draw()
        return crop_and_write_png(figure, np.asarray(canvas.buffer_rgba()), file, dpi)
    finally:
        figure.set_dpi(old_dpi)


def crop_and_write_png(figure: Figure, drawn: np.ndarray, file: IO[bytes], dpi: float) -> bool:
    """Write the figure's drawing ``drawn`` (RGBA rows from the top) as a PNG cut to the pixels that differ from the
    figure's background (a few pixels tighter than savefig's tight box, which counts a text's empty ascent) with
    matplotlib's padding around them (the figure's colour where the padding reaches beyond the canvas, as
    savefig's). False (nothing written) when the drawing touches the canvas's edge: something may reach beyond
    the figure, and only ``savefig`` draws that."""
    import matplotlib as mpl
    from matplotlib.colors import to_rgba

    background = np.round(255 * np.array(to_rgba(figure.get_facecolor()))).astype(np.uint8)
    ink = ink_mask(drawn, background)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    height, width = ink.shape
    if not len(rows) or rows[0] == 0 or cols[0] == 0 or rows[-1] == height - 1 or cols[-1] == width - 1:
        return False
    pad = int(round(mpl.rcParams["savefig.pad_inches"] * dpi))
    out = np.empty((rows[-1] - rows[0] + 1 + 2 * pad, cols[-1] - cols[0] + 1 + 2 * pad, 4), np.uint8)
    out[...] = background  # the padding may reach beyond the canvas: the figure's colour, as savefig's
    top, left = rows[0] - pad, cols[0] - pad
    r0, c0 = max(top, 0), max(left, 0)
    r1, c1 = min(rows[-1] + 1 + pad, height), min(cols[-1] + 1 + pad, width)
    out[r0 - top:r1 - top, c0 - left:c1 - left] = drawn[r0:r1, c0:c1]
    _write_png(file, out, dpi)
    return True


def ink_mask(pixels: np.ndarray, background: np.ndarray) -> np.ndarray:
    """(h, w) bool: the pixels of ``pixels`` (h, w, 4) uint8 whose RGBA differs from ``background`` (4,) uint8 --
    ``(pixels != background).any(axis=2)``, each pixel compared as one 32-bit word (~10x faster on a figure)."""
    if pixels.dtype != np.uint8 or pixels.shape[-1] != 4 or not pixels.flags.c_contiguous:
        return (pixels != background).any(axis=2)
    return pixels.view(np.uint32)[..., 0] != np.ascontiguousarray(background, np.uint8).view(np.uint32)[0]


def _write_png(file: IO[bytes], pixels: np.ndarray, dpi: float) -> None:
    """RGBA pixels (rows from the top) as a PNG with matplotlib's metadata; RGB when opaque (a quarter less to
    compress), at :data:`PNG_COMPRESS_LEVEL`."""
    import matplotlib as mpl
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{mpl.__version__}, https://matplotlib.org/")
    opaque = bool((pixels[..., 3] == 255).all())
    image = Image.fromarray(np.ascontiguousarray(pixels[..., :3]) if opaque else pixels)
    image.save(file, format="png", dpi=(dpi, dpi), pnginfo=info, compress_level=PNG_COMPRESS_LEVEL)


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
