"""Time-optimal retiming of a whole-body path: TOPP-RA under the robot's limits and the ZMP.

:func:`retime` takes waypoints (K, n) -- the states of a plan, or the dense configurations of a Cartesian move --
joins them by a smooth path q(s) through every one of them that never leaves the range of two neighbouring
waypoints (so never a joint limit: :mod:`.joint_path`), and finds the fastest motion along it (TOPP-RA, Pham and
Pham 2018: the constraints of every gridpoint in numpy, :mod:`.gridpoints`; the passes and each gridpoint's 2-D LP
in the C++ core, :mod:`.topp_ra`, as the ``toppra`` package's ``seidel`` solver does them) that keeps, at every
gridpoint (and, the grid refined where needed, between them: at every sample, :mod:`.grid_refinement`):

* each joint's velocity within ``velocity_limit`` (default :data:`VELOCITY_SHARE` of the URDF's);
* each joint's acceleration within ``acceleration_limit`` (URDFs have none: default :data:`ACCELERATION_LIMIT`);
* each joint's torque within ``torque_limit`` (default :data:`TORQUE_SHARE` of the URDF's effort): the torques of
  :func:`snakehead.dynamics.inverse_dynamics.inverse_dynamics`, links resting on the ground carried by it
  (:mod:`.joint_constraints`);
* the ZMP (Eqs. 39-40, p_z = 0) inside the support polygon of the links on the ground
  (``stability.support_polygons(..., contact="ground")``) by ``zmp_margin`` m;
* the horizontal momentum rate within the friction the ground can give the base,
  |dP_xy/dt| <= ``friction`` (M g + dP_z/dt) (default :data:`FRICTION`: a share of the simulation's 0.8), since a
  snake's base slides when it is pushed; and the ground pushing, M g + dP_z/dt >= :data:`MIN_NORMAL_SHARE` M g
  (:mod:`.stability_constraint`).

Where the centre of mass itself is closer than twice ``zmp_margin`` to the polygon's edge (a barely stable path),
the ZMP is asked to keep half the CoM's margin instead (at rest the ZMP is the CoM's projection, so no motion can
do better there: :func:`required_margins`); the result's ``notes`` say where. A waypoint repeated (a zero-length
segment) is a pause of ``hold_s`` s; the motion comes to rest there, at ``stops``, at both ends and where the path
turns back on itself (every joint reverses or stops at a waypoint).

:func:`check_limits` measures any sampled trajectory against the same limits (the retimed one is checked at every
2 ms sample); the result says what binds. The names of the modules this one is made of are importable from here
too.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError, MotionTooLong
from .._validate import MAX_SAMPLES, finite_array, positive
from ..margins import ZMP_MARGIN
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from ..trajectory.interpolation import CONTROL_PERIOD, JointTrajectory, sample_times
from .grid_refinement import PROBES, REFINE_EXTRA_POINTS, REFINE_GROWTH, REFINE_ROUNDS, REFINE_ZMP_M
from .gridpoints import (
    GRID_STEP,
    MAX_GRID_POINTS,
    MAX_JOINT_SPEED,
    MIN_GRID_PER_SEGMENT,
    PATH_SPEED_FACTOR,
    SOLVE_SHARE,
    SOLVE_ZMP_EXTRA_M,
    GridPoints,
)
from .joint_path import INTERPOLATIONS, PathFunction
from .limit_check import BINDING_SHARE, BINDING_ZMP_M, LimitCheck, check_limits
from .path_dynamics import momentum_rate_coefficients
from .rest_to_rest import Piece
from .retiming_limits import ACCELERATION_LIMIT, FRICTION, TORQUE_SHARE, VELOCITY_SHARE, RetimingLimits, resolve_limits
from .stability_constraint import FRICTION_SIDES, MIN_NORMAL_SHARE, stability_rows
from .support_polygon import ZMP_DYNAMIC_ROOM, Support, required_margins
from .timeline import Timeline

__all__ = ["HOLD_S", "SAME_WAYPOINT", "RetimedTrajectory", "retime", "checked_waypoints",
           # the names of the modules it is made of, importable from here too
           "ZMP_MARGIN", "GRID_STEP", "MAX_GRID_POINTS", "MAX_JOINT_SPEED", "MIN_GRID_PER_SEGMENT",
           "PATH_SPEED_FACTOR", "SOLVE_SHARE", "SOLVE_ZMP_EXTRA_M", "GridPoints", "INTERPOLATIONS", "PathFunction",
           "BINDING_SHARE", "BINDING_ZMP_M", "LimitCheck", "check_limits", "momentum_rate_coefficients", "PROBES",
           "REFINE_EXTRA_POINTS", "REFINE_GROWTH", "REFINE_ROUNDS", "REFINE_ZMP_M", "ACCELERATION_LIMIT", "FRICTION",
           "TORQUE_SHARE", "VELOCITY_SHARE", "RetimingLimits", "resolve_limits", "FRICTION_SIDES",
           "MIN_NORMAL_SHARE", "stability_rows", "ZMP_DYNAMIC_ROOM", "Support", "required_margins"]

#: s: a repeated waypoint's pause by default.
HOLD_S = 1.0
#: rad: two waypoints closer than this (largest joint difference) are the same: a hold.
SAME_WAYPOINT = 1e-9


@dataclass(frozen=True)
class RetimedTrajectory(JointTrajectory):
    """A :class:`~snakehead.trajectory.interpolation.JointTrajectory` from :func:`retime`: t, q, qd, qdd sampled every
    dt (``spline(t, nu)`` evaluates it anywhere), and

    waypoint_times (K,) s: when it passes each waypoint (after a hold: when the pause ends); limits: the
    :class:`RetimingLimits` it keeps; check: the :class:`LimitCheck` of its samples (what binds); notes: what the
    retiming had to relax; solve_time_s: the retiming's own run time.
    """

    waypoint_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    limits: RetimingLimits | None = None
    check: LimitCheck | None = None
    notes: tuple[str, ...] = ()
    solve_time_s: float = 0.0

    @property
    def duration(self) -> float:
        """s, from the first sample to the last."""
        return float(self.t[-1] - self.t[0])


def retime(robot: SnakeRobot, waypoints: npt.ArrayLike, base: BasePlacement | None = None, *,
           velocity_limit: npt.ArrayLike | None = None, acceleration_limit: npt.ArrayLike | None = ACCELERATION_LIMIT,
           torque_limit: npt.ArrayLike | None = None, zmp_margin: float = ZMP_MARGIN, friction: float = FRICTION,
           dt: float = CONTROL_PERIOD, hold_s: npt.ArrayLike = HOLD_S, stops: Sequence[int] = (),
           interpolation: str = "monotone", grid_step: float = GRID_STEP, check_samples: bool = True,
           sample: bool = True) -> RetimedTrajectory:
    """The fastest motion through ``waypoints`` that keeps the robot's limits and its balance.

    Parameters
    ----------
    robot : the snake; base : where its base lies (default placement; on flat ground the result is the same for any,
        on a slope it depends on the heading).
    waypoints : (K, n) joint vectors (rad) within the joint limits, K >= 2. The motion passes through every one,
        starts and ends at rest, and rests at each waypoint index in ``stops``.
    velocity_limit : rad/s, a number or (n,); default :data:`VELOCITY_SHARE` of the URDF's (none where it gives 0).
    acceleration_limit : rad/s^2, a number or (n,); default :data:`ACCELERATION_LIMIT`.
    torque_limit : N m, a number or (n,); default :data:`TORQUE_SHARE` of the URDF's effort (none where it gives 0).
    zmp_margin : m the ZMP keeps inside the ground support polygon (see the module's note on barely stable paths).
    friction : the friction coefficient the base may use (default :data:`FRICTION`).
    dt : s between samples (the 2 ms control period). hold_s : s, the pause at a repeated waypoint; a number or one
        per segment (K-1,) (used where the segment has zero length).
    interpolation : the path through the waypoints: "monotone" (default: the piecewise quintic
        :class:`~snakehead.trajectory.interpolation.MonotoneQuintic`, which never leaves the range of two neighbouring
        waypoints) or "spline" (a not-a-knot cubic spline, toppra's own; it may overshoot: ValueError if it leaves
        the joint limits).
    grid_step : rad of path between TOPP-RA's gridpoints (at most; at least MIN_GRID_PER_SEGMENT per segment).
    check_samples : measure every sample against the limits (:func:`check_limits`: the result's ``check``); False
        leaves ``check`` None, for a caller that checks the samples itself (the refined grid keeps the limits
        between gridpoints either way).
    sample : sample the motion every ``dt`` (default); False keeps only its last sample (t, q, qd, qdd: its end,
        the same values as the last of the full sampling), for a caller that samples the result's ``spline`` itself
        (``check_samples`` must then be False).

    Returns a :class:`RetimedTrajectory` (a JointTrajectory with ``duration``, ``waypoint_times``, ``check``).
    Raises ValueError when no motion along the path keeps the limits (the CoM outside the support polygon, the
    torque to hold still beyond the limit, ...), saying where; ``snakehead.InputError`` as soon as the motion timed
    so far is longer than MAX_SAMPLES samples at ``dt`` (2000 s at 2 ms).
    """
    clock = time.perf_counter()
    robot = as_robot(robot)
    placed = as_base(base)
    # on flat ground the timing does not depend on the placement: gravity is vertical and the ground flat, so the
    # limits and the balance are the same wherever the base lies (the friction polygon is taken in the base's
    # frame): the path is timed at the default placement, and one timing serves every placement (the planner times a
    # lift once per base shape). On a slope gravity leans in the base's frame as its heading turns: timed there
    base = BasePlacement() if placed.on_flat_ground else placed
    W = checked_waypoints(robot, waypoints)
    limits = resolve_limits(robot, velocity_limit=velocity_limit, acceleration_limit=acceleration_limit,
                            torque_limit=torque_limit, zmp_margin=zmp_margin, friction=friction)
    dt = positive(dt, "dt")
    grid_step = positive(grid_step, "grid_step")
    _check_options(check_samples, sample, interpolation)
    schedule, holds = _segments(W, stops, hold_s)
    timeline, times, notes = _timed(robot, base, limits, W, schedule, holds, interpolation, grid_step, dt)
    t = sample_times(0.0, timeline.end, dt) if timeline.end > 0 else np.array([0.0])
    if not sample:
        t = t[-1:]  # the end only: each sample is evaluated on its own, so these are the full sampling's last
    q, qd, qdd = timeline.sample(t)
    q[0], q[-1] = W[0], W[-1]
    check = check_limits(robot, q, qd, qdd, base, limits) if check_samples else None
    return RetimedTrajectory(t, q, qd, qdd, timeline, waypoint_times=times, limits=limits, check=check,
                             notes=tuple(notes), solve_time_s=time.perf_counter() - clock)


def checked_waypoints(robot: SnakeRobot, waypoints: npt.ArrayLike) -> np.ndarray:
    """The waypoints (K, n), K >= 2, within the joint limits; InputError otherwise."""
    n = robot.n_joints
    W = finite_array(waypoints, "waypoints")
    if W.ndim != 2 or W.shape[1] != n:
        raise InputError(f"waypoints has shape {W.shape}; expected (K, {n})")
    if W.shape[0] < 2:
        raise InputError(f"waypoints needs at least two configurations, got {W.shape[0]}")
    out = (W < robot.lower - 1e-9) | (W > robot.upper + 1e-9)
    if out.any():
        k, j = np.argwhere(out)[0]
        raise InputError(f"waypoint {k} has joint {robot.joint_names[j]} at {W[k, j]:.4f} rad, outside its limits "
                         f"[{robot.lower[j]:.4f}, {robot.upper[j]:.4f}]")
    return W


def _check_options(check_samples: bool, sample: bool, interpolation: str) -> None:
    """InputTypeError/InputError for :func:`retime`'s flags and interpolation."""
    for name, flag in (("check_samples", check_samples), ("sample", sample)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InputTypeError(f"{name} must be True or False, got {flag!r}")
    if check_samples and not sample:
        raise InputError("check_samples=True needs sample=True (the samples are what it checks)")
    if interpolation not in INTERPOLATIONS:
        raise InputError(f"interpolation must be one of {INTERPOLATIONS}, got {interpolation!r}")


def _timed(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, W: np.ndarray,
           schedule: list[tuple[str, int, int]], holds: np.ndarray, interpolation: str, grid_step: float, dt: float
           ) -> tuple[Timeline, np.ndarray, list[str]]:
    """The motion along ``schedule`` (:func:`_segments`): its timeline, the waypoints' times (K,) s and the notes
    of what was relaxed; MotionTooLong as soon as it lasts longer than MAX_SAMPLES samples at ``dt``."""
    timeline = Timeline(robot.n_joints)
    times = np.zeros(len(W))
    notes: list[str] = []
    for kind, i0, i1 in schedule:
        if kind == "pause":
            timeline.add_pause(W[i1], float(holds[i0]))
            times[i1] = timeline.end
        else:
            piece = Piece(robot, base, limits, W, i0, i1, interpolation)
            grid, sd = piece.time(grid_step, notes)
            t_grid = timeline.add_piece(piece.f, grid, sd)
            times[i0:i1 + 1] = t_grid[np.searchsorted(grid, piece.knots)]
        _check_length(timeline.end, dt)
    return timeline, times, notes


def _check_length(end: float, dt: float) -> None:
    """MotionTooLong as soon as the motion timed so far (``end`` s) is longer than MAX_SAMPLES samples at ``dt`` take:
    before the rest of the path is solved or anything is sampled."""
    if end > (MAX_SAMPLES - 1) * dt:
        raise MotionTooLong(f"the timed motion lasts more than {end:.1f} s; at most {(MAX_SAMPLES - 1) * dt:g} s "
                            f"({MAX_SAMPLES} samples at {dt:g} s)")


def _segments(waypoints: np.ndarray, stops: Sequence[int], hold_s: npt.ArrayLike
              ) -> tuple[list[tuple[str, int, int]], np.ndarray]:
    """The schedule: ("piece", i0, i1) runs of moving segments between rests, ("pause", k, k+1) holds; and the pause
    of each segment (K-1,)."""
    K = len(waypoints)
    same = np.abs(np.diff(waypoints, axis=0)).max(axis=1) <= SAME_WAYPOINT
    holds = _holds(hold_s, K)
    rest = _rests(waypoints, same, stops)
    schedule = []
    start = None
    for k in range(K - 1):
        if same[k]:
            if start is not None:
                schedule.append(("piece", start, k))
                start = None
            schedule.append(("pause", k, k + 1))
            continue
        if start is None:
            start = k
        if rest[k + 1]:
            schedule.append(("piece", start, k + 1))
            start = None
    return schedule, holds


def _holds(hold_s: npt.ArrayLike, K: int) -> np.ndarray:
    """The pause (K-1,) s of each segment from a number or one per segment."""
    holds = finite_array(hold_s, "hold_s")
    if holds.ndim == 0:
        holds = np.full(K - 1, float(holds))
    if holds.shape != (K - 1,):
        raise InputError(f"hold_s must be a number or one per segment ({K - 1},), got shape {holds.shape}")
    if np.any(holds < 0):
        raise InputError("hold_s must be >= 0 s")
    return holds


def _rests(waypoints: np.ndarray, same: np.ndarray, stops: Sequence[int]) -> np.ndarray:
    """(K,) bool: the waypoints where the motion comes to rest: both ends, the ``stops`` and every cusp (every joint
    turns back or stops at the waypoint, so the path stands still there, q'(s) = 0 on the monotone path: a piece
    ends there, as TOPP-RA is ill-conditioned at a standstill inside a path)."""
    K = len(waypoints)
    rest = np.zeros(K, bool)
    rest[[0, -1]] = True
    step = np.diff(waypoints, axis=0)
    rest[1:-1] |= np.all(step[:-1] * step[1:] <= 0.0, axis=1) & ~same[:-1] & ~same[1:]
    for k in stops:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise InputTypeError(f"stops must be waypoint indices (int), got {k!r}")
        if not -K <= k < K:
            raise InputError(f"stop {k} is not a waypoint index (there are {K} waypoints)")
        rest[k] = True
    return rest
