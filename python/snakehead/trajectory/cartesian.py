"""Whole-body interpolation in Cartesian space, paper Eqs. 41-44 (Section 3.2, Figs. 12-13).

The neck's and head's joint positions move on straight lines (Eq. 41) and the joint angles follow them link by
link (Eqs. 42-44); :func:`cartesian_trajectory` times such a motion.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Literal

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputError
from .._validate import finite_array, joint_vector, positive
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .interpolation import CONTROL_PERIOD, JointTrajectory, minimum_jerk, sample_times

__all__ = ["TrackingInterpolation", "CartesianInterpolation", "joint_angle_towards", "cartesian_interpolation",
           "cartesian_trajectory", "TRACKING_DAMPING", "TRACKING_ITERATIONS", "TRACKING_CLEARANCE",
           "TRACKING_GROUND_WEIGHT", "TRACKING_CONTINUITY", "TRACKING_SELF_CLEARANCE", "TRACKING_SELF_STEP",
           "TRACKING_STEP_TOLERANCE", "lifted_self_pairs", "tracking_fit", "tracked_points", "tracking_interpolation",
           "LiftedFit", "tracking_interpolation_with"]


@dataclass(frozen=True)
class TrackingInterpolation:
    """Result of :func:`tracking_interpolation`: q (n_samples, n) rad; s (n_samples,) Eq. 41's t_j; points
    (n_samples, m, 3) the interpolated joint positions; actual (n_samples, m, 3) where the joints are; deviation
    (n_samples,) the largest distance between the two (m) and max_deviation its maximum."""

    q: np.ndarray
    s: np.ndarray
    points: np.ndarray
    actual: np.ndarray
    deviation: np.ndarray
    max_deviation: float


@dataclass(frozen=True)
class CartesianInterpolation(TrackingInterpolation):
    """Result of :func:`cartesian_interpolation` with ``full_output=True``.

    q (n, n_joints) rad; s (n,) the interpolation parameters t_j of Eq. 41; points (n, m, 3) the interpolated joint
    positions p_ij (m = neck + head joints + 1: from the neck's first joint to the head tip), actual (n, m, 3)
    where the recovered configuration puts them; deviation (n,) the largest distance between the two per
    sample (m), max_deviation its maximum; direction_error (n,) the largest angle (rad) between a recovered
    link (joint to next joint) and its interpolated segment; clipped (n, k) which joint angles were clipped to a
    limit. The positions stray even when the directions are exact: a straight-line interpolation between two
    poses shortens the segments (chords), while the links keep their length.
    """

    direction_error: np.ndarray
    clipped: np.ndarray


def _interpolated_joints(robot: SnakeRobot) -> np.ndarray:
    """Joint indices of the neck and head, in chain order."""
    return np.arange(robot.parts.neck.start, robot.parts.head.stop)


def _joint_point_frames(robot: SnakeRobot, joints: np.ndarray) -> np.ndarray:
    """Frame indices (link_names) whose origins are the joint positions p_0 .. p_{m-1} of Eq. 41."""
    child = np.asarray(robot.body.model.joint_child_links)
    return np.r_[child[joints], robot.body.link_index(robot.parts.head_tip)]


def joint_angle_towards(R0: np.ndarray, axis_local: np.ndarray, d_local: np.ndarray, l: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. 42-43 for a joint with any axis: the angle that turns the link's direction closest to ``l``.

    R0 (T, 3, 3): the joint frame's rotation at zero joint angle (world); axis_local (3,) the joint axis and
    d_local (3,) the link's direction (from this joint to the next), both in that frame; l (T, 3) the wanted
    direction (Eq. 44). Both directions are projected on the plane of rotation (normal a = R0 axis, Eq. 43),
    and theta = atan2(a . (d_p x l_p), d_p . l_p). For a yaw joint (a = T_z, d = T_x) this is
    atan2(T_y . l_p, T_x . l_p) = pi/2 - arccos(T_y . l_p / |l_p|) (Eq. 42) whenever |theta| <= pi/2; for a pitch
    joint (a = T_y) it is atan2(-T_z . l_p, T_x . l_p). Returns theta (T,) and ok (T,): False where l or d is
    (nearly) parallel to the axis, so that no angle is defined.
    """
    a = R0 @ axis_local
    d = R0 @ d_local
    dp = d - np.sum(d * a, axis=-1, keepdims=True) * a  # Eq. 43 for the link
    lp = l - np.sum(l * a, axis=-1, keepdims=True) * a  # Eq. 43 for the segment
    ok = (np.linalg.norm(lp, axis=-1) > 1e-9) & (np.linalg.norm(dp, axis=-1) > 1e-9)
    theta = np.arctan2(np.sum(a * np.cross(dp, lp), axis=-1), np.sum(dp * lp, axis=-1))  # Eq. 42, general axis
    return theta, ok


def _interpolation_parameters(n: int | npt.ArrayLike) -> np.ndarray:
    """Eq. 41's t_0 .. t_m: n evenly spaced in [0, 1] for an integer n >= 2, or the given non-decreasing values
    from 0 to 1."""
    if isinstance(n, (int, np.integer)) and not isinstance(n, bool):
        if n < 2:
            raise InputError(f"n must be an integer >= 2 (samples including both ends), got {n!r}")
        return np.linspace(0.0, 1.0, int(n))
    if np.ndim(n) != 1:
        raise InputError(f"n must be an integer >= 2 or a 1-D array of interpolation parameters, got {n!r}")
    s = finite_array(n, "interpolation parameters", (None,))
    if len(s) < 2 or s[0] != 0.0 or s[-1] != 1.0 or np.any(np.diff(s) < 0):
        raise InputError("interpolation parameters must be non-decreasing from exactly 0 to exactly 1 "
                         "(at least two)")
    return s


def cartesian_interpolation(robot: SnakeRobot, q_start: npt.ArrayLike, q_end: npt.ArrayLike, n: int | npt.ArrayLike,
                            base: BasePlacement | None = None, *, aim: str = "segment", full_output: bool = False
                            ) -> Any:
    """Whole-body interpolation in Cartesian space, Eqs. 41-44: n configurations (n, 16) from q_start to q_end.

    ``n`` is the number of samples (t_j of Eq. 41 evenly spaced in [0, 1]) or the t_j themselves, a
    non-decreasing 1-D array from 0 to 1 (see :func:`cartesian_trajectory` for a timed motion).

    * The base joints interpolate linearly in joint space (the base stays on the ground).
    * The joint positions of the neck and head (world points of the joint frames from the neck's first joint
      to the head tip, p_0 .. p_{m-1}) interpolate linearly, p_ij = (1 - t_j) p_si + t_j p_fi (Eq. 41).
    * The joint angles are recovered link by link in chain order: joint i's frame is known from the joints
      before it; its link should point along l_i = (p_{i+1,j} - p_{ij}) / |.| (Eq. 44); the link direction
      and l_i are projected on the plane of the joint's rotation (Eq. 43) and the angle between them (Eq. 42;
      see :func:`joint_angle_towards` for the form for any axis) is clipped to the joint's limits. Where the
      wanted direction passes behind a link (beyond +-90 deg) the clipped angle jumps from one limit to the
      other: ``full_output`` reports the clipped samples; such a motion needs intermediate waypoints.
      ``aim="points"`` instead aims each link from where the recovered chain has put its joint at the next
      interpolated point (the same equations with p_ij replaced by the actual joint position): the chain then
      tracks the interpolated points instead of only their directions.
    * Where a direction is parallel to the joint axis (no angle defined) the joint interpolates linearly.
    * The first sample is q_start and the last q_end exactly.

    Returns q (n, 16), or a :class:`CartesianInterpolation` with ``full_output=True`` (how far the
    recovered joints stray from the interpolated points, m).
    """
    robot = as_robot(robot)
    base = as_base(base)
    nj = robot.n_joints
    q_start = joint_vector(q_start, nj, "q_start")
    q_end = joint_vector(q_end, nj, "q_end")
    s = _interpolation_parameters(n)
    n = len(s)
    if aim not in ("segment", "points"):
        raise InputError(f"aim must be 'segment' (Eq. 44) or 'points', got {aim!r}")
    q = (1.0 - s)[:, None] * q_start + s[:, None] * q_end  # base joints: linear (and the fallback)
    joints = _interpolated_joints(robot)
    pts_idx = _joint_point_frames(robot, joints)
    model = robot.body.model
    child = np.asarray(model.joint_child_links)
    axes = np.asarray(model.joint_axes, float)
    ends = robot.frames_many(np.stack([q_start, q_end]), base)[:, pts_idx][..., :3, 3]  # (2, m, 3)
    P = (1.0 - s)[:, None, None] * ends[0] + s[:, None, None] * ends[1]  # Eq. 41, (n, m, 3)
    # each link's direction (to the next joint position) in its own joint frame: fixed by the geometry
    F0 = robot.body.fk_all(np.zeros(nj))
    clipped = np.zeros((n, len(joints)), bool)
    for i, j in enumerate(joints):
        qz = q.copy()
        qz[:, j] = 0.0
        F = robot.frames_many(qz, base)  # joints before j are final; joint j at zero
        Tj = F[:, child[j]]
        R0 = Tj[:, :3, :3]
        d_local = F0[child[j], :3, :3].T @ (F0[pts_idx[i + 1], :3, 3] - F0[child[j], :3, 3])
        d_local /= np.linalg.norm(d_local)
        start = P[:, i] if aim == "segment" else Tj[:, :3, 3]
        l = P[:, i + 1] - start  # Eq. 44
        norm = np.linalg.norm(l, axis=1, keepdims=True)
        l = l / np.where(norm > 0, norm, 1.0)
        theta, ok = joint_angle_towards(R0, axes[j], d_local, l)
        theta = np.where(ok, theta, q[:, j])
        lo, hi = robot.lower[j], robot.upper[j]
        clipped[:, i] = (theta < lo) | (theta > hi)
        q[:, j] = np.clip(theta, lo, hi)
    q[0], q[-1] = q_start, q_end
    clipped[[0, -1]] = False
    if not full_output:
        return q
    actual = robot.frames_many(q, base)[:, pts_idx][..., :3, 3]
    dev = np.linalg.norm(actual - P, axis=2).max(axis=1)
    links = np.diff(actual, axis=1)
    segs = np.diff(P, axis=1)
    angle = np.arctan2(np.linalg.norm(np.cross(links, segs), axis=2), np.sum(links * segs, axis=2))
    angle = np.where(np.linalg.norm(segs, axis=2) > 1e-12, angle, 0.0)  # a segment of zero length: no direction
    return CartesianInterpolation(q, s, P, actual, dev, float(dev.max()), angle.max(axis=1), clipped)


def cartesian_trajectory(robot: SnakeRobot, q_start: np.ndarray, q_end: np.ndarray, duration: float,
                         dt: float = CONTROL_PERIOD, base: BasePlacement | None = None, *, aim: str = "segment"
                         ) -> JointTrajectory:
    """A timed whole-body Cartesian motion: Eqs. 41-44 sampled every ``dt`` s over ``duration`` s.

    Eq. 41's parameter follows the minimum-jerk scaling t_j = s(t / duration) (:func:`minimum_jerk`), so the
    motion starts and ends at rest. q is :func:`cartesian_interpolation` at those parameters; qd and qdd are
    its finite differences along the samples (np.gradient), zero at the ends. ``spline`` is None.
    """
    duration = positive(duration, "duration")
    t = sample_times(0.0, duration, dt)
    s = minimum_jerk(t / duration)
    s[0], s[-1] = 0.0, 1.0
    q = cartesian_interpolation(robot, q_start, q_end, s, base, aim=aim)
    edge: Literal[1, 2] = 2 if len(t) > 2 else 1
    qd = np.gradient(q, t, axis=0, edge_order=edge)
    qdd = np.gradient(qd, t, axis=0, edge_order=edge)
    qd[[0, -1]] = 0.0
    qdd[[0, -1]] = 0.0
    return JointTrajectory(t, q, qd, qdd, None)


#: Damping (m) and iterations of the tracking interpolation's damped least squares at each sample.
TRACKING_DAMPING = 0.01
TRACKING_ITERATIONS = 12
#: The tracking fit keeps the lifted boxes' lowest corners this high (m) when the interpolated points allow it,
#: weighted this much against the points.
TRACKING_CLEARANCE = 0.002
TRACKING_GROUND_WEIGHT = 10.0
#: Weight (m per rad) of each lifted joint's change from the previous sample in the tracking fit.
TRACKING_CONTINUITY = 0.03
#: The tracking fit keeps the shapes of links two or more joints apart (``robot.self_collision_pairs``) this far
#: apart (m), with the ground's weight: thick links (e.g. cylinders wider than a module is long) folded by the
#: interpolated points would otherwise overlap, and the planner would fall back to a detour for the whole move.
TRACKING_SELF_CLEARANCE = 0.005
#: Step (rad) of the finite differences of the self-clearance term's distances: large enough that GJK's distance
#: noise (~1e-7 m) does not make the differences, so that the fit does not change with round-off (bench/RESULTS.md).
TRACKING_SELF_STEP = 1e-4
#: A sample's fit stops after a step (rad, largest joint change) smaller than this.
TRACKING_STEP_TOLERANCE = 1e-7


def lifted_self_pairs(robot: SnakeRobot, lift: np.ndarray) -> np.ndarray:
    """The self-collision pairs (P, 2) of shapes that the lifted joints ``lift`` move apart: one shape on a link
    that they move, the other not on the same rigid run of links."""
    pairs = robot.self_collision_pairs
    if pairs.size == 0 or lift.size == 0:
        return pairs.reshape(0, 2)
    first = int(np.asarray(robot.body.model.joint_child_links)[lift[0]])
    frame = robot.geometry.shape_frames
    return pairs[(frame[pairs[:, 0]] >= first) | (frame[pairs[:, 1]] >= first)]


def tracking_fit(robot: SnakeRobot, base: BasePlacement, lift: np.ndarray, points: np.ndarray) -> _core.TrackingFit:
    """The core's fit of :func:`tracking_interpolation` (include/snakehead/tracking_fit.hpp): the joints ``lift``
    fitted to the origins of the frames ``points``, the ground and self terms of the robot at ``base``, the
    TRACKING_* settings."""
    return _core.TrackingFit(robot.body.model, robot.geometry.core, robot.root_pose(base), lift.astype(np.int64),
                             points.astype(np.int64), np.asarray(robot.lifted_links, np.int64),
                             np.ascontiguousarray(lifted_self_pairs(robot, lift), np.int64), damping=TRACKING_DAMPING,
                             iterations=TRACKING_ITERATIONS, step_tolerance=TRACKING_STEP_TOLERANCE,
                             clearance=TRACKING_CLEARANCE, ground_weight=TRACKING_GROUND_WEIGHT,
                             continuity=TRACKING_CONTINUITY, self_clearance=TRACKING_SELF_CLEARANCE,
                             self_step=TRACKING_SELF_STEP)


def tracked_points(robot: SnakeRobot) -> np.ndarray:
    """Frame indices (link_names) whose origins Eq. 41 interpolates: the joints the neck lifts with and every joint
    after them (their child links' frames), and the head tip."""
    child = np.asarray(robot.body.model.joint_child_links)
    return np.r_[child[robot.lift_joints.start:], robot.link_index(robot.parts.head_tip)]


def tracking_interpolation(robot: SnakeRobot, q_start: npt.ArrayLike, q_end: npt.ArrayLike, n: int,
                           base: BasePlacement | None = None) -> TrackingInterpolation:
    """Eq. 41 made to track: the lifted joints' positions (from the neck's first lifting joint to the head tip)
    move on straight lines, p_ij = (1 - t_j) p_si + t_j p_fi, and at every sample the lifted joint angles are fitted
    to all those points at once by damped least squares (Levenberg-Marquardt steps, warm-started from the previous
    sample, within the joint limits), instead of Eqs. 42-44's link-by-link directions, which drift off the points
    when they are closer together than the links are long. The ground enters the fit as a stiff one-sided term on
    the lifted boxes' lowest corners (``TRACKING_CLEARANCE``, ``TRACKING_GROUND_WEIGHT``), and so does the body
    itself: links two or more joints apart are kept ``TRACKING_SELF_CLEARANCE`` apart. The joints before the lift
    interpolate linearly in joint space (the base stays on the ground). The first and last samples are q_start and
    q_end exactly.

    Where the interpolated points cannot be met (a straight line between two poses shortens the chain, while links
    keep their lengths), the fit is the closest in the least-squares sense; ``deviation`` says how far it is.

    The fit runs in the C++ core (:func:`tracking_fit`, ``_core.TrackingFit``; the GIL released), step for step as
    the numpy reference does (tests/tracking_reference.py, tests/sim/test_tracking_fit.py).
    """
    return tracking_interpolation_with(robot, q_start, q_end, n, base, _core_fit)


#: A fit of the lifted joints: (robot, base, lift, points, q (S, n), targets (S, m, 3)) -> q with rows 1 .. S-2's
#: lifted joints fitted (:func:`tracking_interpolation`).
LiftedFit = Callable[[SnakeRobot, BasePlacement, np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def _core_fit(robot: SnakeRobot, base: BasePlacement, lift: np.ndarray, points: np.ndarray, q: np.ndarray,
              P: np.ndarray) -> np.ndarray:
    return tracking_fit(robot, base, lift, points).fit(q, P)


def tracking_interpolation_with(robot: SnakeRobot, q_start: npt.ArrayLike, q_end: npt.ArrayLike, n: int,
                              base: BasePlacement | None, fit: LiftedFit) -> TrackingInterpolation:
    """:func:`tracking_interpolation` with the lifted joints fitted by ``fit`` (the core's, or the numpy reference's
    in the tests)."""
    robot = as_robot(robot)
    base = as_base(base)
    nj = robot.n_joints
    q_start = joint_vector(q_start, nj, "q_start")
    q_end = joint_vector(q_end, nj, "q_end")
    s = _interpolation_parameters(n)
    lift = np.arange(robot.lift_joints.start, nj)
    pts_idx = tracked_points(robot)
    ends = robot.frames_many(np.stack([q_start, q_end]), base)[:, pts_idx][..., :3, 3]  # (2, m, 3)
    P = (1.0 - s)[:, None, None] * ends[0] + s[:, None, None] * ends[1]  # Eq. 41
    q = (1.0 - s)[:, None] * q_start + s[:, None] * q_end  # joints before the lift, and the starting guesses
    q = fit(robot, base, lift, pts_idx, q, P)  # the lifted joints of the interior samples
    q[0], q[-1] = q_start, q_end
    actual = robot.frames_many(q, base)[:, pts_idx][..., :3, 3]
    dev = np.linalg.norm(actual - P, axis=2).max(axis=1)
    return TrackingInterpolation(q, s, P, actual, dev, float(dev.max()))
