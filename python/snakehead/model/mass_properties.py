"""Masses and inertias: checks of a robot's inertial data, and inertias recomputed from the collision shapes.

Published descriptions carry inertial data that cannot describe their bodies: a module's joint link of 1 kg with an
inertia of 1 kg m^2 and no geometry, a 0.103 kg shell with ixx = 2.948 kg m^2 (a radius of gyration of 5 m for a
5 cm module). The planner's stability checks, the core's dynamics and MuJoCo all believe those numbers.

* :func:`mass_findings` -- plain-language findings about a :class:`~snakehead.SnakeRobot`'s masses and inertias
  (the numbers the core, the stability checks and MuJoCo use), each naming the link and the numbers:

  - an inertia whose radius of gyration ``sqrt(I / m)`` (largest principal moment) exceeds
    :data:`GYRATION_FACTOR` times the link's *extent* (the largest distance from its centre of mass to a point of
    its collision shapes). Mass inside the shapes cannot have a radius of gyration above the extent (no point of
    it lies farther from an axis through the centre of mass); collision shapes are often simplified and smaller
    than the part, so only a factor of 3 (an inertia 9 times what the shapes could hold) is flagged. A link without
    shapes is compared with the largest extent of the robot's shaped links (a module's size);
  - mass on links without collision shapes: how much, and its share of the robot's mass;
  - a mass share that cannot be right: one link holding more than :data:`MAX_LINK_SHARE` of the robot's mass
    (a snake's mass is spread along its modules), or a link whose mass over its shapes' volume is denser than
    :data:`MAX_DENSITY` (tungsten is 19 300 kg/m^3) or lighter than :data:`MIN_DENSITY` (expanded foam);
  - principal moments that violate the triangle inequality A + B >= C (no distribution of mass has them; the
    core refuses a description with them unless ``inertia = "from_shapes"`` replaces them).

* :func:`with_inertia` -- the description with its ``<inertial>`` elements recomputed from the links' collision
  shapes (``inertia = "from_shapes"`` in the robot file), one *rigid segment* at a time (:func:`rigid_segments`:
  links joined by fixed joints between two moving joints): a uniform density over all the segment's shapes, the
  segment's total URDF mass (or, with ``density`` in kg/m^3, the mass that density gives), so each link with shapes
  holds its shapes' share. Boxes, cylinders and spheres in closed form, meshes as their convex hulls (as everywhere
  in snakehead) through trimesh; several shapes of a link are combined about their common centre of mass
  (parallel-axis theorem), each at its ``<origin>``. Overlapping shapes count twice where they overlap. Links without
  collision shapes in a segment with shapes lose their ``<inertial>`` (their mass moves to the segment's shapes:
  a 1 kg joint link fixed to its shell; :class:`InertiaRewrite` says what moved); segments without shapes keep
  theirs, and so do segments with shapes but no mass when no density is given. It rewrites the URDF text
  (everything but the ``<inertial>`` elements is kept), so the core, the stability checks and MuJoCo all see the
  same numbers.
"""
from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable

import numpy as np
from scipy.spatial.transform import Rotation

from .._errors import InputError, InputTypeError
from ..geometry.meshes import convex_hull_vertices
from .description import Description, MeshResolver

if TYPE_CHECKING:  # robot.py builds on this module (robot_build's rewrite_inertia)
    from .robot import SnakeRobot

__all__ = ["INERTIA_SOURCES", "GYRATION_FACTOR", "MAX_LINK_SHARE", "MAX_DENSITY", "MIN_DENSITY", "TRIANGLE_TOLERANCE",
           "Finding", "MassProperties", "shape_unit_properties", "combine", "shapes_mass_properties",
           "check_inertia_source", "with_inertia", "rewrite_inertia", "link_shapes", "InertiaRewrite",
           "inertia_from_shapes", "rigid_segments", "rewrite_inertia_text", "mass_findings", "findings_of",
           "inertia_source"]

#: The robot file's ``inertia`` values: the URDF's ``<inertial>`` elements, or recomputed from the shapes.
INERTIA_SOURCES = ("urdf", "from_shapes")
#: A radius of gyration above this many times the link's extent is flagged (see the module's docstring).
GYRATION_FACTOR = 3.0
#: One link holding more than this share of the robot's mass is flagged (robots with 4 or more massive links).
MAX_LINK_SHARE = 0.5
#: Mass over the volume of a link's shapes above this (kg/m^3; denser than tungsten) or below MIN_DENSITY is flagged.
MAX_DENSITY = 20000.0
MIN_DENSITY = 10.0
#: Relative tolerance of the triangle inequality of principal moments (the core's: it refuses a description whose
#: moments violate it by more, so on a loaded robot this finding names only what other sources give).
TRIANGLE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Finding:
    """One finding: its kind ("gyration", "shapeless", "share", "density", "triangle"), the links it names and the
    sentence that says it."""

    kind: str
    links: tuple[str, ...]
    text: str

    def __str__(self) -> str:
        return self.text


# ------------------------------------------------------------------------------------------------
# mass properties of shapes
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MassProperties:
    """A body's mass (kg), centre of mass (3,) and inertia (3, 3) about it (kg m^2), in the frame it is given in;
    ``volume`` (m^3) of the shapes it came from."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    volume: float


def shape_unit_properties(kind: str, size: np.ndarray, vertices: np.ndarray | None = None
                          ) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume (m^3), centroid (3,) and inertia about the centroid per unit density (3, 3; m^5) of one shape in its
    own frame: a box of extents ``size``; a cylinder (radius, length) along its z; a sphere (radius); a convex hull
    of ``vertices`` (V, 3) (``kind`` "convex" or "mesh")."""
    s = np.asarray(size, float)
    if kind == "box":
        a, b, c = s
        v = a * b * c
        return v, np.zeros(3), v / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "cylinder":
        r, h = s[0], s[1]
        v = math.pi * r * r * h
        side = v * (3 * r * r + h * h) / 12.0
        return v, np.zeros(3), np.diag([side, side, v * r * r / 2.0])
    if kind == "sphere":
        r = s[0]
        v = 4.0 / 3.0 * math.pi * r ** 3
        return v, np.zeros(3), np.eye(3) * (0.4 * v * r * r)
    if kind in ("convex", "mesh"):
        import trimesh  # heavy to import (~0.2 s): only mesh shapes need it

        hull = trimesh.convex.convex_hull(np.asarray(vertices, float))
        hull.density = 1.0
        return float(hull.volume), np.asarray(hull.center_mass, float), np.asarray(hull.moment_inertia, float)
    raise InputError(f"shape kind must be box, cylinder, sphere or convex, got {kind!r}")


def combine(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """Bodies (mass, centre of mass (3,), inertia about it (3, 3)), all in one frame, as one body: total mass, centre
    of mass and inertia about it (parallel-axis theorem: I + m (|d|^2 E - d d^T) for each body's offset d)."""
    mass = float(sum(m for m, _, _ in parts))
    if mass <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m * np.asarray(c, float) for m, c, _ in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, I in parts:
        d = np.asarray(c, float) - com
        inertia += np.asarray(I, float) + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, np.asarray(com, float), 0.5 * (inertia + inertia.T)


def shapes_mass_properties(shapes: list[tuple[np.ndarray, float, np.ndarray, np.ndarray]], *,
                           mass: float | None = None, density: float | None = None) -> MassProperties:
    """A link's mass properties from its shapes at uniform density: ``shapes`` as (origin (4, 4) in the link frame,
    volume, centroid (3,), unit-density inertia (3, 3)) in each shape's own frame (:func:`shape_unit_properties`);
    the link's ``mass`` spread over them, or ``density`` (kg/m^3) times their volume. Link-frame results."""
    volume = float(sum(v for _, v, _, _ in shapes))
    if volume <= 0:
        raise InputError("shapes without volume have no mass properties")
    rho = float(density) if density is not None else float(mass or 0.0) / volume
    parts = []
    for T, v, c, I in shapes:
        R = np.asarray(T, float)[:3, :3]
        parts.append((rho * v, R @ c + np.asarray(T, float)[:3, 3], rho * (R @ I @ R.T)))
    m, com, inertia = combine(parts)
    return MassProperties(m, com, inertia, volume)


# ------------------------------------------------------------------------------------------------
# the rewrite of the description
# ------------------------------------------------------------------------------------------------
def check_inertia_source(inertia: object, density: object, where: str = "") -> tuple[str, float | None]:
    """``inertia`` and ``density`` checked (InputError naming ``where`` and the key): one of :data:`INERTIA_SOURCES`,
    and a positive finite density in kg/m^3 or None (only with "from_shapes")."""
    prefix = f"{where}: " if where else ""
    if not isinstance(inertia, str) or inertia not in INERTIA_SOURCES:
        raise InputError(f"{prefix}'inertia' must be one of {', '.join(map(repr, INERTIA_SOURCES))}, got {inertia!r}")
    if density is None:
        return inertia, None
    if isinstance(density, bool) or not isinstance(density, (int, float, np.integer, np.floating)):
        raise InputTypeError(f"{prefix}'density' must be a number of kg/m^3, got {density!r}")
    if not (math.isfinite(float(density)) and float(density) > 0):
        raise InputError(f"{prefix}'density' must be a positive finite number of kg/m^3, got {density!r}")
    if inertia != "from_shapes":
        raise InputError(f"{prefix}'density' is given but 'inertia' is {inertia!r}: a density is only used with "
                         "inertia = \"from_shapes\"")
    return inertia, float(density)


def with_inertia(description: Description, inertia: str = "urdf", density: float | None = None,
                 where: str = "") -> Description:
    """The description whose URDF text the core will read: unchanged for ``inertia = "urdf"``; for "from_shapes"
    the ``<inertial>`` elements recomputed from the collision shapes (:func:`rewrite_inertia`)."""
    return rewrite_inertia(description, inertia, density, where)[0]


def rewrite_inertia(description: Description, inertia: str = "urdf", density: float | None = None,
                    where: str = "") -> tuple[Description, InertiaRewrite | None]:
    """:func:`with_inertia` and what it moved: for "from_shapes" the ``<inertial>`` elements recomputed one rigid
    segment at a time (:func:`rewrite_inertia_text`; mesh paths resolved as the robot's shapes are) and the
    :class:`InertiaRewrite`; for "urdf" the description unchanged and None. InputError for a bad ``inertia`` or
    ``density``."""
    inertia, density = check_inertia_source(inertia, density, where)
    if inertia == "urdf":
        return description, None
    resolver = MeshResolver(description.folder, description.folders)
    text = description.text
    if not text.lstrip().startswith("<"):
        text = Path(text).read_text(encoding="utf-8")

    def hull(filename: str, scale: np.ndarray, at: str) -> np.ndarray:
        return convex_hull_vertices(resolver.resolve(filename, at), scale, at)

    text, rewrite = rewrite_inertia_text(text, hull, density, description.source)
    return dataclasses.replace(description, text=text), rewrite


def _numbers(text: str | None, count: int, what: str, default: str | None = None) -> np.ndarray:
    if text is None:
        if default is None:
            raise InputError(f"{what} is missing")
        text = default
    try:
        values = np.array([float(v) for v in text.split()])
    except ValueError:
        raise InputError(f"{what} must be {count} numbers, got {text!r}") from None
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise InputError(f"{what} must be {count} finite numbers, got {text!r}")
    return values


def _origin(element: ET.Element, where: str) -> np.ndarray:
    T = np.eye(4)
    origin = element.find("origin")
    if origin is not None:
        T[:3, 3] = _numbers(origin.get("xyz"), 3, f"{where} <origin> xyz", "0 0 0")
        rpy = _numbers(origin.get("rpy"), 3, f"{where} <origin> rpy", "0 0 0")
        T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()  # URDF: fixed axes, roll about x first
    return T


def _positive(element: ET.Element, attribute: str, count: int, where: str) -> np.ndarray:
    values = _numbers(element.get(attribute), count, f"{where} {attribute}")
    if not np.all(values > 0):
        raise InputError(f"{where} {attribute} must be positive, got {element.get(attribute)!r}")
    return values


def link_shapes(link: ET.Element, hull: Callable[[str, np.ndarray, str], np.ndarray]
                ) -> list[tuple[np.ndarray, float, np.ndarray, np.ndarray]]:
    """A URDF ``<link>``'s collision shapes as (origin (4, 4), volume, centroid, unit-density inertia) for
    :func:`shapes_mass_properties`; ``hull(filename, scale, where)`` gives a mesh's convex hull vertices."""
    name = link.get("name", "")
    out = []
    for n, collision in enumerate(link.findall("collision")):
        where = f"link {name!r} <collision> {n + 1}"
        geometry = collision.find("geometry")
        shape = None if geometry is None else next(iter(geometry), None)
        if shape is None:
            raise InputError(f"{where} has no <geometry> shape")
        if shape.tag == "box":
            props = shape_unit_properties("box", _positive(shape, "size", 3, f"{where} <box>"))
        elif shape.tag == "cylinder":
            r = _positive(shape, "radius", 1, f"{where} <cylinder>")[0]
            h = _positive(shape, "length", 1, f"{where} <cylinder>")[0]
            props = shape_unit_properties("cylinder", np.array([r, h, 0.0]))
        elif shape.tag == "sphere":
            props = shape_unit_properties("sphere", np.array([_positive(shape, "radius", 1, f"{where} <sphere>")[0],
                                                              0.0, 0.0]))
        elif shape.tag == "mesh":
            filename = shape.get("filename")
            if not filename:
                raise InputError(f"{where} <mesh> has no filename")
            scale = _numbers(shape.get("scale"), 3, f"{where} <mesh> scale", "1 1 1")
            props = shape_unit_properties("convex", np.zeros(3), hull(filename, scale, where))
        else:
            raise InputError(f"{where} has an unknown shape <{shape.tag}> (box, cylinder, sphere or mesh)")
        out.append((_origin(collision, where), *props))
    return out


def _number(x: float) -> str:
    return repr(float(x))


def _write_inertial(link: ET.Element, props: MassProperties) -> None:
    """Replace the children of the link's ``<inertial>`` (or a new one) with ``props``: the centre of mass as the
    origin, link-frame axes; the element keeps its place and its indentation."""
    inertial = link.find("inertial")
    if inertial is None:
        inertial = ET.Element("inertial")
        inertial.tail = link.text
        link.insert(0, inertial)
    children = list(inertial)
    indent = inertial.text if children else None
    closing = children[-1].tail if children else None
    for child in children:
        inertial.remove(child)
    I = props.inertia
    ET.SubElement(inertial, "origin", {"xyz": " ".join(_number(v) for v in props.com), "rpy": "0 0 0"})
    ET.SubElement(inertial, "mass", {"value": _number(props.mass)})
    ET.SubElement(inertial, "inertia", {"ixx": _number(I[0, 0]), "ixy": _number(I[0, 1]), "ixz": _number(I[0, 2]),
                                        "iyy": _number(I[1, 1]), "iyz": _number(I[1, 2]), "izz": _number(I[2, 2])})
    new = list(inertial)
    for child in new[:-1]:
        child.tail = indent
    new[-1].tail = closing


@dataclass(frozen=True)
class InertiaRewrite:
    """What ``inertia = "from_shapes"`` did beyond recomputing inertias (:func:`rewrite_inertia_text`).

    ``moved``: (link, URDF mass in kg, the links with shapes of its rigid segment) for each link without shapes
    whose mass went to its segment's shapes (its ``<inertial>`` removed); ``dropped``: links without shapes and
    without mass in such a segment whose ``<inertial>`` was removed (a 0 kg link with 1 kg m^2); ``kept``: links
    with mass in segments without any collision shape (their ``<inertial>`` kept); ``unmassed``: links of
    segments with shapes but no URDF mass (without ``density``: kept as written)."""

    moved: tuple[tuple[str, float, tuple[str, ...]], ...] = ()
    dropped: tuple[str, ...] = ()
    kept: tuple[str, ...] = ()
    unmassed: tuple[str, ...] = ()

    @property
    def moved_mass(self) -> float:
        return float(sum(m for _, m, _ in self.moved))


def inertia_from_shapes(text: str, hull: Callable[[str, np.ndarray, str], np.ndarray], density: float | None = None,
                        where: str = "the URDF") -> str:
    """The URDF text with the ``<inertial>`` elements recomputed from the collision shapes, one rigid segment at a
    time (:func:`rewrite_inertia_text`). ``hull(filename, scale, where)``: a mesh's convex hull vertices."""
    return rewrite_inertia_text(text, hull, density, where)[0]


def rigid_segments(root: ET.Element) -> list[list[ET.Element]]:
    """The URDF's links grouped into rigid segments: links joined by ``fixed`` joints, in either direction (the
    body's tree may be rooted anywhere), each segment bounded by moving joints. Segments and their links in the
    order of the links in the URDF."""
    links = root.findall("link")
    index = {link.get("name", ""): k for k, link in enumerate(links)}
    up = list(range(len(links)))

    def find(k: int) -> int:
        while up[k] != k:
            up[k] = up[up[k]]
            k = up[k]
        return k

    for joint in root.findall("joint"):
        if joint.get("type") != "fixed":
            continue
        parent, child = joint.find("parent"), joint.find("child")
        a = None if parent is None else index.get(parent.get("link", ""))
        b = None if child is None else index.get(child.get("link", ""))
        if a is not None and b is not None:
            up[find(a)] = find(b)
    groups: dict[int, list[ET.Element]] = {}
    for k, link in enumerate(links):
        groups.setdefault(find(k), []).append(link)
    return list(groups.values())


def _urdf_mass(link: ET.Element) -> float:
    node = link.find("inertial/mass")
    if node is None:
        return 0.0
    return float(_numbers(node.get("value"), 1, f"link {link.get('name', '')!r} <inertial> <mass> value")[0])


def rewrite_inertia_text(text: str, hull: Callable[[str, np.ndarray, str], np.ndarray],
                         density: float | None = None, where: str = "the URDF") -> tuple[str, InertiaRewrite]:
    """The URDF text with its ``<inertial>`` elements recomputed from the collision shapes, and what was moved.

    Each rigid segment (:func:`rigid_segments`) is one body of uniform density over all its links' collision
    shapes: its total URDF mass spread over their volume (or ``density`` kg/m^3), so each link with shapes gets
    its shapes' share of the mass and their inertia (about their centre of mass, in the link's frame), and the
    segment's mass is kept. Links without shapes in a segment with shapes get no ``<inertial>`` (mass 0): a joint
    link of 1 kg and 1 kg m^2 fixed to a shell gives its mass to the shell. Segments without shapes, and segments
    with shapes but no mass when ``density`` is None, keep their ``<inertial>`` elements. Only the fixed joints'
    topology matters: each link's share is computed in its own frame, and the core and MuJoCo join the links
    through the fixed joints' transforms as they would any others."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InputError(f"malformed URDF ({where}): {exc}") from None
    moved: list[tuple[str, float, tuple[str, ...]]] = []
    dropped: list[str] = []
    kept: list[str] = []
    unmassed: list[str] = []
    for segment in rigid_segments(root):
        shapes = [link_shapes(link, hull) for link in segment]
        masses = [_urdf_mass(link) for link in segment]
        shaped = [k for k, s in enumerate(shapes) if s]
        if not shaped:
            kept += [link.get("name", "") for link, m in zip(segment, masses) if m > 0]
            continue
        total = float(sum(masses))
        if density is None and not total > 0:
            unmassed += [link.get("name", "") for link in segment]
            continue
        volumes = [float(sum(v for _, v, _, _ in shapes[k])) for k in range(len(segment))]
        volume = float(sum(volumes))
        onto = tuple(segment[k].get("name", "") for k in shaped)
        for k, link in enumerate(segment):
            if shapes[k]:
                share = (density * volumes[k] if density is not None
                         else total if len(shaped) == 1 else total * volumes[k] / volume)
                _write_inertial(link, shapes_mass_properties(shapes[k], mass=share))
                continue
            inertials = link.findall("inertial")
            for inertial in inertials:
                link.remove(inertial)
            if masses[k] > 0:
                moved.append((link.get("name", ""), masses[k], onto))
            elif inertials:
                dropped.append(link.get("name", ""))
    rewrite = InertiaRewrite(tuple(moved), tuple(dropped), tuple(kept), tuple(unmassed))
    return ET.tostring(root, encoding="unicode"), rewrite


# ------------------------------------------------------------------------------------------------
# checks
# ------------------------------------------------------------------------------------------------
def _extents(robot: SnakeRobot) -> dict[int, tuple[float, float]]:
    """Per shaped link (index): the largest distance (m) from its centre of mass to a point of its shapes, and the
    shapes' volume (m^3)."""
    links, points = robot.link_points
    coms = np.asarray(robot.coms, float)
    volumes: dict[int, float] = {}
    for s in robot.geometry.shapes:
        volumes[int(s.frame)] = volumes.get(int(s.frame), 0.0) + shape_unit_properties(s.kind, s.size, s.vertices)[0]
    return {int(k): (float(np.linalg.norm(p - coms[k], axis=1).max()), volumes.get(int(k), 0.0))
            for k, p in zip(links, points)}


def _kg(m: float) -> str:
    return f"{m:.4g} kg"


def mass_findings(robot: SnakeRobot) -> list[Finding]:
    """What is implausible in the masses and inertias the robot uses (those of ``robot.body``: the core's, the
    stability checks' and MuJoCo's; see the module's docstring), each finding naming the link and the numbers; an
    empty list when nothing is."""
    return findings_of(robot.link_names, robot.masses, robot.inertias, _extents(robot))


def findings_of(names: list[str], masses: np.ndarray, inertias: np.ndarray,
                extents: dict[int, tuple[float, float]]) -> list[Finding]:
    """:func:`mass_findings` of links ``names`` with ``masses`` (n,) kg and ``inertias`` (n, 3, 3) kg m^2 about
    their centres of mass; ``extents``: for each link with collision shapes (index), the largest distance (m) from
    its centre of mass to a point of its shapes and their volume (m^3)."""
    masses = np.asarray(masses, float)
    inertias = np.asarray(inertias, float)
    total = float(masses.sum())
    largest = max((e for e, _ in extents.values()), default=0.0)
    per_link: list[tuple[str, str, str]] = []  # (kind, link, text with _WHO for the link)
    for k, name in enumerate(names):
        m = float(masses[k])
        if m <= 0:
            continue
        moments = np.linalg.eigvalsh(0.5 * (inertias[k] + inertias[k].T))
        a, b, c = moments
        if a + b < c - TRIANGLE_TOLERANCE * max(abs(a), abs(c)):
            per_link.append(("triangle", name, f"{_WHO}: principal moments {a:.4g}, {b:.4g}, {c:.4g} "
                                                    f"kg m^2 violate the triangle inequality ({a:.4g} + {b:.4g} < "
                                                    f"{c:.4g}): no body has them"))
        gyration = math.sqrt(max(c, 0.0) / m)
        extent, volume = extents.get(k, (None, 0.0))
        if extent is not None and gyration > GYRATION_FACTOR * extent:
            per_link.append(("gyration", name, f"{_WHO}: radius of gyration {gyration:.3g} m "
                                                    f"(inertia {c:.4g} kg m^2, mass {_kg(m)}) is "
                                                    f"{gyration / extent:.0f} times its collision shapes' extent "
                                                    f"({extent:.3g} m from its centre of mass); more than "
                                                    f"{GYRATION_FACTOR:g} times cannot be the part"))
        elif extent is None and largest > 0 and gyration > GYRATION_FACTOR * largest:
            per_link.append(("gyration", name, f"{_WHO} (no collision shapes): radius of gyration "
                                                    f"{gyration:.3g} m (inertia {c:.4g} kg m^2, mass {_kg(m)}) is "
                                                    f"{gyration / largest:.0f} times the largest link's extent "
                                                    f"({largest:.3g} m); more than {GYRATION_FACTOR:g} times cannot "
                                                    "be a module's part"))
        if volume > 0 and not MIN_DENSITY <= m / volume <= MAX_DENSITY:
            what = "denser than any metal" if m / volume > MAX_DENSITY else "lighter than foam"
            per_link.append(("density", name, f"{_WHO}: {_kg(m)} in {1e6 * volume:.4g} cm^3 of collision "
                                                   f"shapes is {m / volume:.4g} kg/m^3, {what}"))
    out = _grouped(per_link)
    shapeless = [k for k in range(len(names)) if masses[k] > 0 and k not in extents]
    if shapeless and total > 0:
        held = float(masses[shapeless].sum())
        listed = ", ".join(f"{names[k]!r} {_kg(masses[k])}" for k in shapeless[:_LISTED])
        more = f" and {len(shapeless) - _LISTED} more" if len(shapeless) > _LISTED else ""
        out.append(Finding("shapeless", tuple(names[k] for k in shapeless),
                           f"{_kg(held)} of the robot's {_kg(total)} ({100 * held / total:.1f} %) sits on "
                           f"{len(shapeless)} link{'s' if len(shapeless) > 1 else ''} without collision shapes: "
                           f"{listed}{more}; their inertia cannot be checked against shapes nor recomputed from them"))
    massive = int(np.sum(masses > 0))
    if massive >= 4 and total > 0:
        k = int(np.argmax(masses))
        if masses[k] > MAX_LINK_SHARE * total:
            out.append(Finding("share", (names[k],), f"link {names[k]!r} holds {_kg(masses[k])}, "
                                                     f"{100 * masses[k] / total:.1f} % of the robot's {_kg(total)} "
                                                     f"over {massive} links with mass: a snake's mass is spread along "
                                                     "its modules"))
    return out


_WHO = "\x00"  # where a per-link finding's text names its link(s)
_LISTED = 6  # names listed in one finding before "and N more"


def _names(links: list[str]) -> str:
    more = f" and {len(links) - _LISTED} more" if len(links) > _LISTED else ""
    return ", ".join(map(repr, links[:_LISTED])) + more


def _grouped(per_link: list[tuple[str, str, str]]) -> list[Finding]:
    """Per-link findings, those of the same kind and numbers on several links (a module repeated) as one."""
    groups: dict[tuple[str, str], list[str]] = {}
    for kind, link, text in per_link:
        groups.setdefault((kind, text), []).append(link)
    out = []
    for (kind, text), links in groups.items():
        who = f"link {links[0]!r}" if len(links) == 1 else f"{len(links)} links ({_names(links)}) each"
        out.append(Finding(kind, tuple(links), text.replace(_WHO, who)))
    return out


def inertia_source(robot: SnakeRobot) -> str:
    """Which inertial data the robot uses, as a line for ``snakehead info``: with "from_shapes", the mass moved from
    links without shapes onto the shapes of their rigid segment (naming them) and the links that keep the URDF's."""
    args = robot.description_arguments
    if args.get("inertia", "urdf") != "from_shapes":
        return "the URDF's <inertial> elements"
    density = args.get("density")
    how = "the URDF's masses" if density is None else f"{float(density):g} kg/m^3"
    line = f"recomputed from the collision shapes (uniform density over each rigid segment, {how})"
    rewrite: InertiaRewrite | None = getattr(robot, "inertia_rewrite", None)
    if rewrite is not None and rewrite.moved:
        listed = ", ".join(f"{name!r} {_kg(m)} -> {_names(list(onto))}" for name, m, onto in rewrite.moved[:_LISTED])
        more = f" and {len(rewrite.moved) - _LISTED} more" if len(rewrite.moved) > _LISTED else ""
        n = len(rewrite.moved)
        line += (f"; {_kg(rewrite.moved_mass)} on {n} link{'s' if n > 1 else ''} without shapes moved onto the "
                 f"shapes fixed to {'them' if n > 1 else 'it'} (now 0 kg): {listed}{more}")
    if rewrite is not None and rewrite.dropped:
        line += f"; <inertial> of massless links without shapes removed: {_names(list(rewrite.dropped))}"
    shaped = set(int(k) for k in robot.shaped_links)
    kept = [n for k, n in enumerate(robot.link_names) if robot.masses[k] > 0 and k not in shaped]
    if kept:
        line += f"; links without shapes in their rigid segment keep the URDF's: {_names(kept)}"
    return line
