"""The robot's MuJoCo model, on which :func:`snakehead.sim.simulate_trajectory` tracks a plan and the closed loop
runs its gaits.

Model (:func:`build_spec`, a ``mujoco.MjSpec`` built element by element, never XML text; :func:`build_model` compiles
it), generated from the robot's own data, not from the URDF importer:

* one MuJoCo body per frame of ``robot.link_names`` (marker frames are massless bodies welded to their parent),
  nested in chain order, placed with the relative poses of ``robot.body.fk_all(0)``; a free joint on the root
  link (``link_0``), a hinge per revolute joint with the robot's axis and limits;
* each link's mass, centre of mass and full inertia tensor (``robot.masses/coms/inertias``), and its collision
  shapes (``robot.geometry``, any number per link: :func:`shape_geom`): a box, cylinder or sphere as MuJoCo's own
  primitive, a mesh as a mesh asset of its convex hull's vertices (MuJoCo collides a mesh as its convex hull);
* the root link placed where ``robot.root_pose(base)`` says (:meth:`SimModel.set_state`): the body frame at the
  placement, whatever axis the URDF's links run along;
* a ground plane at z = 0 (Coulomb friction ``friction``, default 0.8) and the scene's obstacles
  (:mod:`snakehead.geometry.obstacles`; a wall's round hole becomes a staircase of boxes inscribed in it,
  :func:`obstacle_boxes`; a mesh obstacle is a mesh of its convex hull). The robot's shapes collide with the ground and the
  obstacles; not with each other unless ``self_collision=True`` (parent/child pairs never);
* on a slope (``ground``, a :class:`~snakehead.model.placement.GroundFrame` other than the world's: a plan's
  ``base.ground``) the ground plane is the slope, tilted in the world (at the frame's origin, turned by its
  rotation), and the obstacles, the robot's placement and everything measured are given in the ground frame as the
  planner's are: MuJoCo simulates in the world (gravity (0, 0, -GRAVITY) always), and the model's own readers
  (:meth:`SimModel.frames`, :mod:`snakehead.sim.measurements`) turn what it measures back into the ground frame,
  the one boundary between the two. On flat ground (the world frame) nothing is turned: the numbers are the same
  to the bit;
* timestep 1 ms (physics) under the 2 ms control period of the paper; integrator ``implicitfast``;
  contact ``solref = (0.005 s, 1)`` (stiff: the resting body sinks ~1 um into the ground);
* servo-like joints: armature 1e-3 kg m^2 (reflected rotor inertia of a small geared servo) and viscous damping
  0.02 N m s/rad -- our choice, not the paper's.

MuJoCo is an optional extra (``pip install snakehead[sim]``); it is imported only when a function needs it
(:func:`import_mujoco`), so ``import snakehead`` works without it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from .._errors import InputError, InputTypeError, InternalError
from .._validate import duration, finite_array, integer, non_negative, positive
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..model.physics import GRAVITY, GROUND_FRICTION
from ..model.placement import WORLD_FRAME, GroundFrame
from ..model.robot import BasePlacement, SnakeRobot, as_base, as_robot
from ..terrain.surfaces import FlatGround
from ..trajectory.interpolation import CONTROL_PERIOD
from .gains import default_torque_limits
from .terrain_field import ROUGH_TERRAINS, add_terrain_floor

__all__ = ["DEFAULT_TIMESTEP", "DEFAULT_CONTROL_DT", "MAX_TIMESTEP", "MAX_CONTROL_DT", "MAX_PHYSICS_STEPS",
           "import_mujoco", "DEFAULT_HOLE_SLICES", "obstacle_boxes", "FREE_JOINT", "FLOOR", "shape_geom",
           "add_shape_geom", "SLOPE_NOSLIP_ITERATIONS", "build_spec", "SimModel", "build_model", "in_ground"]


#: Physics timestep (s) and control period (s) used by default; the simulated controller runs at the planner's rate.
DEFAULT_TIMESTEP = 0.001
DEFAULT_CONTROL_DT = CONTROL_PERIOD
#: Upper limits (s) on the physics timestep and the control period, and on the physics steps of one run (10^8: about
#: an hour of computing, 28 hours of motion at 1 ms): beyond them a run would never end or not be a simulation.
MAX_TIMESTEP = 0.1
MAX_CONTROL_DT = 1.0
MAX_PHYSICS_STEPS = 100_000_000

_MISSING = ("MuJoCo is needed for snakehead.sim; it is an optional extra: "
            "pip install 'snakehead[sim]' (or pip install mujoco)")


def import_mujoco() -> Any:
    """The ``mujoco`` module, imported on first use; ImportError naming the extra when it is missing."""
    try:
        import mujoco  # here, not at the top: MuJoCo is an optional extra
    except ImportError as exc:  # pragma: no cover - mujoco is installed where the tests run
        raise ImportError(_MISSING) from exc
    return mujoco


#: Horizontal strips of the staircase that stands for a wall's round hole in the simulation.
DEFAULT_HOLE_SLICES = 32


def obstacle_boxes(obstacles: Sequence[Any], hole_slices: int = DEFAULT_HOLE_SLICES) -> list[BoxObstacle]:
    """The scene's box-like obstacles as MuJoCo can collide them: boxes (a
    :class:`~snakehead.geometry.obstacles.MeshObstacle` is left out: :func:`build_spec` adds it as a mesh of its hull).

    A :class:`~snakehead.geometry.obstacles.WallWithHole` becomes the boxes of the wall around its hole, the round
    hole approximated by ``hole_slices`` strips across it, each leaving the narrowest chord of the circle in its
    height open: a staircase inscribed in the circle (never wider than the hole; 32 strips stay within 0.3 mm of
    the circle where a head's corners pass).
    """
    if not (isinstance(hole_slices, (int, np.integer)) and not isinstance(hole_slices, bool) and hole_slices >= 1):
        raise InputError(f"hole_slices must be a positive integer, got {hole_slices!r}")
    out: list[BoxObstacle] = []
    for ob in obstacles:
        if isinstance(ob, BoxObstacle):
            out.append(ob)
        elif isinstance(ob, WallWithHole):
            out += _wall_boxes(ob, int(hole_slices))
        elif not isinstance(ob, MeshObstacle):
            raise InputTypeError(f"obstacles must be BoxObstacle, WallWithHole or MeshObstacle, got {type(ob).__name__}")
    return out


def _wall_boxes(wall: WallWithHole, slices: int) -> list[BoxObstacle]:
    R = wall.rotation  # columns: width axis u, height axis v, normal
    r = wall.hole_diameter / 2
    w, h, thickness = wall.size
    u0, v0 = wall.hole_offset - np.array([w, h]) / 2  # the wall's corner, from the hole's centre
    u1, v1 = u0 + w, v0 + h
    rects = [(u0, -r, v0, v1), (r, u1, v0, v1), (-r, r, v0, -r), (-r, r, r, v1)]  # around the hole's square
    step = 2 * r / slices
    for k in range(slices):
        a, b = -r + k * step, -r + (k + 1) * step
        far = max(a * a, b * b)  # the chord is narrowest at the strip's edge farthest from the centre
        g = math.sqrt(max(r * r - far, 0.0))
        if g < r - 1e-12:
            rects += [(-r, -g, a, b), (g, r, a, b)]
    boxes = []
    for ua, ub, va, vb in rects:
        if ub - ua <= 1e-12 or vb - va <= 1e-12:
            continue
        centre = wall.centre + R @ np.array([(ua + ub) / 2, (va + vb) / 2, 0.0])
        boxes.append(BoxObstacle(centre, np.array([ub - ua, vb - va, thickness]), R))
    return boxes


# ------------------------------------------------------------------------------------------------
# model
# ------------------------------------------------------------------------------------------------
def _quat_array(R: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (Shepperd's method), (4,)."""
    R = np.asarray(R, float)
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
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


def _torque_limits(robot: SnakeRobot, torque_limit: float | npt.ArrayLike | None) -> np.ndarray:
    n = robot.n_joints
    if torque_limit is None:
        lim = default_torque_limits(robot)
    else:
        lim = np.broadcast_to(finite_array(torque_limit, "torque_limit"), (n,)).astype(float) \
            if np.ndim(torque_limit) == 0 else finite_array(torque_limit, "torque_limit", (n,))
    if np.any(lim <= 0):
        raise InputError(f"torque limits must be positive (N m), got {np.asarray(lim).tolist()}")
    return np.array(lim, float)


#: Names the model gives its own elements; a robot's frames and joints are checked against them.
FREE_JOINT = "root"
FLOOR = "floor"


def _check_names(robot: SnakeRobot) -> None:
    """Names go into the model as data (MjSpec attributes, never parsed), so any text is harmless; only clashes
    with the model's own names would make a different model, and MuJoCo needs non-empty names."""
    for kind, names in (("frame", robot.link_names), ("joint", robot.body.joint_names)):
        for name in names:
            if not isinstance(name, str) or not name:
                raise InputError(f"every {kind} of the robot needs a non-empty name, got {name!r}")
    _check_moving_masses(robot)
    if FREE_JOINT in robot.body.joint_names:
        raise InputError(f"a joint of the robot is named {FREE_JOINT!r}, the simulation's name for the free joint "
                         "of the root link; rename it in the URDF")


def _check_moving_masses(robot: SnakeRobot) -> None:
    """MuJoCo needs a mass and an inertia on every body that a joint moves (the root link's free joint included),
    or on a link welded to it (the links up to the next joint); without them the model fails to compile with
    MuJoCo's terse message (or, had urdfdom dropped a malformed ``<inertial>``, moves weightless). Say which link."""
    child = [0] + [int(c) for c in robot.body.model.joint_child_links]
    joints = [repr(FREE_JOINT) + " (the root link's free joint)"] + [repr(j) for j in robot.body.joint_names]
    ends = child[1:] + [len(robot.link_names)]
    for first, end, joint in zip(child, ends, joints):
        if not any(robot.masses[k] > 0 and np.linalg.eigvalsh(robot.inertias[k]).min() > _MUJOCO_MINVAL
                   for k in range(first, end)):
            raise InputError(f"link {robot.link_names[first]!r} is moved by joint {joint} but has no mass and "
                             "inertia in the URDF (nor a link fixed to it): the simulation needs them on every moving "
                             "link (give it an <inertial> with a positive definite inertia)")


def shape_geom(shape: Any) -> dict:
    """How a collision shape (:class:`snakehead.geometry.shapes.Shape`) becomes a MuJoCo geom: ``type`` (the
    ``mjtGeom`` name), ``size`` (MuJoCo's: a box's half extents; a cylinder's radius and half length, its axis the
    geom frame's z as in URDF; a sphere's radius; unused for a mesh), ``pos`` and ``quat`` (w, x, y, z) in the link
    frame. A mesh's vertices are the shape's own (its frame's coordinates)."""
    s = np.asarray(shape.size, float)
    size = {"box": 0.5 * s, "cylinder": np.array([s[0], 0.5 * s[1], 0.0]), "sphere": np.array([s[0], 0.0, 0.0]),
            "convex": np.zeros(3)}[shape.kind]
    kind = {"box": "mjGEOM_BOX", "cylinder": "mjGEOM_CYLINDER", "sphere": "mjGEOM_SPHERE",
            "convex": "mjGEOM_MESH"}[shape.kind]
    return {"type": kind, "size": size, "pos": np.asarray(shape.origin, float)[:3, 3].copy(),
            "quat": _quat_array(np.asarray(shape.origin, float)[:3, :3])}


def add_shape_geom(spec: Any, body: Any, robot: SnakeRobot, k: int, **options: Any) -> Any:
    """Add the ``k``-th shape of ``robot.geometry`` to the MjSpec ``body`` as geom ``shape_<k>`` (a convex mesh:
    with its asset ``hull_<k>``, the hull's vertices; MuJoCo takes their hull); ``options`` (contype, friction...)
    go to the geom. Returns the geom."""
    mj = import_mujoco()
    shape = robot.geometry.shapes[k]
    g = shape_geom(shape)
    extra = {}
    if shape.kind == "convex":
        if shape.vertices is None or len(shape.vertices) < 4:
            raise InputError(f"the mesh shape {k} ({shape.source}) has fewer than 4 hull vertices")
        mesh = spec.add_mesh(name=f"hull_{k}", uservert=np.asarray(shape.vertices, float).reshape(-1).tolist())
        mesh.inertia = mj.mjtMeshInertia.mjMESH_INERTIA_CONVEX
        extra["meshname"] = mesh.name
    return body.add_geom(name=f"shape_{k}", type=getattr(mj.mjtGeom, g["type"]), size=g["size"], pos=g["pos"],
                         quat=g["quat"], **extra, **options)


#: Iterations of MuJoCo's no-slip solver on a slope (:func:`build_spec`). MuJoCo's soft contacts let a body creep
#: under a steady tangential load that lies well inside the friction cone (the contact's regularisation turns force
#: into a small slip velocity): on a slope the weight's downhill part is such a load all the time, and a bent body
#: lying on a 5 deg slope with friction 0.8 crept 0.02 mm/s, 0.16 mm/s while the head was raised (3 mm over a
#: 20 s plan; the head, 0.5 m away, moved several mm). The no-slip solver (a projected Gauss-Seidel pass on the
#: friction forces after the main solver) removes that creep and leaves real sliding (beyond the cone) as it was;
#: measured: 0.0003 mm in 1 s at rest on 5 and 15 deg, and 0.89 m in 1 s on 25 deg with friction 0.3, the Coulomb
#: figure. On flat ground the tangential loads are the motion's brief ones and the model keeps MuJoCo's default (0).
SLOPE_NOSLIP_ITERATIONS = 10

#: MuJoCo's smallest mass or principal moment of a moving body (mjMINVAL).
_MUJOCO_MINVAL = 1e-15


def build_spec(robot: SnakeRobot, *, timestep: float = DEFAULT_TIMESTEP, friction: float = GROUND_FRICTION,
               joint_damping: float = 0.02, armature: float = 1e-3, torque_limit: float | npt.ArrayLike | None = None,
               obstacles: Sequence = (), hole_slices: int = DEFAULT_HOLE_SLICES, self_collision: bool = False,
               contact_solref: tuple = (0.005, 1.0), ground: GroundFrame = WORLD_FRAME,
               noslip_iterations: int | None = None, terrain: Any = None) -> Any:
    """The MuJoCo model of the robot (free-floating root) on a ground plane with the scene's obstacles, as a
    ``mujoco.MjSpec`` built element by element from the robot's own data (``spec.compile()`` gives the
    ``MjModel``; ``spec.to_xml()`` its MJCF text, for reading only).

    Names: bodies are ``robot.link_names``; hinges ``robot.body.joint_names``; the free joint ``root``;
    a site ``site_<frame>`` at every frame's origin (axes of the frame); a geom ``shape_<i>`` per collision shape
    (``i`` its index in ``robot.geometry.shapes``; a mesh's asset ``hull_<i>``);
    actuators ``act_<joint>`` (affine: force = ctrl - kp q - kd qdot, gains set by the caller); the floor geom
    ``floor``; obstacle geoms ``obstacle_<k>``. Names are data: characters that mean something in XML are kept
    as they are and cannot add elements. Units SI; ``timestep`` s, ``friction`` the sliding coefficient,
    ``joint_damping`` N m s/rad, ``armature`` kg m^2, ``torque_limit`` N m (scalar or (n,); default
    :func:`snakehead.sim.gains.default_torque_limits`: the URDF effort), ``contact_solref`` (time constant s, damping ratio) of every contact.
    ``ground``: the frame of the plane the robot lies on (default the world's: the floor at z = 0); on a slope the
    floor is that plane in the world and the ``obstacles``, given in the ground frame as a plan's are, are put
    through the frame's pose (``ground.matrix``). ``noslip_iterations``: MuJoCo's no-slip solver's iterations
    (``opt.noslip_iterations``), None for the default: 0 on flat ground, :data:`SLOPE_NOSLIP_ITERATIONS` on a slope.
    ``terrain``: a heightfield, mesh or staircase (``snakehead.terrain``) as the floor instead of the plane, an
    hfield geom named ``floor`` (:mod:`.terrain_field`; world frame only); None or flat ground: the plane.
    """
    mj = import_mujoco()
    robot = as_robot(robot)
    timestep = duration(timestep, "timestep", maximum=MAX_TIMESTEP)
    friction = positive(friction, "friction")
    joint_damping = non_negative(joint_damping, "joint_damping")
    armature = non_negative(armature, "armature")
    if not isinstance(self_collision, (bool, np.bool_)):
        raise InputTypeError(f"self_collision must be True or False, got {self_collision!r}")
    solref = finite_array(contact_solref, "contact_solref", (2,))
    if solref[0] < 2 * timestep or solref[1] <= 0:
        raise InputError(f"contact_solref time constant must be >= 2 timesteps ({2 * timestep} s), got {solref}")
    if not isinstance(ground, GroundFrame):
        raise InputTypeError(f"ground must be a GroundFrame, got {type(ground).__name__}")
    if noslip_iterations is None:
        noslip_iterations = 0 if ground.is_world else SLOPE_NOSLIP_ITERATIONS
    noslip = integer(noslip_iterations, "noslip_iterations", least=0, most=1000)
    if isinstance(terrain, FlatGround):
        terrain = None
    if terrain is not None and not (isinstance(terrain, ROUGH_TERRAINS) and ground.is_world):
        raise InputError("terrain must be a heightfield, mesh or steps terrain (a plane is given as the ground "
                         f"frame), on the world frame; got {type(terrain).__name__}")
    boxes = obstacle_boxes(obstacles, hole_slices)
    lim = _torque_limits(robot, torque_limit)
    _check_names(robot)
    surface = dict(solref=solref, friction=[friction, 0.005, 0.0001])  # sliding, torsional, rolling
    spec = _empty_spec(mj, timestep)
    if noslip:  # (MuJoCo's default, 0, is left unset: the flat-ground model as it always was)
        spec.option.noslip_iterations = noslip
    _add_ground_and_obstacles(mj, spec, boxes, [o for o in obstacles if isinstance(o, MeshObstacle)], surface,
                              ground, terrain)
    _add_bodies(mj, spec, robot, joint_damping, armature, self_collision, surface)
    for j, joint in enumerate(robot.body.joint_names):
        act = spec.add_actuator(name=f"act_{joint}", target=joint, trntype=mj.mjtTrn.mjTRN_JOINT)
        act.gainprm[0] = 1.0
        act.biastype = mj.mjtBias.mjBIAS_AFFINE
        act.forcerange = [-lim[j], lim[j]]
    return spec


def _empty_spec(mj: Any, timestep: float) -> Any:
    """An MjSpec with the compiler's and the simulation's options and nothing in its world."""
    spec = mj.MjSpec()
    spec.modelname = "snakehead"
    spec.compiler.degree = False
    spec.compiler.inertiafromgeom = mj.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    spec.compiler.autolimits = True
    spec.option.timestep = timestep
    spec.option.gravity = [0.0, 0.0, -GRAVITY]
    spec.option.integrator = mj.mjtIntegrator.mjINT_IMPLICITFAST
    return spec


def _add_ground_and_obstacles(mj: Any, spec: Any, boxes: Sequence, meshes: Sequence[MeshObstacle],
                              surface: dict, ground: GroundFrame = WORLD_FRAME, terrain: Any = None) -> None:
    """The floor (the ground frame's z = 0 plane, or ``terrain`` as an hfield), the obstacles' boxes
    (``obstacle_<k>``) and their meshes' hulls (after the boxes), the obstacles given in the ground frame."""
    world = spec.worldbody
    if terrain is not None:
        add_terrain_floor(mj, spec, terrain, FLOOR, surface)
    else:
        floor = {} if ground.is_world else {"pos": np.array(ground.origin), "quat": _quat_array(_rotation(ground))}
        world.add_geom(name=FLOOR, type=mj.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 0.05], contype=0, conaffinity=1,
                       **floor, **surface)
    for k, ob in enumerate(boxes):
        centre, rotation = _placed(ground, ob.centre, ob.rotation)
        world.add_geom(name=f"obstacle_{k}", type=mj.mjtGeom.mjGEOM_BOX, pos=centre,
                       quat=_quat_array(rotation), size=0.5 * np.asarray(ob.size, float), contype=0,
                       conaffinity=1, **surface)
    for k, rock in enumerate(meshes):
        mesh = spec.add_mesh(name=f"obstacle_hull_{k}", uservert=np.asarray(rock.vertices, dtype=float).reshape(-1).tolist())
        mesh.inertia = mj.mjtMeshInertia.mjMESH_INERTIA_CONVEX
        centre, rotation = _placed(ground, rock.pose[:3, 3], rock.pose[:3, :3])
        world.add_geom(name=f"obstacle_{len(boxes) + k}", type=mj.mjtGeom.mjGEOM_MESH, meshname=mesh.name,
                       pos=centre, quat=_quat_array(rotation), contype=0, conaffinity=1, **surface)


def _rotation(ground: GroundFrame) -> np.ndarray:
    """The ground frame's rotation (3, 3): its axes' world directions as columns."""
    return np.reshape(ground.rotation, (3, 3))


def _placed(ground: GroundFrame, position: npt.ArrayLike, rotation: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """A pose given in the ground frame (position (3,), rotation (3, 3)) in the world; as it is on flat ground."""
    if ground.is_world:
        return np.asarray(position), np.asarray(rotation)
    return ground.to_world(position), _rotation(ground) @ np.asarray(rotation, float)


def _add_bodies(mj: Any, spec: Any, robot: SnakeRobot, joint_damping: float, armature: float, self_collision: bool,
                surface: dict) -> None:
    """The robot's links as a chain of bodies from a free joint (at q = 0), each with its hinge, inertia, collision
    shapes (colliding with the world, and with each other when ``self_collision``) and a site at its origin."""
    n = robot.n_joints
    model = robot.body.model
    F0 = robot.body.fk_all(np.zeros(n))  # frames at q = 0 in the root frame
    child_of = {int(c): j for j, c in enumerate(model.joint_child_links)}
    axes = np.asarray(model.joint_axes, float)
    jnames = robot.body.joint_names
    lower, upper = robot.lower, robot.upper
    shapes_on: dict[int, list[int]] = {}
    for k, shape in enumerate(robot.geometry.shapes):
        shapes_on.setdefault(int(shape.frame), []).append(k)
    parent = spec.worldbody
    for i, name in enumerate(robot.link_names):
        if i == 0:
            body = parent.add_body(name=name)
            body.add_freejoint(name=FREE_JOINT)
        else:
            rel = np.linalg.solve(F0[i - 1], F0[i])
            body = parent.add_body(name=name, pos=rel[:3, 3], quat=_quat_array(rel[:3, :3]))
            if i in child_of:
                j = child_of[i]
                if robot.body.joint_types[j] not in ("revolute", "continuous"):
                    raise InputError(f"joint {jnames[j]!r} is {robot.body.joint_types[j]}; only revolute joints "
                                     "are simulated")
                hinge = body.add_joint(name=jnames[j], type=mj.mjtJoint.mjJNT_HINGE, axis=axes[j],
                                       damping=joint_damping, armature=armature)
                if np.isfinite(lower[j]):
                    hinge.range = [lower[j], upper[j]]
        m = float(robot.masses[i])
        if m > 0:
            I = robot.inertias[i]
            body.mass = m
            body.ipos = robot.coms[i]
            body.fullinertia = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
            body.explicitinertial = True
        for k in shapes_on.get(i, ()):
            add_shape_geom(spec, body, robot, k, contype=1, conaffinity=1 if self_collision else 0, **surface)
        body.add_site(name=f"site_{name}")
        parent = body


@dataclass
class SimModel:
    """A compiled MuJoCo model of a robot and the indices that map it back to the robot.

    ``body_ids[i]`` is the MuJoCo body of ``robot.link_names[i]``; ``qpos_adr`` / ``dof_adr`` (n,) the joint
    addresses; ``root_body`` the free-floating link; ``robot_geoms`` the ids of the robot's geoms;
    ``shape_geoms`` (S,) the geom of each shape of ``robot.geometry.shapes``; ``ground`` the frame of the plane
    the robot lies on (:func:`build_spec`): what :meth:`frames` (and :mod:`snakehead.sim.measurements`) read is in
    it, and :meth:`set_state` places the robot in it.
    """

    robot: SnakeRobot
    model: Any  # mujoco.MjModel
    body_ids: np.ndarray
    site_ids: np.ndarray
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    root_body: int
    floor_geom: int
    robot_geoms: np.ndarray
    torque_limit: np.ndarray
    shape_geoms: np.ndarray | None = None
    spec: object = None  #: the mujoco.MjSpec it was compiled from (``spec.to_xml()`` to read it)
    ground: GroundFrame = WORLD_FRAME

    def set_state(self, data: Any, q: np.ndarray, base: BasePlacement | None = None, lift: float = 0.0) -> None:
        """Put the body frame at ``base`` (the root link at ``robot.root_pose(base)``, raised by ``lift`` m off the
        ground) and the joints at ``q``; zero velocities; kinematics. On a slope the root link's world pose is
        ``ground.matrix @ robot.root_pose(base)``, raised along the slope's normal; ``base`` must lie on the model's
        ground (``base.ground == self.ground``; None: the default placement on it)."""
        mj = import_mujoco()
        data.qpos[:] = 0.0
        data.qvel[:] = 0.0  # at rest: a free joint's velocities are zero in any frame
        if self.ground.is_world:
            if base is not None and not as_base(base).ground.is_world:
                raise InputError(f"the base {base!r} lies on a slope but the model was built on flat ground; build "
                                 "it with ground=base.ground")
            T = self.robot.root_pose(base)
            data.qpos[0:3] = T[:3, 3] + (0.0, 0.0, lift)
        else:
            T = self._root_in_world(base, lift)
            data.qpos[0:3] = T[:3, 3]
        data.qpos[3:7] = _quat_array(T[:3, :3])
        data.qpos[self.qpos_adr] = q
        mj.mj_forward(self.model, data)

    def _root_in_world(self, base: BasePlacement | None, lift: float) -> np.ndarray:
        """The root link's world pose (4, 4) at ``base`` on the model's slope, raised ``lift`` m along its normal."""
        base = BasePlacement(ground=self.ground) if base is None else as_base(base)
        if base.ground != self.ground:
            raise InputError(f"the base {base!r} lies on another ground than the model's ({self.ground!r}); build the "
                             "model with ground=base.ground")
        T = self.robot.root_pose(base).copy()
        T[2, 3] += lift
        return self.ground.matrix @ T

    def frames(self, data: Any) -> np.ndarray:
        """Poses (n_links, 4, 4) of every frame of ``robot.link_names`` in ``data`` (after kinematics), in the model's
        ground frame (the world's on flat ground), as ``robot.frames(q, base)`` gives them."""
        out = np.zeros((len(self.body_ids), 4, 4))
        out[:, :3, :3] = data.xmat[self.body_ids].reshape(-1, 3, 3)
        out[:, :3, 3] = data.xpos[self.body_ids]
        out[:, 3, 3] = 1.0
        return in_ground(self.ground, out)


def in_ground(ground: GroundFrame, poses: np.ndarray) -> np.ndarray:
    """World poses (..., 4, 4) in the ground frame: ``inv(ground.matrix) @ poses``; the same array on flat ground."""
    if ground.is_world:
        return poses
    out = poses.copy()
    out[..., :3, :] = np.einsum("ji,...jk->...ik", _rotation(ground), poses[..., :3, :])
    out[..., :3, 3] -= np.asarray(ground.origin) @ _rotation(ground)
    return out


def build_model(robot: SnakeRobot, **kwargs: Any) -> SimModel:
    """Compile :func:`build_spec` (same keyword arguments) into a :class:`SimModel`."""
    mj = import_mujoco()
    robot = as_robot(robot)
    spec = build_spec(robot, **kwargs)
    try:
        model = spec.compile()
    except ValueError as exc:  # the robot was checked when it was loaded: a model MuJoCo refuses is ours
        raise InternalError(f"MuJoCo could not compile the model snakehead built of the robot: {exc}") from None
    names = robot.link_names

    def ids(kind: str, keys: Any) -> np.ndarray:
        return np.array([mj.mj_name2id(model, kind, k) for k in keys], int)

    body_ids = ids(mj.mjtObj.mjOBJ_BODY, names)
    site_ids = ids(mj.mjtObj.mjOBJ_SITE, ["site_" + nm for nm in names])
    jids = ids(mj.mjtObj.mjOBJ_JOINT, robot.body.joint_names)
    robot_geoms = np.array([g for g in range(model.ngeom) if model.geom_bodyid[g] != 0], int)
    shape_geoms = ids(mj.mjtObj.mjOBJ_GEOM, [f"shape_{k}" for k in range(len(robot.geometry.shapes))])
    return SimModel(robot=robot, model=model, body_ids=body_ids, site_ids=site_ids,
                    qpos_adr=model.jnt_qposadr[jids].copy(), dof_adr=model.jnt_dofadr[jids].copy(),
                    root_body=int(body_ids[0]),
                    floor_geom=mj.mj_name2id(model, mj.mjtObj.mjOBJ_GEOM, FLOOR),
                    robot_geoms=robot_geoms, shape_geoms=shape_geoms,
                    torque_limit=_torque_limits(robot, kwargs.get("torque_limit")), spec=spec,
                    ground=kwargs.get("ground", WORLD_FRAME))
