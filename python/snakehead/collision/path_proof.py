"""Proofs that a path or a timed motion stays clear, in C++ batches (``_core.PathChecker``,
include/snakehead/path_check.hpp).

* :func:`sample_clearances` -- each configuration's smallest ground clearance (the neck and head links), self
  clearance and obstacle distance, in one call without the GIL.
* :func:`check_path` -- a *proof* that the straight joint segments between waypoints are clear: the clearances are
  evaluated at samples at most ``first_step`` apart (largest joint change) and, between two samples, bounded by how
  far the links can move (below); an interval that the bound does not prove clear is halved, down to ``floor_step``.
* :func:`check_motion` -- a *proof* that a timed motion, its 2 ms samples joined by straight joint segments, is
  clear at and between its samples: evaluated only where some joint has travelled ``first_step`` since the last
  evaluated sample, each interval bounded by the joints' total variation over it (below).

The planner's checks built on them are :mod:`snakehead.planning.motion_checks`'s.

**The motion bound** (proof in path_check.hpp). Along a straight joint segment q(s) = q_a + s (q_b - q_a), s in
[0, 1], of a chain of revolute joints with a fixed root, every point of a shape S moves at most

    B_S = sum_j |dq_j| (r_{j,S} + rho_S)

where rho_S is the radius of S's bounding sphere and r_{j,S} bounds the distance of its centre from joint j's axis
over the whole segment: the smaller of (its distance at either end + sum_{i > j} |dq_i| reach(i, S)) and reach(j, S),
reach(i, S) being the chain's arc length from joint i to the centre (constant). The lowest point of S moves up or down
at most Z_S = sum_j |dq_j| h_j (r_{j,S} + rho_S), h_j <= 1 bounding the horizontal part of joint j's axis (0 for a
vertical yaw axis whose earlier joints do not move); a self pair's distance changes at most by the sum over the joints
between its two links only. A clearance f that is B-Lipschitz in s has min f >= (f(0) + f(1) - B) / 2: an interval
where that is above the floor is proven clear.

**Between the samples of a timed motion** (:func:`check_motion`). The bound needs no straight segment: along any
continuous joint path over which joint j travels at most V_j (its total variation, the integral of |dq_j/dt|),
every point of S moves at most sum_j V_j (r_{j,S} + rho_S) (the speed of a point of S is at most
sum_j |dq_j/dt| dist(p, axis_j), and r_{j,S} bounds that distance over the whole interval with V in place of |dq|),
and the cone bound holds in the arc length u(t) = integral sum_j |dq_j/dt| (r_{j,S} + rho_S) dt. The motion checked
is the one the joints are commanded: its 2 ms samples joined by straight joint segments, over which
V_j = sum_k |q_{k+1,j} - q_{k,j}| exactly, between any two samples, from the samples themselves (no bound on the
spline's or TOPP-RA's velocities is needed). The samples evaluated are those where a joint has travelled
``first_step`` since the last one; an interval the bound does not prove is halved by sample index, and one between
two consecutive samples along its straight segment as :func:`check_path` does.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .. import _core
from ..margins import EXACT_DISTANCE_WITHIN
from ..model.robot import BasePlacement, SnakeRobot, as_base
from .body_collisions import GROUND_TOLERANCE, obstacle_shapes

#: rad: the first sampling of a path that :func:`check_path` proves clear (largest joint change between samples).
#: The planner splits a move into steps of at most this (``planning.waypoints.MAX_WAYPOINT_STEP``); the bound proves
#: most such steps at once and halves the others, the fewest configurations evaluated (bench/path_check.py).
PATH_FIRST_STEP = 0.5
#: rad: intervals are not split below this largest joint change; one still unproven there fails the path.
PATH_FLOOR_STEP = 1e-3
#: rad: :func:`check_motion` evaluates a timed motion's samples where some joint has travelled this far (total
#: variation) since the last one evaluated: the fastest proof with and without obstacles (bench/path_check.py).
MOTION_FIRST_STEP = 0.2

__all__ = ["PATH_FIRST_STEP", "PATH_FLOOR_STEP", "MOTION_FIRST_STEP", "ProofCounts", "PathReport", "MotionReport",
           "checker", "sample_clearances", "check_path", "check_motion"]


def checker(robot: SnakeRobot, base: BasePlacement | None = None, obstacles: Sequence[Any] = ()) -> _core.PathChecker:
    """The C++ checker of the robot at ``base`` among ``obstacles``: the neck and head links' ground clearance
    (floor -GROUND_TOLERANCE), the robot's self-collision pairs, every shaped link against every obstacle shape.
    Immutable (shared by threads); the caller keeps it while robot, placement and obstacles stay (a plan's
    ``Waypoints`` does: obstacles make it costly to build)."""
    base = as_base(base)
    obstacles = list(obstacles)
    g = robot.geometry
    if obstacles:
        scene, owner = obstacle_shapes(obstacles)
        mine = g.shapes_of(robot.shaped_links)
        pairs = np.stack(np.meshgrid(mine, np.arange(len(owner)), indexing="ij"), axis=-1).reshape(-1, 2)
        scene_core = scene.core
    else:
        pairs, scene_core = np.zeros((0, 2), np.int64), None
    return _core.PathChecker(robot.body.model, g.core, robot.root_pose(base), g.shapes_of(robot.lifted_links),
                             np.ascontiguousarray(robot.self_collision_pairs, np.int64), scene_core,
                             np.ascontiguousarray(pairs, np.int64), -GROUND_TOLERANCE, EXACT_DISTANCE_WITHIN)


def sample_clearances(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None,
                      obstacles: Sequence[Any] = (), *, made: _core.PathChecker | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each configuration's (T, n) smallest ground clearance of the neck and head links (as
    ``collision.ground_clearance``), self clearance (``collision.self_clearance``) and obstacle distance
    (``collision.collision_check(exact_within=EXACT_DISTANCE_WITHIN).distance``; +inf without obstacles), m."""
    qs = np.ascontiguousarray(qs, float).reshape(-1, robot.n_joints)
    ground, self_, obstacle = (made if made is not None else checker(robot, base, obstacles)).sample(qs)
    return ground, self_, obstacle


@dataclass(frozen=True)
class ProofCounts:
    """What a proof evaluated: the configurations (``samples``), intervals ``proven`` and ``unproven`` (at the floor),
    ``violations`` (evaluated samples below a floor) and the smallest ground, self and obstacle values evaluated
    (m)."""

    samples: int
    proven: int
    unproven: int
    violations: int
    ground: float
    self_clearance: float
    obstacle: float


def _counts(d: dict) -> dict[str, Any]:
    """The core's counts and smallest values (``check_path``'s and ``check_motion``'s dicts) as ProofCounts' fields."""
    return {"samples": int(d["samples"]), "proven": int(d["proven"]), "unproven": int(d["unproven"]),
            "violations": int(d["violations"]), "ground": float(d["ground"]), "self_clearance": float(d["self"]),
            "obstacle": float(d["obstacle"])}


@dataclass(frozen=True)
class PathReport(ProofCounts):
    """What :func:`check_path` proved: ``clear`` (every segment proven clear), ``segments`` (K-1,) bool, and the
    counts of :class:`ProofCounts`."""

    clear: bool
    segments: np.ndarray


def check_path(robot: SnakeRobot, waypoints: np.ndarray, base: BasePlacement | None = None,
               obstacles: Sequence[Any] = (), *, first_step: float = PATH_FIRST_STEP,
               floor_step: float = PATH_FLOOR_STEP, stop_at_violation: bool = True,
               made: _core.PathChecker | None = None) -> PathReport:
    """Proves the straight joint segments between ``waypoints`` (K, n) clear of the ground (neck and head links, by
    -GROUND_TOLERANCE), of themselves and of ``obstacles`` everywhere along them, not only at samples (the motion
    bound of the module's docstring)."""
    W = np.ascontiguousarray(waypoints, float).reshape(-1, robot.n_joints)
    proof = made if made is not None else checker(robot, base, obstacles)
    d = proof.check_path(W, float(first_step), float(floor_step), bool(stop_at_violation))
    return PathReport(clear=bool(d["clear"]), segments=d["segments"], **_counts(d))


@dataclass(frozen=True)
class MotionReport(ProofCounts):
    """What :func:`check_motion` proved about a sampled motion of T samples: ``clear`` (no violation, nothing
    unproven: ``unproven`` counts intervals between two consecutive samples at the floor), ``obstacle_lower`` (T,) m:
    a lower bound of the smallest obstacle distance from each sample to the next (the last: at it), <= 0 where an
    interval is violated or unproven, +inf without obstacles; and the counts of :class:`ProofCounts`."""

    clear: bool
    obstacle_lower: np.ndarray

    def describe(self) -> str:
        """One line: what was evaluated and proven, and what was not."""
        return (f"{self.samples} configurations evaluated, {self.proven} intervals proven, {self.unproven} unproven, "
                f"{self.violations} violated; smallest ground {1000 * self.ground:.1f} mm, self "
                f"{1000 * self.self_clearance:.1f} mm, obstacles {1000 * self.obstacle:.1f} mm")


def check_motion(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement | None = None, obstacles: Sequence[Any] = (),
                 *, first_step: float = MOTION_FIRST_STEP, floor_step: float = PATH_FLOOR_STEP,
                 made: _core.PathChecker | None = None) -> MotionReport:
    """Proves a sampled motion qs (T, n) (its samples joined by straight joint segments) clear of the ground (neck
    and head links, by -GROUND_TOLERANCE), of itself and of ``obstacles`` at and between its samples, evaluating
    only some (the module's docstring)."""
    Q = np.ascontiguousarray(qs, float).reshape(-1, robot.n_joints)
    proof = made if made is not None else checker(robot, base, obstacles)
    d = proof.check_motion(Q, float(first_step), float(floor_step))
    return MotionReport(clear=bool(d["clear"]), obstacle_lower=d["obstacle_lower"], **_counts(d))
