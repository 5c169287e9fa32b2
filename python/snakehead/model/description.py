"""A robot description as it is published, made ready for the core: xacro expanded, ``continuous`` joints given
limits, mesh paths resolved and collision meshes loaded as their convex hulls.

* :func:`read_description` -- the URDF text of a ``.urdf`` file, a ``.xacro`` file (expanded without ROS by the
  ``xacro`` package, with arguments, without running the file's code: :mod:`.xacro_expansion`) or the XML itself,
  the folder its relative paths start from and the folders it may read (:mod:`.robot_folders`).
* :func:`with_joint_limits` -- ``continuous`` joints turned into revolute ones with the limits a robot file gives
  (a snake's planner needs bounded joints; a continuous joint without limits is an error naming it).
* :class:`MeshResolver` -- ``package://NAME/...``, ``file://...`` and relative mesh paths to files inside the
  robot's folders: the robot file's ``[packages]`` first, then ``ROS_PACKAGE_PATH``; :func:`convex_hull_vertices`
  loads one with trimesh.

Errors are :class:`snakehead.InputError` naming the file and the element.
"""
from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InputError, InputTypeError
from .._validate import MAX_COORDINATE_M, input_file
from .robot_folders import MAX_DESCRIPTION_BYTES, RobotFolders
from .xacro_expansion import expand_xacro

from typing import Any, Mapping


#: A collision mesh larger than this is not a snake module's (and would stall the hull).
MAX_MESH_BYTES = 64 * 1024 * 1024


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
        return Description(urdf, None, "<URDF text>", RobotFolders(extra, package_folders))
    path = input_file(urdf, "the robot's description", MAX_DESCRIPTION_BYTES)
    folder = path.resolve().parent
    folders = RobotFolders((folder, *extra), package_folders)
    if path.suffix == ".xacro":
        text = expand_xacro(path, _xacro_mappings(xacro_args or {}), folders, trusted=trust_xacro)
        return Description(text, folder, os.fspath(path), folders)
    if xacro_args:
        raise InputError(f"xacro_args are given but {os.fspath(path)!r} is not a .xacro file")
    # the core reads URDF files itself (with its own checks); only the folder is needed here
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
                         f"{'need' if len(missing) > 1 else 'needs'} limits: add them to the robot file's [limits] table (joint = [lower, upper] in rad)")
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
    from scipy.spatial.transform import Rotation

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
    from scipy.spatial.transform import Rotation

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


def convex_hull_vertices(path: Path, scale: np.ndarray, where: str) -> np.ndarray:
    """The vertices (V, 3) of the convex hull of the mesh file ``path`` (STL, OBJ, DAE, PLY... through trimesh),
    scaled. A missing, unreadable, empty or flat mesh is an InputError naming ``where`` and the path."""
    import trimesh

    input_file(path, f"{where}: mesh file", MAX_MESH_BYTES)
    try:
        loaded: Any = trimesh.load(os.fspath(path), force="mesh", process=False)
        vertices = np.asarray(loaded.vertices, dtype=float)
    except Exception as exc:  # trimesh raises many kinds for a bad file
        raise InputError(f"{where}: cannot read mesh file {os.fspath(path)!r}: {' '.join(str(exc).split())}") from None
    if vertices.ndim != 2 or vertices.shape[1] != 3:  # e.g. an OBJ "v" line with two coordinates
        raise InputError(f"{where}: mesh file {os.fspath(path)!r} has vertices of shape {vertices.shape}, not (V, 3)")
    vertices = vertices[np.all(np.isfinite(vertices), axis=1)] * np.asarray(scale, float)
    if len(vertices) < 4 or np.linalg.matrix_rank(vertices - vertices.mean(axis=0), tol=1e-9) < 3:
        raise InputError(f"{where}: mesh file {os.fspath(path)!r} has no volume (empty or flat: "
                         f"{len(vertices)} vertices)")
    if np.abs(vertices).max() > MAX_COORDINATE_M:
        raise InputError(f"{where}: mesh file {os.fspath(path)!r} has a vertex {np.abs(vertices).max():.3g} m from its "
                         f"origin (at most {MAX_COORDINATE_M:g} m; is the scale right?)")
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(vertices)
    except QhullError as exc:  # nearly flat, or coordinates whose round-off swamps the shape
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "qhull failed"
        raise InputError(f"{where}: mesh file {os.fspath(path)!r} has no convex hull ({first})") from None
    return np.ascontiguousarray(vertices[hull.vertices])
