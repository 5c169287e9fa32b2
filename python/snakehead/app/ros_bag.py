"""ROS 2 bags of snakehead's motions, written without ROS, and the motion as a JointTrajectory for controllers.

``snakehead plan`` and ``snakehead demo`` write, per scenario, beside ``NAME.html`` (docs: "Replay a plan in Foxglove
or RViz"):

* ``NAME.mcap`` (:func:`write_plan_bag`): a ROS 2 bag, one MCAP file in the ``ros2`` profile (``ros2msg`` schemas,
  CDR messages) that ``ros2 bag play``, RViz and Foxglove read:

  - :data:`JOINT_STATES` (``sensor_msgs/msg/JointState``): every sample of the plan (the control period, 2 ms): the
    robot's joints in the CSV's order (then any other movable joint of the description, a passive wheel at the
    value the planner held it at, else 0), positions (rad) as the description writes them
    (:meth:`SnakeRobot.description_angles`: the planner's plus the robot file's ``[home]``), velocities (rad/s);
  - :data:`TF` (``tf2_msgs/msg/TFMessage``) every :data:`TF_PERIOD`: ``world`` -> the description's root link
    (:attr:`SnakeRobot.description_root`), placed where the plan puts the body (with the joints when the
    description's tree starts from the head), and ``world`` -> ``target/NAME`` (:func:`frame_name`; x-axis along
    the target's direction); the links themselves are robot_state_publisher's, from the URDF and the joint states;
  - :data:`ROBOT_DESCRIPTION` (``std_msgs/msg/String``), once at 0: the description's own URDF as the user wrote it
    (a xacro expanded; :attr:`SnakeRobot.description_text`), not the tree snakehead rewrites for its core;
  - :data:`MARKERS` (``visualization_msgs/msg/MarkerArray``, frame ``world``): the targets and the obstacles every
    :data:`STATIC_MARKER_PERIOD` (stamped 0), the support polygon and the ZMP on the ground every
    :data:`MARKER_PERIOD`.

  A plan on a slope holds its body, targets and obstacles in its ground frame (``plan.base.ground``: z the plane's
  normal). Its bag puts that frame on :data:`TF` as ``world`` -> :data:`GROUND_FRAME` (the same transform at every
  stamp: ``ros2 bag play`` publishes a recorded ``/tf_static`` without its latching QoS, which tf2's listeners
  would not take), and places the root and the targets under it (``ground`` -> root, ``ground`` ->
  ``target/NAME``); every marker is in ``ground`` (its header's frame), and the static ones add the tilted ground
  plane (namespace "ground_plane", :func:`ground_plane_marker`). On flat ground there is no ``ground`` frame: the
  bag is the one written before slopes.

  Time stamps, in the messages' headers and as the bag's log times, are nanoseconds from the start of the motion
  (its first sample at 0). Every channel offers no recorded QoS (``ros2 bag play`` publishes with its defaults).
* ``NAME.mcap`` of a closed loop (:func:`write_loop_bag`, ``snakehead plan --start``): the whole sequence as MuJoCo
  ran it, on the simulation's clock: :data:`JOINT_STATES` the simulated joints, the URDF's root placed where the body
  truly lay, the body frame's pose (what ``BasePlacement`` places) as :data:`TRUE_BASE_FRAME` and as the loop
  believed it as :data:`ESTIMATED_BASE_FRAME` on :data:`TF`, the head phases' plan on
  :data:`PLANNED_JOINT_STATES`, and during the head phases the planned support polygon and ZMP beside the simulated
  ZMP.
* ``NAME_joint_trajectory.yaml`` (:func:`write_joint_trajectory`): ``trajectory_msgs/msg/JointTrajectory`` as YAML
  message fields, a point per sample of the plan.

Every joint angle written is the description's (its names, its signs, its zero); the plans' arrays
(``Plan.q``) hold the planner's, which are the description's minus the robot file's ``[home]``.
"""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np
import numpy.typing as npt
from mcap.writer import CompressionType, Writer
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from .. import __version__
from .._errors import invariant
from .._files import atomic_open, write_text_atomic
from ..dynamics import stability
from ..planning.waypoints import PLAN_CONTACT
from ..solve.head import frame_along
from ..trajectory.interpolation import CONTROL_PERIOD
from . import ros_messages as msgs

if TYPE_CHECKING:
    from ..closed_loop.loop import LoopRun
    from ..model.robot import SnakeRobot
    from ..planning.plan_result import Plan

__all__ = ["WORLD_FRAME", "GROUND_FRAME", "GROUND_PLANE_COLOR", "GROUND_PLANE_THICKNESS", "GROUND_PLANE_MARGIN",
           "ground_frame_of", "ground_plane_marker", "TARGET_FRAME_PREFIX", "TRUE_BASE_FRAME", "ESTIMATED_BASE_FRAME", "JOINT_STATES",
           "PLANNED_JOINT_STATES", "TF", "ROBOT_DESCRIPTION", "MARKERS", "TOPIC_TYPES", "TF_PERIOD", "MARKER_PERIOD",
           "STATIC_MARKER_PERIOD", "TARGET_COLOR", "OBSTACLE_COLOR", "POLYGON_COLOR", "ZMP_COLOR",
           "SIMULATED_ZMP_COLOR", "ARROW_LENGTH", "TARGET_DOT", "ZMP_DOT", "LINE_WIDTH", "TEXT_HEIGHT",
           "GROUND_MARK_Z", "samples_every", "joint_names", "held_values", "frame_name", "target_frames", "IDENTITY",
           "target_markers", "obstacle_markers", "ground_markers", "write_plan_bag", "write_loop_bag", "yaml_float",
           "yaml_floats", "write_joint_trajectory"]

#: The fixed frame everything is placed in (world coordinates: z up, the ground at z = 0).
WORLD_FRAME = "world"
#: A plan's ground frame on a slope (z = 0 the plane, z its upward normal), a child of :data:`WORLD_FRAME`.
GROUND_FRAME = "ground"
#: The ground plane's marker on a slope: colour (r, g, b, a), thickness (m, below the plane) and margin (m) around
#: the body's and the targets' ground-frame x, y.
GROUND_PLANE_COLOR = (0.55, 0.45, 0.4, 0.35)
GROUND_PLANE_THICKNESS = 0.002
GROUND_PLANE_MARGIN = 0.3
#: The targets' frames are named this prefix and their names (:func:`frame_name`).
TARGET_FRAME_PREFIX = "target/"
#: The closed loop's body frame, as MuJoCo had it and as the loop estimated it.
TRUE_BASE_FRAME = "base_true"
ESTIMATED_BASE_FRAME = "base_estimate"

JOINT_STATES = "/joint_states"
PLANNED_JOINT_STATES = "/snakehead/planned_joint_states"
TF = "/tf"
ROBOT_DESCRIPTION = "/robot_description"
MARKERS = "/snakehead/markers"
#: The message type of every topic.
TOPIC_TYPES = {JOINT_STATES: "sensor_msgs/msg/JointState", PLANNED_JOINT_STATES: "sensor_msgs/msg/JointState",
               TF: "tf2_msgs/msg/TFMessage", ROBOT_DESCRIPTION: "std_msgs/msg/String",
               MARKERS: "visualization_msgs/msg/MarkerArray"}

#: s: how often /tf is published (20 Hz, robot_state_publisher's default rate); tf2 interpolates between.
TF_PERIOD = 0.05
#: s: how often the support polygon and the ZMP are published (10 Hz).
MARKER_PERIOD = 0.1
#: s: how often the targets and obstacles are published again (for a viewer that starts late or seeks).
STATIC_MARKER_PERIOD = 1.0

#: Marker colours (r, g, b, a) and sizes (m).
TARGET_COLOR = (0.85, 0.15, 0.1, 1.0)
OBSTACLE_COLOR = (0.55, 0.55, 0.6, 0.6)
POLYGON_COLOR = (0.1, 0.6, 0.2, 1.0)
ZMP_COLOR = (0.1, 0.3, 0.9, 1.0)
SIMULATED_ZMP_COLOR = (0.9, 0.5, 0.0, 1.0)
ARROW_LENGTH = 0.08
TARGET_DOT = 0.012
ZMP_DOT = 0.015
LINE_WIDTH = 0.004
TEXT_HEIGHT = 0.03
GROUND_MARK_Z = 0.001  # m: the polygon and the ZMP are drawn this far above the ground, not in it

_MOVABLE = ("revolute", "continuous", "prismatic")


# --- what a bag holds ---------------------------------------------------------------------------------------------
class _Bag:
    """The messages of a bag, gathered, then written in time order into one MCAP file: a ``ros2msg`` schema per
    type, a ``cdr`` channel per topic (``offered_qos_profiles`` empty: rosbag2 reads it as "no recorded QoS")."""

    def __init__(self) -> None:
        self.records: list[tuple[int, int, str, bytes]] = []  # (stamp ns, order added, topic, CDR)

    def add(self, topic: str, stamp_ns: int, data: bytes) -> None:
        self.records.append((int(stamp_ns), len(self.records), topic, data))

    def add_message(self, topic: str, stamp_ns: int, message: dict) -> None:
        self.add(topic, stamp_ns, _encoder(TOPIC_TYPES[topic])(message))

    def add_many(self, topic: str, stamps: np.ndarray, data: Sequence[bytes]) -> None:
        for s, d in zip(np.asarray(stamps).tolist(), data):
            self.add(topic, s, d)

    def add_joint_states(self, topic: str, stamps: np.ndarray, names: Sequence[str], q: np.ndarray,
                         qd: np.ndarray | None) -> None:
        self.add_many(topic, stamps, msgs.joint_state_cdr(stamps, names, q, qd))

    def write(self, path: str | os.PathLike) -> Path:
        """Write the bag to ``path`` atomically; returns the path."""
        self.records.sort(key=lambda r: (r[0], r[1]))
        with atomic_open(path, "wb") as f:
            writer = Writer(f, compression=CompressionType.ZSTD)
            writer.start(profile="ros2", library=f"snakehead {__version__}")
            schemas: dict[str, int] = {}
            channels: dict[str, int] = {}
            for topic in dict.fromkeys(r[2] for r in self.records):
                kind = TOPIC_TYPES[topic]
                if kind not in schemas:
                    schemas[kind] = writer.register_schema(kind, "ros2msg", msgs.schema_text(kind).encode())
                channels[topic] = writer.register_channel(topic, "cdr", schemas[kind], {"offered_qos_profiles": ""})
            sequence = dict.fromkeys(channels, 0)
            for stamp_ns, _, topic, data in self.records:
                sequence[topic] += 1
                writer.add_message(channels[topic], log_time=stamp_ns, data=data, publish_time=stamp_ns,
                                   sequence=sequence[topic])
            writer.finish()
        return Path(path)


@lru_cache(maxsize=None)
def _encoder(type_name: str) -> Callable[[Any], bytes]:
    return msgs.encoder(type_name)


def _stamps(seconds: np.ndarray) -> np.ndarray:
    """ns (int64) of times in s (>= 0)."""
    invariant(bool((np.asarray(seconds) >= -1e-9).all()), "a time stamp before the start")
    return np.maximum(np.round(np.asarray(seconds, float) * 1e9), 0).astype(np.int64)


def samples_every(t: np.ndarray, period: float) -> np.ndarray:
    """Indices of the samples at (or just after) t[0], t[0] + period, ..., and the last one."""
    grid = t[0] + period * np.arange(int(np.floor((t[-1] - t[0]) / period + 1e-9)) + 1)
    return np.unique(np.r_[np.searchsorted(t, grid - 1e-9), len(t) - 1].clip(0, len(t) - 1))


# --- joints and frames --------------------------------------------------------------------------------------------
def joint_names(robot: SnakeRobot) -> list[str]:
    """The joints :data:`JOINT_STATES` names: the robot's (its body's, the CSV's columns, in order), then every other
    movable joint of the description (:attr:`SnakeRobot.description_text`) that mimics none (a camera's pan, a
    passive wheel: :func:`held_values`), so that robot_state_publisher places every link."""
    body = list(robot.joint_names)
    root = ET.fromstring(robot.description_text)
    extra = [j.get("name", "") for j in root.findall("joint")
             if j.get("type") in _MOVABLE and j.find("mimic") is None and j.get("name") not in body]
    return body + extra


def held_values(robot: SnakeRobot) -> np.ndarray:
    """The positions of :func:`joint_names` past the body's: a joint the planner held (a passive wheel,
    ``robot.tree_changes.held_joints``) at its value, any other at 0."""
    held = {name: value for name, value, _ in robot.tree_changes.held_joints}
    return np.array([held.get(name, 0.0) for name in joint_names(robot)[robot.n_joints:]], float)


def _joint_rows(robot: SnakeRobot, q: np.ndarray, qd: np.ndarray | None) -> tuple[list[str], np.ndarray,
                                                                                 np.ndarray | None]:
    """The names and the position and velocity rows of :data:`JOINT_STATES` for the planner's joints ``q`` (T, n):
    the description's angles (:meth:`SnakeRobot.description_angles`), the other joints at :func:`held_values`
    (velocities 0)."""
    names = joint_names(robot)
    q = robot.description_angles(q)
    pad = len(names) - q.shape[1]
    if pad:
        q = np.concatenate([q, np.broadcast_to(held_values(robot), (len(q), pad))], axis=1)
        qd = None if qd is None else np.pad(qd, ((0, 0), (0, pad)))
    return names, q, qd


def frame_name(name: str) -> str:
    """A valid tf2 frame id from ``name``: every run of characters other than letters, digits and "_" made one
    "_" (a target "sphere 1" is the frame ``target/sphere_1``)."""
    return re.sub(r"[^A-Za-z0-9_]+", "_", str(name)).strip("_") or "unnamed"


def target_frames(targets: Sequence[Any]) -> list[tuple[str, np.ndarray]]:
    """(frame id, world pose (4, 4)) of each target (``name``, ``position``, ``direction``): the x-axis along its
    direction, z as near world z as can be; names made frame ids and unique (a "_2" for the second of a name)."""
    out: list[tuple[str, np.ndarray]] = []
    for tg in targets:
        base = TARGET_FRAME_PREFIX + frame_name(tg.name)
        frame, k = base, 1
        while frame in (f for f, _ in out):
            k += 1
            frame = f"{base}_{k}"
        d = np.asarray(tg.direction, float)
        out.append((frame, frame_along(np.asarray(tg.position, float), d / np.linalg.norm(d))))
    return out


def _quaternions(T: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) as (x, y, z, w) of the rotations of poses T (..., 4, 4)."""
    T = np.asarray(T, float)
    return Rotation.from_matrix(T[..., :3, :3].reshape(-1, 3, 3)).as_quat().reshape(T.shape[:-2] + (4,))


IDENTITY = (0.0, 0.0, 0.0, 1.0)


def _tf_messages(stamps: np.ndarray, children: Sequence[str], poses: np.ndarray,
                 parents: str | Sequence[str] = WORLD_FRAME) -> list[bytes]:
    """TFMessages ``parents`` (one frame, or one per child) -> each child at each stamp: ``poses`` (T, m, 4, 4) in
    the parents (or (m, 4, 4): the same at every stamp)."""
    poses = np.broadcast_to(poses, (len(stamps), len(children), 4, 4))
    return msgs.tf_message_cdr(stamps, parents, children, poses[..., :3, 3], _quaternions(poses))


def ground_frame_of(base: Any) -> str:
    """The frame a plan on ``base`` (a :class:`~snakehead.model.robot.BasePlacement`) is written in: :data:`WORLD_FRAME`
    on flat ground, :data:`GROUND_FRAME` on a slope."""
    return WORLD_FRAME if base.ground.is_world else GROUND_FRAME


# --- markers ------------------------------------------------------------------------------------------------------
def _marker(ns: str, marker_id: int, kind: int, *, stamp_ns: int = 0, position: npt.ArrayLike = (0.0, 0.0, 0.0),
            orientation: npt.ArrayLike = IDENTITY, scale: Sequence[float] = (1.0, 1.0, 1.0),
            color: Sequence[float] = (1.0, 1.0, 1.0, 1.0), points: np.ndarray | None = None, text: str = "",
            delete: bool = False, frame_id: str = WORLD_FRAME) -> dict:
    """A Marker in ``frame_id`` (``world``, or ``ground`` on a slope): its pose (``position`` m, ``orientation``
    quaternion x, y, z, w), sizes in m, ``points`` (k, 3) in its pose's frame; ADD, or DELETE with ``delete``."""
    x, y, z = np.asarray(position, float).tolist()
    qx, qy, qz, qw = np.asarray(orientation, float).reshape(4).tolist()
    r, g, b, a = (float(c) for c in color)
    pts = [] if points is None else [{"x": px, "y": py, "z": pz} for px, py, pz in np.asarray(points, float).tolist()]
    return {"header": {"stamp": msgs.stamp(stamp_ns), "frame_id": frame_id}, "ns": ns, "id": int(marker_id),
            "type": kind, "action": 2 if delete else 0,  # DELETE / ADD
            "pose": {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}},
            "scale": dict(zip("xyz", (float(v) for v in scale))), "color": {"r": r, "g": g, "b": b, "a": a},
            "points": pts, "text": text}


def target_markers(targets: Sequence[Any], diameters: dict[str, float] | None = None, *,
                   frame_id: str = WORLD_FRAME) -> list[dict]:
    """Per target: an arrow of :data:`ARROW_LENGTH` ending at it along its direction, a sphere (the scene's
    ``sphere_diameter``, else a dot) and its name above it (namespaces "targets", "target_names"), in ``frame_id``
    (the targets' frame)."""
    frames = target_frames(targets)
    if not frames:
        return []
    quats = _quaternions(np.array([T for _, T in frames]))
    out = []
    for k, (tg, (_, T), quat) in enumerate(zip(targets, frames, quats)):
        p, x = T[:3, 3], T[:3, 0]
        d = (diameters or {}).get(tg.name) or TARGET_DOT
        out += [_marker("targets", 2 * k, msgs.ARROW, position=p - ARROW_LENGTH * x, orientation=quat,
                        scale=(ARROW_LENGTH, 0.006, 0.012), color=TARGET_COLOR, frame_id=frame_id),
                _marker("targets", 2 * k + 1, msgs.SPHERE, position=p, scale=(d, d, d),
                        color=TARGET_COLOR[:3] + (0.5,), frame_id=frame_id),
                _marker("target_names", k, msgs.TEXT_VIEW_FACING, position=p + [0.0, 0.0, d / 2 + TEXT_HEIGHT],
                        scale=(0.0, 0.0, TEXT_HEIGHT), color=(1.0, 1.0, 1.0, 1.0), text=str(tg.name),
                        frame_id=frame_id)]
    return out


def obstacle_markers(obstacles: Sequence[Any], *, frame_id: str = WORLD_FRAME) -> list[dict]:
    """The obstacles' convex shapes (namespace "obstacles"): boxes as cubes, spheres and cylinders as such, convex
    pieces (a wall's around its hole, a mesh's hull) as one triangle list per obstacle, in ``frame_id`` (the
    obstacles' frame)."""
    out: list[dict] = []
    for obstacle in obstacles:
        triangles = []
        for shape in obstacle.shapes():
            T = shape.origin
            if shape.kind == "convex":
                v = shape.vertices @ T[:3, :3].T + T[:3, 3]
                triangles.append(v[ConvexHull(v).simplices].reshape(-1, 3))
                continue
            kind, size = {"box": (msgs.CUBE, shape.size),
                          "sphere": (msgs.SPHERE, [2 * shape.radius] * 3),
                          "cylinder": (msgs.CYLINDER, [2 * shape.radius, 2 * shape.radius, shape.size[1]])}[shape.kind]
            out.append(_marker("obstacles", len(out), kind, position=T[:3, 3], orientation=_quaternions(T),
                               scale=size, color=OBSTACLE_COLOR, frame_id=frame_id))
        if triangles:
            out.append(_marker("obstacles", len(out), msgs.TRIANGLE_LIST, points=np.concatenate(triangles),
                               color=OBSTACLE_COLOR, frame_id=frame_id))
    return out


def ground_plane_marker(points: npt.ArrayLike) -> dict:
    """The tilted ground plane (namespace "ground_plane") in :data:`GROUND_FRAME`: a slab :data:`GROUND_PLANE_THICKNESS`
    thick just below its z = 0, over the x, y of ``points`` (k, 3) m of the ground frame (the body, the targets)
    and :data:`GROUND_PLANE_MARGIN` around them. Its z-axis is the plane's normal (the frame's)."""
    xy = np.asarray(points, float).reshape(-1, 3)[:, :2]
    lo, hi = xy.min(axis=0) - GROUND_PLANE_MARGIN, xy.max(axis=0) + GROUND_PLANE_MARGIN
    centre = 0.5 * (lo + hi)
    return _marker("ground_plane", 0, msgs.CUBE, position=(centre[0], centre[1], -GROUND_PLANE_THICKNESS / 2),
                   scale=(*(hi - lo), GROUND_PLANE_THICKNESS), color=GROUND_PLANE_COLOR, frame_id=GROUND_FRAME)


def ground_markers(stamp_ns: int, polygon: np.ndarray, zmp: np.ndarray, *, zmp_ns: str = "zmp",
                   zmp_color: Sequence[float] = ZMP_COLOR, frame_id: str = WORLD_FRAME) -> list[dict]:
    """The support polygon (k, 2) (x, y) m of ``frame_id`` (the world, or the ground frame on a slope) as a closed
    line (namespace "support_polygon"; deleted when it has fewer than 2 vertices) and the ZMP (2,) m as a dot
    (namespace ``zmp_ns``; deleted when not finite), on the ground."""
    ring = np.c_[np.r_[polygon, polygon[:1]], np.full(len(polygon) + 1, GROUND_MARK_Z)] if len(polygon) else None
    return [_marker("support_polygon", 0, msgs.LINE_STRIP, stamp_ns=stamp_ns, scale=(LINE_WIDTH, 0, 0),
                    color=POLYGON_COLOR, points=ring, delete=len(polygon) < 2, frame_id=frame_id),
            _marker(zmp_ns, 0, msgs.SPHERE, stamp_ns=stamp_ns, position=[*np.nan_to_num(zmp[:2]), GROUND_MARK_Z],
                    scale=(ZMP_DOT,) * 3, color=zmp_color, delete=not bool(np.isfinite(zmp).all()),
                    frame_id=frame_id)]


def _add_static_markers(bag: _Bag, targets: Sequence[Any], obstacles: Sequence[Any], scene: Any,
                        t_end_s: float, frame_id: str = WORLD_FRAME, plane: dict | None = None) -> None:
    """Targets and obstacles (in ``frame_id``) and the ground ``plane``'s marker if any, every
    :data:`STATIC_MARKER_PERIOD` from 0 to ``t_end_s`` (one encoding: stamped 0)."""
    diameters = {t.name: t.sphere_diameter for t in scene.targets} if scene is not None else {}
    markers = target_markers(targets, diameters, frame_id=frame_id) + obstacle_markers(obstacles, frame_id=frame_id)
    data = _encoder(TOPIC_TYPES[MARKERS])({"markers": markers + ([plane] if plane is not None else [])})
    for s in _stamps(np.arange(0.0, t_end_s + 1e-9, STATIC_MARKER_PERIOD)).tolist():
        bag.add(MARKERS, s, data)


def _add_plan_markers(bag: _Bag, plan: Plan, t0_s: float, simulated: Any = None) -> None:
    """The plan's support polygon and ZMP every :data:`MARKER_PERIOD`, on a clock where the plan starts at ``t0_s``,
    in the plan's frame (:func:`ground_frame_of`); with ``simulated`` (a SimResult of the plan), its ZMP beside
    (namespace "zmp_simulated")."""
    frame = ground_frame_of(plan.base)
    t = np.asarray(plan.t, float)
    idx = samples_every(t, MARKER_PERIOD)
    vertices, count = stability.support_polygons(plan.robot, plan.q[idx], plan.base, contact=PLAN_CONTACT)
    stamps = _stamps(t0_s + t[idx] - t[0])
    sim_zmp = None
    if simulated is not None:
        ticks = np.searchsorted(simulated.t, t[idx] - 1e-9).clip(0, len(simulated.t) - 1)
        sim_zmp = np.asarray(simulated.zmp, float)[ticks]
    for j, k in enumerate(idx):
        markers = ground_markers(int(stamps[j]), vertices[j, :count[j]], plan.stability.zmp[k], frame_id=frame)
        if sim_zmp is not None:
            markers += ground_markers(int(stamps[j]), vertices[j, :count[j]], sim_zmp[j], zmp_ns="zmp_simulated",
                                      zmp_color=SIMULATED_ZMP_COLOR, frame_id=frame)[1:]
        bag.add_message(MARKERS, int(stamps[j]), {"markers": markers})


# --- the bags -----------------------------------------------------------------------------------------------------
def write_plan_bag(plan: Plan, path: str | os.PathLike) -> Path:
    """Write ``plan`` (a :class:`~snakehead.planning.plan_result.Plan`) as a ROS 2 bag at ``path`` (see the module);
    returns the path. Every :data:`JOINT_STATES` sample is the plan's (``t``, ``q`` as the description's angles,
    ``qd``)."""
    robot = plan.robot
    t = np.asarray(plan.t, float)
    invariant(len(t) > 0 and plan.q.shape == (len(t), robot.n_joints), "a plan without samples")
    stamps = _stamps(t - t[0])
    bag = _Bag()
    bag.add_joint_states(JOINT_STATES, stamps, *_joint_rows(robot, np.asarray(plan.q), np.asarray(plan.qd)))
    bag.add(ROBOT_DESCRIPTION, 0, _encoder(TOPIC_TYPES[ROBOT_DESCRIPTION])({"data": robot.description_text}))
    goals = target_frames(plan.targets)
    children = [robot.description_root] + [f for f, _ in goals]
    idx = samples_every(t, TF_PERIOD)
    roots = robot.description_root_pose(robot.root_pose(plan.base), np.asarray(plan.q, float)[idx])
    fixed = np.broadcast_to(np.array([T for _, T in goals]).reshape(-1, 4, 4), (len(idx), len(goals), 4, 4))
    poses = np.concatenate([roots[:, None], fixed], axis=1)
    tf_stamps = stamps[idx]
    frame, plane = ground_frame_of(plan.base), None
    if frame == GROUND_FRAME:  # on a slope: world -> ground, then the root and the targets in the ground frame
        children, poses = [GROUND_FRAME, *children], np.concatenate(
            [np.broadcast_to(plan.base.ground.matrix, (len(idx), 1, 4, 4)), poses], axis=1)
        seen = samples_every(t, STATIC_MARKER_PERIOD)
        plane = ground_plane_marker(np.concatenate([
            robot.frames_many(np.asarray(plan.q, float)[seen], plan.base)[..., :3, 3].reshape(-1, 3),
            np.array([tg.position for tg in plan.targets], float).reshape(-1, 3)]))
    parents = [WORLD_FRAME if child == GROUND_FRAME else frame for child in children]
    bag.add_many(TF, tf_stamps, _tf_messages(tf_stamps, children, poses, parents))
    _add_static_markers(bag, plan.targets, plan.obstacles, plan.scene, float(t[-1] - t[0]), frame, plane)
    _add_plan_markers(bag, plan, 0.0)
    return bag.write(path)


def _loop_tracks(run: LoopRun) -> tuple[np.ndarray, np.ndarray]:
    """Along :meth:`LoopRun.timeline`: the joint velocities (T, n) rad/s (the head phases' simulated, the ground
    phases' by finite differences of the recorded joints) and the root frame's estimated world pose (T, 4, 4): the
    ground phases' dead reckoning (NaN where a run kept none), in the head phases the placement they were planned
    from."""
    segments = run.segments()
    if not segments:
        return np.zeros((0, run.robot.n_joints)), np.zeros((0, 4, 4))
    return np.concatenate([seg["qd"] for seg in segments]), np.concatenate([seg["estimate"] for seg in segments])


def write_loop_bag(run: LoopRun, path: str | os.PathLike) -> Path:
    """Write a closed loop's run (:class:`~snakehead.closed_loop.loop.LoopRun`) as a ROS 2 bag at ``path`` (see the
    module); returns the path."""
    robot = run.robot
    t, roots, q = run.timeline()
    invariant(len(t) > 0, "a loop that simulated nothing has no bag")
    qd, estimates = _loop_tracks(run)
    stamps = _stamps(t)
    bag = _Bag()
    bag.add_joint_states(JOINT_STATES, stamps, *_joint_rows(robot, q, qd))
    bag.add(ROBOT_DESCRIPTION, 0, _encoder(TOPIC_TYPES[ROBOT_DESCRIPTION])({"data": robot.description_text}))
    targets = run.plan.targets if run.plan is not None else list(run.scene.targets)
    goals = target_frames(targets)
    idx = samples_every(t, TF_PERIOD)
    body = robot.body_in_root
    moving = np.stack([robot.description_root_pose(roots[idx], q[idx]), roots[idx] @ body], axis=1)
    fixed = np.broadcast_to(np.array([T for _, T in goals]).reshape(-1, 4, 4), (len(idx), len(goals), 4, 4))
    # the head phases' plan on a slope is in its ground frame: world -> ground on /tf, its targets and markers in it
    frame = ground_frame_of(run.plan.base) if run.plan is not None else WORLD_FRAME
    if frame == GROUND_FRAME:
        assert run.plan is not None
        fixed = np.concatenate([fixed, np.broadcast_to(run.plan.base.ground.matrix, (len(idx), 1, 4, 4))], axis=1)
    names = [robot.description_root, TRUE_BASE_FRAME] + [f for f, _ in goals]
    parents = [WORLD_FRAME, WORLD_FRAME] + [frame] * len(goals) + ([WORLD_FRAME] if frame == GROUND_FRAME else [])
    bag.add_many(TF, stamps[idx], _tf_messages(stamps[idx], names + ([GROUND_FRAME] if frame == GROUND_FRAME else []),
                                               np.concatenate([moving, fixed], axis=1), parents))
    known = idx[np.isfinite(estimates[idx]).all(axis=(1, 2))]
    if len(known):  # (a run whose ground phases kept no estimate has none)
        bag.add_many(TF, stamps[known], _tf_messages(stamps[known], [ESTIMATED_BASE_FRAME],
                                                     estimates[known, None] @ body))
    obstacles = run.plan.obstacles if run.plan is not None and frame == GROUND_FRAME else run.scene.obstacles
    _add_static_markers(bag, targets, list(obstacles), run.scene, float(t[-1]), frame)
    if run.plan is not None:
        p = run.plan
        bag.add_joint_states(PLANNED_JOINT_STATES, _stamps(run.head_t0_s + p.t - p.t[0]),
                             *_joint_rows(robot, np.asarray(p.q), np.asarray(p.qd)))
        if run.head is not None:
            _add_plan_markers(bag, p, run.head_t0_s, run.head)
    return bag.write(path)


# --- the trajectory for controllers -------------------------------------------------------------------------------
def yaml_float(x: float) -> str:
    """``x`` as a YAML float that reads back exactly (Python's shortest repr, with a "." that YAML 1.1 needs)."""
    text = repr(x)
    return text.replace("e", ".0e") if "e" in text and "." not in text else text


#: A float's repr without a "." before its exponent ("1e-05", "-3e+20"): YAML 1.1 reads it as a string.
_BARE_EXPONENT = re.compile(r"(?<![\d.])(\d+)e")


def yaml_floats(row: np.ndarray) -> str:
    """``row``'s floats as :func:`yaml_float` writes them, joined by ", " (the list's repr, made in C: a plan's
    YAML has ~10^5 floats)."""
    text = repr(row.tolist())[1:-1]
    return _BARE_EXPONENT.sub(r"\1.0e", text) if "e" in text else text


def _yaml_string(text: str) -> str:
    return "'" + str(text).replace("'", "''") + "'"


def write_joint_trajectory(plan: Plan, path: str | os.PathLike) -> Path:
    """Write ``plan`` as a ``trajectory_msgs/msg/JointTrajectory`` in YAML (the message's fields, as ``ros2 topic
    echo`` prints them and ``rosidl_runtime_py.set_message_fields`` reads them) at ``path``; returns the path.

    A point per sample of the plan, at the control period (2 ms): ``positions`` (rad, the description's angles:
    :meth:`SnakeRobot.description_angles` of the plan's), ``velocities`` (rad/s), ``time_from_start`` from the
    first sample (0); no accelerations or efforts; ``header.stamp`` 0 (a controller starts it on arrival);
    ``joint_names`` the robot's, in the CSV's order."""
    t = np.asarray(plan.t, float)
    q, qd = plan.robot.description_angles(np.asarray(plan.q, float)), np.asarray(plan.qd, float)
    invariant(len(t) > 0 and bool(np.isfinite(q).all() and np.isfinite(qd).all()), "a plan without finite samples")
    period = float(np.median(np.diff(t))) if len(t) > 1 else CONTROL_PERIOD
    title = " ".join(str(plan.name).split())
    lines = [f"# trajectory_msgs/msg/JointTrajectory: snakehead's plan {title}, {len(t)} points every "
             f"{1000 * period:g} ms; positions in rad, velocities in rad/s",
             "header:", "  stamp: {sec: 0, nanosec: 0}", "  frame_id: ''",
             "joint_names: [" + ", ".join(map(_yaml_string, plan.robot.joint_names)) + "]", "points:"]
    for s, row, rate in zip(_stamps(t - t[0]).tolist(), q, qd):
        time = msgs.stamp(s)
        lines += [f"  - positions: [{yaml_floats(row)}]", f"    velocities: [{yaml_floats(rate)}]",
                  "    accelerations: []", "    effort: []",
                  f"    time_from_start: {{sec: {time['sec']}, nanosec: {time['nanosec']}}}"]
    return write_text_atomic(path, "\n".join(lines) + "\n")
