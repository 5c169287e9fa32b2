"""Snakes written the way published ones are load as they are: every collision shape, any module axis behind a
rotated root, several links per module, xacro, package:// meshes, continuous joints with limits from the robot
file; bad descriptions are InputErrors naming the file and the element."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import snakehead
from snakehead import InputError, SnakeRobot
from snakehead.model.robot import ALIGNED_SUFFIX
from snakehead.samples import published


@pytest.fixture(scope="module")
def robots(tmp_path_factory: pytest.TempPathFactory) -> dict[str, SnakeRobot]:
    folder = tmp_path_factory.mktemp("styles")
    return {style: SnakeRobot.from_file(published.write_robot(style, folder / style)) for style in published.STYLES}


@pytest.mark.parametrize("style", published.STYLES)
def test_every_style_loads_with_its_parts(robots: dict[str, SnakeRobot], style: str) -> None:
    robot = robots[style]
    spec = published.style_spec(style)
    p = robot.parts
    assert robot.n_joints == spec.n_joints
    assert (p.neck.stop - p.neck.start, p.head.stop - p.head.start) == (spec.neck_joints, spec.head_joints)
    # the body frame: straight along its x at q = 0, z up, every joint yaw or pitch, alternating
    F = robot.frames(np.zeros(robot.n_joints))
    origins = F[:, :3, 3]
    np.testing.assert_allclose(origins[:, 1], 0.0, atol=1e-6)
    np.testing.assert_allclose(origins[:, 2], robot.body_axis_height, atol=1e-6)
    assert np.all(np.diff(origins[:, 0]) >= -1e-9)
    kinds = robot.joint_kinds
    assert all(a != b for a, b in zip(kinds, kinds[1:])), kinds
    # the head looks along the body at q = 0, whatever axis its frame points with
    np.testing.assert_allclose(robot.head_pose(np.zeros(robot.n_joints))[:3, 0], [1, 0, 0], atol=1e-6)
    # the base rests on its real shapes: its lowest point at z = 0
    low = robot.lowest_z(F[None], robot.base_links)[0]
    assert low.min() == pytest.approx(0.0, abs=1e-9)


def test_shapes_are_what_the_descriptions_say(robots: dict[str, SnakeRobot]) -> None:
    kinds = {style: {s.kind for s in robots[style].geometry.shapes} for style in robots}
    assert kinds["sea"] == {"cylinder", "convex"}  # cylinders and the STL tail
    assert kinds["reu"] == {"cylinder"}
    assert kinds["rsnake"] == {"cylinder"}  # visual meshes that do not exist are ignored
    assert kinds["mesh"] == {"convex"}
    assert kinds["one_joint_neck"] == {"box"}
    assert kinds["head6"] == {"box", "sphere"}
    # the rsnake's cylinders of 5 cm radius: the body axis 5 cm up
    assert robots["rsnake"].body_axis_height == pytest.approx(0.05, abs=1e-9)
    assert robots["sea"].body_axis_height == pytest.approx(0.026, abs=1e-9)


def test_modules_along_z_behind_a_rotated_root_get_aligned_frames(robots: dict[str, SnakeRobot]) -> None:
    sea = robots["sea"]
    assert sea.parts.head_tip.endswith(ALIGNED_SUFFIX)  # its head frame looks along z
    assert not np.allclose(sea.body_in_root, np.eye(4))
    # the aligned frames sit where the user's frames are
    F = sea.frames(sea.random_configuration(np.random.default_rng(1)))
    for key in ("base_end", "neck_end", "head_tip"):
        user = sea.user_frames[key]
        aligned = getattr(sea.parts, key)
        np.testing.assert_allclose(F[sea.link_index(aligned), :3, 3], F[sea.link_index(user), :3, 3], atol=1e-12)
    # the head's direction is the user's frame's z-axis
    k_user = sea.link_index(sea.user_frames["head_tip"])
    np.testing.assert_allclose(F[sea.link_index(sea.parts.head_tip), :3, 0], F[k_user, :3, 2], atol=1e-12)
    # and the default robot gets none
    default = SnakeRobot.default()
    assert not any(name.endswith(ALIGNED_SUFFIX) for name in default.link_names)


def test_continuous_joints_take_the_robot_files_limits(robots: dict[str, SnakeRobot]) -> None:
    mesh = robots["mesh"]
    np.testing.assert_allclose(mesh.upper, np.pi / 2)
    np.testing.assert_allclose(mesh.lower, -np.pi / 2)
    assert mesh.head_chain.upper.max() == pytest.approx(np.pi / 2)  # the IK's chains have them too


def test_xacro_with_arguments_equals_the_plain_urdf(tmp_path: Path) -> None:
    xacro_robot = SnakeRobot.from_file(published.write_robot("xacro", tmp_path / "x", n_joints=16))
    plain = SnakeRobot.from_file(published.write_robot("reu", tmp_path / "r"))
    assert xacro_robot.n_joints == plain.n_joints == 16
    q = plain.random_configuration(np.random.default_rng(2))
    np.testing.assert_allclose(xacro_robot.head_pose(q), plain.head_pose(q), atol=1e-9)


def _edit(robot_file: Path, old: str, new: str) -> None:
    text = robot_file.read_text()
    assert old in text, (old, text)
    robot_file.write_text(text.replace(old, new))


def test_a_missing_collision_mesh_names_the_link_and_the_path(tmp_path: Path) -> None:
    path = published.write_robot("mesh", tmp_path / "m")
    victim = sorted((tmp_path / "m").rglob("*.STL"))[0]
    victim.unlink()
    with pytest.raises(InputError, match=r"link '.*' <collision>: mesh file '.*" + victim.name):
        SnakeRobot.from_file(path).geometry


def test_an_unknown_package_says_how_to_give_it(tmp_path: Path) -> None:
    path = published.write_robot("sea", tmp_path / "s")
    _edit(path, '"sea_snake" =', '"other_package" =')
    with pytest.raises(InputError, match=r"package 'sea_snake' is not known; add sea_snake = .* \[packages\]"):
        SnakeRobot.from_file(path).geometry


def test_an_empty_or_unreadable_mesh_is_an_input_error(tmp_path: Path) -> None:
    path = published.write_robot("mesh", tmp_path / "m")
    victim = sorted((tmp_path / "m").rglob("*.STL"))[0]
    victim.write_bytes(b"")
    with pytest.raises(InputError, match=victim.name):
        SnakeRobot.from_file(path).geometry
    victim.write_text("solid nothing\nendsolid nothing\n")
    with pytest.raises(InputError, match=victim.name):
        SnakeRobot.from_file(path).geometry


def test_a_continuous_joint_without_limits_names_the_joint(tmp_path: Path) -> None:
    path = published.write_robot("mesh", tmp_path / "m")
    text = path.read_text()
    start = text.index("[limits]")
    first = text[start:].splitlines()[1]
    path.write_text(text.replace(first + "\n", ""))
    joint = first.split("=")[0].strip().strip('"')
    with pytest.raises(InputError, match=rf"continuous joint '{joint}' needs limits"):
        SnakeRobot.from_file(path)


def test_a_xacro_error_names_the_file(tmp_path: Path) -> None:
    path = published.write_robot("xacro", tmp_path / "x")
    xacro_file = next((tmp_path / "x").glob("*.xacro"))
    xacro_file.write_text(xacro_file.read_text().replace("${pi/2}", "${undefined_name/2}", 1))
    with pytest.raises(InputError, match=r"xacro file '.*\.xacro'.*undefined_name"):
        SnakeRobot.from_file(path)


def test_unknown_robot_file_keys_and_bad_tables_are_input_errors(tmp_path: Path) -> None:
    path = published.write_robot("reu", tmp_path / "r")
    text = path.read_text()
    path.write_text(text + '\nhead_axis = "w"\n')
    with pytest.raises(InputError, match=r"robot file '.*reu_snake\.toml': 'head_axis' must be one of x, y, z, -x, -y, -z .*got 'w'"):
        SnakeRobot.from_file(path)
    path.write_text(text + "\n[limits]\nnot_a_joint = [-1.0, 1.0]\n")
    with pytest.raises(InputError, match="not_a_joint"):
        SnakeRobot.from_file(path)
    path.write_text(text + "\n[limits]\nx = [1.0, -1.0]\n")
    with pytest.raises(InputError, match=r"limits.x must be \[lower, upper\]"):
        SnakeRobot.from_file(path)


def test_input_error_is_a_value_error() -> None:
    assert issubclass(snakehead.InputError, ValueError)


@pytest.mark.parametrize("damage", ["missing mesh", "unknown package", "empty mesh", "xacro error",
                                    "continuous without limits"])
def test_bad_descriptions_on_the_command_line_exit_2_with_one_line(tmp_path: Path, damage: str) -> None:
    """Each bad description: ``snakehead info`` exits 2 with one line that names the file and the element."""
    import subprocess
    import sys

    style = {"missing mesh": "mesh", "unknown package": "sea", "empty mesh": "mesh", "xacro error": "xacro",
             "continuous without limits": "mesh"}[damage]
    path = published.write_robot(style, tmp_path / style)
    folder = tmp_path / style
    if damage == "missing mesh":
        victim = sorted(folder.rglob("*.STL"))[0]
        victim.unlink()
        expected = [victim.name, "<collision>"]
    elif damage == "unknown package":
        _edit(path, '"sea_snake" =', '"other_package" =')
        expected = ["sea_snake", "[packages]"]
    elif damage == "empty mesh":
        victim = sorted(folder.rglob("*.STL"))[0]
        victim.write_bytes(b"")
        expected = [victim.name, "<collision>"]
    elif damage == "xacro error":
        xacro_file = next(folder.glob("*.xacro"))
        xacro_file.write_text(xacro_file.read_text().replace("${pi/2}", "${undefined_name/2}", 1))
        expected = [xacro_file.name, "undefined_name"]
    else:
        text = path.read_text()
        first = text[text.index("[limits]"):].splitlines()[1]
        path.write_text(text.replace(first + "\n", ""))
        expected = [first.split("=")[0].strip().strip('"'), "[limits]"]
    proc = subprocess.run([sys.executable, "-m", "snakehead", "info", "--robot", str(path), "--quick"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("snakehead info: error:"), proc.stderr
    for word in expected:
        assert word in lines[0], (word, lines[0])


def test_a_continuous_joint_off_the_body_needs_no_limits() -> None:
    """A camera pan (continuous) on a branch off the body chain: not the planner's, so no [limits] entry."""
    text = snakehead.default_urdf_path().read_text()
    branch = ('<link name="camera"/><joint name="camera_pan" type="continuous"><parent link="link_3"/>'
              '<child link="camera"/><axis xyz="0 0 1"/></joint></robot>')
    robot = SnakeRobot.from_urdf(text.replace("</robot>", branch), base_end="base_end", neck_end="neck_end",
                                 head_tip="head_tip")
    assert robot.n_joints == 16 and "camera_pan" not in robot.joint_names


def test_a_root_placed_off_the_body_line(tmp_path: Path) -> None:
    """A base link whose origin sits off the body's line (a fixed joint 5 cm sideways and 2 cm up to the tail): the
    line runs from the first joint to the head tip, the body frame's origin is the root's projection on it, and
    the body is the snake written without the offset, 3 cm along it."""
    text = snakehead.default_urdf_path().read_text()
    offset = ('<link name="base_link"/><joint name="base_to_tail" type="fixed"><parent link="base_link"/>'
              '<child link="link_0"/><origin xyz="0.03 -0.05 -0.02" rpy="0 0 0"/></joint></robot>')
    shifted = SnakeRobot.from_urdf(text.replace("</robot>", offset), base_end="base_end", neck_end="neck_end",
                                   head_tip="head_tip")
    plain = SnakeRobot.default()
    np.testing.assert_allclose(shifted.body_in_root[:3, :3], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(shifted.body_in_root[:3, 3], [0.0, -0.05, -0.02], atol=1e-12)  # root's projection
    q = plain.random_configuration(np.random.default_rng(3))
    H, H0 = shifted.head_pose(q), plain.head_pose(q)  # the tail 3 cm ahead of the body frame's origin
    np.testing.assert_allclose(H[:3, :3], H0[:3, :3], atol=1e-12)
    np.testing.assert_allclose(H[:3, 3], H0[:3, 3] + [0.03, 0.0, 0.0], atol=1e-12)
    assert shifted.body_axis_height == pytest.approx(plain.body_axis_height, abs=1e-12)
