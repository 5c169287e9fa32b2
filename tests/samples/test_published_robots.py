"""The sample robots written as published descriptions are (snakehead.samples.published): each style's files are
well-formed and describe the snake they claim to, checked with what exists before the new loader (the core's URDF
parser, Chain, trimesh, the PyPI xacro package)."""
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from snakehead import _core
from snakehead._errors import InputError, InputTypeError
from snakehead.model.chain import Chain
from snakehead.samples.published import STYLES, StyleSpec, style_spec, write_robot

#: (base, neck, head) joints of each style, written out here rather than read from the module under test.
PARTS = {"sea": (7, 2, 7), "reu": (7, 2, 7), "rsnake": (6, 2, 6), "mesh": (6, 2, 7), "xacro": (5, 2, 7),
         "one_joint_neck": (6, 1, 7), "head6": (8, 2, 6)}
ROBOT_FILE_KEYS = {"urdf", "xacro_args", "root", "base_end", "neck_end", "head_tip", "head_axis", "map", "packages",
                   "limits"}
AXIS_COLUMN = {"x": 0, "z": 2}
COLLISION_MESH_STYLES = {"sea", "mesh"}


class Robot:
    """A written sample robot: its robot file's contents and its description as URDF text (xacro expanded)."""

    def __init__(self, style: str, robot_file: Path):
        self.style = style
        self.path = robot_file
        self.folder = robot_file.parent
        self.data = tomllib.loads(robot_file.read_text(encoding="utf-8"))
        self.description = self.folder / self.data["urdf"]
        self.xml = expand(self.description, self.data.get("xacro_args", {}))
        self.tree = ET.fromstring(self.xml)

    @property
    def root(self) -> str:
        return self.data.get("root") or _core.urdf_root_link(self.xml)

    def chain(self, base: str | None = None, tip: str | None = None) -> Chain:
        return Chain.from_urdf(self.xml, base or self.root, tip or self.data["head_tip"])

    def joints(self, kind: str | None = None) -> list[ET.Element]:
        return [j for j in self.tree.iter("joint") if kind is None or j.get("type") == kind]


def expand(description: Path, xacro_args: dict) -> str:
    if not description.name.endswith(".xacro"):
        return description.read_text(encoding="utf-8")
    import xacro  # a dependency of the package

    doc = xacro.process_file(str(description), mappings={k: str(v) for k, v in xacro_args.items()})
    return doc.toprettyxml()


@pytest.fixture(scope="module", params=STYLES)
def robot(request, tmp_path_factory) -> Robot:
    return Robot(request.param, write_robot(request.param, tmp_path_factory.mktemp(request.param)))


def full_chain(robot: Robot) -> Chain:
    """The chain root -> head tip, as the core reads the description (continuous joints and meshes included)."""
    return robot.chain()


# --- the robot file ----------------------------------------------------------------------------------------------
def test_robot_file_has_the_design_keys_and_names_existing_files(robot):
    assert set(robot.data) <= ROBOT_FILE_KEYS
    assert {"urdf", "base_end", "neck_end", "head_tip"} <= set(robot.data)
    assert robot.description.is_file()
    assert robot.data.get("head_axis", "x") in AXIS_COLUMN
    for folder in robot.data.get("packages", {}).values():
        assert (robot.folder / folder).is_dir()


def test_continuous_joints_have_their_limits_in_the_robot_file(robot):
    limits = robot.data.get("limits", {})
    continuous = {j.get("name") for j in robot.joints("continuous")}
    assert set(limits) == continuous
    for lower, upper in limits.values():
        assert -np.pi <= lower < upper <= np.pi


# --- the description ---------------------------------------------------------------------------------------------
def test_parts_have_the_expected_joints_and_frames_lie_on_the_chain_in_order(robot):
    base, neck, head = PARTS[robot.style]
    chain = full_chain(robot)
    assert chain.n_joints == base + neck + head
    names = chain.link_names
    frames = [robot.root, robot.data["base_end"], robot.data["neck_end"], robot.data["head_tip"]]
    positions = [names.index(f) for f in frames]
    assert positions == sorted(positions) and positions[0] == 0 and positions[-1] == len(names) - 1
    for (start, end), expected in zip(zip(frames, frames[1:]), (base, neck, head)):
        assert robot.chain(start, end).n_joints == expected


def test_the_body_is_straight_at_zero_and_the_head_looks_along_it(robot):
    chain = full_chain(robot)
    frames = chain.fk_all(np.zeros(chain.n_joints))
    origins = frames[:, :3, 3]
    body = origins[-1] - origins[0]
    direction = body / np.linalg.norm(body)
    off_line = (origins - origins[0]) - np.outer((origins - origins[0]) @ direction, direction)
    assert np.abs(off_line).max() < 1e-9
    # Frames follow one another along the body (no frame behind its parent).
    assert np.all(np.diff(origins @ direction) >= -1e-12)
    head_axis = frames[-1][:3, AXIS_COLUMN[robot.data.get("head_axis", "x")]]
    assert head_axis @ direction == pytest.approx(1.0, abs=1e-9)


def test_joint_axes_alternate_between_yaw_and_pitch(robot):
    chain = full_chain(robot)
    q = np.zeros(chain.n_joints)
    axes = chain.jacobian(q)[3:].T  # angular rows: each joint's axis in the root's frame
    frames = chain.fk_all(q)
    body = frames[-1][:3, 3] - frames[0][:3, 3]
    body /= np.linalg.norm(body)
    assert np.abs(axes @ body).max() < 1e-9
    assert np.abs(np.sum(axes[:-1] * axes[1:], axis=1)).max() < 1e-9  # each at 90 deg to the last
    assert np.abs(np.abs(np.sum(axes[:-2] * axes[2:], axis=1)) - 1).max() < 1e-9
    revolute = np.isfinite(chain.upper)  # continuous joints have their limits in the robot file
    assert np.allclose(chain.upper[revolute], np.pi / 2) and np.allclose(chain.lower[revolute], -np.pi / 2)


def test_names_are_unique_and_bodies_have_mass_and_limits(robot):
    links = [link.get("name") for link in robot.tree.iter("link")]
    joints = [j.get("name") for j in robot.joints()]
    assert len(set(links)) == len(links) and len(set(joints)) == len(joints)
    for link in robot.tree.iter("link"):
        if link.find("collision") is None:
            assert link.find("visual") is None  # markers have no geometry at all
            continue
        inertial = link.find("inertial")
        assert inertial is not None, link.get("name")
        mass = float(inertial.find("mass").get("value"))
        inertia = [float(inertial.find("inertia").get(k)) for k in ("ixx", "iyy", "izz")]
        assert 0.005 < mass < 0.3 and min(inertia) > 0
        # A principal inertia is at most the sum of the other two (a real body).
        assert max(inertia) <= sum(inertia) - max(inertia) + 1e-15
    for joint in robot.joints():
        if joint.get("type") != "fixed":
            limit = joint.find("limit")
            assert float(limit.get("effort")) >= 10 and float(limit.get("velocity")) > 0


def test_module_mass_is_about_the_default_robots(robot):
    chain = full_chain(robot)
    assert 0.17 < chain.total_mass / (chain.n_joints + 1) < 0.23


# --- meshes ------------------------------------------------------------------------------------------------------
def resolve(robot: Robot, filename: str) -> Path:
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        return robot.folder / robot.data["packages"][package] / rest
    return robot.description.parent / filename


def mesh_elements(robot: Robot, kind: str) -> list[ET.Element]:
    return [m for link in robot.tree.iter("link") for el in link.iter(kind) for m in el.iter("mesh")]


def test_every_collision_mesh_exists_and_loads(robot):
    import trimesh

    meshes = mesh_elements(robot, "collision")
    assert bool(meshes) == (robot.style in COLLISION_MESH_STYLES)
    for mesh in meshes:
        path = resolve(robot, mesh.get("filename"))
        assert path.is_file(), path
        loaded = trimesh.load(path, force="mesh")
        scale = float(mesh.get("scale", "1 1 1").split()[0])
        size = loaded.extents * scale
        assert loaded.is_watertight and 0.02 < size.max() < 0.2, (path, size)


def test_published_shapes_of_each_style(robot):
    style = robot.style
    geometry = {el.tag for link in robot.tree.iter("link") for c in link.iter("collision") for el in c.find("geometry")}
    bodies = [link for link in robot.tree.iter("link") if link.find("collision") is not None]
    n = sum(PARTS[style])
    revolute_axes = {j.find("axis").get("xyz") for j in robot.joints() if j.get("type") != "fixed"}
    if style == "sea":
        first = robot.joints()[0]
        assert first.find("parent").get("link") == "kdl_dummy_root" and first.get("type") == "fixed"
        assert np.allclose([float(v) for v in first.find("origin").get("rpy").split()], [0, -np.pi / 2, 0])
        assert geometry == {"cylinder", "mesh"} and len(bodies) == 2 * n + 1 and len(revolute_axes) == 1
        radii = {float(c.get("radius")) for c in robot.tree.iter("cylinder")}
        assert np.allclose(sorted(radii), 0.026)
    elif style in ("reu", "xacro"):
        assert geometry == {"cylinder"} and len(bodies) == 3 * n + 1 and len(revolute_axes) == 2
    elif style == "rsnake":
        assert geometry == {"cylinder"} and {float(c.get("radius")) for c in robot.tree.iter("cylinder")} == {0.05}
        offsets = [c.find("origin").get("xyz") for link in bodies for c in link.iter("collision")]
        assert all(o != "0 0 0" for o in offsets)
        # Its visual meshes are named through a known package but are not there: only collisions may be needed.
        assert all(not resolve(robot, m.get("filename")).exists() for m in mesh_elements(robot, "visual"))
    elif style == "mesh":
        assert geometry == {"mesh"} and {j.get("type") for j in robot.joints()} == {"continuous", "fixed"}
        files = [m.get("filename") for m in mesh_elements(robot, "collision")]
        assert any(f.startswith("package://") for f in files) and any(not f.startswith("package://") for f in files)
        assert {Path(f).suffix for f in files} == {".STL", ".obj", ".dae"}
        stl = [resolve(robot, f).read_bytes()[:5] for f in files if f.endswith(".STL")]
        assert b"solid" in stl and any(head != b"solid" for head in stl)  # ASCII and binary STL
    elif style == "one_joint_neck":
        assert geometry == {"box"}
    elif style == "head6":
        head_link = robot.chain().link_names[-2]
        assert {el.tag for c in robot.tree.find(f"link[@name='{head_link}']").iter("collision")
                for el in c.find("geometry")} == {"sphere"}
        assert geometry == {"box", "sphere"}


# --- xacro -------------------------------------------------------------------------------------------------------
def test_the_xacro_snake_is_the_reu_snake(tmp_path):
    xacro_robot = Robot("xacro", write_robot("xacro", tmp_path / "xacro"))
    text = xacro_robot.description.read_text(encoding="utf-8")
    for feature in ('<xacro:macro name="module" params="i parent', "${pi/2}", "<xacro:property", "$(arg n_modules)"):
        assert feature in text
    n = xacro_robot.data["xacro_args"]["n_modules"]
    reu = Robot("reu", write_robot("reu", tmp_path / "reu", n_joints=n))
    names = {kind: [{e.get("name") for e in r.tree.iter(kind)} for r in (xacro_robot, reu)] for kind in ("link", "joint")}
    assert names["link"][0] == names["link"][1] and names["joint"][0] == names["joint"][1]
    chains = [r.chain() for r in (xacro_robot, reu)]
    assert chains[0].link_names == chains[1].link_names and chains[0].joint_names == chains[1].joint_names
    q = np.random.default_rng(0).uniform(chains[1].lower, chains[1].upper)
    assert np.allclose(chains[0].fk_all(q), chains[1].fk_all(q), atol=1e-12)
    assert chains[0].total_mass == pytest.approx(chains[1].total_mass, rel=1e-12)
    assert np.array_equal(chains[0].lower, chains[1].lower) and np.array_equal(chains[0].upper, chains[1].upper)


def test_the_xacro_args_set_the_module_count(tmp_path):
    robot = Robot("xacro", write_robot("xacro", tmp_path, n_joints=17))
    assert robot.chain().n_joints == 17 and robot.data["xacro_args"] == {"n_modules": 17}


# --- write_robot's arguments -------------------------------------------------------------------------------------
def test_overrides_change_the_numbers(tmp_path):
    robot = Robot("sea", write_robot("sea", tmp_path, n_joints=14, head_joints=6, module_length=0.07))
    assert robot.chain().n_joints == 14 and robot.chain(robot.data["neck_end"]).n_joints == 6
    frames = robot.chain().fk_all(np.zeros(14))
    assert np.linalg.norm(frames[-1][:3, 3]) == pytest.approx(0.07 / 2 + 14 * 0.07)


@pytest.mark.parametrize("style, overrides, error, match", [
    ("snake16", {}, InputError, "unknown style 'snake16'"), ("sea", {"joints": 3}, InputTypeError, "unknown override 'joints'"),
    ("sea", {"n_joints": 9}, InputError, r"n_joints \(9\) must exceed neck_joints \+ head_joints"),
    ("reu", {"module_length": float("nan")}, InputError, "module_length must be finite, got nan"),
    ("mesh", {"n_joints": True}, InputError, "n_joints must be a positive integer, got True"),
    ("rsnake", {"joint_limit_deg": 270}, InputError, "joint_limit_deg must be at most 180, got 270"),
    ("head6", {"effort": -1.0}, InputError, "effort must be positive, got -1.0"),
])
def test_bad_styles_and_overrides_are_refused(tmp_path, style, overrides, error, match):
    with pytest.raises(error, match=match):
        write_robot(style, tmp_path, **overrides)
    assert not any(tmp_path.iterdir())


def test_every_style_has_numbers():
    assert set(STYLES) == set(PARTS)
    for style in STYLES:
        spec = style_spec(style)
        assert isinstance(spec, StyleSpec) and (spec.base_joints, spec.neck_joints, spec.head_joints) == PARTS[style]
        assert 0.06 <= spec.module_length <= 0.09
