"""The gridpoints of a path that TOPP-RA times it on: where they lie (:func:`first_grid`), what the retiming needs
at each (:class:`GridPoints`: the path, its dynamics' coefficients, its ground support), the solve's rows there
(:func:`grid_rows`, computed once per gridpoint and carried over when the grid is refined) and the solve
(:func:`solve_grid`).

TOPP-RA is given a little less than the limits (:data:`SOLVE_SHARE`, :data:`SOLVE_ZMP_EXTRA_M`): the room that the
path's curvature between gridpoints takes, so that the limits themselves hold at every sample without many
refinement rounds.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from .._validate import sample_count
from ..dynamics.inverse_dynamics import inverse_dynamics
from ..model.robot import BasePlacement, SnakeRobot
from . import topp_ra
from .joint_path import PathFunction, path_values
from .path_dynamics import path_dynamics
from .retiming_limits import RetimingLimits
from .stability_constraint import stability_rows
from .support_polygon import Support

__all__ = ["GRID_STEP", "MIN_GRID_PER_SEGMENT", "MAX_GRID_POINTS", "PATH_SPEED_FACTOR", "MAX_JOINT_SPEED",
           "SOLVE_SHARE", "SOLVE_ZMP_EXTRA_M", "first_grid", "GridPoints", "GridRows", "path_limits",
           "stability_limits", "grid_rows", "solve_grid"]

#: rad: the largest step of the path (Euclidean length in joint space) between two TOPP-RA gridpoints.
GRID_STEP = 0.02
#: Gridpoints per segment between two waypoints, at least.
MIN_GRID_PER_SEGMENT = 8
#: The most gridpoints of one retimed path (a path of 1000 rad at the default step): a larger grid is a mistake.
MAX_GRID_POINTS = 100_000
#: Where the path stands still (a cusp: every joint turns back or stops at a waypoint) the joint velocity limits do
#: not bound the path's speed s' (rad of joint-space path per s); it is capped at this multiple of the norm of the
#: velocity limits (each taken at most MAX_JOINT_SPEED rad/s). Elsewhere |q'(s)| is about 1 and the limits bind.
PATH_SPEED_FACTOR = 10.0
MAX_JOINT_SPEED = 100.0
#: TOPP-RA is given this share of the velocity, acceleration, torque and friction limits, and the ZMP margin plus
#: SOLVE_ZMP_EXTRA_M (m).
SOLVE_SHARE = 0.995
SOLVE_ZMP_EXTRA_M = 2e-4


def first_grid(knots: np.ndarray, grid_step: float) -> np.ndarray:
    """Gridpoints at most ``grid_step`` rad apart, at least MIN_GRID_PER_SEGMENT per segment, on every knot (the
    waypoints' path positions)."""
    sample_count(knots[-1], grid_step, "TOPP-RA's grid (the path's length over grid_step)", unit="rad",
                 maximum=MAX_GRID_POINTS)  # before the grid is allocated and solved over
    steps = np.maximum(MIN_GRID_PER_SEGMENT, np.ceil(np.diff(knots) / grid_step).astype(int))
    return np.concatenate([np.linspace(knots[k], knots[k + 1], steps[k] + 1)[:-1] for k in range(len(steps))]
                          + [knots[-1:]])


@dataclass(frozen=True)
class GridPoints:
    """What the retiming needs at gridpoints s (N,) of a path q(s), point by point: q, q'(s), q''(s) (N, n); the
    torques tau_a s'' + tau_b s'^2 + tau_hold (N, n each: Newton-Euler at (q, 0, q'), at (q, q', q'') and the
    torques that hold q still); the momentum rates w = (dP/dt, dL/dt) = w_a s'' + w_b s'^2 (N, 6 each); the ground
    support of q. A refined grid computes only its new points (:meth:`merged`)."""

    s: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau_a: np.ndarray
    tau_b: np.ndarray
    tau_hold: np.ndarray
    w_a: np.ndarray
    w_b: np.ndarray
    support: Support
    #: the solve's rows at these points (:func:`grid_rows`), by id of the limits: (robot, limits, GridRows); a merged
    #: grid carries them over, computing only the new points' rows
    rows: dict[int, tuple[SnakeRobot, RetimingLimits, "GridRows"]] = field(default_factory=dict, compare=False,
                                                                           repr=False)

    @classmethod
    def of(cls, robot: SnakeRobot, base: BasePlacement, f: PathFunction, s: np.ndarray, zmp_margin: float
           ) -> "GridPoints":
        q, dq, ddq = path_values(f, s)
        frames = robot.frames_many(q, base)
        a, b = path_dynamics(robot, q, dq, ddq, base, frames)
        hold = inverse_dynamics(robot, q, np.zeros_like(q), np.zeros_like(q), base)  # along q in the core
        support = Support.of(robot, q, base, zmp_margin, frames)
        return cls(s, q, dq, ddq, a.tau, b.tau, hold, np.hstack([a.Pdot, a.Ldot]), np.hstack([b.Pdot, b.Ldot]),
                   support)

    def merged(self, other: "GridPoints") -> "GridPoints":
        """Both sets of points, in the order of s."""
        order = np.argsort(np.concatenate([self.s, other.s]), kind="stable")
        arrays: dict[str, Any] = {f.name: np.concatenate([getattr(self, f.name), getattr(other, f.name)])[order]
                                  for f in fields(self) if f.name not in ("support", "rows")}
        merged = GridPoints(**arrays, support=self.support.joined(other.support).take(order))
        for key, (robot, limits, rows) in self.rows.items():
            merged.rows[key] = (robot, limits, rows.merged(grid_rows(robot, other, limits), order))
        return merged


@dataclass(frozen=True)
class GridRows:
    """The solve's canonical rows at some gridpoints (:func:`grid_rows`) and their layout: ``joint`` columns (the
    joints' accelerations and torques), then one per support-polygon edge (``edges``), then the friction's."""

    canonical: topp_ra.Canonical
    joint: int
    edges: int

    def padded(self, edges: int) -> "GridRows":
        """The rows of polygons padded to ``edges`` edges as :meth:`Support.joined` pads them (repeating the first
        edge): the first edge's columns repeated after the last edge's."""
        extra = edges - self.edges
        if extra == 0:
            return self
        end = self.joint + self.edges
        cols = np.r_[np.arange(end), np.full(extra, self.joint), np.arange(end, self.canonical.P.shape[1])]
        c = self.canonical
        return GridRows(topp_ra.Canonical(c.P[:, cols], c.Q[:, cols], c.R[:, cols], c.x_max), self.joint, edges)

    def merged(self, other: "GridRows", order: np.ndarray) -> "GridRows":
        """Both sets of rows, padded to one edge count, in ``order`` (as :meth:`GridPoints.merged`)."""
        edges = max(self.edges, other.edges)
        a, b = self.padded(edges).canonical, other.padded(edges).canonical
        return GridRows(topp_ra.Canonical(*(np.concatenate([getattr(a, name), getattr(b, name)])[order]
                                            for name in ("P", "Q", "R", "x_max"))), self.joint, edges)


def path_limits(limits: RetimingLimits) -> topp_ra.PathLimits:
    """The limits TOPP-RA is given: SOLVE_SHARE of the joints' (see there). The path is parametrised by its length
    in joint space (rad): its speed s' is about the joints' speed, which their limits bound; where the path stands
    still they do not, and PATH_SPEED_FACTOR times their norm does."""
    path_speed = PATH_SPEED_FACTOR * np.linalg.norm(np.minimum(limits.velocity, MAX_JOINT_SPEED))
    return topp_ra.PathLimits(SOLVE_SHARE * limits.velocity, SOLVE_SHARE * limits.acceleration,
                              SOLVE_SHARE * limits.torque, float(path_speed) ** 2)


def stability_limits(limits: RetimingLimits) -> RetimingLimits:
    """The limits the stability rows are given in the solve: SOLVE_SHARE of the friction."""
    return replace(limits, friction=SOLVE_SHARE * limits.friction)


def solve_grid(robot: SnakeRobot, points: GridPoints, limits: RetimingLimits) -> topp_ra.Solution:
    """TOPP-RA over the gridpoints ``points.s`` under ``limits`` (the solve's shares of them; the stability rows
    with the ZMP margin plus SOLVE_ZMP_EXTRA_M), rest to rest."""
    return topp_ra.solve(points.s, grid_rows(robot, points, limits).canonical)


def grid_rows(robot: SnakeRobot, points: GridPoints, limits: RetimingLimits) -> GridRows:
    """The canonical rows of :func:`solve_grid` at ``points``: computed once per gridpoint (kept in
    ``points.rows``; a refined grid's merge computes its new points' only: each row depends on its point alone)."""
    cached = points.rows.get(id(limits))
    if cached is not None and cached[0] is robot and cached[1] is limits:
        return cached[2]
    F, g = stability_rows(robot, points.support, stability_limits(limits), SOLVE_ZMP_EXTRA_M)
    canonical = topp_ra.canonical(path_limits(limits), points.dq, points.ddq, points.tau_a, points.tau_b,
                                  points.tau_hold, np.einsum("nkj,nj->nk", F, points.w_a),
                                  np.einsum("nkj,nj->nk", F, points.w_b), g)
    rows = GridRows(canonical, canonical.P.shape[1] - g.shape[1], points.support.offset.shape[1])
    points.rows[id(limits)] = (robot, limits, rows)
    return rows
