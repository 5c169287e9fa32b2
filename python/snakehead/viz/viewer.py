"""The interactive 3-D viewer (viser): a plan's motion in a web browser.

What it shows: the robot's collision shapes (boxes, cylinders, spheres, mesh hulls; base grey, neck orange, head
blue) moving along the planned motion,
with play/pause and a time slider; the targets (spheres or arrows along the desired direction); the obstacles; the
support polygon and the zero-moment point's trace on the ground (with the ZMP and the centre of mass's ground
projection now); the head tip's path; and the head's reachability map as voxels coloured by their index (the
paper's 20-step bar, Figs. 4-5), attached to the head's base frame and hidden until toggled on.

Three ways to it:

* :func:`viewer_scene` turns a :class:`~snakehead.planning.plan_result.Plan` into a :class:`ViewerScene` (plain arrays),
  which :func:`save_viewer_scene` writes as ``NAME_viewer.npz`` (``numpy.load`` reads it) and
  :func:`load_viewer_scene` reads back -- ``snakehead plan`` and ``snakehead demo`` write one per scenario;
* :func:`write_html`: a single HTML file that opens from disk in a browser, with no server and no network (viser's
  client, with the recorded scene inside the file). ``plan`` and ``demo`` write ``NAME.html`` beside the GIF;
  the scene tree (the tree icon at the bottom right) toggles the map, the ZMP, the targets and the obstacles;
* :func:`serve` (``snakehead view DIR``): a live viser server over the scenes in a folder, with a scenario menu,
  play/pause, a time slider, a speed menu and check boxes for the layers;
* :func:`reach_scene`: a still scene of a whole-body reach map (``snakehead reach``; ``snakehead view --map
  reach.npz``): the robot at its start and the voxels it reaches, coloured by the share of directions reached,
  shown at once.

viser is a dependency of snakehead; it is imported only when a page is made or served.
"""
from __future__ import annotations

import contextlib
import io
import os
import threading
import time
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator, Sequence

import numpy as np
import numpy.typing as npt

from .._files import atomic_open, read_npz, write_text_atomic
from .._validate import display_text, name_text
from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from .body import Sphere, hole_rim, part_colors, plan_spheres, wall_faces
from .._errors import InputError

if TYPE_CHECKING:
    import viser

    from ..kinematics.reachability.reachability_map import ReachabilityMap
    from ..planning.plan_result import Plan

#: What :func:`save_viewer_scene` appends to a scenario's name.
SCENE_SUFFIX = "_viewer.npz"
#: Format of ``NAME_viewer.npz`` (stored in the file; :func:`load_viewer_scene` refuses other versions).
SCENE_FORMAT = 2
#: s: default spacing of the viewer's frames along the motion (five frames per second of motion).
FRAME_STEP_S = 0.2
#: Colours (RGB 0-255) of what the viewer draws besides the robot (its parts: viz.body.part_colors).
ZMP_RGB = (192, 57, 43)
COM_RGB = (20, 20, 20)
POLYGON_RGB = (30, 30, 30)
TARGET_RGB = (192, 57, 43)
WALL_RGB = (161, 136, 127)
OBSTACLE_RGB = (141, 110, 99)
TIP_PATH_RGB = (90, 90, 90)
#: m: a target's arrow runs along its direction from this far behind the target to this far short of it.
TARGET_ARROW_M = (0.09, 0.01)
#: m: a target's label is this high above it.
TARGET_LABEL_HEIGHT_M = 0.04
#: Vertical field of view of the initial camera (deg); the browser test projects with it.
CAMERA_FOV_DEG = 45.0
#: (elevation, azimuth) in degrees of the initial camera about the scene's centre, as matplotlib's view_init.
CAMERA_VIEW_DEG = (24.0, -60.0)

_CUBE_VERTICES = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)], np.float32)
_CUBE_TRIANGLES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                            [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.uint32)
#: Segments around a cylinder's or a sphere's axis in the viewer.
VIEWER_SEGMENTS = 24


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

    @property
    def n_frames(self) -> int:
        return len(self.times)

    def bounds(self, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (3,) m of what the scene shows (without the map), with the ground (z = 0)."""
        pts = [self.shape_positions.reshape(-1, 3), self.target_positions, np.zeros((1, 3))]
        if len(self.wall_vertices):
            pts.append(self.wall_vertices)
        if len(self.obstacle_centres):
            pts.append(self.obstacle_centres)
        allp = np.vstack(pts)
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


def _wxyz(R: np.ndarray) -> np.ndarray:
    """Quaternions (w, x, y, z) of rotation matrices (..., 3, 3)."""
    from scipy.spatial.transform import Rotation

    shape = R.shape[:-2]
    xyzw = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat()
    return np.concatenate([xyzw[:, 3:], xyzw[:, :3]], axis=1).reshape(*shape, 4)


def _rgb(color: str) -> tuple[int, int, int]:
    from matplotlib.colors import to_rgb

    r, g, b = to_rgb(color)
    return round(255 * r), round(255 * g), round(255 * b)


def robot_meshes(robot: Any) -> dict[str, np.ndarray]:
    """How the viewer draws the robot's collision shapes (``robot.geometry``): per shape its mesh, the scale of the
    mesh along the shape frame's axes and the shape frame in its link (``origins`` (K, 4, 4)); the meshes in their
    own frames (the :class:`ViewerScene` fields ``shape_mesh``, ``shape_scales``, ``mesh_*``). Boxes share a unit
    cube, cylinders a unit cylinder, spheres a unit sphere; a mesh's hull is a mesh of its own."""
    from ..geometry.shapes import Shape, shape_mesh

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
    from ..dynamics import stability as st

    if not (np.isfinite(frame_step_s) and frame_step_s > 0):
        raise InputError(f"frame_step_s must be a positive number of seconds, got {frame_step_s!r}")
    if int(max_frames) != max_frames or max_frames < 2:
        raise InputError(f"max_frames must be an integer >= 2, got {max_frames!r}")
    robot = plan.robot
    if workspace_map is not None:  # a whole map (a shard shows part of it) of this robot's head
        from ..kinematics.reachability.reachability_map import require_map

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

    # the support polygon of each frame; the frames share a few distinct ones (the base keeps its shape)
    polys: list[np.ndarray] = []
    of_frame = np.zeros(len(idx), np.int32)
    for k, qk in enumerate(q):
        poly = st.support_polygon(robot, qk, plan.base, contact=contact)
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

    dyn = plan.stability
    step = max(1, len(t) // 2000)
    spheres = plan_spheres(plan) if spheres is None else list(spheres)
    diameters = {tuple(np.round(np.asarray(c, float), 9)): d for c, d in spheres}
    targets = list(plan.targets)
    return ViewerScene(
        name=plan.name, title=title or plan.name, times=t[idx], shape_positions=shape_positions,
        shape_wxyz=shape_wxyz, shape_colors=shape_colors(robot), **meshes,
        head_tip=frames[:, robot.link_index(robot.parts.head_tip), :3, 3],
        map_frame_positions=map_frame[:, :3, 3], map_frame_wxyz=_wxyz(map_frame[:, :3, :3]),
        voxel_centers=voxels, voxel_indices=indices, voxel_size=voxel_size,
        zmp=dyn.zmp[idx], com=dyn.com[idx], zmp_path=dyn.zmp[::step], polygons=polygons, polygon_of_frame=of_frame,
        target_positions=np.array([tg.position for tg in targets]).reshape(-1, 3),
        target_directions=np.array([tg.direction for tg in targets]).reshape(-1, 3),
        target_names=np.array([tg.name for tg in targets], dtype=str),
        target_diameters=np.array([diameters.get(tuple(np.round(tg.position, 9)), np.nan) for tg in targets], float),
        **obstacle_arrays(plan.obstacles),
    )


def reach_scene(reach_map: ReachabilityMap, robot: Any, *, title: str = "") -> ViewerScene:
    """A still scene (one frame) of a whole-body reach map (``snakehead reach``) of ``robot``: the robot at the
    start it was computed from (the planner's initial configuration at ``BasePlacement()``), its support polygon
    and centre of mass, and the voxels where the map reaches at least one direction, coloured by the share of
    directions reached (0-100, the index bar). The map's frame is the world frame (the "head base frame" node is
    at the origin)."""
    from ..dynamics import stability as st
    from ..kinematics.reachability.reachability_map import KIND_WHOLE_BODY, require_map
    from ..model.robot import BasePlacement
    from ..planning.plan_many import WORKERS, RobotRecipe

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


def shape_poses(robot: Any, frames: np.ndarray, origins: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions (F, K, 3) and quaternions (F, K, 4) of the robot's K collision shapes, given its link frames
    (F, L, 4, 4) (``robot.frames_many``) and the shapes' frames in their links ``origins`` (K, 4, 4)
    (:func:`robot_meshes`)."""
    B = frames[:, robot.geometry.shape_frames] @ origins
    return B[..., :3, 3], _wxyz(B[..., :3, :3])


def shape_colors(robot: Any) -> np.ndarray:
    """(K, 3) RGB 0-255 of the robot's collision shapes: the colours of their links' parts."""
    colors = part_colors(robot)
    return np.array([_rgb(colors[i]) for i in robot.geometry.shape_frames], np.uint8).reshape(-1, 3)


#: The :class:`ViewerScene` fields that hold the obstacles (:func:`obstacle_arrays`, :func:`add_obstacles`).
OBSTACLE_FIELDS = ("obstacle_centres", "obstacle_sizes", "obstacle_wxyz", "wall_vertices", "wall_triangles",
                   "hole_rims")


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
        from scipy.spatial import ConvexHull

        v = mesh.world_vertices
        wall_vertices = np.concatenate([wall_vertices, v])
        tris.append(ConvexHull(v).simplices + offset)
        offset += len(v)
    return dict(
        obstacle_centres=np.array([b.centre for b in boxes]).reshape(-1, 3),
        obstacle_sizes=np.array([b.size for b in boxes]).reshape(-1, 3),
        obstacle_wxyz=_wxyz(np.array([b.rotation for b in boxes]).reshape(-1, 3, 3)),
        wall_vertices=wall_vertices,
        wall_triangles=np.concatenate(tris).astype(np.int32) if tris else np.zeros((0, 3), np.int32),
        hole_rims=np.array([hole_rim(w) for w in walls]).reshape(-1, 65, 3))


# ----------------------------------------------------------------------------------------------
# NAME_viewer.npz
# ----------------------------------------------------------------------------------------------
def save_viewer_scene(scene: ViewerScene, path: str | Path) -> Path:
    """Write ``scene`` as a compressed ``.npz`` (atomically); returns the path."""
    path = Path(path)
    arrays = {f.name: np.asarray(getattr(scene, f.name)) for f in fields(scene)}
    arrays["format"] = np.asarray(SCENE_FORMAT)
    with atomic_open(path, "wb") as f:
        np.savez_compressed(f, **arrays)  # type: ignore[arg-type]
    return path


#: The largest viewer scene read (bytes, unpacked): a scene of 2000 frames of a 100-link robot is ~20 MB.
MAX_SCENE_BYTES = 512 << 20

#: Each array of a viewer scene: its dtype kind ("f" numbers, "i" integers, "U" text) and its shape, in symbols
#: that must agree across arrays (F frames, K shapes, G1 = G + 1 for G meshes of MV vertices and MT triangles, V voxels,
#: Z ZMP samples, P polygons of M vertices, N targets, B obstacle boxes, W wall vertices, T wall triangles, H hole rims
#: of R points).
_SCENE_ARRAYS = {
    "name": ("U", ()), "title": ("U", ()), "times": ("f", ("F",)), "shape_positions": ("f", ("F", "K", 3)),
    "shape_wxyz": ("f", ("F", "K", 4)), "shape_scales": ("f", ("K", 3)), "shape_colors": ("i", ("K", 3)),
    "shape_mesh": ("i", ("K",)), "mesh_vertices": ("f", ("MV", 3)), "mesh_triangles": ("i", ("MT", 3)),
    "mesh_vertex_starts": ("i", ("G1",)), "mesh_triangle_starts": ("i", ("G1",)),
    "head_tip": ("f", ("F", 3)), "map_frame_positions": ("f", ("F", 3)), "map_frame_wxyz": ("f", ("F", 4)),
    "voxel_centers": ("f", ("V", 3)), "voxel_indices": ("f", ("V",)), "voxel_size": ("f", ()),
    "zmp": ("f", ("F", 2)), "com": ("f", ("F", 3)), "zmp_path": ("f", ("Z", 2)), "polygons": ("f", ("P", "M", 2)),
    "polygon_of_frame": ("i", ("F",)), "target_positions": ("f", ("N", 3)), "target_directions": ("f", ("N", 3)),
    "target_names": ("U", ("N",)), "target_diameters": ("f", ("N",)), "obstacle_centres": ("f", ("B", 3)),
    "obstacle_sizes": ("f", ("B", 3)), "obstacle_wxyz": ("f", ("B", 4)), "wall_vertices": ("f", ("W", 3)),
    "wall_triangles": ("i", ("T", 3)), "hole_rims": ("f", ("H", "R", 3)),
}
#: Arrays that may hold NaN (polygons are NaN-padded; a target without a diameter is an arrow).
_SCENE_NAN_ALLOWED = ("polygons", "target_diameters")


def _check_scene_arrays(where: str, values: dict[str, np.ndarray]) -> None:
    """ValueError naming the array unless every array has its kind and a shape consistent with the others, numbers
    are finite (where NaN means nothing) and indices point inside what they index."""
    sizes: dict[str, int] = {}
    for key, (kind, shape) in _SCENE_ARRAYS.items():
        a = values[key]
        if not (a.dtype.kind == kind or (kind == "f" and a.dtype.kind in "iu") or (kind == "i" and a.dtype.kind == "u")):
            raise InputError(f"{where}: {key} holds {a.dtype}, not {dict(f='numbers', i='integers', U='text')[kind]}")
        if a.ndim != len(shape):
            raise InputError(f"{where}: {key} has shape {a.shape}, expected {len(shape)} dimensions")
        for d, want in zip(a.shape, shape):
            if isinstance(want, int) and d != want or isinstance(want, str) and sizes.setdefault(want, d) != d:
                raise InputError(f"{where}: {key} has shape {a.shape}, which disagrees with the other arrays")
        if kind == "f" and key not in _SCENE_NAN_ALLOWED and not np.all(np.isfinite(a)):
            raise InputError(f"{where}: {key} holds NaN or inf")
    if sizes["F"] < 1 or np.any(np.diff(values["times"]) < 0):
        raise InputError(f"{where}: times must be at least one time, in order")
    for key, bound in (("polygon_of_frame", "P"), ("wall_triangles", "W")):
        a = values[key]
        if a.size and (a.min() < 0 or a.max() >= sizes[bound]):
            raise InputError(f"{where}: {key} points outside its {sizes[bound]} entries")
    vs, ts = values["mesh_vertex_starts"], values["mesh_triangle_starts"]
    if (sizes["G1"] < 1 or vs[0] != 0 or ts[0] != 0 or vs[-1] != sizes["MV"] or ts[-1] != sizes["MT"]
            or np.any(np.diff(vs) < 0) or np.any(np.diff(ts) < 0)):
        raise InputError(f"{where}: mesh_vertex_starts / mesh_triangle_starts must run in order from 0 to the number "
                         "of mesh vertices / triangles")
    mesh = values["shape_mesh"]
    if mesh.size and (mesh.min() < 0 or mesh.max() >= sizes["G1"] - 1):
        raise InputError(f"{where}: shape_mesh points outside its {sizes['G1'] - 1} meshes")
    for g in range(sizes["G1"] - 1):
        tri = values["mesh_triangles"][ts[g]:ts[g + 1]]
        if tri.size and (tri.min() < 0 or tri.max() >= vs[g + 1] - vs[g]):
            raise InputError(f"{where}: mesh_triangles of mesh {g} point outside its {vs[g + 1] - vs[g]} vertices")
    if np.any((values["voxel_indices"] < 0) | (values["voxel_indices"] > 100)) or not values["voxel_size"] >= 0:
        raise InputError(f"{where}: voxel_indices must be within [0, 100] and voxel_size >= 0")


def load_viewer_scene(path: str | Path) -> ViewerScene:
    """Read a scene written by :func:`save_viewer_scene`: ValueError if the file is not one, is damaged (see
    :func:`snakehead._files.read_npz`) or its arrays disagree (shapes, kinds, indices)."""
    where = f"{os.fspath(path)}"
    contents = read_npz(path, "viewer scene", max_bytes=MAX_SCENE_BYTES)
    version = contents.pop("format", None)
    if version is None or version.shape != () or version.dtype.kind not in "iu" or int(version) != SCENE_FORMAT:
        raise InputError(f"{where}: not a viewer scene of format {SCENE_FORMAT} (format {version!r})")
    names = {f.name for f in fields(ViewerScene)}
    missing = names - set(contents)
    if missing:
        raise InputError(f"{where}: viewer scene without {sorted(missing)}")
    values: dict[str, Any] = {k: contents[k] for k in names}
    _check_scene_arrays(where, values)
    values["name"] = name_text(str(values["name"]), f"{where}: name")
    values["title"] = display_text(str(values["title"]), f"{where}: title")
    for k, target in enumerate(values["target_names"].tolist()):
        name_text(target, f"{where}: target_names[{k}]")
    values["voxel_size"] = float(values["voxel_size"])
    return ViewerScene(**values)


def scenes_in(directory: str | Path) -> list[Path]:
    """The viewer scenes (``*_viewer.npz``) in the output folder of ``snakehead plan`` or ``demo``, sorted."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"{directory} is not a directory")
    return sorted(directory.glob("*" + SCENE_SUFFIX))


# ----------------------------------------------------------------------------------------------
# the scene in viser
# ----------------------------------------------------------------------------------------------
class SceneNodes:
    """The nodes of one :class:`ViewerScene` in a viser scene, under ``/ROOT``; :meth:`show_frame` moves them."""

    LAYERS = ("robot", "reachability map", "ZMP and support polygon", "targets", "obstacles", "head tip path")

    def __init__(self, scene_api: viser.SceneApi, data: ViewerScene, root: str = "/snakehead") -> None:
        self.data = data
        self.root = root
        self.frame = -1
        s = scene_api
        light_scene(s)
        # one parent node per layer, so that a layer shows or hides as one (viser's visibility is inherited)
        self.groups = {layer: s.add_frame(f"{root}/{layer}", show_axes=False)
                       for layer in ("ZMP and support polygon", "targets", "obstacles", "head tip path")}
        self.ground = add_ground(s, f"{root}/ground", *data.bounds(margin=0.2))
        self.robot_nodes = RobotNodes(s, f"{root}/robot", {k: getattr(data, k) for k in MESH_FIELDS},
                                      data.shape_colors, data.shape_positions[0], data.shape_wxyz[0])
        self.robot = self.robot_nodes.frame
        self.map_frame = s.add_frame(f"{root}/head base frame", show_axes=True, axes_length=0.05, axes_radius=0.002,
                                     position=data.map_frame_positions[0], wxyz=data.map_frame_wxyz[0])
        self.voxels = None
        if len(data.voxel_centers):
            from .reachability_figures import index_colors

            rgb = np.round(255 * index_colors(data.voxel_indices)).astype(np.uint8)
            n = len(data.voxel_centers)
            self.voxels = s.add_batched_meshes_simple(
                f"{root}/head base frame/reachability map", _CUBE_VERTICES, _CUBE_TRIANGLES,
                batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)), batched_positions=data.voxel_centers,
                batched_scales=np.full(n, 0.8 * data.voxel_size), batched_colors=rgb, opacity=0.35, lod="off",
                cast_shadow=False, receive_shadow=False, visible=data.n_frames == 1)
        self.polygons = []
        for i, poly in enumerate(data.polygons):
            p = poly[np.all(np.isfinite(poly), axis=1)]
            p3 = np.column_stack([p, np.full(len(p), 0.001)])
            segs = np.stack([p3, np.roll(p3, -1, axis=0)], axis=1)
            self.polygons.append(s.add_line_segments(f"{root}/ZMP and support polygon/support polygon {i}", segs,
                                                     POLYGON_RGB, thickness=0.004,
                                                     visible=bool(data.polygon_of_frame[0] == i)))
        z3 = np.column_stack([data.zmp_path, np.full(len(data.zmp_path), 0.0015)])
        if len(z3) > 1:
            s.add_line_segments(f"{root}/ZMP and support polygon/ZMP path", np.stack([z3[:-1], z3[1:]], axis=1),
                                ZMP_RGB, thickness=0.002)
        self.zmp = s.add_icosphere(f"{root}/ZMP and support polygon/ZMP", radius=0.008, color=ZMP_RGB,
                                   position=(*data.zmp[0], 0.0), cast_shadow=False)
        self.com = s.add_icosphere(f"{root}/ZMP and support polygon/CoM ground projection", radius=0.006,
                                   color=COM_RGB, position=(data.com[0, 0], data.com[0, 1], 0.0), cast_shadow=False)
        tip = data.head_tip
        if len(tip) > 1:
            s.add_line_segments(f"{root}/head tip path/path", np.stack([tip[:-1], tip[1:]], axis=1), TIP_PATH_RGB,
                                thickness=0.002)
        for i, (p, d, name, dia) in enumerate(zip(data.target_positions, data.target_directions, data.target_names,
                                                  data.target_diameters)):
            node = f"{root}/targets/{i + 1} {_node_name(name)}"
            if np.isfinite(dia):
                s.add_icosphere(node + "/sphere", radius=float(dia) / 2, color=TARGET_RGB, opacity=0.6,
                                position=p, cast_shadow=False)
            add_target_marker(s, node, str(name), p, d)
        add_obstacles(s, f"{root}/obstacles", **{k: getattr(data, k) for k in OBSTACLE_FIELDS})
        self.show_frame(0)

    def show_frame(self, k: int) -> None:
        """Move everything that moves to frame ``k`` (0 .. n_frames - 1); only what changed is sent."""
        d = self.data
        k = int(np.clip(k, 0, d.n_frames - 1))
        if k == self.frame:
            return
        before = self.frame
        self.frame = k
        self.robot_nodes.move(d.shape_positions[k], d.shape_wxyz[k])
        self.map_frame.position = d.map_frame_positions[k]
        self.map_frame.wxyz = d.map_frame_wxyz[k]
        self.zmp.position = (d.zmp[k, 0], d.zmp[k, 1], 0.0)
        self.com.position = (d.com[k, 0], d.com[k, 1], 0.0)
        if before < 0 or d.polygon_of_frame[before] != d.polygon_of_frame[k]:
            for i, node in enumerate(self.polygons):
                node.visible = bool(d.polygon_of_frame[k] == i)


#: The :class:`ViewerScene` fields that say how the robot's shapes are drawn (:func:`robot_meshes`).
MESH_FIELDS = ("shape_mesh", "shape_scales", "mesh_vertices", "mesh_triangles", "mesh_vertex_starts",
               "mesh_triangle_starts")


class RobotNodes:
    """The robot's collision shapes in a viser scene under the frame ``name``: one batch of instances per mesh
    (every box one unit cube scaled, ...), all moved at once by :meth:`move`. ``meshes``: the :data:`MESH_FIELDS`
    of :func:`robot_meshes`; ``colors`` (K, 3) RGB 0-255; ``positions`` (K, 3) and ``wxyz`` (K, 4): the first pose."""

    def __init__(self, scene_api: viser.SceneApi, name: str, meshes: dict[str, np.ndarray], colors: np.ndarray,
                 positions: np.ndarray, wxyz: np.ndarray) -> None:
        self.frame = scene_api.add_frame(name, show_axes=False)
        self.batches = []
        vs, ts = meshes["mesh_vertex_starts"], meshes["mesh_triangle_starts"]
        for g in range(len(vs) - 1):
            which = np.flatnonzero(meshes["shape_mesh"] == g)
            if not which.size:
                continue
            handle = scene_api.add_batched_meshes_simple(
                f"{name}/mesh {g}", meshes["mesh_vertices"][vs[g]:vs[g + 1]].astype(np.float32),
                meshes["mesh_triangles"][ts[g]:ts[g + 1]].astype(np.uint32), batched_wxyzs=wxyz[which],
                batched_positions=positions[which], batched_scales=meshes["shape_scales"][which],
                batched_colors=colors[which], lod="off", flat_shading=True)
            self.batches.append((handle, which))

    def move(self, positions: np.ndarray, wxyz: np.ndarray) -> None:
        """Put the K shapes at ``positions`` (K, 3) m with orientations ``wxyz`` (K, 4)."""
        for handle, which in self.batches:
            handle.batched_positions = positions[which]
            handle.batched_wxyzs = wxyz[which]


def light_scene(scene_api: viser.SceneApi) -> None:
    """The viewer's lighting: an environment map at 0.4 of its strength (at full strength the parts' colours wash
    out to white)."""
    scene_api.configure_environment_map(hdri="warehouse", environment_intensity=0.4)


def add_ground(scene_api: viser.SceneApi, name: str, lo: np.ndarray, hi: np.ndarray) -> Any:
    """A ground grid (z = 0) under the box [lo, hi] (3,) m: 0.1 m cells, 0.5 m sections."""
    size = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    centre = 0.5 * (lo + hi)
    return scene_api.add_grid(name, width=size, height=size, plane="xy", cell_size=0.1, section_size=0.5,
                              position=(centre[0], centre[1], 0.0))


def add_obstacles(scene_api: viser.SceneApi, root: str, *, obstacle_centres: np.ndarray, obstacle_sizes: np.ndarray,
                  obstacle_wxyz: np.ndarray, wall_vertices: np.ndarray, wall_triangles: np.ndarray,
                  hole_rims: np.ndarray) -> None:
    """The obstacles (:func:`obstacle_arrays`) under ``root``: boxes, walls and mesh hulls, the holes' rims."""
    s = scene_api
    for i, (c, size, q) in enumerate(zip(obstacle_centres, obstacle_sizes, obstacle_wxyz)):
        s.add_box(f"{root}/box {i + 1}", color=OBSTACLE_RGB, dimensions=tuple(size), position=c, wxyz=q, opacity=0.6)
    if len(wall_triangles):
        s.add_mesh_simple(f"{root}/wall", wall_vertices.astype(np.float32), wall_triangles.astype(np.uint32),
                          color=WALL_RGB, opacity=0.45, side="double", cast_shadow=False)
        for i, rim in enumerate(hole_rims):
            s.add_line_segments(f"{root}/hole {i + 1}", np.stack([rim[:-1], rim[1:]], axis=1), (0, 0, 0),
                                thickness=0.002)


def add_target_marker(scene_api: viser.SceneApi, node: str, name: str, position: npt.ArrayLike,
                      direction: npt.ArrayLike) -> None:
    """A target's arrow (along ``direction``, its tip short of ``position``) and its label, under ``node``."""
    p, d = np.asarray(position, float), np.asarray(direction, float)
    back, front = TARGET_ARROW_M
    scene_api.add_arrows(node + "/direction", np.array([[p - back * d, p - front * d]]), TARGET_RGB,
                         shaft_radius=0.003, head_radius=0.008, head_length=0.02)
    scene_api.add_label(node + "/label", name, position=p + np.array([0.0, 0.0, TARGET_LABEL_HEIGHT_M]))


def camera_to(target: Any, position: np.ndarray, look_at: np.ndarray) -> None:
    """Point a viser camera (``server.initial_camera``, a client's ``camera``) from ``position`` at ``look_at``,
    z up, with the viewer's field of view."""
    target.fov = np.radians(CAMERA_FOV_DEG)
    target.up = (0.0, 0.0, 1.0)
    target.position = position
    target.look_at = look_at


def _camera_to(target: Any, data: ViewerScene) -> None:
    camera_to(target, *data.camera())


@contextlib.contextmanager
def _quiet_server(port: int = 0) -> Iterator[viser.ViserServer]:
    """A viser server on the loopback interface (a free port by default) that prints nothing; stopped after. It is
    behind a guard whose token nobody is told (:mod:`.server_guard`): while a page is recorded, no browser gets in."""
    from .server_guard import ServerGuard, guarded_server

    server = guarded_server(ServerGuard(), "127.0.0.1", port)
    try:
        yield server
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()


def html_page(data: ViewerScene) -> str:
    """A standalone HTML page (str) playing ``data``: viser's client with the recorded scene inside, for a browser
    that opens it from disk -- no server, no network. Play/pause and the time slider are at the bottom; the scene
    tree (bottom right) toggles the layers (the reachability map starts hidden)."""
    with _quiet_server() as server:
        _camera_to(server.initial_camera, data)
        recording = server.get_scene_serializer()
        nodes = SceneNodes(server.scene, data)
        for k in range(1, data.n_frames):
            recording.insert_sleep(float(data.times[k] - data.times[k - 1]))
            nodes.show_frame(k)
        recording.insert_sleep(1.0)  # hold the last frame a moment before the player loops
        page = recording.as_html()
    return page.replace("<title>Viser</title>", f"<title>snakehead: {_escape(data.title)}</title>", 1)


def _escape(text: str) -> str:
    """``text`` as HTML shows it literally (``<script>`` is text, not an element)."""
    import html

    return html.escape(text, quote=True)


def _node_name(name: str) -> str:
    """A name as one level of viser's scene tree, whose paths are split at "/": each "/" shown as U+2215."""
    return str(name).replace("/", "\u2215")


def write_html(data: ViewerScene, path: str | Path) -> Path:
    """Write :func:`html_page` of ``data`` to ``path`` (atomically); returns the path."""
    return write_text_atomic(path, html_page(data))


# ----------------------------------------------------------------------------------------------
# snakehead view DIR
# ----------------------------------------------------------------------------------------------
class Viewer:
    """A live viser server over viewer scenes (``snakehead view``): the GUI picks the scenario, plays and pauses,
    scrubs time, sets the speed and toggles the layers (one scene, shared by every browser). Served at :attr:`url`
    behind :mod:`.server_guard` (Host, Origin, the token in the URL; ``allow_hosts``: names besides this
    machine's). What a browser sends is checked: a scenario or a speed not offered, a time that is not one of the
    motion are set back, and playback goes on. :meth:`close` stops it."""

    SPEEDS = ("0.5x", "1x", "2x", "4x", "8x", "16x")

    def __init__(self, scenes: Sequence[ViewerScene], *, host: str = "127.0.0.1", port: int = 8080,
                 allow_hosts: Sequence[str] = ()) -> None:
        from .server_guard import ServerGuard, guarded_server

        if not scenes:
            raise InputError("no viewer scenes to show")
        self.scenes = {s.name: s for s in scenes}
        self.guard = ServerGuard(allow_hosts)
        self._host = host
        self.server = guarded_server(self.guard, host, port)
        self.lock = threading.RLock()  # re-entered: a value set here calls its callback on this thread
        gui = self.server.gui
        gui.configure_theme(control_width="medium")
        self.scenario = gui.add_dropdown("scenario", tuple(self.scenes), initial_value=scenes[0].name)
        self.playing = gui.add_checkbox("play", initial_value=True)
        self.time = gui.add_slider("time (s)", min=0.0, max=1.0, step=0.1, initial_value=0.0)
        self.speed = gui.add_dropdown("speed", self.SPEEDS, initial_value="4x")
        self.layers = {name: gui.add_checkbox(name, initial_value=name != "reachability map")
                       for name in SceneNodes.LAYERS}
        self.nodes: SceneNodes | None = None
        self._stop = threading.Event()
        self._t, self._factor, self._shown = 0.0, 4.0, scenes[0].name  # the checked time, speed and scenario
        self.player_errors = 0  # what the player's loop survived (it logs the first)
        self._load(scenes[0].name)
        self.scenario.on_update(lambda _: self._load(self.scenario.value))
        self.time.on_update(lambda event: self._seek(self.time.value, event.client is not None))
        self.speed.on_update(lambda _: self._speed_changed())
        for layer in self.layers.values():
            layer.on_update(lambda _: self._apply_layers())
        self._thread = threading.Thread(target=self._play, name="snakehead-viewer", daemon=True)
        self._thread.start()

    @property
    def port(self) -> int:
        return int(self.server.get_port())

    @property
    def url(self) -> str:
        """The page's address with this session's token (what ``snakehead view`` prints)."""
        return self.guard.url(self._host, self.port)

    def _load(self, name: str) -> None:
        with self.lock:
            if name not in self.scenes:  # not a scenario offered: the menu set back
                self.scenario.value = self._shown  # type: ignore[misc]  # (viser: assignable, typed read-only)
                return
            self._shown, self._t = name, 0.0
            data = self.scenes[name]
            self.server.scene.reset()
            self.nodes = SceneNodes(self.server.scene, data)
            _camera_to(self.server.initial_camera, data)
            for client in self.server.get_clients().values():
                _camera_to(client.camera, data)
            duration = float(data.times[-1] - data.times[0])
            step = float(max(0.01, np.round(duration / 1000, 2)))
            self.time.max = max(round(duration, 2), step)
            self.time.step = step
            self.time.value = 0.0  # type: ignore[misc]  # viser's handles are assignable (typed read-only)
            if data.n_frames == 1 and len(data.voxel_centers):  # a still scene (a reach map) is there for its map
                self.layers["reachability map"].value = True  # type: ignore[misc]  # (as above)
            self._apply_layers()

    def _frame_at(self, t_rel: float) -> int:
        assert self.nodes is not None
        times = self.nodes.data.times
        return int(np.searchsorted(times - times[0], t_rel + 1e-9, side="right") - 1)

    def _seek(self, t_rel: float, by_client: bool = True) -> None:
        """Show the frame at ``t_rel`` s; a browser's time that is not a number of the motion (NaN, inf, before 0,
        after the end) is refused and the slider set back."""
        with self.lock:
            if self.nodes is None:
                return
            if not (isinstance(t_rel, (int, float)) and np.isfinite(t_rel) and 0.0 <= t_rel <= self.time.max):
                self.time.value = self._t  # type: ignore[misc]  # (viser: assignable, typed read-only)
                return
            if by_client:
                self._t = float(t_rel)
            self.nodes.show_frame(self._frame_at(float(t_rel)))

    def _speed_changed(self) -> None:
        """A speed of :attr:`SPEEDS` is taken; anything else is refused and the menu set back."""
        if self.speed.value in self.SPEEDS:
            self._factor = float(self.speed.value.rstrip("x"))
        else:
            self.speed.value = f"{self._factor:g}x"  # type: ignore[misc]  # (viser: assignable, typed read-only)

    def _apply_layers(self) -> None:
        if self.nodes is None:
            return
        self.nodes.robot.visible = self.layers["robot"].value
        if self.nodes.voxels is not None:
            self.nodes.voxels.visible = self.layers["reachability map"].value
        for layer, group in self.nodes.groups.items():
            group.visible = self.layers[layer].value

    def _play(self, tick_s: float = 0.05) -> None:
        """Step the time along until :meth:`close`, from the checked time and speed only; a step that fails is
        logged (the first time) and counted in ``player_errors``, and the next step comes."""
        import logging

        last = time.perf_counter()
        while not self._stop.wait(tick_s):
            now = time.perf_counter()
            dt, last = now - last, now
            try:
                if not self.playing.value or self.nodes is None:
                    continue
                t_next = self._t + self._factor * dt
                self._t = t_next if 0.0 <= t_next <= self.time.max else 0.0
                self.time.value = self._t  # type: ignore[misc]  # (viser: assignable, typed read-only); moves the scene
            except Exception:  # noqa: BLE001 -- the player outlives any one step
                self.player_errors += 1
                if self.player_errors == 1:
                    logging.getLogger("snakehead.viz.server").exception("the viewer's player failed a step")

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.server.stop()


def serve(directory: str | Path | None, *, host: str = "127.0.0.1", port: int = 8080,
          extra: Sequence[ViewerScene] = (), allow_hosts: Sequence[str] = ()) -> Viewer:
    """Serve the viewer scenes of ``directory`` (the output of ``snakehead plan`` or ``demo``; None: none) and
    ``extra`` scenes (e.g. :func:`reach_scene`'s) at http://HOST:PORT (the next free port if PORT is taken; the
    page at the returned viewer's ``url``, with its token); returns the running :class:`Viewer`."""
    paths = scenes_in(directory) if directory is not None else []
    if not paths and not extra:
        raise InputError(f"{directory} holds no viewer scenes (*{SCENE_SUFFIX}); 'snakehead plan' and "
                         "'snakehead demo' write them")
    return Viewer([load_viewer_scene(p) for p in paths] + list(extra), host=host, port=port, allow_hosts=allow_hosts)
