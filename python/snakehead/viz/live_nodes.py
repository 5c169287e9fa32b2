"""What the live viewer (:mod:`.live`) draws, and a plan as frames to play.

* :class:`LiveMotion` / :func:`live_motion`: a plan's frames (the robot's shapes every ``frame_step_s`` of motion,
  the ZMP), its head tip's path and ZMP's trace, its support polygon at the start;
* :class:`MotionNodes`: the viser nodes that play it -- the robot (:class:`.viewer_nodes.RobotNodes`), the ZMP, and
  paths of a fixed number of segments, so that a new plan moves the points of nodes that exist and rebuilds none;
* :class:`TargetGizmos`: the targets as transform gizmos (the x-axis the head's direction) with their arrows and
  names (:func:`.viewer_nodes.add_target_marker`), and the release of a gizmo as a callback;
* :func:`draw_live_scene`: the still scene the viewer starts with -- the lights, the root node at the ground frame's
  world pose (:class:`GroundNode`), the robot, the obstacles, the gizmos, the ground grid, a terrain, the camera.

Everything of :data:`ROOT` is in the plans' ground frame (the world's on flat ground): the root node holds the
frame's world pose, so on a slope the robot, the paths, the support polygon, the ZMP, the obstacles, the gizmos
and the ground grid are turned into the world by that one transform; a gizmo's pose, which a browser sends in its
parent's frame, is a target's pose in the ground frame, as the planner takes it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np
import numpy.typing as npt

from .._errors import InputError
from ..dynamics.stability import support_polygon
from ..scenes.scene import Target
from ..solve.head import frame_along
from .figure_geometry import terrain_mesh
from .viewer_arrays import (
    FRAME_STEP_S,
    camera_for,
    frame_indices,
    obstacle_arrays,
    quaternions_wxyz,
    robot_meshes,
    shape_colors,
    shape_poses,
)
from .viewer_nodes import (
    POLYGON_RGB,
    TIP_PATH_RGB,
    ZMP_RGB,
    RobotNodes,
    add_ground,
    add_obstacles,
    add_target_marker,
    add_terrain,
    camera_to,
    terrain_node,
)

if TYPE_CHECKING:
    import viser

    from ..model.placement import GroundFrame
    from ..model.robot import BasePlacement, SnakeRobot
    from ..planning.plan_result import Plan
    from ..scenes.scene import Scene

__all__ = ["PATH_SEGMENTS", "POLYGON_EDGES", "ROOT", "FILL_LIGHT", "GROUND_MARGIN_M", "LiveMotion", "live_motion",
           "wxyz_along", "x_axis", "gizmo_pose", "TargetGizmos", "MotionNodes", "GroundNode", "draw_live_scene"]

#: Segments of the head tip's path and of the ZMP's trace: fixed, so that a new plan moves their points only.
PATH_SEGMENTS = 200
#: Edges of the support polygon's node (a polygon of fewer repeats its last vertex; one of more is resampled).
POLYGON_EDGES = 64
#: Where the live viewer's nodes are in viser's scene tree: a node at the ground frame's world pose.
ROOT = "/live"
#: Strength of the hemisphere light that lights the sides the default lights leave dark (no environment map here).
FILL_LIGHT = 1.5
#: m: the margin around what the viewer shows at start for the ground grid (as the viewer's).
GROUND_MARGIN_M = 0.2

@dataclass
class LiveMotion:
    """A plan as the live viewer plays it: frames every ``frame_step_s`` of motion (``times`` (F,) s from 0), the
    robot's K shapes at each (``positions`` (F, K, 3), ``wxyz`` (F, K, 4)), the ZMP at each (``zmp`` (F, 2)); the
    head tip's path and the ZMP's trace as :data:`PATH_SEGMENTS` segments (S, 2, 3), the support polygon at the
    start as :data:`POLYGON_EDGES` edges (E, 2, 3)."""

    number: int
    plan: Plan
    times: np.ndarray
    positions: np.ndarray
    wxyz: np.ndarray
    zmp: np.ndarray
    tip_path: np.ndarray
    zmp_path: np.ndarray
    polygon: np.ndarray

    @property
    def duration_s(self) -> float:
        return float(self.times[-1])

    def frame_at(self, t: float) -> int:
        """The frame shown at ``t`` s into the motion."""
        return int(np.clip(np.searchsorted(self.times, t + 1e-9, side="right") - 1, 0, len(self.times) - 1))


def live_motion(number: int, plan: Plan, origins: np.ndarray, frame_step_s: float = FRAME_STEP_S) -> LiveMotion:
    """The frames of ``plan`` the live viewer plays (``origins``: the shapes' frames in their links,
    :func:`.viewer_arrays.robot_meshes`)."""
    robot, t = plan.robot, np.asarray(plan.t, float)
    idx = frame_indices(t, frame_step_s)
    frames = robot.frames_many(plan.q[idx], plan.base)
    positions, wxyz = shape_poses(robot, frames, origins)
    path = np.linspace(0, len(t) - 1, PATH_SEGMENTS + 1).round().astype(int)
    tip = robot.frames_many(plan.q[path], plan.base)[:, robot.link_index(robot.parts.head_tip), :3, 3]
    zmp = np.asarray(plan.stability.zmp, float)
    polygon = support_polygon(robot, plan.q[0], plan.base, contact="ground")
    return LiveMotion(number=number, plan=plan, times=t[idx] - t[0], positions=positions, wxyz=wxyz, zmp=zmp[idx],
                      tip_path=_segments(tip), zmp_path=_segments(_on_ground(zmp[path], 0.0015)),
                      polygon=_closed_edges(polygon, POLYGON_EDGES))


def _on_ground(xy: np.ndarray, height: float) -> np.ndarray:
    return np.column_stack([xy, np.full(len(xy), height)])


def _segments(points: np.ndarray) -> np.ndarray:
    """(N - 1, 2, 3) segments joining consecutive points (N, 3)."""
    return np.stack([points[:-1], points[1:]], axis=1)


def _closed_edges(polygon: np.ndarray, n: int) -> np.ndarray:
    """The edges of a closed ground polygon (k, 2) as exactly ``n`` segments (n, 2, 3) just above the ground: its
    last vertex repeated when it has fewer, its vertices resampled when it has more."""
    p = np.asarray(polygon, float).reshape(-1, 2)
    if len(p) == 0:
        p = np.zeros((1, 2))
    k = np.arange(n + 1)
    ring = np.vstack([p, p[:1]])
    picked = ring[np.minimum(k, len(p))] if len(p) <= n else ring[np.round(k * len(p) / n).astype(int)]
    return _segments(_on_ground(picked, 0.001))


# ----------------------------------------------------------------------------------------------
# targets and gizmos
# ----------------------------------------------------------------------------------------------
def wxyz_along(direction: npt.ArrayLike) -> np.ndarray:
    """A quaternion (w, x, y, z) of the head's frame for ``direction`` (3,): x along it, z as near the world's up as
    can be (:func:`snakehead.solve.head.frame_along`, the frame the planner aims the head at)."""
    x = np.asarray(direction, float) / np.linalg.norm(direction)
    return quaternions_wxyz(frame_along(np.zeros(3), x)[:3, :3][None])[0]


def x_axis(wxyz: npt.ArrayLike) -> np.ndarray:
    """The x-axis (3,) of the frame turned by the quaternion ``wxyz`` (normalised first)."""
    w, x, y, z = np.asarray(wxyz, float) / np.linalg.norm(wxyz)
    return np.array([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)])


def gizmo_pose(handle: Any) -> tuple[np.ndarray, np.ndarray]:
    """The position (3,) and x-axis (3,) of a gizmo as a browser left it (viser takes the pose a browser sends as it
    is); InputError for a pose that is not 3 and 4 finite numbers with a quaternion of non-zero length."""
    try:
        p = np.asarray(handle.position, dtype=float).reshape(3)
        q = np.asarray(handle.wxyz, dtype=float).reshape(4)
    except (TypeError, ValueError):
        raise InputError("a gizmo's pose must be a position of 3 numbers and a quaternion of 4") from None
    if not (np.isfinite(p).all() and np.isfinite(q).all() and np.linalg.norm(q) > 1e-9):
        raise InputError("a gizmo's pose must be finite numbers and its quaternion not of length 0")
    return p, x_axis(q)


class TargetGizmos:
    """The targets in the scene: one transform gizmo each (its x-axis the target's direction) carrying an arrow and
    the target's name. ``on_release(handle, client)`` is called (on viser's thread) when a user lets go of a gizmo
    (``client``: viser's handle of the browser that did, None if unknown); its pose is the browser's word, to be
    checked."""

    def __init__(self, scene_api: viser.SceneApi, size: float, on_release: Callable[[Any, Any], None]) -> None:
        self.scene, self.size, self.on_release = scene_api, size, on_release
        self.handles: list[Any] = []
        self._made = 0

    def add(self, target: Target) -> None:
        self._made += 1
        node = f"{ROOT}/targets/{self._made}"
        handle = self.scene.add_transform_controls(node, scale=self.size, position=target.position,
                                                   wxyz=wxyz_along(target.direction), depth_test=False)
        add_target_marker(self.scene, node, target.name, np.zeros(3), np.array([1.0, 0.0, 0.0]))
        handle.on_update(self._released)
        self.handles.append(handle)

    def remove(self, index: int) -> None:
        self.handles.pop(index).remove()

    def place(self, index: int, target: Target) -> None:
        handle = self.handles[index]
        handle.position = target.position
        handle.wxyz = wxyz_along(target.direction)

    def index(self, handle: Any) -> int:
        names = [h.name for h in self.handles]
        return names.index(handle.name) if handle.name in names else -1

    def _released(self, event: Any) -> None:
        if event.phase == "end":
            self.on_release(event.target, getattr(event, "client", None))


# ----------------------------------------------------------------------------------------------
# the motion's nodes
# ----------------------------------------------------------------------------------------------
class MotionNodes:
    """What moves with the plan: the robot (its shapes, :class:`.viewer_nodes.RobotNodes`), the ZMP now, and per plan the
    head tip's path, the ZMP's trace and the support polygon (segment nodes of fixed size, their points moved)."""

    def __init__(self, scene_api: viser.SceneApi, robot: SnakeRobot, q: np.ndarray, base: BasePlacement) -> None:
        meshes = robot_meshes(robot)
        self.origins = meshes.pop("origins")
        positions, wxyz = shape_poses(robot, robot.frames(q, base)[None], self.origins)
        self.start_positions = positions[0]
        s = scene_api
        self.robot = RobotNodes(s, f"{ROOT}/robot", meshes, shape_colors(robot), positions[0], wxyz[0])
        nothing = np.zeros((PATH_SEGMENTS, 2, 3))
        self.tip_path = s.add_line_segments(f"{ROOT}/head tip path", nothing, TIP_PATH_RGB, thickness=0.002)
        self.zmp_path = s.add_line_segments(f"{ROOT}/ZMP path", nothing, ZMP_RGB, thickness=0.002)
        self.polygon = s.add_line_segments(f"{ROOT}/support polygon", np.zeros((POLYGON_EDGES, 2, 3)),
                                           POLYGON_RGB, thickness=0.004)
        self.zmp = s.add_icosphere(f"{ROOT}/ZMP", radius=0.008, color=ZMP_RGB, cast_shadow=False, visible=False)
        self.frame = -1

    def start(self, motion: LiveMotion) -> None:
        """Show ``motion``'s first frame (the robot, the ZMP); :meth:`draw_paths` adds its paths."""
        self.zmp.visible = True
        self.frame = -1
        self.show(motion, 0)

    def draw_paths(self, motion: LiveMotion) -> None:
        """Show ``motion``'s head tip path, ZMP trace and support polygon (in place of the last motion's)."""
        self.tip_path.points = motion.tip_path.astype(np.float32)
        self.zmp_path.points = motion.zmp_path.astype(np.float32)
        self.polygon.points = motion.polygon.astype(np.float32)

    def show(self, motion: LiveMotion, k: int) -> None:
        """Move the robot and the ZMP to ``motion``'s frame ``k`` (nothing is sent if it is shown already)."""
        if k == self.frame:
            return
        self.frame = k
        self.robot.move(motion.positions[k], motion.wxyz[k])
        self.zmp.position = (float(motion.zmp[k, 0]), float(motion.zmp[k, 1]), 0.0)


# ----------------------------------------------------------------------------------------------
# the ground frame and the still scene
# ----------------------------------------------------------------------------------------------
class GroundNode:
    """The live viewer's root node (:data:`ROOT`) at the ground frame's world pose: the identity on flat ground, the
    plane's frame on a slope. Made before any node under it; :meth:`place` moves it (and all under it) to another
    plan's ground frame."""

    def __init__(self, scene_api: viser.SceneApi, ground: GroundFrame) -> None:
        self.ground = ground
        pose = self._pose(ground)
        self.handle = scene_api.add_frame(ROOT, show_axes=False, position=pose["position"], wxyz=pose["wxyz"])

    @staticmethod
    def _pose(ground: GroundFrame) -> dict[str, np.ndarray]:
        G = ground.matrix
        return dict(position=G[:3, 3], wxyz=quaternions_wxyz(G[None, :3, :3])[0])

    def place(self, ground: GroundFrame) -> None:
        """Put the root at ``ground``'s world pose (nothing is sent when it is there already)."""
        if ground != self.ground:
            self.ground = ground
            pose = self._pose(ground)
            self.handle.position, self.handle.wxyz = pose["position"], pose["wxyz"]

    def to_world(self, points: np.ndarray) -> np.ndarray:
        """Points (..., 3) of the ground frame in the world."""
        return points if self.ground.is_world else self.ground.to_world(points)


def draw_live_scene(server: viser.ViserServer, robot: SnakeRobot, q: np.ndarray, base: BasePlacement, scene: Scene,
                    gizmo_size: float, on_release: Callable[[Any, Any], None]) -> tuple[GroundNode, MotionNodes,
                                                                                        TargetGizmos]:
    """The still scene the live viewer starts with: the lights, the root node at ``base``'s ground frame, the robot
    at ``q`` on ``base``, ``scene``'s obstacles and a gizmo per target, the ground grid under what is shown (in the
    ground frame: tilted on a slope), the scene's terrain (a heightfield, a mesh, a staircase; in the world) and the
    initial camera on what is shown (in the world)."""
    s = server.scene
    # lit by viser's default lights and a fill light, without shadows or an environment map: each costs a browser
    # that renders in software (no GPU) much of its frame time, which a new motion waits for
    # (bench/live_latency.py)
    s.configure_environment_map(hdri=None)
    s.configure_default_lights(enabled=True, cast_shadow=False)
    root = GroundNode(s, base.ground)  # first: the parent of every node below
    s.add_light_hemisphere(f"{ROOT}/fill light", sky_color=(255, 255, 255), ground_color=(120, 120, 120),
                           intensity=FILL_LIGHT)
    nodes = MotionNodes(s, robot, q, base)
    arrays = obstacle_arrays(scene.obstacles)
    add_obstacles(s, f"{ROOT}/obstacles", **arrays)
    gizmos = TargetGizmos(s, gizmo_size, on_release)
    for target in scene.targets:
        gizmos.add(target)
    shown = np.vstack([nodes.start_positions, np.array([t.position for t in scene.targets]).reshape(-1, 3),
                       arrays["obstacle_centres"], arrays["wall_vertices"], np.zeros((1, 3))])
    lo, hi = shown.min(axis=0), shown.max(axis=0)
    add_ground(s, f"{ROOT}/ground", lo - GROUND_MARGIN_M, hi + GROUND_MARGIN_M)
    add_terrain(s, terrain_node(ROOT), *terrain_mesh(scene.terrain))
    world = root.to_world(shown)
    camera_to(server.initial_camera, *camera_for(world.min(axis=0) - 0.05, world.max(axis=0) + 0.05))
    return root, nodes, gizmos
