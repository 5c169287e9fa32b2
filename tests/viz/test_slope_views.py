"""A plan on a slope in the figures and the viewers, in the world (and flat ground as before).

A plan on a slope holds everything in its ground frame (``plan.base.ground``); the views draw it in the world.
Checked against computations made here: the world pose of a link is ``G @ robot.frame(q, link, base)`` with G the
ground frame's pose built from the slope's normal (``plane_normal_deg``) and a point of the plane, never from the
views' own helpers; the drawn ground's normal is that normal; on flat ground nothing changes (no ground node, the
same viewer file format and fields as before slopes). The ROS bag's slope is in tests/app/test_ros_bag_slope.py.

One target is planned on a 17 degree slope (roll 8, pitch 15, the plane 0.1 m above the origin) and once on flat
ground for the module (a few seconds each).
"""
from __future__ import annotations

import dataclasses
import re
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import snakehead
from snakehead import BasePlacement
from snakehead.model.placement import GroundFrame
from snakehead.terrain.surfaces import HeightfieldTerrain, MeshTerrain, StepsTerrain, plane_normal_deg
from snakehead.viz import animation, body, viewer
from snakehead.viz.figure_geometry import scene_bounds, terrain_mesh
from snakehead.viz.figure_style import ground_patch

TARGET = ((0.1, 0.5, 0.35), (0.0, 1.0, 0.0))
ROLL_DEG, PITCH_DEG = 8.0, 15.0
PLANE_POINT = np.array([0.0, 0.0, 0.1])


def normal() -> np.ndarray:
    """The slope's upward unit normal in the world, from its definition: Ry(pitch) Rx(roll) e_z."""
    r, p = np.radians(ROLL_DEG), np.radians(PITCH_DEG)
    Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    return Ry @ Rx @ np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def ground() -> GroundFrame:
    g = GroundFrame.of_plane(plane_normal_deg(ROLL_DEG, PITCH_DEG), PLANE_POINT)
    G = g.matrix
    # the frame is what it says, checked here once: z the slope's normal, its origin on the plane
    np.testing.assert_allclose(G[:3, 2], normal(), atol=1e-12)
    assert abs(normal() @ (G[:3, 3] - PLANE_POINT)) < 1e-12
    np.testing.assert_allclose(G[:3, :3].T @ G[:3, :3], np.eye(3), atol=1e-12)
    return g


@pytest.fixture(scope="module")
def plan(ground):
    p = snakehead.plan([TARGET], base=BasePlacement(0.05, -0.02, 0.3, ground=ground))
    assert p.success, p.failure  # (the target is reachable on the slope: it lies in the ground frame)
    assert p.base.ground == ground
    return p


@pytest.fixture(scope="module")
def flat_plan():
    p = snakehead.plan([TARGET])
    assert p.success, p.failure
    return p


def world(ground: GroundFrame, T: np.ndarray) -> np.ndarray:
    """Ground-frame poses (..., 4, 4) in the world, by the ground frame's matrix."""
    return ground.matrix @ T


def world_points(ground: GroundFrame, p: np.ndarray) -> np.ndarray:
    G = ground.matrix
    return np.asarray(p, float) @ G[:3, :3].T + G[:3, 3]


def height_on_plane(p: np.ndarray) -> np.ndarray:
    """Signed distance (m) of world points (..., 3) to the slope's plane (> 0 above)."""
    return (np.asarray(p, float) - PLANE_POINT) @ normal()


# ------------------------------------------------------------------------------------------------
# the viewer's arrays and file
# ------------------------------------------------------------------------------------------------
def test_the_viewer_scene_puts_the_body_and_targets_in_the_world(plan, ground):
    data = viewer.viewer_scene(plan)
    robot = plan.robot
    np.testing.assert_array_equal(data.ground_pose, ground.matrix)
    assert not data.on_flat_ground and not data.flat
    idx = viewer.frame_indices(np.asarray(plan.t), viewer.FRAME_STEP_S, 2000)
    for j in np.linspace(0, len(idx) - 1, 6).astype(int):
        q = plan.q[idx[j]]
        tip = world(ground, robot.frame(q, robot.parts.head_tip, plan.base))
        np.testing.assert_allclose(data.to_world(data.head_tip[j]), tip[:3, 3], atol=1e-12)
        shapes = robot.geometry.shapes
        B = world(ground, robot.frames(q, plan.base)[[s.frame for s in shapes]] @ np.array([s.origin for s in shapes]))
        np.testing.assert_allclose(data.to_world(data.shape_positions[j]), B[:, :3, 3], atol=1e-12)
        # the base lies on the slope: its lowest shape points touch the plane (within the planner's tolerance)
        lowest, _ = robot.lowest_points(world(ground, robot.frames(q, plan.base))[None])
        assert height_on_plane(lowest.reshape(-1, 3)).min() == pytest.approx(0.0, abs=2e-3)
    # the head reaches the target: in the world, the target turned by the ground frame
    np.testing.assert_allclose(data.to_world(data.head_tip[-1]), world_points(ground, TARGET[0]), atol=1e-4)
    np.testing.assert_allclose(data.to_world(data.target_positions), world_points(ground, [TARGET[0]]), atol=1e-12)
    # the camera sees the world: the box holds the world's head tip path
    lo, hi = data.bounds()
    tips = data.to_world(data.head_tip)
    assert np.all(tips >= lo) and np.all(tips <= hi)
    # the CoM's mark is below the CoM along gravity: (mark - com) in the world is parallel to world z
    marks = np.column_stack([data.com_marks(), np.zeros(data.n_frames)])
    d = data.to_world(data.com) - data.to_world(marks)
    np.testing.assert_allclose(d[:, :2], 0.0, atol=1e-12)
    assert np.all(d[:, 2] > 0)


def test_a_slope_scene_file_is_format_3_and_reads_back(plan, ground, tmp_path):
    data = viewer.viewer_scene(plan)
    path = viewer.save_viewer_scene(data, tmp_path / f"slope{viewer.SCENE_SUFFIX}")
    with np.load(path) as f:
        assert int(f["format"]) == viewer.SCENE_FORMAT == 3
        arrays = dict(f)
    back = viewer.load_viewer_scene(path)
    np.testing.assert_array_equal(back.ground_pose, ground.matrix)
    np.testing.assert_array_equal(back.head_tip, data.head_tip)
    arrays["ground_pose"] = np.diag([1.0, 2.0, 1.0, 1.0])  # not a rotation
    np.savez(tmp_path / f"bad{viewer.SCENE_SUFFIX}", **arrays)
    with pytest.raises(ValueError, match="ground_pose must be a rigid transform"):
        viewer.load_viewer_scene(tmp_path / f"bad{viewer.SCENE_SUFFIX}")
    del arrays["ground_pose"]
    np.savez(tmp_path / f"missing{viewer.SCENE_SUFFIX}", **arrays)
    with pytest.raises(ValueError, match="without .*ground_pose"):
        viewer.load_viewer_scene(tmp_path / f"missing{viewer.SCENE_SUFFIX}")


def test_flat_ground_is_drawn_as_before(flat_plan, tmp_path):
    """The ground frame of flat ground is the world's: the viewer file is format 2 with the fields it had before
    slopes, the scene's bounds are its ground frame's, and an explicit world frame changes nothing."""
    data = viewer.viewer_scene(flat_plan)
    assert data.on_flat_ground and data.flat
    np.testing.assert_array_equal(data.ground_pose, np.eye(4))
    assert data.to_world(data.head_tip) is data.head_tip and data.com_marks() is not None
    np.testing.assert_array_equal(data.com_marks(), data.com[:, :2])
    for a, b in zip(data.bounds(), data.ground_bounds()):
        np.testing.assert_array_equal(a, b)
    path = viewer.save_viewer_scene(data, tmp_path / f"flat{viewer.SCENE_SUFFIX}")
    with np.load(path) as f:
        assert int(f["format"]) == viewer.FLAT_SCENE_FORMAT == 2
        assert set(f.files) == {f.name for f in dataclasses.fields(viewer.ViewerScene)} - set(viewer.GROUND_FIELDS) \
            | {"format"}
    back = viewer.load_viewer_scene(path)
    np.testing.assert_array_equal(back.ground_pose, np.eye(4))
    assert len(back.terrain_triangles) == 0
    # the same plan with the world frame given explicitly (the plane z = 0): the same arrays
    explicit = BasePlacement(flat_plan.base.x, flat_plan.base.y, flat_plan.base.yaw,
                             ground=GroundFrame.of_plane((0.0, 0.0, 1.0), (0.3, -0.2, 0.0)))
    assert explicit.ground.is_world
    again = viewer.viewer_scene(dataclasses.replace(flat_plan, base=explicit))
    for field in dataclasses.fields(viewer.ViewerScene):
        np.testing.assert_array_equal(getattr(again, field.name), getattr(data, field.name))


# ------------------------------------------------------------------------------------------------
# the viewer's nodes in a viser scene
# ------------------------------------------------------------------------------------------------
class Recorder:
    """A viser scene API that records the name, the keyword arguments and the handle of every node added."""

    def __init__(self, scene_api) -> None:
        self.scene_api = scene_api
        self.added: dict[str, SimpleNamespace] = {}

    def __getattr__(self, name: str):
        method = getattr(self.scene_api, name)
        if not name.startswith("add_"):
            return method

        def add(node: str, *args, **kwargs):
            handle = method(node, *args, **kwargs)
            self.added[node] = SimpleNamespace(kind=name, kwargs=kwargs, handle=handle)
            return handle
        return add


@pytest.fixture(scope="module")
def server():
    from snakehead.viz.server_guard import ServerGuard, guarded_server

    s = guarded_server(ServerGuard(), "127.0.0.1", 0)
    yield s
    s.stop()


def rotation(wxyz) -> np.ndarray:
    w, x, y, z = np.asarray(wxyz, float)
    return Rotation.from_quat([x, y, z, w]).as_matrix()


def test_the_viewer_draws_everything_under_one_node_at_the_ground_frame(plan, ground, server):
    from snakehead.viz.viewer_nodes import SceneNodes

    data = viewer.viewer_scene(plan)
    server.scene.reset()
    rec = Recorder(server.scene)
    nodes = SceneNodes(rec, data)
    names = list(rec.added)
    assert names[0] == "/snakehead" and rec.added["/snakehead"].kind == "add_frame"  # the parent, added first
    assert all(n.startswith("/snakehead/") for n in names[1:])  # everything else beneath it
    root = nodes.ground_frame
    np.testing.assert_allclose(root.position, ground.matrix[:3, 3], atol=1e-12)
    np.testing.assert_allclose(rotation(root.wxyz), ground.matrix[:3, :3], atol=1e-12)
    # the ground grid lies in the root's xy plane: its world normal is the slope's
    grid = rec.added["/snakehead/ground"]
    assert grid.kind == "add_grid" and grid.kwargs["plane"] == "xy" and grid.kwargs["position"][2] == 0.0
    np.testing.assert_allclose(rotation(root.wxyz) @ rotation(grid.handle.wxyz) @ [0, 0, 1], normal(), atol=1e-12)
    # the robot's shapes at the last frame, composed with the root's pose, are where FK puts them in the world
    nodes.show_frame(data.n_frames - 1)
    q = plan.q[-1]
    head = plan.robot.geometry.shapes[-1]
    k = len(plan.robot.geometry.shapes) - 1
    expected = world(ground, plan.robot.frames(q, plan.base)[head.frame] @ head.origin)[:3, 3]
    batches = nodes.robot_nodes.batches
    handle, which = next((h, w) for h, w in batches if k in w)
    local = np.asarray(handle.batched_positions)[list(which).index(k)]
    np.testing.assert_allclose(rotation(root.wxyz) @ local + root.position, expected, atol=1e-6)  # (float32)


def test_on_flat_ground_no_ground_node_is_added(flat_plan, server):
    from snakehead.viz.viewer_nodes import SceneNodes

    server.scene.reset()
    rec = Recorder(server.scene)
    SceneNodes(rec, viewer.viewer_scene(flat_plan))
    assert "/snakehead" not in rec.added and not any(" terrain" in n for n in rec.added)


# ------------------------------------------------------------------------------------------------
# terrain (a heightfield, a mesh, a staircase) as triangles
# ------------------------------------------------------------------------------------------------
def test_a_heightfield_is_drawn_on_its_own_surface():
    rng = np.random.default_rng(4)
    hf = HeightfieldTerrain(rng.uniform(-0.05, 0.05, (300, 7)), (3.0, 0.6), (-1.0, -0.3, 0.02))
    v, tri = terrain_mesh(hf)
    # 300 rows are more than TERRAIN_DRAW_SIDE (129): every 3rd (0 .. 297) is kept, and the last (299); all 7 columns
    assert len(v) == 101 * 7 and tri.max() < len(v) and len(tri) == 2 * 100 * 6
    np.testing.assert_allclose([v[:, 0].min(), v[:, 0].max(), v[:, 1].min(), v[:, 1].max()], [-1.0, 2.0, -0.3, 0.3])
    np.testing.assert_allclose(v[:, 2], hf.height(v[:, :2]), atol=1e-12)  # the vertices are grid heights
    small = HeightfieldTerrain(rng.uniform(-0.05, 0.05, (9, 7)), (1.0, 0.6), (-0.5, -0.3, 0.0))
    v, tri = terrain_mesh(small)
    centroids = v[tri].mean(axis=1)  # inside each triangle: on the surface the queries answer for (its diagonals)
    np.testing.assert_allclose(centroids[:, 2], small.height(centroids[:, :2]), atol=1e-12)
    n = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
    assert np.all(n[:, 2] > 0)  # counter-clockwise from above
    steps = StepsTerrain(0.05, 0.2, count=3)
    v, tri = terrain_mesh(steps)
    np.testing.assert_array_equal(v, steps.triangles()[0])
    mesh = MeshTerrain(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.1]], float), np.array([[0, 1, 2]]))
    v, tri = terrain_mesh(mesh)
    np.testing.assert_array_equal(tri, [[0, 1, 2]])
    for flat in (None, snakehead.terrain.surfaces.FlatGround(),
                 snakehead.terrain.surfaces.PlaneTerrain.from_roll_pitch(ROLL_DEG, PITCH_DEG)):
        assert terrain_mesh(flat)[1].shape == (0, 3)


def test_a_scene_terrain_is_drawn_in_the_world_beside_the_ground_frame(flat_plan, server, tmp_path):
    from snakehead.viz.viewer_nodes import SceneNodes

    steps = StepsTerrain(0.05, 0.2, count=3, start=(0.8, 0.0, 0.0))
    terrain_plan = dataclasses.replace(flat_plan, scene=dataclasses.replace(flat_plan.scene, terrain=steps))
    data = viewer.viewer_scene(terrain_plan)
    np.testing.assert_array_equal(data.terrain_vertices, steps.triangles()[0])
    assert not data.flat
    back = viewer.load_viewer_scene(viewer.save_viewer_scene(data, tmp_path / f"steps{viewer.SCENE_SUFFIX}"))
    np.testing.assert_array_equal(back.terrain_triangles, data.terrain_triangles)
    server.scene.reset()
    rec = Recorder(server.scene)
    SceneNodes(rec, back)
    assert rec.added["/snakehead terrain"].kind == "add_mesh_simple"  # in the world, not under /snakehead
    fig = body.plot_snapshots(terrain_plan, n_panels=2)  # the figures draw it too
    assert fig is not None


# ------------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------------
def test_the_animation_draws_the_world_frames_and_names_the_slope(plan, ground):
    anim = animation.animate(plan, max_frames=6)
    robot = plan.robot
    idx = np.unique(np.linspace(0, len(plan.t) - 1, 6).round().astype(int))
    for k, i in enumerate(idx):
        np.testing.assert_allclose(anim.frames[k], world(ground, robot.frames(plan.q[i], plan.base)), atol=1e-12)
    text = " ".join(t.get_text() for t in anim.figure.texts)
    assert f"{ground.slope_deg:.1f}\N{DEGREE SIGN} slope" in text
    assert ground.slope_deg == pytest.approx(np.degrees(np.arccos(normal()[2])))
    # the drawn ground is the slope: its corners lie on the plane, and the axes hold them
    ax = anim.figure.axes[0]
    lo = np.array([ax.get_xlim()[0], ax.get_ylim()[0], ax.get_zlim()[0]])
    hi = np.array([ax.get_xlim()[1], ax.get_ylim()[1], ax.get_zlim()[1]])
    X, Y, Z = ground_patch(ground, lo, hi)
    corners = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    np.testing.assert_allclose(height_on_plane(corners), 0.0, atol=1e-12)
    assert Z.min() >= lo[2] - 1e-12 and Z.max() <= hi[2] + 1e-12
    images = list(anim.images())
    assert len(images) == len(idx)


def test_the_snapshots_on_a_slope(plan, ground, tmp_path, monkeypatch):
    drawn = []
    draw_body = body.draw_body
    monkeypatch.setattr(body, "draw_body", lambda ax, robot, frames, *a: drawn.append(frames) or draw_body(ax, robot,
                                                                                                    frames, *a))
    fig = body.plot_snapshots(plan, n_panels=4)
    legend = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    assert f"ground: {ground.slope_deg:.1f}\N{DEGREE SIGN} slope" in legend
    # each panel's body is drawn at the world's frames of its state
    states = body.snapshot_states(plan, 4)
    assert len(drawn) == len(states)
    for frames, (_, _, q) in zip(drawn, states):
        np.testing.assert_allclose(frames, world(ground, plan.robot.frames(q, plan.base)), atol=1e-12)
    # the box the panels show holds the body in the world
    lo, hi = scene_bounds(plan)
    tips = world(ground, plan.robot.frames_many(plan.q[::200], plan.base))[..., :3, 3].reshape(-1, 3)
    assert np.all(tips >= lo) and np.all(tips <= hi)
    drawn.clear()
    path = body.save_snapshots(plan, tmp_path / "snapshots.png", n_panels=4)
    assert path.stat().st_size > 10_000 and len(drawn) == len(states)
    np.testing.assert_allclose(drawn[-1], world(ground, plan.robot.frames(states[-1][2], plan.base)), atol=1e-12)


def test_flat_figures_name_no_slope(flat_plan):
    anim = animation.animate(flat_plan, max_frames=4)
    idx = np.unique(np.linspace(0, len(flat_plan.t) - 1, 4).round().astype(int))
    np.testing.assert_array_equal(anim.frames, flat_plan.robot.frames_many(flat_plan.q[idx], flat_plan.base))
    assert not any("slope" in t.get_text() for t in anim.figure.texts)
    fig = body.plot_snapshots(flat_plan, n_panels=2)
    assert not any("slope" in t.get_text() for lg in fig.legends for t in lg.get_texts())


def test_the_zmp_figure_names_the_ground_plane(plan, ground):
    from snakehead.viz.dynamics_figures import plot_zmp

    fig = plot_zmp(plan.robot, plan.t, plan.q, base=plan.base, stability=plan.stability)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x in the ground plane (m)"
    assert re.search(r"on a 17\.0. slope", ax.get_title())


# ------------------------------------------------------------------------------------------------
# the live viewer
# ------------------------------------------------------------------------------------------------
def test_the_live_viewer_draws_a_slope_under_its_ground_node(ground, tmp_path):
    """The live viewer's root node holds the ground frame's pose: the gizmos, the robot and the ground grid are in
    the ground frame under it, so a gizmo's pose (which a browser sends in its parent's frame) is a target's pose
    in the ground frame, as the planner takes it."""
    from snakehead.scenes import Scene, Target
    from snakehead.viz.live import LiveViewer
    from snakehead.viz.live_nodes import ROOT

    base = BasePlacement(0.0, 0.0, 0.0, ground=ground)
    scene = Scene(name="slope", targets=(Target("target", TARGET[0], TARGET[1], hold_s=1.0),), base=base)
    with LiveViewer(scene, port=0, save_dir=tmp_path) as live:
        record = live.wait_for_plan(120.0)
        assert record.error is None and record.failure is None, (record.error, record.failure)
        root = live._root.handle
        assert root.name == ROOT
        np.testing.assert_allclose(root.position, ground.matrix[:3, 3], atol=1e-12)
        np.testing.assert_allclose(rotation(root.wxyz), ground.matrix[:3, :3], atol=1e-12)
        plan = live.latest
        assert plan.base.ground == ground
        # the head at the end of the motion, drawn under the root: in the world where FK on the slope puts it
        tip = world(ground, plan.robot.frame(plan.q[-1], plan.robot.parts.head_tip, plan.base))
        np.testing.assert_allclose(rotation(root.wxyz) @ plan.targets[0].position + root.position, tip[:3, 3],
                                   atol=1e-4)
        # a gizmo's pose is the target's in the ground frame
        np.testing.assert_allclose(live._gizmos.handles[0].position, TARGET[0], atol=1e-12)
        # moving the root to another ground frame and back (a plan on another ground) moves the node
        live._root.place(GroundFrame())
        np.testing.assert_allclose(root.position, 0.0, atol=1e-12)
        live._root.place(ground)
        np.testing.assert_allclose(root.position, ground.matrix[:3, 3], atol=1e-12)


# ------------------------------------------------------------------------------------------------
# the page in a real browser (as tests/viz/test_viewer.py drives it; skipped without Chromium)
# ------------------------------------------------------------------------------------------------
def test_the_page_shows_the_robot_on_the_slope_in_the_world(plan, tmp_path):
    """The browser applies the ground node's pose: the robot's shapes are seen where their world positions project
    with the page's camera, not where their ground-frame positions would."""
    from test_viewer import _canvas_rect, _chromium, _pause, _robot_seen, _settled_screenshot, _wait_for_page

    data = viewer.viewer_scene(plan)
    page = viewer.write_html(data, tmp_path / "slope.html")
    in_world = dataclasses.replace(data, shape_positions=data.to_world(data.shape_positions))
    in_world.camera = data.camera  # the page's camera (its bounds are the world's already)
    driver = _chromium()
    try:
        driver.get(page.resolve().as_uri())
        slider = _wait_for_page(driver)
        t_shown = _pause(driver, slider)
        times = data.times - data.times[0]
        k = int(np.searchsorted(times, t_shown + 0.05, side="right") - 1)
        img = _settled_screenshot(driver)
        rect = _canvas_rect(driver)
        seen_world, mask = _robot_seen(img, in_world, k, rect)
        seen_ground, _ = _robot_seen(img, data, k, rect)  # (the camera is the same: data.camera() is the world's)
    finally:
        driver.quit()
    from PIL import Image

    Image.fromarray(img).save(tmp_path / "slope.png")  # kept by pytest's tmp_path for a look on failure
    assert seen_world >= 0.75 and mask.sum() > 300, (k, seen_world, tmp_path)
    assert seen_ground < seen_world - 0.25, (seen_ground, seen_world, tmp_path)
