"""The text builders of the sample robots' files: URDF elements (links, joints, shapes, inertials) and robot files
(TOML), written as :mod:`snakehead.samples.published` and :mod:`snakehead.samples.published_quirks` write them.

Each builder returns a piece of text, indented to sit inside ``<robot>`` (links and joints) or a ``<link>`` (shapes
and inertials); :func:`robot` puts the pieces together. Lengths are in metres, angles in radians, masses in kg,
inertias in kg m^2. Numbers are written by :func:`num`, so that two writers of one snake write the same text.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Sequence
from xml.sax.saxutils import quoteattr

from .._errors import InputTypeError
from .._validate import finite_float

__all__ = [
    "Vec3", "num", "vec", "origin", "box", "cylinder", "sphere", "mesh", "shape", "inertial", "cylinder_inertia",
    "box_inertia", "link", "fixed_joint", "moving_joint", "robot", "toml_value", "write_robot_file",
]

#: Three numbers: a position (m), a turn (roll, pitch, yaw in rad), a box's size (m) or an inertia's diagonal.
Vec3 = Sequence[float]


# --- XML pieces --------------------------------------------------------------------------------------------------
def num(x: float) -> str:
    """``x`` as written in a description: Python's shortest text that reads back as the same double, without a
    trailing ``.0`` (two writers of one snake agree exactly)."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def vec(v: Vec3) -> str:
    """The numbers of ``v`` (:func:`num`), separated by spaces, as in ``xyz="..."``."""
    return " ".join(num(c) for c in v)


def origin(xyz: Vec3 = (0, 0, 0), rpy: Vec3 = (0, 0, 0)) -> str:
    """An ``<origin>`` element: position ``xyz`` (m) and turn ``rpy`` (rad)."""
    return f'<origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/>'


def box(size: Vec3) -> str:
    """A ``<box>`` geometry of ``size`` (m, along x, y, z), centred on its origin."""
    return f'<box size="{vec(size)}"/>'


def cylinder(radius: float, length: float) -> str:
    """A ``<cylinder>`` geometry (m): along its own z, centred on its origin."""
    return f'<cylinder radius="{num(radius)}" length="{num(length)}"/>'


def sphere(radius: float) -> str:
    """A ``<sphere>`` geometry of ``radius`` (m)."""
    return f'<sphere radius="{num(radius)}"/>'


def mesh(filename: str, scale: float = 1.0) -> str:
    """A ``<mesh>`` geometry: the file ``filename`` (a path or ``package://`` URI), its units times ``scale`` in
    metres (the attribute is left out at 1)."""
    scale_attr = "" if scale == 1.0 else f' scale="{vec((scale, scale, scale))}"'
    return f"<mesh filename={quoteattr(filename)}{scale_attr}/>"


def shape(kind: str, geometry: str, xyz: Vec3 = (0, 0, 0), rpy: Vec3 = (0, 0, 0)) -> str:
    """A ``<visual>`` or ``<collision>`` element (``kind``) of ``geometry`` (:func:`box`, :func:`cylinder`, ...)
    placed at ``xyz`` (m), turned by ``rpy`` (rad) in its link's frame."""
    return f"    <{kind}>\n      {origin(xyz, rpy)}\n      <geometry>{geometry}</geometry>\n    </{kind}>\n"


def inertial(mass: float, com: Vec3, diagonal: Vec3) -> str:
    """An ``<inertial>`` element: ``mass`` (kg) at ``com`` (m), principal inertias ``diagonal`` (kg m^2) along the
    link's axes (no products of inertia)."""
    ixx, iyy, izz = diagonal
    return (f"    <inertial>\n      {origin(com)}\n      <mass value=\"{num(mass)}\"/>\n"
            f"      <inertia ixx=\"{num(ixx)}\" ixy=\"0\" ixz=\"0\" iyy=\"{num(iyy)}\" iyz=\"0\" izz=\"{num(izz)}\"/>\n"
            f"    </inertial>\n")


def cylinder_inertia(mass: float, radius: float, length: float, along: int) -> tuple[float, float, float]:
    """Principal inertias (kg m^2) of a solid cylinder of ``mass`` (kg), ``radius`` and ``length`` (m) whose axis is
    link axis ``along`` (0 x, 1 y, 2 z)."""
    axial = mass * radius * radius / 2
    transverse = mass * (3 * radius * radius + length * length) / 12
    diagonal = [transverse] * 3
    diagonal[along] = axial
    return diagonal[0], diagonal[1], diagonal[2]


def box_inertia(mass: float, size: Vec3) -> tuple[float, float, float]:
    """Principal inertias (kg m^2) of a solid box of ``mass`` (kg) and ``size`` (m, along x, y, z)."""
    x, y, z = size
    return mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12


def link(name: str, body: str = "") -> str:
    """A ``<link>`` element holding ``body`` (:func:`inertial`, :func:`shape` ...); empty, a frame without a body."""
    if not body:
        return f"  <link name={quoteattr(name)}/>\n"
    return f"  <link name={quoteattr(name)}>\n{body}  </link>\n"


def fixed_joint(name: str, parent: str, child: str, xyz: Vec3 = (0, 0, 0), rpy: Vec3 = (0, 0, 0)) -> str:
    """A fixed ``<joint>``: ``child``'s frame at ``xyz`` (m), turned by ``rpy`` (rad), in ``parent``'s."""
    return (f"  <joint name={quoteattr(name)} type=\"fixed\">\n    <parent link={quoteattr(parent)}/>\n"
            f"    <child link={quoteattr(child)}/>\n    {origin(xyz, rpy)}\n  </joint>\n")


def moving_joint(name: str, parent: str, child: str, xyz: Vec3, rpy: Vec3, axis: str, limit: float, effort: float,
                 velocity: float, continuous: bool = False) -> str:
    """A ``revolute`` (or ``continuous``) ``<joint>`` about ``axis`` (the attribute's text, e.g. ``"0 0 1"``):
    ``child``'s frame at ``xyz`` (m), turned by ``rpy`` (rad), in ``parent``'s; range +-``limit`` (rad), ``effort``
    (N m) and ``velocity`` (rad/s) in its ``<limit>``. A continuous joint has no range in the URDF (``limit`` is not
    written): its robot file's ``[limits]`` gives it."""
    bounds = "" if continuous else f'lower="{num(-limit)}" upper="{num(limit)}" '
    return (f"  <joint name={quoteattr(name)} type=\"{'continuous' if continuous else 'revolute'}\">\n"
            f"    <parent link={quoteattr(parent)}/>\n    <child link={quoteattr(child)}/>\n"
            f"    {origin(xyz, rpy)}\n    <axis xyz=\"{axis}\"/>\n"
            f"    <limit {bounds}effort=\"{num(effort)}\" velocity=\"{num(velocity)}\"/>\n  </joint>\n")


def robot(name: str, comment: str, body: Sequence[str], namespaces: str = "") -> str:
    """A whole URDF: the XML declaration, ``comment`` (``--`` written ``- -``, as XML needs), then ``<robot>``
    holding the pieces ``body`` (links and joints), with the extra attributes ``namespaces``."""
    return ('<?xml version="1.0"?>\n' + f"<!-- {comment.replace('--', '- -')} -->\n"
            + f"<robot name={quoteattr(name)}{namespaces}>\n" + "".join(body) + "</robot>\n")


# --- robot files -------------------------------------------------------------------------------------------------
def toml_value(v: Any) -> str:
    """``v`` (a string, an int, a finite float, or a list of these) as a TOML value."""
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a valid TOML basic string (same escapes)
    if isinstance(v, bool) or not isinstance(v, (int, float, list, tuple)):
        raise InputTypeError(f"cannot write {v!r} to a robot file")
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(finite_float(v, "value")) if isinstance(v, float) else str(v)


def write_robot_file(path: Path, comment: str, keys: dict[str, Any], tables: dict[str, dict[str, Any]]) -> Path:
    """Write a robot file (TOML, docs/own_snake.rst) to ``path`` and return ``path``: ``comment`` as ``#`` lines,
    then ``keys`` (None values left out; a dict value as an inline table), then each non-empty table of
    ``tables``."""
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"{k} = {toml_value(v)}" for k, v in keys.items() if v is not None and not isinstance(v, dict)]
    for k, v in keys.items():
        if isinstance(v, dict):
            lines.append(f"{k} = {{ " + ", ".join(f"{json.dumps(a)} = {toml_value(b)}" for a, b in v.items()) + " }")
    for table, entries in tables.items():
        if entries:
            lines += ["", f"[{table}]"] + [f"{json.dumps(a)} = {toml_value(b)}" for a, b in entries.items()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
