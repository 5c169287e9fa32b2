"""What the paper compares (Section 4), measured on MuJoCo's state: the robot's momenta about the world origin, its
contacts with the ground, and their centre of pressure (the zero-moment point); tick by tick, or recorded over a whole
run and computed at its end (:class:`TickLog`, the tracking loop's record: the same numbers to the bit).

Everything here is in the model's ground frame (``SimModel.ground``: the plan's; the world on flat ground, where
nothing is turned): MuJoCo's world quantities are turned into it where they are read (:func:`points_in_ground`,
:func:`vectors_in_ground`), so that "the world origin", "the ground plane z = 0" and "horizontal" below are the
ground frame's on a slope, as the planner's momenta and ZMP are.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..model.placement import GroundFrame
from ..model.robot import SnakeRobot
from .mjcf import SimModel, import_mujoco, in_ground

__all__ = ["momenta_of_state", "momenta_per_body", "ground_contacts", "center_of_pressure", "contacts_decodable",
           "points_in_ground", "vectors_in_ground", "TickLog"]


def points_in_ground(ground: GroundFrame, points: np.ndarray) -> np.ndarray:
    """World ``points`` (..., 3) in the ground frame; the same array on flat ground (the numbers bit for bit)."""
    return points if ground.is_world else ground.to_ground(points)


def vectors_in_ground(ground: GroundFrame, vectors: np.ndarray) -> np.ndarray:
    """World free vectors (..., 3) (forces, velocities, momenta) in the ground frame's axes; the same array on flat
    ground."""
    return vectors if ground.is_world else ground.direction_to_ground(vectors)


def _momenta_in_ground(ground: GroundFrame, mass: float, com: np.ndarray, linvel: np.ndarray, angmom: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """P = M v_c and L_O = L_c + c x P about the ground frame's origin, in its axes, from the world's centre of mass
    ``com``, its velocity ``linvel`` and the angular momentum about it ``angmom`` ((..., 3) each). A translation
    and a rotation of the frame: v_c and L_c only turn, c moves with the origin."""
    P = mass * vectors_in_ground(ground, linvel)
    return P, vectors_in_ground(ground, angmom) + _cross3(points_in_ground(ground, com), P)


def momenta_of_state(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Linear (kg m/s) and angular (kg m^2/s) momentum of the robot about the world origin, (3,) each (the ground
    frame's origin, in its axes, on a slope).

    From MuJoCo's subtree quantities of the root link (``mj_subtreeVel``): P = M v_c,
    L_O = L_c + c x P, with L_c the angular momentum about the subtree's centre of mass c.
    Needs positions and velocities computed (mj_forward or mj_step1).
    """
    mj = import_mujoco()
    mj.mj_subtreeVel(sim.model, data)
    b = sim.root_body
    if not sim.ground.is_world:
        return _momenta_in_ground(sim.ground, sim.model.body_subtreemass[b], data.subtree_com[b],
                                  data.subtree_linvel[b], data.subtree_angmom[b])
    P = sim.model.body_subtreemass[b] * data.subtree_linvel[b]
    c = data.subtree_com[b]
    L = data.subtree_angmom[b] + _cross3(c, P)
    return P.copy(), L.copy()


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of 3-vectors (..., 3), without np.cross's overhead on small arrays."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def momenta_per_body(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """The same momenta summed link by link (paper Eqs. 27-31) from ``mj_objectVelocity`` at each body's CoM.

    An independent path to :func:`momenta_of_state`, used to check it; in the ground frame on a slope (each link's
    momenta turned, its centre of mass moved into the frame).
    """
    mj = import_mujoco()
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
        if not sim.ground.is_world:  # the link's velocity and spin momentum turned, its CoM in the frame
            p = mass * vectors_in_ground(sim.ground, v)
            P += p
            L += np.cross(points_in_ground(sim.ground, data.xipos[b]), p) + vectors_in_ground(sim.ground, Iw @ w)
            continue
        p = mass * v
        P += p
        L += np.cross(data.xipos[b], p) + Iw @ w
    return P, L


def ground_contacts(sim: SimModel, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (k, 3) m and forces on the robot (k, 3) N of every robot-floor contact, in the model's ground
    frame (the world's on flat ground)."""
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
    return points_in_ground(sim.ground, contacts.pos[rows].copy()), vectors_in_ground(sim.ground, f)


def _contact_forces(sim: SimModel, data: Any, rows: np.ndarray) -> np.ndarray:
    """(k, 3) normal and two tangential forces of contacts ``rows`` in their contact frames, as mj_contactForce
    gives them. For the pyramidal friction cone of 3-D contacts (the models :func:`build_model` makes) they are
    decoded from the constraint forces at once: normal = the sum of the pyramid's 4 edge forces, tangent i =
    (edge 2i - edge 2i+1) mu_i; contacts without a constraint row (excluded) carry none. Else contact by contact."""
    mj = import_mujoco()
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
    """The ZMP / centre of pressure on the ground plane z = 0 of contact forces, (2,) m; NaN without load. (On a
    slope: give the points and forces in the ground frame, as :func:`ground_contacts` does, for the point on the
    slope.)

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


def contacts_decodable(model: Any) -> bool:
    """Whether every contact of ``model`` is a 3-D one with a pyramidal friction cone (what ``_contact_forces``
    decodes from the constraint forces alone): geoms of condim 3 only, no explicit pairs or flexes."""
    mj = import_mujoco()
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


class TickLog:
    """What the tracking loop records at each control tick: MuJoCo's arrays copied as they are (the state into
    arrays made for every tick, the contacts and their constraint forces of every physics step into growing arrays),
    and after the loop the :class:`~snakehead.sim.tracking.SimResult`'s quantities computed from them, all ticks at
    once. They are the numbers :func:`momenta_of_state`, :func:`ground_contacts` and :func:`center_of_pressure` give
    tick by tick, to the bit (tested), for much less of the loop's Python (measured: bench/RESULTS.md).

    A tick's ZMP is the centre of pressure of the ground's impulse over all of the tick's physics steps (every step's
    contacts together: the steps are equal), which is what carries the momenta from one tick to the next; one step
    alone aliases the contact solver's chatter (a corner barely touching drops out of the contact set for a step and
    the centre of pressure jumps to the edge of the contacts left: 5 mm for 1 ms). The recorded contacts are the
    tick's first step's."""

    def __init__(self, sim: SimModel, robot: SnakeRobot, N: int) -> None:
        """For a run of ``N`` ticks of ``sim``, ``robot``'s model."""
        m = sim.model
        self.sim, self.robot = sim, robot
        self.xpos, self.xmat = np.empty((N, m.nbody, 3)), np.empty((N, m.nbody, 9))
        self.qpos, self.qvel, self.tau = np.empty((N, m.nq)), np.empty((N, m.nv)), np.empty((N, m.nu))
        self.linvel, self.angmom, self.com = np.empty((N, 3)), np.empty((N, 3)), np.empty((N, 3))
        self.live = not contacts_decodable(m)  # else the ground contacts are measured step by step
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
        import_mujoco().mj_subtreeVel(self.sim.model, d)
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
        base_bodies = sim.body_ids[:robot.link_index(robot.parts.base_end) + 1]
        out["base_positions"] = points_in_ground(sim.ground, self.xpos[:, base_bodies])
        if sim.ground.is_world:
            out["P"] = sim.model.body_subtreemass[sim.root_body] * self.linvel
            out["L"] = self.angmom + _cross3(self.com, out["P"])
        else:
            out["P"], out["L"] = _momenta_in_ground(sim.ground, sim.model.body_subtreemass[sim.root_body], self.com,
                                                    self.linvel, self.angmom)
            out["com"] = points_in_ground(sim.ground, self.com)
        points, forces = self._ground_contacts()  # per step, in the ground frame
        tick = self.tick.array()
        first = np.flatnonzero(np.diff(tick, prepend=-1) != 0)  # each tick's first step
        out["contact_points"] = [points[i] for i in first]
        out["contact_forces"] = [forces[i] for i in first]
        end = first[1:].tolist() + [len(tick)]
        out["zmp"] = _centers_of_pressure([np.concatenate(points[a:b]) for a, b in zip(first, end)],
                                          [np.concatenate(forces[a:b]) for a, b in zip(first, end)])
        return out

    def _poses(self, body: int) -> np.ndarray:
        """(N, 4, 4) poses of ``body`` at every tick (ground frame)."""
        T = np.zeros((len(self.xpos), 4, 4))
        T[:, :3, :3] = self.xmat[:, body].reshape(-1, 3, 3)
        T[:, :3, 3] = self.xpos[:, body]
        T[:, 3, 3] = 1.0
        return in_ground(self.sim.ground, T)

    def _ground_contacts(self) -> tuple[list, list]:
        """Every physics step's :func:`ground_contacts`: the points and forces of the robot-floor contacts (ground
        frame)."""
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
        points, f = points_in_ground(self.sim.ground, points), vectors_in_ground(self.sim.ground, f)
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
