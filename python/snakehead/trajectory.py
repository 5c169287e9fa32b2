"""Whole-body motion: joint-space interpolation, the Cartesian interpolation of Eqs. 41-44, ground clearance
and collisions with obstacles (paper, Section 3.2; DESIGN.md).

* :func:`joint_interpolation` / :func:`joint_trajectory` -- the multi-segment joint-space interpolation,
  sampled at the 2 ms control period.
* :func:`cartesian_interpolation` -- Eqs. 41-44: the neck's and head's joint positions move on straight lines
  and the joint angles follow them link by link.
* :func:`ground_clearance`, :func:`below_ground`, :func:`touching_ground` -- how high every link's
  collision box stays above the ground.
* :class:`BoxObstacle`, :class:`WallWithHole`, :func:`collision_check` -- the links' boxes against obstacles.

Everything is vectorised over the time samples (numpy); Python loops run over joints, links or box features.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from ._validate import finite_array, joint_vector, positive, rotation_matrix, unit_vector3, vector3
from .robot import BasePlacement, SnakeRobot, as_base, as_robot
from .stability import _box_links, _lowest_corner_z

#: The joint controller's period (s), Section 4.
CONTROL_PERIOD = 0.002

#: A link whose box dips lower than this below the ground (m) is driven into it by the plan; a box within
#: this distance of the ground touches it (the base lies at exactly 0).
GROUND_TOLERANCE = 1e-3


# ------------------------------------------------------------------------------------------------
# joint-space interpolation
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class JointTrajectory:
    """A sampled joint trajectory: t (T,) s, q (T, n) rad, qd (T, n) rad/s, qdd (T, n) rad/s^2, and the
    spline it samples (``spline(t, nu)`` evaluates the nu-th derivative anywhere; None for
    :func:`cartesian_trajectory`)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    spline: BSpline | None


def _check_waypoints(times, waypoints) -> tuple[np.ndarray, np.ndarray]:
    times = finite_array(times, "times", (None,))
    if times.shape[0] < 2:
        raise ValueError(f"times needs at least two waypoints, got {times.shape[0]}")
    if np.any(np.diff(times) <= 0):
        raise ValueError("times must increase strictly")
    waypoints = finite_array(waypoints, "waypoints", (times.shape[0], None))
    if waypoints.shape[1] < 1:
        raise ValueError("waypoints have no joints")
    return times, waypoints


def joint_spline(times, waypoints) -> BSpline:
    """The interpolating spline of :func:`joint_trajectory`: times (K,) s, waypoints (K, n) rad -> BSpline.

    A quintic spline (degree 5, scipy ``make_interp_spline``) through every waypoint with zero velocity and
    zero acceleration at both ends: C4 inside (position, velocity, acceleration, jerk and snap continuous),
    at rest at the ends. With two waypoints it is the minimum-jerk quintic 10 s^3 - 15 s^4 + 6 s^5.
    Like every interpolating spline it may overshoot between waypoints (see ``lower``/``upper`` of
    :func:`joint_trajectory`).
    """
    times, waypoints = _check_waypoints(times, waypoints)
    zero = np.zeros(waypoints.shape[1])
    ends = [(1, zero), (2, zero)]
    return make_interp_spline(times, waypoints, k=5, bc_type=(ends, ends), axis=0)


class MonotoneQuintic:
    """Piecewise quintic Hermite interpolation that does not overshoot: times (K,) s, waypoints (K, n).

    Each segment is the quintic with the waypoints' positions, zero accelerations and velocities chosen like
    PCHIP's (Fritsch-Carlson): zero where the neighbouring slopes differ in sign or at either end, else their
    harmonic mean. Position, velocity and acceleration are continuous (the acceleration is zero at every
    waypoint), and a joint never leaves the range of the two waypoints around it: safe for waypoints that
    sit on a joint limit, where the C4 spline of :func:`joint_spline` can overshoot. Call as ``f(t, nu)``.
    """

    def __init__(self, times, waypoints):
        self.times, self.q = _check_waypoints(times, waypoints)
        h = np.diff(self.times)[:, None]
        d = np.diff(self.q, axis=0) / h  # secant slopes (K-1, n)
        v = np.zeros_like(self.q)
        a, b = d[:-1], d[1:]
        same = a * b > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            hm = np.where(same, 2 * a * b / (a + b), 0.0)
        v[1:-1] = hm
        self.v = v

    def __call__(self, t, nu: int = 0) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, float))
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.times) - 2)
        h = (self.times[k + 1] - self.times[k])[:, None]
        s = ((t - self.times[k])[:, None]) / h
        p0, p1, v0, v1 = self.q[k], self.q[k + 1], self.v[k], self.v[k + 1]
        s2, s3, s4, s5 = s * s, s**3, s**4, s**5
        if nu == 0:
            return ((1 - 10 * s3 + 15 * s4 - 6 * s5) * p0 + h * (s - 6 * s3 + 8 * s4 - 3 * s5) * v0
                    + (10 * s3 - 15 * s4 + 6 * s5) * p1 + h * (-4 * s3 + 7 * s4 - 3 * s5) * v1)
        if nu == 1:
            return ((-30 * s2 + 60 * s3 - 30 * s4) * (p0 - p1) / h + (1 - 18 * s2 + 32 * s3 - 15 * s4) * v0
                    + (-12 * s2 + 28 * s3 - 15 * s4) * v1)
        if nu == 2:
            return ((-60 * s + 180 * s2 - 120 * s3) * (p0 - p1) / h**2 + (-36 * s + 96 * s2 - 60 * s3) * v0 / h
                    + (-24 * s + 84 * s2 - 60 * s3) * v1 / h)
        raise ValueError("nu must be 0, 1 or 2")


def sample_times(t0: float, t1: float, dt: float = CONTROL_PERIOD) -> np.ndarray:
    """t0, t0 + dt, ... up to t1, with t1 itself as the last sample: (T,) s."""
    dt = positive(dt, "dt")
    steps = int(np.floor((t1 - t0) / dt + 1e-9))
    t = t0 + dt * np.arange(steps + 1)
    # A gap under a microsecond is round-off, not a sample: stretch the last step to t1 instead of adding a
    # sample a hair after it (two samples closer than any controller or file can tell apart).
    if t1 - t[-1] > min(1e-6, 1e-3 * dt):
        t = np.append(t, t1)
    t[-1] = t1
    return t


def joint_trajectory(times, waypoints, dt: float = CONTROL_PERIOD, *, lower=None, upper=None,
                     method: str = "spline") -> JointTrajectory:
    """Multi-segment joint-space interpolation through waypoints, sampled every ``dt`` s.

    times (K,) strictly increasing (s); waypoints (K, n) joint vectors (rad), the first at rest and the last at
    rest. ``method``: "spline", the C4 quintic spline of :func:`joint_spline`, or "monotone", the piecewise
    quintic of :class:`MonotoneQuintic` that never overshoots the waypoints (use it for dense waypoints or
    waypoints on joint limits). The samples are t0, t0 + dt, ... and the last time;
    the first and last samples equal the first and last waypoints exactly. With ``lower``/``upper`` ((n,), rad)
    a trajectory that overshoots the joint limits raises ValueError.
    """
    dt = positive(dt, "dt")
    times, waypoints = _check_waypoints(times, waypoints)
    if method == "spline":
        spline = joint_spline(times, waypoints)
    elif method == "monotone":
        spline = MonotoneQuintic(times, waypoints)
    else:
        raise ValueError(f"method must be 'spline' or 'monotone', got {method!r}")
    t = sample_times(times[0], times[-1], dt)
    q, qd, qdd = spline(t), spline(t, 1), spline(t, 2)
    q[0], q[-1] = waypoints[0], waypoints[-1]
    qd[[0, -1]] = 0.0
    qdd[[0, -1]] = 0.0
    n = waypoints.shape[1]
    for bound, name, bad in ((lower, "lower", lambda a, b: a < b), (upper, "upper", lambda a, b: a > b)):
        if bound is None:
            continue
        b = joint_vector(bound, n, name)
        over = bad(q, b + (1e-9 if name == "upper" else -1e-9))
        if over.any():
            k, j = np.argwhere(over)[0]
            raise ValueError(f"the interpolation overshoots the {name} limit of joint {j} "
                             f"({q[k, j]:.4f} rad at t = {t[k]:.3f} s; limit {b[j]:.4f} rad)")
    return JointTrajectory(t, q, qd, qdd, spline)


def joint_interpolation(times, waypoints, dt: float = CONTROL_PERIOD) -> tuple[np.ndarray, np.ndarray]:
    """Multi-segment joint-space interpolation (Section 3.2): -> (t (T,) s, q (T, n) rad) at the control period.

    Continuous in velocity and acceleration, at rest at both ends; see :func:`joint_trajectory` for the
    velocities and accelerations.
    """
    traj = joint_trajectory(times, waypoints, dt)
    return traj.t, traj.q


# ------------------------------------------------------------------------------------------------
# Eqs. 41-44: whole-body interpolation in Cartesian space
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CartesianInterpolation:
    """Result of :func:`cartesian_interpolation` with ``full_output=True``.

    q (n, 16) rad; s (n,) the interpolation parameters t_j of Eq. 41; points (n, m, 3) the interpolated joint
    positions p_ij (m = neck + head joints + 1: from the neck's first joint to the head tip), actual (n, m, 3)
    where the recovered configuration puts them; deviation (n,) the largest distance between the two per
    sample (m), max_deviation its maximum; direction_error (n,) the largest angle (rad) between a recovered
    link (joint to next joint) and its interpolated segment; clipped (n, k) which joint angles were clipped to a
    limit. The positions stray even when the directions are exact: a straight-line interpolation between two
    poses shortens the segments (chords), while the links keep their length.
    """

    q: np.ndarray
    s: np.ndarray
    points: np.ndarray
    actual: np.ndarray
    deviation: np.ndarray
    max_deviation: float
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


def _interpolation_parameters(n) -> np.ndarray:
    """Eq. 41's t_0 .. t_m: n evenly spaced in [0, 1] for an integer n >= 2, or the given non-decreasing values
    from 0 to 1."""
    if isinstance(n, (int, np.integer)) and not isinstance(n, bool):
        if n < 2:
            raise ValueError(f"n must be an integer >= 2 (samples including both ends), got {n!r}")
        return np.linspace(0.0, 1.0, int(n))
    if np.ndim(n) != 1:
        raise ValueError(f"n must be an integer >= 2 or a 1-D array of interpolation parameters, got {n!r}")
    s = finite_array(n, "interpolation parameters", (None,))
    if len(s) < 2 or s[0] != 0.0 or s[-1] != 1.0 or np.any(np.diff(s) < 0):
        raise ValueError("interpolation parameters must be non-decreasing from exactly 0 to exactly 1 "
                         "(at least two)")
    return s


def cartesian_interpolation(robot: SnakeRobot, q_start, q_end, n, base: BasePlacement | None = None, *,
                            aim: str = "segment", full_output: bool = False):
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
        raise ValueError(f"aim must be 'segment' (Eq. 44) or 'points', got {aim!r}")
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


def minimum_jerk(tau: np.ndarray) -> np.ndarray:
    """The rest-to-rest time scaling 10 tau^3 - 15 tau^4 + 6 tau^5 of tau in [0, 1]."""
    tau = np.asarray(tau, float)
    return tau ** 3 * (10.0 - 15.0 * tau + 6.0 * tau ** 2)


def cartesian_trajectory(robot: SnakeRobot, q_start, q_end, duration: float, dt: float = CONTROL_PERIOD,
                         base: BasePlacement | None = None, *, aim: str = "segment") -> JointTrajectory:
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
    edge = 2 if len(t) > 2 else 1
    qd = np.gradient(q, t, axis=0, edge_order=edge)
    qdd = np.gradient(qd, t, axis=0, edge_order=edge)
    qd[[0, -1]] = 0.0
    qdd[[0, -1]] = 0.0
    return JointTrajectory(t, q, qd, qdd, None)


# ------------------------------------------------------------------------------------------------
# ground clearance
# ------------------------------------------------------------------------------------------------
def _trajectory(robot: SnakeRobot, qs) -> np.ndarray:
    a = finite_array(qs, "qs")
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != robot.n_joints or a.shape[0] < 1:
        raise ValueError(f"qs has shape {np.shape(qs)}; expected (T, {robot.n_joints}) or ({robot.n_joints},)")
    return a


def ground_clearance(robot: SnakeRobot, qs, base: BasePlacement | None = None) -> np.ndarray:
    """Height (m) of the lowest corner of every link's collision box above the ground: (T, n_links).

    qs (T, 16) (or (16,) -> (1, n_links)). Negative values are below the ground. The base links lying flat are
    at 0 (touching); frames without a box (markers) get +inf.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    frames = robot.frames_many(qs, base)
    out = np.full(frames.shape[:2], np.inf)
    links = _box_links(robot)
    out[:, links] = _lowest_corner_z(frames, robot, links)
    return out


def non_base_links(robot: SnakeRobot) -> np.ndarray:
    """Indices (link_names) of the boxed links after the base part (neck and head): (k,)."""
    first_after = robot.body.link_index(robot.parts.base_end)
    links = _box_links(robot)
    return links[links > first_after]


def below_ground(robot: SnakeRobot, qs, base: BasePlacement | None = None,
                 tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose boxes go deeper than ``tolerance`` m into the ground.

    The base links are never flagged (they lie on it). A box within ``tolerance`` of the ground merely touches.
    """
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = non_base_links(robot)
    out[:, links] = clearance[:, links] < -tolerance
    return out


def touching_ground(robot: SnakeRobot, qs, base: BasePlacement | None = None,
                    tolerance: float = GROUND_TOLERANCE) -> np.ndarray:
    """(T, n_links) bool: the neck and head links whose boxes come within ``tolerance`` m of the ground (or
    below it). The base links, which lie on the ground, are never flagged."""
    tolerance = float(finite_array(tolerance, "tolerance", ()))
    clearance = ground_clearance(robot, qs, base)
    out = np.zeros(clearance.shape, bool)
    links = non_base_links(robot)
    out[:, links] = clearance[:, links] < tolerance
    return out


# ------------------------------------------------------------------------------------------------
# obstacles
# ------------------------------------------------------------------------------------------------
_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)
_EDGES = np.array([(a, b) for a in range(8) for b in range(a + 1, 8)
                   if np.count_nonzero(_SIGNS[a] != _SIGNS[b]) == 1])  # (12, 2) vertex pairs


@dataclass(frozen=True)
class BoxObstacle:
    """A box: centre (3,) m world, size (3,) full extents m, rotation (3, 3) its axes in the world."""

    centre: np.ndarray
    size: np.ndarray
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self):
        object.__setattr__(self, "centre", vector3(self.centre, "box centre"))
        size = vector3(self.size, "box size")
        if np.any(size <= 0):
            raise ValueError(f"box size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "rotation", rotation_matrix(self.rotation, "box rotation"))


@dataclass(frozen=True)
class WallWithHole:
    """A wall (a thin box) with a round hole through it.

    centre (3,) m: the hole's centre, in the middle of the wall's thickness; normal (3,): the hole's axis
    (the wall's thickness direction); size (w, h, thickness) m: w along the horizontal direction in the wall
    (normal x world z; world x if the normal is vertical), h along the third axis; hole_diameter m;
    hole_offset (2,) m: where the wall's centre is relative to the hole along (w, h) (default: the hole is at
    the wall's centre). The hole must lie inside the wall.
    """

    centre: np.ndarray
    normal: np.ndarray
    size: np.ndarray
    hole_diameter: float
    hole_offset: np.ndarray = field(default_factory=lambda: np.zeros(2))

    def __post_init__(self):
        object.__setattr__(self, "centre", vector3(self.centre, "wall centre"))
        object.__setattr__(self, "normal", unit_vector3(self.normal, "wall normal"))
        size = vector3(self.size, "wall size (w, h, thickness)")
        if np.any(size <= 0):
            raise ValueError(f"wall size must be positive, got {size.tolist()}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "hole_diameter", positive(self.hole_diameter, "hole_diameter"))
        off = finite_array(self.hole_offset, "hole_offset", (2,))
        object.__setattr__(self, "hole_offset", off)
        r = self.hole_diameter / 2
        if np.any(np.abs(off) + r >= size[:2] / 2):
            raise ValueError("the hole does not lie inside the wall")

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) columns: the width axis, the height axis, the normal (world)."""
        nrm = self.normal
        u = np.cross(nrm, [0.0, 0.0, 1.0])
        if np.linalg.norm(u) < 1e-9:
            u = np.array([1.0, 0.0, 0.0]) - nrm[0] * nrm
        u /= np.linalg.norm(u)
        return np.column_stack([u, np.cross(nrm, u), nrm])

    def slab(self) -> BoxObstacle:
        """The wall without its hole, as a box."""
        R = self.rotation
        return BoxObstacle(self.centre + R[:, :2] @ self.hole_offset, self.size, R)

    def distance_to_points(self, x: np.ndarray) -> np.ndarray:
        """Exact distance (m) of world points x (..., 3) to the wall's solid (0 inside it).

        The solid is (rectangle minus disc) x [-thickness/2, thickness/2], a prism, so the squared distance is
        the in-plane distance to the rectangle-minus-disc squared plus the distance along the normal squared.
        """
        R = self.rotation
        loc = (np.asarray(x, float) - self.centre) @ R  # (..., 3) hole coordinates
        uv, w = loc[..., :2], loc[..., 2]
        half = self.size / 2
        dw = np.maximum(np.abs(w) - half[2], 0.0)
        rel = uv - self.hole_offset  # coordinates from the wall's centre
        outside_rect = np.linalg.norm(np.maximum(np.abs(rel) - half[:2], 0.0), axis=-1)
        rho = np.linalg.norm(uv, axis=-1)
        in_hole = np.maximum(self.hole_diameter / 2 - rho, 0.0)
        d_plane = np.where(outside_rect > 0, outside_rect, in_hole)
        return np.hypot(d_plane, dw)


def _link_boxes(robot: SnakeRobot, qs: np.ndarray, base: BasePlacement):
    """World collision boxes of the links along a trajectory: links (k,), centres (T, k, 3), rotations
    (T, k, 3, 3), half extents (k, 3)."""
    links = _box_links(robot)
    B = robot.frames_many(qs, base)[:, links] @ robot.box_origins[links]
    return links, B[..., :3, 3], B[..., :3, :3], 0.5 * robot.box_sizes[links]


def self_clearance(robot: SnakeRobot, qs, base: BasePlacement | None = None) -> np.ndarray:
    """Self-collision of the body along a trajectory: (T,) the smallest separating-axis gap (m) between the
    collision boxes of any two links that are not neighbours in the chain (neighbours share a joint and
    always touch there). > 0: no two such boxes meet (and this is a lower bound of their distance); <= 0: some
    overlap. qs (T, 16) or (16,) -> (1,).
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    links, c, R, h = _link_boxes(robot, qs, base)
    i, j = np.triu_indices(len(links), k=2)  # boxed links two or more apart in the chain
    gaps = box_box_sat(c[:, i], R[:, i], h[i], c[:, j], R[:, j], h[j])  # (T, pairs)
    return gaps.min(axis=1)


def _broadcast_boxes(ca, Ra, ha, cb, Rb, hb):
    """Broadcast two batches of boxes (centres (..., 3), rotations (..., 3, 3), half extents (..., 3))."""
    arrs = [np.asarray(v, float) for v in (ca, Ra, ha, cb, Rb, hb)]
    core = [(3,), (3, 3), (3,), (3,), (3, 3), (3,)]
    for a, cs, name in zip(arrs, core, ("centre", "rotation", "half extents") * 2):
        if a.shape[a.ndim - len(cs):] != cs:
            raise ValueError(f"box {name} has shape {a.shape}; expected (..., {', '.join(map(str, cs))})")
    batch = np.broadcast_shapes(*(a.shape[:a.ndim - len(cs)] for a, cs in zip(arrs, core)))
    return [np.broadcast_to(a, batch + cs) for a, cs in zip(arrs, core)]


def box_box_sat(ca, Ra, ha, cb, Rb, hb) -> np.ndarray:
    """Separating-axis test of boxes A (centres (..., 3), rotations (..., 3, 3), half extents (..., 3)) and B.

    Returns the largest gap (m) over the 15 candidate axes (3 + 3 face normals, 9 edge cross products): > 0 the
    boxes are apart (and this is a lower bound of their distance), <= 0 they intersect (and minus it is the
    penetration depth along the best axis). Worked in B's frame with C = Rb^T Ra (Gottschalk's OBB test, with
    each gap divided by its axis' length so that it is in metres).
    """
    ca, Ra, ha, cb, Rb, hb = _broadcast_boxes(ca, Ra, ha, cb, Rb, hb)
    RbT = np.swapaxes(Rb, -1, -2)
    C = RbT @ Ra  # column i: A's axis i in B's frame
    t = (RbT @ (ca - cb)[..., None])[..., 0]  # A's centre in B's frame
    absC = np.abs(C)
    gaps = []
    for j in range(3):  # B's face normals
        gaps.append(np.abs(t[..., j]) - hb[..., j] - (absC[..., j, :] * ha).sum(-1))
    for i in range(3):  # A's face normals
        gaps.append(np.abs((C[..., :, i] * t).sum(-1)) - ha[..., i] - (absC[..., :, i] * hb).sum(-1))
    for i in range(3):  # A's edge i x B's edge j
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            length = np.sqrt(np.maximum(1.0 - C[..., j, i] ** 2, 0.0))
            proj = np.abs(t[..., j2] * C[..., j1, i] - t[..., j1] * C[..., j2, i])
            ra = ha[..., i1] * absC[..., j, i2] + ha[..., i2] * absC[..., j, i1]
            rb = hb[..., j1] * absC[..., j2, i] + hb[..., j2] * absC[..., j1, i]
            ok = length > 1e-9  # parallel edges give no axis
            gaps.append(np.where(ok, (proj - ra - rb) / np.where(ok, length, 1.0), -np.inf))
    return np.max(np.stack(gaps, axis=-1), axis=-1)


def _point_box_distance(p, c, R, h) -> np.ndarray:
    """Distance (m) of points p (..., 3) to boxes (c (..., 3), R (..., 3, 3), h (..., 3)); 0 inside."""
    loc = np.einsum("...ik,...i->...k", R, p - c)
    return np.linalg.norm(np.maximum(np.abs(loc) - h, 0.0), axis=-1)


def _segment_distance(p1, q1, p2, q2) -> np.ndarray:
    """Distance between segments [p1, q1] and [p2, q2], arrays (..., 3) (Ericson, Real-Time Collision
    Detection, 5.1.9), vectorised, degenerate segments included."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.sum(d1 * d1, -1)
    e = np.sum(d2 * d2, -1)
    f = np.sum(d2 * r, -1)
    c = np.sum(d1 * r, -1)
    b = np.sum(d1 * d2, -1)
    eps = 1e-18
    den = a * e - b * b
    s = np.where(den > eps, np.clip((b * f - c * e) / np.where(den > eps, den, 1.0), 0.0, 1.0), 0.0)
    s = np.where(a <= eps, 0.0, s)
    t = np.where(e > eps, (b * s + f) / np.where(e > eps, e, 1.0), 0.0)
    # t outside [0, 1]: clamp it and recompute s
    t_c = np.clip(t, 0.0, 1.0)
    s_c = np.where(a > eps, np.clip((t_c * b - c) / np.where(a > eps, a, 1.0), 0.0, 1.0), 0.0)
    redo = (t < 0.0) | (t > 1.0)
    s = np.where(redo, s_c, s)
    t = t_c
    diff = (p1 + s[..., None] * d1) - (p2 + t[..., None] * d2)
    return np.linalg.norm(diff, axis=-1)


def box_box_distance(ca, Ra, ha, cb, Rb, hb) -> np.ndarray:
    """Signed distance (m) between boxes A and B (shapes as :func:`box_box_sat`): exact when apart (the
    smallest of vertex-box and edge-edge distances, which covers every closest-feature pair of two convex
    polyhedra), minus the separating-axis penetration depth when they intersect."""
    ca, Ra, ha, cb, Rb, hb = _broadcast_boxes(ca, Ra, ha, cb, Rb, hb)
    sat = box_box_sat(ca, Ra, ha, cb, Rb, hb)
    va = ca[..., None, :] + np.einsum("...ik,...vk->...vi", Ra, _SIGNS * ha[..., None, :])  # (..., 8, 3)
    vb = cb[..., None, :] + np.einsum("...ik,...vk->...vi", Rb, _SIGNS * hb[..., None, :])
    d = np.minimum(  # vertices of one box against the other box
        _point_box_distance(va, cb[..., None, :], Rb[..., None, :, :], hb[..., None, :]).min(-1),
        _point_box_distance(vb, ca[..., None, :], Ra[..., None, :, :], ha[..., None, :]).min(-1))
    ea0, ea1 = va[..., _EDGES[:, 0], :], va[..., _EDGES[:, 1], :]  # (..., 12, 3)
    eb0, eb1 = vb[..., _EDGES[:, 0], :], vb[..., _EDGES[:, 1], :]
    dee = _segment_distance(ea0[..., :, None, :], ea1[..., :, None, :], eb0[..., None, :, :], eb1[..., None, :, :])
    d = np.minimum(d, dee.min(axis=(-1, -2)))
    return np.where(sat > 0.0, d, sat)


def box_wall_collision(c, R, h, wall: WallWithHole) -> np.ndarray:
    """Exact intersection test of boxes (c (..., 3), R (..., 3, 3), h (..., 3)) with a wall's solid: (...) bool.

    The box meets the solid (slab minus the hole's cylinder) exactly when it meets the slab (separating axes)
    and its part inside the slab's infinite layer is not wholly inside the cylinder. That part is convex and
    the cylinder is convex, so it is enough to test its vertices: the box's vertices in the layer and the points
    where the box's edges cross the layer's two faces. (The hole lies inside the wall, so leaving the cylinder
    inside the layer means entering the solid.)
    """
    slab = wall.slab()
    meets = box_box_sat(c, R, h, slab.centre, slab.rotation, slab.size / 2) <= 0.0
    W = wall.rotation
    v = c[..., None, :] + np.einsum("...ik,...vk->...vi", R, _SIGNS * h[..., None, :])  # (..., 8, 3)
    loc = (v - wall.centre) @ W  # hole coordinates
    half_t = wall.size[2] / 2
    r2 = (wall.hole_diameter / 2) ** 2
    in_layer = np.abs(loc[..., 2]) <= half_t
    out_cyl = (loc[..., 0] ** 2 + loc[..., 1] ** 2) > r2
    bad = (in_layer & out_cyl).any(axis=-1)
    a, b = loc[..., _EDGES[:, 0], :], loc[..., _EDGES[:, 1], :]  # (..., 12, 3)
    for face in (-half_t, half_t):
        da, db = a[..., 2] - face, b[..., 2] - face
        cross = (da * db <= 0.0) & (da != db)
        s = np.where(cross, da / np.where(da != db, da - db, 1.0), 0.0)
        p = a + s[..., None] * (b - a)
        bad |= (cross & ((p[..., 0] ** 2 + p[..., 1] ** 2) > r2)).any(axis=-1)
    return meets & bad


def _box_surface_points(h: np.ndarray, spacing: float) -> np.ndarray:
    """Points on the surface of a box of half extents h (3,), in its frame, at most ``spacing`` m apart."""
    pts = []
    for k in range(3):
        i, j = [a for a in range(3) if a != k]
        ni = max(2, int(np.ceil(2 * h[i] / spacing)) + 1)
        nj = max(2, int(np.ceil(2 * h[j] / spacing)) + 1)
        gi, gj = np.meshgrid(np.linspace(-h[i], h[i], ni), np.linspace(-h[j], h[j], nj), indexing="ij")
        for sgn in (-1.0, 1.0):
            p = np.zeros((gi.size, 3))
            p[:, i], p[:, j], p[:, k] = gi.ravel(), gj.ravel(), sgn * h[k]
            pts.append(p)
    return np.unique(np.concatenate(pts), axis=0)


@dataclass(frozen=True)
class CollisionReport:
    """Result of :func:`collision_check` for T samples, k boxed links and the obstacles in the order given.

    distance (T,) m: the smallest distance between any link box and any obstacle (<= 0 on collision);
    collides (T,) bool; link_distance (T, k, n_obstacles) and link_collides (T, k, n_obstacles) per link and
    obstacle; links (k,) indices into ``robot.link_names``.
    """

    distance: np.ndarray
    collides: np.ndarray
    link_distance: np.ndarray
    link_collides: np.ndarray
    links: np.ndarray


def collision_check(robot: SnakeRobot, qs, obstacles, base: BasePlacement | None = None, *,
                    exact_within: float = 0.05, spacing: float = 0.004) -> CollisionReport:
    """Collisions of every link's collision box with obstacles along a trajectory qs (T, 16).

    The collision flags are exact. The distances are exact wherever they are below ``exact_within`` m; pairs
    that the separating-axis test already puts farther apart report that test's gap, a lower bound that is
    itself above ``exact_within`` (this keeps long trajectories fast).

    * :class:`BoxObstacle`: exact signed distance (:func:`box_box_distance`; minus the penetration depth when
      they intersect).
    * :class:`WallWithHole`: exact intersection test (:func:`box_wall_collision`); the distance of a nearby
      link that does not collide is the smallest exact distance from points on its box's surface, at most
      ``spacing`` m apart, to the wall's solid: an upper bound, too large by at most about spacing / sqrt(2).
      Colliding links get 0.
    """
    robot = as_robot(robot)
    base = as_base(base)
    qs = _trajectory(robot, qs)
    if isinstance(obstacles, (BoxObstacle, WallWithHole)):
        obstacles = [obstacles]
    obstacles = list(obstacles)
    if not obstacles:
        raise ValueError("no obstacles given")
    for ob in obstacles:
        if not isinstance(ob, (BoxObstacle, WallWithHole)):
            raise TypeError(f"obstacles must be BoxObstacle or WallWithHole, got {type(ob).__name__}")
    spacing = positive(spacing, "spacing")
    try:
        exact_within = float(exact_within)
    except (TypeError, ValueError):
        raise ValueError(f"exact_within must be a number (m, may be inf), got {exact_within!r}") from None
    if np.isnan(exact_within):
        raise ValueError("exact_within is NaN")
    links, c, R, h = _link_boxes(robot, qs, base)
    T, k = c.shape[:2]
    hb = np.broadcast_to(h, (T, k, 3))
    dist = np.empty((T, k, len(obstacles)))
    hit = np.empty((T, k, len(obstacles)), bool)
    for o, ob in enumerate(obstacles):
        box = ob if isinstance(ob, BoxObstacle) else ob.slab()
        d = box_box_sat(c, R, hb, box.centre, box.rotation, box.size / 2)  # lower bound of the distance
        near = d <= exact_within
        if isinstance(ob, BoxObstacle):
            d[near] = box_box_distance(c[near], R[near], hb[near], box.centre, box.rotation, box.size / 2)
            collide = d <= 0.0
        else:
            collide = np.zeros((T, k), bool)
            collide[near] = box_wall_collision(c[near], R[near], hb[near], ob)
            for li in range(k):  # per link (its own surface samples), vectorised over the near samples
                rows = np.flatnonzero(near[:, li] & ~collide[:, li])
                if rows.size == 0:
                    continue
                s = _box_surface_points(h[li], spacing)  # (S, 3)
                p = c[rows, li, None, :] + np.einsum("tik,sk->tsi", R[rows, li], s)
                d[rows, li] = ob.distance_to_points(p).min(axis=1)
            d = np.where(collide, 0.0, d)
        dist[..., o], hit[..., o] = d, collide
    return CollisionReport(dist.min(axis=(1, 2)), hit.any(axis=(1, 2)), dist, hit, links)
