"""`SnakeRobot`: a snake robot from its description and three frame names; the immutable model of its body.

The one place that knows how the body divides into base, neck and head (paper, Section 2) and what it looks like;
everything else asks it, and nothing else names a link or holds a dimension of a particular robot. The model is
built once (:mod:`.robot_build`) and holds the description it came from, its parts, joints, limits, lengths and
masses. The algorithms on it are free functions that its methods call: forward kinematics, Jacobians and the root's
pose (:mod:`.frames`), the collision shapes and what derives from them (:mod:`.robot_geometry`), the straight body
(:mod:`.straight_body`) and the parts' links (:mod:`.robot_parts`).

A robot is a URDF plus three frames (links or fixed marker frames) along one serial chain from the root:

* base = the joints from ``root`` to ``base_end`` (the paper's P0 is the origin of ``base_end``);
* neck = the joints from ``base_end`` to ``neck_end`` (B0, the head part's base frame);
* head = the joints from ``neck_end`` to ``head_tip`` (the head link frame; its x-axis is the head's direction).

The snake lies straight at q = 0 along the *body frame*'s x-axis, z up, whatever way the URDF's link frames turn
(:mod:`.body_frame`). Each joint turns about the body frame's z-axis (a *yaw* joint: it bends the body in the
ground plane while the body lies flat) or its y-axis (a *pitch* joint: it lifts the body off the ground). Frames
whose orientation the planner reads (base_end, neck_end, the lift frame and head_tip) are given aligned twins,
fixed marker frames named ``NAME__aligned``, when the URDF's turn another way.
"""
from __future__ import annotations

import os
from functools import cached_property
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import numpy.typing as npt

from .. import _core
from .._errors import InputTypeError
from ..geometry.shapes import ShapeSet
from . import frames as kin
from . import robot_geometry as geo
from . import robot_parts as rp
from . import straight_body as sb
from .body_frame import ALIGNED_SUFFIX, Straightness, straightness
from .chain import Chain
from .placement import BasePlacement, GroundFrame
from .robot_build import build, check_snake, is_xml_text
from .robot_file import default_robot_file, default_urdf_path, read_robot_file
from .robot_parts import RobotParts
from .straight_body import PITCH, YAW

__all__ = ["SnakeRobot", "BasePlacement", "GroundFrame", "RobotParts", "as_robot", "as_base", "default_robot_file",
           "default_urdf_path", "YAW", "PITCH", "ALIGNED_SUFFIX"]


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
        built = build(urdf, base_end=base_end, neck_end=neck_end, head_tip=head_tip, root=root, source=source,
                      head_axis=head_axis, packages=packages, limits=limits, xacro_args=xacro_args,
                      robot_file=robot_file, trust_xacro=trust_xacro, home=home, inertia=inertia, density=density)
        #: What ``inertia = "from_shapes"`` moved (:class:`.mass_properties.InertiaRewrite`; None for "urdf").
        self.inertia_rewrite = built.inertia_rewrite
        #: The head tip frame's axis that points where the head looks (in the URDF's head_tip frame).
        self.head_axis = head_axis
        #: The frames as the user named them (``parts`` may name their aligned twins).
        self.user_frames = built.user_frames
        #: The head's reachability map file named by the robot file (None: none given).
        self.map_path = None if map_path is None else Path(map_path)
        #: Where the robot came from (a robot file's path), for messages and reports.
        self.source = built.source
        self._meshes = built.meshes
        #: The description's URDF as read (a xacro expanded): what ROS tools take as ``robot_description``.
        self.description_text = built.description_text
        #: What the tree rewrite changed (:class:`.description_tree.TreeChanges`: re-rooting, home pose, lumping).
        self.tree_changes = built.tree_changes
        #: The home pose (:class:`.description_tree.JointOffsets`): the description's angles minus the planner's.
        self.joint_offsets = built.joint_offsets
        #: The URDF text the core reads: the description re-rooted, straightened at its home pose, its branches
        #: lumped, with limits and aligned frames (:mod:`.description_tree`; a path when unchanged).
        self.urdf = built.urdf
        #: The whole-body chain, root to head tip (:class:`.chain.Chain`).
        self.body = built.body
        self._body_in_root = built.body_in_root
        #: The parts and the frames that bound them (:class:`.robot_parts.RobotParts`).
        self.parts = built.parts
        self._chains: dict[tuple[str, str], Chain] = {}
        check_snake(self)

    # --- construction ---------------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str,
                  root: str | None = None, head_axis: str = "x",
                  packages: Mapping[str, str | os.PathLike] | None = None,
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
        against the tree where it must (:mod:`.description_tree`). Raises :class:`~snakehead.InputError` for frames
        that are missing or out of order, a part without joints, or a body that is not a snake (straight at q = 0,
        revolute joints about two perpendicular axes across it, collision shapes on the base). ``inertia``:
        ``"urdf"`` (the description's ``<inertial>``) or ``"from_shapes"`` (the inertias recomputed from the
        collision shapes at uniform density over each rigid segment of links fixed together, with the segment's
        URDF mass or, given ``density`` in kg/m^3, the mass that density gives: :mod:`.mass_properties`).
        """
        return cls(urdf, base_end=base_end, neck_end=neck_end, head_tip=head_tip, root=root, head_axis=head_axis,
                   packages=packages, limits=limits, xacro_args=xacro_args, trust_xacro=trust_xacro, home=home,
                   inertia=inertia, density=density)

    @classmethod
    def from_file(cls, path: str | os.PathLike, *, trust_xacro: bool = False, inside: Path | None = None
                  ) -> "SnakeRobot":
        """A robot from a robot file (TOML; :mod:`snakehead.model.robot_file`). ``trust_xacro``: as in
        :meth:`from_urdf` (a robot file reached through a scene file is never trusted unless the caller says so).
        ``inside``: the folder its urdf, map and packages must lie in (a robot named by a scene file: the scene's)."""
        spec = read_robot_file(path, inside)
        return cls(spec.urdf, base_end=spec.base_end, neck_end=spec.neck_end, head_tip=spec.head_tip,
                   root=spec.root, map_path=spec.map, source=os.fspath(path), head_axis=spec.head_axis,
                   packages=spec.packages, limits=spec.limits, xacro_args=spec.xacro_args, robot_file=path,
                   trust_xacro=trust_xacro, home=spec.home, inertia=spec.inertia, density=spec.density)

    @classmethod
    def default(cls) -> "SnakeRobot":
        """The shipped 16-joint robot of the paper (``snake16.toml``: Table 3, with its head's map)."""
        return cls.from_file(default_robot_file())

    @property
    def description_arguments(self) -> dict[str, Any]:
        """The arguments this robot's description was read with (``urdf``, ``root``, ``head_axis``, ``packages``,
        ``limits``, ``xacro_args``, ``source``, ``robot_file``, ``trust_xacro``, ``home``, ``inertia``,
        ``density``; a copy): with :attr:`user_frames` and :attr:`map_path`, what builds the same robot again, e.g.
        in another process."""
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

    @cached_property
    def urdf_text(self) -> str:
        """The URDF (XML) of :attr:`urdf`: the description as the core reads it (a xacro expanded, joint limits
        and aligned frames added), what ROS tools take as ``robot_description``."""
        return self.urdf if is_xml_text(self.urdf) else _core.read_urdf_file(self.urdf)

    @cached_property
    def description_root(self) -> str:
        """The root link of the description's own URDF (:attr:`description_text`), where ROS tools start its tree
        (/tf places it): ``parts.root``, a frame above it (a link-less dummy root), or, for a tree written from the
        head (re-rooted, :mod:`.description_tree`), a link at the far end of the body."""
        return _core.urdf_root_link(self.description_text)

    def __repr__(self) -> str:
        where = self.source or (self.urdf if not self.urdf.lstrip().startswith("<") else "<URDF text>")
        base, neck, head = (s.stop - s.start for s in (self.parts.base, self.parts.neck, self.parts.head))
        return f"SnakeRobot({where!r}, {self.n_joints} joints: base {base}, neck {neck}, head {head})"

    # --- joints and parts -----------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return self.body.n_joints

    @property
    def joint_names(self) -> list[str]:
        return self.body.joint_names

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
        """The neck joints that lift and aim it: from the neck's first pitch joint to the neck's end
        (:func:`.robot_parts.lift_joints`)."""
        return rp.lift_joints(self)

    @property
    def lift_frame(self) -> str:
        """Where the neck's lifting begins: the frame just before the neck's first pitch joint (``base_end`` when
        the neck begins with a pitch joint; ``neck_end`` when it has none). The neck's Eqs. 18-22 pivot on it."""
        return rp.lift_frame(self)

    @property
    def lift_chain(self) -> Chain:
        """The lifting part of the neck, :attr:`lift_frame` -> neck_end (the whole neck on the default robot)."""
        return self.sub_chain(self.lift_frame, self.parts.neck_end)

    @cached_property
    def base_links(self) -> np.ndarray:
        """Indices (link_names) of the base part's links that carry a body (mass or shapes): those before base_end."""
        return rp.part_bodies(self, rp.part_links(self, None, self.parts.base_end))

    @cached_property
    def neck_links(self) -> np.ndarray:
        """Indices (link_names) of the neck part's bodies: from base_end up to neck_end."""
        return rp.part_bodies(self, rp.part_links(self, self.parts.base_end, self.parts.neck_end))

    @cached_property
    def head_links(self) -> np.ndarray:
        """Indices (link_names) of the head part's bodies: from neck_end to the head tip."""
        return rp.part_bodies(self, rp.part_links(self, self.parts.neck_end, None))

    @cached_property
    def lifted_links(self) -> np.ndarray:
        """Indices (link_names) of the links with collision shapes after the base (neck and head): those that lift
        off the ground."""
        return self.shaped_links[self.shaped_links >= self.link_index(self.parts.base_end)]

    # --- the straight body at q = 0 (along the body frame's x-axis) -------------------------------
    @property
    def body_in_root(self) -> np.ndarray:
        """The body frame (4, 4) in the root frame: x along the straight body towards the head, z up (the root
        frame itself for snakes written along x with z up)."""
        return self._body_in_root.copy()

    @cached_property
    def root_in_body(self) -> np.ndarray:
        """The root frame (4, 4) in the body frame (the inverse of :attr:`body_in_root`; read-only)."""
        T = np.linalg.inv(self._body_in_root)
        T.setflags(write=False)
        return T

    @cached_property
    def straight_frames(self) -> np.ndarray:
        """Every frame (n_links, 4, 4) at q = 0 in the body frame (the body along its x-axis from the origin, z up;
        read-only)."""
        return sb.straight_frames(self.body, self._body_in_root)

    @cached_property
    def joint_axes(self) -> np.ndarray:
        """(n, 3) each joint's axis in the body frame at q = 0."""
        return sb.joint_axes(self.body, self.straight_frames)

    @cached_property
    def joint_frames(self) -> np.ndarray:
        """(n,) index (link_names) of each joint's frame: the link it moves, whose frame sits on the joint."""
        child = np.asarray(self.body.model.joint_child_links, dtype=np.intp)
        child.setflags(write=False)
        return child

    @cached_property
    def joint_kinds(self) -> tuple[str, ...]:
        """Each joint's kind: ``"yaw"`` (axis +-z of the body frame) or ``"pitch"`` (+-y)."""
        return sb.joint_kinds(self.joint_axes)

    @cached_property
    def joint_signs(self) -> np.ndarray:
        """(n,) +1 where the axis is +z (yaw) or +y (pitch), -1 where it is -z or -y."""
        return sb.joint_signs(self.joint_axes)

    @cached_property
    def axis_deviations(self) -> np.ndarray:
        """(n,) each joint axis's angle (rad) from the nearest of the body frame's y- and z-axes at q = 0 (the
        description's true axes; the yaw/pitch split reads them within :data:`.body_frame.AXIS_TOLERANCE_DEG`)."""
        return sb.axis_deviations(self.joint_axes)

    @cached_property
    def straightness(self) -> Straightness:
        """How far the body at q = 0 (the description's home pose) is from its line: the largest side offset of a
        frame (m) and which frame. Offsets within the body's half-section are accepted (CAD exports place joint
        frames a few mm to the side)."""
        return straightness(self.body)[2]

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
        return sb.joint_arc_lengths(self.body, self.straight_frames)

    def frame_arc_length(self, name: str) -> float:
        """A frame's distance from the root frame along the straight body (m)."""
        F = self.straight_frames
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
        return sb.link_lengths(self.straight_frames)

    @property
    def head_link_length(self) -> float:
        """Length of the head link: from the last joint to the head tip (m)."""
        return float(self.body_length - self.joint_arc_lengths[-1])

    # --- mass (per entry of link_names) -----------------------------------------------------------
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

    # --- geometry (:mod:`.robot_geometry`) --------------------------------------------------------
    @cached_property
    def geometry(self) -> ShapeSet:
        """The collision shapes of the links (every URDF <collision> element: boxes, cylinders, spheres, meshes as
        their convex hulls), on the frames of :attr:`link_names`."""
        return geo.collision_shapes(self.body, self._meshes)

    @cached_property
    def shaped_links(self) -> np.ndarray:
        """Indices (link_names) of the frames that have collision shapes, ascending."""
        return self.geometry.frames_with_shapes

    @cached_property
    def shaped_base_links(self) -> np.ndarray:
        """Indices (link_names) of the base part's links that have collision shapes, ascending."""
        return geo.shaped_base_links(self)

    @cached_property
    def body_axis_height(self) -> float:
        """Height (m) of the body axis above the ground when the base lies on it: the base links' collision shapes
        rest on the ground (their lowest points at z = 0) with every joint at zero."""
        return geo.body_axis_height(self)

    @cached_property
    def half_section(self) -> float:
        """The base's narrowest half-width across the body (m): the thinnest module's radius."""
        return geo.half_section(self)

    @cached_property
    def link_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The shaped links (k,) and points (k, M, 3) in each link's frame whose convex hull is the link's shapes
        (cylinders and spheres as polygons of 16 sides; padded by repetition): for bounds, centres and drawing."""
        return geo.link_points(self)

    @cached_property
    def distal_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The shaped links (k,) and, in each link's frame, the points (k, M, 3) of its shapes farthest along the
        body at q = 0: where a link pitched up about its proximal joint leaves the ground last
        (:func:`.robot_geometry.distal_points`)."""
        return geo.distal_points(self)

    @cached_property
    def link_capsules(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per frame of :attr:`link_names`, a capsule inside its collision shapes along the body: end points
        (n_links, 2, 3) in the link frame, radius (n_links,) m and excess (n_links,) m
        (:func:`.robot_geometry.link_capsules`)."""
        return geo.link_capsules(self)

    @cached_property
    def self_collision_pairs(self) -> np.ndarray:
        """(P, 2) the pairs of shapes (indices into ``geometry.shapes``) that self-collision checks: on links two or
        more joints apart (links one joint apart touch at it; links of one rigid module never move apart)."""
        return geo.self_collision_pairs(self)

    def lowest_z(self, frames: np.ndarray, links: np.ndarray | None = None) -> np.ndarray:
        """Lowest world z (m) of the collision shapes of ``links`` (default every shaped link): (T, k), from frames
        (T, n_links, 4, 4) (e.g. :meth:`frames_many`)."""
        return geo.lowest_z(self, frames, links)

    def lowest_points(self, frames: np.ndarray, links: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The lowest candidate ground-contact points of the shapes of ``links`` (default every shaped link):
        world points (T, N, 3) and the link (N,) of each (:meth:`ShapeSet.lowest_points`)."""
        return geo.lowest_points(self, frames, links)

    def hull_points(self, frames: np.ndarray) -> np.ndarray:
        """World points (T, k, M, 3) of :attr:`link_points` for frames (T, n_links, 4, 4)."""
        return geo.hull_points(self, frames)

    def link_centres(self, frames: np.ndarray) -> np.ndarray:
        """World centres (T, k, 3) of the shaped links' capsules (their shapes' middle along the body)."""
        return geo.link_centres(self, frames)

    def lowest_point_per_link(self, frames: np.ndarray, links: np.ndarray) -> np.ndarray:
        """The lowest world point (k, 3) of each link's shapes, from the frames (n_links, 4, 4) of one
        configuration (box corner, cylinder rim point, sphere bottom, hull vertex)."""
        return geo.lowest_point_per_link(self, frames, links)

    # --- kinematics (:mod:`.frames`) ----------------------------------------------------------------
    def body_pose(self, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the body frame when the base lies on the ground at ``base`` (default placement)."""
        return kin.body_pose(self, as_base(base))

    def root_pose(self, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the root frame when the base lies on the ground at ``base`` (default placement)."""
        return kin.root_pose(self, as_base(base))

    def frames(self, q: npt.ArrayLike, base: BasePlacement | None = None) -> np.ndarray:
        """World poses of every frame in ``link_names`` at joint vector ``q`` (n,): (n_links, 4, 4)."""
        return kin.forward_kinematics(self, q, as_base(base))

    def frames_many(self, qs: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """``frames`` along a trajectory: qs (T, n) -> (T, n_links, 4, 4)."""
        return kin.forward_kinematics_many(self, qs, as_base(base))

    def frame(self, q: np.ndarray, name: str, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of one named frame (a link or a marker)."""
        return kin.frame_placement(self, q, name, as_base(base))

    def head_pose(self, q: np.ndarray, base: BasePlacement | None = None) -> np.ndarray:
        """World pose (4, 4) of the head tip: its x-axis is the head's direction."""
        return kin.frame_placement(self, q, self.parts.head_tip, as_base(base))

    def joint_axes_world(self, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World axes (n, 3) and origins (n, 3) of the joints, from the world frames (n_links, 4, 4) of one
        configuration (:meth:`frames`)."""
        return kin.joint_axes_world(self, frames)

    def point_jacobians(self, frames: np.ndarray, points: np.ndarray, links: Any) -> np.ndarray:
        """d(point)/d(q, x, y, yaw) of world points rigidly attached to ``links`` (indices into link_names), for
        the configuration of ``frames`` (n_links, 4, 4): (P, 3, n + 3); the last three columns are the base
        placement's x, y and yaw (:func:`.frames.point_jacobians`)."""
        return kin.point_jacobians(self, frames, points, links)

    @cached_property
    def _description_root_on_body(self) -> tuple[int, np.ndarray]:
        """:func:`.frames.description_root_on_body`, made once."""
        return kin.description_root_on_body(self)

    def description_root_pose(self, root_pose: npt.ArrayLike, q: npt.ArrayLike | None = None) -> np.ndarray:
        """World pose (4, 4) of :attr:`description_root` when the root frame has the world pose ``root_pose`` (e.g.
        :meth:`root_pose`) and the joints are at ``q`` (default 0; :func:`.frames.description_root_pose`): it moves
        with the joints when the description's tree starts from the head."""
        return kin.description_root_pose(self, root_pose, q, self._description_root_on_body)

    def random_configuration(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """Uniform within the joint limits, (n,)."""
        return self.body.random_configuration(rng)


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
