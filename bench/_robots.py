"""The robots the benchmarks run (bench/targets.py, bench/sim_gains.py, bench/gaits.py): the default one, generated
snakes from light and short to heavy and long (their parts marked by fixed frames p0 (base end) and b0 (neck end)),
and snakes written the way published ones are (snakehead.samples.published: cylinders, meshes, xacro, modules along
z behind a rotated root, several links per module, a one-joint neck, a 6-DOF head)."""
from __future__ import annotations

import tempfile
from pathlib import Path

from snakehead import SnakeRobot
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.samples import published

_FOLDER = Path(tempfile.mkdtemp(prefix="snakehead-bench-robots-"))


def published_style(style: str) -> SnakeRobot:
    """A published-style sample robot, written to a temporary folder and loaded from its robot file."""
    return SnakeRobot.from_file(published.write_robot(style, _FOLDER / style))


def generated(n_joints, module, section, mass, first_axis="yaw", head=7, neck=2) -> SnakeRobot:
    base = n_joints - head - neck
    urdf = snake_urdf(SnakeSpec(n_joints=n_joints, module_length=module, section=section, mass_per_module=mass,
                                first_axis=first_axis, markers={"p0": base, "b0": base + neck}))
    return SnakeRobot.from_urdf(urdf, base_end="p0", neck_end="b0", head_tip="head_tip")


def reu_as_written(joint_kg: float = 1.0, shell_kg: float = 0.103,
                   inertia: tuple[float, float] | None = (1.0, 2.948)) -> SnakeRobot:
    """The ReU-style sample (three links per module, 5.08 cm across) with its masses and inertias as a published
    ReU description writes them (issue 34): each module's joint link ("in") ``joint_kg`` with an inertia of
    ``inertia[0]`` kg m^2 about every axis, its shell ("body") ``shell_kg`` with ``inertia[1]``, the "out" link
    without an <inertial>. ``inertia=None``: each link's solid-cylinder inertia for its mass instead."""
    import xml.etree.ElementTree as ET

    spec = published.style_spec("reu", mass_per_module=joint_kg + shell_kg, thickness=0.0508)
    root = ET.fromstring(published.reu_urdf(spec))
    for link in root.findall("link"):
        name, inertial = link.get("name", ""), link.find("inertial")
        if inertial is None or not name.startswith("reu_module_"):
            continue
        part = name.split("_")[2]
        if part == "out":
            link.remove(inertial)
            continue
        mass = joint_kg if part == "in" else shell_kg
        written = inertial.find("mass")
        tensor = inertial.find("inertia")
        assert written is not None and tensor is not None
        scale = mass / float(written.get("value", "1"))
        written.set("value", repr(mass))
        for key in ("ixx", "iyy", "izz"):
            moment = float(tensor.get(key, "0")) * scale if inertia is None else inertia[part != "in"]
            tensor.set(key, repr(moment))
    return SnakeRobot.from_urdf(ET.tostring(root, encoding="unicode"), root="reu_tail", base_end="base_end",
                                neck_end="neck_end", head_tip="head_tip")


#: name: (description, builder)
ROBOTS = {
    "default": ("16 joints, 8.65 cm, 0.2 kg", SnakeRobot.default),
    "twenty": ("20 joints, 7 cm, 5 cm section, 0.2 kg", lambda: generated(20, 0.07, 0.05, 0.2)),
    "pitch_first": ("13 joints (pitch first), 10 cm, 6 cm, 0.3 kg",
                    lambda: generated(13, 0.10, 0.06, 0.3, "pitch", head=6, neck=1)),
    "heavy": ("30 joints, 15 cm, 8 cm, 0.5 kg", lambda: generated(30, 0.15, 0.08, 0.5)),
    "light": ("8 joints, 5 cm, 3 cm, 0.1 kg", lambda: generated(8, 0.05, 0.03, 0.1, head=6, neck=1)),
    # issue 34 item 9: the neck has no pitch joint (its lifting part is empty)
    "reu_as_written": ("ReU style, 1 kg joint links and 0.103 kg shells with 1 and 2.948 kg m^2 inertias",
                       reu_as_written),
    "reu_heavy": ("ReU style, 1 kg joint links and 0.103 kg shells with solid-cylinder inertias",
                  lambda: reu_as_written(inertia=None)),
    "yaw_neck": ("13 joints, a one-joint yaw neck before a pitch-first 6-DOF head, 10 cm, 6 cm, 0.3 kg",
                 lambda: generated(13, 0.10, 0.06, 0.3, "yaw", head=6, neck=1)),
}
ROBOTS.update({f"published:{style}": (f"published style {style!r}", lambda style=style: published_style(style))
               for style in published.ALL_STYLES})
