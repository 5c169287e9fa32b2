"""Sample snakes with the quirks of descriptions found in public repositories (issue 34), in snakehead's own files.

:func:`snakehead.samples.published.write_robot` writes these styles (:data:`QUIRK_STYLES`) as it writes the others;
this module holds their writers. What each reproduces, and where it was seen (docs/own_snake.rst, "Descriptions
found in the wild"):

- ``"cad"``: a SolidWorks-to-URDF export (student snakes). Modules along x, one mesh link per module
  (``base_link``, ``link1`` ...), every axis "0 0 1" with the alternation written as roll turns ``1.5708``,
  ``1.57075``, ``1.57076327`` and ``-1.5708`` (the axes end up to a few 1e-4 rad off the body's y or z); joint
  frames :data:`CAD_SIDE_OFFSET` to alternate sides of the body's line; every yaw joint's frame turned
  :data:`CAD_DRIFT` about its axis, so the body is curved at q = 0 and the robot file's ``[home]`` gives the angles
  at which it lies straight; binary STL collisions through ``package://``; sensor collars (fixed, turned by
  ``3.14152654``) and IMU mounts hanging off the body with mass and shapes.
- ``"reu_reversed"``: the CMU snakes' tree, written from the head: ``kdl_dummy_root`` (turned ``0 -1.57079632679
  0``) is the head's front, the modules run along their z to a ``tail`` leaf, the alternation is a ``-1.57075``
  twist about z per module (SEA style). The robot file says ``root = "tail"`` and ``head_tip = "kdl_dummy_root"``.
- ``"wheeled"``: passive wheels on ``continuous`` and ``revolute`` (+-7 rad) joints hanging off each module, one
  wheel with ``<axis xyz="0 0 0"/>`` (as a published SolidWorks export has), their bottoms 1 mm below the body's.
- ``"cmu_masses"``: the ReU-style snake with the ReU description's inertial data: each module's joint link 1 kg
  with an inertia of 1 kg m^2 and no geometry, the shell 0.103 kg with ixx = 2.948 kg m^2 and products of inertia,
  the output link 0 kg with 1 kg m^2; the robot file asks for ``inertia = "from_shapes"``.
- ``"backwards_head"``: the default convention with a head frame turned by ``3.14152654`` about z (its x points back
  along the body, as the CMU snakes' head-root frames do); the robot file says ``head_axis = "-x"``.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING, Callable

import numpy as np

from .._errors import InputError
from ..model.generate import snake_urdf
from .published import HALF_PI, parts_comment, reu_urdf, snake_spec
from .urdf_text import (
    box_inertia,
    cylinder,
    cylinder_inertia,
    fixed_joint,
    inertial,
    link,
    mesh,
    moving_joint,
    num,
    robot,
    shape,
    vec,
    write_robot_file,
)

if TYPE_CHECKING:
    from .published import StyleSpec

QUIRK_STYLES = ("cad", "reu_reversed", "wheeled", "cmu_masses", "backwards_head")

#: "cad": how far (m) each joint frame sits to the side of the body's line (alternate sides).
CAD_SIDE_OFFSET = 0.0044
#: "cad": the turn (rad, as written) of every yaw joint's frame about its axis; home is minus this.
CAD_DRIFT = 0.034907
#: "cad": the roll texts of the pitch joints' frames, in turn (an exact quarter turn is 1.5707963...).
CAD_PITCH_ROLLS = ("1.57075", "1.57076327", "1.5708")
#: "cad": the roll text of the yaw joints' frames (back from a pitch frame).
CAD_YAW_ROLL = "-1.5708"
#: "cad": the half turn, as written, of the sensor collars' frames.
CAD_COLLAR_TURN = "3.14152654"
#: "reu_reversed": the twist (as written) about the module axis from one module to the next.
REVERSED_TWIST = "-1.57075"
#: "backwards_head": the head frame's turn about z, as written.
BACKWARDS_TURN = "3.14152654"
#: "cmu_masses": the inertial data of the ReU description: the shell's mass (kg) and inertia (kg m^2), and the
#: joint link's and the output link's inertia.
CMU_SHELL_MASS = 0.103
CMU_SHELL_INERTIA = {"ixx": 2.948, "ixy": 0.045, "ixz": 0.409, "iyy": 2.931, "iyz": -0.405, "izz": 1.819}
CMU_UNIT_INERTIA = {"ixx": 1.0, "ixy": 0.0, "ixz": 0.0, "iyy": 1.0, "iyz": 0.0, "izz": 1.0}


def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _stl_box(path: Path, extents: tuple[float, float, float], centre: np.ndarray) -> None:
    import trimesh  # heavy to import: only the cad style's meshes need it

    box = trimesh.creation.box(extents=extents)
    box.apply_translation(centre)
    path.parent.mkdir(parents=True, exist_ok=True)
    box.export(path, file_type="stl")


def _inertial_full(mass: float, com: tuple[float, ...] | np.ndarray, inertia: dict[str, float]) -> str:
    values = " ".join(f'{k}="{num(v)}"' for k, v in inertia.items())
    return (f"    <inertial>\n      <origin xyz=\"{vec(tuple(float(c) for c in com))}\" rpy=\"0 0 0\"/>\n      <mass value=\"{num(mass)}\"/>\n"
            f"      <inertia {values}/>\n    </inertial>\n")


# --- "cad": a SolidWorks export ----------------------------------------------------------------------------------
def cad_home(spec: StyleSpec) -> dict[str, float]:
    """The "cad" style's home pose (joint -> rad): minus the drift on every yaw (odd) joint, 0 on the others."""
    return {f"joint{k}": (-CAD_DRIFT if k % 2 == 1 else 0.0) for k in range(1, spec.n_joints + 1)}


def _write_cad(spec: StyleSpec, folder: Path) -> Path:
    n, L, s = spec.n_joints, spec.module_length, spec.thickness
    lengths = [L / 2] + [L] * (n - 1) + [L / 2]
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    effort = spec.servo_effort(sum(lengths))
    # Home (straight) frames: yaw links world-aligned, pitch links turned a quarter about x; frames zig-zag across.
    rot = [_rx(HALF_PI) if k % 2 == 0 and k > 0 else np.eye(3) for k in range(n + 1)]
    # sides +, -, -, + along each four links: the frames' least-squares line is the body's own line
    side = [0.0] + [CAD_SIDE_OFFSET * (1 if (k - 1) % 4 in (0, 3) else -1) for k in range(1, n + 1)]
    pos = [np.array([starts[k], side[k], 0.0]) for k in range(n + 1)]
    names = ["base_link"] + [f"link{k}" for k in range(1, n + 1)]
    collar_mass, mount_mass = 0.012, 0.006
    parts = []
    for k, (name, length) in enumerate(zip(names, lengths)):
        centre_world = np.array([starts[k] + length / 2, 0.0, 0.0])
        centre = rot[k].T @ (centre_world - pos[k])
        mesh_name = f"meshes/{name}.STL"
        _stl_box(folder / mesh_name, (length, s, s), centre)
        mass = spec.mass(length) - (collar_mass if k % 4 == 2 else 0.0) - (mount_mass if k % 4 == 3 else 0.0)
        reference = f"package://cad_snake_sw/{mesh_name}"
        parts.append(link(name, inertial(mass, centre, box_inertia(mass, (length, s, s)))
                          + shape("visual", mesh(reference)) + shape("collision", mesh(reference))))
        if k % 4 == 2:  # a sensor collar round the module's middle, mounted half a turn about the body's axis
            parts += [fixed_joint(f"collar{k}_joint", name, f"collar{k}", centre, (0, 0, 0)),
                      link(f"collar{k}", inertial(collar_mass, (0, 0, 0),
                                                  cylinder_inertia(collar_mass, s / 2, 0.012, 0))
                           + shape("collision", cylinder(s / 2, 0.012), (0, 0, 0), (0, HALF_PI, 0)))]
            parts[-2] = parts[-2].replace('rpy="0 0 0"', f'rpy="{CAD_COLLAR_TURN} 0 0"')
        if k % 4 == 3:  # an IMU mount on top of a yaw module
            mount = rot[k].T @ (centre_world + np.array([0.0, 0.0, s / 2 + 0.004]) - pos[k])
            parts += [fixed_joint(f"imu{k}_joint", name, f"imu{k}", mount),
                      link(f"imu{k}", inertial(mount_mass, (0, 0, 0), box_inertia(mount_mass, (0.02, 0.016, 0.008)))
                           + shape("collision", '<box size="0.02 0.016 0.008"/>'))]
    for k in range(1, n + 1):
        xyz = rot[k - 1].T @ (pos[k] - pos[k - 1])
        if k == 1:
            rpy = f"0 0 {num(CAD_DRIFT)}"
        elif k % 2 == 0:
            rpy = f"{CAD_PITCH_ROLLS[(k // 2 - 1) % len(CAD_PITCH_ROLLS)]} 0 0"
        else:  # back from a pitch frame, turned by the drift about the joint's own axis: Rx(-pi/2) Rz(d) = Ry(d) Rx(-pi/2)
            rpy = f"{CAD_YAW_ROLL} {num(CAD_DRIFT)} 0"
        joint = moving_joint(f"joint{k}", names[k - 1], names[k], xyz, (0, 0, 0), "0 0 1", spec.limit, effort,
                             spec.velocity)
        parts.append(joint.replace('rpy="0 0 0"', f'rpy="{rpy}"'))
    tip = rot[n].T @ (np.array([starts[n + 1], 0.0, 0.0]) - pos[n])
    parts += [fixed_joint("head_tip_joint", names[n], "head_tip", tip, (-HALF_PI if n % 2 == 0 else 0, 0, 0)),
              link("head_tip")]
    urdf = folder / "cad_snake_sw.urdf"
    urdf.write_text(robot(spec.name, f"{spec.name}: written by snakehead.samples.published_quirks in the manner of a "
                                     f"SolidWorks to URDF export; {parts_comment(spec)}", parts), encoding="utf-8")
    b, nn = spec.base_joints, spec.neck_joints
    return write_robot_file(folder / "cad_snake_sw.toml",
                            "SolidWorks export style: near-right angles, frames off the line, curved at q = 0",
                            {"urdf": urdf.name, "root": "base_link", "base_end": f"link{b}",
                             "neck_end": f"link{b + nn}", "head_tip": "head_tip"},
                            {"packages": {"cad_snake_sw": "."}, "home": cad_home(spec)})


# --- "reu_reversed": the tree written from the head --------------------------------------------------------------
#: The share of a module's length before its joint (the input link); the output link has the rest.
REVERSED_INPUT_SHARE = 0.55


def _write_reu_reversed(spec: StyleSpec, folder: Path) -> Path:
    n, L, r = spec.n_joints, spec.module_length, spec.radius
    a = REVERSED_INPUT_SHARE * L
    cap = L / 2
    effort = spec.servo_effort(2 * cap + n * L)

    def along_z(length: float) -> str:
        centre = (0.0, 0.0, length / 2)
        m = spec.mass(length)
        return (inertial(m, centre, cylinder_inertia(m, r, length, 2))
                + shape("visual", cylinder(r, length), centre) + shape("collision", cylinder(r, length), centre))

    parts = [link("kdl_dummy_root"),
             fixed_joint("kdl_dummy_root_to_head", "kdl_dummy_root", "head", rpy=(0, 0, 0)).replace(
                 'rpy="0 0 0"', 'rpy="0 -1.57079632679 0"'),
             link("head", along_z(cap))]
    parent, offset, twist = "head", cap, "0"
    for m in range(1, n + 1):
        inp, out = f"mod_{m}_in", f"mod_{m}_out"
        parts.append(fixed_joint(f"{parent}_to_{inp}", parent, inp, (0, 0, offset)).replace(
            'rpy="0 0 0"', f'rpy="0 0 {twist}"'))
        parts += [link(inp, along_z(a)),
                  moving_joint(f"mod_{m}_joint", inp, out, (0, 0, a), (0, 0, 0), "0 1 0", spec.limit, effort,
                               spec.velocity),
                  link(out, along_z(L - a))]
        parent, offset, twist = out, L - a, REVERSED_TWIST
    parts += [fixed_joint(f"{parent}_to_tail", parent, "tail", (0, 0, offset)).replace(
        'rpy="0 0 0"', f'rpy="0 0 {twist}"'), link("tail", along_z(cap))]
    urdf = folder / "reu_reversed.urdf"
    urdf.write_text(robot(spec.name, f"{spec.name}: written by snakehead.samples.published_quirks in the manner of "
                                     f"the CMU snakes' descriptions (tree from the head); {parts_comment(spec)}",
                          parts), encoding="utf-8")
    b, nn = spec.base_joints, spec.neck_joints
    # The chain from the tail up to mod_K_in crosses joints n .. K.
    return write_robot_file(folder / "reu_reversed.toml", "head at the URDF's root: the body runs against the tree",
                            {"urdf": urdf.name, "root": "tail", "base_end": f"mod_{n - b + 1}_in",
                             "neck_end": f"mod_{n - b - nn + 1}_in", "head_tip": "kdl_dummy_root"}, {})


# --- "wheeled": passive wheels off every module ------------------------------------------------------------------
WHEEL_WIDTH = 0.008
WHEEL_MASS = 0.01
#: "wheeled": how far (m) the wheels' bottoms reach below the body's (the wheels carry the snake).
WHEEL_DROP = 0.001
#: "wheeled": the wheel whose joint has the zero axis "0 0 0" (link index, side).
ZERO_AXIS_WHEEL = (2, "right")


def wheel_joints(spec: StyleSpec) -> list[str]:
    """The "wheeled" style's wheel joints (one pair on every link but the head link)."""
    return [f"wheel_{i}_{side}_joint" for i in range(spec.n_joints) for side in ("left", "right")]


def _write_wheeled(spec: StyleSpec, folder: Path) -> Path:
    snake = snake_spec(spec)
    text = snake_urdf(snake)
    s = spec.thickness
    rw = 0.6 * s
    wheels = []
    for i in range(spec.n_joints):
        for side, sign in (("left", 1.0), ("right", -1.0)):
            name = f"wheel_{i}_{side}"
            xyz = (snake.link_length(i) / 2, sign * (s / 2 + WHEEL_WIDTH / 2 + 0.002), -s / 2 + rw - WHEEL_DROP)
            continuous = (2 * i + (side == "right")) % 3 != 0
            joint = moving_joint(f"{name}_joint", f"link_{i}", name, xyz, (0, 0, 0), "0 0 1", spec.limit, 1.0,
                                 spec.velocity, continuous=continuous)
            joint = joint.replace('rpy="0 0 0"', 'rpy="-1.5708 0 0"')
            if not continuous:  # the exporter's default range for a passive joint
                joint = joint.replace(f'lower="{num(-spec.limit)}" upper="{num(spec.limit)}"',
                                      'lower="-7" upper="7"')
            if (i, side) == ZERO_AXIS_WHEEL:
                joint = joint.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
            wheels += [joint, link(name, inertial(WHEEL_MASS, (0, 0, 0),
                                                  cylinder_inertia(WHEEL_MASS, rw, WHEEL_WIDTH, 2))
                                   + shape("collision", cylinder(rw, WHEEL_WIDTH)))]
    text = text.replace("</robot>", "".join(wheels) + "</robot>")
    urdf = folder / "wheeled_snake.urdf"
    urdf.write_text(text, encoding="utf-8")
    return write_robot_file(folder / "wheeled_snake.toml", "passive wheels on every module, held at zero",
                            {"urdf": urdf.name, "root": "link_0", "base_end": "base_end", "neck_end": "neck_end",
                             "head_tip": "head_tip"}, {})


# --- "cmu_masses": the ReU description's inertial data -----------------------------------------------------------
def _write_cmu_masses(spec: StyleSpec, folder: Path) -> Path:
    root = ET.fromstring(reu_urdf(spec))
    L = spec.module_length
    joint_mass = spec.mass_per_module - CMU_SHELL_MASS
    for element in root.findall("link"):
        name = element.get("name", "")
        if not name.startswith("reu_module_"):
            continue
        for old in element.findall("inertial") + element.findall("collision") + element.findall("visual"):
            element.remove(old)
        if name.startswith("reu_module_in_"):
            body = _inertial_full(joint_mass, (0, 0, 0), CMU_UNIT_INERTIA)
            body += shape("visual", cylinder(0.006, 0.02), (0, 0, 0), (0, HALF_PI, 0))
        elif name.startswith("reu_module_body_"):
            # the shell's collision covers the whole module: from -0.2 L to 0.8 L in the body link's frame
            centre = (0.3 * L, 0.0, 0.0)
            body = _inertial_full(CMU_SHELL_MASS, (0.3 * L, 0, 0), CMU_SHELL_INERTIA)
            body += shape("collision", cylinder(spec.radius, L), centre, (0, HALF_PI, 0))
        else:
            body = _inertial_full(0.0, (0, 0, 0), CMU_UNIT_INERTIA)
        for child in ET.fromstring(f"<x>{body}</x>"):
            element.append(child)
    urdf = folder / "cmu_masses.urdf"
    urdf.write_text('<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n", encoding="utf-8")
    return write_robot_file(folder / "cmu_masses.toml", "ReU inertial data: 1 kg joint links without geometry",
                            {"urdf": urdf.name, "root": "reu_tail", "base_end": "base_end", "neck_end": "neck_end",
                             "head_tip": "head_tip", "inertia": "from_shapes"}, {})


# --- "backwards_head": a head frame that looks back --------------------------------------------------------------
def _write_backwards_head(spec: StyleSpec, folder: Path) -> Path:
    root = ET.fromstring(snake_urdf(snake_spec(spec)))
    origin = root.find("joint[@name='head_tip_joint']/origin")
    if origin is None:
        raise InputError("the default-convention URDF has no head_tip_joint origin")
    origin.set("rpy", f"0 0 {BACKWARDS_TURN}")
    urdf = folder / "backwards_head.urdf"
    urdf.write_text('<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n", encoding="utf-8")
    return write_robot_file(folder / "backwards_head.toml", "the head frame's x points back along the body",
                            {"urdf": urdf.name, "root": "link_0", "base_end": "base_end", "neck_end": "neck_end",
                             "head_tip": "head_tip", "head_axis": "-x"}, {})


QUIRK_WRITERS: dict[str, Callable[["StyleSpec", Path], Path]] = {
    "cad": _write_cad, "reu_reversed": _write_reu_reversed, "wheeled": _write_wheeled,
    "cmu_masses": _write_cmu_masses, "backwards_head": _write_backwards_head,
}
