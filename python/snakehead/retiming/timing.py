"""Time-optimal retiming of a whole-body path (issue 11, item 3): TOPP-RA under the robot's limits and the ZMP.

:func:`retime` takes waypoints (K, n) -- the states of a plan, or the dense configurations of a Cartesian move --
joins them by a smooth path q(s) through every one of them that never leaves the range of two neighbouring
waypoints (so never a joint limit), and finds the fastest motion along it (TOPP-RA, Pham and Pham 2018: the
constraints of every gridpoint in numpy, :mod:`._topp`; the passes and each gridpoint's 2-D LP in the C++ core,
``snakehead._core.topp_ra``, as the ``toppra`` package's ``seidel`` solver does them) that keeps, at every gridpoint
(and, the grid refined where needed, between them: at every sample):

* each joint's velocity within ``velocity_limit`` (default :data:`VELOCITY_SHARE` of the URDF's);
* each joint's acceleration within ``acceleration_limit`` (URDFs have none: default :data:`ACCELERATION_LIMIT`);
* each joint's torque within ``torque_limit`` (default :data:`TORQUE_SHARE` of the URDF's effort): the torques of
  :func:`snakehead.dynamics.inverse_dynamics.inverse_dynamics`, links resting on the ground carried by it;
* the ZMP (Eqs. 39-40, p_z = 0) inside the support polygon of the links on the ground
  (``stability.support_polygons(..., contact="ground")``) by ``zmp_margin`` m;
* the horizontal momentum rate within the friction the ground can give the base,
  |dP_xy/dt| <= ``friction`` (M g + dP_z/dt) (default :data:`FRICTION`: a share of the simulation's 0.8), since a
  snake's base slides when it is pushed; and the ground pushing, M g + dP_z/dt >= :data:`MIN_NORMAL_SHARE` M g.

Why the ZMP is a linear constraint: with w = (dP/dt, dL/dt) (Eqs. 33-34, L about the world origin), the ZMP
lies on the inner side of a polygon edge n . p >= d + m exactly when, multiplied through by M g + dP_z/dt > 0,
n_x (M g c_x - dL_y/dt) + n_y (M g c_y + dL_x/dt) - (d + m)(M g + dP_z/dt) >= 0 -- linear in w. Along a path q(s)
the joint velocities are q' s' and the accelerations q' s'' + q'' s'^2, so w = a(s) s'' + b(s) s'^2 with a the
momentum rate of Newton-Euler at (q, 0, q') and b at (q, q', q'') (:func:`momentum_rate_coefficients`; the joint
torques split the same way): exactly TOPP-RA's form, one row per edge. Polygons are padded to one edge count by
repeating an edge.

Where the centre of mass itself is closer than twice ``zmp_margin`` to the polygon's edge (a barely stable path),
the ZMP is asked to keep half the CoM's margin instead (at rest the ZMP is the CoM's projection, so no motion can
do better there); the result's ``notes`` say where. A waypoint repeated (a zero-length segment) is a pause of
``hold_s`` s; the motion comes to rest there, at ``stops``, at both ends and where the path turns back on itself
(every joint reverses or stops at a waypoint).

:func:`check_limits` measures any sampled trajectory against the same limits (the retimed one is checked at every
2 ms sample); the result says what binds.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, fields, replace
from typing import Any, Callable, Sequence

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline

from .. import _core
from .._validate import MAX_SAMPLES, finite_array, finite_float, positive, sample_count
from ..dynamics import stability
from ..dynamics.inverse_dynamics import InverseDynamics, inverse_dynamics, newton_euler
from ..margins import ZMP_MARGIN
from ..model.physics import GRAVITY, GROUND_FRICTION
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from . import _topp
from ..trajectory.interpolation import CONTROL_PERIOD, JointTrajectory, MonotoneQuintic, sample_times
from .._errors import Infeasible, InputError, InputTypeError, MotionTooLong

#: q(s) and its derivatives: f(s (N,), order 0, 1 or 2) -> (N, n).
PathFunction = Callable[[np.ndarray, int], np.ndarray]

#: Share of the URDF's joint velocity limits used by default.
VELOCITY_SHARE = 0.5
#: rad/s^2: joint acceleration limit by default (URDFs give none). bench/timing.py measures the paper's scenarios
#: from 0.5 to 4 rad/s^2: at 2 both are within the paper's durations and simulated errors with the simulated ZMP
#: inside by millimetres; at 4 the simulated ZMP comes within a millimetre of the base's edge.
ACCELERATION_LIMIT = 2.0
#: Share of the URDF's joint effort limits used by default: room for the PD controller's corrections.
TORQUE_SHARE = 0.8
#: Where the CoM itself is less than 2 ZMP_MARGIN inside the support polygon, the ZMP must keep ZMP_MARGIN while the
#: CoM keeps this much more (m) of room for the motion's dynamic terms, or else half the CoM's margin.
ZMP_DYNAMIC_ROOM = 0.002
#: Friction coefficient the retiming allows the base by default: half the simulated ground's (GROUND_FRICTION, the
#: MuJoCo model's), since the contacts are unevenly loaded and some slide before the total reaches mu times the load.
FRICTION = 0.5 * GROUND_FRICTION
#: The ground must push with at least this share of the weight (M g + dP_z/dt >= MIN_NORMAL_SHARE M g).
MIN_NORMAL_SHARE = 0.1
#: Sides of the polygon inscribed in the friction circle |dP_xy/dt| <= mu N (a linear constraint).
FRICTION_SIDES = 8
#: s: a repeated waypoint's pause by default.
HOLD_S = 1.0
#: rad: the largest step of the path (Euclidean length in joint space) between two TOPP-RA gridpoints.
GRID_STEP = 0.02
#: Gridpoints per segment between two waypoints, at least.
MIN_GRID_PER_SEGMENT = 8
#: The most gridpoints of one retimed path (a path of 1000 rad at the default step): a larger grid is a mistake.
MAX_GRID_POINTS = 100_000
#: rad: two waypoints closer than this (largest joint difference) are the same: a hold.
SAME_WAYPOINT = 1e-9
#: Where the path stands still (a cusp: every joint turns back or stops at a waypoint) the joint velocity limits do
#: not bound the path's speed s' (rad of joint-space path per s); it is capped at this multiple of the norm of the
#: velocity limits (each taken at most MAX_JOINT_SPEED rad/s). Elsewhere |q'(s)| is about 1 and the limits bind.
PATH_SPEED_FACTOR = 10.0
MAX_JOINT_SPEED = 100.0
#: TOPP-RA is given this share of the velocity, acceleration, torque and friction limits, and the ZMP margin plus
#: SOLVE_ZMP_EXTRA_M: the room that the path's curvature between gridpoints takes, so that the limits themselves hold
#: at every sample without many refinement rounds.
SOLVE_SHARE = 0.995
SOLVE_ZMP_EXTRA_M = 2e-4
#: Rounds of grid refinement: stages that break a limit between their gridpoints are cut in four (their neighbours
#: in two) and the path is solved again.
REFINE_ROUNDS = 4
#: m: how far the ZMP may come inside its required margin between gridpoints before the stage is halved (less is
#: round-off of the path's curvature, not worth a finer grid).
REFINE_ZMP_M = 1e-5
#: The refinement stops when the grid would grow beyond this multiple of its first size plus REFINE_EXTRA_POINTS.
REFINE_GROWTH = 3.0
REFINE_EXTRA_POINTS = 1000
#: Points probed inside each stage for the refinement.
PROBES = 5
#: The paths :func:`retime` can join the waypoints with.
INTERPOLATIONS = ("monotone", "spline")
#: How close (share of the limit) a sample must come to a limit to count as binding in :class:`LimitCheck`.
BINDING_SHARE = 0.97
#: m: how close the ZMP must come to its required margin to count as binding.
BINDING_ZMP_M = 0.001


# ------------------------------------------------------------------------------------------------
# limits
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RetimingLimits:
    """The limits a retimed motion keeps: per joint velocity (rad/s), acceleration (rad/s^2) and torque (N m),
    (n,) each (inf: none); the ZMP's margin (m) inside the support polygon; the friction coefficient."""

    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    zmp_margin: float
    friction: float


def _joint_limit(value: npt.ArrayLike | None, n: int, name: str, default: np.ndarray | None = None) -> np.ndarray:
    """A per-joint limit from a number or (n,) array; zeros in ``default`` (URDF gives none) become inf."""
    if value is None:
        assert default is not None, name
        limit = np.where(default > 0, default, np.inf)
    else:
        try:
            limit = np.asarray(value, float)
        except (TypeError, ValueError):
            raise InputTypeError(f"{name} must be a number or an array of {n} numbers, got {type(value).__name__}") from None
        if limit.ndim == 0:
            limit = np.full(n, float(limit))
        if limit.shape != (n,):
            raise InputError(f"{name} must be a number or shape ({n},), got shape {limit.shape}")
    if np.any(np.isnan(limit)) or np.any(limit <= 0):
        raise InputError(f"{name} must be positive (inf for none), got {np.asarray(limit).tolist()}")
    return limit


def resolve_limits(robot: SnakeRobot, *, velocity_limit: npt.ArrayLike | None = None,
                   acceleration_limit: npt.ArrayLike | None = ACCELERATION_LIMIT, torque_limit: npt.ArrayLike | None = None,
                   zmp_margin: float = ZMP_MARGIN, friction: float = FRICTION) -> RetimingLimits:
    """The limits :func:`retime` uses, from its keywords (see there); ValueError/TypeError for bad ones."""
    robot = as_robot(robot)
    n = robot.n_joints
    vel = _joint_limit(velocity_limit, n, "velocity_limit", VELOCITY_SHARE * robot.velocity_limit)
    if acceleration_limit is None:
        raise InputError("acceleration_limit is needed (URDFs give none); e.g. "
                         f"{ACCELERATION_LIMIT} rad/s^2, the default")
    acc = _joint_limit(acceleration_limit, n, "acceleration_limit")
    tau = _joint_limit(torque_limit, n, "torque_limit", TORQUE_SHARE * robot.effort)
    margin = finite_float(zmp_margin, "zmp_margin")
    if margin < 0:
        raise InputError(f"zmp_margin must be >= 0 m, got {zmp_margin!r}")
    mu = positive(friction, "friction")
    return RetimingLimits(vel, acc, tau, margin, mu)


# ------------------------------------------------------------------------------------------------
# the stability constraint: ZMP in the support polygon, friction, the ground pushing
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Support:
    """The ground support of configurations q (N, n), computed once: each polygon's edges (padded to one count by
    repeating the first) as inward unit normals (N, E, 2) and offsets d (N, E) (inside: n . p >= d); the centre of
    mass (N, 3); its static margin (N,) m; the margin (N,) m the ZMP must keep there (:func:`required_margins`)."""

    normal: np.ndarray
    offset: np.ndarray
    com: np.ndarray
    static: np.ndarray
    required: np.ndarray

    @classmethod
    def of(cls, robot: SnakeRobot, q: np.ndarray, base: BasePlacement, zmp_margin: float,
           frames: np.ndarray | None = None) -> "Support":
        """``frames``: the world frames of q, when the caller has them."""
        frames = robot.frames_many(q, base) if frames is None else frames
        V, count = stability.support_polygons(robot, q, base, contact="ground", frames=frames)
        if np.any(count < 3):
            k = int(np.argmax(count < 3))
            raise Infeasible(f"the links on the ground span no polygon at path point {k} ({count[k]} distinct "
                             "contact points): the body cannot stand there")
        h = np.arange(V.shape[1])[None, :]
        start = np.where(h < count[:, None], h, 0)  # padding repeats the first edge
        stop = np.where(start + 1 < count[:, None], start + 1, 0)
        a = np.take_along_axis(V, start[..., None], axis=1)
        e = np.take_along_axis(V, stop[..., None], axis=1) - a
        normal = np.stack([-e[..., 1], e[..., 0]], axis=-1) / np.linalg.norm(e, axis=-1, keepdims=True)  # inside
        offset = (normal * a).sum(-1)
        com = stability.center_of_mass(robot, q, base, frames=frames)
        static = ((normal * com[:, None, :2]).sum(-1) - offset).min(axis=1)
        return cls(normal, offset, com, static, required_margins(static, zmp_margin))

    def take(self, index: np.ndarray) -> "Support":
        """The support of the configurations ``index`` (an index array into the N)."""
        return Support(*(getattr(self, f.name)[index] for f in fields(self)))

    def joined(self, other: "Support") -> "Support":
        """Both supports, one after the other; the polygons padded to one edge count (repeating the first edge)."""
        edges = max(self.offset.shape[1], other.offset.shape[1])
        a, b = self._padded(edges), other._padded(edges)
        return Support(*(np.concatenate([getattr(a, f.name), getattr(b, f.name)]) for f in fields(self)))

    def _padded(self, edges: int) -> "Support":
        extra = edges - self.offset.shape[1]
        if extra == 0:
            return self
        pad = np.zeros(self.offset.shape[1] + extra, int)
        pad[:self.offset.shape[1]] = np.arange(self.offset.shape[1])
        return replace(self, normal=self.normal[:, pad], offset=self.offset[:, pad])

    def margins(self, xy: np.ndarray) -> np.ndarray:
        """Signed distance (m) of points xy (N, 2) inside each polygon: exact inside (the nearest edge), negative
        outside (by the edge line crossed most)."""
        return ((self.normal * xy[:, None, :]).sum(-1) - self.offset).min(axis=1)


def required_margins(static: npt.ArrayLike, zmp_margin: float) -> np.ndarray:
    """The margin (m) the ZMP must keep inside the support polygon where the CoM keeps ``static`` m:
    ``zmp_margin`` where the CoM leaves ZMP_DYNAMIC_ROOM more, else the larger of half the CoM's own margin and
    the CoM's margin less ZMP_DYNAMIC_ROOM. (Half alone made a plan through a CoM 7-10 mm inside keep a ZMP
    margin under the plan's own check, ``zmp_margin``: it failed although a slower motion passes. Where the
    time-optimal motion kept ``zmp_margin`` anyway, the tighter constraint is inactive and the motion the same.)"""
    static = np.asarray(static, float)
    return np.minimum(zmp_margin, np.maximum(0.5 * static, static - ZMP_DYNAMIC_ROOM))


def stability_rows(robot: SnakeRobot, support: Support, limits: RetimingLimits, extra_margin: float = 0.0
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The stability constraints at N configurations as F w <= g on w = (dP/dt, dL/dt) (N, 6):
    F (N, E + FRICTION_SIDES + 1, 6), g (N, E + FRICTION_SIDES + 1).

    Rows: one per support-polygon edge (the ZMP at least the margin that ``limits.zmp_margin`` requires
    (:func:`required_margins`), plus ``extra_margin`` m (at most 90 % of the CoM's own margin), inside it,
    multiplied through by
    M g + dP_z/dt), the friction polygon inscribed in |dP_xy/dt| <= mu (M g + dP_z/dt), and
    M g + dP_z/dt >= MIN_NORMAL_SHARE M g.
    """
    Mg = robot.total_mass * GRAVITY
    N, E = support.offset.shape
    margin = np.minimum(required_margins(support.static, limits.zmp_margin) + extra_margin, 0.9 * support.static)
    off = support.offset + margin[:, None]
    normal = support.normal
    F_zmp = np.zeros((N, E, 6))
    F_zmp[..., 2] = off  # (d + m) dP_z/dt - n_y dL_x/dt + n_x dL_y/dt <= M g (n . c - d - m)
    F_zmp[..., 3] = -normal[..., 1]
    F_zmp[..., 4] = normal[..., 0]
    g_zmp = Mg * ((normal * support.com[:, None, :2]).sum(-1) - off)
    theta = 2 * np.pi * np.arange(FRICTION_SIDES) / FRICTION_SIDES
    mu = limits.friction * np.cos(np.pi / FRICTION_SIDES)  # the inscribed polygon's apothem
    F_fr = np.zeros((FRICTION_SIDES + 1, 6))
    F_fr[:-1, 0], F_fr[:-1, 1], F_fr[:-1, 2] = np.cos(theta), np.sin(theta), -mu  # u . dP_xy/dt <= mu N
    F_fr[-1, 2] = -1.0  # -dP_z/dt <= (1 - MIN_NORMAL_SHARE) M g
    g_fr = np.r_[np.full(FRICTION_SIDES, mu * Mg), (1.0 - MIN_NORMAL_SHARE) * Mg]
    F = np.concatenate([F_zmp, np.broadcast_to(F_fr, (N,) + F_fr.shape)], axis=1)
    g = np.concatenate([g_zmp, np.broadcast_to(g_fr, (N, len(g_fr)))], axis=1)
    return F, g


def momentum_rate_coefficients(robot: SnakeRobot, q: npt.ArrayLike, dq: npt.ArrayLike, ddq: npt.ArrayLike,
                               base: BasePlacement | None = None, frames: np.ndarray | None = None
                               ) -> tuple[np.ndarray, np.ndarray]:
    """w = (dP/dt, dL/dt) along a path q(s) as a s'' + b s'^2: a, b (N, 6) at points q, dq = q'(s), ddq = q''(s)
    (N, n) each. With qd = q' s' and qdd = q' s'' + q'' s'^2, the momentum rates of Newton-Euler (inertial part:
    :func:`~snakehead.dynamics.inverse_dynamics.newton_euler`) split into a = w(q, 0, q') and b = w(q, q', q'').
    ``frames``: the world frames of q when the caller has them."""
    a, b = _path_dynamics(robot, np.asarray(q, float), np.asarray(dq, float), np.asarray(ddq, float), base, frames)
    return np.hstack([a.Pdot, a.Ldot]), np.hstack([b.Pdot, b.Ldot])


def _path_dynamics(robot: SnakeRobot, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, base: BasePlacement | None,
                   frames: np.ndarray | None = None) -> tuple[Any, Any]:
    """Newton-Euler's inertial terms along q(s): (the pass at (q, 0, q'), the pass at (q, q', q'')); their torques
    and momentum rates are the coefficients of s'' and of s'^2."""
    zero = np.zeros_like(q)
    return (newton_euler(robot, q, zero, dq, base, gravity="none", frames=frames),
            newton_euler(robot, q, dq, ddq, base, gravity="none", frames=frames))


# ------------------------------------------------------------------------------------------------
# checking a sampled trajectory against the limits
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LimitCheck:
    """How a sampled trajectory meets :class:`RetimingLimits` (worst over its samples).

    velocity_ratio, acceleration_ratio, torque_ratio: max over samples and joints of |value| / limit (<= 1 keeps it).
    zmp_margin_m: the least signed distance (m) of the ZMP inside its sample's support polygon; zmp_slack_m: the
    least of that minus the required margin (>= 0 keeps it). friction_ratio: max |dP_xy/dt| / (mu (M g + dP_z/dt)).
    binding: for each of "velocity", "acceleration", "torque", "zmp", "friction", the share of the moving samples
    at which it is within BINDING_SHARE of its limit (the ZMP: within BINDING_ZMP_M of its margin).
    """

    velocity_ratio: float
    acceleration_ratio: float
    torque_ratio: float
    zmp_margin_m: float
    zmp_slack_m: float
    friction_ratio: float
    binding: dict = field(default_factory=dict)

    def within(self, tolerance: float = 1e-3, zmp_tolerance_m: float = 1e-4) -> bool:
        """Every limit kept, ratios up to 1 + ``tolerance`` and the ZMP's margin to ``zmp_tolerance_m`` m."""
        ratios = (self.velocity_ratio, self.acceleration_ratio, self.torque_ratio, self.friction_ratio)
        return max(ratios) <= 1.0 + tolerance and self.zmp_slack_m >= -zmp_tolerance_m


def _ratios(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, support: Support, q: np.ndarray,
            qd: np.ndarray, qdd: np.ndarray, frames: np.ndarray | None = None, dyn: InverseDynamics | None = None
            ) -> dict[str, np.ndarray]:
    """Per sample (T,): the largest |value| / limit of the joint velocities, accelerations and torques, the friction
    used (|dP_xy/dt| / (mu (M g + dP_z/dt))), the ZMP's margin in ``support`` and its slack over the required one.
    ``dyn``: the samples' Newton-Euler pass when the caller has it."""
    if dyn is None:
        dyn = newton_euler(robot, q, qd, qdd, base, frames=frames)  # torques and exact momentum rates
    # in the core (the numpy it replaces, to the bit: Mg + dP_z/dt <= 0 means the ground would have to pull, no ZMP)
    c = np.ascontiguousarray
    ratios = _core.limit_ratios(c(qd), c(qdd), c(dyn.tau), c(dyn.Pdot), c(dyn.Ldot), c(support.com), c(support.normal),
                                c(support.offset), c(limits.velocity, float), c(limits.acceleration, float),
                                c(limits.torque, float), robot.total_mass * GRAVITY, float(limits.friction))
    ratios["zmp_slack"] = ratios["zmp_margin"] - support.required
    return ratios


def check_limits(robot: SnakeRobot, q: npt.ArrayLike, qd: npt.ArrayLike, qdd: npt.ArrayLike, base: BasePlacement | None,
                 limits: RetimingLimits) -> LimitCheck:
    """Measure samples q, qd, qdd (T, n) of a trajectory against ``limits``: joint velocities and accelerations, the
    torques of :func:`inverse_dynamics`, the ZMP of Eqs. 39-40 from the momentum rates of Newton-Euler in the ground
    support polygon of each sample, and the base's friction. (An independent check of the ZMP, from the paper's
    momenta of Eqs. 25-31 and their finite differences: ``stability.dynamic_stability``.)"""
    robot = as_robot(robot)
    base = as_base(base)
    if not isinstance(limits, RetimingLimits):
        raise InputTypeError(f"limits must be RetimingLimits, got {type(limits).__name__}")
    q = finite_array(q, "q", (None, robot.n_joints))
    qd = finite_array(qd, "qd", q.shape)
    qdd = finite_array(qdd, "qdd", q.shape)
    frames = robot.frames_many(q, base)
    r = _ratios(robot, base, limits, Support.of(robot, q, base, limits.zmp_margin, frames), q, qd, qdd, frames)
    moving = np.abs(qd).max(axis=1) > 0

    def share(hit: np.ndarray) -> float:
        return float(np.mean(hit[moving])) if moving.any() else 0.0

    binding = {key: share(r[key] >= BINDING_SHARE) for key in ("velocity", "acceleration", "torque", "friction")}
    binding["zmp"] = share(r["zmp_slack"] <= BINDING_ZMP_M)
    return LimitCheck(float(r["velocity"].max()), float(r["acceleration"].max()), float(r["torque"].max()),
                      float(r["zmp_margin"].min()), float(r["zmp_slack"].min()), float(r["friction"].max()), binding)


# ------------------------------------------------------------------------------------------------
# the retimed trajectory
# ------------------------------------------------------------------------------------------------
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


class _Timeline:
    """The retimed motion as a function of time: rest-to-rest pieces along their paths, and pauses."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.items: list[dict[str, Any]] = []
        self.end = 0.0

    def add_piece(self, f: PathFunction, s: np.ndarray, sd: np.ndarray) -> np.ndarray:
        ds = np.diff(s)
        mean = 0.5 * (sd[:-1] + sd[1:])
        dt = ds / mean  # constant path acceleration over each stage
        u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * ds)
        t = self.end + np.r_[0.0, np.cumsum(dt)]
        self.items.append(dict(kind="piece", t=t, s=s, sd=sd, u=u, f=f))
        self.end = float(t[-1])
        return t

    def add_pause(self, q: np.ndarray, seconds: float) -> None:
        self.items.append(dict(kind="pause", t=np.array([self.end, self.end + seconds]), q=q))
        self.end += seconds

    def __call__(self, t: npt.ArrayLike, nu: int = 0) -> np.ndarray:
        if nu not in (0, 1, 2):
            raise InputError("nu must be 0, 1 or 2")
        return self.sample(t, (nu,))[0]

    def sample(self, t: npt.ArrayLike, orders: tuple[int, ...] = (0, 1, 2)) -> list[np.ndarray]:
        """The motion's derivatives of the given ``orders`` (0, 1, 2: q, qd, qdd) at times t: a list of (N, n), the
        path evaluated once for all of them. Times before the motion take its first item, after it its last."""
        t = np.atleast_1d(finite_array(t, "t"))
        if np.any(np.diff(t) < 0):  # in time order, then back in the caller's
            order = np.argsort(t, kind="stable")
            result = self.sample(t[order], orders)
            for r in result:
                r[order] = r.copy()
            return result
        out = [np.zeros((len(t), self.n)) for _ in orders]
        path_orders = tuple(sorted(set(orders) | ({1} if 2 in orders else set())))  # qdd needs q'(s) too
        # item k holds the times in [start_k, start_k+1) (the last item also its end and after): one search for all
        starts = np.array([item["t"][0] for item in self.items[1:]])
        bounds = np.r_[0, np.searchsorted(t, starts, side="left"), len(t)]
        for item, lo, hi in zip(self.items, bounds[:-1], bounds[1:]):
            if hi <= lo:
                continue
            if item["kind"] == "pause":
                for o, nu in zip(out, orders):
                    if nu == 0:
                        o[lo:hi] = item["q"]
                continue
            tt = item["t"]
            i = np.clip(np.searchsorted(tt, t[lo:hi], side="right") - 1, 0, len(tt) - 2)
            tau = np.clip(t[lo:hi] - tt[i], 0.0, tt[i + 1] - tt[i])
            s = np.clip(item["s"][i] + item["sd"][i] * tau + 0.5 * item["u"][i] * tau ** 2, item["s"][i],
                        item["s"][i + 1])
            sd = np.maximum(item["sd"][i] + item["u"][i] * tau, 0.0)
            d = dict(zip(path_orders, _path_derivatives(item["f"], s, path_orders)))
            for o, nu in zip(out, orders):
                if nu == 0:
                    o[lo:hi] = d[0]
                elif nu == 1:
                    o[lo:hi] = d[1] * sd[:, None]
                else:
                    o[lo:hi] = d[1] * item["u"][i][:, None] + d[2] * (sd ** 2)[:, None]
        return out


def _path_function(s: np.ndarray, waypoints: np.ndarray, interpolation: str) -> PathFunction:
    """q(s) through the waypoints at path positions s (knots): f(s, order) -> (N, n)."""
    if interpolation == "monotone":
        return MonotoneQuintic(s, waypoints)
    spline = CubicSpline(s, waypoints, bc_type="not-a-knot", axis=0)  # as toppra's SplineInterpolator

    def f(x: np.ndarray, order: int = 0) -> np.ndarray:
        return np.asarray(spline(x, order))

    return f


def _path_derivatives(f: PathFunction, s: np.ndarray, orders: tuple[int, ...]) -> list[np.ndarray]:
    """The path's derivatives of the given orders at s (N, n each): the monotone path's in one pass."""
    if isinstance(f, MonotoneQuintic):
        return f.derivatives(s, orders)
    return [f(s, nu) for nu in orders]


def _path_values(f: PathFunction, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q(s), q'(s), q''(s) (N, n) each."""
    q, dq, ddq = _path_derivatives(f, s, (0, 1, 2))
    return q, dq, ddq


def _segments(waypoints: np.ndarray, stops: Sequence[int], hold_s: npt.ArrayLike
              ) -> tuple[list[tuple[str, int, int]], np.ndarray]:
    """The schedule: ("piece", i0, i1) runs of moving segments between rests, ("pause", k) holds; and the pause
    of each segment (K-1,)."""
    K = len(waypoints)
    same = np.abs(np.diff(waypoints, axis=0)).max(axis=1) <= SAME_WAYPOINT
    holds = finite_array(hold_s, "hold_s")
    if holds.ndim == 0:
        holds = np.full(K - 1, float(holds))
    if holds.shape != (K - 1,):
        raise InputError(f"hold_s must be a number or one per segment ({K - 1},), got shape {holds.shape}")
    if np.any(holds < 0):
        raise InputError("hold_s must be >= 0 s")
    rest = np.zeros(K, bool)
    rest[[0, -1]] = True
    # a cusp: every joint turns back or stops at the waypoint, so the path stands still there (q'(s) = 0 on the
    # monotone path): the motion comes to rest there anyway, and a piece ends there (TOPP-RA is ill-conditioned at
    # a standstill inside a path)
    step = np.diff(waypoints, axis=0)
    rest[1:-1] |= np.all(step[:-1] * step[1:] <= 0.0, axis=1) & ~same[:-1] & ~same[1:]
    for k in stops:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise InputTypeError(f"stops must be waypoint indices (int), got {k!r}")
        if not -K <= k < K:
            raise InputError(f"stop {k} is not a waypoint index (there are {K} waypoints)")
        rest[k] = True
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


def retime(robot: SnakeRobot, waypoints: npt.ArrayLike, base: BasePlacement | None = None, *,
           velocity_limit: npt.ArrayLike | None = None, acceleration_limit: npt.ArrayLike | None = ACCELERATION_LIMIT,
           torque_limit: npt.ArrayLike | None = None, zmp_margin: float = ZMP_MARGIN, friction: float = FRICTION,
           dt: float = CONTROL_PERIOD, hold_s: npt.ArrayLike = HOLD_S, stops: Sequence[int] = (),
           interpolation: str = "monotone", grid_step: float = GRID_STEP, check_samples: bool = True,
           sample: bool = True) -> RetimedTrajectory:
    """The fastest motion through ``waypoints`` that keeps the robot's limits and its balance.

    Parameters
    ----------
    robot : the snake; base : where its base lies (default placement; the result is the same for any).
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
    as_base(base)  # validated; the timing does not depend on it:
    # gravity is vertical and the ground flat, so the limits and the balance are the same wherever the base lies
    # (the friction polygon is taken in the base's frame): the path is timed at the default placement, and one
    # timing serves every placement (the planner times a lift once per base shape)
    base = BasePlacement()
    W = _checked_waypoints(robot, waypoints)
    limits = resolve_limits(robot, velocity_limit=velocity_limit, acceleration_limit=acceleration_limit,
                            torque_limit=torque_limit, zmp_margin=zmp_margin, friction=friction)
    dt = positive(dt, "dt")
    grid_step = positive(grid_step, "grid_step")
    for name, flag in (("check_samples", check_samples), ("sample", sample)):
        if not isinstance(flag, (bool, np.bool_)):
            raise InputTypeError(f"{name} must be True or False, got {flag!r}")
    if check_samples and not sample:
        raise InputError("check_samples=True needs sample=True (the samples are what it checks)")
    if interpolation not in INTERPOLATIONS:
        raise InputError(f"interpolation must be one of {INTERPOLATIONS}, got {interpolation!r}")
    schedule, holds = _segments(W, stops, hold_s)
    timeline = _Timeline(robot.n_joints)
    times = np.zeros(len(W))
    notes: list[str] = []
    for kind, i0, i1 in schedule:
        if kind == "pause":
            timeline.add_pause(W[i1], float(holds[i0]))
            times[i1] = timeline.end
        else:
            piece = _Piece(robot, base, limits, W, i0, i1, interpolation)
            grid, sd = piece.time(grid_step, notes)
            t_grid = timeline.add_piece(piece.f, grid, sd)
            times[i0:i1 + 1] = t_grid[np.searchsorted(grid, piece.knots)]
        _check_length(timeline.end, dt)
    t = sample_times(0.0, timeline.end, dt) if timeline.end > 0 else np.array([0.0])
    if not sample:
        t = t[-1:]  # the end only: each sample is evaluated on its own, so these are the full sampling's last
    q, qd, qdd = timeline.sample(t)
    q[0], q[-1] = W[0], W[-1]
    check = check_limits(robot, q, qd, qdd, base, limits) if check_samples else None
    return RetimedTrajectory(t, q, qd, qdd, timeline, waypoint_times=times, limits=limits, check=check,
                             notes=tuple(notes), solve_time_s=time.perf_counter() - clock)


def _checked_waypoints(robot: SnakeRobot, waypoints: npt.ArrayLike) -> np.ndarray:
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


class _Piece:
    """One rest-to-rest piece of the motion: the path f(s) through waypoints i0..i1 (s: its length in joint space,
    rad, with the waypoints at ``knots``), timed by TOPP-RA on a grid refined where the limits break between
    gridpoints."""

    def __init__(self, robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, W: np.ndarray, i0: int,
                 i1: int, interpolation: str) -> None:
        self.robot, self.base, self.limits, self.i0, self.i1 = robot, base, limits, i0, i1
        pts = W[i0:i1 + 1]
        self.knots = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        self.f = _path_function(self.knots, pts, interpolation)
        self.interpolation = interpolation

    def near(self, k: int, grid: np.ndarray) -> int:
        """The waypoint at or before gridpoint k."""
        return self.i0 + int(np.searchsorted(self.knots, grid[k], side="right")) - 1

    def first_grid(self, grid_step: float) -> np.ndarray:
        """Gridpoints at most ``grid_step`` rad apart, at least MIN_GRID_PER_SEGMENT per segment, on every knot."""
        knots = self.knots
        sample_count(knots[-1], grid_step, "TOPP-RA's grid (the path's length over grid_step)", unit="rad",
                     maximum=MAX_GRID_POINTS)  # before the grid is allocated and solved over
        steps = np.maximum(MIN_GRID_PER_SEGMENT, np.ceil(np.diff(knots) / grid_step).astype(int))
        return np.concatenate([np.linspace(knots[k], knots[k + 1], steps[k] + 1)[:-1] for k in range(len(steps))]
                              + [knots[-1:]])

    def time(self, grid_step: float, notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """The grid and the path speeds s' at its points; Infeasible where no timing keeps the limits."""
        points = GridPoints.of(self.robot, self.base, self.f, self.first_grid(grid_step), self.limits.zmp_margin)
        self._precheck(points)
        support, grid = points.support, points.s
        if np.any(support.required < self.limits.zmp_margin):
            k = int(np.argmin(support.static))
            notes.append(f"the CoM is only {1000 * support.static[k]:.1f} mm inside the support polygon near waypoint "
                         f"{self.near(k, grid)}: the ZMP keeps {1000 * support.required[k]:.1f} mm there instead of "
                         f"{1000 * self.limits.zmp_margin:.1f} mm")
        return self._refine(points, notes)

    def _refine(self, points: "GridPoints", notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """Solve; cut the stages that break a limit between their gridpoints; again, up to REFINE_ROUNDS times
        (the constraints computed once per gridpoint)."""
        first_size = len(points.s)
        kept = _stage_keys(np.zeros(0), np.zeros(0))  # stages (s_i, s_i+1, x_i, x_i+1) probed within the limits
        for refinement in range(REFINE_ROUNDS + 1):
            solution = _solve_grid(self.robot, points, self.limits)
            if solution.sd is None:
                raise Infeasible(f"no motion along the path keeps every limit near waypoint "
                                 f"{self.near(max(solution.failed_at, 0), points.s)} (between waypoints {self.i0} and "
                                 f"{self.i1}); loosen the limits or the ZMP margin there")
            if refinement == REFINE_ROUNDS:
                break
            # a stage that is the same as one probed within the limits in an earlier round (same ends, same
            # speeds: the profile there did not change) is within them again: only the others are probed
            x = solution.sd ** 2
            stages = _stage_keys(points.s, x)
            todo = ~np.isin(stages, kept)
            split = _stages_over(self.robot, self.base, self.limits, self.f, points.s, solution.sd, points.support,
                                 only=todo)
            kept = np.concatenate([kept, stages[todo & ~split]])
            if not split.any():
                break
            refined = _refined(points.s, split)
            if len(refined) > REFINE_GROWTH * first_size + REFINE_EXTRA_POINTS:  # not a local defect: say so rather than grow on
                notes.append(f"waypoints {self.i0}..{self.i1}: {split.sum()} of {len(split)} stages still break a "
                             "limit between gridpoints after refining; see check")
                break
            added = GridPoints.of(self.robot, self.base, self.f, np.setdiff1d(refined, points.s),
                                  self.limits.zmp_margin)
            points = points.merged(added)
        assert solution.sd is not None  # the loop raised otherwise
        return points.s, solution.sd

    def _precheck(self, points: "GridPoints") -> None:
        """Clear errors for paths no timing can follow: the spline leaves the joint limits, or holding still already
        breaks a limit."""
        robot, grid, support = self.robot, points.s, points.support
        if self.interpolation == "spline":
            over = np.maximum(robot.lower - points.q, points.q - robot.upper).max()
            if over > 1e-9:
                raise Infeasible(f"the spline through waypoints {self.i0}..{self.i1} overshoots a joint limit by "
                                 f"{np.degrees(over):.2f} deg; use interpolation='monotone'")
        if np.any(support.static <= 0):
            k = int(np.argmin(support.static))
            raise Infeasible(f"the centre of mass is {-1000 * support.static[k]:.1f} mm outside the support polygon "
                             f"near waypoint {self.near(k, grid)}: no motion along this path is stable there")
        hold = np.abs(points.tau_hold) / self.limits.torque
        if hold.max() > 1.0:
            k, j = (int(i) for i in np.unravel_index(int(np.argmax(hold)), hold.shape))
            raise Infeasible(f"joint {robot.joint_names[j]} needs {hold[k, j] * self.limits.torque[j]:.2f} N m to hold "
                             f"the body still near waypoint {self.near(k, grid)}; its torque limit is "
                             f"{self.limits.torque[j]:.2f} N m")


def _stage_keys(s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(N-1,) keys of the stages of gridpoints s with x = s'^2 there (N,): the bytes of (s_i, s_i+1, x_i, x_i+1),
    equal exactly when the four numbers are (s and x are never -0.0 or NaN here), for np.isin."""
    rows = np.ascontiguousarray(np.column_stack([s[:-1], s[1:], x[:-1], x[1:]]), dtype=float)
    return rows.view(np.dtype((np.void, 4 * rows.itemsize))).ravel()


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
    #: the solve's rows at these points (:func:`_grid_rows`), by id of the limits: (robot, limits, _Rows); a merged
    #: grid carries them over, computing only the new points' rows
    rows: dict[int, tuple[SnakeRobot, RetimingLimits, "_Rows"]] = field(default_factory=dict, compare=False,
                                                                        repr=False)

    @classmethod
    def of(cls, robot: SnakeRobot, base: BasePlacement, f: PathFunction, s: np.ndarray, zmp_margin: float
           ) -> "GridPoints":
        q, dq, ddq = _path_values(f, s)
        frames = robot.frames_many(q, base)
        a, b = _path_dynamics(robot, q, dq, ddq, base, frames)
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
            merged.rows[key] = (robot, limits, rows.merged(_grid_rows(robot, other, limits), order))
        return merged


@dataclass(frozen=True)
class _Rows:
    """The solve's canonical rows at some gridpoints (:func:`_grid_rows`) and their layout: ``joint`` columns (the
    joints' accelerations and torques), then one per support-polygon edge (``edges``), then the friction's."""

    canonical: _topp.Canonical
    joint: int
    edges: int

    def padded(self, edges: int) -> "_Rows":
        """The rows of polygons padded to ``edges`` edges as :meth:`Support.joined` pads them (repeating the first
        edge): the first edge's columns repeated after the last edge's."""
        extra = edges - self.edges
        if extra == 0:
            return self
        end = self.joint + self.edges
        cols = np.r_[np.arange(end), np.full(extra, self.joint), np.arange(end, self.canonical.P.shape[1])]
        c = self.canonical
        return _Rows(_topp.Canonical(c.P[:, cols], c.Q[:, cols], c.R[:, cols], c.x_max), self.joint, edges)

    def merged(self, other: "_Rows", order: np.ndarray) -> "_Rows":
        """Both sets of rows, padded to one edge count, in ``order`` (as :meth:`GridPoints.merged`)."""
        edges = max(self.edges, other.edges)
        a, b = self.padded(edges).canonical, other.padded(edges).canonical
        return _Rows(_topp.Canonical(*(np.concatenate([getattr(a, name), getattr(b, name)])[order]
                                       for name in ("P", "Q", "R", "x_max"))), self.joint, edges)


def _path_limits(limits: RetimingLimits) -> _topp.PathLimits:
    """The limits TOPP-RA is given: SOLVE_SHARE of the joints' (see there). The path is parametrised by its length
    in joint space (rad): its speed s' is about the joints' speed, which their limits bound; where the path stands
    still they do not, and PATH_SPEED_FACTOR times their norm does."""
    path_speed = PATH_SPEED_FACTOR * np.linalg.norm(np.minimum(limits.velocity, MAX_JOINT_SPEED))
    return _topp.PathLimits(SOLVE_SHARE * limits.velocity, SOLVE_SHARE * limits.acceleration,
                            SOLVE_SHARE * limits.torque, float(path_speed) ** 2)


def _stability_limits(limits: RetimingLimits) -> RetimingLimits:
    """The limits the stability rows are given in the solve: SOLVE_SHARE of the friction."""
    return replace(limits, friction=SOLVE_SHARE * limits.friction)


def _solve_grid(robot: SnakeRobot, points: GridPoints, limits: RetimingLimits) -> _topp.Solution:
    """TOPP-RA over the gridpoints ``points.s`` under ``limits`` (the solve's shares of them; the stability rows
    with the ZMP margin plus SOLVE_ZMP_EXTRA_M), rest to rest."""
    return _topp.solve(points.s, _grid_rows(robot, points, limits).canonical)


def _grid_rows(robot: SnakeRobot, points: GridPoints, limits: RetimingLimits) -> _Rows:
    """The canonical rows of :func:`_solve_grid` at ``points``: computed once per gridpoint (kept in
    ``points.rows``; a refined grid's merge computes its new points' only: each row depends on its point alone)."""
    cached = points.rows.get(id(limits))
    if cached is not None and cached[0] is robot and cached[1] is limits:
        return cached[2]
    F, g = stability_rows(robot, points.support, _stability_limits(limits), SOLVE_ZMP_EXTRA_M)
    canonical = _topp.canonical(_path_limits(limits), points.dq, points.ddq, points.tau_a, points.tau_b,
                                points.tau_hold, np.einsum("nkj,nj->nk", F, points.w_a),
                                np.einsum("nkj,nj->nk", F, points.w_b), g)
    rows = _Rows(canonical, canonical.P.shape[1] - g.shape[1], points.support.offset.shape[1])
    points.rows[id(limits)] = (robot, limits, rows)
    return rows


def _check_length(end: float, dt: float) -> None:
    """MotionTooLong as soon as the motion timed so far (``end`` s) is longer than MAX_SAMPLES samples at ``dt`` take:
    before the rest of the path is solved or anything is sampled."""
    if end > (MAX_SAMPLES - 1) * dt:
        raise MotionTooLong(f"the timed motion lasts more than {end:.1f} s; at most {(MAX_SAMPLES - 1) * dt:g} s "
                         f"({MAX_SAMPLES} samples at {dt:g} s)")


def _refined(grid: np.ndarray, split: np.ndarray) -> np.ndarray:
    """The grid with each stage in ``split`` cut in four and its neighbours in two."""
    ds = np.diff(grid)
    near = split.copy()
    near[1:] |= split[:-1]
    near[:-1] |= split[1:]
    new = [grid[:-1][near] + 0.5 * ds[near]]
    new += [grid[:-1][split] + f * ds[split] for f in (0.25, 0.75)]
    return np.unique(np.concatenate([grid] + new))


def _stages_over(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, f: PathFunction, grid: np.ndarray,
                 sd: np.ndarray, support: Support, only: np.ndarray | None = None) -> np.ndarray:
    """(N-1,) bool: the stages of a solution that break a limit between their gridpoints (TOPP-RA keeps the limits
    at the gridpoints only). Probed at PROBES points inside each stage, with its constant path acceleration; the
    ZMP against the support polygon of the nearer gridpoint, or the probe's own where the stage's two gridpoints
    stand on different polygons (:func:`_probe_support`). ``only``: (N-1,) bool, the stages to probe (the others
    are reported within the limits)."""
    x = sd ** 2
    ds = np.diff(grid)
    u = (x[1:] - x[:-1]) / (2 * ds)
    frac = (np.arange(PROBES) + 0.5) / PROBES
    probed = np.arange(len(ds)) if only is None else np.flatnonzero(only)
    stage = np.repeat(probed, PROBES)
    fr = np.tile(frac, len(probed))
    s = grid[stage] + fr * ds[stage]
    xs = np.maximum(x[stage] + 2 * u[stage] * (s - grid[stage]), 0.0)
    q, dq, ddq = _path_values(f, s)
    qd, qdd = dq * np.sqrt(xs)[:, None], dq * u[stage][:, None] + ddq * xs[:, None]
    nearer = np.where(fr < 0.5, stage, stage + 1)
    dyn = newton_euler(robot, q, qd, qdd, base)  # in the core along q: no frames array, the CoM with it
    assert dyn.com is not None
    sub = _probe_support(robot, base, limits, support, q, stage, nearer, dyn.com)
    r = _ratios(robot, base, limits, sub, q, qd, qdd, dyn=dyn)
    over = np.zeros(len(s), bool)
    for key in ("velocity", "acceleration", "torque", "friction"):
        over |= r[key] > 1.0
    over |= r["zmp_slack"] < -REFINE_ZMP_M
    bad = np.zeros(len(ds), bool)
    bad[stage[over]] = True
    return bad


def _probe_support(robot: SnakeRobot, base: BasePlacement, limits: RetimingLimits, support: Support, q: np.ndarray,
                   stage: np.ndarray, nearer: np.ndarray, com: np.ndarray) -> Support:
    """The support the probes q (M, n) of stages ``stage`` (M,) are checked against: the nearer gridpoint's
    (``nearer`` (M,)), except in a stage whose two gridpoints stand on different polygons (a link touches down or
    lifts off between them), where each probe's own polygon is computed: the plan's check takes every 2 ms sample's
    own, and a link lifting between gridpoints narrows it there (a heavy ReU-like snake's lift passed the retiming
    with its ZMP 3.3 mm from an edge the gridpoints did not have)."""
    a, b = stage, stage + 1
    changed = (np.any(support.offset[a] != support.offset[b], axis=1)
               | np.any(support.normal[a] != support.normal[b], axis=(1, 2)))
    near = Support(support.normal[nearer], support.offset[nearer], com, support.static[nearer],
                   support.required[nearer])
    if not changed.any():
        return near
    own = Support.of(robot, q[changed], base, limits.zmp_margin)
    order = np.argsort(np.concatenate([np.flatnonzero(~changed), np.flatnonzero(changed)]), kind="stable")
    return near.take(np.flatnonzero(~changed)).joined(own).take(order)
