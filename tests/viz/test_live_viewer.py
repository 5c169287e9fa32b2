"""The live viewer (``snakehead view --live``) and the scene files it saves.

* Scene files written by :func:`snakehead.scenes.save_scene` read back as the same scene.
* The Python API of :class:`snakehead.viz.live.LiveViewer` (what a release of a gizmo does, without a mouse): one
  viewer for the module, planning short motions of the default robot.
* A real browser (Debian's headless Chromium, as ``tests/viz/test_viewer.py`` drives it): the page draws the robot,
  and moving a target through the API makes a new motion that reaches the page. The latency from the request to
  the browser showing the new motion is printed (measured, never asserted: speed is measured in
  ``bench/live_latency.py``).
"""
from __future__ import annotations

import dataclasses
import math
import time
from types import SimpleNamespace

import numpy as np
import pytest

from snakehead import BasePlacement, BoxObstacle, InputError, MeshObstacle, WallWithHole
from snakehead.app.cli import main
from snakehead.scenes import Scene, Target, load_scene, paper_scene, save_scene, scene_to_toml
from snakehead.viz.live import MOTION_WATCH_JS, LiveViewer
from snakehead.viz.live_nodes import wxyz_along, x_axis

#: Targets the default robot reaches with short plans (m, world), and one far above it that fails at once.
NEAR = ((0.10, 0.55, 0.32), (0.05, 0.50, 0.32), (0.08, 0.52, 0.30))
TOO_HIGH = (0.10, 0.50, 1.50)
FORWARD = (0.0, 1.0, 0.0)
TIMEOUT_S = 120.0


# ----------------------------------------------------------------------------------------------
# scene files
# ----------------------------------------------------------------------------------------------
def assert_same_scene(a: Scene, b: Scene) -> None:
    assert (a.name, a.description, a.base) == (b.name, b.description, b.base)
    assert [t.name for t in a.targets] == [t.name for t in b.targets]
    for s, t in zip(a.targets, b.targets):
        np.testing.assert_array_equal(s.position, t.position)  # written to the last digit
        np.testing.assert_array_equal(s.direction, t.direction)
        assert (s.hold_s, s.approach, s.step_m, s.via, s.sphere_diameter) == \
            (t.hold_s, t.approach, t.step_m, t.via, t.sphere_diameter)
    assert [type(o) for o in a.obstacles] == [type(o) for o in b.obstacles]
    for o, p in zip(a.obstacles, b.obstacles):
        for field in ("centre", "size", "rotation", "normal", "hole_diameter", "hole_offset", "pose", "scale"):
            if hasattr(o, field):
                np.testing.assert_allclose(getattr(o, field), getattr(p, field), atol=1e-12)
        if isinstance(o, MeshObstacle):  # the same hull (read from a copy when saved in another folder)
            np.testing.assert_array_equal(o.vertices, p.vertices)


@pytest.mark.parametrize("name", ["spheres", "hole"])
def test_the_paper_scenes_round_trip(tmp_path, name):
    scene = paper_scene(name)
    assert_same_scene(load_scene(save_scene(scene, tmp_path / "copy.toml")), scene)


def test_a_scene_of_every_kind_round_trips(tmp_path):
    import trimesh

    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=(0.2, 0.3, 0.25)).export(tmp_path / "meshes" / "rock.stl")
    out = tmp_path / "out" / "scene.toml"
    (out.parent / "robots").mkdir(parents=True)
    robot_file = out.parent / "robots" / "robot.toml"  # inside the folder saved in (a robot file is not copied)
    robot_file.write_text("")  # named, not read, by a scene file
    targets = (Target('a "quoted" \\ näme <b>', [0.1 / 3, 0.5, 0.3], [1.0, 2.0, 0.5], hold_s=1.5, sphere_diameter=0.04),
               Target("via", [0.2, 0.4, 0.4], [0, 1, 0], via=True),
               Target("line", [0.2, 0.5, 0.4], [0, 1, 0], approach="line", step_m=0.005))
    obstacles = (BoxObstacle.from_yaw([0.5, -0.2, 0.1], [0.2, 0.1, 0.2], yaw=0.7),
                 WallWithHole.standing([0.2, 0.5, 0.4], [0.6, 0.8, 0.0], [0.7, 0.58, 0.01], 0.07),
                 MeshObstacle.load(tmp_path / "meshes" / "rock.stl", [0.9, 0.3, 0.125], yaw=-0.4, scale=[1, 2, 1]))
    scene = Scene(name="every_kind", targets=targets, obstacles=obstacles, robot_file=robot_file,
                  base=BasePlacement(0.1, -0.2, 0.3), description="all of it: ünïcode, \\ and \t")
    text = save_scene(scene, out).read_text()
    # the robot file named where it is; the mesh copied beside the file (a scene file reads only its own folder's)
    assert 'robot = "robots/robot.toml"' in text and 'file = "rock.stl"' in text
    assert (out.parent / "rock.stl").read_bytes() == (tmp_path / "meshes" / "rock.stl").read_bytes()
    again = load_scene(out)
    assert_same_scene(again, scene)
    assert again.robot_file.resolve() == robot_file.resolve()
    assert again.obstacles[2].path.resolve() == (out.parent / "rock.stl").resolve()
    assert scene_to_toml(again, out.parent) == text  # and again the same text


def test_what_a_scene_file_cannot_say_is_an_input_error(tmp_path):
    target = (Target("t", [0.1, 0.5, 0.3], [0, 1, 0]),)
    tilted = BoxObstacle([0.5, 0, 0.1], [0.1, 0.1, 0.1], np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float))
    with pytest.raises(InputError, match=r"obstacles\[0\].*turned other than about the world z-axis"):
        scene_to_toml(Scene(name="s", targets=target, obstacles=(tilted,)))
    floating = WallWithHole([0.2, 0.5, 0.4], [0, 1, 0], [0.7, 0.58, 0.01], 0.07)  # its hole at its centre
    with pytest.raises(InputError, match="does not stand on the ground"):
        scene_to_toml(Scene(name="s", targets=target, obstacles=(floating,)))
    with pytest.raises(TypeError, match="scene must be a Scene"):
        save_scene("not a scene", tmp_path / "x.toml")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="cannot write"):
        save_scene(Scene(name="s", targets=target), tmp_path / "missing" / "x.toml")


# ----------------------------------------------------------------------------------------------
# the Python API
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def live(tmp_path_factory):
    scene = Scene(name="live_test", targets=(Target("target", NEAR[0], FORWARD, hold_s=1.0),))
    viewer = LiveViewer(scene, port=0, save_dir=tmp_path_factory.mktemp("live_saves"))
    try:
        viewer.wait_for_plan(TIMEOUT_S)
        yield viewer
    finally:
        viewer.close()


def test_the_first_plan_plays_the_scene_targets(live):
    first = live.records[0]
    assert first.playing is not None and first.failure is None and first.error is None
    motion = live.motion
    robot = live.robot
    K = len(robot.geometry.shapes)
    assert motion.positions.shape == (len(motion.times), K, 3) and motion.wxyz.shape == (len(motion.times), K, 4)
    # the frames are the plan's: its first and last samples by forward kinematics
    plan = live.latest
    for k, q in ((0, plan.q[0]), (-1, plan.q[-1])):
        frames = robot.frames(q, plan.base)
        B = frames[[s.frame for s in robot.geometry.shapes]] @ np.array([s.origin for s in robot.geometry.shapes])
        np.testing.assert_allclose(motion.positions[k], B[:, :3, 3], atol=1e-9)
    np.testing.assert_allclose(plan.targets[0].position, NEAR[0])
    assert "motion 0 playing" in live._shown.content


def test_moving_a_target_replans_and_plays_the_new_motion_on_the_same_nodes(live):
    nodes = live._nodes
    handles = [h for h, _ in nodes.robot.batches] + [nodes.tip_path, nodes.zmp_path, nodes.polygon]
    number = live.move_target(0, NEAR[1], FORWARD)
    record = live.wait_for_plan(TIMEOUT_S)
    assert record.number == number and record.playing is not None and record.failure is None
    assert record.released <= record.plan_started <= record.planned <= record.drawn <= record.playing
    assert 0 < record.planning_s < record.latency_s and record.overhead_s >= 0
    plan = live.latest
    np.testing.assert_allclose(plan.targets[0].position, NEAR[1])
    assert plan.targets[0].position_error_m < 1e-3
    # drawn by moving the nodes there were, none rebuilt
    assert live._nodes is nodes
    assert [h for h, _ in nodes.robot.batches] + [nodes.tip_path, nodes.zmp_path, nodes.polygon] == handles
    for _ in range(100):  # the paths follow the first frame (PATHS_DELAY_S)
        if np.allclose(nodes.tip_path.points, live.motion.tip_path, atol=1e-6):
            break
        time.sleep(0.05)
    np.testing.assert_allclose(nodes.tip_path.points, live.motion.tip_path, atol=1e-6)
    np.testing.assert_allclose(nodes.polygon.points, live.motion.polygon, atol=1e-6)
    np.testing.assert_allclose(live._gizmos.handles[0].position, NEAR[1])
    assert f"motion {number} playing" in live._shown.content


def test_a_new_release_supersedes_the_plan_running(live):
    first = live.move_target(0, NEAR[2], FORWARD)
    second = live.move_target(0, NEAR[0], FORWARD)
    record = live.wait_for_plan(TIMEOUT_S)
    assert record.number == second
    dropped = live.records[first]
    assert dropped.superseded and dropped.playing is None  # never drawn
    np.testing.assert_allclose(live.latest.targets[0].position, NEAR[0])
    assert live.motion.number == second


def test_releasing_a_gizmo_moves_its_target_to_its_pose(live):
    handle = live._gizmos.handles[0]
    direction = np.array([0.2, 1.0, 0.1]) / np.linalg.norm([0.2, 1.0, 0.1])
    handle._impl.position = np.array(NEAR[1])  # what viser does with a pose the browser sends
    handle._impl.wxyz = wxyz_along(direction)
    before = len(live.records)
    live._gizmos._released(SimpleNamespace(phase="update", target=handle))  # dragging: nothing yet
    assert len(live.records) == before
    live._gizmos._released(SimpleNamespace(phase="end", target=handle))
    record = live.wait_for_plan(TIMEOUT_S)
    assert record.number == before and record.what == "moved 'target'"
    np.testing.assert_allclose(live.targets[0].position, NEAR[1])
    np.testing.assert_allclose(live.targets[0].direction, direction, atol=1e-12)
    np.testing.assert_allclose(x_axis(wxyz_along(direction)), direction, atol=1e-12)


def test_targets_are_added_and_removed(live):
    live.move_target(0, NEAR[0], FORWARD)
    live.add_target()
    live.wait_for_plan(TIMEOUT_S)
    assert [t.name for t in live.targets] == ["target", "target 1"]
    assert [tg.name for tg in live.latest.targets] == ["target", "target 1"]
    assert len(live._gizmos.handles) == 2
    live.remove_target(1)
    live.wait_for_plan(TIMEOUT_S)
    assert [tg.name for tg in live.latest.targets] == ["target"] and len(live._gizmos.handles) == 1
    with pytest.raises(InputError, match="only target cannot be removed"):
        live.remove_target(0)
    with pytest.raises(InputError, match="no target 3"):
        live.move_target(3, NEAR[0])
    with pytest.raises(InputError, match="position"):
        live.move_target(0, [math.nan, 0.5, 0.3])
    with pytest.raises(TypeError, match="index"):
        live.move_target("0", NEAR[0])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="direction"):
        live.add_target(NEAR[1], [0, 0, 0])
    assert len(live.targets) == 1


def test_a_failed_plan_is_shown_with_its_reason(live):
    number = live.move_target(0, TOO_HIGH, FORWARD)
    record = live.wait_for_plan(TIMEOUT_S)
    assert record.number == number and "not solved" in record.failure
    assert "**Failed:**" in live._shown.content and "not solved" in live._shown.content
    live.move_target(0, NEAR[0], FORWARD)
    assert live.wait_for_plan(TIMEOUT_S).failure is None


def test_the_scene_is_saved_as_a_scene_file(live, tmp_path):
    path = live.save_scene(tmp_path / "live.toml")
    again = load_scene(path)
    assert_same_scene(again, live.scene())
    assert live.save_named("from the panel") == "from the panel.toml"  # what the panel's button does
    assert_same_scene(load_scene(live.saves.folder / "from the panel.toml"), live.scene())
    with pytest.raises(InputError, match="bare name"):
        live.save_named(str(tmp_path / "elsewhere.toml"))  # the page saves nowhere else
    assert not (tmp_path / "elsewhere.toml").exists()


def test_the_page_saves_a_scene_with_a_mesh_beside_a_copy_of_it(live, tmp_path, monkeypatch):
    """The page's save copies the scene's mesh files into the save folder (a scene file reads only its own folder's
    files), once: saved again, the same copy is named."""
    import trimesh

    trimesh.creation.box(extents=(0.2, 0.3, 0.25)).export(tmp_path / "boulder.stl")
    rock = MeshObstacle.load(tmp_path / "boulder.stl", [0.9, -0.6, 0.125])
    monkeypatch.setattr(live, "_scene", dataclasses.replace(live._scene, obstacles=(rock,)))
    for _ in range(2):
        assert live.save_named("with a mesh") == "with a mesh.toml"
    again = load_scene(live.saves.folder / "with a mesh.toml")
    assert_same_scene(again, live.scene())
    assert again.obstacles[0].path.resolve() == (live.saves.folder / "boulder.stl").resolve()
    assert sorted(p.name for p in live.saves.folder.glob("boulder*")) == ["boulder.stl"]


def test_the_mujoco_check_shows_its_errors_beside_the_plans(live):
    pytest.importorskip("mujoco")
    number = live.check_dynamics()
    check = live.wait_for_check(600)
    assert check.number == number and check.error is None
    # README: the plans run in MuJoCo land within 2 mm and 1 deg (measured here: 0.22 mm, 0.041 deg)
    assert check.simulation.position_error_m < 2e-3 and check.simulation.direction_error_deg < 1.0
    table = live._errors.content
    assert "| position error |" in table and "MuJoCo" in table and "| - |" not in table


def test_a_snake_unlike_the_default_one(tmp_path):
    """13 joints from a pitch joint, 10 cm modules, a one-joint neck, parts named by link frames (a coarse map)."""
    import snakehead
    from snakehead.kinematics import reachability as ws
    from snakehead.model.generate import SnakeSpec, snake_urdf
    from snakehead.model.robot_file import write_robot_file

    spec = SnakeSpec(n_joints=13, module_length=0.1, section=0.06, mass_per_module=0.3, first_axis="pitch",
                     link_prefix="seg", joint_prefix="j", tip_name="nose", name="pitchy")
    (tmp_path / "pitchy.urdf").write_text(snake_urdf(spec))
    robot_file = write_robot_file(tmp_path / "pitchy.toml", urdf=tmp_path / "pitchy.urdf", base_end="seg6",
                                  neck_end="seg7", head_tip="nose")
    robot = snakehead.SnakeRobot.from_file(robot_file)
    coarse = ws.compute(robot, progress=False, voxel=2 * ws.default_map_options(robot)["voxel"], directions=8,
                        rolls=1)
    controller = snakehead.HeadController(robot, coarse, method="free_roll", seed=1)
    with LiveViewer(controller=controller, robot_file=robot_file, port=0) as viewer:
        first = viewer.wait_for_plan(TIMEOUT_S)
        assert first.error is None and first.playing is not None
        head = robot.head_pose(controller.q_initial, controller.base)  # the one target: where the head starts
        np.testing.assert_allclose(viewer.targets[0].position, head[:3, 3])
        assert viewer.motion.positions.shape[1] == len(robot.geometry.shapes)
        viewer.move_target(0, head[:3, 3] - [0.0, 0.0, 0.03])
        moved = viewer.wait_for_plan(TIMEOUT_S)
        assert moved.error is None and moved.playing is not None, moved
        assert 'robot = "pitchy.toml"' in viewer.save_scene(tmp_path / "scene.toml").read_text()


def test_the_command_line_takes_a_folder_or_live(tmp_path, capsys):
    assert main(["view"]) == 2
    assert "give DIR" in capsys.readouterr().err
    assert main(["view", str(tmp_path), "--live"]) == 2
    assert main(["view", str(tmp_path), "--scene", "x.toml"]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text('[[targets]]\nname = "a"\nposition = [1, 2]\ndirection = [0, 1, 0]\n')
    assert main(["view", "--live", "--scene", str(bad)]) == 2
    assert "position must be a list of 3 numbers" in capsys.readouterr().err


# ----------------------------------------------------------------------------------------------
# a real browser
# ----------------------------------------------------------------------------------------------


def wait_in_page(driver, number: int, timeout: float = 60.0) -> dict:
    """When the page showed motion ``number`` ({"text": ms, "painted": ms})."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        entry = driver.execute_script(f"return (window.__motions || {{}})['{number}'] || null;")
        if entry and "painted" in entry:
            return entry
        time.sleep(0.02)
    raise AssertionError(f"the page did not show motion {number} within {timeout} s")


def test_the_page_draws_the_robot_and_a_moved_target_plays_there(live):
    from test_viewer import _chromium, _hue_mask, _screenshot  # the browser as tests/viz/test_viewer.py drives it

    from snakehead.viz.viewer import rgb255

    driver = _chromium()
    try:
        driver.get(live.url)  # with the session's token
        from selenium.webdriver.common.by import By
        from selenium.webdriver.support import expected_conditions as EC
        from selenium.webdriver.support.ui import WebDriverWait

        WebDriverWait(driver, 60).until(EC.presence_of_element_located((By.CSS_SELECTOR, "canvas")))
        WebDriverWait(driver, 60).until(lambda d: "playing" in d.find_element(By.TAG_NAME, "body").text)
        blue = 0
        for _ in range(60):  # the robot appears once the scene has arrived over the websocket and faded in
            time.sleep(1.0)
            blue = _hue_mask(_screenshot(driver), rgb255("#2e86c1")).sum()  # the head's blue
            if blue > 300:
                break
        assert blue > 300
        driver.execute_script(MOTION_WATCH_JS)
        latencies = []
        for position in (NEAR[1], NEAR[0]):
            number = live.move_target(0, position, FORWARD)
            record = live.wait_for_plan(TIMEOUT_S)
            assert record.number == number and record.playing is not None
            shown = wait_in_page(driver, number)
            assert shown["text"] / 1000 >= record.playing - 0.05  # (the clocks are the same machine's)
            latencies.append((record.planning_s, shown["painted"] / 1000 - record.released))
        for planning, total in latencies:
            print(f"release -> motion painted in the browser {total:.3f} s (planning {planning:.3f} s, the rest "
                  f"{total - planning:.3f} s)")
    finally:
        driver.quit()
