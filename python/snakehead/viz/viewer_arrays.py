"""What the 3-D viewer draws, as plain arrays: :class:`ViewerScene`, made from a plan (:func:`viewer_scene`) or a
whole-body reach map (:func:`reach_scene`).

A scene holds the robot's collision shapes per frame (each a unit mesh scaled, or a mesh hull), the head tip's
path, the head's reachability map in the head's base frame, the ZMP, the centre of mass and the support polygons,
the targets and the obstacles (m, s, z up; quaternions w, x, y, z), all in the plan's ground frame, whose world pose
is ``ground_pose`` (the identity on flat ground: the world frame; on a slope the plane's frame, z its normal); and
a scene's terrain other than a plane as triangles in the world. :mod:`.viewer_file` stores it, :mod:`.viewer_nodes`
puts it in a viser scene (the ground frame's nodes under one parent node that holds ``ground_pose``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from matplotlib.colors import to_rgb
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from .._errors import InputError
from ..dynamics import stability as st
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..geometry.shapes import Shape, shape_mesh
from ..kinematics.reachability.reachability_map import KIND_WHOLE_BODY, require_map
from ..model.robot import BasePlacement
from ..planning.plan_many import WORKERS, RobotRecipe
from .figure_geometry import Sphere, hole_rim, part_colors, plan_spheres, terrain_mesh, wall_faces

if TYPE_CHECKING:
    from ..kinematics.reachability.reachability_map import ReachabilityMap
    from ..planning.plan_result import Plan

__all__ = ["FRAME_STEP_S", "CAMERA_FOV_DEG", "CAMERA_VIEW_DEG", "VIEWER_SEGMENTS", "MESH_FIELDS", "OBSTACLE_FIELDS",
           "GROUND_FIELDS", "ViewerScene", "camera_for", "quaternions_wxyz", "rgb255", "robot_meshes", "viewer_scene",
           "reach_scene", "frame_indices", "distinct_polygons", "ground_arrays", "shape_poses", "shape_colors",
           "obstacle_arrays"]

#: s: default spacing of the viewer's frames along the motion (five frames per second of motion).
FRAME_STEP_S = 0.2
#: Vertical field of view of the initial camera (deg); the browser test projects with it.
CAMERA_FOV_DEG = 45.0
#: (elevation, azimuth) in degrees of the initial camera about the scene's centre, as matplotlib's view_init.
CAMERA_VIEW_DEG = (24.0, -60.0)
#: Segments around a cylinder's or a sphere's axis in the viewer.
VIEWER_SEGMENTS = 24
#: The :class:`ViewerScene` fields that say how the robot's shapes are drawn (:func:`robot_meshes`).
MESH_FIELDS = ("shape_mesh", "shape_scales", "mesh_vertices", "mesh_triangles", "mesh_vertex_starts",
               "mesh_triangle_starts")
#: The :class:`ViewerScene` fields that hold the obstacles (:func:`obstacle_arrays`).
OBSTACLE_FIELDS = ("obstacle_centres", "obstacle_sizes", "obstacle_wxyz", "wall_vertices", "wall_triangles",
                   "hole_rims")
#: The :class:`ViewerScene` fields of the ground: its frame's world pose and a terrain's triangles (flat ground and a
#: plane have none). A scene on flat ground without terrain leaves them at their defaults (:meth:`ViewerScene.flat`).
GROUND_FIELDS = ("ground_pose", "terrain_vertices", "terrain_triangles")


@dataclass
class ViewerScene:
    """Everything the viewer draws, as arrays (m, s, world frame, z up; quaternions w, x, y, z).

    Frames: ``times`` (F,) s; the K collision shapes' frames ``shape_positions`` (F, K, 3) and ``shape_wxyz``
    (F, K, 4), each drawn as mesh ``shape_mesh`` (K,) scaled by ``shape_scales`` (K, 3) along its axes, in
    ``shape_colors`` (K, 3) RGB 0-255; the G meshes in their own frames: ``mesh_vertices`` (MV, 3) and
    ``mesh_triangles`` (MT, 3) (vertex indices within the mesh), mesh g's rows from ``mesh_vertex_starts[g]`` and
    ``mesh_triangle_starts[g]`` to the next entries (G + 1,) (a unit cube for boxes, a unit cylinder of radius and
    length 1 for cylinders, a unit sphere, each mesh's hull); ``head_tip`` (F, 3); ``map_frame_positions`` (F, 3)
    and ``map_frame_wxyz`` (F, 4): the head's base frame, in which the map's ``voxel_centers`` (V, 3) lie (edge
    ``voxel_size``; ``voxel_indices`` (V,) 0-100; V = 0 without a map). ``zmp`` (F, 2) and ``com`` (F, 3) at the
    frames; ``zmp_path`` (Z, 2): the planned ZMP along the whole motion. ``polygons`` (P, M, 2): the distinct
    support polygons, NaN-padded to M vertices; ``polygon_of_frame`` (F,) which one each frame stands on.
    Targets: ``target_positions`` / ``target_directions`` (N, 3), ``target_names`` (N,), ``target_diameters`` (N,)
    (NaN: drawn as an arrow). Obstacles: boxes ``obstacle_centres`` / ``obstacle_sizes`` (B, 3),
    ``obstacle_wxyz`` (B, 4); walls (and mesh obstacles' hulls) as triangles ``wall_vertices`` (W, 3),
    ``wall_triangles`` (T, 3) and the holes' rims ``hole_rims`` (H, 65, 3).

    Everything above is in the plan's ground frame, whose world pose is ``ground_pose`` (4, 4) (the identity on flat
    ground); :meth:`to_world` turns points into the world. A terrain other than flat ground or a plane:
    ``terrain_vertices`` (TV, 3) in the world and ``terrain_triangles`` (TT, 3) (TV = TT = 0 without one).
    """

    name: str
    title: str
    times: np.ndarray
    shape_positions: np.ndarray
    shape_wxyz: np.ndarray
    shape_scales: np.ndarray
    shape_colors: np.ndarray
    shape_mesh: np.ndarray
    mesh_vertices: np.ndarray
    mesh_triangles: np.ndarray
    mesh_vertex_starts: np.ndarray
    mesh_triangle_starts: np.ndarray
    head_tip: np.ndarray
    map_frame_positions: np.ndarray
    map_frame_wxyz: np.ndarray
    voxel_centers: np.ndarray
    voxel_indices: np.ndarray
    voxel_size: float
    zmp: np.ndarray
    com: np.ndarray
    zmp_path: np.ndarray
    polygons: np.ndarray
    polygon_of_frame: np.ndarray
    target_positions: np.ndarray
    target_directions: np.ndarray
    target_names: np.ndarray
    target_diameters: np.ndarray
    obstacle_centres: np.ndarray
    obstacle_sizes: np.ndarray
    obstacle_wxyz: np.ndarray
    wall_vertices: np.ndarray
    wall_triangles: np.ndarray
    hole_rims: np.ndarray
    ground_pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    terrain_vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    terrain_triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int32))

    @property
    def n_frames(self) -> int:
        return len(self.times)

    @property
    def on_flat_ground(self) -> bool:
        """Whether the ground frame is the world frame (``ground_pose`` the identity)."""
        return bool(np.array_equal(self.ground_pose, np.eye(4)))

    @property
    def flat(self) -> bool:
        """On flat ground without a terrain: the scene a viewer of format 2 draws (:mod:`.viewer_file`)."""
        return self.on_flat_ground and len(self.terrain_triangles) == 0

    def to_world(self, points: np.ndarray) -> np.ndarray:
        """Points (..., 3) of the ground frame in the world (the same array on flat ground)."""
        if self.on_flat_ground:
            return points
        G = np.asarray(self.ground_pose, float)
        return np.asarray(points, float) @ G[:3, :3].T + G[:3, 3]

    def com_marks(self) -> np.ndarray:
        """(F, 2) m: the points of the ground (its frame's z = 0) below the centre of mass along gravity, which the
        viewer marks: its x, y on flat ground; on a slope, shifted where the weight leans (gravity, the world's -z,
        turned into the ground frame: minus the third row of the frame's rotation)."""
        if self.on_flat_ground:
            return self.com[:, :2]
        g = -np.asarray(self.ground_pose, float)[2, :3]
        return self.com[:, :2] + self.com[:, 2:3] * (g[:2] / -g[2])

    def _shown_points(self) -> np.ndarray:
        pts = [self.shape_positions.reshape(-1, 3), self.target_positions, np.zeros((1, 3))]
        if len(self.wall_vertices):
            pts.append(self.wall_vertices)
        if len(self.obstacle_centres):
            pts.append(self.obstacle_centres)
        return np.vstack(pts)

    def ground_bounds(self, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (3,) m in the ground frame of what the scene shows (without the map), with the
        ground's origin: where the viewer lays its ground grid."""
        allp = self._shown_points()
        return allp.min(axis=0) - margin, allp.max(axis=0) + margin

    def bounds(self, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (3,) m in the world of what the scene shows (without the map), with the ground's
        origin (:meth:`ground_bounds` on flat ground)."""
        if self.on_flat_ground:
            return self.ground_bounds(margin)
        allp = self.to_world(self._shown_points())
        return allp.min(axis=0) - margin, allp.max(axis=0) + margin

    def camera(self) -> tuple[np.ndarray, np.ndarray]:
        """(position, look-at point) of the initial camera: the whole scene in view from :data:`CAMERA_VIEW_DEG`."""
        return camera_for(*self.bounds())


def camera_for(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(position, look-at point) of a camera that sees the box [lo, hi] (3,) m whole from :data:`CAMERA_VIEW_DEG`."""
    centre = 0.5 * (lo + hi)
    radius = 0.5 * float(np.linalg.norm(hi - lo))
    elev, azim = np.radians(CAMERA_VIEW_DEG)
    towards_eye = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])
    distance = 1.05 * radius / np.sin(np.radians(CAMERA_FOV_DEG) / 2)
    return centre + distance * towards_eye, centre


def quaternions_wxyz(R: np.ndarray) -> np.ndarray:
    """Quaternions (w, x, y, z), viser's order, of rotation matrices (..., 3, 3)."""
    shape = R.shape[:-2]
    xyzw = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat()
    return np.concatenate([xyzw[:, 3:], xyzw[:, :3]], axis=1).reshape(*shape, 4)


def rgb255(color: str) -> tuple[int, int, int]:
    """A matplotlib colour (``"#2e86c1"``, ``"orange"``) as viser takes it: RGB, 0-255."""
    r, g, b = to_rgb(color)
    return round(255 * r), round(255 * g), round(255 * b)


def robot_meshes(robot: Any) -> dict[str, np.ndarray]:
    """How the viewer draws the robot's collision shapes (``robot.geometry``): per shape its mesh, the scale of the
    mesh along the shape frame's axes and the shape frame in its link (``origins`` (K, 4, 4)); the meshes in their
    own frames (the :class:`ViewerScene` fields ``shape_mesh``, ``shape_scales``, ``mesh_*``). Boxes share a unit
    cube, cylinders a unit cylinder, spheres a unit sphere; a mesh's hull is a mesh of its own."""
    unit = {"box": Shape("box", 0, np.eye(4), np.array([1.0, 1.0, 1.0])),
            "cylinder": Shape("cylinder", 0, np.eye(4), np.array([1.0, 1.0, 0.0])),
            "sphere": Shape("sphere", 0, np.eye(4), np.array([1.0, 0.0, 0.0]))}
    meshes: list[tuple[np.ndarray, np.ndarray]] = []
    mesh_of: dict[str, int] = {}
    which: list[int] = []
    scales: list[tuple[float, float, float]] = []
    geometry = robot.geometry
    for k, shape in enumerate(geometry.shapes):
        if shape.kind == "convex":
            v, f = shape_mesh(shape, VIEWER_SEGMENTS, hull=geometry, index=k)
            R, p = shape.origin[:3, :3], shape.origin[:3, 3]
            meshes.append(((v - p) @ R, f))  # back into the shape's own frame
            which.append(len(meshes) - 1)
            scales.append((1.0, 1.0, 1.0))
            continue
        if shape.kind not in mesh_of:
            meshes.append(shape_mesh(unit[shape.kind], VIEWER_SEGMENTS))
            mesh_of[shape.kind] = len(meshes) - 1
        which.append(mesh_of[shape.kind])
        size = np.asarray(shape.size, float)
        r = float(size[0])
        scales.append((float(size[0]), float(size[1]), float(size[2])) if shape.kind == "box" else
                      (r, r, float(size[1])) if shape.kind == "cylinder" else (r, r, r))
    vstarts = np.cumsum([0] + [len(v) for v, _ in meshes])
    tstarts = np.cumsum([0] + [len(f) for _, f in meshes])
    return dict(
        shape_mesh=np.array(which, np.int32), shape_scales=np.array(scales, float).reshape(-1, 3),
        mesh_vertices=np.concatenate([v for v, _ in meshes]).reshape(-1, 3) if meshes else np.zeros((0, 3)),
        mesh_triangles=(np.concatenate([f for _, f in meshes]).reshape(-1, 3).astype(np.int32) if meshes
                        else np.zeros((0, 3), np.int32)),
        mesh_vertex_starts=vstarts.astype(np.int64), mesh_triangle_starts=tstarts.astype(np.int64),
        origins=np.array([s.origin for s in geometry.shapes], float).reshape(-1, 4, 4))


def viewer_scene(plan: Plan, *, workspace_map: ReachabilityMap | None = None, spheres: Sequence[Sphere] | None = None,
                 frame_step_s: float = FRAME_STEP_S, max_frames: int = 2000, title: str = "",
                 contact: str = "ground") -> ViewerScene:
    """What the viewer shows of ``plan``: frames every ``frame_step_s`` s of motion (at most ``max_frames``, the
    first and the last sample included), the plan's targets and obstacles, ``spheres`` (default: the scene's), the
    head's ``workspace_map`` (a map of the robot's head chain, in the head's base frame) and the support polygons
    of ``contact`` (the contact model the plan was checked with)."""
    if not (np.isfinite(frame_step_s) and frame_step_s > 0):
        raise InputError(f"frame_step_s must be a positive number of seconds, got {frame_step_s!r}")
    if int(max_frames) != max_frames or max_frames < 2:
        raise InputError(f"max_frames must be an integer >= 2, got {max_frames!r}")
    robot = plan.robot
    if workspace_map is not None:  # a whole map (a shard shows part of it) of this robot's head
        require_map(workspace_map, robot, what="workspace_map")
    t = np.asarray(plan.t, float)
    idx = frame_indices(t, frame_step_s, max_frames)
    q = plan.q[idx]
    frames = robot.frames_many(q, plan.base)
    meshes = robot_meshes(robot)
    shape_positions, shape_wxyz = shape_poses(robot, frames, meshes.pop("origins"))
    map_frame = frames[:, robot.link_index(robot.parts.neck_end)]

    if workspace_map is not None and len(workspace_map):
        voxels = np.asarray(workspace_map.centers, float)
        indices = np.asarray(workspace_map.indices, float)
        voxel_size = float(workspace_map.voxel_size)
    else:
        voxels, indices, voxel_size = np.zeros((0, 3)), np.zeros(0), 0.0

    polygons, of_frame = distinct_polygons(robot, q, plan.base, contact)
    dyn = plan.stability
    step = max(1, len(t) // 2000)
    spheres = plan_spheres(plan) if spheres is None else list(spheres)
    diameters = {tuple(np.round(np.asarray(c, float), 9)): d for c, d in spheres}
    targets = list(plan.targets)
    return ViewerScene(
        name=plan.name, title=title or plan.name, times=t[idx], shape_positions=shape_positions,
        shape_wxyz=shape_wxyz, shape_colors=shape_colors(robot), **meshes,
        head_tip=frames[:, robot.link_index(robot.parts.head_tip), :3, 3],
        map_frame_positions=map_frame[:, :3, 3], map_frame_wxyz=quaternions_wxyz(map_frame[:, :3, :3]),
        voxel_centers=voxels, voxel_indices=indices, voxel_size=voxel_size,
        zmp=dyn.zmp[idx], com=dyn.com[idx], zmp_path=dyn.zmp[::step], polygons=polygons, polygon_of_frame=of_frame,
        target_positions=np.array([tg.position for tg in targets]).reshape(-1, 3),
        target_directions=np.array([tg.direction for tg in targets]).reshape(-1, 3),
        target_names=np.array([tg.name for tg in targets], dtype=str),
        target_diameters=np.array([diameters.get(tuple(np.round(tg.position, 9)), np.nan) for tg in targets], float),
        **obstacle_arrays(plan.obstacles), **ground_arrays(plan),
    )


def ground_arrays(plan: Plan) -> dict[str, np.ndarray]:
    """The :data:`GROUND_FIELDS` of ``plan``: its ground frame's world pose, its scene's terrain's triangles (none
    for flat ground and a plane: :func:`.figure_geometry.terrain_mesh`)."""
    vertices, triangles = terrain_mesh(getattr(getattr(plan, "scene", None), "terrain", None))
    return dict(ground_pose=plan.base.ground.matrix, terrain_vertices=vertices,
                terrain_triangles=triangles.astype(np.int32))


def reach_scene(reach_map: ReachabilityMap, robot: Any, *, title: str = "") -> ViewerScene:
    """A still scene (one frame) of a whole-body reach map (``snakehead reach``) of ``robot``: the robot at the
    start it was computed from (the planner's initial configuration at ``BasePlacement()``), its support polygon
    and centre of mass, and the voxels where the map reaches at least one direction, coloured by the share of
    directions reached (0-100, the index bar). The map's frame is the world frame (the "head base frame" node is
    at the origin)."""
    m = require_map(reach_map, robot, kind=KIND_WHOLE_BODY, what="reach_map")
    q0 = WORKERS.get(RobotRecipe.of(robot), None, "rotated", 1).q_initial
    base = BasePlacement()
    frames = robot.frames_many(q0[None], base)
    meshes = robot_meshes(robot)
    shape_positions, shape_wxyz = shape_poses(robot, frames, meshes.pop("origins"))
    shown = np.asarray(m.solved) > 0
    com = st.center_of_mass(robot, q0, base)
    poly = st.support_polygon(robot, q0, base, contact="ground")
    return ViewerScene(
        name="reach", title=title or f"whole-body reach ({int(shown.sum())} of {len(m)} voxels reached)",
        times=np.zeros(1), shape_positions=shape_positions, shape_wxyz=shape_wxyz, shape_colors=shape_colors(robot),
        **meshes, head_tip=frames[:, robot.link_index(robot.parts.head_tip), :3, 3],
        map_frame_positions=np.zeros((1, 3)), map_frame_wxyz=np.array([[1.0, 0.0, 0.0, 0.0]]),
        voxel_centers=np.asarray(m.centers, float)[shown], voxel_indices=np.asarray(m.indices, float)[shown],
        voxel_size=float(m.voxel_size), zmp=com[None, :2], com=com[None], zmp_path=com[None, :2],
        polygons=poly[None], polygon_of_frame=np.zeros(1, np.int32), target_positions=np.zeros((0, 3)),
        target_directions=np.zeros((0, 3)), target_names=np.array([], dtype=str), target_diameters=np.zeros(0),
        **obstacle_arrays([]))


def frame_indices(t: np.ndarray, frame_step_s: float = FRAME_STEP_S, max_frames: int = 2000) -> np.ndarray:
    """Indices into the sample times ``t`` (T,) s of the viewer's frames: one every ``frame_step_s`` s of motion, at
    most ``max_frames``, the first and the last sample included."""
    n = int(min(max_frames, len(t), np.floor((t[-1] - t[0]) / frame_step_s) + 1))
    return np.unique(np.r_[np.searchsorted(t, np.linspace(t[0], t[-1], max(n, 2))), len(t) - 1].clip(0, len(t) - 1))


def distinct_polygons(robot: Any, q: np.ndarray, base: Any, contact: str) -> tuple[np.ndarray, np.ndarray]:
    """The support polygons of the configurations ``q`` (F, n) on ``base`` under ``contact``, each distinct one once:
    ``polygons`` (P, M, 2) m, NaN-padded to M vertices, and ``of_frame`` (F,) which one each configuration stands on
    (the frames share a few: the base keeps its shape)."""
    polys: list[np.ndarray] = []
    of_frame = np.zeros(len(q), np.int32)
    for k, qk in enumerate(q):
        poly = st.support_polygon(robot, qk, base, contact=contact)
        last = polys[of_frame[k - 1]] if k else None
        if last is not None and last.shape == poly.shape and np.allclose(last, poly, atol=1e-6):
            of_frame[k] = of_frame[k - 1]
            continue
        match = [i for i, p in enumerate(polys) if p.shape == poly.shape and np.allclose(p, poly, atol=1e-6)]
        if not match:
            polys.append(poly)
            match = [len(polys) - 1]
        of_frame[k] = match[0]
    width = max(len(p) for p in polys)
    polygons = np.full((len(polys), width, 2), np.nan)
    for i, p in enumerate(polys):
        polygons[i, :len(p)] = p
    return polygons, of_frame


def shape_poses(robot: Any, frames: np.ndarray, origins: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions (F, K, 3) and quaternions (F, K, 4) of the robot's K collision shapes, given its link frames
    (F, L, 4, 4) (``robot.frames_many``) and the shapes' frames in their links ``origins`` (K, 4, 4)
    (:func:`robot_meshes`)."""
    B = frames[:, robot.geometry.shape_frames] @ origins
    return B[..., :3, 3], quaternions_wxyz(B[..., :3, :3])


def shape_colors(robot: Any) -> np.ndarray:
    """(K, 3) RGB 0-255 of the robot's collision shapes: the colours of their links' parts."""
    colors = part_colors(robot)
    return np.array([rgb255(colors[i]) for i in robot.geometry.shape_frames], np.uint8).reshape(-1, 3)


def obstacle_arrays(obstacles: Sequence[Any]) -> dict[str, np.ndarray]:
    """The obstacles as the :class:`ViewerScene` draws them (:data:`OBSTACLE_FIELDS`): boxes by centre, size and
    rotation; walls and mesh obstacles' hulls as triangles; the holes' rims."""
    boxes = [o for o in obstacles if isinstance(o, BoxObstacle)]
    walls = [o for o in obstacles if isinstance(o, WallWithHole)]
    quads = [wall_faces(w) for w in walls]
    wall_vertices = np.concatenate([qd.reshape(-1, 3) for qd in quads]) if quads else np.zeros((0, 3))
    tris = []
    offset = 0
    for qd in quads:
        base_idx = offset + 4 * np.arange(len(qd))[:, None]
        tris.append(np.concatenate([base_idx + [0, 1, 2], base_idx + [0, 2, 3]]))
        offset += 4 * len(qd)
    for mesh in (o for o in obstacles if isinstance(o, MeshObstacle)):  # drawn with the walls: triangles
        v = mesh.world_vertices
        wall_vertices = np.concatenate([wall_vertices, v])
        tris.append(ConvexHull(v).simplices + offset)
        offset += len(v)
    return dict(
        obstacle_centres=np.array([b.centre for b in boxes]).reshape(-1, 3),
        obstacle_sizes=np.array([b.size for b in boxes]).reshape(-1, 3),
        obstacle_wxyz=quaternions_wxyz(np.array([b.rotation for b in boxes]).reshape(-1, 3, 3)),
        wall_vertices=wall_vertices,
        wall_triangles=np.concatenate(tris).astype(np.int32) if tris else np.zeros((0, 3), np.int32),
        hole_rims=np.array([hole_rim(w) for w in walls]).reshape(-1, 65, 3))
