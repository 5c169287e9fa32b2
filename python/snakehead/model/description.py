"""A robot description as it is published, made ready for the core: xacro expanded, ``continuous`` joints given
limits, mesh paths resolved and collision meshes loaded as their convex hulls.

* :func:`read_description` -- the URDF text of a ``.urdf`` file, a ``.xacro`` file (expanded without ROS by the
  ``xacro`` package, with arguments, without running the file's code: :mod:`.xacro_expansion`) or the XML itself,
  the folder its relative paths start from and the folders it may read (:mod:`.robot_folders`).
* :func:`with_joint_limits` -- ``continuous`` joints turned into revolute ones with the limits a robot file gives
  (a snake's planner needs bounded joints; a continuous joint without limits is an error naming it).
* :class:`MeshResolver` -- ``package://NAME/...``, ``file://...`` and relative mesh paths to files inside the
  robot's folders: the robot file's ``[packages]`` first, then ``ROS_PACKAGE_PATH``;
  :func:`~snakehead.geometry.meshes.convex_hull_vertices` loads one with trimesh.

Errors are :class:`snakehead.InputError` naming the file and the element.
"""
from __future__ import annotations

import math
import os
import re
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np
from scipy.spatial.transform import Rotation

from .._errors import InputError, InputTypeError
from .._validate import input_file
from ..geometry.meshes import MAX_MESH_BYTES
from .robot_folders import MAX_DESCRIPTION_BYTES, RobotFolders
from .xacro_expansion import expand_xacro

__all__ = ["Description", "read_description", "JOINT_TYPES", "GEOMETRY_KINDS", "check_description", "with_joint_limits",
           "origin_matrix", "set_origin", "add_fixed_frames", "MeshResolver"]


@dataclass(frozen=True)
class Description:
    """A description's URDF text and the folder its relative mesh paths start from (None for XML given inline)."""

    text: str
    folder: Path | None
    source: str
    folders: RobotFolders = field(default_factory=RobotFolders)


def _is_xml(urdf: str) -> bool:
    return urdf.lstrip().startswith("<")


def read_description(urdf: str | os.PathLike[str], xacro_args: Mapping[str, object] | None = None, *,
                     packages: Mapping[str, str | os.PathLike[str]] | None = None,
                     robot_file: str | os.PathLike[str] | None = None, trust_xacro: bool = False) -> Description:
    """The URDF text of ``urdf``: a path to a ``.urdf`` or ``.xacro`` file, or the XML itself. ``packages`` and
    ``robot_file`` (the robot file it came from) add to the folders the description may read
    (:class:`.robot_folders.RobotFolders`). A xacro is expanded without running code unless ``trust_xacro``
    (:mod:`.xacro_expansion`)."""
    if isinstance(urdf, os.PathLike):
        urdf = os.fspath(urdf)
    if not isinstance(urdf, str):
        raise InputTypeError(f"urdf must be a path or an XML string, got {type(urdf).__name__}")
    if not isinstance(trust_xacro, bool):
        raise InputTypeError(f"trust_xacro must be True or False, got {trust_xacro!r}")
    package_folders = {str(k): Path(v) for k, v in (packages or {}).items()}
    extra = () if robot_file is None else (Path(robot_file).resolve().parent,)
    if _is_xml(urdf):
        if xacro_args:
            raise InputError("xacro_args are given but the description is URDF text, not a .xacro file")
        check_description(urdf, "<URDF text>")
        return Description(urdf, None, "<URDF text>", RobotFolders(extra, package_folders))
    path = input_file(urdf, "the robot's description", MAX_DESCRIPTION_BYTES)
    folder = path.resolve().parent
    folders = RobotFolders((folder, *extra), package_folders)
    if path.suffix == ".xacro":
        text = expand_xacro(path, _xacro_mappings(xacro_args or {}), folders, trusted=trust_xacro)
        check_description(text, os.fspath(path))
        return Description(text, folder, os.fspath(path), folders)
    if xacro_args:
        raise InputError(f"xacro_args are given but {os.fspath(path)!r} is not a .xacro file")
    # the core reads URDF files itself (with its own checks: the size, the encoding, the nesting); the content is
    # checked here first, for messages that name the element (a file that is not UTF-8 is left to the core)
    try:
        check_description(path.read_text(encoding="utf-8"), os.fspath(path))
    except UnicodeDecodeError:
        pass
    return Description(os.fspath(path), folder, os.fspath(path), folders)


def _xacro_mappings(args: Mapping[str, object]) -> dict[str, str]:
    """xacro's arguments as the strings it takes (booleans as ``true``/``false``)."""
    mappings = {}
    for key, value in args.items():
        if not isinstance(value, (str, int, float, bool)):
            raise InputError(f"xacro argument {key!r} must be a string or a number, got {value!r}")
        mappings[str(key)] = str(value).lower() if isinstance(value, bool) else str(value)
    return mappings


def _xml_root(text: str, where: str) -> ET.Element:
    try:
        return ET.fromstring(text)
    except ET.ParseError as exc:
        raise InputError(f"malformed URDF ({where}): {exc}") from None


# --- the description's content, each problem named by its element ----------------------------------------------
#: The joint types a URDF may give (urdfdom's).
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: The geometry elements a URDF shape may be (urdfdom's).
GEOMETRY_KINDS = ("box", "cylinder", "sphere", "mesh")
#: A number as urdfdom reads one (a C++ stream in the classic locale): no nan, inf, hex or digit separators.
_NUMBER = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _scalar(text: str | None) -> float | None:
    """The finite number urdfdom reads from an attribute's text, else None (nan, inf, words, trailing spaces)."""
    if text is None or not _NUMBER.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def _vector(text: str | None) -> list[float] | None:
    """The three finite numbers of a vector attribute as urdfdom reads it (separated by spaces), else None."""
    if text is None:
        return None
    pieces = [piece for piece in text.split(" ") if piece]
    values = [_scalar(piece) for piece in pieces]
    return [v for v in values if v is not None] if len(values) == 3 and None not in values else None


def _check_origin(parent: ET.Element, what: str) -> None:
    origin = parent.find("origin")  # urdfdom reads the first <origin> only
    if origin is None:
        return
    for key in ("xyz", "rpy"):
        text = origin.get(key)
        if text is not None and _vector(text) is None:
            raise InputError(f"{what} <origin> {key} must be 3 finite numbers separated by spaces, got {text!r}")


def _check_geometry(shape: ET.Element, what: str) -> None:
    """A <visual> or <collision> element's <origin> and <geometry>: one shape of a known kind, its numbers readable;
    a collision mesh's scale positive (the core takes no mirrored or flattened collision mesh)."""
    _check_origin(shape, what)
    geometry = shape.find("geometry")
    if geometry is None:
        raise InputError(f"{what} has no <geometry> shape (no <geometry> element)")
    kinds = list(geometry)
    if not kinds:
        raise InputError(f"{what} has no <geometry> shape (an empty <geometry>: give it a <box>, <cylinder>, "
                         "<sphere> or <mesh>)")
    element = kinds[0]  # urdfdom reads the first
    kind = element.tag
    if kind not in GEOMETRY_KINDS:
        raise InputError(f"{what} has an unknown shape <{kind}> (box, cylinder, sphere or mesh)")
    if kind == "box":
        size = element.get("size")
        if size is None:
            raise InputError(f"{what} <box> has no size attribute (three numbers of metres)")
        if _vector(size) is None:
            raise InputError(f"{what} <box> size must be 3 finite numbers separated by spaces, got {size!r}")
    elif kind in ("cylinder", "sphere"):
        for key in ("radius", "length") if kind == "cylinder" else ("radius",):
            text = element.get(key)
            if text is None:
                raise InputError(f"{what} <{kind}> has no {key} attribute")
            if _scalar(text) is None:
                raise InputError(f"{what} <{kind}> {key} must be a finite number of metres, got {text!r}")
    else:
        filename = element.get("filename")
        if filename is None or not filename.strip():
            raise InputError(f"{what} <mesh> has no filename")
        scale_text = element.get("scale")
        if scale_text is None:
            return
        scale = _vector(scale_text)
        if scale is None:
            raise InputError(f"{what} <mesh filename={filename!r}> scale must be 3 finite numbers separated by "
                             f"spaces, got {scale_text!r}")
        if shape.tag == "collision" and min(scale) <= 0:
            raise InputError(f"{what} <mesh filename={filename!r}> scale must be 3 positive numbers, got "
                             f"{scale_text!r} (a collision mesh is not mirrored or flattened: mirror the file itself)")


def _check_link(link: ET.Element, what: str) -> None:
    for kind in ("visual", "collision"):
        for k, shape in enumerate(link.findall(kind)):
            _check_geometry(shape, f"{what} <{kind}> {k + 1}")  # numbered from 1, as mass_properties does


def _check_joint(joint: ET.Element, what: str, links: set[str]) -> tuple[str, str]:
    """A <joint>'s type, parent, child, origin and axis; (parent, child). urdfdom reads an axis only on a joint that
    moves about one; <limit>, <dynamics> and the rest are left to it (its messages name the joint and the value)."""
    kind = joint.get("type")
    if kind is None:
        raise InputError(f"{what} has no type (one of {', '.join(JOINT_TYPES)})")
    if kind not in JOINT_TYPES:
        raise InputError(f"{what} has type {kind!r}, not one of {', '.join(JOINT_TYPES)}")
    ends = []
    for end in ("parent", "child"):
        element = joint.find(end)
        name = None if element is None else element.get("link")
        if name is None:
            raise InputError(f"{what} has no <{end} link=\"...\"> element")
        if name not in links:
            raise InputError(f"{what} names {end} link {name!r}, which the URDF does not have")
        ends.append(name)
    _check_origin(joint, what)
    axis = joint.find("axis")
    if axis is not None and kind not in ("fixed", "floating") and axis.get("xyz") is not None \
            and _vector(axis.get("xyz")) is None:
        raise InputError(f"{what} <axis> xyz must be 3 finite numbers separated by spaces, got {axis.get('xyz')!r}")
    return ends[0], ends[1]


def _names(elements: list[ET.Element], kind: str, where: str) -> list[str]:
    names: list[str] = []
    for element in elements:
        name = element.get("name")
        if name is None:
            before = f" (after {kind} {names[-1]!r})" if names else " (the first)"
            raise InputError(f"{where}: a <{kind}> has no name{before}")
        if name in names:
            raise InputError(f"{where}: two <{kind}> elements are named {name!r}: names must be unique")
        names.append(name)
    return names


def check_description(text: str, where: str) -> None:
    """Check a URDF's content before the core reads it, so that each problem is one line naming ``where`` (the
    file) and the element: links and joints named and unique, joint types, parents and children that exist (one
    parent per link, one root), readable origins, axes and shapes (a shape's kind, its sizes; a collision mesh's
    filename and a positive scale). Numbers are read as urdfdom reads them; what this does not check is left to
    the core, whose messages name the element too."""
    root = _xml_root(text, where)
    if root.tag.startswith("{"):  # a namespaced document: urdfdom ignores namespaces, ElementTree does not
        return
    if root.tag != "robot":
        raise InputError(f"{where}: the document's root element is <{root.tag}>, not <robot>")
    if root.get("name") is None:
        raise InputError(f"{where}: the <robot> element has no name attribute")
    link_elements = root.findall("link")
    links = _names(link_elements, "link", where)
    if not links:
        raise InputError(f"{where}: the URDF has no <link>")
    for name, link in zip(links, link_elements):
        _check_link(link, f"{where}: link {name!r}")
    joint_elements = root.findall("joint")
    parent_joint: dict[str, str] = {}
    for name, joint in zip(_names(joint_elements, "joint", where), joint_elements):
        _, child = _check_joint(joint, f"{where}: joint {name!r}", set(links))
        if child in parent_joint:
            raise InputError(f"{where}: link {child!r} is the child of two joints, {parent_joint[child]!r} and "
                             f"{name!r}: a URDF is a tree (one parent per link)")
        parent_joint[child] = name
    roots = [name for name in links if name not in parent_joint]
    if len(roots) > 1:
        shown = ", ".join(map(repr, roots[:6])) + (f" and {len(roots) - 6} more" if len(roots) > 6 else "")
        raise InputError(f"{where}: the links {shown} hang from no joint: a URDF is one tree with one root link "
                         f"(join the others to it with joints, or remove them)")


def with_joint_limits(text: str, limits: Mapping[str, tuple[float, float]], where: str,
                      needed: list[str] | None = None) -> str:
    """The URDF text with ``continuous`` joints made revolute within ``limits`` (joint -> (lower, upper) rad) and
    the limits of other named joints replaced. ``needed``: the continuous joints that must get limits (those on
    the robot's body); others keep no limit. Effort and velocity are kept (0 where none is written)."""
    root = _xml_root(text, where)
    joints = {j.get("name", ""): j for j in root.iter("joint")}
    unknown = sorted(set(limits) - set(joints))
    if unknown:
        raise InputError(f"{where}: [limits] names joints the URDF does not have: {', '.join(map(repr, unknown))}")
    missing = [name for name in (needed or []) if name not in limits]
    if missing:
        raise InputError(f"{where}: continuous joint{'s' if len(missing) > 1 else ''} {', '.join(map(repr, missing))} "
                         f"{'need' if len(missing) > 1 else 'needs'} limits: add them to the robot file's [limits] "
                         "table (joint = [lower, upper] in rad)")
    for name, (lower, upper) in limits.items():
        joint = joints[name]
        if joint.get("type") not in ("revolute", "continuous"):
            raise InputError(f"{where}: [limits] gives limits to {name!r}, a {joint.get('type')} joint")
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit")
        limit.set("lower", repr(float(lower)))
        limit.set("upper", repr(float(upper)))
        limit.set("effort", limit.get("effort", "0"))
        limit.set("velocity", limit.get("velocity", "0"))
    return ET.tostring(root, encoding="unicode")


def origin_matrix(element: ET.Element, where: str = "origin") -> np.ndarray:
    """The pose (4, 4) an element's ``<origin xyz rpy>`` gives (identity without one); InputError naming ``where``
    and the attribute for one that is not three finite numbers."""
    T = np.eye(4)
    origin = element.find("origin")
    if origin is None:
        return T
    values = {}
    for key in ("xyz", "rpy"):
        text = origin.get(key, "0 0 0")
        try:
            values[key] = np.array([float(v) for v in text.split()])
        except ValueError:
            values[key] = np.zeros(0)
        if values[key].shape != (3,) or not np.all(np.isfinite(values[key])):
            raise InputError(f"{where}: <origin {key}> must be three finite numbers, got {text!r}")
    T[:3, 3] = values["xyz"]
    T[:3, :3] = Rotation.from_euler("xyz", values["rpy"]).as_matrix()
    return T


def set_origin(joint: ET.Element, T: np.ndarray) -> None:
    """Write T (4, 4) as the element's ``<origin xyz rpy>``."""
    origin = joint.find("origin")
    if origin is None:
        origin = ET.SubElement(joint, "origin")
    origin.set("xyz", " ".join(repr(float(v)) for v in T[:3, 3]))
    with warnings.catch_warnings():  # at a gimbal lock scipy picks one of the equal decompositions, and says so
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    origin.set("rpy", " ".join(repr(float(v)) for v in rpy))


def add_fixed_frames(text: str, frames: list[tuple[str, str, np.ndarray]]) -> str:
    """The URDF text with fixed marker frames put in line: for each (parent, name, R), a link ``name`` on a fixed
    joint ``name + "_joint"`` at the parent's origin turned by R (3, 3), and the joints that hung from the parent
    hung from it instead (their origins turned back, so that nothing else moves)."""
    root = _xml_root(text, "adding aligned frames")
    for parent, name, R in frames:
        T = np.eye(4)
        T[:3, :3] = R
        inv = np.linalg.inv(T)
        for joint in root.iter("joint"):
            p = joint.find("parent")
            if p is not None and p.get("link") == parent:
                p.set("link", name)
                set_origin(joint, inv @ origin_matrix(joint, f"joint {joint.get('name')!r}"))
        ET.SubElement(root, "link", {"name": name})
        joint = ET.SubElement(root, "joint", {"name": name + "_joint", "type": "fixed"})
        ET.SubElement(joint, "parent", {"link": parent})
        ET.SubElement(joint, "child", {"link": name})
        set_origin(joint, T)
    return ET.tostring(root, encoding="unicode")


@dataclass(frozen=True)
class MeshResolver:
    """Where mesh files are: ``package://NAME/rest`` in the package's folder (:meth:`.RobotFolders.package_folder`),
    ``file://`` and absolute paths as they are, relative paths from ``folder`` (the URDF's); each must be inside
    the robot's folders (:meth:`.RobotFolders.inside`)."""

    folder: Path | None = None
    folders: RobotFolders = field(default_factory=RobotFolders)

    def resolve(self, filename: str, where: str) -> Path:
        return self.folders.inside(self._path(filename, where), f"{where}: mesh file", MAX_MESH_BYTES)

    def _path(self, filename: str, where: str) -> Path:
        if filename.startswith("package://"):
            name, _, inside = filename[len("package://"):].partition("/")
            if not name or not inside:
                raise InputError(f"{where}: mesh {filename!r} is not package://NAME/path")
            return self.folders.package_folder(name, f"{where}: mesh {filename!r}") / inside
        if filename.startswith("file://"):
            return Path(filename[len("file://"):])
        path = Path(filename)
        if not path.is_absolute():
            if self.folder is None:
                raise InputError(f"{where}: mesh {filename!r} is a relative path, but the URDF was given as text "
                                 "(no folder to resolve it from)")
            path = self.folder / path
        return path
