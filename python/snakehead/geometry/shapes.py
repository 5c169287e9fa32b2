"""Convex collision shapes on frames: the one geometry layer of the robot and the scene.

A :class:`Shape` is a box, cylinder, sphere or convex mesh (a mesh is used as its convex hull) whose own frame
sits at ``origin`` in the frame it is attached to: a link of the robot (``frame`` = its index in
``robot.link_names``) or the world (a scene's obstacle, ``frame`` = 0 of a single identity frame).
:class:`ShapeSet` holds shapes with the C++ core's :class:`snakehead._core.ShapeSet` (distances on Debian's FCL,
lowest points in closed form, many samples per call without the GIL) and answers per frame:

* :meth:`ShapeSet.lowest_z` -- the lowest world z of each frame's shapes (ground clearance);
* :meth:`ShapeSet.lowest_points` -- the lowest candidate points of each shape (box corners, cylinder rims,
  sphere bottoms, hull vertices): the ground contact points of support polygons;
* :func:`pair_distances`, :func:`pair_min_distances` -- signed distances of shape pairs (self-collision,
  obstacles);
* :func:`shape_mesh` -- a triangle mesh of any shape, for figures, the viewer and MuJoCo.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cached_property
from typing import Sequence

import numpy as np
from scipy.spatial import ConvexHull

from .. import _core
from .._errors import InputError

__all__ = ["KINDS", "CONTACT_POINTS", "DRAW_SEGMENTS", "SHAPES_OF_KEPT", "Shape", "ShapeSet", "pair_distances",
           "pair_min_distances", "shape_mesh", "shape_points"]

KINDS = ("box", "cylinder", "sphere", "convex")

#: How many lowest candidate points of a shape of each kind count as its possible ground contacts: a box rests on a
#: face of 4 corners, a sphere on one point, a cylinder on its two rims' lowest points or (upright) on its rim drawn
#: as 8 points; a mesh hull on up to 10 of its vertices. A set takes the largest its shapes need.
CONTACT_POINTS = {"box": 4, "sphere": 1, "cylinder": 10, "convex": 10}

#: Segments of a cylinder's or sphere's drawn mesh around its axis.
DRAW_SEGMENTS = 24
#: Frame lists whose shapes a ShapeSet remembers (:meth:`ShapeSet.shapes_of`; it forgets them all when full).
SHAPES_OF_KEPT = 64


@dataclass(frozen=True, eq=False)
class Shape:
    """One convex shape: kind ("box", "cylinder", "sphere", "convex"), the frame it is attached to, its pose
    there (4, 4), size (box: extents; cylinder: (radius, length, 0), axis along its own z; sphere: (radius, 0, 0);
    convex: unused), vertices (convex: (V, 3) in its own frame, scale applied) and where it came from (a mesh
    file, for messages)."""

    kind: str
    frame: int
    origin: np.ndarray
    size: np.ndarray
    vertices: np.ndarray | None = None
    source: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"shape kind must be one of {KINDS}, got {self.kind!r}")
        origin = np.array(self.origin, float).reshape(4, 4)
        size = np.array(self.size, float).reshape(3)
        origin.setflags(write=False)
        size.setflags(write=False)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "size", size)
        if self.vertices is not None:
            v = np.array(self.vertices, float).reshape(-1, 3)
            v.setflags(write=False)
            object.__setattr__(self, "vertices", v)

    @property
    def radius(self) -> float:
        """Cylinder or sphere radius (m)."""
        return float(self.size[0])


@dataclass(frozen=True, eq=False)
class ShapeSet:
    """Shapes on ``n_frames`` frames, with the core's set built once (immutable; share it freely)."""

    shapes: tuple[Shape, ...]
    n_frames: int
    _core_set: _core.ShapeSet = field(init=False, repr=False)
    #: :meth:`shapes_of`'s answers by frame list (a plan asks for the same few lists hundreds of times)
    _shapes_on: dict = field(init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        shapes = tuple(self.shapes)
        object.__setattr__(self, "shapes", shapes)
        for s in shapes:
            if not 0 <= s.frame < self.n_frames:
                raise InputError(f"shape on frame {s.frame}, outside [0, {self.n_frames})")
        try:
            core = _core.ShapeSet([s.kind for s in shapes],
                                  np.array([s.frame for s in shapes], dtype=np.int64).reshape(-1),
                                  np.array([s.origin for s in shapes], float).reshape(-1, 4, 4),
                                  np.array([s.size for s in shapes], float).reshape(-1, 3),
                                  [s.vertices for s in shapes])
        except InputError as exc:  # the core names a shape by its index: say which shape that is
            raise InputError(_named_shape(str(exc), shapes)) from None
        object.__setattr__(self, "_core_set", core)

    @property
    def core(self) -> _core.ShapeSet:
        return self._core_set

    @cached_property
    def shape_frames(self) -> np.ndarray:
        """(S,) the frame of each shape."""
        return np.array([s.frame for s in self.shapes], dtype=np.int64).reshape(-1)

    @cached_property
    def frames_with_shapes(self) -> np.ndarray:
        """Indices of the frames that carry at least one shape, ascending."""
        return np.unique(self.shape_frames)

    def shapes_of(self, frames: Sequence[int] | np.ndarray) -> np.ndarray:
        """Indices of the shapes on the given frames, in shape order (read-only; remembered per frame list)."""
        key = np.asarray(frames, dtype=np.int64).tobytes()
        found = self._shapes_on.get(key)
        if found is None:
            found = np.flatnonzero(np.isin(self.shape_frames, np.frombuffer(key, dtype=np.int64)))
            found.flags.writeable = False
            if len(self._shapes_on) >= SHAPES_OF_KEPT:
                self._shapes_on.clear()
            self._shapes_on[key] = found
        return found

    @cached_property
    def contact_points_per_shape(self) -> int:
        """How many lowest candidate points :meth:`lowest_points` keeps per shape (:data:`CONTACT_POINTS`)."""
        return max((CONTACT_POINTS[s.kind] for s in self.shapes), default=1)

    def lowest_z(self, frames: np.ndarray, on: np.ndarray) -> np.ndarray:
        """Lowest world z (m) of the shapes on each frame of ``on``: (T, k); +inf for a frame without shapes.
        ``frames`` (T, n_frames, 4, 4) world poses."""
        on = np.asarray(on, dtype=np.int64).reshape(-1)
        idx = self.shapes_of(on)
        out = np.full((frames.shape[0], len(on)), np.inf)
        if idx.size == 0:
            return out
        z = _core.shape_lowest_z(np.ascontiguousarray(frames, float), self.core, idx)  # (T, s)
        _reduce_to_frames(z, self.shape_frames[idx], on, out)
        return out

    def lowest_points(self, frames: np.ndarray, on: np.ndarray,
                      per_shape: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The lowest candidate ground points of the shapes on the frames ``on``: points (T, N, 3) world and the
        frame (N,) each belongs to; N = shapes x ``per_shape`` (default :attr:`contact_points_per_shape`), each
        shape's sorted lowest first (``per_shape=1``: each shape's lowest point)."""
        per_shape = self.contact_points_per_shape if per_shape is None else per_shape
        idx = self.shapes_of(on)
        T = frames.shape[0]
        if idx.size == 0:
            return np.zeros((T, 0, 3)), np.zeros(0, dtype=np.int64)
        pts = _core.shape_lowest_points(np.ascontiguousarray(frames, float), self.core, idx, per_shape)
        return pts.reshape(T, -1, 3), np.repeat(self.shape_frames[idx], per_shape)


def _named_shape(message: str, shapes: tuple[Shape, ...]) -> str:
    """The core's message about "shape i" with what that shape is: its kind, frame and mesh file."""
    found = re.search(r"\bshape (\d+)\b", message)
    if found is None or int(found.group(1)) >= len(shapes):
        return message
    s = shapes[int(found.group(1))]
    source = f", mesh file {s.source!r}" if s.source else ""
    return f"{message} ({s.kind} shape on frame {s.frame}{source})"


def _reduce_to_frames(values: np.ndarray, owner_frames: np.ndarray, on: np.ndarray, out: np.ndarray) -> None:
    """out[:, c] = the smallest of the columns of ``values`` (T, s) whose shape is on frame ``on[c]``."""
    column = np.full(int(max(on.max(), owner_frames.max())) + 1, -1, dtype=np.int64)
    column[on] = np.arange(len(on))
    owner = column[owner_frames]
    if np.all(owner[1:] > owner[:-1]):  # one shape per frame, in order (the common case): no reduction
        out[:, owner] = values
        return
    order = np.argsort(owner, kind="stable")
    sorted_owner = owner[order]
    starts = np.flatnonzero(np.r_[True, sorted_owner[1:] != sorted_owner[:-1]])
    out[:, sorted_owner[starts]] = np.minimum.reduceat(values[:, order], starts, axis=1)


def pair_distances(frames_a: np.ndarray, a: ShapeSet, frames_b: np.ndarray, b: ShapeSet, pairs: np.ndarray,
                   cutoff: float = np.inf) -> np.ndarray:
    """Signed distances (T, P) of shape pairs (P, 2): shape ``pairs[p, 0]`` of ``a`` (frames_a (T, La, 4, 4)) and
    ``pairs[p, 1]`` of ``b`` (frames_b (T or 1, Lb, 4, 4)). Exact below ``cutoff``; a lower bound above it."""
    return _core.shape_pair_distances(np.ascontiguousarray(frames_a, float), a.core,
                                      np.ascontiguousarray(frames_b, float), b.core,
                                      np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2), float(cutoff))


def pair_min_distances(frames_a: np.ndarray, a: ShapeSet, frames_b: np.ndarray, b: ShapeSet, pairs: np.ndarray,
                       cutoff: float = np.inf) -> np.ndarray:
    """The smallest signed distance (T,) over the pairs of :func:`pair_distances` (+inf without pairs)."""
    return _core.shape_pair_min_distances(np.ascontiguousarray(frames_a, float), a.core,
                                          np.ascontiguousarray(frames_b, float), b.core,
                                          np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2), float(cutoff))


# ------------------------------------------------------------------------------------------------
# drawing and fitting: points and triangles of a shape in its attached frame
# ------------------------------------------------------------------------------------------------
_BOX_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)
_BOX_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def _cylinder_mesh(radius: float, length: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    a = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)
    v = np.concatenate([np.c_[ring, np.full(n, -length / 2)], np.c_[ring, np.full(n, length / 2)],
                        [[0, 0, -length / 2], [0, 0, length / 2]]])
    i = np.arange(n)
    j = (i + 1) % n
    sides = np.concatenate([np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
    caps = np.concatenate([np.stack([np.full(n, 2 * n), j, i], 1), np.stack([np.full(n, 2 * n + 1), n + i, n + j], 1)])
    return v, np.concatenate([sides, caps])


def _sphere_mesh(radius: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    rings = max(3, n // 2)
    theta = np.pi * np.arange(1, rings) / rings
    phi = 2 * np.pi * np.arange(n) / n
    v = [[0, 0, radius]] + [[radius * np.sin(t) * np.cos(p), radius * np.sin(t) * np.sin(p), radius * np.cos(t)]
                            for t in theta for p in phi] + [[0, 0, -radius]]
    faces = []
    for k in range(n):
        faces.append([0, 1 + k, 1 + (k + 1) % n])
    for r in range(rings - 2):
        for k in range(n):
            a, b = 1 + r * n + k, 1 + r * n + (k + 1) % n
            faces += [[a, a + n, b], [b, a + n, b + n]]
    last = len(v) - 1
    base = 1 + (rings - 2) * n
    for k in range(n):
        faces.append([last, base + (k + 1) % n, base + k])
    return np.array(v, float), np.array(faces)


def shape_mesh(shape: Shape, segments: int = DRAW_SEGMENTS, hull: ShapeSet | None = None,
               index: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh of ``shape`` in the frame it is attached to: vertices (V, 3), faces (F, 3). A convex shape is
    drawn as its hull (from ``hull.core`` when given with the shape's ``index``, else computed with scipy)."""
    if shape.kind == "box":
        v, f = _BOX_SIGNS * (0.5 * shape.size), _BOX_FACES
    elif shape.kind == "cylinder":
        v, f = _cylinder_mesh(shape.radius, float(shape.size[1]), segments)
    elif shape.kind == "sphere":
        v, f = _sphere_mesh(shape.radius, segments)
    else:
        if hull is not None and index is not None:
            v, f = np.asarray(hull.core.hull_vertices(index)), np.asarray(hull.core.hull_faces(index))
        else:
            assert shape.vertices is not None  # a convex shape has them (its constructor's contract)
            h = ConvexHull(shape.vertices)
            v, f = np.asarray(shape.vertices), h.simplices
    R, p = shape.origin[:3, :3], shape.origin[:3, 3]
    return v @ R.T + p, np.asarray(f, dtype=np.int64)


def shape_points(shape: Shape, segments: int = 16) -> np.ndarray:
    """Points (P, 3) whose convex hull is the shape (a cylinder's and a sphere's to ``segments``), in the frame it
    is attached to: for fitting and bounds."""
    v, _ = shape_mesh(shape, segments)
    return v
