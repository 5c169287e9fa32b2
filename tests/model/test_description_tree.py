"""The description's tree rewritten into the body (snakehead.model.description_tree), against pinocchio.

pinocchio reads the descriptions as written (its own URDF parser, its own tree, the head at its root where the file
puts it); our robot reads the rewritten tree. Every frame of the body, the Jacobian, the masses and the centre of
mass must agree at the description's joint angles.
"""
from __future__ import annotations

import numpy as np
import pytest

from snakehead import InputError, SnakeRobot
from snakehead.app.cli import main
from snakehead.model.body_frame import NotStraight, suggest_home

pin = pytest.importorskip("pinocchio")

L, R, M = 0.07, 0.025, 0.2  # module length (m), radius (m), mass (kg)


def _module(cx: float, mass: float = M) -> str:
    ixx = mass * R ** 2 / 2
    iyy = mass * (3 * R ** 2 + L ** 2) / 12
    return (f'<inertial><origin xyz="{cx} 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{iyy}"/></inertial>'
            f'<collision><origin xyz="{cx} 0 0" rpy="0 1.5707963267948966 0"/>'
            f'<geometry><cylinder radius="{R}" length="{L}"/></geometry></collision>')


def tail_first(n: int = 12, *, rpy90: str = "1.5708", side: float = 0.0, curl: float = 0.0,
               collars: bool = False, wheels: bool = False) -> str:
    """Modules along x from the tail (m0) to the head (m{n}); even joints pitch through frames turned about x by
    ``rpy90`` and back by the next; ``side``: joint frames alternately that far to the side (m); ``curl``: each yaw
    joint's frame turned by that much (rad) about z, so that the body curls at zero; collars on fixed joints and
    wheels on continuous ones (the first with axis 0 0 0) hang off some modules."""
    from scipy.spatial.transform import Rotation

    out = ['<robot name="quirky">', f'<link name="m0">{_module(L / 2)}</link>']
    for k in range(1, n + 1):
        pitch = k % 2 == 0
        roll = float(rpy90) if pitch else (-float(rpy90) if k > 1 else 0.0)
        # curl about the joint's own axis (its frame's z after the roll)
        rpy = Rotation.from_matrix(Rotation.from_euler("x", roll).as_matrix()
                                   @ Rotation.from_euler("z", 0.0 if pitch else curl).as_matrix()).as_euler("xyz")
        # the side offset along the body's y: the parent's y when unrolled (m0, odd links), its -z when rolled
        xyz = f"{L} {side} 0" if k == 1 else (f"{L} {-side} 0" if pitch else f"{L} 0 {-side}")
        out.append(f'<joint name="j{k}" type="revolute"><parent link="m{k - 1}"/><child link="m{k}"/>'
                   f'<origin xyz="{xyz}" rpy="{float(rpy[0])!r} {float(rpy[1])!r} {float(rpy[2])!r}"/><axis xyz="0 0 1"/>'
                   '<limit lower="-1.5" upper="1.5" effort="5" velocity="3"/></joint>')
        out.append(f'<link name="m{k}">{_module(L / 2)}</link>')
        if collars and k % 3 == 0:
            out.append(f'<joint name="collar{k}_joint" type="fixed"><parent link="m{k}"/><child link="collar{k}"/>'
                       f'<origin xyz="{L / 2} 0.01 {R}" rpy="0.2 0 0.3"/></joint>'
                       f'<link name="collar{k}"><inertial><origin xyz="0.003 0 0.005" rpy="0.1 0.2 0"/>'
                       '<mass value="0.05"/><inertia ixx="2e-5" ixy="1e-6" ixz="0" iyy="3e-5" iyz="0" izz="4e-5"/>'
                       '</inertial><collision><geometry><box size="0.02 0.02 0.01"/></geometry></collision></link>')
        if wheels and k % 4 == 1:
            axis = "0 0 0" if k == 1 else "0 0 1"
            out.append(f'<joint name="wheel{k}_joint" type="continuous"><parent link="m{k}"/><child link="wheel{k}"/>'
                       f'<origin xyz="{L / 2} 0 {-R}" rpy="1.5708 0 0"/><axis xyz="{axis}"/></joint>'
                       f'<link name="wheel{k}"><inertial><origin xyz="0 0 0.002"/><mass value="0.03"/>'
                       '<inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="2e-5"/></inertial>'
                       '<collision><geometry><cylinder radius="0.01" length="0.005"/></geometry></collision></link>')
    out.append(f'<joint name="tip_joint" type="fixed"><parent link="m{n}"/><child link="head_tip"/>'
               f'<origin xyz="{L} 0 0"/></joint><link name="head_tip"/></robot>')
    return "\n".join(out)


def head_first(n: int = 12) -> str:
    """The tree starts at the head's tip and ends at the tail h{n}: each module's frame at its front end, the
    module along its -x (as one published snake is written)."""
    out = ['<robot name="headfirst">', '<link name="head_tip"/>',
           '<joint name="tip_joint" type="fixed"><parent link="head_tip"/><child link="h0"/>'
           '<origin xyz="0 0 0" rpy="0 0 0.0"/></joint>', f'<link name="h0">{_module(-L / 2)}</link>']
    for k in range(1, n + 1):
        axis = "0 1 0" if k % 2 == 0 else "0 0 1"
        out.append(f'<joint name="j{k}" type="revolute"><parent link="h{k - 1}"/><child link="h{k}"/>'
                   f'<origin xyz="{-L} 0 0" rpy="0 0 0"/><axis xyz="{axis}"/>'
                   '<limit lower="-1.5" upper="1.4" effort="5" velocity="3"/></joint>')
        out.append(f'<link name="h{k}">{_module(-L / 2)}</link>')
    return "\n".join(out + ["</robot>"])


class Pinocchio:
    """A description read by pinocchio, placed at joint angles given by name (others, wheels included, at 0)."""

    def __init__(self, text: str) -> None:
        self.model = pin.buildModelFromXML(text)
        self.data = self.model.createData()

    def q(self, angles: dict[str, float]) -> np.ndarray:
        q = pin.neutral(self.model)
        for name, value in angles.items():
            q[self.model.joints[self.model.getJointId(name)].idx_q] = value
        return q

    def frames(self, angles: dict[str, float]) -> dict[str, np.ndarray]:
        pin.framesForwardKinematics(self.model, self.data, self.q(angles))
        return {f.name: self.data.oMf[i].homogeneous for i, f in enumerate(self.model.frames)}

    def com(self, angles: dict[str, float]) -> tuple[float, np.ndarray]:
        """Total mass and centre of mass (world) with the root link's own body, which pinocchio fixes to its
        universe and leaves out of both."""
        moving = float(pin.computeTotalMass(self.model))
        c = pin.centerOfMass(self.model, self.data, self.q(angles))
        fixed = self.model.inertias[0]
        return moving + fixed.mass, (moving * c + fixed.mass * fixed.lever) / (moving + fixed.mass)


def _relative(frames: dict[str, np.ndarray], base: str, names: list[str]) -> np.ndarray:
    inv = np.linalg.inv(frames[base])
    return np.stack([inv @ frames[name] for name in names])


def _angles(robot: SnakeRobot, q: np.ndarray) -> dict[str, float]:
    return dict(zip(robot.joint_names, robot.description_angles(q)))


def _every_link(robot: SnakeRobot, text: str) -> list[str]:
    """The description's links on the body (markers the rewrite added left out)."""
    names = set(Pinocchio(text).frames({}))
    return [name for name in robot.link_names if name in names]


@pytest.fixture(scope="module")
def reversed_robot() -> tuple[str, SnakeRobot]:
    text = head_first()
    return text, SnakeRobot.from_urdf(text, root="h12", base_end="h5", neck_end="h2", head_tip="head_tip")


def test_reversed_body_matches_pinocchio(reversed_robot):
    """The body runs against the tree (root = the tail, a leaf; head_tip = the URDF's root): every link's pose
    relative to the tail equals pinocchio's on the description as written, at the same joint angles (names and
    signs kept)."""
    text, robot = reversed_robot
    assert robot.joint_names == [f"j{k}" for k in range(12, 0, -1)]
    assert set(robot.tree_changes.reversed_joints) == {"tip_joint"} | {f"j{k}" for k in range(1, 13)}
    assert robot.joint_kinds == tuple("pitch" if k % 2 == 0 else "yaw" for k in range(12, 0, -1))
    links = _every_link(robot, text)
    assert len(links) == 14
    ref = Pinocchio(text)
    rng = np.random.default_rng(1)
    for q in [np.zeros(12)] + [rng.uniform(robot.lower, robot.upper) for _ in range(4)]:
        expected = _relative(ref.frames(_angles(robot, q)), "h12", links)
        ours = robot.body.fk_all(q)[[robot.link_index(n) for n in links]]
        np.testing.assert_allclose(ours, expected, atol=1e-12)
    # the limits are the description's, not mirrored: j1 .. j12 all [-1.5, 1.4]
    np.testing.assert_array_equal(robot.lower, -1.5)
    np.testing.assert_array_equal(robot.upper, 1.4)


def test_reversed_jacobian_matches_finite_differences_of_pinocchio(reversed_robot):
    """The head tip's Jacobian on the reversed chain (the core's) against central differences of pinocchio's head
    tip pose relative to the tail."""
    text, robot = reversed_robot
    ref = Pinocchio(text)
    q = np.random.default_rng(2).uniform(-1.0, 1.0, 12)

    def tip(qq: np.ndarray) -> np.ndarray:
        return _relative(ref.frames(_angles(robot, qq)), "h12", ["head_tip"])[0]

    h = 1e-6
    J = np.zeros((6, 12))
    for j in range(12):
        dq = np.zeros(12)
        dq[j] = h
        Tp, Tm = tip(q + dq), tip(q - dq)
        J[:3, j] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ tip(q)[:3, :3].T  # skew(omega)
        J[3:, j] = [W[2, 1], W[0, 2], W[1, 0]]
    np.testing.assert_allclose(robot.body.jacobian(q), J, atol=1e-7)


def test_near_right_angles_keep_the_true_axes():
    """rpy written as 1.57 (8e-4 rad off pi/2): the joints count as pitch, the largest deviation is reported, and
    the kinematics is the description's (not snapped): pinocchio agrees to 1e-12 where snapping would be off by
    millimetres."""
    text = tail_first(rpy90="1.57")
    robot = SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")
    assert robot.joint_kinds == tuple("pitch" if k % 2 == 0 else "yaw" for k in range(1, 13))
    assert np.degrees(robot.axis_deviations).max() == pytest.approx(np.degrees(np.pi / 2 - 1.57), rel=0.05)
    ref, exact = Pinocchio(text), Pinocchio(tail_first(rpy90=repr(np.pi / 2)))
    q = np.random.default_rng(3).uniform(-1.0, 1.0, 12)
    links = _every_link(robot, text)
    ours = robot.body.fk_all(q)[[robot.link_index(n) for n in links]]
    np.testing.assert_allclose(ours, _relative(ref.frames(_angles(robot, q)), "m0", links), atol=1e-12)
    snapped = _relative(exact.frames(_angles(robot, q)), "m0", links)
    assert np.abs(snapped[:, :3, 3] - ours[:, :3, 3]).max() > 1e-4


def test_axis_beyond_the_tolerance_is_named():
    with pytest.raises(InputError, match=r"joint 'j2' turns about .* 2\.\d\d deg off its y- or z-axis \(at most 1 deg\)"):
        SnakeRobot.from_urdf(tail_first(rpy90="1.53"), base_end="m6", neck_end="m9", head_tip="head_tip")


def test_side_offsets_within_the_section_are_accepted_and_reported():
    text = tail_first(side=0.0044)
    robot = SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")
    assert 0.0015 < robot.straightness.offset <= 0.0044  # the 4.4 mm zigzag about the fitted line
    assert robot.half_section == pytest.approx(R, rel=0.03)  # the hull of the cylinder's mesh
    q = np.random.default_rng(4).uniform(-1.0, 1.0, 12)
    links = _every_link(robot, text)
    np.testing.assert_allclose(robot.body.fk_all(q)[[robot.link_index(n) for n in links]],
                               _relative(Pinocchio(text).frames(_angles(robot, q)), "m0", links), atol=1e-12)


CURL = np.radians(3.0)  # 6 yaw joints: the body's middle 36 mm off the line through its ends


def _curled_home() -> dict[str, float]:
    return {f"j{k}": -CURL for k in range(1, 13, 2)}


def test_home_pose_straightens_a_curled_body():
    """3 deg of curl per yaw joint with [home] = -3 deg: the planner's zero is
    the home pose, FK agrees with pinocchio at the description's angles (planner's + home) and the limits shift."""
    text = tail_first(curl=CURL)
    home = _curled_home()
    robot = SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip", home=home)
    assert robot.straightness.offset < 1e-9
    np.testing.assert_allclose(robot.description_angles(np.zeros(12)), [home.get(j, 0.0) for j in robot.joint_names])
    np.testing.assert_allclose(robot.body_angles(robot.description_angles(np.ones(12))), np.ones(12))
    np.testing.assert_allclose(robot.lower, -1.5 - robot.joint_offsets.home)
    ref = Pinocchio(text)
    links = _every_link(robot, text)
    for q in (np.zeros(12), np.random.default_rng(5).uniform(-1.0, 1.0, 12)):
        np.testing.assert_allclose(robot.body.fk_all(q)[[robot.link_index(n) for n in links]],
                                   _relative(ref.frames(_angles(robot, q)), "m0", links), atol=1e-12)


def test_curled_body_is_refused_with_a_home_suggestion(capsys, tmp_path):
    text = tail_first(curl=CURL)
    # the curl shows both ways: frames off the line, joint axes off the body's y or z
    with pytest.raises(NotStraight, match=r"(mm off the body's line|deg off its y- or z-axis).*\[home\]") as info:
        SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")
    found = suggest_home(info.value.chain)
    expected = np.array([_curled_home().get(f"j{k}", 0.0) for k in range(1, 13)])
    np.testing.assert_allclose(found, expected, atol=1e-4)
    (tmp_path / "curled.urdf").write_text(text)
    (tmp_path / "curled.toml").write_text('urdf = "curled.urdf"\nbase_end = "m6"\nneck_end = "m9"\n'
                                          'head_tip = "head_tip"\n')
    assert main(["info", "--robot", str(tmp_path / "curled.toml"), "--quick"]) == 2
    out, err = capsys.readouterr()
    assert "[home] table" in err and "SUGGESTION" in out and "[home]" in out
    table = out[out.index("[home]"):].splitlines()[1:]
    suggested = {line.split(" = ")[0].strip('"'): float(line.split(" = ")[1]) for line in table if " = " in line}
    assert set(suggested) == {f"j{k}" for k in range(1, 13, 2)}
    np.testing.assert_allclose(list(suggested.values()), -CURL, atol=1e-4)
    # the suggestion, pasted into the robot file, loads
    with open(tmp_path / "curled.toml", "a") as f:
        f.write("[home]\n" + "\n".join(table) + "\n")
    assert SnakeRobot.from_file(tmp_path / "curled.toml").straightness.offset < 1e-3


def test_side_branches_count_in_the_body():
    """Collars on fixed joints and wheels on continuous joints (one with axis 0 0 0) hang off the body: the robot's
    total mass, its centre of mass at random poses (wheels at 0) and each collared link's mass data equal
    pinocchio's, which merges fixed children into their parent body itself."""
    text = tail_first(collars=True, wheels=True)
    robot = SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")
    held = {joint: note for joint, _, note in robot.tree_changes.held_joints}
    assert held == {"wheel1_joint": "axis 0 0 0", "wheel5_joint": "continuous", "wheel9_joint": "continuous"}
    ref = Pinocchio(text.replace('<axis xyz="0 0 0"/>', '<axis xyz="0 0 1"/>'))  # pinocchio refuses a zero axis
    mass, _ = ref.com({})
    assert robot.total_mass == pytest.approx(mass, rel=1e-12)
    frames_ref = ref.frames({})
    for q in (np.zeros(12), np.random.default_rng(6).uniform(-1.0, 1.0, 12)):
        _, com = ref.com(_angles(robot, q))
        com_in_root = np.linalg.inv(ref.frames(_angles(robot, q))["m0"]) @ np.r_[com, 1.0]
        F = robot.body.fk_all(q)
        ours = np.einsum("k,kij,kj->i", robot.masses, F[:, :3, :3], robot.coms) + robot.masses @ F[:, :3, 3]
        np.testing.assert_allclose(ours / robot.total_mass, com_in_root[:3], atol=1e-12)
    for k in (3, 6, 12):  # pinocchio's body of joint j{k}: m{k} with its collar
        body = ref.model.inertias[ref.model.getJointId(f"j{k}")]
        i = robot.link_index(f"m{k}")
        assert robot.masses[i] == pytest.approx(body.mass, rel=1e-12)
        np.testing.assert_allclose(robot.coms[i], body.lever, atol=1e-12)
        np.testing.assert_allclose(robot.inertias[i], body.inertia, atol=1e-12)
    assert "collar3" in frames_ref  # the branch links stay frames of the description


def test_branch_shapes_move_with_their_link():
    """A collar's box becomes a shape of the link it hangs from, where pinocchio's collision model puts it."""
    text = tail_first(collars=True)
    robot = SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")
    boxes = [s for s in robot.geometry.shapes if s.kind == "box"]
    assert len(boxes) == 4 and {robot.link_names[s.frame] for s in boxes} == {"m3", "m6", "m9", "m12"}
    ref = Pinocchio(text)
    q = np.random.default_rng(7).uniform(-1.0, 1.0, 12)
    frames = ref.frames(_angles(robot, q))
    F = robot.body.fk_all(q)
    for s in boxes:
        collar = "collar" + robot.link_names[s.frame][1:]
        expected = np.linalg.inv(frames["m0"]) @ frames[collar]
        np.testing.assert_allclose(F[s.frame] @ s.origin, expected, atol=1e-12)


@pytest.mark.parametrize("mutate, message", [
    (lambda t: t.replace('<joint name="j3" type="revolute"><parent link="m2"/>',
                         '<joint name="j3" type="revolute"><parent link="nowhere"/>'),
     r"joint 'j3' names parent link 'nowhere', which the URDF does not have"),
    (lambda t: t.replace("</robot>", '<link name="x"/><joint name="again" type="fixed"><parent link="x"/>'
                                     '<child link="m4"/></joint></robot>'),
     r"link 'm4' is the child of two joints, 'j4' and 'again'"),
    (lambda t: t.replace('<origin xyz="0.07 0.0 0" rpy="0.0 0.0 0.0"/>', '<origin xyz="0.07 0" rpy="0 0 0"/>', 1),
     r"joint 'j1' <origin> xyz must be 3 finite numbers separated by spaces, got '0.07 0'"),
    (lambda t: t.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 one"/>', 1),
     r"joint 'j1' <axis> xyz must be 3 finite numbers separated by spaces, got '0 0 one'"),
])
def test_bad_trees_name_the_element(mutate, message):
    text = mutate(tail_first())
    with pytest.raises(InputError, match=message):
        SnakeRobot.from_urdf(text, base_end="m6", neck_end="m9", head_tip="head_tip")


def test_bad_home_tables_name_the_joint():
    text = tail_first(curl=CURL)
    kwargs = {"base_end": "m6", "neck_end": "m9", "head_tip": "head_tip"}
    with pytest.raises(InputError, match=r"\[home\] names joints the URDF does not have: 'j99'"):
        SnakeRobot.from_urdf(text, home={**_curled_home(), "j99": 0.1}, **kwargs)
    with pytest.raises(InputError, match=r"\[home\] gives 'tip_joint' an angle, but it is a fixed joint"):
        SnakeRobot.from_urdf(text, home={**_curled_home(), "tip_joint": 0.1}, **kwargs)
    with pytest.raises(InputError, match=r"home\.j1 = 2 rad lies outside the joint's limits \[-1\.5, 1\.5\]"):
        SnakeRobot.from_urdf(text, home={**_curled_home(), "j1": 2.0}, **kwargs)
    with pytest.raises(InputError, match=r"home\.j1 must be a finite angle in rad, got nan"):
        SnakeRobot.from_urdf(text, home={"j1": float("nan")}, **kwargs)


def test_reversing_a_floating_joint_is_refused():
    text = head_first().replace('<joint name="j4" type="revolute">', '<joint name="j4" type="floating">')
    with pytest.raises(InputError, match=r"joint 'j4' \(floating\) lies between the root and the URDF's root link"):
        SnakeRobot.from_urdf(text, root="h12", base_end="h5", neck_end="h2", head_tip="head_tip")


def test_unchanged_descriptions_stay_as_written():
    """A tail-first, straight, branch-free description is not rewritten: the core reads the file itself."""
    from snakehead.model.robot import default_urdf_path

    robot = SnakeRobot.default()
    assert not robot.tree_changes.any
    assert robot.urdf == str(default_urdf_path())
    np.testing.assert_array_equal(robot.joint_offsets.home, np.zeros(robot.n_joints))


@pytest.mark.parametrize("style", ["cad", "reu_reversed"])
def test_quirk_plans_track_in_mujoco(tmp_path, mujoco, style):
    """A body straightened by [home] (cad: curled at zero, side offsets, near-right rolls, side branches) and a
    body running against its tree (reu_reversed): a reachable target planned on the rewritten model is followed in
    MuJoCo (built from the same rewritten model) within 2 mm and 1 deg, the base in place."""
    from conftest import reachable_plan_in_mujoco

    from snakehead.samples.published import write_robot

    robot = SnakeRobot.from_file(write_robot(style, tmp_path))
    assert robot.tree_changes.home if style == "cad" else robot.tree_changes.reversed_joints
    sim = reachable_plan_in_mujoco(robot)
    assert sim.metrics["base_slide_m"] < 2e-3, sim.metrics
