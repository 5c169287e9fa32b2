"""Robots as a parameter: the robot model derived from any URDF and three frame names, robot files, scene files,
and their bad inputs (clear errors, never a crash)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead import BasePlacement, SnakeRobot, default_robot_file
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.model.robot_file import read_robot_file, write_robot_file
from snakehead.scenes import Scene, Target, load_scene, paper_scene


def write(tmp: Path, name: str, text: str) -> Path:
    p = tmp / name
    p.write_text(text)
    return p


@pytest.fixture(scope="module")
def pitch_first(tmp_path_factory) -> Path:
    """A 13-joint snake starting with a pitch joint, 10 cm modules, 6 cm section, frames named by links."""
    tmp = tmp_path_factory.mktemp("pitch_first")
    spec = SnakeSpec(n_joints=13, module_length=0.1, section=0.06, mass_per_module=0.3, first_axis="pitch",
                     link_prefix="seg", joint_prefix="j", tip_name="nose", name="pitchy")
    return write(tmp, "pitchy.urdf", snake_urdf(spec))


# --- the model derived from the URDF ------------------------------------------------------------------------
def test_default_robot_parts_and_shape():
    robot = SnakeRobot.default()
    assert (robot.parts.base, robot.parts.neck, robot.parts.head) == (slice(0, 7), slice(7, 9), slice(9, 16))
    assert robot.parts.root == "link_0" and robot.source.endswith("snake16.toml")
    assert robot.body_axis_height == pytest.approx(0.043 / 2, abs=1e-15)
    assert robot.base_length == pytest.approx(0.0405 + 7 * 0.0865, abs=1e-12)  # P0: the end of link_7
    assert robot.neck_length == pytest.approx(2 * 0.0865, abs=1e-12)
    assert robot.head_length == pytest.approx(6 * 0.0865 + 0.046, abs=1e-12)
    assert robot.head_link_length == pytest.approx(0.046, abs=1e-12)
    assert [robot.link_names[i] for i in robot.base_links] == [f"link_{i}" for i in range(8)]
    assert [robot.link_names[i] for i in robot.neck_links] == ["link_8", "link_9"]
    assert [robot.link_names[i] for i in robot.head_links] == [f"link_{i}" for i in range(10, 17)]
    assert robot.map_path.name == "snake16_head7.npz"


def test_generated_robot_with_link_frames(pitch_first):
    robot = SnakeRobot.from_urdf(pitch_first, base_end="seg6", neck_end="seg7", head_tip="nose")
    assert robot.parts.root == "seg0"  # the URDF's root link by default
    # base = joints root -> seg6 (j1..j6), neck = j7, head = j8..j13 (6 DOF)
    assert robot.parts.base == slice(0, 6) and robot.parts.neck == slice(6, 7) and robot.parts.head == slice(7, 13)
    assert robot.head_chain.n_joints == 6 and robot.neck_chain.n_joints == 1
    assert robot.joint_kinds[:3] == ("pitch", "yaw", "pitch") and robot.joint_kinds[6] == "pitch"
    # every frame computed from the URDF alone: body axis = half the 6 cm section; lengths from FK at q = 0
    assert robot.body_axis_height == pytest.approx(0.03, abs=1e-12)
    assert robot.body_length == pytest.approx(0.05 + 12 * 0.1 + 0.05, abs=1e-12)
    assert robot.base_length == pytest.approx(0.05 + 5 * 0.1, abs=1e-12)  # seg6's frame is at joint 6
    np.testing.assert_allclose(robot.joint_arc_lengths, 0.05 + 0.1 * np.arange(13), atol=1e-12)
    assert robot.total_mass == pytest.approx(0.3 * 13, abs=1e-9)
    # the base lies on the ground: its lowest box corners at z = 0 wherever it is placed
    base = BasePlacement(0.3, -0.2, 1.0)
    F = robot.frames(np.zeros(robot.n_joints), base)
    low = robot.lowest_z(F[None], robot.base_links)[0]
    np.testing.assert_allclose(low, 0.0, atol=1e-12)
    # seg6 (the frame at P0) begins the neck: its body lies after P0
    assert robot.link_names[robot.neck_links[0]] == "seg6"


def test_marker_and_link_frames():
    """A part boundary named by a marker at link k's distal end or by link k's own frame (at its proximal joint):
    the same joints, and P0 one link apart along the body."""
    spec = SnakeSpec(n_joints=10, markers={"p0": 5, "b0": 7})
    xml = snake_urdf(spec)
    a = SnakeRobot.from_urdf(xml, base_end="p0", neck_end="b0", head_tip="head_tip")
    b = SnakeRobot.from_urdf(xml, base_end="link_5", neck_end="link_7", head_tip="head_tip")
    assert (a.parts.base, a.parts.neck, a.parts.head) == (b.parts.base, b.parts.neck, b.parts.head)
    assert a.parts.base == slice(0, 5) and a.parts.neck == slice(5, 7)
    q = np.random.default_rng(0).uniform(-1, 1, a.n_joints)
    Fa, Fb = a.frame(q, "p0"), b.frame(q, "link_5")
    np.testing.assert_allclose(Fa, Fb @ np.array([[1, 0, 0, spec.module_length], [0, 1, 0, 0], [0, 0, 1, 0],
                                                  [0, 0, 0, 1]]), atol=1e-12)
    assert a.base_length == pytest.approx(b.base_length + spec.module_length, abs=1e-12)


def test_generator_writes_the_default_robot():
    """urdf/generate_snake16.py writes the committed snake16.urdf with snake_urdf."""
    import importlib.util

    urdf_dir = Path(__file__).resolve().parents[2] / "urdf"  # the source tree's (the script is not installed)
    path = urdf_dir / "generate_snake16.py"
    spec = importlib.util.spec_from_file_location("generate_snake16", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.build() == (urdf_dir / "snake16.urdf").read_text()
    assert (urdf_dir / "snake16.urdf").read_text() == default_robot_file().with_name("snake16.urdf").read_text()


# --- robot files --------------------------------------------------------------------------------------------
def test_robot_file_round_trip(tmp_path, pitch_first):
    path = write_robot_file(tmp_path / "r.toml", urdf=pitch_first, base_end="seg6", neck_end="seg7", head_tip="nose")
    spec = read_robot_file(path)
    assert Path(spec.urdf).resolve() == pitch_first.resolve() and spec.root is None and spec.map is None
    robot = SnakeRobot.from_file(path)
    assert robot.n_joints == 13 and robot.source == str(path)


URDF = snake_urdf(SnakeSpec(n_joints=8, markers={"p0": 3, "b0": 4}))


@pytest.mark.parametrize("body, message", [
    ('urdf = "r.urdf"\nbase_end = "p0"\nneck_end = "b0"\nhead_tip = "head_tip"\ncolour = "red"\n', "unknown key 'colour'"),
    ('urdf = "r.urdf"\nbase_end = "p0"\nhead_tip = "head_tip"\n', "missing 'neck_end'"),
    ('urdf = "r.urdf"\nbase_end = "p0"\nneck_end = "nope"\nhead_tip = "head_tip"\n', "'nope' is not a frame"),
    ('urdf = "r.urdf"\nbase_end = "b0"\nneck_end = "p0"\nhead_tip = "head_tip"\n', "out of order"),
    ('urdf = "r.urdf"\nbase_end = "link_0"\nneck_end = "b0"\nhead_tip = "head_tip"\n', "out of order"),
    ('urdf = "r.urdf"\nroot = "link_1"\nbase_end = "link_1"\nneck_end = "b0"\nhead_tip = "head_tip"\n',
     "out of order"),
    ('urdf = "r.urdf"\nroot = "link_1"\nbase_end = "link_2"\nneck_end = "b0"\nhead_tip = "head_tip"\n',
     None),  # a valid robot whose root is not the URDF's root link
    ('urdf = "r.urdf"\nbase_end = "link_4"\nneck_end = "b0"\nhead_tip = "head_tip"\n', "neck part .* has no joint"),
    ('urdf = "r.urdf"\nroot = "link_3"\nbase_end = "p0"\nneck_end = "b0"\nhead_tip = "head_tip"\n',
     "base part .* has no joint"),
    ('urdf = "missing.urdf"\nbase_end = "p0"\nneck_end = "b0"\nhead_tip = "head_tip"\n', "does not exist"),
    ('urdf = 3\nbase_end = "p0"\nneck_end = "b0"\nhead_tip = "head_tip"\n', "'urdf' must be a non-empty string"),
    ('urdf = "r.urdf"\nbase_end = "p0"\nneck_end = "b0"\nhead_tip = "head_tip"\nmap = "none.npz"\n',
     "its map .* does not exist"),
    ('urdf = "r.urdf"\nbase_end = "p0" neck_end = "b0"\n', "not valid TOML"),
])
def test_bad_robot_files(tmp_path, body, message):
    write(tmp_path, "r.urdf", URDF)
    path = write(tmp_path, "r.toml", body)
    if message is None:
        robot = SnakeRobot.from_file(path)
        assert robot.n_joints == 7 and robot.parts.base == slice(0, 1) and robot.joint_names[0] == "joint_2"
        return
    with pytest.raises(ValueError, match=message):
        SnakeRobot.from_file(path)


def test_bad_robots(tmp_path):
    with pytest.raises(TypeError, match="urdf"):
        SnakeRobot.from_urdf(3, base_end="p0", neck_end="b0", head_tip="head_tip")
    with pytest.raises(TypeError, match="neck_end"):
        SnakeRobot.from_urdf(URDF, base_end="p0", neck_end=None, head_tip="head_tip")
    with pytest.raises(ValueError, match="does not exist"):
        SnakeRobot.from_file(tmp_path / "none.toml")
    # not a snake: a joint about x, a body that is not straight, no boxes, no mass
    about_x = URDF.replace('<axis xyz="0 1 0"/>', '<axis xyz="1 0 0"/>', 1)
    with pytest.raises(ValueError, match="turns about"):
        SnakeRobot.from_urdf(about_x, base_end="p0", neck_end="b0", head_tip="head_tip")
    # a joint 8 cm to the side: beyond the body's half-section (21.5 mm), so not a CAD offset but a bent body
    bent = URDF.replace('<origin xyz="0.0865 0 0" rpy="0 0 0"/>\n    <axis', '<origin xyz="0.0865 0.08 0" rpy="0 0 0"/>\n    <axis', 1)
    with pytest.raises(ValueError, match=r"does not lie straight at its zero: frame '\w+' is \d+\.\d+ mm off the body's line .*\[home\]"):
        SnakeRobot.from_urdf(bent, base_end="p0", neck_end="b0", head_tip="head_tip")
    no_boxes = URDF.replace("<collision>", "<!--").replace("</collision>", "-->")
    with pytest.raises(ValueError, match="collision> shape"):
        SnakeRobot.from_urdf(no_boxes, base_end="p0", neck_end="b0", head_tip="head_tip")
    with pytest.raises(ValueError, match="base_end"):
        SnakeRobot.from_urdf(URDF, base_end="nothing", neck_end="b0", head_tip="head_tip")


def test_spec_rejects_bad_numbers():
    for kwargs, message in [({"n_joints": 0}, "n_joints"), ({"module_length": -1.0}, "module_length"),
                            ({"first_axis": "roll"}, "first_axis"), ({"markers": {"p": 40}}, "marker"),
                            ({"section": float("nan")}, "section"), ({"markers": {"link_3": 1}}, "marker name")]:
        with pytest.raises(ValueError, match=message):
            SnakeSpec(**kwargs)


# --- scenes -------------------------------------------------------------------------------------------------
def test_paper_scenes():
    spheres, hole = paper_scene("spheres"), paper_scene("hole")
    assert [t.name for t in spheres.reported] == ["sphere 1", "sphere 2"]
    np.testing.assert_allclose(spheres.targets[0].position, [-4.05e-2, 0.5443, 0.3])  # Section 4.1
    np.testing.assert_allclose(spheres.targets[2].position, [0.1505, 0.5076, 0.3954])
    assert spheres.targets[0].sphere_diameter == 0.04 and spheres.targets[1].via
    wall = hole.obstacles[0]
    np.testing.assert_allclose(wall.centre, [0.2, 0.5, 0.4])  # Section 4.2
    np.testing.assert_allclose(wall.size, [0.7, 0.58, 0.01])
    assert wall.hole_diameter == 0.07 and [t.approach for t in hole.targets] == ["free", "line", "line"]
    with pytest.raises(ValueError, match="paper's scenes"):
        paper_scene("moon")


def test_scene_file_round_trip(tmp_path):
    path = write(tmp_path, "s.toml", """
name = "reach"
base = { x = 0.1, yaw = 0.2 }
[[targets]]
name = "a"
position = [0.1, 0.5, 0.3]
direction = [0, 2, 0]
hold_s = 1.5
[[obstacles]]
kind = "box"
centre = [0.5, 0.2, 0.1]
size = [0.2, 0.2, 0.2]
yaw = 0.5
""")
    scene = load_scene(path)
    assert scene.name == "reach" and scene.base == BasePlacement(0.1, 0.0, 0.2)
    np.testing.assert_allclose(scene.targets[0].direction, [0, 1, 0])
    box = scene.obstacles[0]
    np.testing.assert_allclose(box.rotation[:2, 0], [math.cos(0.5), math.sin(0.5)])


@pytest.mark.parametrize("body, message", [
    ('[[targets]]\nname = "a"\nposition = [0, "x", 0.3]\ndirection = [0, 1, 0]\n', "position must be a list of 3 numbers"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5]\ndirection = [0, 1, 0]\n', "position must be a list of 3"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 0, 0]\n', "zero length"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\nspeed = 2\n', "unknown key 'speed'"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\n', "missing 'direction'"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\nhold_s = -1\n', "hold_s"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\napproach = "line"\n', "first target"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n'
     '[[obstacles]]\nkind = "sphere"\n', "kind must be one of"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n'
     '[[obstacles]]\nkind = "box"\ncentre = [0, 0, 0]\nsize = [0.1, -0.1, 0.1]\n', "size must be positive"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n'
     '[[obstacles]]\nkind = "wall_with_hole"\nhole_centre = [0, 0.5, 0.4]\nnormal = [0, 0, 1]\n'
     'size = [0.7, 0.58, 0.01]\nhole_diameter = 0.07\n', "horizontal"),
    ('targets = []\n', "non-empty"),
    ('name = 3\n[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n', "name must be a string"),
    ('robot = "nobody.toml"\n[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n',
     "robot file .* does not exist"),
    ('[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n'
     '[[targets]]\nname = "a"\nposition = [0, 0.5, 0.4]\ndirection = [0, 1, 0]\n', "names must differ"),
    ('base = { x = 0, roll = 1 }\n[[targets]]\nname = "a"\nposition = [0, 0.5, 0.3]\ndirection = [0, 1, 0]\n',
     "unknown key 'roll'"),
])
def test_bad_scene_files(tmp_path, body, message):
    path = write(tmp_path, "bad.toml", body)
    with pytest.raises(ValueError, match=message):
        load_scene(path)


def test_scene_objects_reject_bad_input():
    with pytest.raises(ValueError, match="no targets"):
        Scene(name="x", targets=())
    with pytest.raises(TypeError, match="Target"):
        Scene(name="x", targets=("a",))
    with pytest.raises(ValueError, match="NaN"):
        Target("a", [np.nan, 0, 0], [1, 0, 0])
    with pytest.raises(ValueError, match="approach"):
        Target("a", [0, 0, 0.3], [1, 0, 0], approach="spiral")
    with pytest.raises(ValueError, match="pair"):
        Scene.from_targets([(1, 2, 3)])
    with pytest.raises(TypeError, match="obstacles"):
        snakehead.plan([([0.1, 0.5, 0.3], [0, 1, 0])], obstacles=["wall"])
