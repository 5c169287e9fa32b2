"""`SnakeRobot`: a snake robot from its URDF and three frame names; its parts and everything derived from the URDF.

This is the one place that knows how the body divides into base, neck and head (paper, Section 2) and what the
body looks like: where the joints sit along it, which bend in yaw and which in pitch, how long the links are,
the collision boxes and their corners, the height of the body's axis when the base lies on the ground.
Everything else asks it; nothing else names a link or holds a dimension of a particular robot.

A robot is a URDF plus three frames (links or fixed marker frames) along one serial chain from the root:

* base = the joints from ``root`` to ``base_end`` (the paper's P0 is the origin of ``base_end``);
* neck = the joints from ``base_end`` to ``neck_end`` (B0, the head part's base frame);
* head = the joints from ``neck_end`` to ``head_tip`` (the head link frame; its x-axis is the head's direction).

The snake lies straight along the root frame's x-axis at q = 0, and each joint turns about the root frame's
z-axis (a *yaw* joint: it bends the body in the ground plane while the body lies flat) or its y-axis (a *pitch*
joint: it lifts the body off the ground).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .. import _core
from .._validate import finite_array, joint_vector
from .chain import Chain, _check_utf8

import numpy.typing as npt
from typing import Any

YAW = "yaw"
PITCH = "pitch"

#: How far (rad) a joint axis may be from the root frame's y- or z-axis, and how far (m) a frame may be from the
#: root frame's x-axis at q = 0, for the body to count as a straight snake with yaw and pitch joints.
STRAIGHT_TOLERANCE = 1e-6


def default_robot_file() -> Path:
    """Path of the shipped robot file ``snake16.toml`` (package data; the source tree's copy when run in place)."""
    for folder in (Path(__file__).resolve().parents[1] / "urdf", Path(__file__).resolve().parents[3] / "urdf"):
        if (folder / "snake16.toml").exists():
            return folder / "snake16.toml"
    raise FileNotFoundError("snake16.toml is neither installed with the package nor in the source tree")


def default_urdf_path() -> Path:
    """Path of the shipped ``snake16.urdf`` (beside :func:`default_robot_file`)."""
    return default_robot_file().with_name("snake16.urdf")


@dataclass(frozen=True)
class BasePlacement:
    """Where the base lies on the ground: the root link's frame at planar position (x, y), turned by ``yaw``.

    x, y in m (world), yaw in rad about the world z-axis. The root frame's height is the robot's
    (:attr:`SnakeRobot.body_axis_height`: the base's boxes rest on the ground), so a placement fits any robot:
    ``robot.root_pose(base)`` is the 4x4 world pose. The default puts the root frame (the tail end) at the origin
    with the body along world +x.
    """

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def __post_init__(self) -> None:
        finite_array([self.x, self.y, self.yaw], "base placement (x, y, yaw)", (3,))
        for name in ("x", "y", "yaw"):
            object.__setattr__(self, name, float(getattr(self, name)))

    def matrix(self, height: float) -> np.ndarray:
        """World pose (4, 4) of the root frame with its origin ``height`` m above the ground."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        T[:3, 3] = (self.x, self.y, float(height))
        return T


@dataclass(frozen=True)
class RobotParts:
    """How the joint vector splits into the paper's parts, and the frames that bound them.

    Joint ranges are Python slices into the whole-body joint vector (chain order, 0-based).
    """

    base: slice
    neck: slice
    head: slice
    root: str
    base_end: str  # P0: end frame of the base part
    neck_end: str  # B0: end frame of the neck part = base frame of the head part
    head_tip: str  # head link frame; its x-axis is the head's direction


def _urdf_source(urdf: str | os.PathLike[str]) -> str:
    if isinstance(urdf, os.PathLike):
        urdf = os.fspath(urdf)
    if not isinstance(urdf, str):
        raise TypeError(f"urdf must be a path or an XML string, got {type(urdf).__name__}")
    _check_utf8(urdf, "urdf")  # before the core sees it (urdf_root_link below)
    return urdf


def _frame_name(value: Any, what: str) -> str:
    if not isinstance(value, str) or not value:
        raise TypeError(f"{what} must be a frame name (a non-empty str), got {value!r}")
    _check_utf8(value, what)
    return value


class SnakeRobot:
    """A snake robot: the whole-body chain (root to head tip), its parts, its shape and mass data.

    Build one with :meth:`from_urdf` (a URDF and three frame names), :meth:`from_file` (a robot file) or
    :meth:`default` (the paper's 16-joint robot). Immutable; chains and derived data are computed once.
    """

    def __init__(self, urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str,
                 root: str | None = None, map_path: str | os.PathLike | None = None, source: str | None = None) -> None:
        self.urdf = _urdf_source(urdf)
        base_end = _frame_name(base_end, "base_end")
        neck_end = _frame_name(neck_end, "neck_end")
        head_tip = _frame_name(head_tip, "head_tip")
        root = _core.urdf_root_link(self.urdf) if root is None else _frame_name(root, "root")
        #: The head's reachability map file named by the robot file (None: none given).
        self.map_path = None if map_path is None else Path(map_path)
        #: Where the robot came from (a robot file's path), for messages and reports.
        self.source = source
        try:
            self.body = Chain.from_urdf(self.urdf, root, head_tip)
        except ValueError as exc:
            raise ValueError(f"the robot's body (root {root!r} -> head_tip {head_tip!r}): {exc}") from None
        names = self.body.link_names
        order = [("root", root), ("base_end", base_end), ("neck_end", neck_end), ("head_tip", head_tip)]
        for key, name in order:
            if name not in names:
                raise ValueError(f"{key} {name!r} is not a frame on the chain from the root {root!r} to the head tip "
                                 f"{head_tip!r} (frames: {', '.join(names)})")
        idx = [names.index(name) for _, name in order]
        for (ka, na), (kb, nb), a, b in zip(order, order[1:], idx, idx[1:]):
            if not a < b:
                raise ValueError(f"frames out of order: {kb} {nb!r} must come after {ka} {na!r} along the body "
                                 "(root -> base_end -> neck_end -> head_tip)")
        joints_before = self._joints_before
        slices = []
        for (ka, na), (kb, nb), a, b in zip(order, order[1:], idx, idx[1:]):
            start, stop = joints_before(a), joints_before(b)
            part = {"base_end": "base", "neck_end": "neck", "head_tip": "head"}[kb]
            if stop <= start:
                raise ValueError(f"the {part} part ({ka} {na!r} -> {kb} {nb!r}) has no joint")
            slices.append(slice(start, stop))
        self.parts = RobotParts(base=slices[0], neck=slices[1], head=slices[2], root=root, base_end=base_end,
                                neck_end=neck_end, head_tip=head_tip)
        self._chains: dict[tuple[str, str], Chain] = {}
        self._check_snake()

    # --- construction ---------------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str,
                  root: str | None = None) -> "SnakeRobot":
        """A robot from a URDF (a path, or the XML itself starting with ``<``) and the frames that bound its parts.

        ``root`` defaults to the URDF's root link. Any link or fixed marker frame may be named. Raises ValueError
        for frames that are missing or out of order, a part without joints, or a body that is not a snake
        (straight along x at q = 0, revolute joints about the root frame's y or z, collision boxes on the base).
        """
        return cls(urdf, base_end=base_end, neck_end=neck_end, head_tip=head_tip, root=root)

    @classmethod
    def from_file(cls, path: str | os.PathLike) -> "SnakeRobot":
        """A robot from a robot file (TOML; :mod:`snakehead.model.robot_file`)."""
        from .robot_file import read_robot_file

        spec = read_robot_file(path)
        return cls(spec.urdf, base_end=spec.base_end, neck_end=spec.neck_end, head_tip=spec.head_tip,
                   root=spec.root, map_path=spec.map, source=os.fspath(path))

    @classmethod
    def default(cls) -> "SnakeRobot":
        """The shipped 16-joint robot of the paper (``snake16.toml``: Table 3, with its head's map)."""
        return cls.from_file(default_robot_file())

    def _joints_before(self, link_index: int) -> int:
        """How many joints lie between the root and the frame ``link_names[link_index]``."""
        child = np.asarray(self.body.model.joint_child_links)
        return int(np.sum(child <= link_index))

    def _check_snake(self) -> None:
        types = set(self.body.joint_types)
        if types - {"revolute"}:
            raise ValueError(f"a snake robot's joints are revolute with limits; this body has {sorted(types)} joints")
        F = self.body.fk_all(np.zeros(self.n_joints))
        p = F[:, :3, 3]
        if np.abs(p[:, 1:]).max() > STRAIGHT_TOLERANCE or np.any(np.diff(p[:, 0]) < -STRAIGHT_TOLERANCE):
            raise ValueError("the body does not lie straight along the root frame's x-axis at q = 0 (every frame on "
                             "the x-axis, in order); snakehead's snakes do")
        for j, a in enumerate(self.joint_axes):
            if not (np.allclose(np.abs(a), (0, 0, 1), atol=STRAIGHT_TOLERANCE)
                    or np.allclose(np.abs(a), (0, 1, 0), atol=STRAIGHT_TOLERANCE)):
                raise ValueError(f"joint {self.joint_names[j]!r} turns about {np.round(a, 6).tolist()} in the root frame; "
                                 "a snake's joints turn about its z-axis (yaw) or y-axis (pitch)")
        if len(self.base_links) == 0 or not np.all(self.box_sizes[self.base_links] > 0):
            missing = [self.link_names[i] for i in self.base_links if not np.all(self.box_sizes[i] > 0)]
            raise ValueError("every base link needs a collision box (the base lies on the ground on them); "
                             f"missing on {missing or 'the base'}")
        if not self.total_mass > 0:
            raise ValueError("the robot has no mass (no <inertial> on its links): stability needs the masses")

    # --- parts -------------------------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return self.body.n_joints

    @property
    def joint_names(self) -> list[str]:
        return self.body.joint_names

    def sub_chain(self, base: str, tip: str) -> Chain:
        """The chain between two frames of the body (cached; chains are immutable)."""
        key = (base, tip)
        if key not in self._chains:
            self._chains[key] = Chain.from_urdf(self.urdf, base, tip)
        return self._chains[key]

    @property
    def base_chain(self) -> Chain:
        """The base part, root -> base_end (P0)."""
        return self.sub_chain(self.parts.root, self.parts.base_end)

    @property
    def neck_chain(self) -> Chain:
        """The neck part, base_end (P0) -> neck_end (B0)."""
        return self.sub_chain(self.parts.base_end, self.parts.neck_end)

    @property
    def head_chain(self) -> Chain:
        """The head part, neck_end (B0) -> head_tip."""
        return self.sub_chain(self.parts.neck_end, self.parts.head_tip)

    @cached_property
    def lift_joints(self) -> slice:
        """The neck joints that lift and aim it: from the neck's first pitch joint to the neck's end.

        A neck that begins with yaw joints has links before its first pitch joint that cannot leave the ground
        (no joint lifts them): turning them would drag them, loaded by the lifted body, across the ground and
        push the base. They are held where the initial configuration puts them, like the base's joints.
        """
        neck = self.parts.neck
        first = next((j for j in range(neck.start, neck.stop) if self.joint_kinds[j] == PITCH), neck.stop)
        return slice(first, neck.stop)

    @property
    def lift_frame(self) -> str:
        """Where the neck's lifting begins: the frame just before the neck's first pitch joint (``base_end`` when
        the neck begins with a pitch joint; ``neck_end`` when it has none). The neck's Eqs. 18-22 pivot on it."""
        start = self.lift_joints.start
        if start == self.parts.neck.stop:
            return self.parts.neck_end
        child = int(self.body.model.joint_child_links[start])
        return self.link_names[child - 1]

    @property
    def lift_chain(self) -> Chain:
        """The lifting part of the neck, :attr:`lift_frame` -> neck_end (the whole neck on the default robot)."""
        return self.sub_chain(self.lift_frame, self.parts.neck_end)

    @property
    def lower(self) -> np.ndarray:
        return self.body.lower

    @property
    def upper(self) -> np.ndarray:
        return self.body.upper

    @property
    def effort(self) -> np.ndarray:
        """(n,) the URDF's joint effort limits (N m; 0 where the URDF gives none)."""
        return np.asarray(self.body.model.effort, float)

    @property
    def velocity_limit(self) -> np.ndarray:
        """(n,) the URDF's joint velocity limits (rad/s; 0 where the URDF gives none)."""
        return np.asarray(self.body.model.velocity, float)

    @property
    def link_names(self) -> list[str]:
        """Every frame of the body in chain order: links and the marker frames between them."""
        return self.body.link_names

    def link_index(self, name: str) -> int:
        """Index of a frame in :attr:`link_names` (ValueError for a frame not on the body)."""
        return self.body.link_index(name)

    def _part_links(self, start: str | None, stop: str | None) -> np.ndarray:
        n = len(self.link_names)
        a = 0 if start is None else self.link_index(start)
        b = n if stop is None else self.link_index(stop)
        return np.arange(a, b)

    @cached_property
    def base_links(self) -> np.ndarray:
        """Indices (link_names) of the base part's links that carry a body (mass or box): those before base_end."""
        return self._bodies(self._part_links(None, self.parts.base_end))

    @cached_property
    def neck_links(self) -> np.ndarray:
        """Indices (link_names) of the neck part's bodies: from base_end up to neck_end."""
        return self._bodies(self._part_links(self.parts.base_end, self.parts.neck_end))

    @cached_property
    def head_links(self) -> np.ndarray:
        """Indices (link_names) of the head part's bodies: from neck_end to the head tip."""
        return self._bodies(self._part_links(self.parts.neck_end, None))

    def _bodies(self, links: np.ndarray) -> np.ndarray:
        keep = (self.masses[links] > 0) | np.all(self.box_sizes[links] > 0, axis=1)
        return links[keep]

    @cached_property
    def lifted_links(self) -> np.ndarray:
        """Indices (link_names) of the boxed links after the base (neck and head): those that lift off the ground."""
        return self.boxed_links[self.boxed_links >= self.link_index(self.parts.base_end)]

    # --- shape at q = 0 (the body straight along the root frame's x-axis) ------------------------------------
    @cached_property
    def _straight_frames(self) -> np.ndarray:
        F = self.body.fk_all(np.zeros(self.n_joints))
        F.setflags(write=False)
        return F

    @cached_property
    def joint_axes(self) -> np.ndarray:
        """(n, 3) each joint's axis in the root frame at q = 0."""
        F = self._straight_frames
        child = np.asarray(self.body.model.joint_child_links)
        local = np.asarray(self.body.model.joint_axes, float)
        axes = np.einsum("jik,jk->ji", F[child, :3, :3], local)
        axes.setflags(write=False)
        return axes

    @cached_property
    def joint_frames(self) -> np.ndarray:
        """(n,) index (link_names) of each joint's frame: the link it moves, whose frame sits on the joint."""
        child = np.asarray(self.body.model.joint_child_links, dtype=np.intp)
        child.setflags(write=False)
        return child

    @cached_property
    def joint_kinds(self) -> tuple[str, ...]:
        """Each joint's kind: ``"yaw"`` (axis +-z of the root frame) or ``"pitch"`` (+-y)."""
        return tuple(YAW if abs(a[2]) > 0.5 else PITCH for a in self.joint_axes)

    @cached_property
    def joint_signs(self) -> np.ndarray:
        """(n,) +1 where the axis is +z (yaw) or +y (pitch), -1 where it is -z or -y."""
        a = self.joint_axes
        return np.where(np.where(np.abs(a[:, 2]) > 0.5, a[:, 2], a[:, 1]) > 0, 1.0, -1.0)

    @cached_property
    def joint_arc_lengths(self) -> np.ndarray:
        """(n,) each joint's distance from the root frame along the straight body (m): its body arc length."""
        child = np.asarray(self.body.model.joint_child_links)
        return self._straight_frames[child, 0, 3] - self._straight_frames[0, 0, 3]

    def frame_arc_length(self, name: str) -> float:
        """A frame's distance from the root frame along the straight body (m)."""
        F = self._straight_frames
        return float(F[self.link_index(name), 0, 3] - F[0, 0, 3])

    @property
    def body_length(self) -> float:
        """Length of the body from the root frame to the head tip (m)."""
        return self.frame_arc_length(self.parts.head_tip)

    @property
    def base_length(self) -> float:
        """Body arc length of P0 (base_end) from the root frame (m): the base arc's length."""
        return self.frame_arc_length(self.parts.base_end)

    @property
    def neck_length(self) -> float:
        """Length of the neck part, P0 -> B0 along the straight body (m)."""
        return self.frame_arc_length(self.parts.neck_end) - self.base_length

    @property
    def lift_length(self) -> float:
        """Length of the neck's lifting part, :attr:`lift_frame` -> B0 along the straight body (m)."""
        return self.frame_arc_length(self.parts.neck_end) - self.frame_arc_length(self.lift_frame)

    @property
    def head_length(self) -> float:
        """Length of the head part, B0 -> head tip along the straight body (m)."""
        return self.body_length - self.frame_arc_length(self.parts.neck_end)

    @cached_property
    def link_lengths(self) -> np.ndarray:
        """(n_links,) each frame's distance to the next frame along the straight body (m; 0 for the last)."""
        x = self._straight_frames[:, 0, 3]
        return np.append(np.diff(x), 0.0)

    @property
    def head_link_length(self) -> float:
        """Length of the head link: from the last joint to the head tip (m)."""
        return float(self.body_length - self.joint_arc_lengths[-1])

    @cached_property
    def body_axis_height(self) -> float:
        """Height (m) of the root frame above the ground when the base lies on it: the base links' boxes rest on
        the ground (their lowest corners at z = 0) with every pitch joint of the base at zero."""
        corners = self.box_corners(self._straight_frames[None], self.base_links)[0]
        return float(-corners[..., 2].min())

    # --- mass and geometry (per entry of link_names) ---------------------------------------------------------
    @property
    def masses(self) -> np.ndarray:
        """(n_links,) kg."""
        return self.body.model.link_masses

    @property
    def total_mass(self) -> float:
        return float(self.masses.sum())

    @property
    def coms(self) -> np.ndarray:
        """(n_links, 3) centre of mass of each link in its own frame (m)."""
        return self.body.model.link_coms

    @property
    def inertias(self) -> np.ndarray:
        """(n_links, 3, 3) inertia about each link's centre of mass, link-frame axes (kg m^2)."""
        return self.body.model.link_inertias

    @property
    def box_sizes(self) -> np.ndarray:
        """(n_links, 3) collision box extents (m); zeros for links without a box (marker frames)."""
        return self.body.model.link_box_sizes

    @property
    def box_origins(self) -> np.ndarray:
        """(n_links, 4, 4) pose of each collision box's centre in its link frame."""
        return self.body.model.link_box_origins

    @cached_property
    def boxed_links(self) -> np.ndarray:
        """Indices (link_names) of the frames that have a collision box."""
        return np.flatnonzero(np.all(self.box_sizes > 0.0, axis=1))

    def box_poses(self, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
        """World poses of the collision boxes' centres, (T, k, 4, 4), from frames (T, n_links, 4, 4)."""
        links = self.boxed_links if links is None else np.asarray(links)
        return frames[:, links] @ self.box_origins[links]

    def box_corners(self, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
        """The eight corners of the collision boxes of ``links`` (default: every boxed link), (T, k, 8, 3) world,
        from frames (T, n_links, 4, 4) (e.g. :meth:`frames_many`)."""
        links = self.boxed_links if links is None else np.asarray(links)
        B = self.box_poses(frames, links)
        local = _BOX_SIGNS[None, :, :] * (0.5 * self.box_sizes[links])[:, None, :]  # (k, 8, 3)
        return np.einsum("tkij,kcj->tkci", B[..., :3, :3], local) + B[..., None, :3, 3]

    def lowest_box_z(self, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
        """Lowest z (m) of the collision boxes of ``links`` (default every boxed link): (T, k).

        A box of half-extents h, centre c and rotation R reaches down to c_z - sum_k |R[2, k]| h_k.
        """
        links = self.boxed_links if links is None else np.asarray(links)
        frames = np.asarray(frames, float)
        if frames.ndim != 4 or frames.shape[1:] != (len(self.link_names), 4, 4):
            raise ValueError(f"frames has shape {frames.shape}; expected (T, {len(self.link_names)}, 4, 4)")
        _, z = _core.lowest_box_corners(np.ascontiguousarray(frames), self.box_origins, 0.5 * self.box_sizes,
                                        links.astype(np.int32).reshape(-1))  # the lowest corner first
        return z[..., 0]

    # --- whole-body kinematics ---------------------------------------------------------------------------
    def joint_axes_world(self, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World axes (n, 3) and origins (n, 3) of the joints, from the world frames (n_links, 4, 4) of one
        configuration (:meth:`frames`)."""
        child = np.asarray(self.body.model.joint_child_links)
        local = np.asarray(self.body.model.joint_axes, float)
        return np.einsum("jik,jk->ji", frames[child, :3, :3], local), frames[child, :3, 3]

    def point_jacobians(self, frames: np.ndarray, points: np.ndarray, links: Any) -> np.ndarray:
        """d(point)/d(q, x, y, yaw) of world points rigidly attached to ``links`` (indices into link_names), for
        the configuration of ``frames`` (n_links, 4, 4): (P, 3, n + 3). The last three columns are the base
        placement's x, y and yaw.

        A revolute joint j moves the points distal to it by a_j x (p - o_j) (a_j its world axis, o_j its origin);
        the base's placement moves every point by (1, 0, 0), (0, 1, 0) and e_z x (p - root).
        """
        points = np.asarray(points, float).reshape(-1, 3)
        a, o = self.joint_axes_world(frames)
        n = len(a)
        child = np.asarray(self.body.model.joint_child_links)
        J = np.zeros((len(points), 3, n + 3))
        moved = child[None, :] <= np.asarray(links).reshape(-1)[:, None]  # (P, n): joint j moves point's link
        r = points[:, None, :] - o[None, :, :]  # (P, n, 3)
        J[:, 0, :n] = (a[None, :, 1] * r[..., 2] - a[None, :, 2] * r[..., 1]) * moved
        J[:, 1, :n] = (a[None, :, 2] * r[..., 0] - a[None, :, 0] * r[..., 2]) * moved
        J[:, 2, :n] = (a[None, :, 0] * r[..., 1] - a[None, :, 1] * r[..., 0]) * moved
        root = frames[0, :3, 3]
        J[:, 0, n] = 1.0
        J[:, 1, n + 1] = 1.0
        J[:, 0, n + 2] = -(points[:, 1] - root[1])  # e_z x (p - root)
        J[:, 1, n + 2] = points[:, 0] - root[0]
        return J

    def root_pose(self, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the root frame when the base lies on the ground at ``base`` (default placement)."""
        return as_base(base).matrix(self.body_axis_height)

    def frames(self, q: npt.ArrayLike, base: BasePlacement | None = None) -> np.ndarray:
        """World poses of every frame in ``link_names`` at joint vector ``q`` (n,): (n_links, 4, 4)."""
        q = joint_vector(q, self.n_joints)
        return self.root_pose(base) @ self.body.fk_all(q)

    def frames_many(self, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """``frames`` along a trajectory: qs (T, n) -> (T, n_links, 4, 4)."""
        return self.body.fk_all_many(qs, self.root_pose(base))

    def frame(self, q: np.ndarray, name: str, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of one named frame (a link or a marker)."""
        k = self.link_index(name)
        return self.frames(q, base)[k]

    def head_pose(self, q: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the head tip: its x-axis is the head's direction."""
        return self.frame(q, self.parts.head_tip, base)

    def random_configuration(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """Uniform within the joint limits, (n,)."""
        return self.body.random_configuration(rng)

    def __repr__(self) -> str:
        where = self.source or (self.urdf if not self.urdf.lstrip().startswith("<") else "<URDF text>")
        return (f"SnakeRobot({where!r}, {self.n_joints} joints: base {self.parts.base.stop - self.parts.base.start}, "
                f"neck {self.parts.neck.stop - self.parts.neck.start}, head {self.parts.head.stop - self.parts.head.start})")


_BOX_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)


def as_robot(robot: SnakeRobot) -> SnakeRobot:
    """``robot`` itself if it is a SnakeRobot, else TypeError (the check every planning function makes)."""
    if not isinstance(robot, SnakeRobot):
        raise TypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return robot


def as_base(base: BasePlacement | None) -> BasePlacement:
    """``base`` if it is a BasePlacement, the default placement for None, else TypeError."""
    if base is None:
        return BasePlacement()
    if not isinstance(base, BasePlacement):
        raise TypeError(f"base must be a BasePlacement or None, got {type(base).__name__}")
    return base
