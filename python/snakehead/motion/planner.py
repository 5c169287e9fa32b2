"""The planner: head targets (a scene) -> a checked whole-body motion sampled at the 2 ms control period.

It strings the control process of Section 3.3 together on any snake robot. The body starts in the bending state
(Figs. 17b, 22a: the base on its optimised arc, the neck and head curled flat on the ground inside it:
:func:`bending_state`) and lifts the head to the initial state of Section 3.3 (1) (the base arc joined to the
neck-and-head Bezier: ``backbone.initial_configuration``). Each target is solved by the
:class:`~snakehead.control.HeadController` and reached by a whole-body move (Section 3.2: the Cartesian
interpolation of Eqs. 41-44 where it is valid, else joint space through a stable detour when needed; see
``_Waypoints.move``), or, for targets approached along a line, by the head's poses solved every few millimetres
along it. The waypoints are joined by the multi-segment interpolation at 2 ms, and the result is checked at every
sample: the ZMP inside the support polygon (Eqs. 36-40), every neck and head link above the ground, no link
touching an obstacle.

Why the bending state: on the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg); lifted as a
cantilever beyond P0 they would tip the body, so they are curled over the base before they rise. Getting from an
arbitrary lying state into the bending state is a reconfiguration on the ground (the paper's rolling gait or
turning in place) that is not part of these plans.

The path through the waypoints is timed at the end by the time-optimal retiming (``motion.timing.retime``:
TOPP-RA under joint velocity, acceleration and torque limits, the ZMP inside the support polygon by a margin and
the ground's friction); the motion rests at every target.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from .._errors import Infeasible, InputError, InputTypeError, MotionTooLong, entry_point, inputs_checked
from .._validate import MAX_SAMPLES, integer, joint_vector
from ..control.controller import HeadController
from ..dynamics import stability
from ..geometry import collision as coll
from ..geometry import path_check
from ..model.robot import BasePlacement, SnakeRobot
from ..scenes.scene import Scene, Target
from . import interpolation as interp
from .cartesian import tracking_interpolation

import os

import numpy.typing as npt
from typing import TYPE_CHECKING, Any, Callable, Sequence

if TYPE_CHECKING:
    from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole

#: m: the least distance a solved configuration keeps from every obstacle.
OBSTACLE_CLEARANCE = 0.002
#: The contact model plans are checked with (``dynamics.stability.support_polygon``): every link lying on the ground.
PLAN_CONTACT = "ground"
DETOUR_MARGIN = 0.01  # m: static margin every planned configuration keeps (twice the ZMP margin: room for the motion)
DETOUR_TRIALS = 256  # candidate detour waypoints tried for a move whose straight path is unstable
DETOUR_SPREAD = 0.4  # rad: spread of the neck and head joints of a detour waypoint around the midpoint
DETOUR_SEED = 20211  # fixed: the same inputs give the same plan
JOINT_STEP_CHECK = 0.02  # rad: a joint-space step is checked at least this densely
FALLBACK_SPEED = 0.1  # rad/s: the pace of a path that the retiming cannot time (the plan then fails; faster when
#                        the motion would be longer than MAX_MOTION_S)
DENSIFY = 3  # configurations checked between consecutive waypoints of a move, at least
MOVE_CHECK_STEP = 0.05  # rad: a move's configurations are checked at most this far apart (largest joint change)
MAX_WAYPOINT_STEP = 0.5  # rad: a move's steps longer than this (largest joint change) are split into equal ones
DETOUR_BATCH = 16  # detour candidates screened at once, shortest first
KEPT_LIFTS = 16  # lifts (checked paths, timed motions) a controller keeps, one per base shape
ZMP_MARGIN = 0.005  # m: the least distance of the ZMP inside the support polygon a successful plan keeps
LIFT_STEPS = 16  # waypoints of the lift from the bending state to the initial state
BENDING_GRID_DEG = 15.0  # deg: finest grid of the neck and head's yaw joints searched for the bending state
BENDING_COMBINATIONS = 30000  # the grid coarsens so that it never holds more curls than this
BENDING_CLEARANCE = 0.005  # m: least gap between non-neighbouring links of the bending state
#: How far choose_base tries stepping the base back from the targets, as shares of the body's length
#: (0.05, 0.1, 0.15, 0.2 m on the default robot, 1.384 m long).
BASE_STEP_SHARES = tuple(k * 0.05 / 1.384 for k in (1, 2, 3, 4))


#: s: the longest motion a plan may have: MAX_SAMPLES samples at the 2 ms control period (2000 s). Checked before
#: anything is solved (the targets' holds alone), after each target is solved (the holds and the least time the
#: joints' velocity limits allow for the moves so far) and while the path is timed (``motion.timing.retime``),
#: before anything is sampled: a scene that needs more raises ``snakehead.InputError`` (split it into scenes).
MAX_MOTION_S = (MAX_SAMPLES - 1) * interp.CONTROL_PERIOD
#: The most poses a plan solves: its targets and the poses along its straight-line approaches (each a whole-body
#: solve, ~0.1-0.5 s on the default robot), counted before any is solved.
MAX_POSES = 5000


@dataclass(frozen=True)
class PlanProgress:
    """What :func:`plan` tells its ``progress`` callback, one record per call.

    kind: "target" once a target of the scene has been solved and the move to it planned (in the scene's order,
    via poses included): ``index`` 1..``count`` (the scene's targets), ``name``, ``solved``, ``seconds`` (its solve
    and move), ``message`` (why it was not solved; "" when it was). "stage" when a stage over the whole plan begins:
    ``name`` "base" (every target solved from the start, to choose the base), "timing" (the time-optimal retiming of
    the whole path, often the longest stage), "checks" (the ZMP, the ground and the obstacles at every 2 ms sample);
    ``message`` says what it does. ``elapsed_s``: seconds since :func:`plan` was called.
    """

    kind: str
    name: str
    index: int = 0
    count: int = 0
    solved: bool = True
    seconds: float = 0.0
    elapsed_s: float = 0.0
    message: str = ""


#: The signature of ``plan(progress=...)``: called with a :class:`PlanProgress`; its return value is ignored and an
#: exception it raises stops the plan (it propagates to the caller of :func:`plan`).
ProgressCallback = Callable[[PlanProgress], None]


@dataclass
class TargetResult:
    """One head target of a plan and how well the plan reaches it (planned, by forward kinematics)."""

    name: str
    position: np.ndarray  # (3,) m
    direction: np.ndarray  # (3,) unit
    time_s: float  # when the plan arrives
    solution: Any  # control.whole_body.WholeBodySolution (the segmented HeadSolution in its ``segmented``)

    @property
    def position_error_m(self) -> float:
        return self.solution.position_error_m

    @property
    def direction_error_deg(self) -> float:
        return self.solution.direction_error_deg

    @property
    def solved(self) -> bool:
        return bool(self.solution.success)


@dataclass
class Plan:
    """A planned motion: the 2 ms joint trajectory, its states and targets, and its checks.

    name: the scene's. robot, base: the robot and where its base lies. t (T,) s, q (T, n) rad, qd (T, n) rad/s.
    states: (label, time s, q (n,)) of every waypoint. targets: :class:`TargetResult` per reported target.
    stability: ``dynamics.DynamicStability`` (ZMP and its margin at every sample). ground_clearance (T,) m: the
    lowest neck or head box corner above the ground. obstacles and obstacle_distance (T,) m (None without
    obstacles). segments: (segment, interpolation used). notes: what the planner had to do or could not.
    """

    name: str
    robot: SnakeRobot
    base: BasePlacement
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    states: list
    targets: list
    stability: stability.DynamicStability
    ground_clearance: np.ndarray
    obstacles: list = field(default_factory=list)
    obstacle_distance: np.ndarray | None = None
    planning_time_s: float = 0.0
    notes: list = field(default_factory=list)
    segments: list = field(default_factory=list)
    scene: Scene | None = None
    relocation: "Relocation | None" = None  # the change of base the targets need, before the plan (locomotion)
    timing_failure: str | None = None  # why the path could not be timed within the limits, when it could not
    out_of_range: str | None = None  # why no relocation was tried: a target beyond MAX_RELOCATION_M of the start

    @property
    def min_zmp_margin_m(self) -> float:
        return float(self.stability.min_margin)

    @property
    def min_ground_clearance_m(self) -> float:
        return float(self.ground_clearance.min())

    @property
    def duration_s(self) -> float:
        return float(self.t[-1] - self.t[0])

    @property
    def touches_obstacle(self) -> bool:
        return self.obstacle_distance is not None and bool((self.obstacle_distance <= 0).any())

    @property
    def failure(self) -> str | None:
        """None when the plan succeeds, else the first reason it does not (a target not solved, the ZMP leaving the
        support polygon, a link in the ground, a link touching an obstacle)."""
        for tg in self.targets:
            if not tg.solved:
                why = self.out_of_range if self.out_of_range is not None else tg.solution.message
                return f"target {tg.name!r} not solved: {why}"
        if self.timing_failure is not None:
            return self.timing_failure
        if self.min_zmp_margin_m < ZMP_MARGIN:
            k = self.stability.argmin
            where = "leaves the support polygon by" if self.min_zmp_margin_m < 0 else "comes within"
            return (f"the ZMP {where} {abs(1000 * self.min_zmp_margin_m):.1f} mm of its edge at t = {self.t[k]:.2f} s "
                    f"(a plan keeps it {1000 * ZMP_MARGIN:.0f} mm inside)")
        if self.min_ground_clearance_m <= -coll.GROUND_TOLERANCE:
            k = int(np.argmin(self.ground_clearance))
            return (f"a neck or head link goes {-1000 * self.min_ground_clearance_m:.1f} mm into the ground at "
                    f"t = {self.t[k]:.2f} s")
        if self.touches_obstacle and self.obstacle_distance is not None:
            k = int(np.argmax(self.obstacle_distance <= 0))
            return f"a link touches an obstacle at t = {self.t[k]:.2f} s"
        return None

    @property
    def success(self) -> bool:
        return self.failure is None


def _subdivide(qs: np.ndarray, step: float, least: int = 1) -> np.ndarray:
    """The waypoints qs (K, n) with each straight segment between two cut into equal pieces, as many as keep every
    joint's change within ``step`` rad and at least ``least``."""
    qs = np.asarray(qs, float)
    out = [qs[:1]]
    for a, b in zip(qs[:-1], qs[1:]):
        pieces = max(least, int(np.ceil(np.abs(b - a).max() / step - 1e-9)))
        out.append(a + (np.arange(1, pieces + 1) / pieces)[:, None] * (b - a))
    return np.concatenate(out)


def _split_steps(qs: np.ndarray, most: float = MAX_WAYPOINT_STEP) -> np.ndarray:
    """The path of waypoints qs (K, n) with every step whose largest joint change exceeds ``most`` rad split into
    equal joint-space steps (the same straight segments, more waypoints)."""
    return _subdivide(qs, most)


def _checked(qs: np.ndarray, step: float = MOVE_CHECK_STEP) -> np.ndarray:
    """The configurations a path of waypoints qs (K, n) is checked at: every waypoint and, along the straight
    segment between two, as many evenly spaced ones as keep each joint's change below ``step`` rad (at least
    DENSIFY)."""
    return _subdivide(qs, step, DENSIFY + 1)


def _densify(qs: np.ndarray, between: int = DENSIFY) -> np.ndarray:
    """The waypoints (..., K, n) with ``between`` evenly spaced configurations inserted between consecutive ones
    (what the motion passes through between the waypoints, to within the interpolation's curvature)."""
    qs = np.asarray(qs, float)
    s = np.arange(between + 1) / (between + 1)
    a, b = qs[..., :-1, :], qs[..., 1:, :]
    fine = a[..., None, :] + s[:, None] * (b - a)[..., None, :]  # (..., K-1, between+1, n)
    fine = fine.reshape(qs.shape[:-2] + (-1, qs.shape[-1]))
    return np.concatenate([fine, qs[..., -1:, :]], axis=-2)


class _Waypoints:
    """Accumulates the path's waypoints (label, q), the pauses and the stops, then times the whole path
    (``motion.timing.retime``: TOPP-RA under the robot's limits and the ZMP) and samples it at the control period."""

    def __init__(self, robot: SnakeRobot, base: BasePlacement, obstacles: Sequence[Any] = ()) -> None:
        self.robot, self.base = robot, base
        self.obstacles = list(obstacles)
        self.labels: list[str] = []
        self.qs: list[np.ndarray] = []
        self.times: list[float] = []  # filled in by sample()
        self.holds: dict[int, float] = {}  # segment index -> pause (s)
        self.stops: list[int] = []  # waypoints where the motion comes to rest
        self.methods: list[tuple[str, str]] = []  # (segment, interpolation used)
        self.timing_failure: str | None = None  # why the path could not be timed, when it could not
        self.lift_index: int | None = None  # the waypoint where the lift from the bending state ends (a stop)
        self.lift_cache: dict | None = None  # timed lifts, kept by the controller
        self._problem: Any = None  # control.whole_body.BodyProblem, made when first needed (_base_margins)
        self._least = (0, 0.0)  # (waypoints counted, s): least_duration's sum so far

    def least_duration(self, velocity: np.ndarray) -> float:
        """s: the least the motion through the waypoints so far can last: each step at the joints' velocity limits
        (rad/s, (n,)) and the holds (the retiming keeps the limits: the timed motion lasts at least this long)."""
        done, total = self._least
        if len(self.qs) > done + 1:
            steps = np.abs(np.diff(np.array(self.qs[max(done - 1, 0):]), axis=0)) / velocity
            total += float(steps.max(axis=1).sum())
            self._least = (len(self.qs), total)
        return total + float(sum(self.holds.values()))

    def start(self, label: str, q: npt.ArrayLike) -> None:
        self.labels, self.qs = [label], [np.asarray(q, float)]
        self._least = (0, 0.0)

    def _append(self, label: str, q: np.ndarray) -> None:
        if np.abs(q - self.qs[-1]).max() <= 1e-12:  # the same configuration: nothing to move
            self.labels[-1] = label
            return
        self.qs.append(q)
        self.labels.append(label)

    def stop(self) -> int:
        """The motion comes to rest at the last waypoint (a target); its index."""
        self.stops.append(len(self.qs) - 1)
        return len(self.qs) - 1

    def move_joint(self, label: str, q: npt.ArrayLike) -> None:
        """A short joint-space step to q (e.g. the next pose along a line); a whole-body move (:meth:`move`) when
        the straight step is not safe throughout."""
        q = np.asarray(q, float)
        step = np.abs(q - self.qs[-1]).max()
        n = max(3, int(np.ceil(step / JOINT_STEP_CHECK)) + 1)
        s = np.linspace(0.0, 1.0, n)[:, None]
        if not self._feasible(self.qs[-1] + s * (q - self.qs[-1])).all():
            self.move(label, q)
            return
        self._append(label, q)

    def move(self, label: str, q: npt.ArrayLike, n: int = 12) -> str:
        """A whole-body move from the last state to q (Section 3.2); returns the method used.

        First the tracking Cartesian interpolation (Eq. 41 with every joint point fitted:
        ``motion.cartesian.tracking_interpolation``), kept when every configuration is safe (above the ground, clear
        of itself and the obstacles, statically stable with DETOUR_MARGIN); else the straight joint-space path;
        else a joint-space path through a safe detour waypoint (see ``_joint_path``). Steps longer than
        MAX_WAYPOINT_STEP are split (:func:`_split_steps`) and every path is checked at least every
        MOVE_CHECK_STEP (:func:`_checked`): the timed motion passes near the straight segments between the
        waypoints only when they are short (a fit that cannot follow the points to q ends in one long jump).
        """
        q = np.asarray(q, float)
        if np.abs(q - self.qs[-1]).max() <= 1e-12:
            self._append(label, q)
            return "none"
        path = _split_steps(tracking_interpolation(self.robot, self.qs[-1], q, n, self.base).q)
        if self._path_feasible(path):
            qs, method = path, "cartesian (Eq. 41, tracked)"
        else:
            qs, method = self._joint_path(self.qs[-1], q, n)
        self.append_path(label, qs, method)
        return method

    def append_path(self, label: str, qs: np.ndarray, method: str) -> None:
        """The configurations qs[1:] of a checked path from the last state (qs[0]), made by ``method``."""
        for k in range(1, len(qs)):
            self._append(label if k == len(qs) - 1 else f"{label} ({k}/{len(qs) - 1})", qs[k])
        self.methods.append((label, method))

    def _margins(self, qs: np.ndarray) -> np.ndarray:
        """Static margins (m) of configurations qs (m, n): the CoM's distance inside the support polygon of every
        link lying on the ground (``contact="ground"``); once the head is up (after the lift: ``lift_index`` set),
        the smaller of that and the base's own (:meth:`_base_margins`): a motion must not lean on a neck or head
        link that touches the ground at a checked configuration and may leave it in between."""
        com = stability.center_of_mass(self.robot, qs, self.base)[:, :2]
        margin = stability.support_margins(self.robot, qs, com, self.base, contact=PLAN_CONTACT)
        if self.lift_index is not None:
            margin = np.minimum(margin, self._base_margins(qs, com))
        return margin

    def _base_margins(self, qs: np.ndarray, com_xy: np.ndarray) -> np.ndarray:
        """Static margins (m) of configurations qs (m, n) with CoM projections com_xy (m, 2) over the support of the
        links that lie on the ground whatever the pose (``control.whole_body.BodyProblem.ground_links``: the base's
        and the neck's before it lifts, flat: their boxes' bottom corners), as ``check_solution`` takes it."""
        from ..control.whole_body import BodyProblem

        if self._problem is None:
            self._problem = BodyProblem(self.robot)
        prob, start = self._problem, self.robot.lift_joints.start
        shapes, which = np.unique(np.round(qs[:, :start], 12), axis=0, return_inverse=True)
        polygons = []
        for shape in shapes:  # those links move with the joints before the lift only
            q = np.zeros(self.robot.n_joints)
            q[:start] = shape
            polygons.append(prob.contact_points(prob.frames(q, self.base))[0][:, :2])
        pts = np.stack(polygons)[np.asarray(which).reshape(-1)]
        return stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool), com_xy)

    def _feasible(self, qs: np.ndarray) -> np.ndarray:
        """(m,) bool: above the ground, statically stable with DETOUR_MARGIN to spare, no two non-neighbouring links
        overlapping, and clear of the obstacles (``geometry.path_check.feasible``: the clearances in one C++ call)."""
        return path_check.feasible(self, qs, DETOUR_MARGIN)

    def _path_feasible(self, path: np.ndarray) -> bool:
        """A path of waypoints whose clearances are proven along its straight segments and whose static margin
        keeps DETOUR_MARGIN at its :func:`_checked` configurations (``geometry.path_check.path_feasible``)."""
        return path_check.path_feasible(self, path, _checked(path), DETOUR_MARGIN)

    def _joint_path(self, qa: np.ndarray, qb: np.ndarray, n: int) -> tuple[np.ndarray, str]:
        """A joint-space path qa -> qb of about n configurations that stays stable and above the ground.

        The straight path when it does; else the shortest of DETOUR_TRIALS two-piece paths through a waypoint
        drawn around the midpoint (the joints from the neck's first lifting joint on perturbed, seeded: plans are
        reproducible; the joints before it keep their straight path, since their links lie on the ground and a
        detour would sweep them across it, the ground's friction pushing the base) whose every
        configuration passes (tried shortest first, DETOUR_BATCH at a time, each screened at DENSIFY
        configurations per step and then checked as densely as a move); else the one with the largest worst
        margin (the scenario's checks report it).
        """
        s = np.linspace(0.0, 1.0, n)[:, None]
        straight = _split_steps(qa + s * (qb - qa))
        if self._path_feasible(straight):
            return straight, "joint space"
        movable = np.arange(self.robot.lift_joints.start, self.robot.parts.head.stop)
        rng = np.random.default_rng(DETOUR_SEED)
        W = np.tile(0.5 * (qa + qb), (DETOUR_TRIALS, 1))
        W[:, movable] += rng.normal(0.0, DETOUR_SPREAD, (DETOUR_TRIALS, len(movable)))
        W = np.clip(W, self.robot.lower, self.robot.upper)
        paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], axis=1)
        length = np.abs(np.diff(paths, axis=1)).sum(axis=(1, 2))
        order = np.argsort(length, kind="stable")
        for batch in np.array_split(order, max(1, len(order) // DETOUR_BATCH)):
            flat = _densify(paths[batch]).reshape(-1, qa.size)
            ok = self._feasible(flat).reshape(len(batch), -1).all(axis=1)
            for k in batch[ok]:
                path = _split_steps(paths[k])
                if self._path_feasible(path):
                    return path, "joint space via a stable detour"
        flat = _densify(paths).reshape(-1, qa.size)
        worst = self._margins(flat).reshape(len(W), -1).min(axis=1)
        return _split_steps(paths[int(np.argmax(worst))]), "joint space (no stable detour found)"

    def hold(self, seconds: float) -> None:
        """A pause of ``seconds`` at the last waypoint (which becomes a stop)."""
        if self.stops[-1:] != [len(self.qs) - 1]:
            self.stop()
        self.holds[len(self.qs) - 1] = float(seconds)
        self.qs.append(self.qs[-1].copy())
        self.labels.append(self.labels[-1] + " (hold)")

    def sample(self, notes: list, timing: dict[str, Any]) -> interp.JointTrajectory:
        """The fastest motion through the waypoints (``motion.timing.retime``, options ``timing``) at 2 ms; fills in
        ``times`` (when each waypoint is reached)."""
        from .timing import retime

        # the plan checks its 2 ms samples itself (_finish: the ZMP by the paper's momenta, the ground, obstacles);
        # the retiming keeps the joint limits between its gridpoints by refining them
        timing = dict(timing, check_samples=False)
        hold_s = np.zeros(len(self.qs) - 1)
        for k, seconds in self.holds.items():
            hold_s[k] = seconds
        Q = np.array(self.qs)
        stops = sorted(set(self.stops))
        try:
            k = self.lift_index if self.lift_index is not None else -1
            if 0 < k < len(Q) - 1 and self.lift_cache is not None:
                # the lift from the bending state is the same for every target from a base of this shape, wherever
                # it lies (retime does not depend on the placement): time it once
                key = (np.round(Q[:k + 1], 9).tobytes(), repr(sorted(timing.items())))  # round-off apart
                lift = self.lift_cache.get(key)
                if lift is None:
                    lift = retime(self.robot, Q[:k + 1], self.base, hold_s=hold_s[:k],
                                  stops=[i for i in stops if i <= k], **timing)
                    if len(self.lift_cache) > KEPT_LIFTS:
                        self.lift_cache.clear()
                    self.lift_cache[key] = lift
                rest = retime(self.robot, Q[k:], self.base, hold_s=hold_s[k:], stops=[i - k for i in stops if i >= k],
                              **timing)
                _check_motion_length(float(lift.t[-1]) + float(rest.t[-1]))
                # the whole motion is sampled again from the pieces' splines: the rest's samples (~400 B each) are
                # dropped first, so that they and the whole motion's are never held at once
                rest = replace(rest, t=rest.t[-1:].copy(), q=rest.q[-1:].copy(), qd=rest.qd[-1:].copy(),
                               qdd=rest.qdd[-1:].copy())
                traj = _concatenate(lift, rest)
            else:
                traj = retime(self.robot, Q, self.base, hold_s=hold_s, stops=stops, **timing)
        except MotionTooLong:  # no slower fallback either: the motion is already too long
            raise
        except Infeasible as exc:  # (the caller's options were checked when plan() began)
            # no motion along this path keeps the limits (e.g. it passes a state that cannot be held): time it at a
            # slow fixed pace so that the plan can still be looked at, and fail it
            self.timing_failure = f"the path cannot be timed within the robot's limits: {exc}"
            move = np.abs(np.diff(np.array(self.qs), axis=0)).max(axis=1)
            # faster than FALLBACK_SPEED when that pace would make the motion longer than a plan may be (the plan
            # fails on its timing either way; its motion must still fit in MAX_SAMPLES samples)
            budget = 0.95 * MAX_MOTION_S - float(hold_s.sum()) - 1e-3 * len(move)
            speed = max(FALLBACK_SPEED, float(move.sum()) / budget) if budget > 0 else FALLBACK_SPEED
            times = np.concatenate([[0.0], np.cumsum(np.maximum(move / speed, hold_s) + 1e-3)])
            _check_motion_length(float(times[-1]), "with its holds")
            self.times = [float(x) for x in times]
            return interp.joint_trajectory(times, np.array(self.qs), method="monotone")
        self.times = [float(x) for x in traj.waypoint_times]
        notes += list(traj.notes)
        return traj


def _check_motion_length(duration_s: float, how: str = "") -> None:
    """MotionTooLong when a motion of ``duration_s`` is longer than :data:`MAX_MOTION_S` (before it is sampled)."""
    if duration_s > MAX_MOTION_S:
        raise MotionTooLong(f"the timed motion lasts {duration_s:.1f} s{' ' + how if how else ''}; at most "
                         f"{MAX_MOTION_S:g} s ({MAX_SAMPLES} samples at {interp.CONTROL_PERIOD:g} s)")


def _concatenate(a: Any, b: Any) -> Any:
    """Two retimed motions (``motion.timing.RetimedTrajectory``), the second starting where and when (at rest) the
    first ends, as one sampled on one 2 ms grid; its ``waypoint_times`` the first's and the second's after its
    first. Of the second's samples only the last is used (its end: when and where)."""
    from .timing import RetimedTrajectory

    offset = float(a.t[-1])
    dt = float(a.t[1] - a.t[0]) if len(a.t) > 1 else interp.CONTROL_PERIOD
    t = interp.sample_times(0.0, offset + float(b.t[-1]), dt)
    first = t <= offset
    arrays = []
    for nu in (0, 1, 2):
        x = np.empty((len(t), a.q.shape[1]))
        x[first] = a.spline(t[first], nu)
        x[~first] = b.spline(t[~first] - offset, nu)
        arrays.append(x)
    arrays[0][-1] = b.q[-1]
    return RetimedTrajectory(t, arrays[0], arrays[1], arrays[2], None,
                             waypoint_times=np.concatenate([a.waypoint_times, b.waypoint_times[1:] + offset]),
                             limits=b.limits, check=None, notes=tuple(a.notes) + tuple(b.notes),
                             solve_time_s=b.solve_time_s)


def _finish(name: str, plan: _Waypoints, targets: Any, t_start: float, obstacles: Sequence[Any] = (),
            notes: Sequence[str] = (), scene: Scene | None = None, timing: dict[str, Any] | None = None,
            stage: Callable[[str, str], None] | None = None) -> Plan:
    robot, base = plan.robot, plan.base
    notes = list(notes)
    stage = stage or (lambda what, message: None)
    stage("timing", f"timing the motion through {len(plan.qs)} waypoints (TOPP-RA under the robot's limits)")
    traj = plan.sample(notes, timing or {})
    t, q, qd = traj.t, traj.q, traj.qd
    del traj  # its accelerations (unused) are freed before the checks
    stage("checks", f"checking the {len(t)} samples of {float(t[-1] - t[0]):.1f} s of motion (ZMP, ground"
                    + (", obstacles)" if obstacles else ")"))
    for tg in targets:  # the waypoint each target was reached at -> when
        tg.time_s = plan.times[tg.time_s]
    # the ZMP, the ground and the obstacles at every sample, in C++ (geometry.path_check.finish_checks)
    dyn, clearance, distance = path_check.finish_checks(robot, base, t, q, qd, obstacles, PLAN_CONTACT)
    states = [(lab, float(when), qk) for lab, when, qk in zip(plan.labels, plan.times, plan.qs)]
    return Plan(name=name, robot=robot, base=base, t=t, q=q, qd=qd, states=states, targets=targets,
                stability=dyn, ground_clearance=clearance, obstacles=list(obstacles), obstacle_distance=distance,
                planning_time_s=time.perf_counter() - t_start, notes=notes, segments=list(plan.methods), scene=scene,
                timing_failure=plan.timing_failure)


def bending_state(controller: HeadController, q_shape: np.ndarray | None = None) -> np.ndarray:
    """The bending state (Figs. 17b, 22a): the base on its arc and the neck and head curled flat on the ground
    inside it, so that lifting them keeps their mass over the base (n,).

    On the default robot the neck and head (1.7 kg) outweigh the base (1.5 kg): lifted from a straight line
    beyond P0 they tip the body. Here the pitch joints are 0 (everything lies on the ground) and the neck and
    head's yaw joints are chosen on a grid (15 deg, coarser for many joints) for the largest static margin over the base's support polygon
    alone (the support left once they are lifted), among the curls in which no two non-neighbouring links
    overlap. Deterministic. ``q_shape``: a configuration whose base (and the neck's links that stay on the ground)
    give the shape on the ground (default: the controller's initial configuration)."""
    robot = controller.robot
    shape = controller.q_initial if q_shape is None else np.asarray(q_shape, float)
    key = shape[:robot.lift_joints.start].tobytes()
    cache = controller.__dict__.setdefault("_bending_states", {})
    if key not in cache:
        cache[key] = ground_curl(robot, shape)
    return cache[key].copy()


def ground_curl(robot: SnakeRobot, shape: np.ndarray) -> np.ndarray:
    """:func:`bending_state` for the base shape of ``shape`` (n,), uncached. ValueError when no curl is stable."""
    q = np.zeros(robot.n_joints)
    # the base, and the links before the first pitch joint of the neck, which cannot leave the ground: their yaw
    # joints keep the shape's angles, or the lift would sweep those links across the ground and the friction would
    # push the base
    first_pitch = robot.lift_joints.start
    q[:first_pitch] = shape[:first_pitch]
    up = np.arange(robot.parts.neck.start, robot.parts.head.stop)
    yaw = np.array([j for j in up if robot.joint_kinds[j] == "yaw" and j > first_pitch], int)  # bend when flat
    if len(yaw) == 0:
        return q
    # the finest grid (at most BENDING_GRID_DEG) with at most BENDING_COMBINATIONS curls
    per_joint = max(3, min(int(round(180.0 / BENDING_GRID_DEG)) + 1,
                           int(np.floor(BENDING_COMBINATIONS ** (1.0 / len(yaw)) + 1e-9))))
    combos = np.stack(np.meshgrid(*[np.linspace(0.0, 1.0, per_joint)] * len(yaw), indexing="ij"), -1)
    combos = combos.reshape(-1, len(yaw))
    lo, hi = np.maximum(robot.lower[yaw], -np.pi / 2), np.minimum(robot.upper[yaw], np.pi / 2)
    qs = np.tile(q, (len(combos), 1))
    qs[:, yaw] = lo + combos * (hi - lo)
    poly = stability.support_polygon(robot, q)  # the base's, placement-independent in its own frame
    com = stability.center_of_mass(robot, qs)
    pts = np.broadcast_to(poly, (len(qs),) + poly.shape)
    margin = stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool), com[:, :2])
    order = np.argsort(-margin)
    stable = order[margin[order] > 0]
    for chunk in np.array_split(stable, max(1, stable.size // 500 + 1)) if stable.size else []:
        ok = coll.self_clearance(robot, qs[chunk]) > BENDING_CLEARANCE
        if ok.any():
            return qs[chunk[np.argmax(ok)]]
    raise Infeasible("no curl of the neck and head on the ground keeps their mass over the base (the base is too "
                     "short or light for them: 'snakehead info --robot FILE' suggests a split of the parts that works)")



#: The farthest (m) the planner moves the base by locomotion before a plan (a relocation). A target farther than
#: this plus the body's length from where the base lies is out of range: the plan fails at once and says so.
MAX_RELOCATION_M = 10.0


def _out_of_range(robot: SnakeRobot, start: BasePlacement, targets: Sequence[Any]) -> str | None:
    """Why no relocation can reach ``targets`` from ``start`` (None: every one is in range)."""
    for t in targets:
        d = float(np.hypot(t.position[0] - start.x, t.position[1] - start.y))
        if d > MAX_RELOCATION_M + robot.body_length:
            return (f"out of range: it is {d:.4g} m from the base; a relocation moves the base at most "
                    f"{MAX_RELOCATION_M:g} m (snakehead.motion.planner.MAX_RELOCATION_M) and the body is "
                    f"{robot.body_length:.3g} m long")
    return None


@dataclass(frozen=True)
class Relocation:
    """A change of base that the targets need, carried out before the plan by locomotion (the paper's rolling gait
    or turning in place, Section 3.3 (3)): from placement ``start`` to ``base``, with the base's flat shape changed
    when ``shape_changed``; ``reason`` says why (what failed from the start)."""

    start: BasePlacement
    base: BasePlacement
    shape_changed: bool
    reason: str

    def as_dict(self) -> dict:
        return {"from": {"x_m": self.start.x, "y_m": self.start.y, "yaw_rad": self.start.yaw},
                "to": {"x_m": self.base.x, "y_m": self.base.y, "yaw_rad": self.base.yaw},
                "distance_m": float(np.hypot(self.base.x - self.start.x, self.base.y - self.start.y)),
                "shape_changed": self.shape_changed, "reason": self.reason}


def _shape_of(robot: SnakeRobot, q_shape: np.ndarray, q_rest: np.ndarray) -> np.ndarray:
    """``q_rest`` with the joints of the links lying on the ground (the base's, and the neck's before it lifts)
    taken from ``q_shape``."""
    q = np.asarray(q_rest, float).copy()
    q[:robot.lift_joints.start] = q_shape[:robot.lift_joints.start]
    return q


def choose_base(controller: HeadController, targets: Any, obstacles: Sequence[Any] = (),
                allow_relocation: bool = True, base_shape: npt.ArrayLike | None = None, *,
                solved: dict | None = None) -> tuple[BasePlacement, np.ndarray, Relocation | None, list[str]]:
    """One base (placement and flat shape) for a whole scene: the controller's when every target is solved from it
    (:func:`~snakehead.control.whole_body.solve_target` with the base kept) and the body starts clear of the
    obstacles; else the first base that the whole-body solve with the base moved finds for a target (the failing
    one first) from which every target is solved, among the bases whose flat shape holds a stable curl of the neck
    and head (:func:`bending_state`: the plan lifts them from it; a straight base, e.g., may hold none). ``base_shape``: a configuration whose base joints (and those of
    the neck's links that stay on the ground) give the base's flat shape at the controller's placement (default:
    the controller's initial configuration's). Returns the placement, a configuration with the base's shape
    (the initial configuration's otherwise), the relocation (None when the base stays) and notes. ``solved``: a
    dict that keeps the solves with the base kept (:func:`_solve_kept`) for the plan to reuse."""
    from ..control.whole_body import solve_checked_target

    robot = controller.robot
    obstacles = list(obstacles)
    targets = list(targets)

    def clear(q: np.ndarray, b: Any) -> bool:
        if not obstacles:
            return True
        return bool(coll.collision_check(robot, q[None], obstacles, b, exact_within=0.005).distance[0]
                    > OBSTACLE_CLEARANCE)

    def failing(b: Any, q_shape: Any) -> Any:
        """The first target not solved from this base (None: all are), or why the start state is not usable
        ("no curl": the base's shape holds no stable curl of the neck and head; "the start": it is in an obstacle)."""
        try:
            q_bend = bending_state(controller, q_shape)
        except Infeasible:
            return "no curl", None
        if not clear(q_bend, b):
            return "the start", None
        for t in targets:
            sol = _solve_kept(controller, t.position, t.direction, q_shape, b, obstacles, solved)
            if not sol.success:
                return t, sol
        return None, None

    start, q0 = controller.base, controller.q_initial
    if base_shape is not None:
        q0 = _shape_of(robot, joint_vector(base_shape, robot.n_joints, "base_shape"), q0)
    first, why = failing(start, q0)
    if first is None:
        return start, q0.copy(), None, []
    reason = ("the start state touches an obstacle" if first == "the start" else
              "no curl of the neck and head on the ground is stable on the start's base" if first == "no curl" else
              f"target {first.name!r} is not reached from the start ({why.reason})")
    if not allow_relocation:
        return start, q0.copy(), None, [f"the base is kept (no relocation allowed): {reason}"]
    far = _out_of_range(robot, start, targets)
    if far is not None:
        return start, q0.copy(), None, [f"no relocation: a target is {far}"]
    # a relocated base must hold a stable curl of the neck and head (the bending state the plan lifts them from):
    # the whole-body solve is told so, and looks further than a shape (e.g. a straight base) that holds none
    no_curl = controller.__dict__.setdefault("_shapes_without_curl", set())

    def has_curl(q: np.ndarray) -> bool:
        key = np.round(q[:robot.lift_joints.start], 12).tobytes()
        if key in no_curl:
            return False
        try:
            bending_state(controller, q)
        except Infeasible:
            no_curl.add(key)
            return False
        return True

    order = ([first] if first not in ("the start", "no curl") else []) + [t for t in targets if t is not first]
    for t in order:
        sol = solve_checked_target(controller, t.position, t.direction, q_prev=q0, base=start, obstacles=obstacles,
                           allow_base_move=True, problem=controller.body_problem, min_margin=DETOUR_MARGIN,
                           shape_ok=has_curl)
        if not sol.success or (sol.base == start and np.array_equal(sol.q[:robot.lift_joints.start],
                                                                   q0[:robot.lift_joints.start])):
            continue
        if np.hypot(sol.base.x - start.x, sol.base.y - start.y) > MAX_RELOCATION_M:
            continue
        q_shape = _shape_of(robot, sol.q, q0)
        if failing(sol.base, q_shape)[0] is None:
            changed = not np.allclose(q_shape[:robot.lift_joints.start], q0[:robot.lift_joints.start])
            reloc = Relocation(start, sol.base, changed, reason)
            return sol.base, q_shape, reloc, [f"the base is relocated to {sol.base}"
                                              + (" with another flat shape" if changed else "")
                                              + f" (by locomotion, before the plan): {reason}"]
    return start, q0.copy(), None, [f"no single base reaches every target: {reason}"]


#: The retiming options ``plan(timing=...)`` takes; the planner sets the others (holds, stops, the 2 ms control
#: period: a coarser period would leave the motion between samples unchecked).
TIMING_OPTIONS = ("velocity_limit", "acceleration_limit", "torque_limit", "zmp_margin", "friction")


def _check_timing(robot: SnakeRobot, timing: dict[str, Any]) -> None:
    """ValueError/TypeError naming an unknown option of ``timing`` or a bad value (``motion.timing.resolve_limits``)."""
    from .timing import resolve_limits

    unknown = [key for key in timing if key not in TIMING_OPTIONS]
    if unknown:
        raise InputError(f"timing has no option {unknown[0]!r}; its options are {', '.join(TIMING_OPTIONS)}")
    resolve_limits(robot, **timing)


#: The most poses solved along one straight-line approach (approach = "line"; each is a whole-body solve).
MAX_LINE_POSES = 2000


def _check_lines(targets: Sequence[Target]) -> None:
    """InputError for a target approached along a line (approach = "line") in more than MAX_LINE_POSES steps."""
    for a, b in zip(targets, targets[1:]):
        length = float(np.linalg.norm(b.position - a.position))
        if b.approach == "line" and length / b.step_m > MAX_LINE_POSES:  # each pose is a whole-body solve
            raise InputError(f"target {b.name!r}: the line from {a.name!r} is {length:.4g} m long; at step_m = "
                             f"{b.step_m:g} m that is {length / b.step_m:.3g} poses, at most {MAX_LINE_POSES}: take "
                             "a larger step_m")


def _line_poses(a: Target, b: Target) -> list[np.ndarray]:
    """Positions from target ``a`` to target ``b`` every ``b.step_m`` m (b included, a excluded; their number was
    checked by :func:`_check_lines`)."""
    d = b.position - a.position
    length = float(np.linalg.norm(d))
    n = int(np.ceil(length / b.step_m - 1e-9))
    steps = [min(k * b.step_m, length) for k in range(1, n + 1)]
    if length > 0 and steps and abs(steps[-1] - length) > 1e-12:
        steps.append(length)
    return [a.position + (s / length) * d for s in steps] if length > 0 else [b.position.copy()]


def _solve_kept(controller: HeadController, position: np.ndarray, direction: np.ndarray, q_prev: np.ndarray,
                base: BasePlacement, obstacles: Sequence[Any], solved: dict | None, near: bool = False) -> Any:
    """``control.whole_body.solve_target`` with the base kept, kept in ``solved`` (one plan's: its obstacles are
    fixed) so that choose_base's solves of the chosen base are not repeated by the plan (the solve is
    deterministic: the same inputs give the same solution)."""
    from ..control.whole_body import solve_checked_target

    key = (np.asarray(position, float).tobytes(), np.asarray(direction, float).tobytes(),
           np.asarray(q_prev, float).tobytes(), base, near)
    if solved is not None and key in solved:
        return solved[key]
    sol = solve_checked_target(controller, position, direction, q_prev=q_prev, base=base, obstacles=obstacles,
                       allow_base_move=False, problem=controller.body_problem, min_margin=DETOUR_MARGIN, near=near)
    if solved is not None:
        solved[key] = sol
    return sol


def _solve(controller: HeadController, position: np.ndarray, direction: np.ndarray, q_prev: np.ndarray,
           base: BasePlacement, obstacles: Sequence[Any], name: str, notes: list, near: bool = False,
           solved: dict | None = None) -> Any:
    """One target with the base kept (:func:`_solve_kept`); a note when it fails."""
    sol = _solve_kept(controller, position, direction, q_prev, base, obstacles, solved, near)
    if not sol.success:
        notes.append(f"{name}: {sol.message}")
    return sol


def as_scene(targets: Any, *, obstacles: Sequence[Any] = (), base: BasePlacement | None = None) -> Scene:
    """A :class:`Scene` from a scene, a scene file's path, or (position, direction) pairs (with ``obstacles``)."""
    import os

    from .._validate import sequence
    from ..scenes.scene import load_scene

    if isinstance(targets, Scene):
        scene = targets
        obstacles = sequence(obstacles, "obstacles")
        if obstacles:
            scene = Scene(name=scene.name, targets=scene.targets, obstacles=tuple(scene.obstacles) + obstacles,
                          robot_file=scene.robot_file, base=scene.base, description=scene.description, path=scene.path)
        return scene
    if isinstance(targets, (str, os.PathLike)):
        return as_scene(load_scene(targets), obstacles=obstacles, base=base)
    return Scene.from_targets(targets, obstacles=obstacles, base=base)


@entry_point
def plan(targets: Scene | str | os.PathLike[str] | Sequence[tuple[npt.ArrayLike, npt.ArrayLike]], *,
         robot: SnakeRobot | None = None, controller: HeadController | None = None,
         obstacles: Sequence[BoxObstacle | WallWithHole | MeshObstacle] = (), base: BasePlacement | None = None,
         method: str = "rotated", seed: int | None = 1, allow_relocation: bool = True,
         timing: dict[str, Any] | None = None, base_shape: npt.ArrayLike | None = None,
         start_q: npt.ArrayLike | None = None, progress: ProgressCallback | None = None) -> Plan:
    """Plan the head through ``targets`` and check the motion (the control process of Section 3.3).

    Parameters
    ----------
    targets : a :class:`~snakehead.scenes.Scene`, a scene file's path, or (position, direction) pairs (m, world;
        the direction is the head's x-axis), each then held 1 s.
    robot : the snake (default: the scene's robot file, else ``SnakeRobot.default()``).
    controller : a :class:`~snakehead.control.HeadController` to solve the head with (default: one for ``robot``
        with its head's map, ``method`` and ``seed``).
    obstacles : more obstacles (``geometry.BoxObstacle``, ``geometry.WallWithHole``) besides the scene's.
    base : where the base lies at first (default: the scene's, else ``BasePlacement()``); when a target cannot be
        reached from there, the planner chooses another placement (and flat shape) that reaches every target: the
        plan starts there and ``relocation`` says what locomotion must do first (unless ``allow_relocation`` is
        False: then the base stays and the plan fails on the targets it cannot reach).
    method : the head IK: "rotated" (the paper's Fig. 9) or "free_roll".
    seed : the head TRAC-IK's seed (the plan is a function of it); None for unseeded.
    timing : options of the time-optimal retiming (``motion.timing.retime``: ``acceleration_limit`` rad/s^2,
        ``velocity_limit`` rad/s, ``torque_limit`` N m, ``zmp_margin`` m, ``friction``); its defaults otherwise.
    base_shape : a configuration (n,) whose base joints (and those of the neck's links that stay on the ground) give
        the base's flat shape at ``base`` (default: the controller's initial configuration's): a closed loop that
        curled the body into a relocation's shape plans on from it (``snakehead.sim.loop``).
    start_q : the configuration (n,) the plan starts from instead of the bending state it would choose: the body as
        it lies (measured) in a bending state on the ground, so that the plan starts where the robot is (a closed
        loop, ``snakehead.sim.loop``). Its base shape is ``base_shape``'s default. Used when the base stays (no
        relocation); a note says so otherwise.
    progress : called as ``progress(record)`` with a :class:`PlanProgress` after each target is solved (in the
        scene's order) and when each stage over the whole plan begins (choosing the base, the timing, the checks);
        an exception it raises stops the plan.

    Bounds, checked before anything is solved (``snakehead.InputError`` naming the scene): at most
    ``scenes.MAX_TARGETS`` (1000) targets; the targets' holds at most :data:`MAX_MOTION_S` (2000 s: MAX_SAMPLES
    samples at 2 ms) together; at most :data:`MAX_POSES` poses solved in all (the targets and the poses along their
    line approaches). The motion's length is checked again after each target is solved (the holds and the least
    time the joints' velocity limits allow for the moves so far) and while the path is timed, before it is sampled.

    Memory grows with the motion's 2 ms samples, not with the targets: the plan keeps t, q, qd and the checks'
    results, ~370 bytes per sample on the 16-joint default robot (8 + 2 x 128 for t, q, qd; ~105 for the ZMP, its
    margin, the momenta, the CoM and the ground clearance); the world frames of the samples (2.5 kB each) are made
    and dropped a chunk at a time (``dynamics.stability.SAMPLE_CHUNK``). Measured peak of ``snakehead plan --no-sim``
    (bench/many_targets.py, figures included): ~300 MiB + ~0.75 kB per sample, e.g. 100 targets, 556 s of motion,
    277,699 samples: 498 MiB; at MAX_SAMPLES (2000 s) about 1 GiB.

    Returns a :class:`Plan` (``success``, ``failure``, ``t``, ``q``, ``targets`` with their errors,
    ``min_zmp_margin_m``, ``min_ground_clearance_m``, ``duration_s``, ``planning_time_s``).
    """
    t_start = time.perf_counter()
    scene = as_scene(targets, obstacles=obstacles, base=base)
    if progress is not None and not callable(progress):
        raise InputTypeError(f"progress must be a function of a PlanProgress (or None), got {type(progress).__name__}")
    lines = _check_size(scene)  # before anything is solved
    if timing is not None and not isinstance(timing, dict):
        raise InputTypeError(f"timing must be a dict of retime's options, got {type(timing).__name__}")
    # checked even when a controller (with its own method and seed) is given: a bad value is a mistake either way
    if not isinstance(method, str) or method not in ("rotated", "free_roll"):
        raise InputError(f"method must be 'rotated' or 'free_roll', got {method!r}")
    if seed is not None:
        integer(seed, "seed", least=0, most=2**64 - 1)
    if not isinstance(allow_relocation, (bool, np.bool_)):  # "False" or None would pass a truth test
        raise InputTypeError(f"allow_relocation must be True or False, got {type(allow_relocation).__name__} "
                        f"{allow_relocation!r}")
    if controller is not None:
        if not isinstance(controller, HeadController):
            raise InputTypeError(f"controller must be a HeadController, got {type(controller).__name__}")
        if robot is not None and robot is not controller.robot:
            raise InputError("give a robot or a controller (whose robot is used), not both")
        chosen = base if base is not None else scene.base
        if chosen is not None:
            controller.base = chosen
    else:
        if robot is None:
            robot = SnakeRobot.from_file(scene.robot_file) if scene.robot_file is not None else SnakeRobot.default()
        elif not isinstance(robot, SnakeRobot):
            raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
        controller = HeadController(robot, base_pose=base if base is not None else scene.base, method=method,
                                    seed=seed)
    robot = controller.robot
    if timing:  # checked before anything is planned: a bad option is the caller's, found at once
        _check_timing(robot, timing)
    obstacles = list(scene.obstacles)
    notes: list[str] = []
    if controller.dexterous_threshold < 100.0:
        notes.append(controller.dexterous_note)
    if start_q is not None:
        start_q = joint_vector(start_q, robot.n_joints, "start_q")
        if base_shape is None:
            base_shape = start_q
    if base_shape is not None:
        base_shape = joint_vector(base_shape, robot.n_joints, "base_shape")
    inputs_checked()  # from here on an InputError would be a bug of the planner's (the entry point says so)
    scene_targets = scene.targets
    count = len(scene_targets)
    from .timing import resolve_limits

    velocity = resolve_limits(robot, **(timing or {})).velocity  # for the least duration of the moves so far

    def stage(what: str, message: str) -> None:
        if progress is not None:
            progress(PlanProgress("stage", what, count=count, elapsed_s=time.perf_counter() - t_start,
                                  message=message))

    def done(k: int, sol: Any, seconds: float) -> None:
        """Target k (0-based) is solved and the move to it planned: tell progress; MotionTooLong once the motion
        so far cannot fit in MAX_MOTION_S (the scene's input was valid: its moves only turn out too long)."""
        tg = scene_targets[k]
        if progress is not None:
            progress(PlanProgress("target", tg.name, k + 1, count, bool(sol.success), seconds,
                                  time.perf_counter() - t_start, "" if sol.success else str(sol.message)))
        least = way.least_duration(velocity)
        if least > MAX_MOTION_S:
            raise MotionTooLong(f"scene {scene.name!r}: the motion to its target {k + 1} of {count} ({tg.name!r}) lasts "
                             f"at least {least:.0f} s (the moves at the joints' velocity limits and the holds); a plan "
                             f"lasts at most {MAX_MOTION_S:g} s (MAX_MOTION_S): split the scene into scenes planned "
                             "one after the other")

    solved: dict = {}  # the solves with the base kept, shared by choose_base and the targets below
    reported = len(scene.reported)
    stage("base", f"solving the {reported} target{'' if reported == 1 else 's'} from the start to choose the base")
    chosen, q_shape, relocation, base_notes = choose_base(controller, scene.reported, obstacles, allow_relocation,
                                                          base_shape, solved=solved)
    notes += base_notes
    way = _Waypoints(robot, chosen, obstacles)
    if start_q is not None and relocation is not None:
        notes.append("start_q is not used: the plan starts at the relocated base, in its bending state")
        start_q = None
    way.start("bending state", bending_state(controller, q_shape) if start_q is None else start_q)
    # the initial state of Section 3.3 (1) (the head lifted on its Bezier) with the base's shape, when it is a safe
    # state there; else the lift goes straight to the first target
    q = _shape_of(robot, q_shape, controller.q_initial)
    if way._feasible(q[None])[0] and (not obstacles or coll.collision_check(
            robot, q[None], obstacles, chosen, exact_within=0.005).distance[0] > OBSTACLE_CLEARANCE):
        # the lift's path, like its timing, is the same for every plan from a base of this shape wherever it lies
        # (obstacles apart: with them it is checked again)
        lifts = controller.__dict__.setdefault("_lift_paths", {})
        key = (np.round(way.qs[-1], 9).tobytes(), np.round(q, 9).tobytes())
        kept = lifts.get(key) if not obstacles else None  # (one lookup: another thread may clear the dict)
        if kept is not None:
            way.append_path("initial state (head lifted)", *kept)
        else:
            first = len(way.qs) - 1
            method = way.move("initial state (head lifted)", q, n=LIFT_STEPS)
            if not obstacles:
                if len(lifts) > KEPT_LIFTS:
                    lifts.clear()
                lifts[key] = (np.array(way.qs[first:]), method)
        way.lift_index = way.stop()  # the lift comes to rest in the initial state (Fig. 17c-d)
        way.lift_cache = controller.__dict__.setdefault("_timed_lifts", {})
    else:
        q = way.qs[-1]
    results: list[TargetResult] = []
    k = 0
    while k < len(scene_targets):
        # a run: this target and the following ones approached along a line from it
        end = k
        while end + 1 < len(scene_targets) and scene_targets[end + 1].approach == "line":
            end += 1
        if end == k:
            tg = scene_targets[k]
            clock = time.perf_counter()
            sol = _solve(controller, tg.position, tg.direction, q, chosen, obstacles, tg.name, notes, solved=solved)
            way.move(tg.name, sol.q)
            q = sol.q
            if not tg.via:  # time_s holds the waypoint's index until the path is timed (_finish)
                results.append(TargetResult(tg.name, tg.position, tg.direction, way.stop(), sol))
            if tg.hold_s > 0:
                way.hold(tg.hold_s)
            done(k, sol, time.perf_counter() - clock)
            k += 1
            continue
        # poses along the lines, solved backwards from the deepest (the most constrained, e.g. only the head link in
        # a hole) out to the run's first target, each from the previous joints: a branch of solutions that clears
        # an obstacle deep in it also clears it further out, while one chosen from the outside may run into it
        poses: list[tuple[str, np.ndarray, np.ndarray, Target | None]] = [
            (scene_targets[k].name, scene_targets[k].position, scene_targets[k].direction, scene_targets[k])]
        owner = [k]  # the scene target each pose leads to
        for j in range(k + 1, end + 1):
            line = lines[j]
            for m, p in enumerate(line):
                last = m == len(line) - 1
                label = scene_targets[j].name if last else f"{scene_targets[j].name} ({m + 1}/{len(line)})"
                poses.append((label, p, scene_targets[j].direction, scene_targets[j] if last else None))
                owner.append(j)
        seconds = dict.fromkeys(range(k, end + 1), 0.0)  # each target's share of the run's solves and moves
        sols: list = [None] * len(poses)
        q_back = q
        for m in range(len(poses) - 1, -1, -1):
            clock = time.perf_counter()
            label, p, d, _ = poses[m]
            sols[m] = _solve(controller, p, d, q_back, chosen, obstacles, label, notes, near=m < len(poses) - 1)
            if sols[m].success:
                q_back = sols[m].q
            seconds[owner[m]] += time.perf_counter() - clock
        for m, (label, p, d, line_target) in enumerate(poses):
            clock = time.perf_counter()
            if m == 0:
                way.move(label, sols[m].q)
            else:
                way.move_joint(label, sols[m].q)
            if line_target is not None:
                if not line_target.via:
                    results.append(TargetResult(line_target.name, line_target.position, line_target.direction,
                                                way.stop(), sols[m]))
                if line_target.hold_s > 0:
                    way.hold(line_target.hold_s)
            seconds[owner[m]] += time.perf_counter() - clock
            if line_target is not None:
                done(owner[m], sols[m], seconds[owner[m]])
        q = sols[-1].q
        k = end + 1
    try:
        plan = _finish(scene.name, way, results, t_start, obstacles=obstacles, notes=notes, scene=scene, timing=timing,
                       stage=stage)
    except MotionTooLong as exc:
        raise MotionTooLong(f"scene {scene.name!r}: {exc}: split the scene into scenes planned one after the other"
                            ) from None
    plan.relocation = relocation
    if allow_relocation and relocation is None:
        plan.out_of_range = _out_of_range(robot, chosen, scene.reported)
    return plan


def _check_size(scene: Scene) -> dict[int, list[np.ndarray]]:
    """InputError (naming the scene) for a scene too large to plan, before anything is solved (see :func:`plan`);
    the poses along its line approaches (target index -> positions), which are counted here."""
    from ..scenes.scene import check_target_count

    targets = scene.targets
    check_target_count(len(targets), f"scene {scene.name!r}")
    _check_lines(targets)  # before the poses along the lines are made
    hold = float(sum(t.hold_s for t in targets))
    if hold > MAX_MOTION_S:
        raise InputError(f"scene {scene.name!r}: its targets' hold_s add up to {hold:g} s; a plan's motion lasts at "
                         f"most {MAX_MOTION_S:g} s (MAX_MOTION_S: {MAX_SAMPLES} samples at "
                         f"{interp.CONTROL_PERIOD:g} s): split the scene into scenes planned one after the other")
    lines = {j: _line_poses(targets[j - 1], targets[j]) for j in range(1, len(targets)) if targets[j].approach == "line"}
    poses = len(targets) + sum(len(line) - 1 for line in lines.values())
    if poses > MAX_POSES:
        raise InputError(f"scene {scene.name!r}: its {len(targets)} targets and the poses along their line approaches "
                         f"are {poses} whole-body solves; at most {MAX_POSES} (MAX_POSES): take a larger step_m or "
                         "split the scene")
    return lines
