"""The path a plan is built of: waypoints joined by checked whole-body moves (Section 3.2), with stable detours
where the straight path is not safe, pauses and stops, then timed by the time-optimal retiming and sampled at the
2 ms control period (:class:`Waypoints`)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import Infeasible, MotionTooLong
from ..collision import path_proof
from ..dynamics import stability
from ..margins import DETOUR_MARGIN
from ..model.robot import BasePlacement, SnakeRobot
from ..retiming.timing import RetimedTrajectory, retime
from ..solve.whole_body import BodyProblem
from ..trajectory import interpolation as interp
from ..trajectory.cartesian import tracking_interpolation
from . import motion_checks, plan_bounds
from .plan_bounds import check_motion_length
from .plan_cache import KeptMap

#: The contact model plans are checked with (``dynamics.stability.support_polygon``): every link lying on the ground.
PLAN_CONTACT = "ground"
DETOUR_TRIALS = 256  # candidate detour waypoints tried for a move whose straight path is unstable
DETOUR_SPREAD = 0.4  # rad: spread of the neck and head joints of a detour waypoint around the midpoint
DETOUR_SEED = 20211  # fixed: the same inputs give the same plan
JOINT_STEP_CHECK = 0.02  # rad: a joint-space step is checked at least this densely
FALLBACK_SPEED = 0.1  # rad/s: the pace of a path that the retiming cannot time (the plan then fails; faster when
#                        the motion would be longer than MAX_MOTION_S)
DENSIFY = 3  # configurations checked between consecutive waypoints of a move, at least
MOVE_CHECK_STEP = 0.05  # rad: a move's configurations are checked at most this far apart (largest joint change)
# rad: a move's steps longer than this (largest joint change) are split into equal ones: the clearance proof's first
# sampling, so that it evaluates the waypoints themselves
MAX_WAYPOINT_STEP = path_proof.PATH_FIRST_STEP
DETOUR_BATCH = 16  # detour candidates screened at once, shortest first
#: A move whose tracked path fails its check and that finds no stable joint-space detour either is fitted once more
#: with this many times the samples: between two samples the path is a straight joint segment, and where thick links
#: fold past each other (RSNAKE-style cylinders) a coarse fit can dip into itself between samples 3 mm apart. (Not
#: before the detours: a denser fit times to a longer motion than a detour that passes, 16.1 s against 12.8 s.)
TRACKING_RETRY_FACTOR = 2
#: The methods of a move (:meth:`Waypoints.move`): the tracked interpolation, and the joint-space path that is kept
#: when no detour passes (the plan's checks then fail it).
TRACKED = "cartesian (Eq. 41, tracked)"
NO_DETOUR = "joint space (no stable detour found)"
MARGIN_TIE = 1e-12  # m: smallest margins this close are equal (their round-off differs with the batch)


def _subdivide(qs: np.ndarray, step: float, least: int = 1) -> np.ndarray:
    """The waypoints qs (K, n) with each straight segment between two cut into equal pieces, as many as keep every
    joint's change within ``step`` rad and at least ``least``."""
    qs = np.asarray(qs, float)
    out = [qs[:1]]
    for a, b in zip(qs[:-1], qs[1:]):
        pieces = max(least, int(np.ceil(np.abs(b - a).max() / step - 1e-9)))
        out.append(a + (np.arange(1, pieces + 1) / pieces)[:, None] * (b - a))
    return np.concatenate(out)


def split_steps(qs: np.ndarray, most: float = MAX_WAYPOINT_STEP) -> np.ndarray:
    """The path of waypoints qs (K, n) with every step whose largest joint change exceeds ``most`` rad split into
    equal joint-space steps (the same straight segments, more waypoints)."""
    return _subdivide(qs, most)


def check_points(qs: np.ndarray, step: float = MOVE_CHECK_STEP) -> np.ndarray:
    """The configurations a path of waypoints qs (K, n) is checked at: every waypoint and, along the straight
    segment between two, as many evenly spaced ones as keep each joint's change below ``step`` rad (at least
    DENSIFY)."""
    return _subdivide(qs, step, DENSIFY + 1)


def densify(qs: np.ndarray, between: int = DENSIFY) -> np.ndarray:
    """The waypoints (..., K, n) with ``between`` evenly spaced configurations inserted between consecutive ones
    (what the motion passes through between the waypoints, to within the interpolation's curvature)."""
    qs = np.asarray(qs, float)
    s = np.arange(between + 1) / (between + 1)
    a, b = qs[..., :-1, :], qs[..., 1:, :]
    fine = a[..., None, :] + s[:, None] * (b - a)[..., None, :]  # (..., K-1, between+1, n)
    fine = fine.reshape(qs.shape[:-2] + (-1, qs.shape[-1]))
    return np.concatenate([fine, qs[..., -1:, :]], axis=-2)


class Waypoints:
    """Accumulates the path's waypoints (label, q), the pauses and the stops, then times the whole path
    (``retiming.timing.retime``: TOPP-RA under the robot's limits and the ZMP) and samples it at the control period."""
    def __init__(self, robot: SnakeRobot, base: BasePlacement, obstacles: Sequence[Any] = ()) -> None:
        self.robot, self.base = robot, base
        self.obstacles = list(obstacles)
        self._checker: _core.PathChecker | None = None  # built when first needed (checker)
        self.labels: list[str] = []
        self.qs: list[np.ndarray] = []
        self.times: list[float] = []  # filled in by sample()
        self.holds: dict[int, float] = {}  # segment index -> pause (s)
        self.stops: list[int] = []  # waypoints where the motion comes to rest
        self.methods: list[tuple[str, str]] = []  # (segment, interpolation used)
        self.timing_failure: str | None = None  # why the path could not be timed, when it could not
        self.lift_index: int | None = None  # the waypoint where the lift from the bending state ends (a stop)
        self.lift_cache: KeptMap[tuple[bytes, str], Any] | None = None  # timed lifts: plan_cache_of(controller)'s
        # the lift's part of the ZMP check per placement: plan_cache_of(controller)'s checked_lifts (finish_checks)
        self.checked_lifts: KeptMap[tuple[bytes, str], stability.KeptSamples] | None = None
        self._problem: Any = None  # solve.whole_body.BodyProblem, made when first needed (_base_margins)
        # the timed lift's key in lift_cache and its samples at the start of the motion, when sample() used a kept
        # lift (finish_checks keeps their part of the ZMP check there too)
        self._lift_rows: tuple[tuple[bytes, str], int] | None = None
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
        if not self.feasible(self.qs[-1] + s * (q - self.qs[-1])).all():
            self.move(label, q)
            return
        self._append(label, q)

    def move(self, label: str, q: npt.ArrayLike, n: int = 12) -> str:
        """A whole-body move from the last state to q (Section 3.2); returns the method used.

        First the tracking Cartesian interpolation (Eq. 41 with every joint point fitted:
        ``trajectory.cartesian.tracking_interpolation``), kept when every configuration is safe (above the ground, clear
        of itself and the obstacles, statically stable with DETOUR_MARGIN); else the straight joint-space path;
        else a joint-space path through a safe detour waypoint (see ``_joint_path``); else the tracked interpolation
        with TRACKING_RETRY_FACTOR times the samples, when it passes. Steps longer than
        MAX_WAYPOINT_STEP are split (:func:`split_steps`) and every path is checked at least every
        MOVE_CHECK_STEP (:func:`check_points`): the timed motion passes near the straight segments between the
        waypoints only when they are short (a fit that cannot follow the points to q ends in one long jump).
        """
        q = np.asarray(q, float)
        if np.abs(q - self.qs[-1]).max() <= 1e-12:
            self._append(label, q)
            return "none"
        qs, method = self._tracked(q, n), TRACKED
        if qs is None:
            qs, method = self._joint_path(self.qs[-1], q, n)
        if method == NO_DETOUR and (denser := self._tracked(q, TRACKING_RETRY_FACTOR * n)) is not None:
            qs, method = denser, TRACKED
        self.append_path(label, qs, method)
        return method

    def tracked_path(self, q: npt.ArrayLike, n: int) -> np.ndarray | None:
        """The tracked path of n samples from the last state to q when it passes its checks (the first path
        :meth:`move` tries), else None."""
        return self._tracked(np.asarray(q, float), n)

    def _tracked(self, q: np.ndarray, n: int) -> np.ndarray | None:
        """The tracking Cartesian interpolation's path of n samples from the last state to q, split into steps of
        at most MAX_WAYPOINT_STEP, when it passes :meth:`path_feasible`; else None."""
        path = split_steps(tracking_interpolation(self.robot, self.qs[-1], q, n, self.base).q)
        return path if self.path_feasible(path) else None

    def append_path(self, label: str, qs: np.ndarray, method: str) -> None:
        """The configurations qs[1:] of a checked path from the last state (qs[0]), made by ``method``."""
        for k in range(1, len(qs)):
            self._append(label if k == len(qs) - 1 else f"{label} ({k}/{len(qs) - 1})", qs[k])
        self.methods.append((label, method))

    def static_margins(self, qs: np.ndarray) -> np.ndarray:
        """Static margins (m) of configurations qs (m, n): the CoM's distance inside the support polygon of every
        link lying on the ground (``contact="ground"``); once the head is up (after the lift: ``lift_index`` set),
        the smaller of that and the base's own (``_base_margins``): a motion must not lean on a neck or head
        link that touches the ground at a checked configuration and may leave it in between."""
        com = self.base.below_along_gravity(stability.center_of_mass(self.robot, qs, self.base))
        margin = stability.support_margins(self.robot, qs, com, self.base, contact=PLAN_CONTACT)
        if self.lift_index is not None:
            margin = np.minimum(margin, self._base_margins(qs, com))
        return margin

    def _base_margins(self, qs: np.ndarray, com_xy: np.ndarray) -> np.ndarray:
        """Static margins (m) of configurations qs (m, n) with CoM projections com_xy (m, 2) over the support of the
        links that lie on the ground whatever the pose (``solve.whole_body.BodyProblem.ground_links``: the base's
        and the neck's before it lifts, flat: their boxes' bottom corners), as ``check_solution`` takes it."""
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

    @property
    def checker(self) -> _core.PathChecker:
        """The C++ path checker of the robot at this plan's base among its obstacles (``collision.path_proof``),
        built once per plan."""
        if self._checker is None:
            self._checker = path_proof.checker(self.robot, self.base, self.obstacles)
        return self._checker

    def feasible(self, qs: np.ndarray) -> np.ndarray:
        """(m,) bool: above the ground, statically stable with DETOUR_MARGIN to spare, no two non-neighbouring links
        overlapping, and clear of the obstacles (``planning.motion_checks.feasible``: the clearances in one C++ call)."""
        return motion_checks.feasible(self, qs, DETOUR_MARGIN)

    def path_feasible(self, path: np.ndarray) -> bool:
        """A path of waypoints whose clearances are proven along its straight segments and whose static margin
        keeps DETOUR_MARGIN at its :func:`check_points` configurations (``planning.motion_checks.path_feasible``)."""
        return motion_checks.path_feasible(self, path, check_points(path), DETOUR_MARGIN)

    def _joint_path(self, qa: np.ndarray, qb: np.ndarray, n: int) -> tuple[np.ndarray, str]:
        """A joint-space path qa -> qb of about n configurations that stays stable and above the ground.

        The straight path when it does; else the shortest of DETOUR_TRIALS two-piece paths through a waypoint
        drawn around the midpoint (the joints from the neck's first lifting joint on perturbed, seeded: plans are
        reproducible; the joints before it keep their straight path, since their links lie on the ground and a
        detour would sweep them across it, the ground's friction pushing the base) whose every
        configuration passes (tried shortest first, DETOUR_BATCH at a time, each screened at DENSIFY
        configurations per step, :meth:`_screened`, and then checked as densely as a move); else the one with the
        largest worst margin (:meth:`_steadiest`; the plan's checks then find what is wrong with it, and fail it).
        """
        s = np.linspace(0.0, 1.0, n)[:, None]
        straight = split_steps(qa + s * (qb - qa))
        if self.path_feasible(straight):
            return straight, "joint space"
        movable = np.arange(self.robot.lift_joints.start, self.robot.parts.head.stop)
        rng = np.random.default_rng(DETOUR_SEED)
        W = np.tile(0.5 * (qa + qb), (DETOUR_TRIALS, 1))
        W[:, movable] += rng.normal(0.0, DETOUR_SPREAD, (DETOUR_TRIALS, len(movable)))
        W = np.clip(W, self.robot.lower, self.robot.upper)
        paths = np.concatenate([qa + s[None] * (W[:, None] - qa), W[:, None] + s[None, 1:] * (qb - W[:, None])], axis=1)
        length = np.abs(np.diff(paths, axis=1)).sum(axis=(1, 2))
        order = np.argsort(length, kind="stable")
        dense = densify(paths)
        for batch in np.array_split(order, max(1, len(order) // DETOUR_BATCH)):
            for k in batch[self._screened(dense[batch], n - 1)]:
                path = split_steps(paths[k])
                if self.path_feasible(path):
                    return path, "joint space via a stable detour"
        return split_steps(paths[self._steadiest(dense, n - 1)]), NO_DETOUR

    def _screened(self, dense: np.ndarray, middle: int) -> np.ndarray:
        """(T,) bool: whether every configuration of each densified path dense (T, D, n) (:func:`densify` of paths of
        waypoints whose ``middle``-th is the detour's) is :meth:`feasible`. Cheap first: the detour waypoints, then
        every waypoint, then the rest, each only on the paths that passed the one before (a path that fails at some
        configurations fails: the answer is the check of every configuration's)."""
        T, D = dense.shape[:2]
        every = np.arange(0, D, DENSIFY + 1)  # the paths' waypoints
        stages = [np.array([middle * (DENSIFY + 1)]), every, np.setdiff1d(np.arange(D), every)]
        ok = np.ones(T, bool)
        for columns in stages:
            rows = np.flatnonzero(ok)
            if rows.size == 0:
                break
            ok[rows] = self.feasible(dense[rows][:, columns].reshape(-1, dense.shape[2])).reshape(
                len(rows), -1).all(axis=1)
        return ok

    def _steadiest(self, dense: np.ndarray, middle: int) -> int:
        """The index of the densified path dense (T, D, n) whose smallest static margin (:meth:`static_margins`) is the
        largest: the first path within MARGIN_TIE of the largest (paths often share their smallest margin, at an
        end they share, equal but for round-off that depends on which configurations are computed together). Each
        path's margins are computed only while it may be that one: its smallest margin is at most its ends' and its
        detour waypoint's, so the paths are taken by that bound, largest first, until every bound left is below the
        best found by more than twice MARGIN_TIE."""
        T, D, nj = dense.shape
        ends = np.array([0, middle * (DENSIFY + 1), D - 1])
        bound = self.static_margins(dense[:, ends].reshape(-1, nj)).reshape(T, len(ends)).min(axis=1)
        worst = np.full(T, np.nan)
        order = np.argsort(-bound, kind="stable")
        for batch in np.array_split(order, max(1, T // DETOUR_BATCH)):
            best = np.nanmax(worst) if np.isfinite(worst).any() else -np.inf
            batch = batch[bound[batch] >= best - 2 * MARGIN_TIE]
            if batch.size == 0:
                break
            worst[batch] = self.static_margins(dense[batch].reshape(-1, nj)).reshape(len(batch), D).min(axis=1)
        if not np.isfinite(worst).any():  # no configuration stands (e.g. none touches the ground): the first
            return 0
        return int(np.flatnonzero(worst >= np.nanmax(worst) - MARGIN_TIE)[0])

    def hold(self, seconds: float) -> None:
        """A pause of ``seconds`` at the last waypoint (which becomes a stop)."""
        if self.stops[-1:] != [len(self.qs) - 1]:
            self.stop()
        self.holds[len(self.qs) - 1] = float(seconds)
        self.qs.append(self.qs[-1].copy())
        self.labels.append(self.labels[-1] + " (hold)")

    def sample(self, notes: list, timing: dict[str, Any]) -> interp.JointTrajectory:
        """The fastest motion through the waypoints (``retiming.timing.retime``, options ``timing``) at 2 ms; fills in
        ``times`` (when each waypoint is reached)."""
        # the plan checks its 2 ms samples itself (_finish: the ZMP by the paper's momenta, the ground, obstacles);
        # the retiming keeps the joint limits between its gridpoints by refining them
        timing = dict(timing, check_samples=False)
        self._lift_rows = None  # set again below when this timing uses a kept lift (a plan may be timed again)
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
                    lift = self.lift_cache.put(key, retime(self.robot, Q[:k + 1], self.base, hold_s=hold_s[:k],
                                                           stops=[i for i in stops if i <= k], **timing))
                # the whole motion is sampled from the pieces' splines (concatenate_motions), which reads only the
                # rest's end: the rest is not sampled on its own
                rest = retime(self.robot, Q[k:], self.base, hold_s=hold_s[k:], stops=[i - k for i in stops if i >= k],
                              sample=False, **timing)
                check_motion_length(float(lift.t[-1]) + float(rest.t[-1]))
                traj = concatenate_motions(lift, rest)
                self._lift_rows = (key, int(np.count_nonzero(traj.t <= float(lift.t[-1]))))
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
            budget = 0.95 * plan_bounds.MAX_MOTION_S - float(hold_s.sum()) - 1e-3 * len(move)
            speed = max(FALLBACK_SPEED, float(move.sum()) / budget) if budget > 0 else FALLBACK_SPEED
            times = np.concatenate([[0.0], np.cumsum(np.maximum(move / speed, hold_s) + 1e-3)])
            check_motion_length(float(times[-1]), "with its holds")
            self.times = [float(x) for x in times]
            return interp.joint_trajectory(times, np.array(self.qs), method="monotone")
        self.times = [float(x) for x in traj.waypoint_times]
        notes += list(traj.notes)
        return traj


    def finish_checks(self, t: np.ndarray, q: np.ndarray, qd: np.ndarray
                      ) -> tuple[stability.DynamicStability, np.ndarray, np.ndarray | None, path_proof.MotionReport]:
        """The checks of the timed motion t, q, qd (``planning.motion_checks.finish_checks``: the ZMP and the ground
        clearance at every sample, the ground, self and obstacle clearances proven between them), with the lift's
        part of the ZMP check kept in ``checked_lifts`` for the next plan from a base of this shape (the motion begins
        with the same samples: ``dynamics.stability.KeptSamples``; at the placement it was made at the result is the
        same to the bit, at another the kept momenta, CoM and polygons are moved there: the same to ~1e-15 m)."""
        kept = None
        if self._lift_rows is not None and self.checked_lifts is not None:
            (shape, timing), rows = self._lift_rows
            key = (shape, timing)  # at another placement the core moves the kept part there (KeptSamples)
            kept = self.checked_lifts.get(key)
            if kept is None or kept.samples != rows:
                kept = self.checked_lifts.put(key, stability.KeptSamples(rows))
        return motion_checks.finish_checks(self.robot, self.base, t, q, qd, self.obstacles, PLAN_CONTACT,
                                        made=self.checker, kept=kept)


def _sample_all(motion: Any, t: np.ndarray) -> list[np.ndarray]:
    """q, qd, qdd (N, n) of a timed motion at times t, its path evaluated once for all three when its spline can
    (``retiming.timing``'s timeline: the same values as three calls)."""
    spline = motion.spline
    if hasattr(spline, "sample"):
        return list(spline.sample(t, (0, 1, 2)))
    return [spline(t, nu) for nu in (0, 1, 2)]


def concatenate_motions(a: Any, b: Any) -> Any:
    """Two retimed motions (``retiming.timing.RetimedTrajectory``), the second starting where and when (at rest) the
    first ends, as one sampled on one 2 ms grid; its ``waypoint_times`` the first's and the second's after its
    first. Of the second's samples only the last is used (its end: when and where)."""
    offset = float(a.t[-1])
    dt = float(a.t[1] - a.t[0]) if len(a.t) > 1 else interp.CONTROL_PERIOD
    t = interp.sample_times(0.0, offset + float(b.t[-1]), dt)
    first = t <= offset
    m = int(np.count_nonzero(first))  # the first's samples come first
    # the first's own samples where its grid is this one's (the same times): its spline's values there, except its
    # ends, which retime set to the waypoints exactly (q only)
    shared = min(m, len(a.t))
    redo = np.ones(m, bool)  # the rows the first's spline is evaluated at
    redo[:shared] = a.t[:shared] != t[:shared]
    redo[[0, shared - 1]] = True
    arrays = [np.empty((len(t), a.q.shape[1])) for _ in range(3)]
    for x, own in zip(arrays, (a.q, a.qd, a.qdd)):
        x[:shared] = own[:shared]
    rows = np.flatnonzero(redo)
    for x, v in zip(arrays, _sample_all(a, t[rows])):
        x[rows] = v
    for x, v in zip(arrays, _sample_all(b, t[m:] - offset)):
        x[m:] = v
    arrays[0][-1] = b.q[-1]
    return RetimedTrajectory(t, arrays[0], arrays[1], arrays[2], None,
                             waypoint_times=np.concatenate([a.waypoint_times, b.waypoint_times[1:] + offset]),
                             limits=b.limits, check=None, notes=tuple(a.notes) + tuple(b.notes),
                             solve_time_s=b.solve_time_s)


__all__ = ["Waypoints", "split_steps", "check_points", "densify", "concatenate_motions", "PLAN_CONTACT",
           "DETOUR_TRIALS", "DETOUR_SPREAD", "DETOUR_SEED", "JOINT_STEP_CHECK", "FALLBACK_SPEED", "DENSIFY", "MOVE_CHECK_STEP",
           "MAX_WAYPOINT_STEP", "DETOUR_BATCH", "MARGIN_TIE", "TRACKING_RETRY_FACTOR", "TRACKED", "NO_DETOUR"]
