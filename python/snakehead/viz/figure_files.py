"""Figures and animations written to files: :func:`save` (a figure by its suffix, an animation as a GIF; the file
appears whole or not at all), and the PNG writer that draws a figure once and crops it as ``savefig`` would
(:func:`crop_and_write_png`)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import IO, TYPE_CHECKING, Union

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from PIL import Image, PngImagePlugin

from .._errors import InputError, InputTypeError
from .._files import atomic_open

if TYPE_CHECKING:
    from .animation import BodyAnimation

__all__ = ["DEFAULT_DPI", "PNG_COMPRESS_LEVEL", "PathLike", "save", "crop_and_write_png", "ink_mask"]

#: Resolution of saved figures (dots per inch) unless save() is told otherwise.
DEFAULT_DPI = 150
#: zlib's level for the PNGs save() draws once: lower than zlib's default (6), as small for figures and faster.
PNG_COMPRESS_LEVEL = 3

PathLike = Union[str, "os.PathLike[str]"]


def save(figure: Figure | BodyAnimation, path: PathLike, *, dpi: float | None = None) -> Path:
    """Write a figure (PNG, PDF, SVG, ... by the suffix) or an animation (``.gif``) to ``path``; returns the path.

    The file appears whole or not at all: it is written under a temporary name in the same folder and renamed
    (``snakehead._files.atomic_open``). Missing parent folders are created. Figures are cropped to what is
    drawn (``bbox_inches="tight"``) at ``dpi`` (default :data:`DEFAULT_DPI`); an animation has its own size.
    """
    from .animation import BodyAnimation  # a real cycle: the animation draws with the figures' modules

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
    measure every artist's extent, once at the cropped size, where every text is measured again; here the figure
    is drawn once on its canvas and cut by :func:`crop_and_write_png`. False (nothing written) when the drawing
    touches the canvas's edge."""
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
    ``(pixels != background).any(axis=2)``, each pixel compared as one 32-bit word."""
    if pixels.dtype != np.uint8 or pixels.shape[-1] != 4 or not pixels.flags.c_contiguous:
        return (pixels != background).any(axis=2)
    return pixels.view(np.uint32)[..., 0] != np.ascontiguousarray(background, np.uint8).view(np.uint32)[0]


def _write_png(file: IO[bytes], pixels: np.ndarray, dpi: float) -> None:
    """RGBA pixels (rows from the top) as a PNG with matplotlib's metadata; RGB when opaque (a quarter less to
    compress), at :data:`PNG_COMPRESS_LEVEL`."""
    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{mpl.__version__}, https://matplotlib.org/")
    opaque = bool((pixels[..., 3] == 255).all())
    image = Image.fromarray(np.ascontiguousarray(pixels[..., :3]) if opaque else pixels)
    image.save(file, format="png", dpi=(dpi, dpi), pnginfo=info, compress_level=PNG_COMPRESS_LEVEL)
