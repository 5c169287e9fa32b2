"""Every description error names the element (issue 34, item 6), and valid descriptions never exit 3.

A robot file's description with a defect -- a malformed number in an origin, axis, limit, inertia or shape, a zero
axis, a mesh that is missing, empty, not a mesh or flat once scaled, duplicate names, a joint naming a link that is
not there, a loop, two roots -- stops ``snakehead info`` with exit 2 and one line that names the link or joint, the
element and (where there is one) the attribute and the mesh file. Published descriptions with default (x) axes and
STL collisions scaled from millimetres load.

The property tests take the sample descriptions (``published.write_robot``) through valid variations (numbers within
their ranges, visual meshes whose files are absent, elements reordered, links added on fixed joints): ``info``
exits 0, 1 or 2, never 3; and through invalid mutations of a drawn element: exit 2 with a line naming it.
"""
from __future__ import annotations

import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Callable

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from snakehead import InputError, SnakeRobot
from snakehead.app import cli
from snakehead.geometry.meshes import convex_hull_vertices
from snakehead.model.description import check_description
from snakehead.samples.published import write_robot

EXIT_BAD_INPUT, EXIT_INTERNAL = 2, 3


@pytest.fixture(scope="module")
def samples(tmp_path_factory) -> dict[str, Path]:
    """Sample robots, each written once (copied before each change)."""
    root = tmp_path_factory.mktemp("samples")
    return {style: write_robot(style, root / style) for style in ("reu", "sea", "mesh", "cad")}


def copy(robot_file: Path, into: Path) -> tuple[Path, Path]:
    """The sample's folder copied into ``into``: (its robot file, its description)."""
    shutil.copytree(robot_file.parent, into, dirs_exist_ok=True)
    toml = into / robot_file.name
    urdf = next(p for p in into.iterdir() if p.suffix == ".urdf")
    return toml, urdf


def info(toml: Path, capsys) -> tuple[int, str]:
    """``snakehead info --robot toml``: its exit status and the last line of stderr."""
    capsys.readouterr()
    status = cli.main(["info", "--robot", str(toml)])
    err = capsys.readouterr().err.strip()
    return status, err.splitlines()[-1] if err else ""


def substitute(pattern: str, replacement: str | Callable) -> Callable[[Path, Path], None]:
    def change(folder: Path, urdf: Path) -> None:
        text = urdf.read_text(encoding="utf-8")
        changed = re.sub(pattern, replacement, text, count=1, flags=re.S)
        assert changed != text, pattern
        urdf.write_text(changed, encoding="utf-8")
    return change


def write_file(name: str, data: bytes | str) -> Callable[[Path, Path], None]:
    def change(folder: Path, urdf: Path) -> None:
        (folder / name).write_bytes(data if isinstance(data, bytes) else data.encode())
    return change


FLAT_STL = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]]).export(file_type="stl")
REU_J = r'(<joint name="reu_joint_3" type="revolute">.*?)'  # the ReU sample's third body joint
SEA_MESH = r'(<collision>\s*<origin[^>]*/>\s*<geometry><mesh filename="[^"]*")'  # the SEA tail's collision mesh
TAIL_STL = r"meshes/tail\.stl"

#: (case, style, change, what the line must say)
CASES = [
    ("origin xyz", "reu", substitute(REU_J + r'<origin xyz="[^"]*"', r'\1<origin xyz="0.1 abc 0"'),
     r"reu_snake\.urdf: joint 'reu_joint_3' <origin> xyz must be 3 finite numbers .*'0\.1 abc 0'"),
    ("origin rpy short", "reu", substitute(REU_J + r'rpy="[^"]*"', r'\1rpy="0 0"'),
     r"joint 'reu_joint_3' <origin> rpy must be 3 finite numbers .*'0 0'"),
    ("origin nan", "reu", substitute(REU_J + r'<origin xyz="[^"]*"', r'\1<origin xyz="0 nan 0"'),
     r"joint 'reu_joint_3' <origin> xyz must be 3 finite numbers"),
    ("axis word", "reu", substitute(REU_J + r'<axis xyz="[^"]*"', r'\1<axis xyz="0 x 1"'),
     r"joint 'reu_joint_3' <axis> xyz must be 3 finite numbers .*'0 x 1'"),
    ("axis inf", "reu", substitute(REU_J + r'<axis xyz="[^"]*"', r'\1<axis xyz="0 inf 0"'),
     r"joint 'reu_joint_3' <axis> xyz must be 3 finite numbers"),
    ("axis zero", "reu", substitute(REU_J + r'<axis xyz="[^"]*"', r'\1<axis xyz="0 0 0"'),
     r"joint 'reu_joint_3' has a zero axis"),
    ("limit word", "reu", substitute(REU_J + r'lower="[^"]*"', r'\1lower="-abc"'),
     r"lower value \(-abc\) is not a valid float.*limit element for joint \[reu_joint_3\]"),
    ("limit swapped", "reu", substitute(REU_J + r'lower="[^"]*" upper="[^"]*"', r'\1lower="1" upper="-1"'),
     r"joint 'reu_joint_3' has lower limit > upper limit"),
    ("limit missing", "reu", substitute(REU_J + r"<limit[^>]*/>", r"\1"),
     r"Joint \[reu_joint_3\] is of type REVOLUTE but it does not specify limits"),
    ("mass word", "reu", substitute(r'<mass value="[^"]*"', '<mass value="heavy"'),
     r"mass \[heavy\] is not a float.*inertial element for Link \[reu_tail\]"),
    ("mass negative", "reu", substitute(r'<mass value="[^"]*"', '<mass value="-1"'),
     r"link 'reu_tail' <inertial>: mass must be a finite number of kg >= 0, got -1"),
    ("inertia word", "reu", substitute(r'ixx="[^"]*"', 'ixx="1e-5x"'),
     r"inertia element ixx is not a valid double.*Link \[reu_tail\]"),
    ("cylinder radius word", "reu", substitute(r'(<collision>.*?)radius="[^"]*"', r'\1radius="r"'),
     r"link 'reu_tail' <collision> 1 <cylinder> radius must be a finite number of metres, got 'r'"),
    ("cylinder radius zero", "reu", substitute(r'(<collision>.*?)radius="[^"]*"', r'\1radius="0"'),
     r"link 'reu_tail' <collision>: a cylinder's radius and length must be positive, got 0 and"),
    ("cylinder length missing", "reu", substitute(r'(<collision>.*?)length="[^"]*"', r"\1"),
     r"link 'reu_tail' <collision> 1 <cylinder> has no length attribute"),
    ("visual origin", "reu", substitute(r'(<visual>\s*<origin xyz=")[^"]*"', r'\1a b c"'),
     r"link 'reu_tail' <visual> 1 <origin> xyz must be 3 finite numbers .*'a b c'"),
    ("no geometry", "reu", substitute(r"(<collision>.*?)<geometry>.*?</geometry>", r"\1"),
     r"link 'reu_tail' <collision> 1 has no <geometry> shape"),
    ("empty geometry", "reu", substitute(r"(<collision>.*?)<geometry>.*?</geometry>", r"\1<geometry/>"),
     r"link 'reu_tail' <collision> 1 has no <geometry> shape"),
    ("unknown geometry", "reu", substitute(r"(<collision>.*?)<cylinder[^>]*/>", r'\1<cone radius="1"/>'),
     r"link 'reu_tail' <collision> 1 has an unknown shape <cone>"),
    ("duplicate joint", "reu", substitute(r'(<joint name=")reu_joint_3(")', r"\1reu_joint_2\2"),
     r"two <joint> elements are named 'reu_joint_2'"),
    ("duplicate link", "reu", substitute(r"</robot>", '<link name="head_tip"/></robot>'),
     r"two <link> elements are named 'head_tip'"),
    ("unnamed joint", "reu", substitute(r'<joint name="reu_joint_3"', "<joint"),
     r"a <joint> has no name \(after joint 'reu_module_body_2_to_out'\)"),
    ("joint type", "reu", substitute(r'(<joint name="reu_joint_3") type="revolute"', r'\1 type="hinge"'),
     r"joint 'reu_joint_3' has type 'hinge', not one of revolute, continuous"),
    ("unknown parent", "reu", substitute(REU_J + r'<parent link="[^"]*"', r'\1<parent link="nowhere"'),
     r"joint 'reu_joint_3' names parent link 'nowhere', which the URDF does not have"),
    ("unknown child", "reu", substitute(REU_J + r'<child link="[^"]*"', r'\1<child link="nowhere"'),
     r"joint 'reu_joint_3' names child link 'nowhere', which the URDF does not have"),
    ("two parents", "reu", substitute(r"</robot>", '<joint name="again" type="fixed"><parent link="reu_tail"/>'
                                                  '<child link="head_tip"/></joint></robot>'),
     r"link 'head_tip' is the child of two joints, 'head_tip_joint' and 'again'"),
    ("loop", "reu", substitute(r"</robot>", '<joint name="loop" type="fixed"><parent link="head_tip"/>'
                                            '<child link="reu_tail"/></joint></robot>'),
     r"the joints 'loop', .* form a loop"),
    ("two roots", "reu", substitute(r"</robot>", '<link name="orphan"/></robot>'),
     r"the links 'reu_tail', 'orphan' hang from no joint"),
    ("mesh missing", "sea", lambda folder, urdf: (folder / "meshes/tail.stl").unlink(),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + "': it does not exist"),
    ("mesh empty", "sea", write_file("meshes/tail.stl", b""),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + r"' is empty \(0 bytes\)"),
    ("not a mesh", "sea", write_file("meshes/tail.stl", "hello, not a mesh\n"),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + "' has no vertices"),
    ("flat mesh", "sea", write_file("meshes/tail.stl", FLAT_STL),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + "' is flat"),
    ("mesh scale zero", "sea", substitute(SEA_MESH, r'\1 scale="0.001 0 0.001"'),
     r"link 'tail' <collision> 1 <mesh filename='package://sea_snake/meshes/tail.stl'> scale must be 3 positive "
     r"numbers, got '0.001 0 0.001'"),
    ("mesh scale negative", "sea", substitute(SEA_MESH, r'\1 scale="-1 1 1"'),
     r"link 'tail' <collision> 1 <mesh filename='package://sea_snake/meshes/tail.stl'> scale must be 3 positive"),
    ("mesh scale short", "sea", substitute(SEA_MESH, r'\1 scale="0.001 0.001"'),
     r"link 'tail' <collision> 1 <mesh filename='.*tail.stl'> scale must be 3 finite numbers .*'0.001 0.001'"),
    ("mesh flat once scaled", "sea", substitute(SEA_MESH, r'\1 scale="1e-9 1e-9 1e-9"'),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + r"' scaled by 1e-09 1e-09 1e-09 is .* m thin"),
    ("mesh thin once scaled", "sea", substitute(SEA_MESH, r'\1 scale="1 1 1e-7"'),
     r"link 'tail' <collision>: mesh file '.*" + TAIL_STL + r"' scaled by 1 1 1e-07 is .* m thin"),
    ("mesh without filename", "sea", substitute(r"(<collision>\s*<origin[^>]*/>\s*<geometry><mesh) filename=\"[^\"]*\"",
                                                r"\1"),
     r"link 'tail' <collision> 1 <mesh> has no filename"),
    ("mesh in an unknown package", "sea", substitute(r'(<collision>\s*<origin[^>]*/>\s*<geometry><mesh filename=")'
                                                     r"package://sea_snake/", r"\1package://nopkg/"),
     r"link 'tail' <collision>: mesh 'package://nopkg/meshes/tail.stl': package 'nopkg' is not known"),
    ("OBJ with 2-D vertices", "mesh", write_file("meshes/link5.obj", "v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n"),
     r"link 'link5' <collision>: mesh file '.*link5\.obj' has vertices of shape \(3, 2\)"),
    ("robot without name", "reu", substitute(r'<robot name="[^"]*"', "<robot"),
     r"the <robot> element has no name attribute"),
]


@pytest.mark.parametrize("case, style, change, match", CASES, ids=[c[0] for c in CASES])
def test_a_bad_description_is_one_line_naming_the_element(samples, tmp_path, capsys, case, style, change, match):
    toml, urdf = copy(samples[style], tmp_path / "robot")
    change(tmp_path / "robot", urdf)
    with pytest.raises(InputError, match=match) as err:
        SnakeRobot.from_file(toml)
    assert "\n" not in str(err.value)
    status, line = info(toml, capsys)
    assert status == EXIT_BAD_INPUT, line
    assert line.startswith("snakehead info: error: ") and re.search(match, line), line


# --- the description: default (x) axes, STL collisions in millimetres scaled by 0.001 ----------------------
def millimetre_collisions(folder: Path, urdf: Path, scale: str = "0.001 0.001 0.001") -> None:
    """The SEA sample with every <axis> removed (its axes are x, the default) and its cylinders replaced by one STL
    module half in millimetres, scaled."""
    half = trimesh.creation.cylinder(radius=26.0, height=31.95, sections=24)
    half.apply_translation((0, 0, 31.95 / 2))
    half.export(folder / "meshes" / "half_mm.stl")
    text = re.sub(r'<axis xyz="1 0 0"\s*/>', "", urdf.read_text(encoding="utf-8"))
    text, n = re.subn(r"<collision>\s*<origin[^>]*/>\s*<geometry><cylinder[^>]*/></geometry>",
                      '<collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><mesh '
                      f'filename="package://sea_snake/meshes/half_mm.stl" scale="{scale}"/></geometry>', text)
    assert n == 32 and "<axis" not in text
    urdf.write_text(text, encoding="utf-8")


def test_default_axes_and_millimetre_meshes_load(samples, tmp_path, capsys):
    toml, urdf = copy(samples["sea"], tmp_path / "robot")
    millimetre_collisions(tmp_path / "robot", urdf)
    robot = SnakeRobot.from_file(toml)
    assert robot.n_joints == 16
    assert sum(s.kind == "convex" for s in robot.geometry.shapes) == 33
    assert robot.body_axis_height == pytest.approx(0.026, abs=1e-3)  # the 26 mm radius, read in metres
    status, line = info(toml, capsys)
    assert status == 0, line


@pytest.mark.parametrize("scale", ["0.001 0 0.001", "0.001 0.001 -0.001", "-1 1 1", "0 0 0"])
def test_default_axes_and_bad_millimetre_scales_name_the_mesh(samples, tmp_path, capsys, scale):
    """The same description with one module's scale wrong: the line names the link, the mesh file and the scale."""
    toml, urdf = copy(samples["sea"], tmp_path / "robot")
    millimetre_collisions(tmp_path / "robot", urdf)
    substitute(r'(<link name="module3__output">.*?<collision>.*?) scale="[^"]*"', rf'\1 scale="{scale}"')(
        tmp_path / "robot", urdf)
    status, line = info(toml, capsys)
    assert status == EXIT_BAD_INPUT, line
    assert re.search(r"sea_snake\.urdf: link 'module3__output' <collision> 1 <mesh "
                     r"filename='package://sea_snake/meshes/half_mm\.stl'> scale must be 3 positive numbers, got "
                     + re.escape(repr(scale)), line), line


def test_millimetres_scaled_twice_are_flagged(samples, tmp_path, capsys):
    """Scaled by 1e-6 (millimetres read as micrometres) the modules are 26 um thick: a valid description whose
    robot cannot be (exit 1, never 3): the check names the links whose masses sit in no volume."""
    toml, urdf = copy(samples["sea"], tmp_path / "robot")
    millimetre_collisions(tmp_path / "robot", urdf, scale="1e-6 1e-6 1e-6")
    capsys.readouterr()
    status = cli.main(["info", "--robot", str(toml)])
    out = capsys.readouterr().out
    assert status == 1
    assert re.search(r"MASS: 32 links \('module1__body'.*denser than any metal", out), out


def test_the_checks_read_numbers_as_urdfdom_does():
    """What urdfdom reads is accepted (signs, exponents, leading dots, several spaces); what it refuses is refused
    with a named line (nan, inf, words, hex)."""
    template = ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
                '<child link="b"/><origin xyz="{}"/><axis xyz="0 0 1"/>'
                '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    for good in ("0 0 0", "+1 -2.5 3e-2", ".5 5. 1E+3", "  1   2  3 "):
        check_description(template.format(good), "t.urdf")
    for bad in ("nan 0 0", "0 inf 0", "0x1 0 0", "1 2", "1 2 3 4", "1,2,3"):
        with pytest.raises(InputError, match=r"t\.urdf: joint 'j' <origin> xyz must be 3 finite numbers"):
            check_description(template.format(bad), "t.urdf")


def test_a_mesh_as_written_and_scaled(tmp_path):
    """convex_hull_vertices: a good mesh scaled; each bad one names the place and the file."""
    box = tmp_path / "box.stl"
    trimesh.creation.box((10.0, 20.0, 30.0)).export(box)
    v = convex_hull_vertices(box, np.array([0.001, 0.001, 0.001]), "here")
    np.testing.assert_allclose(v.max(axis=0) - v.min(axis=0), [0.01, 0.02, 0.03])
    with pytest.raises(InputError, match=r"here: mesh file '.*box\.stl' scaled by 1 1 0 is 0 m thin"):
        convex_hull_vertices(box, np.array([1.0, 1.0, 0.0]), "here")


# --- properties: valid variations never exit 3; invalid mutations exit 2 naming the element -------------------------
def fuzz(examples: int) -> settings:
    return settings(max_examples=examples, derandomize=True, deadline=None, database=None, print_blob=False,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def _scale_attribute(element: ET.Element, key: str, factor: float) -> None:
    values = [float(v) * factor for v in element.get(key, "").split()]
    element.set(key, " ".join(repr(v) for v in values))


@st.composite
def valid_variation(draw) -> tuple[str, Callable[[ET.Element], None]]:
    """A style and a change to its URDF that keeps it a valid description."""
    style = draw(st.sampled_from(["reu", "sea", "mesh", "cad"]))
    mass_factor = draw(st.floats(0.5, 2.0))
    size_factor = draw(st.floats(0.95, 1.2))
    limit_factor = draw(st.floats(0.8, 1.0))
    servo_factor = draw(st.floats(1.0, 4.0))
    visuals = draw(st.lists(st.integers(0, 10 ** 6), max_size=4))
    extra = draw(st.lists(st.tuples(st.integers(0, 10 ** 6), st.booleans()), max_size=3))
    shuffle = draw(st.randoms(use_true_random=False))

    def change(robot: ET.Element) -> None:
        links = robot.findall("link")
        for mass in robot.iter("mass"):
            _scale_attribute(mass, "value", mass_factor)
        for inertia in robot.iter("inertia"):
            for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                _scale_attribute(inertia, key, mass_factor)
        for cylinder in robot.iter("cylinder"):
            _scale_attribute(cylinder, "radius", size_factor)
        for limit in robot.iter("limit"):
            for key in ("lower", "upper"):
                if limit.get(key) is not None:
                    _scale_attribute(limit, key, limit_factor)
            for key in ("effort", "velocity"):
                if limit.get(key) is not None:
                    _scale_attribute(limit, key, servo_factor)
        for k in visuals:  # visual meshes whose files are not there (only collisions are read)
            link = links[k % len(links)]
            visual = ET.SubElement(link, "visual")
            ET.SubElement(ET.SubElement(visual, "geometry"), "mesh",
                          {"filename": f"package://absent_pkg/meshes/visual_{k}.dae", "scale": "0.001 0.001 0.001"})
        for n, (k, sized) in enumerate(extra):  # links that are not the body's: fixed, with or without a small box
            parent = links[k % len(links)].get("name", "")
            name = f"extra_{n}"
            link = ET.SubElement(robot, "link", {"name": name})
            if sized:
                collision = ET.SubElement(link, "collision")
                ET.SubElement(ET.SubElement(collision, "geometry"), "box", {"size": "0.005 0.005 0.005"})
            joint = ET.SubElement(robot, "joint", {"name": f"{name}_joint", "type": "fixed"})
            ET.SubElement(joint, "parent", {"link": parent})
            ET.SubElement(joint, "child", {"link": name})
        children = list(robot)  # reorder: links and joints in any order, each link's elements in any order
        shuffle.shuffle(children)
        for child in children:
            robot.remove(child)
        robot.extend(children)
        for link in robot.findall("link"):
            parts = list(link)
            shuffle.shuffle(parts)
            for part in parts:
                link.remove(part)
            link.extend(parts)

    return style, change


def apply(robot_file: Path, folder: Path, change: Callable[[ET.Element], None]) -> Path:
    toml, urdf = copy(robot_file, folder)
    robot = ET.fromstring(urdf.read_text(encoding="utf-8"))
    change(robot)
    urdf.write_text(ET.tostring(robot, encoding="unicode"), encoding="utf-8")
    return toml


@fuzz(24)
@given(variation=valid_variation())
def test_valid_variations_never_exit_3(samples, capsys, variation):
    style, change = variation
    with tempfile.TemporaryDirectory() as folder:
        toml = apply(samples[style], Path(folder), change)
        status, line = info(toml, capsys)
    assert status in (0, 1, EXIT_BAD_INPUT), line
    assert status != EXIT_INTERNAL


def _bad_origin(element: ET.Element) -> None:
    origin = element.find("origin")
    if origin is None:
        origin = ET.SubElement(element, "origin")
    origin.set("xyz", "0 zero 0")


def _bad_axis(joint: ET.Element) -> None:
    axis = joint.find("axis")
    if axis is None:
        axis = ET.SubElement(joint, "axis")
    axis.set("xyz", "0 0")


def _bad_type(joint: ET.Element) -> None:
    joint.set("type", "hinge")


def _unknown_parent(joint: ET.Element) -> None:
    parent = joint.find("parent")
    assert parent is not None
    parent.set("link", "no_such_link")


#: invalid changes of one joint, and what the line says about it (besides its name)
JOINT_MUTATIONS = [(_bad_origin, r"<origin> xyz must be 3 finite numbers"), (_bad_axis, r"<axis> xyz must be 3"),
                   (_bad_type, r"has type 'hinge'"), (_unknown_parent, r"names parent link 'no_such_link'")]


def _bad_box(link: ET.Element) -> None:
    collision = ET.SubElement(link, "collision")
    ET.SubElement(ET.SubElement(collision, "geometry"), "box", {"size": "0.01 0.01"})


def _unknown_shape(link: ET.Element) -> None:
    visual = ET.SubElement(link, "visual")
    ET.SubElement(ET.SubElement(visual, "geometry"), "capsule", {"radius": "0.01", "length": "0.02"})


def _zero_scale(link: ET.Element) -> None:
    collision = ET.SubElement(link, "collision")
    ET.SubElement(ET.SubElement(collision, "geometry"), "mesh", {"filename": "meshes/m.stl", "scale": "1 0 1"})


def _no_geometry(link: ET.Element) -> None:
    ET.SubElement(link, "collision")


#: invalid changes of one link, and what the line says about it (besides its name)
LINK_MUTATIONS = [(_bad_box, r"<collision> \d+ <box> size must be 3 finite numbers"),
                  (_unknown_shape, r"<visual> \d+ has an unknown shape <capsule>"),
                  (_zero_scale, r"<collision> \d+ <mesh filename='meshes/m.stl'> scale must be 3 positive numbers"),
                  (_no_geometry, r"<collision> \d+ has no <geometry> shape")]


@fuzz(24)
@given(style=st.sampled_from(["reu", "sea", "mesh", "cad"]), on_joint=st.booleans(), which=st.integers(0, 10 ** 6),
       mutation=st.integers(0, 3))
def test_invalid_mutations_exit_2_naming_the_element(samples, capsys, style, on_joint, which, mutation):
    kind = "joint" if on_joint else "link"
    mutate, says = (JOINT_MUTATIONS if on_joint else LINK_MUTATIONS)[mutation]
    named: list[str] = []

    def change(robot: ET.Element) -> None:
        elements = robot.findall(kind)
        element = elements[which % len(elements)]
        named.append(element.get("name", ""))
        mutate(element)

    with tempfile.TemporaryDirectory() as folder:
        toml = apply(samples[style], Path(folder), change)
        status, line = info(toml, capsys)
    assert status == EXIT_BAD_INPUT, line
    assert re.search(rf"{kind} {re.escape(repr(named[0]))} {says}", line), line
