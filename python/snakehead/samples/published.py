"""Sample snake robots written the way published descriptions are, for tests and benchmarks.

``write_robot(style, folder)`` writes one robot into ``folder``: its description (URDF or xacro), any mesh files it
uses, and a robot file (TOML, see docs/own_snake.rst) naming its frames; it returns the robot file's path. Nothing here is
kept in git: every style is generated on the fly, small enough to write in milliseconds.

The styles (:data:`STYLES`), each modelled on a public description but sized near the default robot so that it
plans (modules 6-9 cm long, about 0.2 kg each, alternating yaw/pitch, +-90 deg):

- ``"sea"``: CMU SEA snake. A link-less ``kdl_dummy_root`` and a fixed joint rotated by -90 deg about y; modules
  along their own z, two links each (``moduleK__body``, ``moduleK__output``) joined by a fixed joint; cylinders of
  radius 0.026 m; an STL tail mesh through ``package://sea_snake/...``; every joint's axis "1 0 0", alternation by
  joint frames turned 90 deg about the module axis; the head frame's z points where the head looks.
- ``"reu"``: CMU ReU snake. Three links per module (in, body, out) joined by fixed joints, cylinders along x,
  alternation by the joints' axis attribute.
- ``"rsnake"``: HEBI R8 snake. Modules along y, cylinders of radius 0.05 m centred mid-module (collision origin
  offset and rotated), visual meshes through ``package://`` whose files do not exist.
- ``"mesh"``: a SolidWorks export. Collision meshes as files (binary and ASCII STL, one OBJ in millimetres, one DAE),
  referenced by ``package://cad_snake/...`` and by paths relative to the URDF; ``continuous`` joints, their limits
  in the robot file. The DAE (COLLADA) is read and written by trimesh with pycollada.
- ``"xacro"``: the ``"reu"`` snake as a xacro module macro with ``$(arg n_modules)``, expanded by the PyPI
  ``xacro`` package (no ROS: no ``$(find ...)``).
- ``"one_joint_neck"``: the default convention (:func:`snakehead.model.generate.snake_urdf`), 14 joints, a
  one-joint neck.
- ``"head6"``: the default convention with a 6-joint head whose head link collides as spheres.

The quirk styles (:data:`QUIRK_STYLES`, written by :mod:`snakehead.samples.published_quirks`) do what descriptions
found in public repositories do and the styles above do not (docs/own_snake.rst, "Descriptions found in the wild"):

- ``"cad"``: a SolidWorks export: rolls written ``1.5708``, ``1.57075``, ``1.57076327`` (axes up to 2.6e-4 rad off),
  joint frames 4.4 mm to alternate sides of the body's line, each yaw joint's frame turned 2 deg (curved at q = 0;
  the robot file's ``[home]`` straightens it), STL collisions, collars (turned ``3.14152654``) and IMU mounts on
  fixed side branches.
- ``"reu_reversed"``: the CMU snakes' tree from the head: ``root = "tail"`` (a leaf), ``head_tip =
  "kdl_dummy_root"`` (the URDF's root); ``-1.57075`` twists (axes up to 7e-4 rad off).
- ``"wheeled"``: 32 passive wheels on continuous and revolute (+-7 rad) joints, one with ``axis xyz="0 0 0"``.
- ``"cmu_masses"``: 1 kg joint links with 1 kg m^2 and no geometry, 0.103 kg shells with ixx = 2.948 kg m^2;
  ``inertia = "from_shapes"``.
- ``"backwards_head"``: a head frame whose x points back along the body; ``head_axis = "-x"``.

Every moving joint has effort and velocity limits; every link with a body has an ``<inertial>`` (a module's mass
split between its links by length); marker frames are links without geometry hung from a fixed joint, placed inline
(the next joint hangs from the marker) so that the parts' chains start and end on them.
"""
from __future__ import annotations

import dataclasses
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .._errors import InputError, InputTypeError
from .._validate import finite_float
from ..model.generate import SnakeSpec, holding_effort, snake_urdf
from .urdf_text import (
    box_inertia,
    cylinder,
    cylinder_inertia,
    fixed_joint,
    inertial,
    link,
    mesh,
    moving_joint,
    robot,
    shape,
    sphere,
    write_robot_file,
)

__all__ = [
    "STYLES", "QUIRK_STYLES", "ALL_STYLES", "HALF_PI", "StyleSpec", "DEFAULT_SPECS", "style_spec", "write_robot",
    "parts_comment", "snake_spec", "SEA_TAIL_MESH", "REU_THIRDS", "reu_urdf", "reu_robot_file", "XACRO_DEFAULT_MODULES",
    "reu_xacro", "RSNAKE_VISUAL_MESH", "MESH_OBJ_LINK", "MESH_DAE_LINK", "MM",
]

STYLES = ("sea", "reu", "rsnake", "mesh", "xacro", "one_joint_neck", "head6")
#: Styles with the quirks of descriptions found in public repositories (published_quirks.py).
QUIRK_STYLES = ("cad", "reu_reversed", "wheeled", "cmu_masses", "backwards_head")
ALL_STYLES = STYLES + QUIRK_STYLES

HALF_PI = math.pi / 2


@dataclass(frozen=True)
class StyleSpec:
    """The numbers of a sample robot (SI units; ``_deg`` where the name says so).

    n_joints: moving joints (one per module). module_length: one module, joint to joint (m). thickness: the
    cylinders' diameter or the boxes' section (m). neck_joints / head_joints: the neck's and head's joints (the
    base has the rest). mass_per_module: kg per module_length of body. joint_limit_deg: symmetric limit of every
    joint. velocity (rad/s), effort (N m; None: :func:`holding_effort` for the body): the servo limits.
    name: the robot's name.
    """

    n_joints: int
    module_length: float
    thickness: float
    neck_joints: int = 2
    head_joints: int = 7
    mass_per_module: float = 0.2
    joint_limit_deg: float = 90.0
    velocity: float = 3.0
    effort: float | None = None
    name: str = "snake"

    def __post_init__(self) -> None:
        for key in ("n_joints", "neck_joints", "head_joints"):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise InputError(f"{key} must be a positive integer, got {v!r}")
        if self.base_joints < 1:
            raise InputError(f"n_joints ({self.n_joints}) must exceed neck_joints + head_joints "
                             f"({self.neck_joints} + {self.head_joints}): the base needs a joint")
        for key in ("module_length", "thickness", "mass_per_module", "joint_limit_deg", "velocity"):
            if not finite_float(getattr(self, key), key) > 0:
                raise InputError(f"{key} must be positive, got {getattr(self, key)!r}")
        if self.effort is not None and not finite_float(self.effort, "effort") > 0:
            raise InputError(f"effort must be positive, got {self.effort!r}")
        if self.joint_limit_deg > 180:
            raise InputError(f"joint_limit_deg must be at most 180, got {self.joint_limit_deg}")
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"name must be a non-empty string, got {self.name!r}")

    @property
    def base_joints(self) -> int:
        return self.n_joints - self.neck_joints - self.head_joints

    @property
    def radius(self) -> float:
        return self.thickness / 2

    @property
    def limit(self) -> float:
        """The joints' symmetric limit (rad)."""
        return math.radians(self.joint_limit_deg)

    def mass(self, length: float) -> float:
        """The mass (kg) of ``length`` m of body."""
        return self.mass_per_module * length / self.module_length

    def servo_effort(self, body_length: float) -> float:
        return self.effort if self.effort is not None else holding_effort(
            self.mass_per_module / self.module_length, body_length)


#: Each style's numbers; ``write_robot``'s overrides replace fields. Sizes of the public robots where they fit
#: the planner (the SEA module is 6.39 cm long, 5.2 cm across; the R8 cylinder 10 cm across), else the default's.
DEFAULT_SPECS = {
    "sea": StyleSpec(n_joints=16, module_length=0.0639, thickness=0.052, name="sea_snake"),
    "reu": StyleSpec(n_joints=16, module_length=0.066, thickness=0.05, name="reu_snake"),
    "rsnake": StyleSpec(n_joints=14, module_length=0.09, thickness=0.10, head_joints=6, name="rsnake"),
    "mesh": StyleSpec(n_joints=15, module_length=0.08, thickness=0.045, name="cad_snake"),
    "xacro": StyleSpec(n_joints=14, module_length=0.066, thickness=0.05, name="reu_snake_xacro"),
    "one_joint_neck": StyleSpec(n_joints=14, module_length=0.0865, thickness=0.043, neck_joints=1,
                                name="snake_one_joint_neck"),
    "head6": StyleSpec(n_joints=16, module_length=0.0865, thickness=0.043, head_joints=6, name="snake_head6"),
    # the quirk styles: a student snake's 72.4 mm modules; the SEA module; the default's; the ReU's 1.103 kg
    "cad": StyleSpec(n_joints=16, module_length=0.0724, thickness=0.045, name="cad_snake_sw"),
    "reu_reversed": StyleSpec(n_joints=16, module_length=0.0639, thickness=0.052, name="reu_reversed"),
    "wheeled": StyleSpec(n_joints=16, module_length=0.0865, thickness=0.043, name="wheeled_snake"),
    "cmu_masses": StyleSpec(n_joints=16, module_length=0.066, thickness=0.0508, mass_per_module=1.103,
                            name="cmu_masses"),
    "backwards_head": StyleSpec(n_joints=16, module_length=0.0865, thickness=0.043, name="backwards_head"),
}


def style_spec(style: str, **overrides: Any) -> StyleSpec:
    """The numbers ``write_robot(style, ...)`` uses: the style's defaults with ``overrides`` (StyleSpec fields)."""
    if style not in DEFAULT_SPECS:
        raise InputError(f"unknown style {style!r} (known: {', '.join(ALL_STYLES)})")
    fields = {f.name for f in dataclasses.fields(StyleSpec)}
    unknown = sorted(set(overrides) - fields)
    if unknown:
        raise InputTypeError(f"unknown override{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                        f"(known: {', '.join(sorted(fields))})")
    return dataclasses.replace(DEFAULT_SPECS[style], **overrides)


def write_robot(style: str, folder: str | os.PathLike, **overrides: Any) -> Path:
    """Write the sample robot ``style`` (one of :data:`ALL_STYLES`) into ``folder`` (created if needed): its description,
    its meshes and its robot file. ``overrides`` replace the style's numbers (:class:`StyleSpec` fields, e.g.
    ``n_joints=14``). Returns the robot file's path."""
    spec = style_spec(style, **overrides)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    if style in QUIRK_STYLES:
        from .published_quirks import QUIRK_WRITERS  # it builds on this module's pieces

        return QUIRK_WRITERS[style](spec, out)
    return _WRITERS[style](spec, out)


# --- the styles' shared pieces (their URDF and robot-file text: urdf_text.py) ------------------------------------
def parts_comment(spec: StyleSpec) -> str:
    """The description's comment on the parts of ``spec``: each part's joints, the modules' length, mass, limit."""
    return (f"parts: base {spec.base_joints} joints, neck {spec.neck_joints}, head {spec.head_joints}; "
            f"modules {spec.module_length:g} m, {spec.mass_per_module:g} kg, +-{spec.joint_limit_deg:g} deg")


def _boundary_after(spec: StyleSpec, joint: int) -> str | None:
    """The marker frame that ends a part at the distal end of module ``joint`` (1-based), if any."""
    if joint == spec.base_joints:
        return "base_end"
    if joint == spec.base_joints + spec.neck_joints:
        return "neck_end"
    return None


# --- "sea": CMU SEA snake ----------------------------------------------------------------------------------------
SEA_TAIL_MESH = "meshes/tail.stl"


def _write_sea(spec: StyleSpec, folder: Path) -> Path:
    L, r = spec.module_length, spec.radius
    half = L / 2  # body and output halves of a module
    tail_length = L / 2
    effort = spec.servo_effort(tail_length + spec.n_joints * L)
    _write_tail_mesh(folder / SEA_TAIL_MESH, r, tail_length)
    along_z = (0.0, 0.0, half / 2)
    parts = [link("kdl_dummy_root"),
             # The published description turns the chain so that its modules' z runs along the root's -x.
             fixed_joint("kdl_dummy_root_to_tail", "kdl_dummy_root", "tail", rpy=(0, -HALF_PI, 0)),
             link("tail", inertial(spec.mass(tail_length), (0, 0, tail_length / 2),
                                   cylinder_inertia(spec.mass(tail_length), r, tail_length, 2))
                  + shape("visual", mesh("package://sea_snake/" + SEA_TAIL_MESH))
                  + shape("collision", mesh("package://sea_snake/" + SEA_TAIL_MESH)))]
    parent, offset = "tail", tail_length
    cylinder_half = inertial(spec.mass(half), along_z, cylinder_inertia(spec.mass(half), r, half, 2))
    cylinder_half += shape("visual", cylinder(r, half), along_z) + shape("collision", cylinder(r, half), along_z)
    for k in range(1, spec.n_joints + 1):
        body, output = f"module{k}__body", f"module{k}__output"
        # Every axis is the module's x; each module's frame turns 90 deg about the body (z) from the last one's,
        # so the axes alternate between yaw and pitch.
        twist = 0.0 if k == 1 else HALF_PI
        parts += [moving_joint(f"module{k}__joint", parent, body, (0, 0, offset), (0, 0, twist), "1 0 0",
                               spec.limit, effort, spec.velocity),
                  link(body, cylinder_half),
                  fixed_joint(f"module{k}__body_to_output", body, output, (0, 0, half)),
                  link(output, cylinder_half)]
        parent, offset = output, half
        marker = _boundary_after(spec, k)
        if marker:
            parts += [fixed_joint(f"{marker}_joint", parent, marker, (0, 0, offset)), link(marker)]
            parent, offset = marker, 0.0
    parts += [fixed_joint("head_tip_joint", parent, "head_tip", (0, 0, offset)), link("head_tip")]
    urdf = folder / "sea_snake.urdf"
    urdf.write_text(robot(spec.name, f"{spec.name}: SEA-snake style sample robot written by snakehead.model."
                                     f"published; {parts_comment(spec)}", parts), encoding="utf-8")
    return write_robot_file(folder / "sea_snake.toml", "SEA-snake style: dummy root, modules along z, head's z",
                            {"urdf": urdf.name, "root": "kdl_dummy_root", "base_end": "base_end",
                             "neck_end": "neck_end", "head_tip": "head_tip", "head_axis": "z"},
                            {"packages": {"sea_snake": "."}})


def _write_tail_mesh(path: Path, radius: float, length: float) -> None:
    """The SEA tail: a cylinder cap along z from 0 to ``length``, written as binary STL."""
    import trimesh  # heavy to import: only the mesh style needs it

    cap = trimesh.creation.cylinder(radius=radius, height=length, sections=24)
    cap.apply_translation((0, 0, length / 2))
    path.parent.mkdir(parents=True, exist_ok=True)
    cap.export(path, file_type="stl")


# --- "reu": CMU ReU snake ----------------------------------------------------------------------------------------
#: The in, body and out links' shares of a ReU module's length.
REU_THIRDS = (("in", 0.2), ("body", 0.6), ("out", 0.2))


def _reu_axis(joint: int) -> str:
    return "0 0 1" if joint % 2 == 1 else "0 1 0"  # odd joints yaw, even joints pitch


def _cylinder_along_x(spec: StyleSpec, length: float) -> str:
    centre = (length / 2, 0.0, 0.0)
    # A URDF cylinder runs along its own z: turned by 90 deg about y it runs along the link's x.
    tube = cylinder(spec.radius, length)
    return (inertial(spec.mass(length), centre, cylinder_inertia(spec.mass(length), spec.radius, length, 0))
            + shape("visual", tube, centre, (0, HALF_PI, 0)) + shape("collision", tube, centre, (0, HALF_PI, 0)))


def reu_urdf(spec: StyleSpec) -> str:
    """The URDF of the ReU-style snake ``spec`` (the ``"reu"`` style; ``"xacro"`` writes the same snake)."""
    L = spec.module_length
    tail_length = L / 2
    effort = spec.servo_effort(tail_length + spec.n_joints * L)
    parts = [link("reu_tail", _cylinder_along_x(spec, tail_length))]
    parent, offset = "reu_tail", tail_length
    for k in range(1, spec.n_joints + 1):
        names = [f"reu_module_{part}_{k}" for part, _ in REU_THIRDS]
        lengths = [share * L for _, share in REU_THIRDS]
        parts.append(moving_joint(f"reu_joint_{k}", parent, names[0], (offset, 0, 0), (0, 0, 0), _reu_axis(k),
                                  spec.limit, effort, spec.velocity))
        for i, (name, length) in enumerate(zip(names, lengths)):
            parts.append(link(name, _cylinder_along_x(spec, length)))
            if i + 1 < len(names):
                parts.append(fixed_joint(f"{name}_to_{REU_THIRDS[i + 1][0]}", name, names[i + 1], (length, 0, 0)))
        parent, offset = names[-1], lengths[-1]
        marker = _boundary_after(spec, k)
        if marker:
            parts += [fixed_joint(f"{marker}_joint", parent, marker, (offset, 0, 0)), link(marker)]
            parent, offset = marker, 0.0
    parts += [fixed_joint("head_tip_joint", parent, "head_tip", (offset, 0, 0)), link("head_tip")]
    return robot(spec.name, f"{spec.name}: ReU-snake style sample robot written by snakehead.samples.published; "
                            f"{parts_comment(spec)}", parts)


def reu_robot_file(folder: Path, stem: str, description: str, xacro_args: dict[str, Any] | None = None) -> Path:
    """Write the ReU-style snake's robot file ``folder/stem.toml`` for the description file ``description`` (a URDF,
    or a xacro file expanded with ``xacro_args``); return its path."""
    return write_robot_file(folder / f"{stem}.toml", "ReU-snake style: three links per module, modules along x",
                            {"urdf": description, "xacro_args": xacro_args, "root": "reu_tail",
                             "base_end": "base_end", "neck_end": "neck_end", "head_tip": "head_tip"}, {})


def _write_reu(spec: StyleSpec, folder: Path) -> Path:
    urdf = folder / "reu_snake.urdf"
    urdf.write_text(reu_urdf(spec), encoding="utf-8")
    return reu_robot_file(folder, "reu_snake", urdf.name)


# --- "xacro": the ReU snake as a xacro macro (published_xacro.py) -----------------------------------------------------
#: The xacro file's own default module count; the robot file passes the spec's through ``xacro_args``.
XACRO_DEFAULT_MODULES = 16


def reu_xacro(spec: StyleSpec) -> str:
    """The ReU-style snake as a xacro file (:func:`snakehead.samples.published_xacro.reu_xacro`): expanded with
    ``n_modules = spec.n_joints`` it is :func:`reu_urdf` of ``spec``."""
    from .published_xacro import reu_xacro as written  # it builds on this module's pieces

    return written(spec)


def _write_xacro(spec: StyleSpec, folder: Path) -> Path:
    from .published_xacro import write_xacro  # it builds on this module's pieces

    return write_xacro(spec, folder)



# --- "rsnake": HEBI R8 snake -------------------------------------------------------------------------------------
RSNAKE_VISUAL_MESH = "package://rsnake_description/meshes/R8_16_link.stl"


def _write_rsnake(spec: StyleSpec, folder: Path) -> Path:
    L, r = spec.module_length, spec.radius
    effort = spec.servo_effort((spec.n_joints + 1) * L)
    centre = (0.0, L / 2, 0.0)
    # The cylinder (along its z) is turned 90 deg about x to run along the module (y), centred mid-module.
    module_body = (inertial(spec.mass(L), centre, cylinder_inertia(spec.mass(L), r, L, 1))
                   + shape("visual", mesh(RSNAKE_VISUAL_MESH, 0.001))
                   + shape("collision", cylinder(r, L), centre, (HALF_PI, 0, 0)))
    parts = [link("module_0", module_body)]
    parent, offset = "module_0", L
    for k in range(1, spec.n_joints + 1):
        axis = "0 0 1" if k % 2 == 1 else "1 0 0"  # yaw (up), pitch (across the body)
        parts += [moving_joint(f"module_{k}_joint", parent, f"module_{k}", (0, offset, 0), (0, 0, 0), axis,
                               spec.limit, effort, spec.velocity),
                  link(f"module_{k}", module_body)]
        parent, offset = f"module_{k}", L
        marker = _boundary_after(spec, k)
        if marker:
            parts += [fixed_joint(f"{marker}_joint", parent, marker, (0, offset, 0)), link(marker)]
            parent, offset = marker, 0.0
    # A head frame turned so that its x runs along the body (y), as a camera frame would be added.
    parts += [fixed_joint("head_tip_joint", parent, "head_tip", (0, offset, 0), (0, 0, HALF_PI)), link("head_tip")]
    urdf = folder / "rsnake.urdf"
    urdf.write_text(robot(spec.name, f"{spec.name}: HEBI R8 (RSNAKE) style sample robot written by snakehead.model."
                                     f"published; visual meshes deliberately absent; {parts_comment(spec)}", parts),
                    encoding="utf-8")
    # The visual meshes' package is known but its files are not there: a loader must not need visuals.
    return write_robot_file(folder / "rsnake.toml", "RSNAKE style: modules along y, offset cylinders, no root key",
                            {"urdf": urdf.name, "base_end": "base_end", "neck_end": "neck_end",
                             "head_tip": "head_tip"}, {"packages": {"rsnake_description": "."}})


# --- "mesh": SolidWorks export -----------------------------------------------------------------------------------
#: The link (0 = base_link) whose mesh is an OBJ in millimetres, as CAD tools often write them.
MESH_OBJ_LINK = 5
#: The link of the "mesh" style whose collision mesh is COLLADA (DAE, read and written by trimesh with pycollada).
MESH_DAE_LINK = 3
MM = 0.001


def _mesh_file(index: int) -> tuple[str, str]:
    """(file name, trimesh file type) of link ``index``'s collision mesh (0: base_link): binary STL on even links,
    ASCII STL on odd ones, one OBJ, one COLLADA (DAE)."""
    if index == MESH_OBJ_LINK:
        return f"link{index}.obj", "obj"
    if index == MESH_DAE_LINK:
        return f"link{index}.dae", "dae"
    name = "base_link" if index == 0 else f"link{index}"
    return f"{name}.STL", "stl" if index % 2 == 0 else "stl_ascii"


def _write_link_mesh(path: Path, file_type: str, length: float, section: float, head: bool, scale: float) -> None:
    import trimesh  # heavy to import: only the mesh style needs it

    if head:
        # A rounded head: a capsule along x whose ends reach the link's two ends.
        solid = trimesh.creation.capsule(height=max(length - section, 1e-3), radius=section / 2)
        solid.apply_transform(trimesh.transformations.rotation_matrix(HALF_PI, (0, 1, 0)))
    else:
        solid = trimesh.creation.box(extents=(length, section, section))
    solid.apply_translation((length / 2, 0, 0))
    solid.apply_scale(1 / scale)
    path.parent.mkdir(parents=True, exist_ok=True)
    solid.export(path, file_type=file_type)


def _write_mesh(spec: StyleSpec, folder: Path) -> Path:
    L, s, n = spec.module_length, spec.thickness, spec.n_joints
    lengths = [L / 2] + [L] * (n - 1) + [L / 2]
    effort = spec.servo_effort(sum(lengths))
    names = ["base_link"] + [f"link{k}" for k in range(1, n + 1)]
    parts = []
    limits = {}
    for i, (name, length) in enumerate(zip(names, lengths)):
        file_name, file_type = _mesh_file(i)
        scale = MM if file_type == "obj" else 1.0
        _write_link_mesh(folder / "meshes" / file_name, file_type, length, s, head=i == n, scale=scale)
        # Half the meshes through the package, half relative to the URDF's folder: exporters write both.
        reference = f"package://cad_snake/meshes/{file_name}" if i % 2 == 0 else f"meshes/{file_name}"
        m = spec.mass(length)
        centre = (length / 2, 0.0, 0.0)
        parts.append(link(name, inertial(m, centre, box_inertia(m, (length, s, s)))
                          + shape("visual", mesh(reference, scale)) + shape("collision", mesh(reference, scale))))
    parent, offset = names[0], lengths[0]
    for k in range(1, n + 1):
        axis = "0 0 1" if k % 2 == 1 else "0 1 0"
        parts.append(moving_joint(f"joint{k}", parent, names[k], (offset, 0, 0), (0, 0, 0), axis, spec.limit, effort,
                                  spec.velocity, continuous=True))
        limits[f"joint{k}"] = [-spec.limit, spec.limit]
        parent, offset = names[k], lengths[k]
        marker = _boundary_after(spec, k)
        if marker:
            parts += [fixed_joint(f"{marker}_joint", parent, marker, (offset, 0, 0)), link(marker)]
            parent, offset = marker, 0.0
    parts += [fixed_joint("head_tip_joint", parent, "head_tip", (offset, 0, 0)), link("head_tip")]
    urdf = folder / "cad_snake.urdf"
    urdf.write_text(robot(spec.name, f"{spec.name}: SolidWorks-export style sample robot written by snakehead.model."
                                     f"published; collision meshes, continuous joints; {parts_comment(spec)}",
                          parts), encoding="utf-8")
    return write_robot_file(folder / "cad_snake.toml", "CAD export style: mesh collisions, continuous joints",
                            {"urdf": urdf.name, "root": "base_link", "base_end": "base_end",
                             "neck_end": "neck_end", "head_tip": "head_tip"},
                            {"packages": {"cad_snake": "."}, "limits": limits})


# --- "one_joint_neck" and "head6": the default convention --------------------------------------------------------
def snake_spec(spec: StyleSpec, first_axis: str = "yaw") -> SnakeSpec:
    """``spec`` as the default convention's :class:`~snakehead.model.generate.SnakeSpec` (for
    :func:`~snakehead.model.generate.snake_urdf`), its marker frames ``base_end`` and ``neck_end`` between the parts;
    joint 1's axis is ``first_axis``."""
    return SnakeSpec(n_joints=spec.n_joints, module_length=spec.module_length, section=spec.thickness,
                     mass_per_module=spec.mass_per_module, joint_limit_deg=spec.joint_limit_deg, effort=spec.effort,
                     velocity=spec.velocity, name=spec.name, first_axis=first_axis,
                     markers={"base_end": spec.base_joints, "neck_end": spec.base_joints + spec.neck_joints})


def _default_robot_file(folder: Path, stem: str, urdf: str, comment: str) -> Path:
    return write_robot_file(folder / f"{stem}.toml", comment,
                            {"urdf": urdf, "root": "link_0", "base_end": "base_end", "neck_end": "neck_end",
                             "head_tip": "head_tip"}, {})


def _write_one_joint_neck(spec: StyleSpec, folder: Path) -> Path:
    urdf = folder / "snake_one_joint_neck.urdf"
    # the neck's one joint pitches (it lifts the head's base): the axes alternate from whichever joint 1 needs
    first = "pitch" if spec.base_joints % 2 == 0 else "yaw"
    urdf.write_text(snake_urdf(snake_spec(spec, first)), encoding="utf-8")
    return _default_robot_file(folder, "snake_one_joint_neck", urdf.name, "default convention, one-joint neck")


def _with_sphere_head(urdf: str, head_link: str, length: float, radius: float) -> str:
    """``urdf`` with the collision of ``head_link`` (a link along x of ``length`` m) replaced by two spheres."""
    root = ET.fromstring(urdf)
    head = root.find(f"link[@name='{head_link}']")
    if head is None:
        raise InputError(f"no link {head_link!r}")
    for old in head.findall("collision"):
        head.remove(old)
    for x in (length / 4, 3 * length / 4):
        head.append(ET.fromstring(shape("collision", sphere(radius), (x, 0, 0)).strip()))
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _write_head6(spec: StyleSpec, folder: Path) -> Path:
    snake = snake_spec(spec)
    urdf = folder / "snake_head6.urdf"
    urdf.write_text(_with_sphere_head(snake_urdf(snake), f"link_{spec.n_joints}", snake.link_length(spec.n_joints),
                                      spec.thickness / 2), encoding="utf-8")
    return _default_robot_file(folder, "snake_head6", urdf.name, "default convention, 6-joint head, sphere head")


_WRITERS: dict[str, Callable[[StyleSpec, Path], Path]] = {
    "sea": _write_sea, "reu": _write_reu, "rsnake": _write_rsnake, "mesh": _write_mesh, "xacro": _write_xacro,
    "one_joint_neck": _write_one_joint_neck, "head6": _write_head6,
}
