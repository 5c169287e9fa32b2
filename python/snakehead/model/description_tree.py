"""The description's link tree, rewritten into the body the planner reads: rooted at the tail, straight at zero,
with the side branches' bodies on the links they hang from.

Published snakes are not all written tail first and straight at q = 0, and many carry collars, sensor mounts or
passive wheels off the body's line. :func:`body_description` rewrites the URDF's tree (never the robot's motion):

* **Re-rooting** (``root`` a leaf, the head an ancestor, or any two links joined through the tree): every joint on
  the way from the URDF's root to ``root`` is turned around. A fixed joint gets the inverse origin; a moving joint
  ``J`` (parent P, child C, origin T, axis a) becomes ``J`` from C to a new marker ``P__reversed`` at C's origin,
  axis -a, followed by a fixed joint with origin T^-1 to P. Every link keeps its frame, every joint its name, its
  limits and the sign of its angle: P = C Rot(-a, q) T^-1 is the description's C = P T Rot(a, q).
* **Home pose** (the robot file's ``[home]``, joint -> rad): a body joint's origin becomes T Rot(a, home) and its
  limits shift by -home, so that the body lies straight at zero. The planner's angles are the description's
  minus home (:class:`JointOffsets`).
* **Side branches**: each link off the body's chain gives its inertial, collision and visual elements to the body
  link it hangs from (masses and inertias summed about the common centre of mass, origins composed); moving joints
  on a branch are held at their home value or 0 (made fixed). The branch links stay as empty frames, so every
  link of the description still has a place for /tf.

Errors (:class:`snakehead.InputError`) name the link, joint or attribute.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
from scipy.spatial.transform import Rotation

from .._errors import InputError
from .description import origin_matrix, set_origin

__all__ = ["REVERSED_SUFFIX", "BranchLink", "TreeChanges", "JointOffsets", "body_description"]

#: The suffix of the marker frame a turned-around moving joint moves (the parent link's frame on the joint).
REVERSED_SUFFIX = "__reversed"

_MOVING = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class BranchLink:
    """A link off the body's chain whose body was moved onto a body link."""

    name: str
    onto: str  # the body link it hangs from
    mass: float  # kg
    shapes: int  # collision elements moved


@dataclass(frozen=True)
class TreeChanges:
    """What :func:`body_description` changed, for ``snakehead info``."""

    reversed_joints: tuple[str, ...] = ()
    branch_links: tuple[BranchLink, ...] = ()
    held_joints: tuple[tuple[str, float, str], ...] = ()  # (joint, value held at (rad or m), note)
    home: tuple[tuple[str, float], ...] = ()  # (joint, rad) of the body

    @property
    def any(self) -> bool:
        return bool(self.reversed_joints or self.branch_links or self.held_joints or self.home)


@dataclass(frozen=True)
class JointOffsets:
    """The planner's joint angles against the description's: description = planner + ``home`` (rad; zeros when
    the body lies straight at the description's zero)."""

    home: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def to_description(self, q: np.ndarray) -> np.ndarray:
        return np.asarray(q, float) + self.home

    def from_description(self, q: np.ndarray) -> np.ndarray:
        return np.asarray(q, float) - self.home


class _Tree:
    """The links and joints of a URDF's XML, checked: every joint names existing links, every link has at most one
    parent, one root."""

    def __init__(self, text: str, where: str) -> None:
        self.where = where
        try:
            self.xml = ET.fromstring(text)
        except ET.ParseError as exc:
            raise InputError(f"malformed URDF ({where}): {exc}") from None
        self.links = {link.get("name", ""): link for link in self.xml.findall("link")}
        self.joints = {joint.get("name", ""): joint for joint in self.xml.findall("joint")}
        self.parent_joint: dict[str, str] = {}
        for name, joint in self.joints.items():
            parent, child = self.ends(name)
            for role, link in (("parent", parent), ("child", child)):
                if link not in self.links:
                    raise InputError(f"{where}: joint {name!r} names {role} link {link!r}, which the URDF does not "
                                     "have")
            if child in self.parent_joint:
                raise InputError(f"{where}: link {child!r} is the child of two joints, {self.parent_joint[child]!r} "
                                 f"and {name!r}")
            self.parent_joint[child] = name

    def ends(self, joint: str) -> tuple[str, str]:
        element = self.joints[joint]
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise InputError(f"{self.where}: joint {joint!r} has no <parent> or <child> element")
        return parent.get("link", ""), child.get("link", "")

    def has(self, link: str, what: str) -> None:
        if link not in self.links:
            raise InputError(f"{what} {link!r} is not a link of the URDF ({self.where})")

    def up(self, link: str) -> list[str]:
        """The joints from ``link`` up to the tree's root, nearest first."""
        out: list[str] = []
        while link in self.parent_joint:
            joint = self.parent_joint[link]
            if joint in out:
                raise InputError(f"{self.where}: the joints {', '.join(map(repr, out))} form a loop")
            out.append(joint)
            link = self.ends(joint)[0]
        return out

    def children(self, link: str) -> list[str]:
        return [j for j in self.joints if self.ends(j)[0] == link]

    def path_links(self, root: str, tip: str) -> list[str]:
        """The links from ``root`` down to ``tip`` (the tree rooted at ``root``)."""
        out = [tip]
        while out[-1] != root:
            if out[-1] not in self.parent_joint:
                raise InputError(f"link {tip!r} does not hang below {root!r} ({self.where})")
            out.append(self.ends(self.parent_joint[out[-1]])[0])
        return out[::-1]

    def text(self) -> str:
        return ET.tostring(self.xml, encoding="unicode")


def _axis(joint: ET.Element, name: str, where: str) -> np.ndarray:
    axis = joint.find("axis")
    try:
        a = np.array([float(v) for v in (axis.get("xyz", "1 0 0") if axis is not None else "1 0 0").split()])
    except ValueError:
        a = np.zeros(0)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise InputError(f"{where}: joint {name!r}: <axis xyz> must be three numbers, got "
                         f"{axis.get('xyz') if axis is not None else None!r}")
    return a


def _motion(joint: ET.Element, name: str, value: float, where: str) -> np.ndarray:
    """The joint's motion transform (4, 4) at ``value``: a rotation about its axis (revolute, continuous) or a
    translation along it (prismatic)."""
    T = np.eye(4)
    if value == 0.0 or joint.get("type") not in _MOVING:
        return T
    a = _axis(joint, name, where)
    if not np.linalg.norm(a) > 0:
        raise InputError(f"{where}: joint {name!r} has axis 0 0 0: it cannot be moved to {value!r}")
    a = a / np.linalg.norm(a)
    if joint.get("type") == "prismatic":
        T[:3, 3] = a * value
        return T
    T[:3, :3] = Rotation.from_rotvec(a * value).as_matrix()
    return T


def _reverse(tree: _Tree, joint: str) -> None:
    """Turn one joint around (module docstring): the child becomes the parent."""
    element = tree.joints[joint]
    parent, child = tree.ends(joint)
    kind = element.get("type")
    T = origin_matrix(element, f"{tree.where}: joint {joint!r}")
    element.find("parent").set("link", child)  # type: ignore[union-attr]
    if kind == "fixed":
        element.find("child").set("link", parent)  # type: ignore[union-attr]
        set_origin(element, np.linalg.inv(T))
        return
    if kind not in _MOVING:
        raise InputError(f"{tree.where}: joint {joint!r} ({kind}) lies between the root and the URDF's root link; only "
                         "fixed, revolute, continuous and prismatic joints can be turned around")
    marker = parent + REVERSED_SUFFIX
    element.find("child").set("link", marker)  # type: ignore[union-attr]
    set_origin(element, np.eye(4))
    axis = element.find("axis")
    if axis is None:
        axis = ET.SubElement(element, "axis")
    axis.set("xyz", " ".join(repr(float(-v)) for v in _axis(element, joint, tree.where)))
    link = ET.SubElement(tree.xml, "link", {"name": marker})
    tree.links[marker] = link
    fixed = ET.SubElement(tree.xml, "joint", {"name": joint + REVERSED_SUFFIX, "type": "fixed"})
    ET.SubElement(fixed, "parent", {"link": marker})
    ET.SubElement(fixed, "child", {"link": parent})
    set_origin(fixed, np.linalg.inv(T))
    tree.joints[fixed.get("name", "")] = fixed


def _reroot(tree: _Tree, root: str) -> tuple[str, ...]:
    """Re-root the tree at ``root``; the joints turned around, nearest the old root first."""
    path = tree.up(root)[::-1]
    for joint in path:
        _reverse(tree, joint)
    tree.parent_joint = {}
    for name in tree.joints:
        tree.parent_joint[tree.ends(name)[1]] = name
    return tuple(path)


def _apply_home(tree: _Tree, home: Mapping[str, float], body_joints: list[str]) -> None:
    """Turn each body joint's origin by its home angle and shift its limits (module docstring)."""
    for joint in body_joints:
        value = float(home.get(joint, 0.0))
        if value == 0.0:
            continue
        element = tree.joints[joint]
        set_origin(element, origin_matrix(element, f"{tree.where}: joint {joint!r}")
                   @ _motion(element, joint, value, tree.where))
        limit = element.find("limit")
        if limit is not None and element.get("type") != "continuous":
            for key in ("lower", "upper"):
                if key in limit.attrib:
                    limit.set(key, repr(float(limit.get(key, "0")) - value))


def _hold(tree: _Tree, joint: str, value: float) -> str:
    """Make a branch's moving joint fixed at ``value``; a note for info."""
    element = tree.joints[joint]
    axis = _axis(element, joint, tree.where) if element.get("type") in _MOVING else np.ones(3)
    note = "axis 0 0 0" if not np.linalg.norm(axis) > 0 else element.get("type", "")
    if element.get("type") in ("floating", "planar"):
        note = f"{element.get('type')} joint"
    moved = _motion(element, joint, value, tree.where) if np.linalg.norm(axis) > 0 else np.eye(4)
    set_origin(element, origin_matrix(element, f"{tree.where}: joint {joint!r}") @ moved)
    element.set("type", "fixed")
    for tag in ("axis", "limit", "mimic", "dynamics", "safety_controller", "calibration"):
        for sub in element.findall(tag):
            element.remove(sub)
    return note


@dataclass
class _Body:
    """A rigid body's mass data in one frame: mass (kg), centre of mass (3,), inertia about it (3, 3)."""

    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def plus(self, other: "_Body") -> "_Body":
        m = self.mass + other.mass
        if not m > 0:
            return _Body()
        c = (self.mass * self.com + other.mass * other.com) / m
        out = np.zeros((3, 3))
        for b in (self, other):
            d = b.com - c
            out += b.inertia + b.mass * (d @ d * np.eye(3) - np.outer(d, d))  # parallel axes
        return _Body(m, c, out)


def _inertial(link: ET.Element, name: str, where: str) -> _Body:
    element = link.find("inertial")
    if element is None:
        return _Body()
    here = f"{where}: link {name!r} <inertial>"
    mass_el, inertia_el = element.find("mass"), element.find("inertia")
    try:
        mass = float(mass_el.get("value", "0")) if mass_el is not None else 0.0
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        v = {k: float(inertia_el.get(k, "0")) if inertia_el is not None else 0.0 for k in keys}
    except ValueError as exc:
        raise InputError(f"{here}: {exc}") from None
    if not (math.isfinite(mass) and mass >= 0) or not all(math.isfinite(x) for x in v.values()):
        raise InputError(f"{here}: mass and inertia must be finite, the mass >= 0")
    origin = origin_matrix(element, here)
    R = origin[:3, :3]
    inertia = np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]], [v["ixz"], v["iyz"], v["izz"]]])
    return _Body(mass, origin[:3, 3].copy(), R @ inertia @ R.T)


def _write_inertial(link: ET.Element, body: _Body) -> None:
    for old in link.findall("inertial"):
        link.remove(old)
    if not body.mass > 0:
        return
    element = ET.Element("inertial")
    link.insert(0, element)
    ET.SubElement(element, "origin", {"xyz": " ".join(repr(float(v)) for v in body.com), "rpy": "0 0 0"})
    ET.SubElement(element, "mass", {"value": repr(float(body.mass))})
    I = body.inertia
    ET.SubElement(element, "inertia", {k: repr(float(I[i, j])) for k, (i, j) in
                                       {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2),
                                        "izz": (2, 2)}.items()})


def _move_body(tree: _Tree, name: str, onto: str, T: np.ndarray) -> BranchLink:
    """Move link ``name``'s inertial, collisions and visuals onto ``onto`` (T: name's frame in onto's)."""
    link, target = tree.links[name], tree.links[onto]
    moved = _inertial(link, name, tree.where)
    R = T[:3, :3]
    moved = _Body(moved.mass, T[:3, :3] @ moved.com + T[:3, 3], R @ moved.inertia @ R.T)
    if moved.mass > 0:
        _write_inertial(target, _inertial(target, onto, tree.where).plus(moved))
    _write_inertial(link, _Body())
    shapes = 0
    for tag in ("collision", "visual"):
        for element in link.findall(tag):
            set_origin(element, T @ origin_matrix(element, f"{tree.where}: link {name!r} <{tag}>"))
            link.remove(element)
            target.append(element)
            shapes += tag == "collision"
    return BranchLink(name, onto, moved.mass, shapes)


def _lump_branches(tree: _Tree, body_links: list[str], home: Mapping[str, float]) -> tuple[
        tuple[BranchLink, ...], tuple[tuple[str, float, str], ...]]:
    """Move every branch's bodies onto the body link it hangs from; hold its moving joints (module docstring)."""
    on_body = set(body_links)
    moved: list[BranchLink] = []
    held: list[tuple[str, float, str]] = []

    def visit(link: str, onto: str, T: np.ndarray) -> None:
        for joint in tree.children(link):
            child = tree.ends(joint)[1]
            if child in on_body:
                continue
            element = tree.joints[joint]
            if element.get("type") != "fixed":
                value = float(home.get(joint, 0.0))
                held.append((joint, value, _hold(tree, joint, value)))
            T_child = T @ origin_matrix(element, f"{tree.where}: joint {joint!r}")
            branch = _move_body(tree, child, onto, T_child)
            if branch.mass > 0 or branch.shapes:
                moved.append(branch)
            visit(child, onto, T_child)

    for link in body_links:
        visit(link, link, np.eye(4))
    return tuple(moved), tuple(held)


def body_description(text: str, root: str, head_tip: str, home: Mapping[str, float], where: str) -> tuple[
        str | None, TreeChanges]:
    """The URDF text rewritten for the body ``root`` -> ``head_tip`` (module docstring) and what changed; None for
    the text when nothing needs to change. ``home``: joint -> rad (body joints) or the value a branch joint is
    held at."""
    tree = _Tree(text, where)
    for key, link in (("root", root), ("head_tip", head_tip)):
        tree.has(link, key)
    unknown = sorted(set(home) - set(tree.joints))
    if unknown:
        raise InputError(f"{where}: [home] names joints the URDF does not have: {', '.join(map(repr, unknown))}")
    reversed_joints = _reroot(tree, root) if root in tree.parent_joint else ()
    body_links = tree.path_links(root, head_tip)
    body_joints = [tree.parent_joint[link] for link in body_links[1:]]
    body_home = {j: float(home[j]) for j in body_joints if j in home}
    for joint, value in body_home.items():
        if tree.joints[joint].get("type") not in _MOVING:
            raise InputError(f"{where}: [home] gives {joint!r} an angle, but it is a {tree.joints[joint].get('type')} "
                             "joint")
    _apply_home(tree, body_home, body_joints)
    branches, held = _lump_branches(tree, body_links, home)
    changes = TreeChanges(tuple(reversed_joints), branches, held,
                          tuple((j, v) for j, v in body_home.items() if v != 0.0))
    return (tree.text() if changes.any else None), changes

