"""The figure of the package's layers on the architecture page (``.. snakehead-layers::``), drawn at build time from
the import-linter contract in pyproject.toml, so that the page shows what ``lint-imports`` checks and cannot drift
from it; and the page's check that it has a section for every package of the contract.

Rows run top to bottom as the contract lists them: a package may import the rows below its own, never those above.
Names side by side on one row are one layer: joined by ``|`` in the contract they are independent (neither imports
the other), joined by ``:`` they may import each other. The C++ core lies under every row.
"""
from __future__ import annotations

import io
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from matplotlib import rc_context
from matplotlib.figure import Figure
from matplotlib.patches import FancyBboxPatch
from sphinx.util import logging

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"
PACKAGE_DIR = ROOT / "python" / "snakehead"
#: The docname of the page that holds the figure and one section per package.
PAGE = "architecture"

ROW_HEIGHT = 0.42  # inches a row takes, gap included
BOX_HEIGHT = 0.30  # inches
WIDTH = 7.0  # inches
PACKAGE_COLOR = "#dbe9f6"
MODULE_COLOR = "#eeeeee"
CORE_COLOR = "#fbe3c8"
EDGE_COLOR = "#4a6a8a"


@dataclass(frozen=True)
class Layer:
    """One row of the contract: its names (without ``snakehead.``) and whether they are independent siblings."""

    names: tuple[str, ...]
    independent: bool


def read_layers(pyproject: Path = PYPROJECT) -> list[Layer]:
    """The rows of the contract of type ``layers`` in ``pyproject``'s ``[tool.importlinter]``, top to bottom."""
    config = tomllib.loads(pyproject.read_text())["tool"]["importlinter"]
    root = config["root_package"]
    contract = next(c for c in config["contracts"] if c["type"] == "layers")
    rows = []
    for row in contract["layers"]:
        independent = "|" in row
        names = tuple(name.strip().removeprefix(f"{root}.") for name in re.split(r"[|:]", row))
        rows.append(Layer(names, independent))
    return rows


def is_package(name: str) -> bool:
    """Whether ``snakehead.NAME`` is a package (a folder) rather than a single foundation module."""
    return (PACKAGE_DIR / name).is_dir()


def packages(layers: list[Layer]) -> list[str]:
    """The packages of the contract, top to bottom (the foundation modules left out)."""
    return [name for layer in layers for name in layer.names if is_package(name)]


def _box(ax, x: float, y: float, width: float, text: str, color: str, dashed: bool = False) -> None:
    ax.add_patch(FancyBboxPatch((x, y), width, BOX_HEIGHT, boxstyle="round,pad=0,rounding_size=0.06",
                                facecolor=color, edgecolor=EDGE_COLOR, linewidth=0.8,
                                linestyle="--" if dashed else "-"))
    ax.text(x + width / 2, y + BOX_HEIGHT / 2, text, ha="center", va="center", fontsize=9,
            family="monospace")


def _draw_row(ax, layer: Layer, y: float, left: float, right: float) -> None:
    """A row's boxes side by side; independent siblings get a '|' between them, the others ':'."""
    gap = 0.25
    width = (right - left - gap * (len(layer.names) - 1)) / len(layer.names)
    for i, name in enumerate(layer.names):
        x = left + i * (width + gap)
        _box(ax, x, y, width, name, PACKAGE_COLOR if is_package(name) else MODULE_COLOR)
        if i:
            ax.text(x - gap / 2, y + BOX_HEIGHT / 2, "|" if layer.independent else ":", ha="center", va="center",
                    fontsize=11, color=EDGE_COLOR, weight="bold")


def draw(layers: list[Layer]) -> Figure:
    """The layers as stacked boxes, top to bottom, the C++ core under them and an arrow for the import direction."""
    rows = len(layers) + 1
    height = rows * ROW_HEIGHT + 0.1
    fig = Figure(figsize=(WIDTH, height), facecolor="white")
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, WIDTH)
    ax.set_ylim(0, height)
    ax.axis("off")
    left, right = 0.9, WIDTH - 0.1
    for i, layer in enumerate(layers):
        _draw_row(ax, layer, height - (i + 1) * ROW_HEIGHT, left, right)
    _box(ax, left, 0.05, right - left, "_core: the C++ core (include/, cpp/, bindings/), called from any row",
         CORE_COLOR, dashed=True)
    ax.annotate("", xy=(0.45, 0.2), xytext=(0.45, height - 0.2),
                arrowprops=dict(arrowstyle="-|>", color=EDGE_COLOR, linewidth=1.2))
    ax.text(0.3, height / 2, "imports", rotation=90, ha="center", va="center", fontsize=9, color=EDGE_COLOR)
    return fig


def svg_text(fig: Figure, label: str) -> str:
    """The figure as an inline ``<svg>`` element (text kept as text, no date) labelled ``label`` for screen readers,
    scaled to the page's width."""
    out = io.StringIO()
    with rc_context({"svg.fonttype": "none", "svg.hashsalt": "layers"}):
        fig.savefig(out, format="svg", metadata={"Date": None})
    svg = out.getvalue()
    svg = svg[svg.index("<svg"):]
    return svg.replace("<svg ", f'<svg style="max-width: 100%; height: auto" role="img" aria-label="{label}" ', 1)


def alt_text(layers: list[Layer]) -> str:
    """The rows in words, top to bottom (the figure's text for readers that do not see it)."""
    rows = [(" | " if layer.independent else " : ").join(layer.names) for layer in layers]
    return "Layers, top to bottom: " + "; ".join(rows) + "; and the C++ core under them."


class LayersFigure(Directive):
    """``.. snakehead-layers::`` followed by an indented caption: the contract's layers as an inline SVG figure."""

    has_content = True

    def run(self) -> list[nodes.Node]:
        layers = read_layers()
        figure = nodes.figure(align="center")
        figure += nodes.raw("", svg_text(draw(layers), alt_text(layers)), format="html")
        messages: list[nodes.Node] = []
        if self.content:
            text, messages = self.state.inline_text(" ".join(self.content), self.lineno)
            figure += nodes.caption("", "", *text)
        return [figure, *messages]


def check_sections(app, doctree) -> None:
    """Warn when the architecture page lacks a section titled with a package of the contract (``snakehead.NAME``),
    so that a package added to the contract gets its paragraph."""
    if app.env.docname != PAGE:
        return
    titles = {node.astext() for node in doctree.findall(nodes.title)}
    for name in packages(read_layers()):
        if f"snakehead.{name}" not in titles:
            logging.getLogger("snakehead.docs").warning(
                f"{PAGE}.rst has no section titled snakehead.{name} (a package of pyproject.toml's layers)",
                location=PAGE)
