"""`SnakeRobot`: a snake robot from its URDF and three frame names; its parts and everything derived from the URDF.

This is the one place that knows how the body divides into base, neck and head (paper, Section 2) and what the
body looks like: where the joints sit along it, which bend in yaw and which in pitch, how long the links are,
the collision shapes and their lowest points, the height of the body's axis when the base lies on the ground.
Everything else asks it; nothing else names a link or holds a dimension of a particular robot.

A robot is a URDF plus three frames (links or fixed marker frames) along one serial chain from the root:

* base = the joints from ``root`` to ``base_end`` (the paper's P0 is the origin of ``base_end``);
* neck = the joints from ``base_end`` to ``neck_end`` (B0, the head part's base frame);
* head = the joints from ``neck_end`` to ``head_tip`` (the head link frame; its x-axis is the head's direction).

The snake lies straight at q = 0: every frame on one line, the *body axis*, whatever way the URDF's link frames
turn (modules along their x, y or z, a rotated dummy root). The *body frame* has its x-axis along that line
towards the head and its z-axis up; up is the joint-axis direction nearest the root frame's z (then x, then y).
Each joint turns about the body frame's z-axis (a *yaw* joint: it bends the body in the ground plane while the
body lies flat) or its y-axis (a *pitch* joint: it lifts the body off the ground). Frames whose orientation the
planner reads (base_end, neck_end, the lift frame and head_tip) are given aligned twins when the URDF's are not
(x along the body, z up at q = 0; the head tip's x along its ``head_axis``), added to the URDF as fixed marker
frames named ``NAME__aligned``.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .. import _core
from .._errors import InputError, InputTypeError
from .._validate import finite_array, joint_vector
from .chain import Chain, _check_utf8
from .body_frame import (ALIGNED_SUFFIX, AXIS_TOLERANCE_DEG, HEAD_AXES, STRAIGHT_TOLERANCE, NotStraight,
                         Straightness, aligned_frames, body_frame, straightness)
from ..geometry.meshes import convex_hull_vertices
from .description import MeshResolver, read_description, with_joint_limits
from .mass_properties import rewrite_inertia
from .description_tree import JointOffsets, TreeChanges, body_description

import numpy.typing as npt
from typing import TYPE_CHECKING, Any, Mapping

if TYPE_CHECKING:  # the geometry layer imports this module
    from ..geometry.shapes import ShapeSet

YAW = "yaw"
PITCH = "pitch"



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
    """Where the base lies on the ground: the body frame (:attr:`SnakeRobot.body_in_root`; the root link's frame
    for snakes written along x) at planar position (x, y), turned by ``yaw``.

    x, y in m (world), yaw in rad about the world z-axis. The root frame's height is the robot's
    (:attr:`SnakeRobot.body_axis_height`: the base's shapes rest on the ground), so a placement fits any robot:
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
        raise InputTypeError(f"urdf must be a path or an XML string, got {type(urdf).__name__}")
    _check_utf8(urdf, "urdf")  # before the core sees it (urdf_root_link below)
    return urdf


def _frame_name(value: Any, what: str) -> str:
    if not isinstance(value, str) or not value:
        raise InputTypeError(f"{what} must be a frame name (a non-empty str), got {value!r}")
    _check_utf8(value, what)
    return value


class SnakeRobot:
    """A snake robot: the whole-body chain (root to head tip), its parts, its shape and mass data.

    Build one with :meth:`from_urdf` (a URDF and three frame names), :meth:`from_file` (a robot file) or
    :meth:`default` (the paper's 16-joint robot). Immutable; chains and derived data are computed once.
    """

    def __init__(self, urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str,
                 root: str | None = None, map_path: str | os.PathLike | None = None, source: str | None = None,
                 head_axis: str = "x", packages: Mapping[str, str | os.PathLike] | None = None,
                 limits: Mapping[str, tuple[float, float]] | None = None,
                 xacro_args: Mapping[str, object] | None = None, robot_file: str | os.PathLike | None = None,
                 trust_xacro: bool = False, home: Mapping[str, float] | None = None,
                 inertia: str = "urdf", density: float | None = None) -> None:
        self._arguments = {"urdf": urdf, "root": root, "head_axis": head_axis, "packages": packages, "limits": limits,
                           "xacro_args": xacro_args, "source": source, "robot_file": robot_file,
                           "trust_xacro": trust_xacro, "home": home, "inertia": inertia, "density": density}
        description = read_description(_urdf_source(urdf), xacro_args, packages=packages, robot_file=robot_file,
                                        trust_xacro=trust_xacro)
        description, rewrite = rewrite_inertia(description, inertia, density)  # <inertial> from the shapes, if asked
        #: What ``inertia = "from_shapes"`` moved (:class:`.mass_properties.InertiaRewrite`; None for "urdf").
        self.inertia_rewrite = rewrite
        names = {"base_end": _frame_name(base_end, "base_end"), "neck_end": _frame_name(neck_end, "neck_end"),
                 "head_tip": _frame_name(head_tip, "head_tip")}
        if head_axis not in HEAD_AXES:
            raise InputError(f"head_axis must be one of {', '.join(HEAD_AXES)}, got {head_axis!r}")
        #: The head tip frame's axis that points where the head looks (in the URDF's head_tip frame).
        self.head_axis = head_axis
        #: The frames as the user named them (``parts`` may name their aligned twins).
        self.user_frames = dict(names)
        #: The head's reachability map file named by the robot file (None: none given).
        self.map_path = None if map_path is None else Path(map_path)
        #: Where the robot came from (a robot file's path), for messages and reports.
        self.source = source or description.source
        self._meshes = MeshResolver(description.folder, description.folders)
        text = description.text
        _check_utf8(text, "urdf")
        root = _core.urdf_root_link(text) if root is None else _frame_name(root, "root")  # the core checks the text
        #: The description's URDF as read (a xacro expanded): what ROS tools take as ``robot_description``.
        self.description_text = text if _is_xml_text(text) else _core.read_urdf_file(text)
        text, self.tree_changes, raw = _body_text(text, self.description_text, root, names["head_tip"],
                                                  limits or {}, _home_table(home), description.source)
        self.joint_offsets = JointOffsets(np.array([dict(self.tree_changes.home).get(j, 0.0)
                                                    for j in raw.joint_names]))
        parts = _part_slices(raw, root, names)
        body_in_root = body_frame(raw)
        aligned, text = aligned_frames(text, raw, body_in_root, parts, names, head_axis)
        #: The URDF text the core reads: the description re-rooted, straightened at its home pose, its branches
        #: lumped, with limits and aligned frames (:mod:`.description_tree`; a path when unchanged).
        self.urdf = text
        self.body = raw if aligned == names else _body_chain(text, root, aligned["head_tip"])
        self._body_in_root = body_in_root
        self.parts = RobotParts(base=parts[0], neck=parts[1], head=parts[2], root=root, base_end=aligned["base_end"],
                                neck_end=aligned["neck_end"], head_tip=aligned["head_tip"])
        self._chains: dict[tuple[str, str], Chain] = {}
        self._check_snake()

    # --- construction ---------------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str,
                  root: str | None = None, head_axis: str = "x", packages: Mapping[str, str | os.PathLike] | None = None,
                  limits: Mapping[str, tuple[float, float]] | None = None,
                  xacro_args: Mapping[str, object] | None = None, trust_xacro: bool = False,
                  home: Mapping[str, float] | None = None, inertia: str = "urdf",
                  density: float | None = None) -> "SnakeRobot":
        """A robot from a description (a URDF or ``.xacro`` path, or the URDF XML itself starting with ``<``) and
        the frames that bound its parts.

        ``root`` defaults to the URDF's root link. Any link or fixed marker frame may be named. ``head_axis``: the
        head_tip frame's axis that points where the head looks. ``packages``: NAME -> folder for
        ``package://NAME/...`` meshes. ``limits``: joint -> (lower, upper) rad, needed for ``continuous`` joints.
        ``xacro_args``: the arguments of a xacro file. ``trust_xacro``: expand a xacro with xacro's own Python
        evaluator, the environment and any file (only for a description you trust; by default its expressions are
        evaluated without running code and it reads only its own folders: SECURITY.md). ``home``: joint -> angle
        (rad) at which the body lies straight (default 0; the planner's angles are the description's minus these,
        :meth:`description_angles`). ``root`` may lie anywhere on the tree: the body runs from it to ``head_tip``
        against the tree where it must (:mod:`.description_tree`). Raises :class:`~snakehead.InputError` for frames that are
        missing or out of order, a part without joints, or a body that is not a snake (straight at q = 0,
        revolute joints about two perpendicular axes across it, collision shapes on the base). ``inertia``:
        ``"urdf"`` (the description's ``<inertial>``) or ``"from_shapes"`` (the inertias recomputed from the
        collision shapes at uniform density over each rigid segment of links fixed together, with the segment's
        URDF mass or, given ``density`` in kg/m^3, the mass that density gives: :mod:`.mass_properties`).
        """
        return cls(urdf, base_end=base_end, neck_end=neck_end, head_tip=head_tip, root=root, head_axis=head_axis,
                   packages=packages, limits=limits, xacro_args=xacro_args, trust_xacro=trust_xacro, home=home,
                   inertia=inertia, density=density)

    @classmethod
    def from_file(cls, path: str | os.PathLike, *, trust_xacro: bool = False) -> "SnakeRobot":
        """A robot from a robot file (TOML; :mod:`snakehead.model.robot_file`). ``trust_xacro``: as in
        :meth:`from_urdf` (a robot file reached through a scene file is never trusted unless the caller says so)."""
        from .robot_file import read_robot_file

        spec = read_robot_file(path)
        return cls(spec.urdf, base_end=spec.base_end, neck_end=spec.neck_end, head_tip=spec.head_tip,
                   root=spec.root, map_path=spec.map, source=os.fspath(path), head_axis=spec.head_axis,
                   packages=spec.packages, limits=spec.limits, xacro_args=spec.xacro_args, robot_file=path,
                   trust_xacro=trust_xacro, home=spec.home, inertia=spec.inertia, density=spec.density)

    @property
    def description_arguments(self) -> dict[str, Any]:
        """The arguments this robot's description was read with (``urdf``, ``root``, ``head_axis``, ``packages``,
        ``limits``, ``xacro_args``, ``source``, ``robot_file``, ``trust_xacro``, ``home``, ``inertia``, ``density``; a copy): with :attr:`user_frames` and :attr:`map_path`, what builds
        the same robot again, e.g. in another process."""
        return dict(self._arguments)

    def with_parts(self, base_end: str | None = None, neck_end: str | None = None,
                   head_tip: str | None = None) -> "SnakeRobot":
        """The same description split into parts at other frames (the URDF's names; None keeps the frame); the head's
        map is kept when the head is the same."""
        frames = {"base_end": base_end or self.user_frames["base_end"],
                  "neck_end": neck_end or self.user_frames["neck_end"],
                  "head_tip": head_tip or self.user_frames["head_tip"]}
        same_head = (frames["neck_end"], frames["head_tip"]) == (self.user_frames["neck_end"],
                                                                  self.user_frames["head_tip"])
        return SnakeRobot(**self._arguments, **frames,  # type: ignore[arg-type]
                          map_path=self.map_path if same_head else None)

    @classmethod
    def default(cls) -> "SnakeRobot":
        """The shipped 16-joint robot of the paper (``snake16.toml``: Table 3, with its head's map)."""
        return cls.from_file(default_robot_file())

    def _joints_before(self, link_index: int) -> int:
        """How many joints lie between the root and the frame ``link_names[link_index]``."""
        return _joints_before(self.body, link_index)

    def _check_snake(self) -> None:
        shaped = set(self.shaped_links.tolist())
        segments: dict[int, list[int]] = {}  # the base's rigid segments: links between the same two joints
        for i in self.base_links.tolist():
            segments.setdefault(self._joints_before(i), []).append(i)
        bare = [self.link_names[i] for links in segments.values() if not shaped & set(links) for i in links]
        if not segments or bare:
            raise InputError("every rigid segment of the base needs a <collision> shape (the base lies on the ground "
                             f"on them); none on {bare or 'the base'}")
        if not self.base_length > STRAIGHT_TOLERANCE:  # the base arc's radius would be 0
            raise InputError(f"the base part (root {self.parts.root!r} -> base_end {self.user_frames['base_end']!r}) is "
                             f"{1000 * self.base_length:.3g} mm long along the body: put base_end further along it")
        self._check_straight()  # first: a curled body's axes are off its line too
        off_deg = np.degrees(self.axis_deviations)
        for j in np.flatnonzero(off_deg > AXIS_TOLERANCE_DEG):
            a = self.joint_axes[j]
            message = (f"joint {self.joint_names[j]!r} turns about {np.round(a, 4).tolist()} in the body frame (x "
                       f"along the body, z up), {off_deg[j]:.2f} deg off its y- or z-axis (at most "
                       f"{AXIS_TOLERANCE_DEG:g} deg): a snake's joints turn about its z-axis (yaw) or y-axis (pitch)")
            if self.straightness.offset > STRAIGHT_TOLERANCE:  # a body bent at zero: a home pose may straighten it
                raise NotStraight(message + "; if the body is not straight at zero, give the robot file a [home] table",
                                  self.body, self.joint_offsets.home, self.half_section)
            raise InputError(message)
        if not self.total_mass > 0:
            raise InputError("the robot has no mass (no <inertial> on its links): stability needs the masses")

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
        """Indices (link_names) of the base part's links that carry a body (mass or shapes): those before base_end."""
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
        keep = (self.masses[links] > 0) | np.isin(links, self.shaped_links)
        return links[keep]

    @cached_property
    def lifted_links(self) -> np.ndarray:
        """Indices (link_names) of the links with collision shapes after the base (neck and head): those that lift
        off the ground."""
        return self.shaped_links[self.shaped_links >= self.link_index(self.parts.base_end)]

    # --- shape at q = 0 (the body straight along the body frame's x-axis) --------------------------------------
    @cached_property
    def _straight_frames(self) -> np.ndarray:
        """Every frame at q = 0 in the body frame (the body along its x-axis from the origin, z up)."""
        F = np.linalg.inv(self._body_in_root) @ self.body.fk_all(np.zeros(self.n_joints))
        F.setflags(write=False)
        return F

    @property
    def body_in_root(self) -> np.ndarray:
        """The body frame (4, 4) in the root frame: x along the straight body towards the head, z up (the root
        frame itself for snakes written along x with z up)."""
        return self._body_in_root.copy()

    @cached_property
    def joint_axes(self) -> np.ndarray:
        """(n, 3) each joint's axis in the body frame at q = 0."""
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
        """Each joint's kind: ``"yaw"`` (axis +-z of the body frame) or ``"pitch"`` (+-y)."""
        return tuple(YAW if abs(a[2]) > 0.5 else PITCH for a in self.joint_axes)

    @cached_property
    def joint_signs(self) -> np.ndarray:
        """(n,) +1 where the axis is +z (yaw) or +y (pitch), -1 where it is -z or -y."""
        a = self.joint_axes
        return np.where(np.where(np.abs(a[:, 2]) > 0.5, a[:, 2], a[:, 1]) > 0, 1.0, -1.0)

    @cached_property
    def axis_deviations(self) -> np.ndarray:
        """(n,) each joint axis's angle (rad) from the nearest of the body frame's y- and z-axes at q = 0 (the
        description's true axes; the yaw/pitch split reads them within :data:`.body_frame.AXIS_TOLERANCE_DEG`)."""
        a = self.joint_axes / np.linalg.norm(self.joint_axes, axis=1, keepdims=True)
        out = np.arccos(np.clip(np.maximum(np.abs(a[:, 1]), np.abs(a[:, 2])), -1.0, 1.0))
        out.setflags(write=False)
        return out

    @cached_property
    def straightness(self) -> Straightness:
        """How far the body at q = 0 (the description's home pose) is from its line: the largest side offset of a
        frame (m) and which frame. Offsets within the body's half-section are accepted (CAD exports place joint
        frames a few mm to the side)."""
        return straightness(self.body)[2]

    @cached_property
    def half_section(self) -> float:
        """The base's narrowest half-width across the body (m): the thinnest module's radius."""
        radii = self.link_capsules[1][self.shaped_base_links]
        return float(radii.min()) if len(radii) else 0.0

    def _check_straight(self) -> None:
        st = self.straightness
        if st.out_of_order or st.offset > self.half_section:
            where = (f"frame {st.out_of_order[0]!r} lies behind the one before it" if st.out_of_order else
                     f"frame {st.frame!r} is {1000 * st.offset:.2f} mm off the body's line (at most the body's "
                     f"half-section, {1000 * self.half_section:.1f} mm)")
            raise NotStraight(f"the body does not lie straight at its zero: {where}; give the robot file a [home] table "
                              "of the joint angles at which it lies straight (`snakehead info` suggests one)",
                              self.body, self.joint_offsets.home, self.half_section)

    def description_angles(self, q: npt.ArrayLike) -> np.ndarray:
        """Joint angles (..., n) as the description writes them: the planner's ``q`` plus the home pose (the planner
        reads the body straight at zero; files written for the robot hold the description's angles)."""
        return self.joint_offsets.to_description(np.asarray(q, float))

    def body_angles(self, q_description: npt.ArrayLike) -> np.ndarray:
        """The planner's joint angles (..., n) for the description's (the inverse of :meth:`description_angles`)."""
        return self.joint_offsets.from_description(np.asarray(q_description, float))

    @cached_property
    def joint_arc_lengths(self) -> np.ndarray:
        """(n,) each joint's distance from the root frame along the straight body (m): its body arc length."""
        child = np.asarray(self.body.model.joint_child_links)
        return self._straight_frames[child, 0, 3] - self._straight_frames[0, 0, 3]

    def frame_arc_length(self, name: str) -> float:
        """A frame's distance from the root frame along the straight body (m)."""
        F = self._straight_frames
        return float(F[self.link_index(name), 0, 3] - F[0, 0, 3])

    def arc_length_of_user_frame(self, name: str) -> float:
        """:meth:`frame_arc_length` of a frame named as in the description (its aligned twin, if it has one)."""
        aligned = name + ALIGNED_SUFFIX
        return self.frame_arc_length(aligned if aligned in self.link_names else name)

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
        """Height (m) of the body axis above the ground when the base lies on it: the base links' collision shapes
        rest on the ground (their lowest points at z = 0) with every joint at zero."""
        return float(-self.geometry.lowest_z(self._straight_frames[None], self.base_links)[0].min())

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

    @cached_property
    def geometry(self) -> ShapeSet:
        """The collision shapes of the links (every URDF <collision> element: boxes, cylinders, spheres, meshes as
        their convex hulls), on the frames of :attr:`link_names`."""
        from ..geometry.shapes import Shape, ShapeSet

        shapes = []
        for k, elements in enumerate(self.body.model.link_collisions):
            for kind, origin, size, filename in elements:
                where = f"link {self.link_names[k]!r} <collision>"
                if kind == "mesh":
                    path = self._meshes.resolve(filename, where)
                    shapes.append(Shape("convex", k, origin, size, convex_hull_vertices(path, size, where),
                                        source=os.fspath(path)))
                else:
                    shapes.append(Shape(kind, k, origin, size))
        return ShapeSet(tuple(shapes), len(self.link_names))

    @cached_property
    def shaped_links(self) -> np.ndarray:
        """Indices (link_names) of the frames that have collision shapes, ascending."""
        return self.geometry.frames_with_shapes

    @cached_property
    def shaped_base_links(self) -> np.ndarray:
        """Indices (link_names) of the base part's links that have collision shapes, ascending."""
        links = np.asarray(self.base_links, int)
        return links[np.isin(links, self.shaped_links)]

    @cached_property
    def distal_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The shaped links (k,) and, in each link's frame, the points (k, M, 3) of its shapes farthest along the
        body at q = 0 (a box's distal face, a cylinder's distal rim; padded by repetition): where a link pitched up
        about its proximal joint leaves the ground last."""
        links, local = self.link_points
        F = self._straight_frames
        chosen = []
        for k, pts in zip(links, local):
            axial = pts @ (F[k, :3, :3].T @ np.array([1.0, 0.0, 0.0]))
            chosen.append(np.unique(pts[axial >= axial.max() - STRAIGHT_TOLERANCE], axis=0))
        width = max(len(c) for c in chosen)
        out = np.array([c[np.arange(width) % len(c)] for c in chosen])
        out.setflags(write=False)
        return links, out

    @cached_property
    def self_collision_pairs(self) -> np.ndarray:
        """(P, 2) the pairs of shapes (indices into ``geometry.shapes``) that self-collision checks: on links two or
        more joints apart (links one joint apart touch at it; links of one rigid module never move apart)."""
        segment = np.array([self._joints_before(int(f)) for f in self.geometry.shape_frames], dtype=np.int64)
        i, j = np.triu_indices(len(segment), k=1)
        keep = np.abs(segment[i] - segment[j]) >= 2
        pairs = np.stack([i[keep], j[keep]], axis=1).astype(np.int64)
        pairs.setflags(write=False)
        return pairs

    def lowest_z(self, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
        """Lowest world z (m) of the collision shapes of ``links`` (default every shaped link): (T, k), from frames
        (T, n_links, 4, 4) (e.g. :meth:`frames_many`)."""
        links = self.shaped_links if links is None else np.asarray(links)
        frames = np.asarray(frames, float)
        if frames.ndim != 4 or frames.shape[1:] != (len(self.link_names), 4, 4):
            raise InputError(f"frames has shape {frames.shape}; expected (T, {len(self.link_names)}, 4, 4)")
        return self.geometry.lowest_z(frames, links)

    def lowest_points(self, frames: np.ndarray, links: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The lowest candidate ground-contact points of the shapes of ``links`` (default every shaped link):
        world points (T, N, 3) and the link (N,) of each (box corners, cylinder rims, sphere bottoms, mesh hull
        vertices; see :meth:`ShapeSet.lowest_points`)."""
        links = self.shaped_links if links is None else np.asarray(links)
        return self.geometry.lowest_points(np.asarray(frames, float), links)

    @cached_property
    def link_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The shaped links (k,) and points (k, M, 3) in each link's frame whose convex hull is the link's shapes
        (cylinders and spheres as polygons of 16 sides; padded by repetition): for bounds, centres and drawing."""
        from ..geometry.shapes import shape_points

        links = self.shaped_links
        pts = [np.concatenate([shape_points(s) for s in self.geometry.shapes if s.frame == k]) for k in links]
        width = max(len(p) for p in pts)
        out = np.array([np.concatenate([p, np.repeat(p[:1], width - len(p), axis=0)]) for p in pts])
        out.setflags(write=False)
        return links, out

    def hull_points(self, frames: np.ndarray) -> np.ndarray:
        """World points (T, k, M, 3) of :attr:`link_points` for frames (T, n_links, 4, 4)."""
        links, local = self.link_points
        F = np.asarray(frames)[:, links]
        return np.einsum("tkij,kmj->tkmi", F[..., :3, :3], local) + F[:, :, None, :3, 3]

    def link_centres(self, frames: np.ndarray) -> np.ndarray:
        """World centres (T, k, 3) of the shaped links' capsules (their shapes' middle along the body)."""
        links = self.shaped_links
        ends = self.link_capsules[0][links]
        mid = 0.5 * (ends[:, 0] + ends[:, 1])
        F = np.asarray(frames)[:, links]
        return np.einsum("tkij,kj->tki", F[..., :3, :3], mid) + F[..., :3, 3]

    def lowest_point_per_link(self, frames: np.ndarray, links: np.ndarray) -> np.ndarray:
        """The lowest world point (k, 3) of each link's shapes, from the frames (n_links, 4, 4) of one
        configuration (box corner, cylinder rim point, sphere bottom, hull vertex)."""
        links = np.asarray(links, dtype=np.int64)
        pts, owner = self.geometry.lowest_points(np.asarray(frames)[None], links, per_shape=1)  # each shape's lowest
        pts = pts[0]
        if np.array_equal(owner, links):  # one shape per link (the common case)
            return pts
        out = np.empty((len(links), 3))
        for c, k in enumerate(links):
            mine = pts[owner == k]
            out[c] = mine[np.argmin(mine[:, 2])]
        return out

    @cached_property
    def link_capsules(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per frame of :attr:`link_names`, a capsule inside its collision shapes along the body's direction at
        q = 0: end points (n_links, 2, 3) in the link frame, radius (n_links,) m (the shapes' smallest half-width
        across the body, so that the capsule stays inside a box) and excess (n_links,) m (how far the shapes stick
        out of the capsule: a box's corners). Zeros for frames without shapes. The whole-body solve's smooth
        collision terms use them; a box's capsule is its x-axis segment shortened by the radius at both ends."""
        n = len(self.link_names)
        ends, radii, excess = np.zeros((n, 2, 3)), np.zeros(n), np.zeros(n)
        links, local = self.link_points
        F = self._straight_frames
        across = np.array([[0.0, np.cos(a), np.sin(a)] for a in np.linspace(0, np.pi, 16, endpoint=False)])
        for k, pts in zip(links, local):
            R = F[k, :3, :3]
            axis = R.T @ np.array([1.0, 0.0, 0.0])  # the body's direction in the link frame
            centre = 0.5 * (pts.max(axis=0) + pts.min(axis=0))
            t = (pts - centre) @ axis
            radial = (pts - centre) - np.outer(t, axis)
            support = np.abs(radial @ (R.T @ across.T)).max(axis=0)  # half-widths across the body
            r_in = float(support.min())
            half = max(0.5 * (t.max() - t.min()) - r_in, 0.0)
            mid = centre + 0.5 * (t.max() + t.min()) * axis
            ends[k] = [mid - half * axis, mid + half * axis]
            radii[k] = r_in
            excess[k] = float(np.linalg.norm(radial, axis=1).max()) - r_in
        return ends, radii, excess

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
        root = (frames[0] @ self._body_in_root)[:3, 3]  # the placement's pivot: the body frame's origin
        J[:, 0, n] = 1.0
        J[:, 1, n + 1] = 1.0
        J[:, 0, n + 2] = -(points[:, 1] - root[1])  # e_z x (p - root)
        J[:, 1, n + 2] = points[:, 0] - root[0]
        return J

    def body_pose(self, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the body frame when the base lies on the ground at ``base`` (default placement)."""
        return as_base(base).matrix(self.body_axis_height)

    def root_pose(self, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the root frame when the base lies on the ground at ``base`` (default placement)."""
        return self.body_pose(base) @ self._root_in_body

    @cached_property
    def _root_in_body(self) -> np.ndarray:
        """The root frame (4, 4) in the body frame (the inverse of ``body_in_root``, made once)."""
        T = np.linalg.inv(self._body_in_root)
        T.setflags(write=False)
        return T

    @cached_property
    def urdf_text(self) -> str:
        """The URDF (XML) of :attr:`urdf`: the description as the core reads it (a xacro expanded, joint limits
        and aligned frames added), what ROS tools take as ``robot_description``."""
        return self.urdf if _is_xml_text(self.urdf) else _core.read_urdf_file(self.urdf)

    @cached_property
    def description_root(self) -> str:
        """The root link of the description's own URDF (:attr:`description_text`), where ROS tools start its tree
        (/tf places it): ``parts.root``, a frame above it (a link-less dummy root), or, for a tree written from the
        head (re-rooted, :mod:`.description_tree`), a link at the far end of the body."""
        return _core.urdf_root_link(self.description_text)

    @cached_property
    def _description_root_on_body(self) -> tuple[int, np.ndarray]:
        """(k, F): :attr:`description_root` is F (4, 4) in the body frame ``link_names[k]``, the nearest body frame
        above it in :attr:`urdf_text` (every link of the description keeps its frame there; the joints off the
        body are fixed there, moving branch joints at the value they are held at)."""
        import xml.etree.ElementTree as ET

        from .._errors import invariant
        from .description import origin_matrix

        up: dict[str, tuple[ET.Element, str]] = {}
        for joint in ET.fromstring(self.urdf_text).findall("joint"):
            parent, child = joint.find("parent"), joint.find("child")
            if parent is not None and child is not None:
                up[child.get("link", "")] = (joint, parent.get("link", ""))
        on_body = set(self.link_names)
        link, F = self.description_root, np.eye(4)
        while link not in on_body:
            invariant(link in up, f"the description's root {self.description_root!r} is not below the body's root "
                                  f"{self.parts.root!r} in the internal URDF")
            joint, link = up[link]
            invariant(joint.get("type") == "fixed", f"joint {joint.get('name')!r} off the body is not fixed in the "
                                                    "internal URDF")
            F = origin_matrix(joint, f"joint {joint.get('name')!r}") @ F
        F.setflags(write=False)
        return self.link_index(link), F

    def description_root_pose(self, root_pose: npt.ArrayLike, q: npt.ArrayLike | None = None) -> np.ndarray:
        """World pose (4, 4) of :attr:`description_root` when the root frame (``parts.root``) has the world pose
        ``root_pose`` (4, 4) (e.g. :meth:`root_pose`) and the body's joints are at ``q`` (the planner's angles
        (n,); default 0, the home pose): it moves with the joints when the description's tree starts from the head.
        Along a motion, ``q`` (T, n) with ``root_pose`` (T, 4, 4) or (4, 4) gives (T, 4, 4)."""
        T = np.asarray(root_pose, dtype=float)
        if T.shape[-2:] != (4, 4) or T.ndim > 3 or not np.isfinite(T).all():
            raise InputError(f"root_pose must be finite (4, 4) or (T, 4, 4), got shape {T.shape}")
        k, F = self._description_root_on_body
        if q is None or np.ndim(q) <= 1:
            q = np.zeros(self.n_joints) if q is None else joint_vector(q, self.n_joints)
            return T @ (self.body.fk_all(q)[k] @ F)
        qs = finite_array(q, "q", (None, self.n_joints))
        return T @ (self.body.fk_all_many(qs)[:, k] @ F)

    def frames(self, q: npt.ArrayLike, base: BasePlacement | None = None) -> np.ndarray:
        """World poses of every frame in ``link_names`` at joint vector ``q`` (n,): (n_links, 4, 4)."""
        q = joint_vector(q, self.n_joints)
        return self.root_pose(base) @ self.body.fk_all(q)

    def frames_many(self, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """``frames`` along a trajectory: qs (T, n) -> (T, n_links, 4, 4)."""
        return self.body.fk_all_many(qs, self.root_pose(base))

    def _frames_many_checked(self, qs: np.ndarray, base: BasePlacement) -> np.ndarray:
        """:meth:`frames_many` of joint vectors already checked where they entered (float64 (T, n), finite) at a
        placement: the core's batched forward kinematics without checking them again (the library's inner loops,
        e.g. the whole-body solve's checks of its candidates)."""
        return self.body.model.fk_all_many(np.ascontiguousarray(qs, dtype=np.float64), self.root_pose(base))

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




# ------------------------------------------------------------------------------------------------
# construction steps
# ------------------------------------------------------------------------------------------------
def _home_table(home: Mapping[str, float] | None) -> dict[str, float]:
    """The ``[home]`` table checked: joint name -> finite angle (rad, or m for a prismatic branch joint)."""
    if home is None:
        return {}
    if not isinstance(home, Mapping):
        raise InputTypeError(f"home must be a mapping of joint name -> angle (rad), got {type(home).__name__}")
    out = {}
    for name, value in home.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                or not np.isfinite(value):
            raise InputError(f"home.{name} must be a finite angle in rad, got {value!r}")
        out[str(name)] = float(value)
    return out


def _checked_limits(limits: Mapping[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
    checked = {}
    for name, pair in limits.items():
        try:
            lo, hi = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise InputError(f"limits of {name!r} must be [lower, upper] in rad, got {pair!r}") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise InputError(f"limits of {name!r} must be finite with lower < upper, got [{lo}, {hi}]")
        checked[str(name)] = (lo, hi)
    return checked


def _body_text(text: str, xml: str, root: str, head_tip: str, limits: Mapping[str, tuple[float, float]],
               home: Mapping[str, float], where: str) -> tuple[str, TreeChanges, Chain]:
    """The text the core reads for the body ``root`` -> ``head_tip`` (``text``: a path or URDF text; ``xml``: its
    XML), what the tree rewrite changed and the body chain: the robot file's limits first (they are the
    description's angles), then :func:`.description_tree.body_description` (re-rooted, straight at zero, branches
    lumped). The body's ``continuous`` joints need limits (InputError naming them); those off the body do not."""
    checked = _checked_limits(limits)
    if checked:
        xml = with_joint_limits(xml, checked, where)
        text = xml
    rewritten, changes = body_description(xml, root, head_tip, home, where)
    if rewritten is not None:
        text = xml = rewritten
    _check_home_limits(xml, changes, root, head_tip, where)
    raw = _body_chain(text, root, head_tip)
    needed = [n for n, t in zip(raw.joint_names, raw.joint_types) if t == "continuous"]
    if needed:
        with_joint_limits(xml, {}, where, needed=needed)  # raises, naming them
    return text, changes, raw


def _check_home_limits(xml: str, changes: TreeChanges, root: str, head_tip: str, where: str) -> None:
    """InputError for a home angle outside its joint's limits (the straight body must be a pose the robot takes)."""
    if not changes.home:
        return
    chain = _body_chain(xml, root, head_tip)
    for name, value in changes.home:
        j = chain.joint_names.index(name)
        if not chain.lower[j] <= 0.0 <= chain.upper[j]:
            raise InputError(f"{where}: home.{name} = {value:.6g} rad lies outside the joint's limits "
                             f"[{chain.lower[j] + value:.6g}, {chain.upper[j] + value:.6g}]")


def _is_xml_text(text: str) -> bool:
    return text.lstrip().startswith("<")


def _body_chain(text: str, root: str, head_tip: str) -> Chain:
    try:
        return Chain.from_urdf(text, root, head_tip)
    except ValueError as exc:
        raise InputError(f"the robot's body (root {root!r} -> head_tip {head_tip!r}): {exc}") from None


def _joints_before(body: Chain, link_index: int) -> int:
    """How many joints lie between the root and the frame ``link_names[link_index]``."""
    child = np.asarray(body.model.joint_child_links)
    return int(np.sum(child <= link_index))


def _part_slices(body: Chain, root: str, names: Mapping[str, str]) -> list[slice]:
    """The joint slices of the base, neck and head parts (InputError for frames missing or out of order, or a
    part without joints)."""
    link_names = body.link_names
    order = [("root", root)] + [(key, names[key]) for key in ("base_end", "neck_end", "head_tip")]
    for key, name in order:
        if name not in link_names:
            raise InputError(f"{key} {name!r} is not a frame on the chain from the root {root!r} to the head tip "
                             f"{names['head_tip']!r} (frames: {', '.join(link_names)})")
    idx = [link_names.index(name) for _, name in order]
    slices = []
    for (ka, na), (kb, nb), a, b in zip(order, order[1:], idx, idx[1:]):
        if not a < b:
            raise InputError(f"frames out of order: {kb} {nb!r} must come after {ka} {na!r} along the body "
                             "(root -> base_end -> neck_end -> head_tip)")
        start, stop = _joints_before(body, a), _joints_before(body, b)
        part = {"base_end": "base", "neck_end": "neck", "head_tip": "head"}[kb]
        if stop <= start:
            raise InputError(f"the {part} part ({ka} {na!r} -> {kb} {nb!r}) has no joint")
        slices.append(slice(start, stop))
    return slices


def as_robot(robot: SnakeRobot) -> SnakeRobot:
    """``robot`` itself if it is a SnakeRobot, else TypeError (the check every planning function makes)."""
    if not isinstance(robot, SnakeRobot):
        raise InputTypeError(f"robot must be a SnakeRobot, got {type(robot).__name__}")
    return robot


def as_base(base: BasePlacement | None) -> BasePlacement:
    """``base`` if it is a BasePlacement, the default placement for None, else TypeError."""
    if base is None:
        return BasePlacement()
    if not isinstance(base, BasePlacement):
        raise InputTypeError(f"base must be a BasePlacement or None, got {type(base).__name__}")
    return base
