"""Figures of reachability maps like the paper's Figs. 4-7.

- :func:`plot_map`: the voxels as a 3-D scatter coloured on a 20-step colour bar, red (low) to blue (high),
  as in Figs. 4(a) and 5(a);
- :func:`plot_section`: a sectional view, the voxels of one grid layer (Figs. 4(b), 5(b));
- :func:`plot_dexterous`: the voxels of index 100 (Fig. 6);
- :func:`plot_clusters`: their k-means++ clusters, the centroids and the chosen centre G0 (Fig. 7);
- :func:`figure_map`: (a) and (b) side by side, as Figs. 4 and 5; :func:`map_figures`: Figs. 4/5, 6 and 7 at once.

Coordinates are in the map's frame (the chain's base frame), in metres. Each function draws into ``ax`` when given
one (a 3-D Axes for the 3-D views), else into a new figure, and returns the :class:`~matplotlib.figure.Figure`;
write it with :func:`snakehead.viz.save`. :func:`index_colors` gives the colour bar's colours (the 3-D viewer uses
them too).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib
import matplotlib.colors as mcolors
import numpy as np
import numpy.typing as npt
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from .._errors import InputError
from ..kinematics.reachability.reachability_map import Clusters, ReachabilityMap
from .figure_style import literal, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import BoundaryNorm, Colormap

__all__ = ["N_STEPS", "index_colors", "plot_map", "plot_section", "figure_map", "plot_dexterous", "plot_clusters",
           "map_figures"]

#: 20 colours over [0, 100]: red for low reachability through to blue for high (the paper's bar).
N_STEPS = 20


def _cmap_norm() -> tuple[Colormap, BoundaryNorm]:
    """The paper's bar: :data:`N_STEPS` colours of ``jet_r`` over [0, 100] and the norm that bins an index."""
    cmap = matplotlib.colormaps["jet_r"].resampled(N_STEPS)
    norm = mcolors.BoundaryNorm(np.linspace(0.0, 100.0, N_STEPS + 1), cmap.N)
    return cmap, norm


def index_colors(indices: npt.ArrayLike) -> np.ndarray:
    """The colour of each reachability index (0-100) on the paper's 20-step bar: (N, 3) RGB in [0, 1]."""
    cmap, norm = _cmap_norm()
    return np.asarray(cmap(norm(np.asarray(indices, float))), float)[..., :3]


def _check(m: Any) -> None:
    if not isinstance(m, ReachabilityMap):
        raise InputError(f"expected a ReachabilityMap, got {type(m).__name__}")
    if len(m) == 0:
        raise InputError("the map has no voxels")


def _axes3d(ax: Any) -> Any:
    if ax is None:
        fig = new_figure(figsize=(6.5, 5.5))
        ax = fig.add_subplot(projection="3d")
    if getattr(ax, "name", "") != "3d":
        raise InputError("a 3-D Axes is needed (fig.add_subplot(projection='3d'))")
    return ax


def _label3d(ax: Any, m: ReachabilityMap) -> None:
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    r = m.grid_size / 2
    c = m.grid_origin + r
    for setter, k in ((ax.set_xlim, 0), (ax.set_ylim, 1), (ax.set_zlim, 2)):
        setter(c[k] - r, c[k] + r)
    ax.set_box_aspect((1, 1, 1))


def _colorbar(fig: Any, mappable: Any, ax: Any) -> Any:
    cb = fig.colorbar(mappable, ax=ax, shrink=0.75, pad=0.1, ticks=np.linspace(0, 100, 11))
    cb.set_label("reachability index D")
    return cb


def plot_map(m: ReachabilityMap, ax: Any = None, min_index: float = 0.0, size: float | None = None,
             alpha: float = 0.6, colorbar: bool = True) -> Figure:
    """3-D scatter of the voxels with index >= min_index, coloured by index (Figs. 4(a), 5(a))."""
    _check(m)
    ax = _axes3d(ax)
    cmap, norm = _cmap_norm()
    keep = m.indices >= min_index
    p, d = m.centers[keep], m.indices[keep]
    s = size if size is not None else max(2.0, 4000.0 * m.voxel_size ** 2)
    sc = ax.scatter(p[:, 0], p[:, 1], p[:, 2], c=d, cmap=cmap, norm=norm, s=s, alpha=alpha, depthshade=False,
                    edgecolors="none")
    _label3d(ax, m)
    ax.set_title(f"{literal(m.base)} \u2192 {literal(m.tip)}: {len(p)} voxels")  # frame names: data
    if colorbar:
        _colorbar(ax.figure, sc, ax)
    return ax.figure


def plot_section(m: ReachabilityMap, ax: Axes | None = None, axis: str = "z", value: float = 0.0,
                 colorbar: bool = True) -> Figure:
    """The voxels of the grid layer containing ``axis = value`` as squares (Figs. 4(b), 5(b))."""
    _check(m)
    if axis not in ("x", "y", "z"):
        raise InputError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    k = "xyz".index(axis)
    u, v = [i for i in range(3) if i != k]
    h = m.voxel_size
    layer = np.floor((float(value) - m.grid_origin[k]) / h)
    if not 0 <= layer < m.grid_shape[k]:
        raise InputError(f"{axis} = {value} is outside the grid")
    at = m.grid_origin[k] + (layer + 0.5) * h
    keep = np.abs(m.centers[:, k] - at) < h / 2
    if ax is None:
        ax = new_figure(figsize=(6, 5)).subplots()
    cmap, norm = _cmap_norm()
    squares = [Rectangle((c[u] - h / 2, c[v] - h / 2), h, h) for c in m.centers[keep]]
    pc = PatchCollection(squares, cmap=cmap, norm=norm, edgecolor="white", linewidth=0.3)
    pc.set_array(m.indices[keep])
    ax.add_collection(pc)
    r = m.grid_size / 2
    c0 = m.grid_origin + r
    ax.set_xlim(c0[u] - r, c0[u] + r)
    ax.set_ylim(c0[v] - r, c0[v] + r)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[u]} (m)")
    ax.set_ylabel(f"{'xyz'[v]} (m)")
    ax.set_title(f"section {axis} = {at:+.3f} m ({int(keep.sum())} voxels)")
    if colorbar:
        _colorbar(ax.figure, pc, ax)
    fig = ax.get_figure(root=True)
    assert fig is not None  # the axes belong to a figure
    return fig


def figure_map(m: ReachabilityMap, axis: str = "z", value: float = 0.0, title: str | None = None) -> Figure:
    """Figs. 4 and 5: (a) the map in 3-D, (b) a sectional view through ``axis = value`` (m)."""
    fig = new_figure(figsize=(13, 5.5))
    a = fig.add_subplot(1, 2, 1, projection="3d")
    plot_map(m, a, colorbar=False)
    b = fig.add_subplot(1, 2, 2)
    plot_section(m, b, axis, value, colorbar=True)
    a.set_title("(a) " + a.get_title())
    b.set_title("(b) " + b.get_title())
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_dexterous(m: ReachabilityMap, ax: Any = None, threshold: float = 100.0) -> Figure:
    """The dexterous workspace: voxels of index >= threshold (Fig. 6)."""
    _check(m)
    ax = _axes3d(ax)
    p = m.dexterous(threshold)
    ax.scatter(p[:, 0], p[:, 1], p[:, 2], color="tab:blue", s=max(4.0, 4000.0 * m.voxel_size ** 2), alpha=0.8,
               depthshade=False)
    _label3d(ax, m)
    ax.set_title(f"index \u2265 {threshold:g}: {len(p)} voxels ({100 * len(p) / len(m):.2f} %)")
    return ax.figure


def plot_clusters(m: ReachabilityMap, clusters: Clusters | None = None, ax: Any = None, k: int = 3,
                  threshold: float = 100.0) -> Figure:
    """The dexterous voxels by k-means++ cluster, the centroids (x) and G0 (star) (Fig. 7)."""
    _check(m)
    ax = _axes3d(ax)
    c = clusters if clusters is not None else m.clusters(k=k, threshold=threshold)
    colors = ["tab:red", "tab:green", "tab:blue", "tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive"]
    s = max(4.0, 4000.0 * m.voxel_size ** 2)
    for j in range(len(c.centroids)):
        p = c.points[c.labels == j]
        col = colors[j % len(colors)]
        ax.scatter(p[:, 0], p[:, 1], p[:, 2], color=col, s=s, alpha=0.35, depthshade=False,
                   label=f"cluster {j + 1} ({len(p)})")
        ax.scatter(*c.centroids[j], color=col, marker="X", s=120, edgecolors="black", depthshade=False)
    ax.scatter(*c.center, color="gold", marker="*", s=400, edgecolors="black", depthshade=False,
               label=f"G0 = ({c.center[0]:.3f}, {c.center[1]:.3f}, {c.center[2]:.3f})")
    _label3d(ax, m)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"k-means++ clusters of the dexterous workspace (G0: {c.rule} cluster)")
    return ax.figure


def map_figures(m: ReachabilityMap, k: int = 3) -> dict[str, Figure]:
    """Figs. 4/5-, 6- and 7-like figures of ``m``: {"map": :func:`figure_map`, "dexterous": :func:`plot_dexterous`,
    "clusters": :func:`plot_clusters` with ``k`` clusters}."""
    figures = {"map": figure_map(m)}
    for name, draw in (("dexterous", plot_dexterous), ("clusters", lambda mm, ax: plot_clusters(mm, ax=ax, k=k))):
        fig = new_figure(figsize=(7, 6))
        draw(m, fig.add_subplot(projection="3d"))
        figures[name] = fig
    return figures
