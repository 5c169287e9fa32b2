"""Track a planned joint trajectory in MuJoCo (:func:`simulate_trajectory`): the paper's "dynamics software"
(Section 4). The plan is tracked by a PD controller with gravity compensation on a free-floating model of the robot
lying on a ground plane with friction (:mod:`snakehead.sim.mjcf`), so the body can really slide or tip; what the paper
compares (Figs. 18-20, 23-25) is recorded (:mod:`snakehead.sim.measurements`): the head frame, the linear and angular
momentum about the world origin, the zero-moment point (centre of pressure of the ground contact forces), and whether
the base moved.

Controller: every ``control_dt`` (2 ms) the reference q_ref, qdot_ref and the gravity term are updated (zero-order
hold); the joint torque is

    tau = kp (q_ref - q) + kd (qdot_ref - qdot) + g_mj(q, qdot)     clipped to +-torque_limit

where g_mj is a gravity term on the joints. The PD part is a MuJoCo affine actuator, i.e. evaluated at every
physics step as in a servo's inner loop, with the velocity gain integrated implicitly (stable for the light
distal links). Gravity compensation (``gravity_compensation``):

* "supported" (default): each joint holds the weight of the run of lifted links hanging from it, up to the
  first link that rests on the ground in the plan (:func:`~snakehead.dynamics.inverse_dynamics.carried_weights`,
  :func:`gravity_torques`); links on the ground are carried by the ground;
* "bias": MuJoCo's ``qfrc_bias`` (gravity + Coriolis) on every joint, the textbook term for a fixed-base arm.
  For a snake lying on the ground it is wrong at the base joints: it is the torque that would hold the whole
  distal body as a cantilever from the tail, so the base pitch joints push against the ground;
* "none": PD only.

Default gains and torque limits come from each joint's load (:mod:`snakehead.sim.gains`), so they suit any robot's
masses; the torque limit is the URDF's effort (a 3 N m servo cannot lift the default robot's head part from flat:
joint 10 needs ~3.9 N m).

On a slope (a ``base`` whose ground frame is not the world's, as a plan made there has) the ground plane is the
slope, tilted in the world (:func:`snakehead.sim.build_spec` with ``ground=base.ground``), and what is recorded is
in the ground frame, like the plan: the poses, momenta, centre of mass, contacts and ZMP (turned back from MuJoCo's
world at one boundary, :meth:`snakehead.sim.mjcf.SimModel.frames` and :mod:`snakehead.sim.measurements`). The
gravity compensation works on MuJoCo's world quantities, where gravity is (0, 0, -GRAVITY) on any slope.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError
from .._validate import duration, finite_array, non_negative, sample_count
from ..dynamics.inverse_dynamics import LIFT_RAMP, carried_weights  # noqa: F401  (the one rule; re-exported)
from ..model.physics import GRAVITY, GROUND_FRICTION
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .gains import default_gains, gain_vector
from .measurements import TickLog, center_of_pressure, ground_contacts, momenta_of_state, momenta_per_body
from .mjcf import (
    DEFAULT_CONTROL_DT,
    DEFAULT_HOLE_SLICES,
    DEFAULT_TIMESTEP,
    MAX_CONTROL_DT,
    MAX_PHYSICS_STEPS,
    MAX_TIMESTEP,
    SimModel,
    build_model,
    import_mujoco,
)

# the simulation's own names, then the measurements it records, importable from here as they always were
__all__ = ["SimState", "SimResult", "simulate_trajectory", "check_trajectory", "sample_count_covering",
           "GRAVITY_COMPENSATION", "gravity_torques", "carried_weights", "LIFT_RAMP", "GRAVITY",
           "momenta_of_state", "momenta_per_body", "ground_contacts", "center_of_pressure"]


@dataclass
class SimState:
    """A snapshot of the simulated robot: MuJoCo's qpos and qvel, and the simulated time (s). Any model of the same
    robot takes it (obstacles and ground settings add no state): a gait run, a curl and a head plan continue from
    one another's states (:class:`snakehead.closed_loop.GaitSimulator`, :func:`simulate_trajectory` with
    ``state=``)."""

    qpos: np.ndarray
    qvel: np.ndarray
    time: float = 0.0

    def copy(self) -> "SimState":
        return SimState(self.qpos.copy(), self.qvel.copy(), float(self.time))

    def load(self, sim: SimModel, data: Any) -> None:
        """Put ``data`` (of ``sim``'s model) in this state and compute its kinematics."""
        if self.qpos.shape != data.qpos.shape or self.qvel.shape != data.qvel.shape:
            raise InputError(f"the state (qpos {self.qpos.shape}) belongs to another robot's model (qpos "
                             f"{data.qpos.shape})")
        if not (np.all(np.isfinite(self.qpos)) and np.all(np.isfinite(self.qvel))):
            raise InputError("the state contains NaN or inf")
        data.qpos[:] = self.qpos
        data.qvel[:] = self.qvel
        import_mujoco().mj_forward(sim.model, data)


@dataclass
class SimResult:
    """What :func:`simulate_trajectory` recorded, one row per control tick (``control_dt`` apart), after settling.

    t (N,) s, starting at the planned t[0]; q, qdot, q_ref (N, n) rad, rad/s; tau (N, n) N m applied joint
    torques; head_pose (N, 4, 4) world pose of ``head_tip``; P (N, 3) kg m/s and L (N, 3) kg m^2/s momenta about
    the world origin; com (N, 3) m; zmp (N, 2) m centre of pressure of the ground's impulse over each tick's physics
    steps (NaN if airborne); contact_points / contact_forces: per tick (k, 3) arrays (m, N, world) of the
    robot-floor contacts at the tick's first physics step;
    base_positions (N, nb, 3) world origins of the base-part frames; base_slide_m / base_lift_m the largest
    horizontal / upward displacement of any of them from the first tick (m). root_pose (N, 4, 4): the root frame's
    world pose at every tick; end_state: the simulated state after the last tick (continue from it; MuJoCo's own
    state, in the world).

    "World" is the ground frame of ``base`` (``base.ground``): the world on flat ground; on a slope the frame whose
    z = 0 plane is the slope, so that "horizontal" and "upward" are along and across it, as in the plan.
    """

    t: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    q_ref: np.ndarray
    tau: np.ndarray
    head_pose: np.ndarray
    P: np.ndarray
    L: np.ndarray
    com: np.ndarray
    zmp: np.ndarray
    contact_points: list
    contact_forces: list
    base_positions: np.ndarray
    base: BasePlacement
    torque_limit: np.ndarray
    settings: dict = field(default_factory=dict)
    root_pose: np.ndarray | None = None
    end_state: SimState | None = None

    @property
    def head_position(self) -> np.ndarray:
        """(N, 3) m."""
        return self.head_pose[:, :3, 3]

    @property
    def head_direction(self) -> np.ndarray:
        """(N, 3) unit x-axis of head_tip."""
        return self.head_pose[:, :3, 0]

    @property
    def base_slide_m(self) -> float:
        d = self.base_positions[:, :, :2] - self.base_positions[:1, :, :2]
        return float(np.linalg.norm(d, axis=2).max())

    @property
    def base_lift_m(self) -> float:
        return float(max((self.base_positions[:, :, 2] - self.base_positions[:1, :, 2]).max(), 0.0))

    @property
    def saturation_fraction(self) -> float:
        """Fraction of (tick, joint) samples whose torque was at the limit."""
        return float(np.mean(np.abs(self.tau) >= self.torque_limit * (1 - 1e-9)))


def check_trajectory(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Validate a planned trajectory: t (T,) strictly increasing, q (T, n) finite within the joint limits."""
    n = robot.n_joints
    t = finite_array(t, "t")
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"t must be a 1-D array of at least 2 times, got shape {t.shape}")
    q = finite_array(q, "q")
    if q.ndim != 2 or q.shape[1] != n:
        raise InputError(f"q must have shape (T, {n}), got {q.shape}")
    if q.shape[0] != t.size:
        raise InputError(f"t and q have different lengths ({t.size} and {q.shape[0]})")
    if np.any(np.diff(t) <= 0):
        raise InputError("t must be strictly increasing")
    tol = 1e-9
    bad = (q < robot.lower - tol) | (q > robot.upper + tol)
    if bad.any():
        k, j = np.argwhere(bad)[0]
        raise InputError(f"q[{k}, {j}] = {q[k, j]:.6g} rad is outside the joint limits "
                         f"[{robot.lower[j]:.6g}, {robot.upper[j]:.6g}]")
    return t, q


def sample_count_covering(span: float, period: float) -> int:
    """How many ticks ``period`` apart, the first at 0, it takes for the last to be at or after ``span`` (>= 0):
    ceil(span / period) + 1, with ``span`` a whole number of periods up to rounding (1e-9 of a period) taking no
    extra tick."""
    return int(math.ceil(max(span, 0.0) / period - 1e-9)) + 1


#: Modes of gravity compensation in :func:`simulate_trajectory`.
GRAVITY_COMPENSATION = ("supported", "bias", "none")

def _compensated_mode(gravity_compensation: str) -> str:
    if gravity_compensation not in GRAVITY_COMPENSATION:
        raise InputError(f"gravity_compensation must be one of {GRAVITY_COMPENSATION}, got {gravity_compensation!r}")
    return gravity_compensation


def gravity_torques(sim: SimModel, data: Any, weights: np.ndarray) -> np.ndarray:
    """Joint torques (n,) N m holding the weighted link weights against gravity in the state ``data``.

    tau_j = -a_j . sum_i W_ji (c_i - p_j) x (m_i g): a_j, p_j the joint's world axis and anchor, c_i, m_i each
    link's centre of mass and mass, W (n, n_links) from :func:`carried_weights`. With every W = 1 on the
    distal links this is the gravity part of MuJoCo's ``qfrc_bias`` on the joints (tested). Read from MuJoCo's world
    quantities, where g = (0, 0, -GRAVITY) also when the ground is a slope.
    """
    m = sim.model
    jid = m.dof_jntid[sim.dof_adr]
    a = data.xaxis[jid]  # (n, 3)
    p = data.xanchor[jid]  # (n, 3)
    c = data.xipos[sim.body_ids]  # (L, 3)
    # with g = (0, 0, -G): a . (r x m g) = m G (a_y r_x - a_x r_y), r = c - p, so the sum over links needs only
    # the weighted masses' totals and first moments (one matrix product, no (n, L, 3) cross products)
    wm = weights * m.body_mass[sim.body_ids][None, :]  # (n, L)
    moment = wm @ c[:, :2] - wm.sum(axis=1)[:, None] * p[:, :2]  # (n, 2): sum_i W m (c_i - p_j), x and y
    return GRAVITY * (a[:, 0] * moment[:, 1] - a[:, 1] * moment[:, 0])


class _GravityTerm:
    """:func:`gravity_torques` in the tracking loop, with what does not change from tick to tick prepared once: the
    joints' and links' indices, and every tick's weighted masses and their totals (the same products and sums, so
    the same torques to the bit)."""

    def __init__(self, sim: SimModel, weights: np.ndarray) -> None:
        m = sim.model
        self.joints = _as_slice(m.dof_jntid[sim.dof_adr])
        self.bodies = _as_slice(sim.body_ids)
        self.wm = weights * m.body_mass[sim.body_ids][None, None, :]  # (N, n, L)
        self.total = self.wm.sum(axis=2)[:, :, None]  # (N, n, 1)

    def __call__(self, data: Any, k: int) -> np.ndarray:
        """The torques (n,) N m of tick ``k`` in the state ``data``."""
        a = data.xaxis[self.joints]
        p = data.xanchor[self.joints]
        moment = self.wm[k] @ data.xipos[self.bodies, :2] - self.total[k] * p[:, :2]
        return GRAVITY * (a[:, 0] * moment[:, 1] - a[:, 1] * moment[:, 0])


def _as_slice(index: np.ndarray) -> slice | np.ndarray:
    """``index`` as a slice when it is a run of consecutive integers (a view, no copy, when indexing), else as it is."""
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index




def simulate_trajectory(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike, base: BasePlacement | None = None,
                        kp: npt.ArrayLike | None = None, kd: npt.ArrayLike | None = None, *,
                        control_dt: float = DEFAULT_CONTROL_DT, timestep: float = DEFAULT_TIMESTEP,
                        settle: float = 0.3, hold: float = 0.0, gravity_compensation: str = "supported",
                        torque_limit: npt.ArrayLike | None = None, friction: float = GROUND_FRICTION,
                        joint_damping: float = 0.02, armature: float = 1e-3, obstacles: Sequence = (),
                        hole_slices: int = DEFAULT_HOLE_SLICES, self_collision: bool = False,
                        drop: float = 2e-4, state: SimState | None = None,
                        noslip_iterations: int | None = None, terrain: Any = None) -> SimResult:
    """Track the planned joint trajectory in MuJoCo with PD control plus gravity compensation.

    t (T,) s strictly increasing, q (T, n) rad: the plan (any sampling; the reference is interpolated linearly
    at every control tick, qdot_ref from ``np.gradient(q, t)``). ``base``: where the tail lies.
    kp (N m/rad, > 0) and kd (N m s/rad, >= 0): scalars or (n,); None (default): derived per joint from its load
    (:func:`snakehead.sim.gains.default_gains`). ``control_dt`` (s): the control period (2 ms,
    the paper's), a whole multiple of the physics ``timestep`` (1 ms). ``settle`` s: the robot is first put at
    q[0], ``drop`` m above its resting height, and held there with the same controller before t[0] (with ``state``,
    a :class:`SimState` of the same robot, e.g. where a gait or a curl left it: the simulation continues from that
    state instead, wherever the body lies; ``base`` is then where the plan believes the base is, used for nothing
    but the result's record, and the time goes on from ``state.time``); ``hold`` s:
    after t[-1] the last configuration is held and recorded. ``gravity_compensation``: "supported" (default: each joint
    carries the lifted run of links hanging from it, judged from the planned configuration, see
    :func:`carried_weights`), "bias" (MuJoCo's ``qfrc_bias`` on every joint: gravity and Coriolis as if the tail
    were clamped) or "none". ``torque_limit`` N m: scalar or (n,), default the URDF
    effort (:func:`snakehead.sim.gains.default_torque_limits`). Other keywords go to :func:`snakehead.sim.build_spec`
    (``terrain``: a heightfield, mesh or staircase as the floor; the body is put at its height above z = 0: give a
    ``drop`` above the terrain's highest point under it).

    Returns a :class:`SimResult` sampled at every control tick from t[0] through the first tick at or after
    t[-1] + hold (so that any time of the motion, its end included, lies within the recorded span).
    """
    robot = as_robot(robot)
    base = as_base(base)
    t, q = check_trajectory(robot, t, q)
    o = _TrackingOptions.checked(robot, t, kp, kd, control_dt, timestep, settle, hold, gravity_compensation, armature,
                                 drop)
    sim = build_model(robot, timestep=o.timestep, friction=friction, joint_damping=joint_damping,
                      armature=o.armature, torque_limit=torque_limit, obstacles=obstacles, hole_slices=hole_slices,
                      self_collision=self_collision, ground=base.ground, noslip_iterations=noslip_iterations,
                      terrain=terrain)
    sim.model.actuator_biasprm[:, 1] = -o.kp
    sim.model.actuator_biasprm[:, 2] = -o.kd
    d = _start_data(sim, q[0], base, o.drop, state)
    _settle(sim, d, robot, q[0], base, o)
    ts, q_ref, qd_ref = _reference(robot, t, q, o)
    rec = _track(sim, d, robot, base, ts, q_ref, qd_ref, o)

    settings = dict(kp=o.kp.tolist(), kd=o.kd.tolist(), control_dt=o.control_dt, timestep=o.timestep,
                    settle=o.settle, hold=o.hold, gravity_compensation=o.mode,
                    friction=float(friction), joint_damping=float(joint_damping), armature=o.armature,
                    n_obstacles=len(obstacles), self_collision=bool(self_collision), from_state=state is not None)
    if not base.on_flat_ground:
        settings.update(slope_deg=base.ground.slope_deg, noslip_iterations=int(sim.model.opt.noslip_iterations))
    if terrain is not None:
        settings.update(terrain=type(terrain).__name__)
    # the state's clock: the plan's without ``state``, else going on from the state's time
    t_end = (ts[-1] if state is None else float(state.time) + o.settle + ts[-1] - t[0]) + o.control_dt
    return SimResult(t=ts, q_ref=q_ref, **rec, base=base, torque_limit=sim.torque_limit, settings=settings,
                     end_state=SimState(d.qpos.copy(), d.qvel.copy(), t_end))


@dataclass(frozen=True)
class _TrackingOptions:
    """:func:`simulate_trajectory`'s numbers, checked: the gains (n,), the control period and physics step (s), the
    physics steps per control tick, the settling and holding times (s), the drop (m), the armature and the gravity
    compensation's mode."""

    kp: np.ndarray
    kd: np.ndarray
    control_dt: float
    timestep: float
    sub: int
    settle: float
    hold: float
    drop: float
    armature: float
    mode: str

    @staticmethod
    def checked(robot: SnakeRobot, t: np.ndarray, kp: Any, kd: Any, control_dt: Any, timestep: Any, settle: Any,
                hold: Any, gravity_compensation: Any, armature: Any, drop: Any) -> _TrackingOptions:
        """InputError naming the first bad argument; also when the run would record or step more than its bounds
        allow (checked before anything is allocated or stepped)."""
        n = robot.n_joints
        timestep = duration(timestep, "timestep", maximum=MAX_TIMESTEP)
        armature = non_negative(armature, "armature")
        if kp is None or kd is None:
            kp_load, kd_load = default_gains(robot, armature=armature)
            kp = kp_load if kp is None else kp
            kd = kd_load if kd is None else kd
        kp = gain_vector(kp, n, "kp", allow_zero=False)
        kd = gain_vector(kd, n, "kd", allow_zero=True)
        control_dt = duration(control_dt, "control_dt", maximum=MAX_CONTROL_DT)
        sub = int(round(control_dt / timestep))
        if sub < 1 or abs(sub * timestep - control_dt) > 1e-9 * control_dt:
            raise InputError(f"control_dt ({control_dt} s) must be a whole multiple of timestep ({timestep} s)")
        settle, hold = duration(settle, "settle", allow_zero=True), duration(hold, "hold", allow_zero=True)
        drop = non_negative(drop, "drop", maximum=1.0)
        sample_count(t[-1] - t[0] + hold, control_dt, "the simulated motion (t[-1] - t[0] + hold)")
        sample_count(settle + t[-1] - t[0] + hold, timestep, "the physics steps (settle + motion + hold)",
                     maximum=MAX_PHYSICS_STEPS)
        return _TrackingOptions(kp, kd, float(control_dt), float(timestep), sub, float(settle), float(hold),
                                float(drop), float(armature), _compensated_mode(gravity_compensation))


def _start_data(sim: SimModel, q0: np.ndarray, base: BasePlacement, drop: float, state: Any) -> Any:
    """MuJoCo's data at the start: the robot at q0, ``drop`` m above its resting height at ``base``, or ``state``."""
    d = import_mujoco().MjData(sim.model)
    if state is None:
        sim.set_state(d, q0, base, lift=drop)
    elif isinstance(state, SimState):
        state.load(sim, d)
    else:
        raise InputTypeError(f"state must be a SimState (from GaitSimulator or a SimResult's end_state), got "
                             f"{type(state).__name__}")
    return d


def _control(sim: SimModel, d: Any, o: _TrackingOptions, qr: np.ndarray, qdr: np.ndarray,
             W: np.ndarray | None) -> None:
    """The servo's command at one tick: PD on (qr, qdr) plus the gravity compensation of ``o.mode`` (W: the
    carried weights, for "supported")."""
    tau_g: np.ndarray | float
    if o.mode == "supported":
        assert W is not None  # the supported mode computes the weights
        tau_g = gravity_torques(sim, d, W)
    elif o.mode == "bias":
        tau_g = d.qfrc_bias[sim.dof_adr]
    else:
        tau_g = 0.0
    d.ctrl[:] = o.kp * qr + o.kd * qdr + tau_g


def _settle(sim: SimModel, d: Any, robot: SnakeRobot, q0: np.ndarray, base: BasePlacement,
            o: _TrackingOptions) -> None:
    """Hold q0 with the same controller for ``o.settle`` s (unrecorded)."""
    mj, m = import_mujoco(), sim.model
    zero = np.zeros(robot.n_joints)
    W0 = carried_weights(robot, robot.frames_many(q0[None], base))[0]
    for _ in range(int(round(o.settle / o.control_dt))):
        mj.mj_step1(m, d)
        _control(sim, d, o, q0, zero, W0)
        mj.mj_step2(m, d)
        for _ in range(o.sub - 1):
            mj.mj_step(m, d)


def _reference(robot: SnakeRobot, t: np.ndarray, q: np.ndarray, o: _TrackingOptions
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ticks ts (N,) and the reference q_ref, qd_ref (N, n) at them. Ticks are control_dt apart from t[0] through
    the first one at or after t[-1] + hold: the recorded span covers the whole motion (and hold) even when its length
    is not a whole number of periods (a plan's last sample is its exact end, at most one period after the previous
    one); past t[-1] the reference holds q[-1] at rest."""
    n = robot.n_joints
    qdot_plan = np.gradient(q, t, axis=0)
    N = sample_count_covering(t[-1] - t[0] + o.hold, o.control_dt)
    ts = t[0] + o.control_dt * np.arange(N)
    q_ref = np.column_stack([np.interp(ts, t, q[:, j]) for j in range(n)])
    qd_ref = np.column_stack([np.interp(ts, t, qdot_plan[:, j]) for j in range(n)])
    qd_ref[ts > t[-1]] = 0.0
    return ts, q_ref, qd_ref


def _track(sim: SimModel, d: Any, robot: SnakeRobot, base: BasePlacement, ts: np.ndarray, q_ref: np.ndarray,
           qd_ref: np.ndarray, o: _TrackingOptions) -> dict:
    """Run the servo along the reference, tick by tick, and return the recorded fields of the SimResult
    (:class:`~snakehead.sim.measurements.TickLog`)."""
    mj, m = import_mujoco(), sim.model
    Wref = carried_weights(robot, robot.frames_many(q_ref, base)) if o.mode == "supported" else None
    log = TickLog(sim, robot, len(ts))
    pd_ref = o.kp * q_ref + o.kd * qd_ref  # the servo's reference terms, as _control adds them, for every tick
    gravity = _GravityTerm(sim, Wref) if Wref is not None else None
    for k in range(len(ts)):
        mj.mj_step1(m, d)  # positions, velocities, collisions, bias forces at this tick
        log.state(k, d)
        if gravity is not None:
            d.ctrl[:] = pd_ref[k] + gravity(d, k)
        else:
            _control(sim, d, o, q_ref[k], qd_ref[k], None)
        mj.mj_step2(m, d)  # constraint (contact) forces of this tick's state, then integration
        log.forces(k, d)
        for _ in range(o.sub - 1):  # the tick's other physics steps: their contacts count in its ZMP (TickLog)
            mj.mj_step(m, d)
            log.step(k, d)
        if not math.isfinite(d.qpos.sum()):  # NaN or inf anywhere (a sum of finite angles does not overflow)
            raise RuntimeError(f"the simulation diverged at t = {ts[k]:.3f} s; lower the gains or the timestep")
    return log.result()
