"""The planner's checks of configurations, paths and timed motions, on the clearance proofs of
:mod:`snakehead.collision.path_proof` and the ZMP check of :mod:`snakehead.dynamics.stability`:

* :func:`feasible`, :func:`path_feasible` -- configurations and paths (ground, static margin, self, obstacles);
* :func:`finish_checks` -- a timed motion: the ZMP in the support polygon at every 2 ms sample, the neck and head's
  ground clearance at every sample (from the same pass) and ``check_motion`` (ground, self and obstacles proven
  between the samples).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .. import _core
from ..collision.body_collisions import GROUND_TOLERANCE
from ..collision.path_proof import MotionReport, check_motion, check_path, checker, sample_clearances
from ..dynamics import stability
from ..dynamics.stability import DynamicStability, KeptSamples
from ..model.robot import BasePlacement, SnakeRobot

__all__ = ["feasible", "path_feasible", "finish_checks"]


def feasible(way: Any, qs: np.ndarray, margin: float) -> np.ndarray:
    """(m,) bool: the planner's check of configurations qs (m, n) (``planning.planner._Waypoints``): the neck and head
    above the ground (by -GROUND_TOLERANCE), the static margin at least ``margin`` (``way.static_margins``), no two
    non-neighbouring links overlapping, clear of the obstacles; the clearances in one C++ call."""
    qs = np.asarray(qs, float)
    ground, self_, obstacle = sample_clearances(way.robot, qs, way.base, way.obstacles, made=way.checker)
    ok = (ground >= -GROUND_TOLERANCE) & (self_ > 0.0) & (obstacle > 0.0)
    if ok.any():
        rows = np.flatnonzero(ok)
        ok[rows] = way.static_margins(qs[rows]) >= margin
    return ok


def path_feasible(way: Any, path: np.ndarray, checked: np.ndarray, margin: float) -> bool:
    """The planner's check of a path of waypoints (K, n): its clearances proven along the straight segments
    (:func:`check_path`), its static margin at least ``margin`` at the configurations ``checked`` (sampled: the
    support polygon changes as links touch or leave the ground, so it has no motion bound)."""
    if not check_path(way.robot, path, way.base, way.obstacles, made=way.checker).clear:
        return False
    return bool((way.static_margins(np.asarray(checked, float)) >= margin).all())


def finish_checks(robot: SnakeRobot, base: BasePlacement, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                  obstacles: Sequence[Any], contact: str, made: _core.PathChecker | None = None,
                  kept: KeptSamples | None = None
                  ) -> tuple[DynamicStability, np.ndarray, np.ndarray | None, MotionReport]:
    """The checks of a timed motion (``Waypoints.finish_checks``): the dynamic stability at every sample
    (``stability.dynamic_stability``: momenta, ZMP and its margin, in C++ in one call; ``kept``: the first samples'
    part of an earlier check, see ``stability.KeptSamples``), the lowest point of the neck and head links above the
    ground at every sample (exact, from the same pass), and :func:`check_motion`: the ground, self and obstacle
    clearances proven at and between the samples. Returns those, and the obstacle distance per sample (the proof's
    ``obstacle_lower``: a lower bound from each sample to the next; None without obstacles)."""
    made = made if made is not None else checker(robot, base, obstacles)
    dyn, clearance = stability.dynamic_stability_with_clearance(robot, t, q, base, qd, contact=contact, made=made,
                                                                kept=kept)
    proof = check_motion(robot, q, base, obstacles, made=made)
    return dyn, clearance, (proof.obstacle_lower if obstacles else None), proof
