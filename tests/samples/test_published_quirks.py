"""The quirk styles of snakehead.samples.published (written by model/published_quirks.py, issue 34): each description
does what the published one it stands for does, checked against pinocchio (an independent URDF parser and FK), and
each loads as it is into a SnakeRobot whose kinematics are the description's.

What each style must reproduce is written out here (numbers and texts), not read from the module under test."""
import math
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from snakehead.samples.published import QUIRK_STYLES, STYLES, style_spec, write_robot

pin = pytest.importorskip("pinocchio")

#: (base, neck, head) joints of every quirk style (16 joints each).
PARTS = {style: (7, 2, 7) for style in QUIRK_STYLES}
#: The largest side offset (m) of a body frame from the body's line at home, as each style states it.
SIDE_OFFSET = {"cad": 0.0044, "reu_reversed": 1e-9, "wheeled": 1e-9, "cmu_masses": 1e-9, "backwards_head": 1e-9}
#: The near-right angles each style writes in its joint origins (texts that must appear).
NEAR_RIGHT = {"cad": ("1.5708", "1.57075", "1.57076327", "3.14152654"), "reu_reversed": ("-1.57075",),
              "backwards_head": ("3.14152654",)}


class Written:
    """A written quirk robot: its robot file, its URDF (ElementTree) and its pinocchio model."""

    def __init__(self, style: str, path: Path):
        self.style = style
        self.path = path
        self.data = tomllib.loads(path.read_text(encoding="utf-8"))
        self.text = (path.parent / self.data["urdf"]).read_text(encoding="utf-8")
        self.tree = ET.fromstring(self.text)
        self.model = pin.buildModelFromXML(self.text)
        self.parent = {j.find("child").get("link"): j for j in self.tree.iter("joint")}

    @property
    def home(self) -> dict[str, float]:
        return self.data.get("home", {})

    def up(self, link: str) -> list[str]:
        """``link`` and its ancestors, up to the URDF's root."""
        out = [link]
        while out[-1] in self.parent:
            out.append(self.parent[out[-1]].find("parent").get("link"))
        return out

    def path_links(self, a: str, b: str) -> list[str]:
        """The links on the tree's path from ``a`` to ``b`` (through their nearest common ancestor)."""
        ua, ub = self.up(a), self.up(b)
        common = next(x for x in ua if x in ub)
        return ua[:ua.index(common) + 1] + ub[:ub.index(common)][::-1]

    def body_links(self) -> list[str]:
        return self.path_links(self.data.get("root"), self.data["head_tip"])

    def body_joints(self) -> list[str]:
        """The moving joints of the body in body order (root to head tip)."""
        links = self.body_links()
        out = []
        for a, b in zip(links, links[1:]):
            joint = self.parent[b] if self.parent.get(b) is not None and self.parent[b].find("parent").get(
                "link") == a else self.parent[a]
            if joint.get("type") != "fixed":
                out.append(joint.get("name"))
        return out

    def q(self, angles: dict[str, float]) -> np.ndarray:
        q = pin.neutral(self.model)
        for name, value in angles.items():
            joint = self.model.joints[self.model.getJointId(name)]
            if joint.nq == 2:  # continuous: (cos, sin)
                q[joint.idx_q:joint.idx_q + 2] = (math.cos(value), math.sin(value))
            else:
                q[joint.idx_q] = value
        return q

    def placements(self, angles: dict[str, float]) -> dict[str, pin.SE3]:
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, self.q(angles))
        return {f.name: data.oMf[i] for i, f in enumerate(self.model.frames)}


def line_fit(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(centre, unit direction from the first point towards the last, each point's distance from the line)."""
    centre = points.mean(axis=0)
    direction = np.linalg.svd(points - centre)[2][0]
    if np.dot(points[-1] - points[0], direction) < 0:
        direction = -direction
    rel = points - centre
    side = rel - np.outer(rel @ direction, direction)
    return centre, direction, np.linalg.norm(side, axis=1)


@pytest.fixture(scope="module", params=QUIRK_STYLES)
def written(request, tmp_path_factory) -> Written:
    return Written(request.param, write_robot(request.param, tmp_path_factory.mktemp(request.param)))


def test_quirk_styles_are_their_own():
    assert set(QUIRK_STYLES).isdisjoint(STYLES)
    assert set(QUIRK_STYLES) == {"cad", "reu_reversed", "wheeled", "cmu_masses", "backwards_head"}
    for style in QUIRK_STYLES:
        spec = style_spec(style)
        assert (spec.base_joints, spec.neck_joints, spec.head_joints) == PARTS[style]


def test_body_lies_on_its_line_at_home(written):
    """pinocchio's frames of the body (root to head tip) at the robot file's home lie on one line, in order,
    within the style's stated side offset."""
    places = written.placements(written.home)
    links = written.body_links()
    points = np.array([places[name].translation for name in links])
    _, direction, side = line_fit(points)
    assert side.max() <= SIDE_OFFSET[written.style] + 1e-9, (links[int(side.argmax())], side.max())
    along = (points - points[0]) @ direction
    assert np.all(np.diff(along) >= -1e-9)
    assert along[-1] > 1.0  # 16 modules of 6-9 cm
    assert len(written.body_joints()) == 16


def test_cad_is_curved_at_zero_and_straight_at_home(tmp_path):
    w = Written("cad", write_robot("cad", tmp_path))
    links = w.body_links()
    home = {j: v for j, v in w.home.items()}
    assert set(home) == set(w.body_joints())
    assert sum(abs(v) > 0.03 for v in home.values()) == 8  # the yaw joints undo a 2 deg turn each
    at_zero = np.array([w.placements({})[name].translation for name in links])
    side_zero = line_fit(at_zero)[2]
    assert side_zero.max() > 0.02  # 8 turns of 2 deg curl the 1.2 m body: 24 mm off its line, not 4.4 mm
    zero = w.placements({})
    turn = math.degrees(math.acos(zero["base_link"].rotation[:, 0] @ zero["head_tip"].rotation[:, 0]))
    assert turn == pytest.approx(8 * 2.0, abs=0.01)
    at_home = np.array([w.placements(home)[name].translation for name in links])
    side_home = line_fit(at_home)[2]
    assert 0.0043 < side_home.max() <= 0.0044 + 1e-9  # the joint frames sit 4.4 mm to the side
    for text in NEAR_RIGHT["cad"]:
        assert f'rpy="{text} ' in w.text or f' {text}"' in w.text or f' {text} ' in w.text, text
    assert 'rpy="1.5707963' not in w.text  # no exact quarter turn anywhere
    # mesh collisions on every module, through package://
    meshes = [m.get("filename") for m in w.tree.iter("mesh")]
    assert len(meshes) >= 2 * 17 and all(m.startswith("package://cad_snake_sw/meshes/") for m in meshes)
    for m in meshes:
        assert (tmp_path / m.removeprefix("package://cad_snake_sw/")).is_file()


def test_joint_axes_are_near_right_angles(written):
    """At home, each body joint's axis is within 1 deg of the body frame's y or z; the near-right angles of the
    CAD export and of the reversed CMU tree leave them 1e-4 to 8e-4 rad off (as the published ones are)."""
    places = written.placements(written.home)
    links = written.body_links()
    points = np.array([places[name].translation for name in links])
    _, x_axis, _ = line_fit(points)
    root_frame = places[links[0]].rotation if written.style != "reu_reversed" else places[links[-1]].rotation
    up = root_frame[:, 2] - np.dot(root_frame[:, 2], x_axis) * x_axis
    if written.style == "reu_reversed":  # the URDF root (the head's front) has its z up
        up = places["kdl_dummy_root"].rotation[:, 2]
    z_axis = up / np.linalg.norm(up)
    y_axis = np.cross(z_axis, x_axis)
    deviations = []
    for name in written.body_joints():
        joint = next(j for j in written.tree.iter("joint") if j.get("name") == name)
        axis = np.array([float(v) for v in joint.find("axis").get("xyz").split()])
        world = places[joint.find("child").get("link")].rotation @ axis
        world /= np.linalg.norm(world)
        off = math.acos(min(1.0, max(abs(world @ y_axis), abs(world @ z_axis))))
        deviations.append(off)
        assert abs(world @ x_axis) < 0.02
    worst = max(deviations)
    if written.style in ("cad", "reu_reversed"):
        assert 1e-4 <= worst <= 8e-4, worst
    else:
        assert worst < 1e-9, worst
    kinds = [abs(places[next(j for j in written.tree.iter("joint") if j.get("name") == n).find("child").get("link")]
                 .rotation @ np.array([float(v) for v in next(j for j in written.tree.iter("joint")
                                                              if j.get("name") == n).find("axis").get("xyz").split()])
                 @ z_axis) > 0.5 for n in written.body_joints()]
    assert all(a != b for a, b in zip(kinds, kinds[1:]))  # yaw and pitch alternate


def test_reversed_tree_runs_from_the_head(tmp_path):
    w = Written("reu_reversed", write_robot("reu_reversed", tmp_path))
    assert w.data["root"] == "tail" and w.data["head_tip"] == "kdl_dummy_root"
    assert not any(j.find("parent").get("link") == "tail" for j in w.tree.iter("joint"))  # a leaf
    assert w.up("tail")[-1] == "kdl_dummy_root"  # the head tip is the URDF's root, an ancestor of the root
    assert w.body_joints()[0] == "mod_16_joint" and w.body_joints()[-1] == "mod_1_joint"
    places = w.placements({})
    # the head frame's x points out of the head, away from the body
    head, tail = places["kdl_dummy_root"], places["tail"]
    forward = head.translation - tail.translation
    assert head.rotation[:, 0] @ (forward / np.linalg.norm(forward)) > 1 - 1e-6
    # the parts end where the robot file says: base 7 joints from the tail, neck 2
    base = w.path_links("tail", w.data["base_end"])
    neck = w.path_links(w.data["base_end"], w.data["neck_end"])
    moving = {j.get("name") for j in w.tree.iter("joint") if j.get("type") != "fixed"}
    crossed = lambda links: sum(  # noqa: E731
        1 for a, b in zip(links, links[1:]) for j in (w.parent.get(a), w.parent.get(b))
        if j is not None and j.get("name") in moving and {j.find("parent").get("link"), j.find("child").get("link")}
        == {a, b})
    assert (crossed(base), crossed(neck)) == (7, 2)


def test_wheels_hang_off_every_module(tmp_path):
    w = Written("wheeled", write_robot("wheeled", tmp_path))
    wheels = [j for j in w.tree.iter("joint") if j.find("child").get("link").startswith("wheel_")]
    assert len(wheels) == 32
    kinds = {j.get("type") for j in wheels}
    assert kinds == {"continuous", "revolute"}
    zero = [j.get("name") for j in wheels if j.find("axis").get("xyz") == "0 0 0"]
    assert zero == ["wheel_2_right_joint"]
    assert all(j.find("limit").get("lower") == "-7" for j in wheels if j.get("type") == "revolute")
    # the wheels' bottoms lie 1 mm below the body's at q = 0: they carry the snake
    places = w.placements({})
    section = style_spec("wheeled").thickness
    body_bottom = places["link_0"].translation[2] - section / 2
    for j in wheels:
        wheel = places[j.find("child").get("link")]
        radius = float(w.tree.find(f"link[@name='{j.find('child').get('link')}']/collision/geometry/cylinder")
                       .get("radius"))
        assert abs(abs(wheel.rotation[:, 2] @ np.array([0, 1.0, 0])) - 1) < 1e-6  # the axle runs across the body
        assert wheel.translation[2] - radius == pytest.approx(body_bottom - 0.001, abs=1e-6)


def test_cmu_masses_are_the_published_ones(tmp_path):
    w = Written("cmu_masses", write_robot("cmu_masses", tmp_path))
    assert w.data["inertia"] == "from_shapes"
    links = {link.get("name"): link for link in w.tree.iter("link")}
    joint_links = [n for n in links if n.startswith("reu_module_in_")]
    shells = [n for n in links if n.startswith("reu_module_body_")]
    assert len(joint_links) == len(shells) == 16
    for n in joint_links:
        assert links[n].find("collision") is None
        assert float(links[n].find("inertial/mass").get("value")) == pytest.approx(1.0)
        assert float(links[n].find("inertial/inertia").get("ixx")) == 1.0
    for n in shells:
        assert float(links[n].find("inertial/mass").get("value")) == 0.103
        ixx = float(links[n].find("inertial/inertia").get("ixx"))
        assert ixx == 2.948 and math.sqrt(ixx / 0.103) > 5  # a 5 m radius of gyration for a 5 cm module
    masses = [sum(pin_inertia.mass for pin_inertia in [w.model.inertias[i]]) for i in range(w.model.njoints)]
    total = sum(masses)
    assert total == pytest.approx(16 * 1.103 + sum(float(links[n].find("inertial/mass").get("value"))
                                                   for n in ("reu_tail",)), rel=1e-9)
    assert 16.0 / total > 0.85  # most of the mass sits on links without geometry


def test_backwards_head_points_back(tmp_path):
    w = Written("backwards_head", write_robot("backwards_head", tmp_path))
    assert w.data["head_axis"] == "-x"
    places = w.placements({})
    tip, root = places["head_tip"], places["link_0"]
    forward = (tip.translation - root.translation) / np.linalg.norm(tip.translation - root.translation)
    assert tip.rotation[:, 0] @ forward == pytest.approx(-1.0, abs=1e-8)
    assert tip.rotation[:, 2] @ np.array([0, 0, 1.0]) == pytest.approx(1.0, abs=1e-8)


# --- loaded as they are --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def loaded(written):
    from snakehead import SnakeRobot

    return SnakeRobot.from_file(written.path)


def test_loads_with_the_descriptions_kinematics(written, loaded):
    """The loaded robot has the description's joints in body order, its parts, and its head tip where pinocchio
    puts it (relative to the root frame) at the planner's zero (the home pose) and at random poses."""
    assert loaded.joint_names == written.body_joints()
    assert (len(loaded.base_chain.joint_names), len(loaded.neck_chain.joint_names),
            len(loaded.head_chain.joint_names)) == PARTS[written.style]
    root, tip = written.data.get("root"), written.data["head_tip"]
    rng = np.random.default_rng(34)
    for q in [np.zeros(16)] + [rng.uniform(-0.8, 0.8, 16) for _ in range(3)]:
        q_description = loaded.description_angles(q)
        places = written.placements(dict(zip(loaded.joint_names, q_description)))
        expected = places[root].inverse() * places[tip]
        ours = loaded.body.fk(q)
        np.testing.assert_allclose(ours[:3, 3], expected.translation, atol=1e-9)
    if written.home:
        np.testing.assert_allclose(loaded.description_angles(np.zeros(16)),
                                   [written.home.get(j, 0.0) for j in loaded.joint_names], atol=0)


def test_loaded_axes_and_straightness(written, loaded):
    worst = float(np.max(loaded.axis_deviations))
    if written.style in ("cad", "reu_reversed"):
        assert 1e-4 <= worst <= 8e-4, worst
    else:
        assert worst < 1e-9
    assert loaded.straightness.offset <= 0.005  # within the body's half-section (the CAD frames' 4.4 mm)
    assert loaded.head_axis == written.data.get("head_axis", "x")


def test_loaded_side_branches(written, loaded):
    changes = loaded.tree_changes
    if written.style == "wheeled":
        held = {name for name, _, _ in changes.held_joints}
        assert held == {f"wheel_{i}_{side}_joint" for i in range(16) for side in ("left", "right")}
        assert all(value == 0.0 for _, value, _ in changes.held_joints)
    if written.style == "cad":
        moved = {b.name: b for b in changes.branch_links}
        assert {"collar2", "collar6", "imu3", "imu7"} <= set(moved)
        assert moved["collar2"].onto == "link2" and moved["collar2"].shapes == 1
        assert moved["collar2"].mass == pytest.approx(0.012)
    if written.style == "reu_reversed":
        assert len(changes.reversed_joints) >= 16


def test_cmu_masses_are_reported(tmp_path):
    from snakehead import SnakeRobot
    from snakehead.model.mass_properties import mass_findings

    path = write_robot("cmu_masses", tmp_path)
    text = path.read_text(encoding="utf-8").replace('inertia = "from_shapes"\n', "")
    as_written = tmp_path / "as_written.toml"
    as_written.write_text(text, encoding="utf-8")
    findings = mass_findings(SnakeRobot.from_file(as_written))
    kinds = {f.kind for f in findings}
    assert {"gyration", "shapeless"} <= kinds, [str(f) for f in findings]
    assert any("reu_module_body_1" in f.links for f in findings if f.kind == "gyration")


#: What ``snakehead info --quick`` must say of each quirk style (lines of its output, in part).
INFO_SAYS = {
    "cad": ("home (the body lies straight; planner angles = description's - home): joint1 = -0.0349",
            "side branches: 8 links (0.072 kg, 8 collision shapes)", "collar2 -> link2",
            "joint axes within 0.015 deg of the body's y or z", "frames within 4."),
    "reu_reversed": ("the body runs against the URDF's tree", "-> kdl_dummy_root (1.0544 m",
                     "7 joints (mod_16_joint:y", "joint axes within 0.040 deg"),
    "wheeled": ("held: 32 moving joints off the body", "with axis 0 0 0: wheel_2_right_joint",
                "side branches: 32 links (0.320 kg, 32 collision shapes)"),
    "cmu_masses": ("inertia: recomputed from the collision shapes (uniform density over each rigid segment",
                   "16 kg on 16 links without shapes moved onto the shapes fixed to them (now 0 kg): "
                   "'reu_module_in_1' 1 kg -> 'reu_module_body_1'", "masses and inertias: plausible"),
    "backwards_head": ("head: neck_end", "design: the base holds the lifted neck and head"),
}


def test_info_reports_each_quirk(written):
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "snakehead", "info", "--quick", "--robot", str(written.path)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for text in INFO_SAYS[written.style]:
        assert text in proc.stdout, (text, proc.stdout)
