"""The geometry the figures, the animation and the 3-D viewer draw: the faces of every collision shape
(:func:`body_faces`: boxes, cylinders, spheres, mesh hulls from :func:`snakehead.geometry.shapes.shape_mesh`,
coplanar triangles merged into one polygon, so that a box is drawn as its six faces), the shapes seen from above
(:func:`shape_footprints`), the obstacles' faces (:func:`box_faces`, :func:`mesh_obstacle_faces`, :func:`wall_faces`
for a wall with a hole, :func:`hole_rim`), the spheres at a plan's targets, the points along the body's axis, a box
around a plan's scene and the angle it is seen from, and the parts' colours (:func:`part_colors`: base grey, neck
orange, head blue); poses of a plan's ground frame in the world (:func:`world_frames`) and a scene's terrain as
triangles (:func:`terrain_mesh`).

Positions in m. A plan holds its body, targets and obstacles in its ground frame (``plan.base.ground``: the world
frame on flat ground, z up and the ground at z = 0); the figures draw them in the world, where a slope is tilted.
"""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Sequence

import numpy as np
import numpy.typing as npt
from scipy.spatial import ConvexHull

from ..geometry.obstacles import BoxObstacle, MeshObstacle, WallWithHole
from ..geometry.shapes import shape_mesh
from ..model.placement import GroundFrame
from ..model.robot import SnakeRobot
from ..terrain.surfaces import HeightfieldTerrain, MeshTerrain, StepsTerrain
from .figure_style import BASE_COLOR, HEAD_COLOR, NECK_COLOR

if TYPE_CHECKING:
    from ..planning.plan_result import Plan

__all__ = ["FIGURE_SEGMENTS", "Sphere", "part_colors", "convex_facets", "BodyDrawing", "body_drawing", "body_faces",
           "shape_footprints", "mesh_obstacle_faces", "box_faces", "wall_faces", "hole_rim", "plan_spheres",
           "scene_bounds", "view_angles", "body_points", "TERRAIN_DRAW_SIDE", "world_frames", "terrain_mesh"]

#: Segments around a cylinder's or a sphere's axis in the figures.
FIGURE_SEGMENTS = 16
#: A sphere drawn at a target: (centre (3,) m, diameter m).
Sphere = tuple[npt.ArrayLike, float]


def part_colors(robot: SnakeRobot) -> list[str]:
    """A colour per frame of ``robot.link_names``: base grey, neck orange, head blue."""
    names = robot.link_names
    base_end = names.index(robot.parts.base_end)
    neck_end = names.index(robot.parts.neck_end)
    return [BASE_COLOR if i <= base_end else NECK_COLOR if i <= neck_end else HEAD_COLOR for i in range(len(names))]


def convex_facets(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """The faces of a convex triangle mesh as polygons: each plane's triangles merged into one polygon, its corners
    (indices into ``vertices``) in order around it, points inside it or on its edges left out (a box's 12 triangles
    are its 6 faces; a cylinder's caps are two polygons)."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    scale = max(float(np.ptp(v, axis=0).max()) if len(v) else 0.0, 1e-12)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    norm = np.linalg.norm(n, axis=1)
    good = norm > 1e-12 * scale * scale
    f, n, a = f[good], n[good] / norm[good, None], a[good]
    n *= np.where(np.einsum("ij,ij->i", n, a - v.mean(axis=0)) < 0, -1.0, 1.0)[:, None]  # outward, whatever the winding
    d = np.einsum("ij,ij->i", n, a)
    planes: list[tuple[np.ndarray, float, list[int]]] = []
    for i in range(len(f)):
        for pn, pd, members in planes:
            if np.abs(pn - n[i]).max() < 1e-6 and abs(pd - d[i]) < 1e-6 * scale:
                members.append(i)
                break
        else:
            planes.append((n[i], float(d[i]), [i]))
    out = []
    for pn, _, members in planes:
        idx = np.unique(f[members])
        u = np.cross(pn, [1.0, 0.0, 0.0] if abs(pn[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        w = np.cross(pn, u)
        out.append(idx[_hull_2d(np.column_stack([v[idx] @ u, v[idx] @ w]), 1e-9 * scale)])
    return out


def _hull_2d(p: np.ndarray, tol: float) -> np.ndarray:
    """Indices of the corners of the convex hull of 2-D points (k, 2), in order around it (monotone chain)."""
    order = np.lexsort((p[:, 1], p[:, 0]))

    def half(seq: np.ndarray) -> list[int]:
        chain: list[int] = []
        for i in seq:
            while len(chain) >= 2:
                o, a = p[chain[-2]], p[chain[-1]]
                if (a[0] - o[0]) * (p[i][1] - o[1]) - (a[1] - o[1]) * (p[i][0] - o[0]) > tol * tol:
                    break
                chain.pop()
            chain.append(int(i))
        return chain

    lower, upper = half(order), half(order[::-1])
    return np.array(lower[:-1] + upper[:-1] if len(order) > 2 else list(order), dtype=np.int64)


class BodyDrawing:
    """The polygons of every collision shape of a robot in its link frames (made once per robot: see
    :func:`body_drawing`): ``vertices`` (V, 3), the frame of each (``vertex_frame`` (V,)), ``polygons`` (index
    arrays into the vertices), the shape of each polygon (``polygon_shape``), each shape's vertices
    (``shape_vertices``) and frame (``shape_frames``)."""

    def __init__(self, robot: SnakeRobot, segments: int) -> None:
        geometry = robot.geometry
        verts, frames, polys, owner, shape_vertices = [], [], [], [], []
        start = 0
        for k, shape in enumerate(geometry.shapes):
            v, f = shape_mesh(shape, segments, hull=geometry, index=k)
            for poly in convex_facets(v, f):
                polys.append(poly + start)
                owner.append(k)
            verts.append(v)
            frames.append(np.full(len(v), shape.frame))
            shape_vertices.append(np.arange(start, start + len(v)))
            start += len(v)
        self.vertices = np.concatenate(verts) if verts else np.zeros((0, 3))
        self.vertex_frame = np.concatenate(frames) if frames else np.zeros(0, np.int64)
        self.polygons = polys
        self.polygon_shape = np.array(owner, dtype=np.int64)
        self.shape_vertices = shape_vertices
        self.shape_frames = np.array([s.frame for s in geometry.shapes], dtype=np.int64)

    def world(self, frames: np.ndarray) -> np.ndarray:
        """The vertices (V, 3) m in the world, given the link frames ``frames`` (L, 4, 4)."""
        F = frames[self.vertex_frame]
        return np.einsum("vij,vj->vi", F[:, :3, :3], self.vertices) + F[:, :3, 3]


_DRAWINGS: "weakref.WeakKeyDictionary[SnakeRobot, dict[int, BodyDrawing]]" = weakref.WeakKeyDictionary()


def body_drawing(robot: SnakeRobot, segments: int = FIGURE_SEGMENTS) -> BodyDrawing:
    """The robot's :class:`BodyDrawing` with ``segments`` around round shapes, made once per robot."""
    per_robot = _DRAWINGS.setdefault(robot, {})
    if segments not in per_robot:
        per_robot[segments] = BodyDrawing(robot, segments)
    return per_robot[segments]


def body_faces(robot: SnakeRobot, frames: npt.ArrayLike) -> tuple[list[np.ndarray], list[str]]:
    """The faces of every collision shape (boxes, cylinders, spheres, mesh hulls): a list of polygons, each (k, 3)
    world corners (m), and one colour per polygon (its link's part). A box gives its 6 faces, a cylinder its
    :data:`FIGURE_SEGMENTS` sides and two caps.

    frames (L, 4, 4): world poses of ``robot.link_names`` (``robot.frames``); frames without shapes draw nothing.
    """
    frames = np.asarray(frames, float)
    drawing = body_drawing(robot)
    W = drawing.world(frames)
    colors = part_colors(robot)
    shape_color = [colors[int(f)] for f in drawing.shape_frames]
    return [W[p] for p in drawing.polygons], [shape_color[int(k)] for k in drawing.polygon_shape]


def shape_footprints(robot: SnakeRobot, frames: npt.ArrayLike, links: npt.ArrayLike | None = None) -> list[np.ndarray]:
    """Each collision shape of ``links`` (default all) seen from above: its outline (k, 2) m in the ground plane,
    in order around it, at ``frames`` (L, 4, 4)."""
    frames = np.asarray(frames, float)
    drawing = body_drawing(robot)
    W = drawing.world(frames)
    keep = np.arange(len(drawing.shape_frames)) if links is None else \
        np.flatnonzero(np.isin(drawing.shape_frames, np.asarray(links)))
    out = []
    for k in keep:
        xy = W[drawing.shape_vertices[int(k)], :2]
        scale = max(float(np.ptp(xy, axis=0).max()), 1e-12)
        out.append(xy[_hull_2d(xy, 1e-9 * scale)])
    return out


_BOX_CORNERS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
_BOX_QUADS = np.array([[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]])


def mesh_obstacle_faces(mesh: MeshObstacle) -> list[np.ndarray]:
    """A mesh obstacle's hull as its faces: a list of polygons (k, 3) of world corners (m)."""
    v = mesh.world_vertices
    return [v[p] for p in convex_facets(v, ConvexHull(v).simplices)]


def box_faces(box: BoxObstacle) -> np.ndarray:
    """A box obstacle's six faces: (6, 4, 3) world corners (m)."""
    corners = box.centre + (_BOX_CORNERS * np.asarray(box.size, float)) @ np.asarray(box.rotation, float).T
    return corners[_BOX_QUADS]


def wall_faces(wall: WallWithHole, n: int = 64) -> np.ndarray:
    """The wall's mid-plane as quads tiling the rectangle minus the hole: (K, 4, 3) world corners (m).

    Each quad joins two neighbouring points of the hole's rim to the points where the same rays from the hole's
    centre leave the rectangle; the rays include the rectangle's corners, so the tiling is exact up to the rim's
    ``n``-gon.
    """
    R = wall.rotation
    half = wall.size[:2] / 2
    off = wall.hole_offset
    r = wall.hole_diameter / 2
    corners = np.array([[sx, sy] for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]) * half + off
    angles = np.sort(np.r_[np.linspace(0, 2 * np.pi, n, endpoint=False),
                           np.arctan2(corners[:, 1], corners[:, 0]) % (2 * np.pi)])
    d = np.column_stack([np.cos(angles), np.sin(angles)])
    # distance along each ray to the rectangle [off - half, off + half] (the hole's centre is inside it)
    with np.errstate(divide="ignore"):
        tx = np.where(d[:, 0] > 0, (off[0] + half[0]) / d[:, 0],
                      np.where(d[:, 0] < 0, (off[0] - half[0]) / d[:, 0], np.inf))
        ty = np.where(d[:, 1] > 0, (off[1] + half[1]) / d[:, 1],
                      np.where(d[:, 1] < 0, (off[1] - half[1]) / d[:, 1], np.inf))
    outer = d * np.minimum(tx, ty)[:, None]
    inner = d * r
    nxt = np.roll(np.arange(len(angles)), -1)
    quads = np.stack([inner, inner[nxt], outer[nxt], outer], axis=1)  # (K, 4, 2) in (width, height)
    return wall.centre + quads @ R[:, :2].T


def hole_rim(wall: WallWithHole, n: int = 65) -> np.ndarray:
    """The hole's rim: (n, 3) world points (m), closed (the last equals the first)."""
    th = np.linspace(0, 2 * np.pi, n)
    return wall.centre + (wall.hole_diameter / 2) * (np.outer(np.cos(th), wall.rotation[:, 0])
                                                     + np.outer(np.sin(th), wall.rotation[:, 1]))


def plan_spheres(plan: Plan) -> list[Sphere]:
    """The spheres a plan's scene draws at its targets (targets with a ``sphere_diameter``)."""
    scene = getattr(plan, "scene", None)
    if scene is None:
        return []
    return [(t.position, float(t.sphere_diameter)) for t in scene.targets if t.sphere_diameter is not None]


def scene_bounds(plan: Plan, spheres: Sequence[Sphere] = (), margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (3,) m of a box holding the body over the whole motion, the scenery (``spheres`` in
    the plan's ground frame, as its targets) and the ground's origin, in the world (on a slope: the ground frame's
    points turned into the world)."""
    step = max(1, len(plan.q) // 200)
    pts = plan.robot.frames_many(plan.q[::step], plan.base)[..., :3, 3].reshape(-1, 3)
    extra = [pts, np.zeros((1, 3))]
    extra += [np.asarray(c, float)[None] for c, _ in spheres]
    extra += [tg.position[None] for tg in plan.targets]
    for ob in plan.obstacles:
        if isinstance(ob, WallWithHole):
            R = ob.rotation
            half = ob.size[:2] / 2
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half + ob.hole_offset
            extra.append(ob.centre + corners @ R[:, :2].T)
        elif isinstance(ob, BoxObstacle):
            extra.append(box_faces(ob).reshape(-1, 3))
        elif isinstance(ob, MeshObstacle):
            extra.append(ob.world_vertices)
    allp = np.vstack(extra)
    ground = plan.base.ground
    if not ground.is_world:
        allp = ground.to_world(allp)
    return allp.min(axis=0) - margin, allp.max(axis=0) + margin


def view_angles(plan: Plan) -> tuple[float, float]:
    """(elevation, azimuth) in degrees: from behind and to the side of the head's approach."""
    return (18.0, -58.0) if plan.obstacles else (22.0, -62.0)


def body_points(robot: SnakeRobot, frames: np.ndarray) -> np.ndarray:
    """Points along the body's axis, tail end to head tip: the root frame, every joint, the head tip.

    frames (..., L, 4, 4) (``robot.frames`` / ``frames_many``) -> (..., n + 2, 3) m.
    """
    idx = np.r_[0, robot.joint_frames, robot.link_index(robot.parts.head_tip)]
    return np.take(frames, idx, axis=-3)[..., :3, 3]


#: Heights per side at most of a heightfield as the figures and the viewer draw it (a finer grid is drawn at every
#: k-th height, its last row and column kept).
TERRAIN_DRAW_SIDE = 129


def world_frames(ground: GroundFrame, frames: np.ndarray) -> np.ndarray:
    """Poses (..., 4, 4) of the ground frame ``ground`` (a plan's ``base.ground``) in the world: the same array on flat
    ground (the world frame), ``ground.matrix @ frames`` on a slope."""
    return frames if ground.is_world else ground.matrix @ np.asarray(frames, float)


def _every(n: int, most: int) -> np.ndarray:
    """Indices 0 .. n - 1 at a stride that keeps at most ``most`` of them, the last one included."""
    step = max(1, -(-(n - 1) // max(most - 1, 1)))
    return np.unique(np.r_[np.arange(0, n, step), n - 1])


def terrain_mesh(terrain: object, side: int = TERRAIN_DRAW_SIDE) -> tuple[np.ndarray, np.ndarray]:
    """A scene's terrain as triangles to draw: vertices (V, 3) m in the world and triangles (T, 3) (vertex indices).
    A heightfield's grid (at most ``side`` heights per side: :data:`TERRAIN_DRAW_SIDE`), split along the diagonals
    the terrain's queries use; a mesh's triangles; a staircase's treads and risers. None (V = T = 0) for flat
    ground and a plane, which the figures and the viewer draw as the ground of the plan's ground frame."""
    if isinstance(terrain, HeightfieldTerrain):
        h = np.asarray(terrain.heights, float)
        nx, ny = h.shape
        i, j = _every(nx, side), _every(ny, side)
        x0, y0, z0 = np.asarray(terrain.origin, float)
        sx, sy = np.asarray(terrain.extent, float)
        X, Y = np.meshgrid(x0 + i * sx / (nx - 1), y0 + j * sy / (ny - 1), indexing="ij")
        vertices = np.column_stack([X.ravel(), Y.ravel(), (z0 + h[np.ix_(i, j)]).ravel()])
        m = len(j)
        a = (np.arange(len(i) - 1)[:, None] * m + np.arange(m - 1)[None, :]).ravel()  # corner (i, j) of each cell
        triangles = np.concatenate([np.column_stack([a, a + m, a + m + 1]), np.column_stack([a, a + m + 1, a + 1])])
        return vertices, triangles.astype(np.int64)
    if isinstance(terrain, MeshTerrain):
        return np.asarray(terrain.vertices, float), np.asarray(terrain.faces, np.int64)
    if isinstance(terrain, StepsTerrain):
        vertices, triangles = terrain.triangles()
        return np.asarray(vertices, float), np.asarray(triangles, np.int64)
    return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
