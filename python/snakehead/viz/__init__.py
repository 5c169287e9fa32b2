"""Figures, animations and the 3-D viewer.

One convention: every plotting function returns a :class:`matplotlib.figure.Figure` (made outside pyplot, so no
backend is chosen at import or at all, and nothing needs closing), and :func:`save` writes a figure or an animation
to a file, atomically. By topic:

* :mod:`.body` -- the body in 3-D with its scene: Figs. 17/22 (snapshots), Fig. 8 (a head solution), Figs. 11/13;
* :mod:`.backbone_figures` -- backbone curves and their links: Figs. 2-3 and 14, the base arc's area against its
  angle;
* :mod:`.reachability_figures` -- reachability maps: Figs. 4-7;
* :mod:`.dynamics_figures` -- momenta (Figs. 18-19) and the ZMP in the support polygon (Fig. 20);
* :mod:`.loop_figures` -- a closed loop's path over the ground and its animation;
* :mod:`.animation` -- a plan's motion as a GIF (:func:`~.animation.animate`);
* :mod:`.viewer` -- the interactive 3-D viewer (viser): a standalone HTML page per plan and ``snakehead view``
  (:mod:`.viewer_arrays`: what it draws, as arrays; :mod:`.viewer_file`: ``NAME_viewer.npz``; :mod:`.viewer_nodes`:
  its nodes in a viser scene);
* :mod:`.live` -- the live viewer (``snakehead view --live``): drag the head's targets, the plan follows
  (:mod:`.live_nodes`: what it draws; :mod:`.live_panel`: its records, texts and each browser's own panel);
* :mod:`.server_guard` -- what both servers check before viser sees a request (Host, Origin, the token, the
  messages a browser may send); :mod:`.save_folder` -- the one folder the live page saves into, bare names only.

What they share: :mod:`.figure_style` (colours, a figure outside pyplot, 3-D axes with equal scales),
:mod:`.figure_geometry` (the body's and the obstacles' faces, footprints, a scene's bounds) and
:mod:`.figure_files` (:func:`save`).

>>> from snakehead.viz import save, body
>>> save(body.plot_snapshots(plan), "snapshots.png")                    # doctest: +SKIP
"""
from .figure_files import save

__all__ = ["save"]
