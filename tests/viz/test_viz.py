"""Figures and animations (snakehead.viz): the plotting convention, save(), the GIF's frames, and the figures of a
generated snake whose frames and parts are named unlike the default robot's."""
from __future__ import annotations

import os
import stat
import subprocess
import sys

import matplotlib.colors
import numpy as np
import pytest
from matplotlib.figure import Figure

from snakehead import BasePlacement, SnakeRobot
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.geometry.obstacles import BoxObstacle, WallWithHole
from snakehead.geometry.shapes import shape_mesh
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.planning.plan_result import Plan
from snakehead.viz import animation, body, save, viewer
from snakehead.viz import dynamics_figures as dynamics


@pytest.fixture(scope="module")
def snake(tmp_path_factory) -> SnakeRobot:
    """A 12-joint snake that starts with a pitch joint, with 7 cm modules, a 5 cm section and its own names."""
    spec = SnakeSpec(n_joints=12, module_length=0.07, section=0.05, mass_per_module=0.25, first_axis="pitch",
                     markers={"p0": 5, "b0": 7}, tip_name="nose", link_prefix="seg", joint_prefix="j")
    path = tmp_path_factory.mktemp("snake") / "snake12.urdf"
    path.write_text(snake_urdf(spec))
    return SnakeRobot.from_urdf(path, base_end="p0", neck_end="b0", head_tip="nose")


@pytest.fixture(scope="module")
def plan(snake) -> Plan:
    """A made-up 4 s motion of the snake (the base curls, the neck rises) wrapped as a Plan, with a wall and a box."""
    base = BasePlacement(0.1, -0.05, 0.3)
    t = np.linspace(0.0, 4.0, 401)
    q_end = np.zeros(snake.n_joints)
    yaw = np.array([k == "yaw" for k in snake.joint_kinds])
    q_end[snake.parts.base][yaw[snake.parts.base]] = 0.5
    neck = np.arange(snake.n_joints)[snake.parts.neck]
    q_end[neck[~yaw[neck]]] = -0.6  # the neck's pitch joint lifts neck and head
    s = 0.5 - 0.5 * np.cos(np.pi * t / t[-1])
    q = s[:, None] * q_end
    qd = np.gradient(q, t, axis=0)
    dyn = stability.dynamic_stability(snake, t, q, base, contact="ground")
    wall = WallWithHole.standing([0.6, 0.4, 0.3], [0.0, 1.0, 0.0], [0.5, 0.45, 0.01], 0.08)
    box = BoxObstacle.from_yaw([0.2, 0.45, 0.05], [0.1, 0.1, 0.1], 0.4)
    return Plan(name="made-up", robot=snake, base=base, t=t, q=q, qd=qd,
                states=[("lying", 0.0, q[0]), ("halfway", 2.0, q[200]), ("raised", 4.0, q[-1])], targets=[],
                stability=dyn, ground_clearance=coll.ground_clearance(snake, q, base)[:, snake.lifted_links].min(1),
                obstacles=[wall, box])


# ----------------------------------------------------------------------------------------------
# the convention
# ----------------------------------------------------------------------------------------------
def test_no_backend_is_chosen_at_import_or_when_drawing(tmp_path):
    """Importing snakehead.viz and making and saving a figure leave matplotlib's backend to the user."""
    code = ("import matplotlib, snakehead.viz, sys\n"
            "from snakehead.viz import animation, backbone_figures, body, dynamics_figures, viewer, reachability_figures\n"
            "from snakehead.viz import save\n"
            "save(backbone_figures.plot_area_vs_angle(), sys.argv[1])\n"
            "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'\n"
            "print(matplotlib.get_backend())\n")
    env = {**os.environ, "MPLBACKEND": "template"}
    run = subprocess.run([sys.executable, "-c", code, str(tmp_path / "a.png")], capture_output=True, text=True,
                         env=env)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "template"


def test_save_writes_by_suffix_atomically(tmp_path, monkeypatch):
    fig = Figure(figsize=(2, 2))
    fig.subplots().plot([0, 1], [1, 0])
    starts = {"png": b"\x89PNG", "pdf": b"%PDF", "svg": b"<?xml"}
    for suffix, magic in starts.items():
        p = save(fig, tmp_path / "sub" / f"f.{suffix}")  # missing folders are made
        assert p.read_bytes().startswith(magic)
    # files get the permissions open() would give them, not mkstemp's private ones
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE((tmp_path / "sub" / "f.png").stat().st_mode) == 0o666 & ~umask
    with pytest.raises(ValueError, match="suffix"):
        save(fig, tmp_path / "nosuffix")
    with pytest.raises(TypeError, match="Figure"):
        save("not a figure", tmp_path / "x.png")
    # a failure while writing leaves the old file as it was and no temporary file behind
    target = tmp_path / "kept.png"
    target.write_bytes(b"old")

    def broken(f, **kwargs):
        f.write(b"half a PNG")
        raise RuntimeError("disk full")

    monkeypatch.setattr(fig, "savefig", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        save(fig, target)
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.png", "sub"]


# ----------------------------------------------------------------------------------------------
# a generated snake: frames and parts named unlike the default robot's
# ----------------------------------------------------------------------------------------------
def test_body_geometry_of_a_generated_snake(snake, plan):
    colors = body.part_colors(snake)
    assert len(colors) == len(snake.link_names)
    for links, color in ((snake.base_links, "#7f8c8d"), (snake.neck_links, "#e67e22"),
                         (snake.head_links, "#2e86c1")):
        assert {colors[i] for i in links} == {color}
    F = snake.frames(plan.q[-1], plan.base)
    faces, face_colors = body.body_faces(snake, F)
    # a box is drawn as its six faces, each a quad
    assert all(s.kind == "box" for s in snake.geometry.shapes)
    assert len(faces) == 6 * len(snake.geometry.shapes) and len(face_colors) == len(faces)
    assert {len(f) for f in faces} == {4}
    # the faces' corners are the boxes' corners (the shapes' meshes, placed by their links' frames)
    corners = np.concatenate([shape_mesh(s)[0] @ F[s.frame, :3, :3].T + F[s.frame, :3, 3]
                              for s in snake.geometry.shapes])
    np.testing.assert_allclose(np.unique(np.concatenate(faces).round(12), axis=0),
                               np.unique(corners.round(12), axis=0), atol=1e-12)
    # points along the body: the root, each joint (its frame's origin) and the nose
    P = body.body_points(snake, F)
    assert P.shape == (snake.n_joints + 2, 3)
    np.testing.assert_allclose(P[1:-1], F[snake.joint_frames, :3, 3])
    np.testing.assert_allclose(P[-1], snake.head_pose(plan.q[-1], plan.base)[:3, 3])
    # consecutive joints are one module apart (the body's links are rigid)
    gaps = np.linalg.norm(np.diff(P[1:-1], axis=0), axis=1)
    np.testing.assert_allclose(gaps, 0.07, atol=1e-12)


def test_snapshots_draw_box_obstacles_and_target_arrows(plan):
    """A user's report: the snapshot figures drew neither box obstacles nor the targets' arrows. Every panel draws
    the box (its six faces) and one arrow per target, ending at the target."""
    from dataclasses import replace

    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from snakehead.planning.plan_result import TargetResult

    tip = plan.robot.head_pose(plan.q[-1], plan.base)
    targets = [TargetResult("reached", tip[:3, 3], tip[:3, 0], 4.0, None)]
    fig = body.plot_snapshots(replace(plan, targets=targets), columns=3)
    box = plan.obstacles[1]
    panels = [ax for ax in fig.axes if ax.name == "3d"]
    assert panels
    for ax in panels:
        polys = [c for c in ax.collections if isinstance(c, Poly3DCollection)]
        obstacle = matplotlib.colors.to_rgb(body.OBSTACLE_COLOR)
        assert any(len(c.get_facecolor()) == 6 and np.allclose(c.get_facecolor()[:, :3], obstacle) for c in polys), \
            "no box obstacle drawn"
        arrows = [c for c in ax.collections if isinstance(c, Line3DCollection)]
        assert len(arrows) == len(targets)
    np.testing.assert_allclose(np.unique(body.box_faces(box).reshape(-1, 3).round(12), axis=0),
                               np.unique((box.centre + (np.array([[x, y, z] for x in (-.5, .5) for y in (-.5, .5)
                                                                   for z in (-.5, .5)]) * box.size) @ box.rotation.T
                                          ).round(12), axis=0), atol=1e-12)


def test_wall_faces_tile_the_wall_minus_the_hole(plan):
    wall = plan.obstacles[0]
    quads = body.wall_faces(wall, n=256)

    def area(q):  # planar quads in the wall's plane: two triangles each
        a = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
        b = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 0])
        return 0.5 * (np.linalg.norm(a, axis=1) + np.linalg.norm(b, axis=1)).sum()

    expected = wall.size[0] * wall.size[1] - np.pi * (wall.hole_diameter / 2) ** 2
    assert area(quads) == pytest.approx(expected, rel=1e-3)
    # every corner lies in the wall's mid-plane
    np.testing.assert_allclose((quads.reshape(-1, 3) - wall.centre) @ wall.normal, 0.0, atol=1e-12)


def test_figures_of_a_generated_snake(plan, tmp_path):
    snaps = body.plot_snapshots(plan, columns=3)
    assert len([ax for ax in snaps.axes if ax.name == "3d"]) == len(body.snapshot_states(plan)) == 3
    zmp = dynamics.plot_zmp(plan.robot, plan.t, plan.q, base=plan.base, stability=plan.stability)
    # the planned ZMP scatter holds the plan's ZMP
    scatter = zmp.axes[0].collections[0]
    np.testing.assert_allclose(scatter.get_offsets(), plan.stability.zmp[::1])
    mom = dynamics.plot_momenta(plan.t, plan.stability.P, plan.stability.L, figures=(None, None))
    np.testing.assert_allclose(mom.axes[0].get_lines()[0].get_ydata(), plan.stability.L[:, 0])
    for name, fig in (("snapshots", snaps), ("zmp", zmp), ("momenta", mom)):
        assert save(fig, tmp_path / f"{name}.png").stat().st_size > 10_000


def test_the_gif_frames_are_full_redraws(plan, tmp_path):
    """Blitting draws each frame as a full draw of the figure would: compare with full draws of the same state."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    anim = animation.animate(plan, max_frames=4)
    frames = [np.asarray(im) for im in anim.images()]
    assert len(frames) == len(anim) == 4
    body_art, trace, clock = anim._artists
    robot = plan.robot
    tip = anim.frames[:, robot.link_index(robot.parts.head_tip), :3, 3]
    canvas = FigureCanvasAgg(anim.figure)
    for k in (0, 3):
        body_art.set_verts(body.body_faces(robot, anim.frames[k])[0])
        trace.set_data_3d(tip[: k + 1, 0], tip[: k + 1, 1], tip[: k + 1, 2])
        clock.set_text(animation.clock_time(anim.times[k]))  # the clock's time: its words are still
        canvas.draw()
        full = np.asarray(canvas.buffer_rgba())
        assert np.abs(full.astype(int) - frames[k]).max() <= 1, k
    assert np.abs(frames[0].astype(int) - frames[3]).sum(axis=2).astype(bool).mean() > 0.005  # the body moved
    p = save(anim, tmp_path / "made-up.gif")
    from PIL import Image

    with Image.open(p) as im:
        assert im.n_frames == 4 and im.size == (400, 320)
        written = []
        for k in range(4):
            im.seek(k)
            written.append(np.asarray(im.convert("RGB"), int))
    # one palette for all frames, each pixel its nearest colour: close to the drawing everywhere (the palette was
    # chosen from these frames): a mean error of a few levels of 255 (measured 2.4), no pixel far off
    error = np.abs(np.array(written) - np.array(frames)[..., :3])
    assert error.mean() < 4.0 and np.percentile(error, 99.9) < 40, (error.mean(), np.percentile(error, 99.9))
    with pytest.raises(ValueError, match="gif"):
        save(anim, tmp_path / "made-up.png")
    with pytest.raises(ValueError, match="fps"):
        animation.animate(plan, fps=0)
    with pytest.raises(ValueError, match="max_frames"):
        animation.animate(plan, max_frames=1)


def test_the_gif_clock_reads_as_one_centred_line(plan):
    """The clock is its still words and the time, drawn apart (only the time changes per frame): read left to
    right they are "NAME: t = 1.2 s  (x3.4 speed)", side by side without overlap, centred on the figure."""
    anim = animation.animate(plan, max_frames=4)
    list(anim.images())  # leaves the last frame's time
    fig = anim.figure
    renderer = fig.canvas.get_renderer()
    top = [t for t in fig.texts if t.get_text()]
    boxes = sorted(((t.get_window_extent(renderer), t.get_text()) for t in top), key=lambda b: b[0].x0)
    assert "".join(text for _, text in boxes) == (f"{plan.name}: t = {anim.times[-1]:.1f} s  "
                                                  f"(x{anim._speedup:.1f} speed)")
    for (a, _), (b, _) in zip(boxes, boxes[1:]):
        assert a.x1 <= b.x0 + 0.5 and abs(a.y1 - b.y1) < 1.0
    middle = 0.5 * (boxes[0][0].x0 + boxes[-1][0].x1)
    assert abs(middle - fig.bbox.width / 2) < 3.0  # pixels; the time's room is the longest time's


def test_viewer_scene_of_a_generated_snake(plan, tmp_path):
    data = viewer.viewer_scene(plan, frame_step_s=0.5)
    assert data.n_frames == 9 and data.times[0] == 0.0 and data.times[-1] == 4.0
    robot = plan.robot
    F = robot.frames_many(plan.q[[0, -1]], plan.base)
    shapes = robot.geometry.shapes
    B = F[:, [s.frame for s in shapes]] @ np.array([s.origin for s in shapes])  # the shapes' frames
    np.testing.assert_allclose(data.shape_positions[[0, -1]], B[..., :3, 3], atol=1e-12)
    # the quaternions turn the shapes like their rotation matrices
    from scipy.spatial.transform import Rotation

    w, xyz = data.shape_wxyz[-1][:, :1], data.shape_wxyz[-1][:, 1:]
    np.testing.assert_allclose(Rotation.from_quat(np.hstack([xyz, w])).as_matrix(), B[-1, :, :3, :3], atol=1e-12)
    # every box is the one unit cube, scaled by the box's size
    np.testing.assert_array_equal(data.shape_scales, [s.size for s in shapes])
    assert set(data.shape_mesh.tolist()) == {0} and len(data.mesh_vertex_starts) == 2
    np.testing.assert_allclose(np.abs(data.mesh_vertices), 0.5)
    assert len(data.voxel_centers) == 0  # no map given
    assert data.obstacle_centres.shape == (1, 3) and data.hole_rims.shape == (1, 65, 3)
    assert data.wall_triangles.max() < len(data.wall_vertices)
    # the map's frame is the head's base frame (neck_end = b0) at every frame
    np.testing.assert_allclose(data.map_frame_positions[-1], F[-1, robot.link_index("b0"), :3, 3], atol=1e-12)
    # the camera sees the whole scene: every shape's centre within the field of view
    eye, look_at = data.camera()
    d = data.shape_positions.reshape(-1, 3) - eye
    axis = (look_at - eye) / np.linalg.norm(look_at - eye)
    angle = np.degrees(np.arccos(d @ axis / np.linalg.norm(d, axis=1)))
    assert angle.max() < viewer.CAMERA_FOV_DEG / 2
    page = viewer.write_html(data, tmp_path / "made-up.html")
    assert page.read_text().count("__VISER_EMBED_DATA__") == 1
    with pytest.raises(ValueError, match="frame_step_s"):
        viewer.viewer_scene(plan, frame_step_s=0.0)
    with pytest.raises(ValueError, match="max_frames"):
        viewer.viewer_scene(plan, max_frames=1)


def test_viewer_refuses_a_map_of_another_head(plan):
    from snakehead import load_map

    m = load_map(SnakeRobot.default().map_path)
    with pytest.raises(ValueError, match="another head chain"):
        viewer.viewer_scene(plan, workspace_map=m)


@pytest.mark.parametrize("contact", ["ground", "endpoints"])
def test_distinct_support_polygons_are_the_samples_own_without_repeats(plan, contact):
    """The batch (one support_polygons call, deduplicated by rounded vertices) against the polygons computed sample
    by sample with support_polygon and compared by np.allclose: the same polygons, in the same order."""
    robot, q, base = plan.robot, plan.q, plan.base
    got = dynamics.distinct_support_polygons(robot, q, base, contact, samples=100)
    step = max(1, len(q) // 100)
    expected: list[np.ndarray] = []
    for k in range(0, len(q), step):
        poly = stability.support_polygon(robot, q[k], base, contact=contact)
        if not any(p.shape == poly.shape and np.allclose(p, poly, atol=1e-6) for p in expected):
            expected.append(poly)
    assert len(expected) > 1 if contact == "ground" else len(expected) >= 1  # the neck lifts off the ground
    assert len(got) == len(expected)
    for a, b in zip(got, expected):
        np.testing.assert_allclose(a, b, atol=1e-9)


def _ink_box(image: np.ndarray) -> tuple[int, int, int, int]:
    ink = (image[..., :3] != 255).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    return rows[0], rows[-1] + 1, cols[0], cols[-1] + 1


def _momenta_figure() -> Figure:
    t = np.linspace(0.0, 5.0, 500)
    P = np.column_stack([np.sin(t), np.cos(t), 0.01 * t])
    return dynamics.plot_momenta(t, P, 0.3 * P, title="a title wider than the panels' labels")


def test_save_draws_a_png_once_as_savefig_draws_it_twice(tmp_path, monkeypatch):
    """save() draws a PNG once and cuts it to the ink plus matplotlib's padding; savefig(bbox_inches="tight")
    draws it twice. The same picture: the same ink within a pixel of the same place, the same padding."""
    from matplotlib.image import imread

    draws = []
    original = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda self, renderer: draws.append(1) or original(self, renderer))
    ours = imread(save(_momenta_figure(), tmp_path / "ours.png"))
    assert len(draws) == 1
    draws.clear()
    _momenta_figure().savefig(tmp_path / "ref.png", dpi=150, bbox_inches="tight")
    assert len(draws) == 2
    ref = imread(tmp_path / "ref.png")
    ours, ref = (np.round(255 * im).astype(int) for im in (ours, ref))
    (a0, a1, b0, b1), (c0, c1, d0, d1) = _ink_box(ours), _ink_box(ref)
    assert abs((a1 - a0) - (c1 - c0)) <= 1 and abs((b1 - b0) - (d1 - d0)) <= 1  # the same ink, to a pixel
    pad = round(0.1 * 150)  # savefig.pad_inches at save()'s dpi
    assert (a0, b0, ours.shape[0] - a1, ours.shape[1] - b1) == (pad, pad, pad, pad)
    # savefig's: the artists' boxes, padded (a glyph's antialiased ink may reach a pixel or two past its box)
    assert min(c0, d0, ref.shape[0] - c1, ref.shape[1] - d1) >= pad - 2
    h, w = min(a1 - a0, c1 - c0), min(b1 - b0, d1 - d0)
    inked = ours[a0:a0 + h, b0:b0 + w, :3], ref[c0:c0 + h, d0:d0 + w, :3]
    assert np.mean(np.abs(inked[0] - inked[1]) > 64) < 0.02  # the same picture, up to sub-pixel placement


def test_save_falls_back_to_savefig_for_what_reaches_beyond_the_figure(tmp_path):
    """Text hanging over the figure's edge touches the canvas's edge: save() leaves it to savefig, whose tight box
    takes it in whole (the PNG is wider than the figure)."""
    from matplotlib.image import imread

    fig = _momenta_figure()
    fig.text(-0.05, 0.5, "beyond the left edge", fontsize=14)
    image = imread(save(fig, tmp_path / "over.png"))
    assert image.shape[1] > fig.get_figwidth() * 150


def test_save_snapshots_draws_plot_snapshots_picture(plan, tmp_path):
    """save_snapshots (one panel's still picture drawn once and copied, the states drawn per panel) writes the
    picture that save(plot_snapshots(...)) draws: the same size to a pixel, and the same pixels up to sub-pixel
    placement (the panels sit on whole pixels): under 2 % of them differ by more than a quarter of the range."""
    from matplotlib.image import imread

    scenery = [((0.3, 0.0, 0.25), 0.05)]
    fast = imread(body.save_snapshots(plan, tmp_path / "fast.png", spheres=scenery, n_panels=5, columns=3))
    full = imread(save(body.plot_snapshots(plan, spheres=scenery, n_panels=5, columns=3), tmp_path / "full.png"))
    assert abs(fast.shape[0] - full.shape[0]) <= 1 and abs(fast.shape[1] - full.shape[1]) <= 1
    h, w = min(fast.shape[0], full.shape[0]), min(fast.shape[1], full.shape[1])
    differ = np.abs(fast[:h, :w, :3] - full[:h, :w, :3]).max(axis=2) > 0.25
    assert differ.mean() < 0.02
    # every panel's body is there: the part colours cover as much of the picture in both
    for colour in (body.BASE_COLOR, body.NECK_COLOR, body.HEAD_COLOR):
        rgb = np.array(matplotlib.colors.to_rgb(colour))
        near = [np.abs(im[..., :3] - rgb).max(axis=2) < 0.08 for im in (fast, full)]
        assert near[1].sum() > 100 and abs(near[0].sum() - near[1].sum()) < 0.05 * near[1].sum()


def _panel_text_boxes(ax, renderer) -> list:
    """The boxes of what an axes writes around itself as drawn: each axis's tick labels, label and offset text (one
    box an axis), and its titles."""
    boxes = [axis.get_tightbbox(renderer) for axis in (ax.xaxis, ax.yaxis)]
    titles = [t for t in (ax.title, ax._left_title, ax._right_title) if t.get_visible() and t.get_text()]
    return [b for b in boxes if b is not None and b.width > 0] + [t.get_window_extent(renderer) for t in titles]


@pytest.mark.parametrize("kind, scale", [("momenta", 1.0), ("momenta", 1e4), ("momenta", 1e-5), ("zmp", 1.0)])
def test_the_dynamics_figures_fit_their_text(plan, kind, scale):
    """The momenta and ZMP figures are laid out at once (no tight_layout): at any magnitude every text lies on the
    figure, and no panel's text (tick labels, axis labels, titles) reaches into another panel or its text."""
    if kind == "momenta":
        P, L = scale * plan.stability.P, scale * plan.stability.L
        fig = dynamics.plot_momenta(plan.t, P, L, title="a title")
    else:
        fig = dynamics.plot_zmp(plan.robot, plan.t, plan.q, base=plan.base, stability=plan.stability)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    boxes = {ax: _panel_text_boxes(ax, renderer) for ax in fig.axes}
    assert sum(map(len, boxes.values())) >= 2 * len(fig.axes)
    for ax, own in boxes.items():
        for box in own:
            assert page.x0 <= box.x0 and box.x1 <= page.x1 and page.y0 <= box.y0 and box.y1 <= page.y1
        for other in fig.axes:
            if other is ax:
                continue
            frame = other.get_window_extent(renderer)
            for box in own:
                assert not box.overlaps(frame), (ax.get_title(), other.get_title())
                assert not any(box.overlaps(b) for b in boxes[other]), (ax.get_title(), other.get_title())
