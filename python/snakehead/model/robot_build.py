"""Building a robot's model from its description, and the checks that it is a snake.

:func:`build` reads the description (a URDF or a xacro expanded; :mod:`.description`), recomputes its inertias
when asked (:mod:`.mass_properties`), adds the robot file's joint limits, re-roots it at ``root`` and straightens
it at its home pose with its branches lumped (:mod:`.description_tree`), splits the body into its parts
(:mod:`.robot_parts`), finds the body frame and adds aligned twins of the frames the planner reads
(:mod:`.body_frame`). :func:`check_snake` then checks the built robot: shapes on the base, a straight body, joints
about the body's y- or z-axis, a mass.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from .. import _core
from .._errors import InputError, InputTypeError
from .body_frame import AXIS_TOLERANCE_DEG, HEAD_AXES, STRAIGHT_TOLERANCE, NotStraight, aligned_frames, body_frame
from .chain import Chain, check_utf8
from .description import MeshResolver, read_description, with_joint_limits
from .description_tree import JointOffsets, TreeChanges, body_description
from .mass_properties import InertiaRewrite, rewrite_inertia
from .robot_parts import RobotParts, joints_before, part_slices

if TYPE_CHECKING:  # robot.py builds on this module
    from .robot import SnakeRobot

__all__ = ["BuiltRobot", "build", "urdf_source", "frame_name", "home_table", "checked_limits", "body_text",
           "check_home_limits", "is_xml_text", "body_chain", "check_snake", "check_straight"]


@dataclass(frozen=True)
class BuiltRobot:
    """What :func:`build` reads from a description: the data a :class:`~snakehead.model.robot.SnakeRobot` holds
    (its attributes of the same names)."""

    inertia_rewrite: InertiaRewrite | None
    user_frames: dict[str, str]
    source: str | None
    meshes: MeshResolver
    description_text: str
    tree_changes: TreeChanges
    joint_offsets: JointOffsets
    urdf: str
    body: Chain
    body_in_root: np.ndarray
    parts: RobotParts


def build(urdf: str | os.PathLike, *, base_end: str, neck_end: str, head_tip: str, root: str | None,
          source: str | None, head_axis: str, packages: Mapping[str, str | os.PathLike] | None,
          limits: Mapping[str, tuple[float, float]] | None, xacro_args: Mapping[str, object] | None,
          robot_file: str | os.PathLike | None, trust_xacro: bool, home: Mapping[str, float] | None,
          inertia: str, density: float | None) -> BuiltRobot:
    """The model of the robot the description ``urdf`` and its frames give (the arguments of
    :meth:`SnakeRobot.from_urdf`); InputError for a description or frames that do not make one."""
    description = read_description(urdf_source(urdf), xacro_args, packages=packages, robot_file=robot_file,
                                   trust_xacro=trust_xacro)
    description, rewrite = rewrite_inertia(description, inertia, density)  # <inertial> from the shapes, if asked
    names = {"base_end": frame_name(base_end, "base_end"), "neck_end": frame_name(neck_end, "neck_end"),
             "head_tip": frame_name(head_tip, "head_tip")}
    if head_axis not in HEAD_AXES:
        raise InputError(f"head_axis must be one of {', '.join(HEAD_AXES)}, got {head_axis!r}")
    meshes = MeshResolver(description.folder, description.folders)
    text = description.text
    check_utf8(text, "urdf")
    root = _core.urdf_root_link(text) if root is None else frame_name(root, "root")  # the core checks the text
    description_text = text if is_xml_text(text) else _core.read_urdf_file(text)
    text, tree_changes, raw = body_text(text, description_text, root, names["head_tip"], limits or {},
                                        home_table(home), description.source)
    joint_offsets = JointOffsets(np.array([dict(tree_changes.home).get(j, 0.0) for j in raw.joint_names]))
    parts = part_slices(raw, root, names)
    body_in_root = body_frame(raw)
    aligned, text = aligned_frames(text, raw, body_in_root, parts, names, head_axis)
    body = raw if aligned == names else body_chain(text, root, aligned["head_tip"])
    return BuiltRobot(
        inertia_rewrite=rewrite, user_frames=dict(names), source=source or description.source,
        meshes=meshes, description_text=description_text,
        tree_changes=tree_changes, joint_offsets=joint_offsets, urdf=text, body=body, body_in_root=body_in_root,
        parts=RobotParts(base=parts[0], neck=parts[1], head=parts[2], root=root, base_end=aligned["base_end"],
                         neck_end=aligned["neck_end"], head_tip=aligned["head_tip"]))


def urdf_source(urdf: Any) -> str:
    """``urdf`` (a path or the XML) as a str the core takes; InputTypeError for anything else, InputError for text
    that is not UTF-8."""
    if isinstance(urdf, os.PathLike):
        urdf = os.fspath(urdf)
    if not isinstance(urdf, str):
        raise InputTypeError(f"urdf must be a path or an XML string, got {type(urdf).__name__}")
    check_utf8(urdf, "urdf")  # before the core sees it (urdf_root_link below)
    return urdf


def frame_name(value: Any, what: str) -> str:
    """``value`` checked as the name of a frame (a non-empty UTF-8 str)."""
    if not isinstance(value, str) or not value:
        raise InputTypeError(f"{what} must be a frame name (a non-empty str), got {value!r}")
    check_utf8(value, what)
    return value


def home_table(home: Mapping[str, float] | None) -> dict[str, float]:
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


def checked_limits(limits: Mapping[str, tuple[float, float]]) -> dict[str, tuple[float, float]]:
    """The ``[limits]`` table checked: joint name -> (lower, upper) rad, finite with lower < upper."""
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


def body_text(text: str, xml: str, root: str, head_tip: str, limits: Mapping[str, tuple[float, float]],
              home: Mapping[str, float], where: str) -> tuple[str, TreeChanges, Chain]:
    """The text the core reads for the body ``root`` -> ``head_tip`` (``text``: a path or URDF text; ``xml``: its
    XML), what the tree rewrite changed and the body chain: the robot file's limits first (they are the
    description's angles), then :func:`.description_tree.body_description` (re-rooted, straight at zero, branches
    lumped). The body's ``continuous`` joints need limits (InputError naming them); those off the body do not."""
    checked = checked_limits(limits)
    if checked:
        xml = with_joint_limits(xml, checked, where)
        text = xml
    rewritten, changes = body_description(xml, root, head_tip, home, where)
    if rewritten is not None:
        text = xml = rewritten
    check_home_limits(xml, changes, root, head_tip, where)
    raw = body_chain(text, root, head_tip)
    needed = [n for n, t in zip(raw.joint_names, raw.joint_types) if t == "continuous"]
    if needed:
        with_joint_limits(xml, {}, where, needed=needed)  # raises, naming them
    return text, changes, raw


def check_home_limits(xml: str, changes: TreeChanges, root: str, head_tip: str, where: str) -> None:
    """InputError for a home angle outside its joint's limits (the straight body must be a pose the robot takes)."""
    if not changes.home:
        return
    chain = body_chain(xml, root, head_tip)
    for name, value in changes.home:
        j = chain.joint_names.index(name)
        if not chain.lower[j] <= 0.0 <= chain.upper[j]:
            raise InputError(f"{where}: home.{name} = {value:.6g} rad lies outside the joint's limits "
                             f"[{chain.lower[j] + value:.6g}, {chain.upper[j] + value:.6g}]")


def is_xml_text(text: str) -> bool:
    """Whether ``text`` is URDF XML itself rather than a path to it."""
    return text.lstrip().startswith("<")


def body_chain(text: str, root: str, head_tip: str) -> Chain:
    """The chain ``root`` -> ``head_tip`` of the URDF ``text`` (a path or the XML); InputError naming the body."""
    try:
        return Chain.from_urdf(text, root, head_tip)
    except ValueError as exc:
        raise InputError(f"the robot's body (root {root!r} -> head_tip {head_tip!r}): {exc}") from None


def check_snake(robot: SnakeRobot) -> None:
    """InputError unless the built robot is a snake: collision shapes on every rigid segment of the base, a base
    with length, a body straight at q = 0 (:class:`.body_frame.NotStraight` otherwise), every joint about the body
    frame's y- or z-axis within :data:`.body_frame.AXIS_TOLERANCE_DEG`, and a mass."""
    shaped = set(robot.shaped_links.tolist())
    segments: dict[int, list[int]] = {}  # the base's rigid segments: links between the same two joints
    for i in robot.base_links.tolist():
        segments.setdefault(joints_before(robot.body, i), []).append(i)
    bare = [robot.link_names[i] for links in segments.values() if not shaped & set(links) for i in links]
    if not segments or bare:
        raise InputError("every rigid segment of the base needs a <collision> shape (the base lies on the ground "
                         f"on them); none on {bare or 'the base'}")
    if not robot.base_length > STRAIGHT_TOLERANCE:  # the base arc's radius would be 0
        raise InputError(f"the base part (root {robot.parts.root!r} -> base_end {robot.user_frames['base_end']!r}) "
                         f"is {1000 * robot.base_length:.3g} mm long along the body: put base_end further along it")
    check_straight(robot)  # first: a curled body's axes are off its line too
    off_deg = np.degrees(robot.axis_deviations)
    for j in np.flatnonzero(off_deg > AXIS_TOLERANCE_DEG):
        a = robot.joint_axes[j]
        message = (f"joint {robot.joint_names[j]!r} turns about {np.round(a, 4).tolist()} in the body frame (x "
                   f"along the body, z up), {off_deg[j]:.2f} deg off its y- or z-axis (at most "
                   f"{AXIS_TOLERANCE_DEG:g} deg): a snake's joints turn about its z-axis (yaw) or y-axis (pitch)")
        if robot.straightness.offset > STRAIGHT_TOLERANCE:  # a body bent at zero: a home pose may straighten it
            raise NotStraight(message + "; if the body is not straight at zero, give the robot file a [home] table",
                              robot.body, robot.joint_offsets.home, robot.half_section)
        raise InputError(message)
    if not robot.total_mass > 0:
        raise InputError("the robot has no mass (no <inertial> on its links): stability needs the masses")


def check_straight(robot: SnakeRobot) -> None:
    """:class:`.body_frame.NotStraight` unless the body at q = 0 lies on its line within its half-section, its frames
    in order along it."""
    st = robot.straightness
    if st.out_of_order or st.offset > robot.half_section:
        where = (f"frame {st.out_of_order[0]!r} lies behind the one before it" if st.out_of_order else
                 f"frame {st.frame!r} is {1000 * st.offset:.2f} mm off the body's line (at most the body's "
                 f"half-section, {1000 * robot.half_section:.1f} mm)")
        raise NotStraight(f"the body does not lie straight at its zero: {where}; give the robot file a [home] table "
                          "of the joint angles at which it lies straight (`snakehead info` suggests one)",
                          robot.body, robot.joint_offsets.home, robot.half_section)
