"""The 3-D viewer: the scene data the pipeline writes, and the standalone page in a real browser.

The browser tests drive Debian's headless Chromium (``chromium``, ``chromedriver``; installed by .ci/setup) with
Selenium; WebGL runs on SwiftShader (``--use-angle=swiftshader``). They check what a person would see: the
robot's links where the camera model puts them (pixels of the links' colours at the projected shape centres), and
the robot somewhere else after the time slider is moved. Locally, without Chromium, they are skipped; under CI
(``CI`` set) a missing browser is a failure.
"""
from __future__ import annotations

import colorsys
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from snakehead.viz import viewer

POSITION = ("0.05", "0.55", "0.30")
DIRECTION = ("0", "1", "0")


# ----------------------------------------------------------------------------------------------
# the pipeline's output: one target planned with the CLI (no simulation, quick timing)
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def planned(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("viewer")
    run = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--position", *POSITION, "--direction",
                          *DIRECTION, "--out", str(out), "--no-sim", "--fast"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    return out


@pytest.fixture(scope="module")
def scene(planned) -> viewer.ViewerScene:
    return viewer.load_viewer_scene(planned / f"target{viewer.SCENE_SUFFIX}")


def test_the_pipeline_writes_the_viewer_scene_and_page(planned, scene):
    from snakehead import SnakeRobot, load_map

    robot = SnakeRobot.default()
    assert (planned / "target.html").stat().st_size > 500_000  # viser's client with the recording inside
    page = (planned / "target.html").read_text()
    assert "__VISER_EMBED_DATA__" in page and "<title>snakehead:" in page
    # nothing fetched at run time: no URL the page would load (links in the client's about box aside)
    assert "src=\"http" not in page and "href=\"http" not in page.split("</head>")[0]
    F = scene.n_frames
    K = len(robot.geometry.shapes)
    assert scene.shape_positions.shape == (F, K, 3) and scene.shape_wxyz.shape == (F, K, 4)
    np.testing.assert_allclose(np.linalg.norm(scene.shape_wxyz, axis=-1), 1.0, atol=1e-9)
    assert np.all(np.diff(scene.times) > 0) and F >= 10
    # the frames are the plan's: the last one is the head at the target (planned to the micrometre)
    np.testing.assert_allclose(scene.head_tip[-1], np.array(POSITION, float), atol=1e-4)
    # the boxes' centres at the first frame are the robot's, by forward kinematics of the CSV's first row
    q0 = np.loadtxt(planned / "target_trajectory.csv", delimiter=",", skiprows=1, max_rows=1)[1:]
    base = scene_base(planned)
    shapes = robot.geometry.shapes
    B = robot.frames(q0, base)[[s.frame for s in shapes]] @ np.array([s.origin for s in shapes])
    np.testing.assert_allclose(scene.shape_positions[0], B[:, :3, 3], atol=1e-6)  # the CSV rounds
    # the map is the robot's head map, in the head's base frame (neck_end), which moves with the neck
    m = load_map(robot.map_path)
    assert len(scene.voxel_centers) == len(m) and scene.voxel_size == m.voxel_size
    np.testing.assert_allclose(scene.map_frame_positions[0], robot.frame(q0, robot.parts.neck_end, base)[:3, 3],
                               atol=1e-6)
    # every frame stands on one of the support polygons
    assert scene.polygon_of_frame.min() >= 0 and scene.polygon_of_frame.max() < len(scene.polygons)


def scene_base(out: Path):
    import json

    from snakehead import BasePlacement

    report = json.loads((out / "report.json").read_text())
    b = report["scenarios"]["target"]["base"]
    return BasePlacement(b["x_m"], b["y_m"], b["yaw_rad"])


def test_viewer_scene_round_trip_and_bad_files(tmp_path, scene):
    path = viewer.save_viewer_scene(scene, tmp_path / f"copy{viewer.SCENE_SUFFIX}")
    again = viewer.load_viewer_scene(path)
    for name in ("times", "shape_positions", "voxel_indices", "polygons", "target_names"):
        np.testing.assert_array_equal(getattr(again, name), getattr(scene, name))
    assert again.name == scene.name and again.voxel_size == scene.voxel_size
    bad = tmp_path / f"bad{viewer.SCENE_SUFFIX}"
    bad.write_text("not a zip")
    with pytest.raises(ValueError, match="viewer scene .* is not a .npz archive"):
        viewer.load_viewer_scene(bad)
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(ValueError, match="format"):
        viewer.load_viewer_scene(tmp_path / "other.npz")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no viewer scenes"):
        viewer.serve(tmp_path / "empty")
    with pytest.raises(ValueError, match="not a directory"):
        viewer.serve(tmp_path / "missing")


# ----------------------------------------------------------------------------------------------
# a real browser
# ----------------------------------------------------------------------------------------------
def _chromium():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if chromium is None or driver is None:
        if os.environ.get("CI"):
            pytest.fail("Chromium and chromedriver are missing (bash .ci/setup installs Debian's chromium and "
                        "chromium-driver)")
        pytest.skip("Chromium is not installed (apt-get install chromium chromium-driver)")
    pytest.importorskip("selenium")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--window-size=1000,720", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(driver), options=options)


@pytest.fixture(scope="module")
def browser():
    driver = _chromium()
    yield driver
    driver.quit()


def _screenshot(driver) -> np.ndarray:
    from io import BytesIO

    from PIL import Image

    return np.asarray(Image.open(BytesIO(driver.get_screenshot_as_png())).convert("RGB"))


def _canvas_rect(driver) -> tuple[float, float, float, float]:
    r = driver.execute_script("const r = document.querySelector('canvas').getBoundingClientRect();"
                              "return [r.left, r.top, r.width, r.height];")
    return tuple(float(v) for v in r)


def project(points, eye, look_at, width: float, height: float, fov_deg: float) -> np.ndarray:
    """Pixels (N, 2) (x right, y down) of world points (N, 3) seen by three.js's perspective camera at ``eye``
    looking at ``look_at`` with +z up and a vertical field of view of ``fov_deg``."""
    forward = np.asarray(look_at, float) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(points, float) - eye
    x, y, z = rel @ right, rel @ up, rel @ forward
    f = 0.5 * height / np.tan(np.radians(fov_deg) / 2)
    return np.column_stack([0.5 * width + f * x / z, 0.5 * height - f * y / z])


def _hue_mask(img: np.ndarray, rgb, tolerance_deg: float = 20.0) -> np.ndarray:
    """Pixels whose hue is within ``tolerance_deg`` of ``rgb``'s and that are clearly coloured (shading changes
    the brightness of a lit face, not its hue)."""
    h0 = colorsys.rgb_to_hsv(*(np.asarray(rgb) / 255.0))[0] * 360
    x = img.astype(float) / 255.0
    mx, mn = x.max(axis=2), x.min(axis=2)
    chroma = mx - mn
    with np.errstate(invalid="ignore", divide="ignore"):
        r, g, b = x[..., 0], x[..., 1], x[..., 2]
        h = np.where(mx == r, ((g - b) / chroma) % 6, np.where(mx == g, (b - r) / chroma + 2, (r - g) / chroma + 4))
    hue = 60 * np.nan_to_num(h)
    d = np.abs((hue - h0 + 180) % 360 - 180)
    return (d < tolerance_deg) & (chroma > 0.12) & (mx > 0.15)


def _robot_seen(img: np.ndarray, scene: viewer.ViewerScene, k: int, rect) -> tuple[float, np.ndarray]:
    """The share of the neck's and head's boxes at frame k whose projected centre has pixels of its colour around
    it, and the mask of all pixels of those colours in the canvas."""
    left, top, width, height = rect
    eye, look_at = scene.camera()
    px = project(scene.shape_positions[k], eye, look_at, width, height, viewer.CAMERA_FOV_DEG) + [left, top]
    coloured = [i for i, c in enumerate(scene.shape_colors) if colorsys.rgb_to_hsv(*(c / 255.0))[1] > 0.5]
    masks = {tuple(c): _hue_mask(img, c) for c in {tuple(scene.shape_colors[i]) for i in coloured}}
    found = 0
    for i in coloured:
        x, y = np.round(px[i]).astype(int)
        window = masks[tuple(scene.shape_colors[i])][max(y - 6, 0):y + 7, max(x - 6, 0):x + 7]
        found += window.sum() >= 8
    canvas = np.zeros(img.shape[:2], bool)
    canvas[int(top):int(top + height), int(left):int(left + width)] = True
    return found / len(coloured), np.logical_or.reduce(list(masks.values())) & canvas


def _wait_for_page(driver, timeout: float = 90.0):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support import expected_conditions as EC
    from selenium.webdriver.support.ui import WebDriverWait

    WebDriverWait(driver, timeout).until(EC.presence_of_element_located((By.CSS_SELECTOR, "canvas")))
    return WebDriverWait(driver, timeout).until(
        EC.presence_of_element_located((By.CSS_SELECTOR, ".mantine-Slider-root")))


def _shown_time(driver) -> float:
    return float(driver.execute_script("return document.querySelector('input.mantine-NumberInput-input').value;"))


def _pause(driver, slider) -> float:
    """Press the playback bar's play/pause button (the page plays on load) and wait until the time stands still;
    the time (s) it shows."""
    from selenium.webdriver.common.by import By

    bar = slider.find_element(By.XPATH, "./ancestor::div[contains(@class, 'mantine-Paper-root')][1]")
    bar.find_elements(By.TAG_NAME, "button")[0].click()
    shown = _shown_time(driver)
    for _ in range(120):
        time.sleep(1.0)
        now = _shown_time(driver)
        if now == shown:
            return now
        shown = now
    raise AssertionError("the time kept running after pause")


def _seek(driver, slider, fraction: float, duration: float) -> float:
    """Click the time slider at ``fraction`` of its length (this pauses playback) and wait until the page shows
    that time (to 5 % of the recording's ``duration``; SwiftShader under load can take seconds); the time shown."""
    from selenium.webdriver.common.action_chains import ActionChains

    width = slider.size["width"]
    ActionChains(driver).move_to_element_with_offset(slider, int((fraction - 0.5) * width), 0).click().perform()
    shown = _shown_time(driver)
    for _ in range(240):
        if abs(shown - fraction * duration) < 0.05 * duration:
            break
        time.sleep(0.5)
        shown = _shown_time(driver)
    assert abs(shown - fraction * duration) < 0.05 * duration, (shown, fraction * duration)
    return shown


def _settled_screenshot(driver, timeout: float = 90.0) -> np.ndarray:
    """A screenshot once the picture stops changing: three in a row, a second apart, alike and with as many
    clearly coloured pixels (the page fades in, and a frame takes a while in SwiftShader on a loaded machine)."""
    def coloured(img: np.ndarray) -> int:
        x = img.astype(float) / 255.0
        return int(((x.max(axis=2) - x.min(axis=2)) > 0.2).sum())

    shots = [_screenshot(driver)]
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        time.sleep(1.0)
        shots = shots[-2:] + [_screenshot(driver)]
        if len(shots) == 3:
            counts = [coloured(im) for im in shots]
            alike = all(np.abs(a.astype(int) - b).mean() < 0.05 for a, b in zip(shots, shots[1:]))
            if alike and max(counts) - min(counts) <= 0.02 * max(counts) and counts[-1] > 0:
                return shots[-1]
    return shots[-1]


def test_the_page_shows_the_robot_and_the_slider_moves_it(browser, planned, scene, tmp_path):
    page = planned / "target.html"
    browser.get(page.resolve().as_uri())
    slider = _wait_for_page(browser)
    times = scene.times - scene.times[0]
    duration = float(times[-1]) + 1.0  # the recording holds the last frame 1 s
    shots = []
    # paused early in the motion, then the slider stepped forward to its end (a step back would replay the
    # recording from its start, its nodes fading in again: slow in SwiftShader)
    for step in ("pause", "slider"):
        t_shown = _pause(browser, slider) if step == "pause" else _seek(browser, slider, 0.97, duration)
        k = int(np.searchsorted(times, t_shown + 0.05, side="right") - 1)  # the time is shown to 0.1 s
        img = _settled_screenshot(browser)
        share, mask = _robot_seen(img, scene, k, _canvas_rect(browser))
        shots.append((k, share, mask, img))
    from PIL import Image

    for (k, share, mask, img), name in zip(shots, ("start", "end")):
        Image.fromarray(img).save(tmp_path / f"{name}.png")  # kept by pytest's tmp_path for a look on failure
        assert share >= 0.75, (k, share, tmp_path)
        assert mask.sum() > 300, (k, mask.sum(), tmp_path)
    (k1, _, m1, _), (k2, _, m2, _) = shots
    assert k2 > k1
    # the robot moved: its coloured pixels are mostly elsewhere
    overlap = (m1 & m2).sum() / (m1 | m2).sum()
    assert overlap < 0.5, (overlap, tmp_path)


def _pixels_served(browser, args: list, rgb, enough: int, tolerance_deg: float = 20.0) -> tuple[int, str]:
    """Run ``snakehead view ARGS --port P``, open the page, and count the pixels of ``rgb``'s hue on screenshots
    until there are ``enough`` (the scene arrives over the websocket and fades in) or a minute has passed; returns
    the count and the command's first line."""
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "snakehead", "view", *args, "--port", str(port)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        line = proc.stdout.readline()
        assert f"http://127.0.0.1:{port}/?token=" in line, line
        browser.get(line.split()[2])  # the URL as printed, with its token
        from selenium.webdriver.common.by import By
        from selenium.webdriver.support import expected_conditions as EC
        from selenium.webdriver.support.ui import WebDriverWait

        WebDriverWait(browser, 60).until(EC.presence_of_element_located((By.CSS_SELECTOR, "canvas")))
        seen = 0
        for _ in range(60):
            time.sleep(1.0)
            seen = int(_hue_mask(_screenshot(browser), rgb, tolerance_deg).sum())
            if seen > enough:
                break
        return seen, line
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_snakehead_view_serves_the_folder(browser, planned):
    """``snakehead view DIR`` serves the scenes of a plan's folder; the page shows the robot."""
    blue, _ = _pixels_served(browser, [str(planned)], viewer.rgb255("#2e86c1"), 300)  # the head's blue
    assert blue > 300


# ----------------------------------------------------------------------------------------------
# a whole-body reach map (snakehead reach) as a still scene
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def reach_file(tmp_path_factory) -> Path:
    """A whole-body map of a tiny grid written by the one map writer, its bits chosen (not computed): every voxel of
    the lower layer reaches one direction of two (a share of 50 %), one voxel both; the upper layer none."""
    from snakehead import SnakeRobot
    from snakehead.planning import whole_body_reach as reach

    robot = SnakeRobot.default()
    grid = reach.reach_grid(robot, 0.6, 2)
    M, N = len(grid.centers), len(grid.directions)
    bits = np.zeros((M, N), bool)
    low = grid.layers == 0
    bits[low, 0] = True
    bits[np.flatnonzero(low)[0], 1] = True
    k = robot.lift_joints.start
    joints = np.where(bits[..., None], 0.0, np.nan) * np.ones((M, N, k))
    placements = np.where(bits[..., None], 0.0, np.nan) * np.ones((M, N, 3))
    m = reach._as_map(robot, grid, bits, placements, joints, 1, 0.0, 1, "test")
    path = tmp_path_factory.mktemp("reach") / "reach.npz"
    m.save(path)
    return path


def test_reach_scene_shows_the_reached_voxels_around_the_start(reach_file, tmp_path):
    from snakehead import BasePlacement, SnakeRobot, load_map
    from snakehead.planning import whole_body_reach as reach

    robot = SnakeRobot.default()
    m = load_map(reach_file)
    scene = viewer.reach_scene(m, robot)
    bits = m.reached_units()
    shown = bits.any(axis=1)
    assert scene.n_frames == 1 and len(scene.voxel_centers) == int(shown.sum()) < len(m)
    np.testing.assert_allclose(scene.voxel_centers, m.centers[shown])  # the map's frame is the world frame
    np.testing.assert_allclose(scene.voxel_indices, 100.0 * bits[shown].mean(axis=1))  # the share reached
    assert sorted(set(scene.voxel_indices.tolist())) == [50.0, 100.0]
    np.testing.assert_allclose(scene.map_frame_positions, 0.0) and np.testing.assert_allclose(
        scene.map_frame_wxyz, [[1, 0, 0, 0]])
    # the robot at the planner's start: its shapes where forward kinematics of the initial configuration puts them
    q0 = reach.WORKERS.get(reach.RobotRecipe.of(robot), None, "rotated", 1).q_initial
    shapes = robot.geometry.shapes
    B = robot.frames(q0, BasePlacement())[[s.frame for s in shapes]] @ np.array([s.origin for s in shapes])
    np.testing.assert_allclose(scene.shape_positions[0], B[:, :3, 3], atol=1e-9)
    again = viewer.load_viewer_scene(viewer.save_viewer_scene(scene, tmp_path / f"reach{viewer.SCENE_SUFFIX}"))
    np.testing.assert_array_equal(again.voxel_indices, scene.voxel_indices)
    with pytest.raises(ValueError, match="head map"):  # a head map is not a whole-body map
        viewer.reach_scene(load_map(robot.map_path), robot)


def test_snakehead_view_map_shows_the_reach_map(browser, reach_file):
    """``snakehead view --map reach.npz`` serves the still scene with its voxels shown at once: the page holds the
    50 % voxels' colour (the index bar's)."""
    from snakehead.viz.reachability_figures import index_colors

    half = np.round(255 * index_colors([50.0])[0]).astype(int)
    seen, line = _pixels_served(browser, ["--map", str(reach_file)], half, 300, tolerance_deg=15.0)
    assert "reach" in line and seen > 300


def test_view_map_options(tmp_path, capsys, reach_file):
    from snakehead.app.cli import main

    assert main(["view", "--live", "--map", str(reach_file)]) == 2  # a still scene: not with --live
    assert "not with --live" in capsys.readouterr().err
    assert main(["view", str(tmp_path), "--robot", "r.toml"]) == 2  # --robot goes with --map or --live
    assert main(["view", "--map", str(tmp_path / "missing.npz")]) == 2
