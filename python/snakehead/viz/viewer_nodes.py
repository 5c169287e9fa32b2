"""A :class:`~.viewer_arrays.ViewerScene` in a viser scene: the nodes that draw it (:class:`SceneNodes`, the robot's
shapes as :class:`RobotNodes`) and the pieces the live viewer shares (the ground frame's node, the ground grid, a
terrain, obstacles, target markers, lighting, the camera).

A plan on a slope is drawn in its ground frame: every node of it sits under one parent node (the viewer's root)
that holds the ground frame's world pose (:func:`add_ground_frame`), so the body, the targets, the obstacles, the
ZMP and the support polygons, and the ground grid itself, are turned into the world by that one transform. On flat
ground there is no such node (the ground frame is the world's) and the scene is the one drawn before slopes.

Colours are RGB 0-255, as viser takes them; the robot's parts take theirs from :func:`.body.part_colors`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from .reachability_figures import index_colors
from .viewer_arrays import CAMERA_FOV_DEG, MESH_FIELDS, OBSTACLE_FIELDS, ViewerScene, quaternions_wxyz

if TYPE_CHECKING:
    import viser

__all__ = ["ZMP_RGB", "COM_RGB", "POLYGON_RGB", "TARGET_RGB", "WALL_RGB", "OBSTACLE_RGB", "TIP_PATH_RGB",
           "TARGET_ARROW_M", "TARGET_LABEL_HEIGHT_M", "CUBE_VERTICES", "CUBE_TRIANGLES", "TERRAIN_RGB", "SceneNodes",
           "RobotNodes", "light_scene", "add_ground_frame", "add_ground", "add_terrain", "add_obstacles",
           "add_target_marker", "camera_to", "node_name", "terrain_node"]

#: Colours (RGB 0-255) of what the viewer draws besides the robot (its parts: viz.body.part_colors).
ZMP_RGB = (192, 57, 43)
COM_RGB = (20, 20, 20)
POLYGON_RGB = (30, 30, 30)
TARGET_RGB = (192, 57, 43)
WALL_RGB = (161, 136, 127)
OBSTACLE_RGB = (141, 110, 99)
TIP_PATH_RGB = (90, 90, 90)
TERRAIN_RGB = (188, 170, 164)
#: m: a target's arrow runs along its direction from this far behind the target to this far short of it.
TARGET_ARROW_M = (0.09, 0.01)
#: m: a target's label is this high above it.
TARGET_LABEL_HEIGHT_M = 0.04
#: The unit cube (edge 1, centred on the origin) the map's voxels are drawn as: its 8 vertices (8, 3) ...
CUBE_VERTICES = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)], np.float32)
#: ... and its 12 triangles (12, 3) as vertex indices.
CUBE_TRIANGLES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                           [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.uint32)


class SceneNodes:
    """The nodes of one :class:`ViewerScene` in a viser scene, under ``root`` (on a slope a node at the ground frame's
    world pose: :func:`add_ground_frame`; a terrain beside it, in the world); :meth:`show_frame` moves them."""

    LAYERS = ("robot", "reachability map", "ZMP and support polygon", "targets", "obstacles", "head tip path")

    def __init__(self, scene_api: viser.SceneApi, data: ViewerScene, root: str = "/snakehead") -> None:
        self.data = data
        self.root = root
        self.frame = -1
        s = scene_api
        light_scene(s)
        self.ground_frame = add_ground_frame(s, root, data.ground_pose)  # first: the parent of all that follows
        self.terrain = add_terrain(s, terrain_node(root), data.terrain_vertices, data.terrain_triangles)
        # one parent node per layer, so that a layer shows or hides as one (viser's visibility is inherited)
        self.groups = {layer: s.add_frame(f"{root}/{layer}", show_axes=False)
                       for layer in ("ZMP and support polygon", "targets", "obstacles", "head tip path")}
        self.ground = add_ground(s, f"{root}/ground", *data.ground_bounds(margin=0.2))
        self.robot_nodes = RobotNodes(s, f"{root}/robot", {k: getattr(data, k) for k in MESH_FIELDS},
                                      data.shape_colors, data.shape_positions[0], data.shape_wxyz[0])
        self.robot = self.robot_nodes.frame
        self.map_frame = s.add_frame(f"{root}/head base frame", show_axes=True, axes_length=0.05, axes_radius=0.002,
                                     position=data.map_frame_positions[0], wxyz=data.map_frame_wxyz[0])
        self.voxels = self._add_voxels(s) if len(data.voxel_centers) else None
        self._add_support_and_zmp(s)
        tip = data.head_tip
        if len(tip) > 1:
            s.add_line_segments(f"{root}/head tip path/path", np.stack([tip[:-1], tip[1:]], axis=1), TIP_PATH_RGB,
                                thickness=0.002)
        self._add_targets(s)
        add_obstacles(s, f"{root}/obstacles", **{k: getattr(data, k) for k in OBSTACLE_FIELDS})
        self.show_frame(0)

    def _add_voxels(self, s: viser.SceneApi) -> Any:
        """The head's map in the head's base frame: a cube per voxel coloured by its index (shown at once only in
        a still scene)."""
        data = self.data
        rgb = np.round(255 * index_colors(data.voxel_indices)).astype(np.uint8)
        n = len(data.voxel_centers)
        return s.add_batched_meshes_simple(
            f"{self.root}/head base frame/reachability map", CUBE_VERTICES, CUBE_TRIANGLES,
            batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)), batched_positions=data.voxel_centers,
            batched_scales=np.full(n, 0.8 * data.voxel_size), batched_colors=rgb, opacity=0.35, lod="off",
            cast_shadow=False, receive_shadow=False, visible=data.n_frames == 1)

    def _add_support_and_zmp(self, s: viser.SceneApi) -> None:
        """The support polygons (the first frame's shown), the planned ZMP's path, the ZMP and the centre of mass's
        ground projection."""
        data, group = self.data, f"{self.root}/ZMP and support polygon"
        self.polygons = []
        for i, poly in enumerate(data.polygons):
            p = poly[np.all(np.isfinite(poly), axis=1)]
            p3 = np.column_stack([p, np.full(len(p), 0.001)])
            segs = np.stack([p3, np.roll(p3, -1, axis=0)], axis=1)
            self.polygons.append(s.add_line_segments(f"{group}/support polygon {i}", segs, POLYGON_RGB,
                                                     thickness=0.004, visible=bool(data.polygon_of_frame[0] == i)))
        z3 = np.column_stack([data.zmp_path, np.full(len(data.zmp_path), 0.0015)])
        if len(z3) > 1:
            s.add_line_segments(f"{group}/ZMP path", np.stack([z3[:-1], z3[1:]], axis=1), ZMP_RGB, thickness=0.002)
        self.zmp = s.add_icosphere(f"{group}/ZMP", radius=0.008, color=ZMP_RGB, position=(*data.zmp[0], 0.0),
                                   cast_shadow=False)
        self.com_marks = data.com_marks()  # below the CoM along gravity (on flat ground: its x, y)
        self.com = s.add_icosphere(f"{group}/CoM ground projection", radius=0.006, color=COM_RGB,
                                   position=(*self.com_marks[0], 0.0), cast_shadow=False)

    def _add_targets(self, s: viser.SceneApi) -> None:
        """Each target: its arrow and label, and its sphere when it has a diameter."""
        data = self.data
        for i, (p, d, name, dia) in enumerate(zip(data.target_positions, data.target_directions, data.target_names,
                                                  data.target_diameters)):
            node = f"{self.root}/targets/{i + 1} {node_name(name)}"
            if np.isfinite(dia):
                s.add_icosphere(node + "/sphere", radius=float(dia) / 2, color=TARGET_RGB, opacity=0.6,
                                position=p, cast_shadow=False)
            add_target_marker(s, node, str(name), p, d)

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
        self.com.position = (self.com_marks[k, 0], self.com_marks[k, 1], 0.0)
        if before < 0 or d.polygon_of_frame[before] != d.polygon_of_frame[k]:
            for i, node in enumerate(self.polygons):
                node.visible = bool(d.polygon_of_frame[k] == i)


class RobotNodes:
    """The robot's collision shapes in a viser scene under the frame ``name``: one batch of instances per mesh
    (every box one unit cube scaled, ...), all moved at once by :meth:`move`. ``meshes``: the
    :data:`~.viewer_arrays.MESH_FIELDS` of :func:`~.viewer_arrays.robot_meshes`; ``colors`` (K, 3) RGB 0-255;
    ``positions`` (K, 3) and ``wxyz`` (K, 4): the first pose."""

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


def add_ground_frame(scene_api: viser.SceneApi, name: str, pose: npt.ArrayLike) -> Any:
    """The node ``name`` at the ground frame's world pose ``pose`` (4, 4): added before anything under it, it is the
    parent of everything drawn in the ground frame (one transform at one place). None on flat ground (``pose`` the
    identity): no node, so that a flat scene is drawn as before slopes."""
    G = np.asarray(pose, float)
    if np.array_equal(G, np.eye(4)):
        return None
    return scene_api.add_frame(name, show_axes=False, position=G[:3, 3], wxyz=quaternions_wxyz(G[None, :3, :3])[0])


def terrain_node(root: str) -> str:
    """Where a terrain is drawn beside the viewer's ``root``: in the world, not under the ground frame's node."""
    return f"{root} terrain"


def add_terrain(scene_api: viser.SceneApi, name: str, vertices: np.ndarray, triangles: np.ndarray) -> Any:
    """A terrain's triangles (:func:`.figure_geometry.terrain_mesh`, world) as one mesh, both sides shaded; None
    without triangles."""
    if not len(triangles):
        return None
    return scene_api.add_mesh_simple(name, np.asarray(vertices, np.float32), np.asarray(triangles, np.uint32),
                                     color=TERRAIN_RGB, side="double", flat_shading=True, cast_shadow=False)


def add_ground(scene_api: viser.SceneApi, name: str, lo: np.ndarray, hi: np.ndarray) -> Any:
    """A ground grid (z = 0 of the frame ``name``'s parent: the world, or the ground frame's node on a slope, where it
    lies in the slope) under the box [lo, hi] (3,) m of that frame: 0.1 m cells, 0.5 m sections."""
    size = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    centre = 0.5 * (lo + hi)
    return scene_api.add_grid(name, width=size, height=size, plane="xy", cell_size=0.1, section_size=0.5,
                              position=(centre[0], centre[1], 0.0))


def add_obstacles(scene_api: viser.SceneApi, root: str, *, obstacle_centres: np.ndarray, obstacle_sizes: np.ndarray,
                  obstacle_wxyz: np.ndarray, wall_vertices: np.ndarray, wall_triangles: np.ndarray,
                  hole_rims: np.ndarray) -> None:
    """The obstacles (:func:`~.viewer_arrays.obstacle_arrays`) under ``root``: boxes, walls and mesh hulls, the holes' rims."""
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


def node_name(name: str) -> str:
    """A name as one level of viser's scene tree, whose paths are split at "/": each "/" shown as U+2215."""
    return str(name).replace("/", "\u2215")
