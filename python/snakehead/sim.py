"""Optional dynamics check in MuJoCo: the paper's "dynamics software" (Section 4).

The planned joint trajectory is tracked by a PD controller with gravity compensation on a free-floating
model of the robot lying on a ground plane with friction, so the body can really slide or tip. What the
paper compares (Figs. 18-20, 23-25) is recorded: the head frame, the linear and angular momentum about the
world origin, the zero-moment point (centre of pressure of the ground contact forces), and whether the base
moved.

MuJoCo is an optional extra (``pip install snakehead[sim]``); it is imported only when a function here needs
it, so ``import snakehead`` works without it.

Model (:func:`build_mjcf`), generated from the robot's own data, not from the URDF importer:

* one MuJoCo body per frame of ``robot.link_names`` (marker frames are massless bodies welded to their parent),
  nested in chain order, placed with the relative poses of ``robot.body.fk_all(0)``; a free joint on the root
  link (``link_0``), a hinge per revolute joint with the robot's axis and limits;
* each link's mass, centre of mass and full inertia tensor (``robot.masses/coms/inertias``), and its collision
  box (``robot.box_sizes/box_origins``);
* a ground plane at z = 0 (Coulomb friction ``friction``, default 0.8) and optional static obstacle boxes
  (:func:`wall_with_hole` builds the paper's wall of Section 4.2). Robot boxes collide with the ground and the
  obstacles; not with each other unless ``self_collision=True`` (parent/child pairs never);
* timestep 1 ms (physics) under the 2 ms control period of the paper; integrator ``implicitfast``;
  contact ``solref = (0.005 s, 1)`` (stiff: the resting body sinks ~1 um into the ground);
* servo-like joints: armature 1e-3 kg m^2 (reflected rotor inertia of a small geared servo) and viscous damping
  0.02 N m s/rad -- our choice, not the paper's.

Controller (:func:`simulate`): every ``control_dt`` (2 ms) the reference q_ref, qdot_ref and the gravity term are
updated (zero-order hold); the joint torque is

    tau = kp (q_ref - q) + kd (qdot_ref - qdot) + g_mj(q, qdot)     clipped to +-torque_limit

where g_mj is a gravity term on the joints. The PD part is a MuJoCo affine actuator, i.e. evaluated at every
physics step as in a servo's inner loop, with the velocity gain integrated implicitly (stable for the light
distal links). Gravity compensation (``gravity_compensation``):

* "supported" (default): each joint holds the weight of the run of lifted links hanging from it, up to the
  first link that rests on the ground in the plan (:func:`carried_weights`, :func:`gravity_torques`); links
  on the ground are carried by the ground;
* "bias": MuJoCo's ``qfrc_bias`` (gravity + Coriolis) on every joint, the textbook term for a fixed-base arm.
  For a snake lying on the ground it is wrong at the base joints: it is the torque that would hold the whole
  distal body as a cantilever from the tail, so the base pitch joints push against the ground;
* "none": PD only.

Default gains kp = 200 N m/rad, kd = 3 N m s/rad. The URDF's 3 N m effort cannot lift the head part from flat
(joint 10 needs ~3.9 N m); pass ``torque_limit`` to raise it (bench/RESULTS.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ._validate import finite_array, positive
from .head import angle_between_deg
from .robot import BasePlacement, SnakeRobot, as_base, as_robot

#: Standard gravity (m/s^2), the same as snakehead.stability.
GRAVITY = 9.80665

#: Physics timestep (s) and control period (s) used by default.
DEFAULT_TIMESTEP = 0.001
DEFAULT_CONTROL_DT = 0.002

#: Default PD gains (N m/rad, N m s/rad) for every joint.
DEFAULT_KP = 200.0
DEFAULT_KD = 3.0

_MISSING = ("MuJoCo is needed for snakehead.sim; it is an optional extra: "
            "pip install 'snakehead[sim]' (or pip install mujoco)")


def _mujoco():
    """Import MuJoCo lazily; ImportError naming the extra when it is missing."""
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - mujoco is installed where the tests run
        raise ImportError(_MISSING) from exc
    return mujoco


# ------------------------------------------------------------------------------------------------
# obstacles
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ObstacleBox:
    """A static box in the world: centre (3,) m, full extents ``size`` (3,) m, rotated by ``yaw`` rad about z."""

    center: tuple
    size: tuple
    yaw: float = 0.0

    def __post_init__(self):
        c = finite_array(self.center, "obstacle centre", (3,))
        s = finite_array(self.size, "obstacle size", (3,))
        if np.any(s <= 0):
            raise ValueError(f"obstacle size must be positive, got {s.tolist()}")
        finite_array(self.yaw, "obstacle yaw", ())
        object.__setattr__(self, "center", tuple(float(v) for v in c))
        object.__setattr__(self, "size", tuple(float(v) for v in s))
        object.__setattr__(self, "yaw", float(self.yaw))


def wall_with_hole(hole_center=(0.2, 0.5, 0.4), wall_size=(0.7, 0.58, 0.01), hole_diameter: float = 0.07,
                   yaw: float = 0.0, slices: int = 8) -> list[ObstacleBox]:
    """The wall of the paper's Section 4.2 as boxes: 0.7 m wide, 0.58 m high, 0.01 m thick, a 7 cm hole.

    The paper gives the wall's size and the hole's centre (0.2, 0.5, 0.4) m but not the wall's placement; we
    assume the wall stands on the ground (bottom at z = 0), centred horizontally on the hole, its normal along
    world +y rotated by ``yaw`` (rad) about the vertical through the hole's centre. The round hole is
    approximated by ``slices`` horizontal strips, each leaving the narrowest chord of the circle in its height
    open, so the opening is a staircase inscribed in the circle (conservative: never wider than the hole).

    Returns the boxes (list of :class:`ObstacleBox`).
    """
    c = finite_array(hole_center, "hole_center", (3,))
    W, H, D = finite_array(wall_size, "wall_size", (3,))
    r = 0.5 * positive(hole_diameter, "hole_diameter")
    if W <= 0 or H <= 0 or D <= 0:
        raise ValueError(f"wall_size must be positive, got {[W, H, D]}")
    if not (isinstance(slices, (int, np.integer)) and slices >= 1):
        raise ValueError(f"slices must be a positive integer, got {slices!r}")
    zc = float(c[2])
    if not (r < W / 2 and zc - r > 0 and zc + r < H):
        raise ValueError("the hole does not fit inside the wall (wall bottom on the ground, centred on the hole)")
    rects = [(-W / 2, -r, -zc, H - zc), (r, W / 2, -zc, H - zc),  # left, right: full height
             (-r, r, -zc, -r), (-r, r, r, H - zc)]  # below, above the hole
    h = 2 * r / slices
    for k in range(slices):
        v0, v1 = -r + k * h, -r + (k + 1) * h
        far = max(v0 * v0, v1 * v1)  # the chord is narrowest at the strip's edge farthest from the centre
        g = math.sqrt(max(r * r - far, 0.0))
        if g < r - 1e-12:
            rects += [(-r, -g, v0, v1), (g, r, v0, v1)]
    cy, sy = math.cos(yaw), math.sin(yaw)
    boxes = []
    for u0, u1, v0, v1 in rects:
        u, v = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
        centre = (c[0] + cy * u, c[1] + sy * u, zc + v)
        boxes.append(ObstacleBox(centre, (u1 - u0, D, v1 - v0), yaw))
    return boxes


# ------------------------------------------------------------------------------------------------
# model
# ------------------------------------------------------------------------------------------------
def _f(x: float) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return " ".join(_f(x) for x in np.asarray(v, float).ravel())


def _quat(R: np.ndarray) -> str:
    """MJCF text of the unit quaternion (w, x, y, z) of a rotation matrix."""
    return _vec(_quat_array(R))


def _quat_array(R: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (Shepperd's method), (4,)."""
    R = np.asarray(R, float)
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = (0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s)
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = [0.0] * 4
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (R[j, i] + R[i, j]) / s
        q[1 + k] = (R[k, i] + R[i, k]) / s
    return np.asarray(q, float)




def _torque_limits(robot: SnakeRobot, torque_limit) -> np.ndarray:
    n = robot.n_joints
    if torque_limit is None:
        lim = np.asarray(robot.body.model.effort, float)
    else:
        lim = np.broadcast_to(finite_array(torque_limit, "torque_limit"), (n,)).astype(float) \
            if np.ndim(torque_limit) == 0 else finite_array(torque_limit, "torque_limit", (n,))
    if np.any(lim <= 0):
        raise ValueError(f"torque limits must be positive (N m), got {np.asarray(lim).tolist()}")
    return np.array(lim, float)


def build_mjcf(robot: SnakeRobot, *, timestep: float = DEFAULT_TIMESTEP, friction: float = 0.8,
               joint_damping: float = 0.02, armature: float = 1e-3, torque_limit=None,
               obstacles: Sequence[ObstacleBox] = (), self_collision: bool = False,
               contact_solref: tuple = (0.005, 1.0)) -> str:
    """MJCF text of the robot (free-floating root) on a ground plane, with optional obstacle boxes.

    Names: bodies are ``robot.link_names``; hinges ``robot.body.joint_names``; the free joint ``root``;
    a site ``site_<frame>`` at every frame's origin (axes of the frame); actuators ``act_<joint>`` (affine:
    force = ctrl - kp q - kd qdot, gains set by :func:`simulate`); the floor geom ``floor``; obstacle geoms
    ``obstacle_<k>``. Units SI; ``timestep`` s, ``friction`` the sliding coefficient, ``joint_damping``
    N m s/rad, ``armature`` kg m^2, ``torque_limit`` N m (scalar or (n,); default the URDF effort).
    """
    robot = as_robot(robot)
    timestep = positive(timestep, "timestep")
    friction = positive(friction, "friction")
    if not (np.isfinite(joint_damping) and joint_damping >= 0):
        raise ValueError(f"joint_damping must be >= 0, got {joint_damping!r}")
    if not (np.isfinite(armature) and armature >= 0):
        raise ValueError(f"armature must be >= 0, got {armature!r}")
    solref = finite_array(contact_solref, "contact_solref", (2,))
    if solref[0] < 2 * timestep or solref[1] <= 0:
        raise ValueError(f"contact_solref time constant must be >= 2 timesteps ({2 * timestep} s), got {solref}")
    for ob in obstacles:
        if not isinstance(ob, ObstacleBox):
            raise TypeError(f"obstacles must be ObstacleBox, got {type(ob).__name__}")
    lim = _torque_limits(robot, torque_limit)
    n = robot.n_joints
    model = robot.body.model
    names = robot.link_names
    F0 = robot.body.fk_all(np.zeros(n))  # frames at q = 0 in the root frame
    child_of = {int(c): j for j, c in enumerate(model.joint_child_links)}
    axes = np.asarray(model.joint_axes, float)
    jnames = robot.body.joint_names
    lower, upper = robot.lower, robot.upper
    conaff = 1 if self_collision else 0

    lines = ['<mujoco model="snakehead">',
             '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
             f'  <option timestep="{_f(timestep)}" gravity="0 0 {_f(-GRAVITY)}" integrator="implicitfast"/>',
             '  <default>',
             f'    <geom solref="{_vec(solref)}" friction="{_f(friction)} 0.005 0.0001"/>',
             '  </default>',
             '  <worldbody>',
             '    <geom name="floor" type="plane" size="0 0 0.05" contype="0" conaffinity="1"/>']
    for k, ob in enumerate(obstacles):
        R = np.array([[math.cos(ob.yaw), -math.sin(ob.yaw), 0], [math.sin(ob.yaw), math.cos(ob.yaw), 0], [0, 0, 1]])
        lines.append(f'    <geom name="obstacle_{k}" type="box" pos="{_vec(ob.center)}" quat="{_quat(R)}" '
                     f'size="{_vec(0.5 * np.asarray(ob.size))}" contype="0" conaffinity="1"/>')
    depth = 0
    for i, name in enumerate(names):
        ind = "    " + "  " * depth
        if i == 0:
            lines.append(f'{ind}<body name="{name}">')
            lines.append(f'{ind}  <freejoint name="root"/>')
        else:
            rel = np.linalg.solve(F0[i - 1], F0[i])
            lines.append(f'{ind}<body name="{name}" pos="{_vec(rel[:3, 3])}" quat="{_quat(rel[:3, :3])}">')
            if i in child_of:
                j = child_of[i]
                if robot.body.joint_types[j] not in ("revolute", "continuous"):
                    raise ValueError(f"joint {jnames[j]} is {robot.body.joint_types[j]}; only revolute joints are simulated")
                rng = f' range="{_f(lower[j])} {_f(upper[j])}"' if np.isfinite(lower[j]) else ""
                lines.append(f'{ind}  <joint name="{jnames[j]}" type="hinge" axis="{_vec(axes[j])}"{rng} '
                             f'damping="{_f(joint_damping)}" armature="{_f(armature)}"/>')
        m = float(robot.masses[i])
        if m > 0:
            I = robot.inertias[i]
            lines.append(f'{ind}  <inertial pos="{_vec(robot.coms[i])}" mass="{_f(m)}" fullinertia="'
                         f'{_vec([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>')
        if np.all(robot.box_sizes[i] > 0):
            B = robot.box_origins[i]
            lines.append(f'{ind}  <geom name="box_{name}" type="box" size="{_vec(0.5 * robot.box_sizes[i])}" '
                         f'pos="{_vec(B[:3, 3])}" quat="{_quat(B[:3, :3])}" contype="1" conaffinity="{conaff}"/>')
        lines.append(f'{ind}  <site name="site_{name}"/>')
        depth += 1
    for d in range(depth - 1, -1, -1):
        lines.append("    " + "  " * d + "</body>")
    lines.append('  </worldbody>')
    lines.append('  <actuator>')
    for j in range(n):
        lines.append(f'    <general name="act_{jnames[j]}" joint="{jnames[j]}" gainprm="1" biastype="affine" '
                     f'biasprm="0 0 0" forcerange="{_f(-lim[j])} {_f(lim[j])}"/>')
    lines.append('  </actuator>')
    lines.append('</mujoco>')
    return "\n".join(lines)


@dataclass
class SimModel:
    """A compiled MuJoCo model of a robot and the indices that map it back to the robot.

    ``body_ids[i]`` is the MuJoCo body of ``robot.link_names[i]``; ``qpos_adr`` / ``dof_adr`` (n,) the joint
    addresses; ``root_body`` the free-floating link; ``robot_geoms`` the ids of the robot's boxes.
    """

    robot: SnakeRobot
    model: object
    body_ids: np.ndarray
    site_ids: np.ndarray
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    root_body: int
    floor_geom: int
    robot_geoms: np.ndarray
    torque_limit: np.ndarray

    def set_state(self, data, q, base: BasePlacement | None = None, lift: float = 0.0) -> None:
        """Put the root at ``base`` (raised by ``lift`` m) and the joints at ``q``; zero velocities; kinematics."""
        mj = _mujoco()
        T = as_base(base).matrix()
        data.qpos[:] = 0.0
        data.qvel[:] = 0.0
        data.qpos[0:3] = T[:3, 3] + (0.0, 0.0, lift)
        data.qpos[3:7] = _quat_array(T[:3, :3])
        data.qpos[self.qpos_adr] = q
        mj.mj_forward(self.model, data)

    def frames(self, data) -> np.ndarray:
        """World poses (n_links, 4, 4) of every frame of ``robot.link_names`` in ``data`` (after kinematics)."""
        out = np.zeros((len(self.body_ids), 4, 4))
        out[:, :3, :3] = data.xmat[self.body_ids].reshape(-1, 3, 3)
        out[:, :3, 3] = data.xpos[self.body_ids]
        out[:, 3, 3] = 1.0
        return out


def build_model(robot: SnakeRobot, **kwargs) -> SimModel:
    """Compile :func:`build_mjcf` (same keyword arguments) into a :class:`SimModel`."""
    mj = _mujoco()
    robot = as_robot(robot)
    xml = build_mjcf(robot, **kwargs)
    model = mj.MjModel.from_xml_string(xml)
    names = robot.link_names
    body_ids = np.array([mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, nm) for nm in names])
    site_ids = np.array([mj.mj_name2id(model, mj.mjtObj.mjOBJ_SITE, "site_" + nm) for nm in names])
    jids = [mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, nm) for nm in robot.body.joint_names]
    robot_geoms = np.array([g for g in range(model.ngeom) if model.geom_bodyid[g] != 0])
    return SimModel(robot=robot, model=model, body_ids=body_ids, site_ids=site_ids,
                    qpos_adr=np.array([model.jnt_qposadr[j] for j in jids]),
                    dof_adr=np.array([model.jnt_dofadr[j] for j in jids]),
                    root_body=int(body_ids[0]),
                    floor_geom=mj.mj_name2id(model, mj.mjtObj.mjOBJ_GEOM, "floor"),
                    robot_geoms=robot_geoms,
                    torque_limit=_torque_limits(robot, kwargs.get("torque_limit")))


# ------------------------------------------------------------------------------------------------
# measurements on a MuJoCo state
# ------------------------------------------------------------------------------------------------
def momenta_of_state(sim: SimModel, data) -> tuple[np.ndarray, np.ndarray]:
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
    L = data.subtree_angmom[b] + np.cross(c, P)
    return P.copy(), L.copy()


def momenta_per_body(sim: SimModel, data) -> tuple[np.ndarray, np.ndarray]:
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


def ground_contacts(sim: SimModel, data) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (k, 3) m and forces on the robot (k, 3) N, world frame, of every robot-floor contact."""
    mj = _mujoco()
    pts, frc = [], []
    f6 = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        g1, g2 = int(c.geom1), int(c.geom2)
        if sim.floor_geom not in (g1, g2):
            continue
        mj.mj_contactForce(sim.model, data, i, f6)
        frame = np.asarray(c.frame).reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
        f = frame.T @ f6[:3]  # force of geom1 on geom2, world
        if g1 != sim.floor_geom:
            f = -f
        pts.append(np.array(c.pos))
        frc.append(f)
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.array(pts), np.array(frc)


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
class SimResult:
    """What :func:`simulate` recorded, one row per control tick (``control_dt`` apart), after settling.

    t (N,) s, starting at the planned t[0]; q, qdot, q_ref (N, n) rad, rad/s; tau (N, n) N m applied joint
    torques; head_pose (N, 4, 4) world pose of ``head_tip``; P (N, 3) kg m/s and L (N, 3) kg m^2/s momenta about
    the world origin; com (N, 3) m; zmp (N, 2) m centre of pressure of the ground forces (NaN if airborne);
    contact_points / contact_forces: per tick (k, 3) arrays (m, N, world) of the robot-floor contacts;
    base_positions (N, nb, 3) world origins of the base-part frames; base_slide_m / base_lift_m the largest
    horizontal / upward displacement of any of them from the first tick (m).
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


def _gains(x, n: int, name: str, allow_zero: bool) -> np.ndarray:
    a = finite_array(x, name)
    if a.ndim == 0:
        a = np.full(n, float(a))
    elif a.shape != (n,):
        raise ValueError(f"{name} must be a number or shape ({n},), got shape {a.shape}")
    if np.any(a < 0) or (not allow_zero and np.any(a <= 0)):
        raise ValueError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {a.tolist()}")
    return a


def check_trajectory(robot: SnakeRobot, t, q) -> tuple[np.ndarray, np.ndarray]:
    """Validate a planned trajectory: t (T,) strictly increasing, q (T, n) finite within the joint limits."""
    n = robot.n_joints
    t = finite_array(t, "t")
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"t must be a 1-D array of at least 2 times, got shape {t.shape}")
    q = finite_array(q, "q")
    if q.ndim != 2 or q.shape[1] != n:
        raise ValueError(f"q must have shape (T, {n}), got {q.shape}")
    if q.shape[0] != t.size:
        raise ValueError(f"t and q have different lengths ({t.size} and {q.shape[0]})")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must be strictly increasing")
    tol = 1e-9
    bad = (q < robot.lower - tol) | (q > robot.upper + tol)
    if bad.any():
        k, j = np.argwhere(bad)[0]
        raise ValueError(f"q[{k}, {j}] = {q[k, j]:.6g} rad is outside the joint limits "
                         f"[{robot.lower[j]:.6g}, {robot.upper[j]:.6g}]")
    return t, q


#: Modes of gravity compensation in :func:`simulate`.
GRAVITY_COMPENSATION = ("supported", "bias", "none")

#: Ramp (m) of the support-aware compensation: a link whose lowest box corner is this high in the plan is
#: fully carried by the joints; on the ground (height 0) not at all; linear in between.
LIFT_RAMP = 0.005


def carried_weights(robot: SnakeRobot, frames: np.ndarray, ramp: float = LIFT_RAMP) -> np.ndarray:
    """How much of each joint's distal links' weight the joint carries: W (T, n, n_links) in [0, 1].

    frames (T, n_links, 4, 4): planned world poses. A link with a box is lifted by w = clip(h / ramp, 0, 1),
    h the height of the lowest corner of its box's distal face (+x end; massless marker frames: w = 1). The
    distal face, not the whole box: a link pitched up about its proximal joint still touches the ground with
    its proximal edge, right under the joint's axis, where the ground's reaction has no moment about the
    joint, so the joint carries the link from the first degrees of lift. Joint j carries link i (i at or after
    j's child link in chain order) by the product of w over the links from j's child to i: the weight of the
    lifted run of links that hangs from the joint, up to the first link resting on the ground, which the
    ground carries instead.
    """
    L = len(robot.link_names)
    boxed = np.all(robot.box_sizes > 0, axis=1)
    B = frames[:, boxed] @ robot.box_origins[boxed]
    half = 0.5 * robot.box_sizes[boxed]
    low = (B[..., 2, 3] + B[..., 2, 0] * half[:, 0]
           - np.abs(B[..., 2, 1]) * half[:, 1] - np.abs(B[..., 2, 2]) * half[:, 2])
    w = np.ones((frames.shape[0], L))
    w[:, boxed] = np.clip(low / ramp, 0.0, 1.0)
    child = np.asarray(robot.body.model.joint_child_links, int)
    W = np.zeros((frames.shape[0], robot.n_joints, L))
    for j, c in enumerate(child):
        W[:, j, c:] = np.cumprod(w[:, c:], axis=1)
    return W


def _compensated_mode(gravity_compensation) -> str:
    if gravity_compensation not in GRAVITY_COMPENSATION:
        raise ValueError(f"gravity_compensation must be one of {GRAVITY_COMPENSATION}, got {gravity_compensation!r}")
    return gravity_compensation


def gravity_torques(sim: SimModel, data, weights: np.ndarray) -> np.ndarray:
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
    mg = m.body_mass[sim.body_ids][:, None] * np.array([0.0, 0.0, -GRAVITY])  # (L, 3)
    r = c[None, :, :] - p[:, None, :]  # (n, L, 3)
    torque = np.cross(r, mg[None, :, :])  # (n, L, 3)
    return -np.einsum("nl,nlk,nk->n", weights, torque, a)


def simulate(robot: SnakeRobot, t, q, base: BasePlacement | None = None, kp=DEFAULT_KP, kd=DEFAULT_KD, *,
             control_dt: float = DEFAULT_CONTROL_DT, timestep: float = DEFAULT_TIMESTEP, settle: float = 0.3,
             hold: float = 0.0, gravity_compensation: str = "supported", torque_limit=None, friction: float = 0.8,
             joint_damping: float = 0.02, armature: float = 1e-3, obstacles: Sequence[ObstacleBox] = (),
             self_collision: bool = False, drop: float = 2e-4) -> SimResult:
    """Track the planned joint trajectory in MuJoCo with PD control plus gravity compensation.

    t (T,) s strictly increasing, q (T, n) rad: the plan (any sampling; the reference is interpolated linearly
    at every control tick, qdot_ref from ``np.gradient(q, t)``). ``base``: where the tail lies.
    kp (N m/rad, > 0) and kd (N m s/rad, >= 0): scalars or (n,). ``control_dt`` (s): the control period (2 ms,
    the paper's), a whole multiple of the physics ``timestep`` (1 ms). ``settle`` s: the robot is first put at
    q[0], ``drop`` m above its resting height, and held there with the same controller before t[0]; ``hold`` s:
    after t[-1] the last configuration is held and recorded. ``gravity_compensation``: "supported" (default: each joint
    carries the lifted run of links hanging from it, judged from the planned configuration, see
    :func:`carried_weights`), "bias" (MuJoCo's ``qfrc_bias`` on every joint: gravity and Coriolis as if the tail
    were clamped) or "none". ``torque_limit`` N m: scalar or (n,), default the URDF
    effort. Other keywords go to :func:`build_mjcf`.

    Returns a :class:`SimResult` sampled at every control tick from t[0] to t[-1] + hold.
    """
    mj = _mujoco()
    robot = as_robot(robot)
    base = as_base(base)
    t, q = check_trajectory(robot, t, q)
    n = robot.n_joints
    kp = _gains(kp, n, "kp", allow_zero=False)
    kd = _gains(kd, n, "kd", allow_zero=True)
    timestep = positive(timestep, "timestep")
    control_dt = positive(control_dt, "control_dt")
    sub = int(round(control_dt / timestep))
    if sub < 1 or abs(sub * timestep - control_dt) > 1e-9 * control_dt:
        raise ValueError(f"control_dt ({control_dt} s) must be a whole multiple of timestep ({timestep} s)")
    for name, val in (("settle", settle), ("hold", hold), ("drop", drop)):
        v = finite_array(val, name, ())
        if v < 0:
            raise ValueError(f"{name} must be >= 0, got {val!r}")
    mode = _compensated_mode(gravity_compensation)

    sim = build_model(robot, timestep=timestep, friction=friction, joint_damping=joint_damping,
                      armature=armature, torque_limit=torque_limit, obstacles=obstacles,
                      self_collision=self_collision)
    m = sim.model
    m.actuator_biasprm[:, 1] = -kp
    m.actuator_biasprm[:, 2] = -kd
    d = mj.MjData(m)
    sim.set_state(d, q[0], base, lift=float(drop))

    qdot_plan = np.gradient(q, t, axis=0)
    qa, da = sim.qpos_adr, sim.dof_adr

    def control(qr, qdr, W):
        if mode == "supported":
            tau_g = gravity_torques(sim, d, W)
        elif mode == "bias":
            tau_g = d.qfrc_bias[da]
        else:
            tau_g = 0.0
        d.ctrl[:] = kp * qr + kd * qdr + tau_g

    # settle at q[0]
    zero = np.zeros(n)
    W0 = carried_weights(robot, robot.frames_many(q[:1], base))[0]
    for _ in range(int(round(float(settle) / control_dt))):
        mj.mj_step1(m, d)
        control(q[0], zero, W0)
        mj.mj_step2(m, d)
        for _ in range(sub - 1):
            mj.mj_step(m, d)

    N = int(math.floor((t[-1] - t[0] + float(hold)) / control_dt + 1e-9)) + 1
    ts = t[0] + control_dt * np.arange(N)
    q_ref = np.column_stack([np.interp(ts, t, q[:, j]) for j in range(n)])
    qd_ref = np.column_stack([np.interp(ts, t, qdot_plan[:, j]) for j in range(n)])
    qd_ref[ts > t[-1]] = 0.0
    Wref = carried_weights(robot, robot.frames_many(q_ref, base)) if mode == "supported" else None

    head_k = robot.body.link_index(robot.parts.head_tip)
    base_last = int(robot.body.model.joint_child_links[robot.parts.base.stop - 1])
    base_frames = sim.body_ids[:base_last + 2]  # base links and the base_end marker (distal end of the last)
    rec = {k: np.zeros((N, 3)) for k in ("P", "L", "com")}
    qs, qds, taus = np.zeros((N, n)), np.zeros((N, n)), np.zeros((N, n))
    head = np.zeros((N, 4, 4))
    basepos = np.zeros((N, len(base_frames), 3))
    zmp = np.zeros((N, 2))
    cpts, cfrc = [], []
    hb = sim.body_ids[head_k]
    for k in range(N):
        mj.mj_step1(m, d)  # positions, velocities, collisions, bias forces at this tick
        qs[k] = d.qpos[qa]
        qds[k] = d.qvel[da]
        head[k, :3, :3] = d.xmat[hb].reshape(3, 3)
        head[k, :3, 3] = d.xpos[hb]
        head[k, 3, 3] = 1.0
        basepos[k] = d.xpos[base_frames]
        rec["P"][k], rec["L"][k] = momenta_of_state(sim, d)
        rec["com"][k] = d.subtree_com[sim.root_body]
        control(q_ref[k], qd_ref[k], None if Wref is None else Wref[k])
        mj.mj_step2(m, d)  # constraint (contact) forces of this tick's state, then integration
        taus[k] = d.actuator_force
        p, f = ground_contacts(sim, d)
        cpts.append(p)
        cfrc.append(f)
        zmp[k] = center_of_pressure(p, f)
        for _ in range(sub - 1):
            mj.mj_step(m, d)
        if not np.all(np.isfinite(d.qpos)):
            raise RuntimeError(f"the simulation diverged at t = {ts[k]:.3f} s; lower the gains or the timestep")

    settings = dict(kp=kp.tolist(), kd=kd.tolist(), control_dt=control_dt, timestep=timestep,
                    settle=float(settle), hold=float(hold), gravity_compensation=mode,
                    friction=float(friction), joint_damping=float(joint_damping), armature=float(armature),
                    n_obstacles=len(obstacles), self_collision=bool(self_collision))
    return SimResult(t=ts, q=qs, qdot=qds, q_ref=q_ref, tau=taus, head_pose=head, P=rec["P"], L=rec["L"],
                     com=rec["com"], zmp=zmp, contact_points=cpts, contact_forces=cfrc, base_positions=basepos,
                     base=base, torque_limit=sim.torque_limit, settings=settings)


# ------------------------------------------------------------------------------------------------
# comparison with the plan
# ------------------------------------------------------------------------------------------------
def _targets(robot, planned_t, planned_q, base, targets):
    """[(time, desired position (3,), desired unit direction (3,))]."""
    if targets is None:
        targets = [float(planned_t[-1])]
    out = []
    for k, tg in enumerate(targets):
        if isinstance(tg, (int, float, np.integer, np.floating)) or (isinstance(tg, np.ndarray) and tg.ndim == 0):
            time, pos, dirn = float(tg), None, None
        else:
            if not isinstance(tg, (tuple, list)) or len(tg) != 3:
                raise ValueError(f"targets[{k}] must be a time or (time, position, direction), got {tg!r}")
            time, pos, dirn = tg
            time = float(finite_array(time, f"targets[{k}] time", ()))
        if not np.isfinite(time):
            raise ValueError(f"targets[{k}] time is not finite")
        if pos is None or dirn is None:
            qk = np.array([np.interp(time, planned_t, planned_q[:, j]) for j in range(planned_q.shape[1])])
            H = robot.head_pose(qk, base)
            pos = H[:3, 3] if pos is None else pos
            dirn = H[:3, 0] if dirn is None else dirn
        pos = finite_array(pos, f"targets[{k}] position", (3,))
        dirn = finite_array(dirn, f"targets[{k}] direction", (3,))
        nd = np.linalg.norm(dirn)
        if nd < 1e-12:
            raise ValueError(f"targets[{k}] direction has zero length")
        out.append((time, pos, dirn / nd))
    return out


def compare(robot: SnakeRobot, planned_t, planned_q, result: SimResult, targets=None,
            base: BasePlacement | None = None) -> dict:
    """Compare a simulation with its plan, as the paper does in Section 4.

    ``targets``: a sequence whose items are a time (s; the desired head pose is then the planned one at that
    time) or (time, position (3,) m, direction (3,)) with either of position/direction None for the planned
    one; default: the end of the plan. The simulated head at each target time is interpolated between ticks.
    ``base`` defaults to the result's.

    Returns a dict of floats (SI units) and lists:

    * ``position_error_m`` / ``direction_error_deg``: the largest over the targets of |p_sim - p_des| and of the
      angle between the head's x-axis and the desired direction; per target in ``position_errors_m`` /
      ``direction_errors_deg``;
    * ``max_linear_momentum_error`` (kg m/s) / ``max_angular_momentum_error`` (kg m^2/s): max over the ticks of
      |P_sim - P_plan| and |L_sim - L_plan| (vector difference, about the world origin; planned from
      :func:`snakehead.stability.momenta`); ``..._magnitude_error``: max ||P_sim| - |P_plan|| (the paper's wording);
    * ``zmp_inside``: whether every simulated ZMP lay inside the support polygon of the planned configuration
      (:func:`snakehead.stability.support_polygon`, footprint contact model -- the physical contact area of the
      boxes); ``zmp_min_margin_m`` the smallest signed distance (positive inside);
    * ``base_slide_m``, ``base_lift_m``, ``max_torque_nm``, ``torque_saturation_fraction``.
    """
    from . import stability

    robot = as_robot(robot)
    if not isinstance(result, SimResult):
        raise TypeError(f"result must be a SimResult, got {type(result).__name__}")
    base = result.base if base is None else as_base(base)
    planned_t, planned_q = check_trajectory(robot, planned_t, planned_q)

    pos_err, dir_err = [], []
    for time, pos, dirn in _targets(robot, planned_t, planned_q, base, targets):
        if not (result.t[0] - 1e-9 <= time <= result.t[-1] + 1e-9):
            raise ValueError(f"target time {time} s is outside the simulated span [{result.t[0]}, {result.t[-1]}]")
        p = np.array([np.interp(time, result.t, result.head_position[:, i]) for i in range(3)])
        x = np.array([np.interp(time, result.t, result.head_direction[:, i]) for i in range(3)])
        x /= np.linalg.norm(x)
        pos_err.append(float(np.linalg.norm(p - pos)))
        dir_err.append(angle_between_deg(x, dirn))

    # planned momenta on the simulated ticks within the plan
    inside = result.t <= planned_t[-1] + 1e-9
    ts = result.t[inside]
    Pp, Lp = stability.momenta(robot, planned_t, planned_q, base)
    Pp = np.column_stack([np.interp(ts, planned_t, Pp[:, i]) for i in range(3)])
    Lp = np.column_stack([np.interp(ts, planned_t, Lp[:, i]) for i in range(3)])
    Ps, Ls = result.P[inside], result.L[inside]
    dP = np.linalg.norm(Ps - Pp, axis=1)
    dL = np.linalg.norm(Ls - Lp, axis=1)
    dPm = np.abs(np.linalg.norm(Ps, axis=1) - np.linalg.norm(Pp, axis=1))
    dLm = np.abs(np.linalg.norm(Ls, axis=1) - np.linalg.norm(Lp, axis=1))

    margins = zmp_margins(robot, result, planned_t, planned_q, base)
    ok = np.isfinite(margins)
    return {
        "position_error_m": float(max(pos_err)),
        "direction_error_deg": float(max(dir_err)),
        "position_errors_m": pos_err,
        "direction_errors_deg": dir_err,
        "max_linear_momentum_error": float(dP.max()),
        "max_angular_momentum_error": float(dL.max()),
        "max_linear_momentum_magnitude_error": float(dPm.max()),
        "max_angular_momentum_magnitude_error": float(dLm.max()),
        "zmp_inside": bool(ok.all() and np.all(margins > 0)),
        "zmp_min_margin_m": float(margins[ok].min()) if ok.any() else float("nan"),
        "base_slide_m": result.base_slide_m,
        "base_lift_m": result.base_lift_m,
        "max_torque_nm": float(np.abs(result.tau).max()),
        "torque_saturation_fraction": result.saturation_fraction,
    }


def zmp_margins(robot: SnakeRobot, result: SimResult, planned_t, planned_q, base: BasePlacement | None = None,
                contact: str = "footprint") -> np.ndarray:
    """Signed distance (m, positive inside) of each simulated ZMP to the planned support polygon at that tick.

    The polygon is :func:`snakehead.stability.support_polygon` of the planned configuration (interpolated to the
    tick; recomputed only when the base joints change). Ticks without ground load get NaN.
    """
    from . import stability

    base = result.base if base is None else as_base(base)
    n = robot.n_joints
    bs = robot.parts.base
    out = np.full(len(result.t), np.nan)
    loaded = np.flatnonzero(np.all(np.isfinite(result.zmp), axis=1))
    if loaded.size == 0:
        return out
    ts = result.t[loaded]
    qb_ticks = np.column_stack([np.interp(ts, planned_t, planned_q[:, j]) for j in range(n)])[:, bs]
    # one polygon per distinct base configuration; all of its ticks at once
    keys, group = np.unique(np.round(qb_ticks, 9), axis=0, return_inverse=True)
    group = np.asarray(group).reshape(-1)
    for g in range(len(keys)):
        ticks = np.flatnonzero(group == g)
        qb = np.zeros(n)
        qb[bs] = qb_ticks[ticks[0]]  # the polygon depends on the base joints only
        poly = stability.support_polygon(robot, qb, base, contact=contact)
        pts = np.broadcast_to(poly, (len(ticks),) + poly.shape)
        out[loaded[ticks]] = stability.polygon_margin_many(pts, np.ones(pts.shape[:2], bool),
                                                           result.zmp[loaded[ticks]])
    return out
