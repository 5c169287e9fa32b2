"""Track a planned joint trajectory in MuJoCo: PD control with gravity compensation at the 2 ms control period,
and what the paper compares (Section 4): the head frame, the momenta, the zero-moment point.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from .._validate import duration, finite_array, non_negative, sample_count
from ..dynamics.inverse_dynamics import LIFT_RAMP, carried_weights  # noqa: F401  (the one rule; re-exported)
from ..model.physics import GRAVITY, GROUND_FRICTION
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from .gains import default_gains
from .mjcf import (DEFAULT_CONTROL_DT, DEFAULT_HOLE_SLICES, DEFAULT_TIMESTEP, MAX_CONTROL_DT,
                   MAX_PHYSICS_STEPS, MAX_TIMESTEP, SimModel, _mujoco, build_model)

import numpy.typing as npt
from .._errors import InputError, InputTypeError


# ------------------------------------------------------------------------------------------------
# measurements on a MuJoCo state
# ------------------------------------------------------------------------------------------------
def momenta_of_state(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Linear (kg m/s) and angular (kg m^2/s) momentum of the robot about the world origin, (3,) each.

    From MuJoCo's subtree quantities of the root link (``mj_subtreeVel``): P = M v_c,
    L_O = L_c + c x P, with L_c the angular momentum about the subtree's centre of mass c.
    Needs positions and velocities computed (mj_forward or mj_step1).
    """
    mj = _mujoco()
    mj.mj_subtreeVel(sim.model, data)
    b = sim.root_body
    P = sim.model.body_subtreemass[b] * data.subtree_linvel[b]
    c = data.subtree_com[b]
    L = data.subtree_angmom[b] + _cross3(c, P)
    return P.copy(), L.copy()


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of 3-vectors (..., 3) (np.cross costs ~20 us a call)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def momenta_per_body(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """The same momenta summed link by link (paper Eqs. 27-31) from ``mj_objectVelocity`` at each body's CoM.

    An independent path to :func:`momenta_of_state`, used to check it.
    """
    mj = _mujoco()
    m = sim.model
    P, L = np.zeros(3), np.zeros(3)
    v6 = np.zeros(6)
    for b in range(1, m.nbody):
        mass = m.body_mass[b]
        if mass <= 0:
            continue
        mj.mj_objectVelocity(m, data, mj.mjtObj.mjOBJ_BODY, b, v6, 0)  # (omega, v) at xipos, world axes
        w, v = v6[:3], v6[3:]
        R = data.ximat[b].reshape(3, 3)
        Iw = R @ np.diag(m.body_inertia[b]) @ R.T
        p = mass * v
        P += p
        L += np.cross(data.xipos[b], p) + Iw @ w
    return P, L


def ground_contacts(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (k, 3) m and forces on the robot (k, 3) N, world frame, of every robot-floor contact."""
    if data.ncon == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    contacts = data.contact  # the contact list's fields as arrays (ncon, ...): one read, not one per contact
    g1, g2 = contacts.geom1, contacts.geom2
    rows = np.flatnonzero((g1 == sim.floor_geom) | (g2 == sim.floor_geom))
    if rows.size == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    frame = contacts.frame[rows].reshape(-1, 3, 3)  # rows: normal (geom1 -> geom2), tangents
    f = np.einsum("kij,ki->kj", frame, _contact_forces(sim, data, rows))  # force of geom1 on geom2, world
    f[g1[rows] != sim.floor_geom] *= -1.0  # on the robot
    return contacts.pos[rows].copy(), f


def _contact_forces(sim: SimModel, data: Any, rows: np.ndarray) -> np.ndarray:
    """(k, 3) normal and two tangential forces of contacts ``rows`` in their contact frames, as mj_contactForce
    gives them. For the pyramidal friction cone of 3-D contacts (the models :func:`build_model` makes) they are
    decoded from the constraint forces at once: normal = the sum of the pyramid's 4 edge forces, tangent i =
    (edge 2i - edge 2i+1) mu_i; contacts without a constraint row (excluded) carry none. Else contact by contact."""
    mj = _mujoco()
    contacts = data.contact
    if sim.model.opt.cone == mj.mjtCone.mjCONE_PYRAMIDAL and np.all(contacts.dim[rows] == 3):
        adr = contacts.efc_address[rows]
        edges = np.where(adr[:, None] >= 0, data.efc_force[np.maximum(adr, 0)[:, None] + np.arange(4)], 0.0)
        mu = contacts.friction[rows, :2]
        return np.column_stack([edges.sum(axis=1), (edges[:, 0] - edges[:, 1]) * mu[:, 0],
                                (edges[:, 2] - edges[:, 3]) * mu[:, 1]])
    local = np.empty((rows.size, 3))
    f6 = np.zeros(6)
    for k, i in enumerate(rows):
        mj.mj_contactForce(sim.model, data, int(i), f6)
        local[k] = f6[:3]
    return local


def center_of_pressure(points: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """The ZMP / centre of pressure on the ground plane z = 0 of contact forces, (2,) m; NaN without load.

    The point p on z = 0 about which the contact forces have no horizontal moment:
    p_x = sum(x_i f_zi - z_i f_xi) / sum f_zi,  p_y = sum(y_i f_zi - z_i f_yi) / sum f_zi.
    The z_i terms correct for contact points off the plane (MuJoCo puts them mid-penetration, ~1e-4 m) carrying
    friction; with z_i = 0 this is the plain p = sum f_z p_i / sum f_z.
    """
    points = np.asarray(points, float).reshape(-1, 3)
    forces = np.asarray(forces, float).reshape(-1, 3)
    fz = forces[:, 2].sum()
    if points.shape[0] == 0 or fz <= 1e-9:
        return np.array([np.nan, np.nan])
    px = (points[:, 0] * forces[:, 2] - points[:, 2] * forces[:, 0]).sum() / fz
    py = (points[:, 1] * forces[:, 2] - points[:, 2] * forces[:, 1]).sum() / fz
    return np.array([px, py])


# ------------------------------------------------------------------------------------------------
# simulation
# ------------------------------------------------------------------------------------------------
@dataclass
class SimState:
    """A snapshot of the simulated robot: MuJoCo's qpos and qvel, and the simulated time (s). Any model of the same
    robot takes it (obstacles and ground settings add no state): a gait run, a curl and a head plan continue from
    one another's states (:class:`snakehead.closed_loop.GaitSimulator`, :func:`simulate_trajectory` with ``state=``)."""

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
        _mujoco().mj_forward(sim.model, data)


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
    world pose at every tick; end_state: the simulated state after the last tick (continue from it).
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


def _gains(x: npt.ArrayLike, n: int, name: str, allow_zero: bool) -> np.ndarray:
    a = finite_array(x, name)
    if a.ndim == 0:
        a = np.full(n, float(a))
    elif a.shape != (n,):
        raise InputError(f"{name} must be a number or shape ({n},), got shape {a.shape}")
    if np.any(a < 0) or (not allow_zero and np.any(a <= 0)):
        raise InputError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {a.tolist()}")
    return a


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
    distal links this is the gravity part of MuJoCo's ``qfrc_bias`` on the joints (tested).
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


def _contacts_decodable(model: Any) -> bool:
    """Whether every contact of ``model`` is a 3-D one with a pyramidal friction cone (what :func:`_contact_forces`
    decodes from the constraint forces alone): geoms of condim 3 only, no explicit pairs or flexes."""
    mj = _mujoco()
    return bool(model.opt.cone == mj.mjtCone.mjCONE_PYRAMIDAL and np.all(model.geom_condim == 3)
                and model.npair == 0 and model.nflex == 0)


def _centers_of_pressure(points: list, forces: list) -> np.ndarray:
    """(N, 2) :func:`center_of_pressure` of each tick's contacts (views into one array each): the products for all
    ticks at once, each tick's sums as that function sums them (so the same numbers to the bit)."""
    zmp = np.full((len(points), 2), np.nan)
    if not points:
        return zmp
    p, f = np.concatenate(points), np.concatenate(forces)
    fz = f[:, 2]
    terms = np.stack([fz, p[:, 0] * fz - p[:, 2] * f[:, 0], p[:, 1] * fz - p[:, 2] * f[:, 1]])  # (3, K): rows
    end = np.cumsum([len(x) for x in points])  # summed along, pairwise as a 1-D sum is: the same bits
    for k, (a, b) in enumerate(zip((end - [len(x) for x in points]).tolist(), end.tolist())):
        total, mx, my = terms[:, a:b].sum(axis=1).tolist()
        if b > a and total > 1e-9:
            zmp[k] = mx / total, my / total
    return zmp


class _TickLog:
    """What the tracking loop records at each control tick: MuJoCo's arrays copied as they are (the state into
    arrays made for every tick, the contacts and their constraint forces of every physics step into growing arrays),
    and after the loop the :class:`SimResult`'s quantities computed from them, all ticks at once. They are the numbers
    :func:`momenta_of_state`, :func:`ground_contacts` and :func:`center_of_pressure` give tick by tick, to the bit
    (tested), for a fifth of the loop's Python, which cost more than MuJoCo's physics.

    A tick's ZMP is the centre of pressure of the ground's impulse over all of the tick's physics steps (every step's
    contacts together: the steps are equal), which is what carries the momenta from one tick to the next; one step
    alone aliases the contact solver's chatter (a corner barely touching drops out of the contact set for a step and
    the centre of pressure jumps to the edge of the contacts left: 5 mm for 1 ms). The recorded contacts are the
    tick's first step's."""

    def __init__(self, sim: SimModel, robot: SnakeRobot, N: int) -> None:
        m = sim.model
        self.sim, self.robot = sim, robot
        self.xpos, self.xmat = np.empty((N, m.nbody, 3)), np.empty((N, m.nbody, 9))
        self.qpos, self.qvel, self.tau = np.empty((N, m.nq)), np.empty((N, m.nv)), np.empty((N, m.nu))
        self.linvel, self.angmom, self.com = np.empty((N, 3)), np.empty((N, 3)), np.empty((N, 3))
        self.live = not _contacts_decodable(m)  # else the ground contacts are measured step by step
        self.contacts: list = []  # (live) each step's ground_contacts
        # every contact of every physics step, one row each, and every step's constraint forces, in growing arrays;
        # the tick of each step
        self.ncon, self.nefc, self.tick = _Rows((), int), _Rows((), int), _Rows((), int)
        self.geom, self.address = _Rows((2,), np.int32), _Rows((), np.int32)
        self.pos, self.frame, self.friction = _Rows((3,), float), _Rows((9,), float), _Rows((2,), float)
        self.efc = _Rows((), float)

    def state(self, k: int, d: Any) -> None:
        """Tick ``k``'s state, after ``mj_step1``."""
        self.xpos[k] = d.xpos
        self.xmat[k] = d.xmat
        self.qpos[k] = d.qpos
        self.qvel[k] = d.qvel
        _mujoco().mj_subtreeVel(self.sim.model, d)
        b = self.sim.root_body
        self.linvel[k] = d.subtree_linvel[b]
        self.angmom[k] = d.subtree_angmom[b]
        self.com[k] = d.subtree_com[b]

    def forces(self, k: int, d: Any) -> None:
        """Tick ``k``'s torques and its first physics step's contact forces, after ``mj_step2``."""
        self.tau[k] = d.actuator_force
        self.step(k, d)

    def step(self, k: int, d: Any) -> None:
        """The contact forces of a physics step of tick ``k``, after it (``mj_step2`` or ``mj_step``)."""
        self.tick.add(np.array([k]))
        if self.live:
            self.contacts.append(ground_contacts(self.sim, d))
            return
        c = d.contact
        self.ncon.add(np.array([d.ncon]))
        self.nefc.add(np.array([d.nefc]))
        self.geom.add(c.geom)
        self.pos.add(c.pos)
        self.frame.add(c.frame)
        self.address.add(c.efc_address)
        self.friction.add(c.friction[:, :2])
        self.efc.add(d.efc_force)

    def result(self) -> dict:
        """The SimResult's recorded fields (q, qdot, tau, head_pose, root_pose, base_positions, P, L, com, zmp,
        contact_points, contact_forces)."""
        sim, robot = self.sim, self.robot
        out: dict[str, Any] = {"q": self.qpos[:, sim.qpos_adr], "qdot": self.qvel[:, sim.dof_adr],
                               "tau": self.tau, "com": self.com}
        out["head_pose"] = self._poses(sim.body_ids[robot.body.link_index(robot.parts.head_tip)])
        out["root_pose"] = self._poses(sim.root_body)
        out["base_positions"] = self.xpos[:, sim.body_ids[:robot.link_index(robot.parts.base_end) + 1]]
        out["P"] = sim.model.body_subtreemass[sim.root_body] * self.linvel
        out["L"] = self.angmom + _cross3(self.com, out["P"])
        points, forces = self._ground_contacts()  # per step
        tick = self.tick.array()
        first = np.flatnonzero(np.diff(tick, prepend=-1) != 0)  # each tick's first step
        out["contact_points"] = [points[i] for i in first]
        out["contact_forces"] = [forces[i] for i in first]
        end = first[1:].tolist() + [len(tick)]
        out["zmp"] = _centers_of_pressure([np.concatenate(points[a:b]) for a, b in zip(first, end)],
                                          [np.concatenate(forces[a:b]) for a, b in zip(first, end)])
        return out

    def _poses(self, body: int) -> np.ndarray:
        """(N, 4, 4) world poses of ``body`` at every tick."""
        T = np.zeros((len(self.xpos), 4, 4))
        T[:, :3, :3] = self.xmat[:, body].reshape(-1, 3, 3)
        T[:, :3, 3] = self.xpos[:, body]
        T[:, 3, 3] = 1.0
        return T

    def _ground_contacts(self) -> tuple[list, list]:
        """Every physics step's :func:`ground_contacts`: the points and forces of the robot-floor contacts."""
        if self.live:
            return [p for p, _ in self.contacts], [f for _, f in self.contacts]
        counts = self.ncon.array()
        efc_start = np.concatenate([[0], np.cumsum(self.nefc.array())])  # each step's constraint forces in one array
        tick = np.repeat(np.arange(len(counts)), counts)
        geom = self.geom.array()
        floor = self.sim.floor_geom
        rows = np.flatnonzero((geom[:, 0] == floor) | (geom[:, 1] == floor))
        adr = self.address.array()[rows]
        efc = np.concatenate([self.efc.array(), np.zeros(4)])  # (padded: a row without constraints reads 0 below)
        edges = np.where(adr[:, None] >= 0,
                         efc[np.where(adr >= 0, efc_start[tick[rows]] + adr, 0)[:, None] + np.arange(4)], 0.0)
        mu = self.friction.array()[rows]
        local = np.column_stack([edges.sum(axis=1), (edges[:, 0] - edges[:, 1]) * mu[:, 0],
                                 (edges[:, 2] - edges[:, 3]) * mu[:, 1]])
        f = np.einsum("kij,ki->kj", self.frame.array()[rows].reshape(-1, 3, 3), local)
        f[geom[rows, 0] != floor] *= -1.0  # on the robot
        points = self.pos.array()[rows]
        end = np.cumsum(np.bincount(tick[rows], minlength=len(counts))).tolist()
        start = [0] + end[:-1]
        return [points[a:b] for a, b in zip(start, end)], [f[a:b] for a, b in zip(start, end)]


class _Rows:
    """Rows of one shape added a few at a time into one array that grows (doubling): no array per addition to
    join after."""

    def __init__(self, shape: tuple, dtype: Any, capacity: int = 4096) -> None:
        self.data = np.empty((capacity, *shape), dtype)
        self.n = 0

    def add(self, rows: np.ndarray) -> None:
        end = self.n + len(rows)
        if end > len(self.data):
            self.data = np.concatenate([self.data[:self.n], np.empty((max(end, 2 * len(self.data)) - self.n,
                                                                       *self.data.shape[1:]), self.data.dtype)])
        self.data[self.n:end] = rows
        self.n = end

    def array(self) -> np.ndarray:
        return self.data[:self.n]


def simulate_trajectory(robot: SnakeRobot, t: npt.ArrayLike, q: npt.ArrayLike, base: BasePlacement | None = None,
                        kp: npt.ArrayLike | None = None, kd: npt.ArrayLike | None = None, *,
                        control_dt: float = DEFAULT_CONTROL_DT, timestep: float = DEFAULT_TIMESTEP,
                        settle: float = 0.3, hold: float = 0.0, gravity_compensation: str = "supported",
                        torque_limit: npt.ArrayLike | None = None, friction: float = GROUND_FRICTION,
                        joint_damping: float = 0.02, armature: float = 1e-3, obstacles: Sequence = (),
                        hole_slices: int = DEFAULT_HOLE_SLICES, self_collision: bool = False,
                        drop: float = 2e-4, state: SimState | None = None) -> SimResult:
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
    effort (:func:`snakehead.sim.gains.default_torque_limits`). Other keywords go to :func:`snakehead.sim.build_spec`.

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
                      self_collision=self_collision)
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
        kp = _gains(kp, n, "kp", allow_zero=False)
        kd = _gains(kd, n, "kd", allow_zero=True)
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
    d = _mujoco().MjData(sim.model)
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
    mj, m = _mujoco(), sim.model
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
    (:class:`_TickLog`)."""
    mj, m = _mujoco(), sim.model
    Wref = carried_weights(robot, robot.frames_many(q_ref, base)) if o.mode == "supported" else None
    log = _TickLog(sim, robot, len(ts))
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
        for _ in range(o.sub - 1):  # the tick's other physics steps: their contacts count in its ZMP (_TickLog)
            mj.mj_step(m, d)
            log.step(k, d)
        if not math.isfinite(d.qpos.sum()):  # NaN or inf anywhere (a sum of finite angles does not overflow)
            raise RuntimeError(f"the simulation diverged at t = {ts[k]:.3f} s; lower the gains or the timestep")
    return log.result()
