"""``head_axis`` with a sign (issue 34, item 7): one published snake's head frame points its x-axis back along the
body. The same snake written twice -- as the default convention writes it, and with its head frame turned 180 deg
about z and ``head_axis = "-x"`` in its robot file -- is one robot: the head looks the same way at every
configuration, the head's solve and the plan of a reachable target are the same. A bad ``head_axis`` is exit 2 with
a line that lists the choices."""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from plan_verification import verify_plan

import snakehead
from snakehead.app import cli
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.samples.targets import reachable_targets

#: The default robot's numbers and frames (snake16.urdf is written from them)
SPEC = SnakeSpec(markers={"p0": 7, "b0": 9}, name="turned_head_snake")
FRAMES = {"base_end": "p0", "neck_end": "b0", "head_tip": "head_tip"}


def turned_urdf(yaw: float) -> str:
    """The SPEC snake with its head_tip frame turned by ``yaw`` about its z (its x then looks back for yaw = pi)."""
    root = ET.fromstring(snake_urdf(SPEC))
    origin = root.find("joint[@name='head_tip_joint']/origin")
    assert origin is not None and origin.get("rpy", "0 0 0").split() == ["0", "0", "0"]
    origin.set("rpy", f"0 0 {yaw!r}")
    return ET.tostring(root, encoding="unicode")


def write(folder, name: str, urdf: str, head_axis: str):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.urdf").write_text(urdf, encoding="utf-8")
    path = folder / f"{name}.toml"
    keys = {"urdf": f"{name}.urdf", **FRAMES, "head_axis": head_axis}
    path.write_text("".join(f'{key} = "{value}"\n' for key, value in keys.items()), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("head_axis")
    return {"plain": write(folder, "plain", snake_urdf(SPEC), "x"),
            "turned": write(folder, "turned", turned_urdf(math.pi), "-x"),
            "as_published": write(folder, "as_published", turned_urdf(3.14152654), "-x")}


@pytest.fixture(scope="module")
def robots(files):
    return {key: snakehead.SnakeRobot.from_file(path) for key, path in files.items()}


def random_configurations(robot, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(robot.lower, robot.upper, size=(n, robot.n_joints))


def test_the_turned_frame_looks_back_in_the_description(robots):
    """The test's premise: in the turned description the head_tip frame's own x points back along the body (so a
    loader that ignored the sign would make the head look backwards)."""
    turned = robots["turned"]
    raw = turned.body.fk_all(np.zeros(turned.n_joints))
    tip = raw[turned.body.link_index("head_tip")]
    forward = tip[:3, 3] - raw[0, :3, 3]
    assert tip[:3, 0] @ forward / np.linalg.norm(forward) == pytest.approx(-1.0, abs=1e-12)
    assert turned.head_axis == "-x"


@pytest.mark.parametrize("key, tolerance", [("turned", 1e-12), ("as_published", 2e-4)])
def test_the_head_looks_the_same_way(robots, key, tolerance):
    """At random configurations the planner's head frame (position and axes) is the unturned robot's (the turn
    3.14152654 written as published is 7e-5 rad short of pi: its head direction differs by that)."""
    plain, other = robots["plain"], robots[key]
    assert other.n_joints == plain.n_joints and other.joint_names == plain.joint_names
    for q in random_configurations(plain, 20, 3):
        A, B = plain.head_pose(q), other.head_pose(q)
        np.testing.assert_allclose(B[:3, 3], A[:3, 3], atol=1e-12)
        np.testing.assert_allclose(B[:3, :3], A[:3, :3], atol=tolerance)
    assert other.body_length == pytest.approx(plain.body_length, abs=1e-12)


def test_unsigned_axis_on_the_turned_frame_looks_back(files, robots):
    """The sign matters: the turned description read with ``head_axis = "x"`` has a head that looks the other way
    (or is refused), never the plain robot's head."""
    path = files["turned"]
    text = path.read_text(encoding="utf-8")
    unsigned = path.with_name("turned_unsigned.toml")
    unsigned.write_text(re.sub(r'head_axis = "-x"', 'head_axis = "x"', text), encoding="utf-8")
    try:
        robot = snakehead.SnakeRobot.from_file(unsigned)
    except snakehead.InputError:
        return
    q = np.zeros(robot.n_joints)
    assert robot.head_pose(q)[:3, 0] @ robots["plain"].head_pose(q)[:3, 0] < 0


def test_the_head_solve_is_the_same(robots):
    """The segmented solve of reachable targets gives the same joint angles for both."""
    plain = snakehead.HeadController(robots["plain"], method="free_roll", seed=1)
    turned = snakehead.HeadController(robots["turned"], method="free_roll", seed=1)
    for t in reachable_targets(plain, "same", 2, np.random.default_rng(0)):
        a, b = plain.solve(t.position, t.direction), turned.solve(t.position, t.direction)
        assert a.success and b.success
        np.testing.assert_allclose(b.q, a.q, atol=1e-6)
        H = robots["turned"].head_pose(b.q, b.base)  # whole-body FK of the turned robot: on the target
        assert np.linalg.norm(H[:3, 3] - t.position) <= 1e-3
        assert H[:3, 0] @ t.direction > math.cos(math.radians(1.0))
        np.testing.assert_allclose(b.head_frame, H, atol=1e-9)


def test_a_reachable_target_plans_the_same(robots):
    """A reachable target plans with both robots; the plans pass the independent checks and move the joints the
    same way (the turned head's plan is the plain one's)."""
    plain = snakehead.HeadController(robots["plain"], method="free_roll", seed=1)
    turned = snakehead.HeadController(robots["turned"], method="free_roll", seed=1)
    t = reachable_targets(plain, "same", 1, np.random.default_rng(0))[0]
    a = snakehead.plan([(t.position, t.direction)], controller=plain)
    b = snakehead.plan([(t.position, t.direction)], controller=turned)
    verify_plan(a, t.position, t.direction)
    verify_plan(b, t.position, t.direction)
    assert b.q.shape == a.q.shape
    np.testing.assert_allclose(b.q, a.q, atol=1e-6)


def test_info_reads_the_signed_axis(files, capsys):
    assert cli.main(["info", "--robot", str(files["turned"])]) == 0
    out = capsys.readouterr().out
    assert "head_tip" in out


@pytest.mark.parametrize("value", ["w", "+x", "X", "-", "--x", "x "])
def test_a_bad_head_axis_lists_the_choices(files, capsys, value):
    """Exit 2 with one line that names the robot file, head_axis, the value and every choice."""
    path = files["turned"]
    bad = path.with_name("bad_axis.toml")
    bad.write_text(path.read_text(encoding="utf-8").replace('head_axis = "-x"', f'head_axis = "{value}"'),
                   encoding="utf-8")
    assert cli.main(["info", "--robot", str(bad)]) == 2
    line = capsys.readouterr().err.strip()
    assert "\n" not in line
    assert re.search(r"robot file '.*bad_axis\.toml': 'head_axis' must be one of x, y, z, -x, -y, -z \(.*\), got "
                     + re.escape(repr(value)), line), line
