"""Live replanning latency of ``snakehead view --live``: from releasing a target to its new motion playing in a browser.

A :class:`snakehead.viz.live.LiveViewer` serves the default robot to Debian's headless Chromium (as the tests drive
it: SwiftShader, no GPU; a 1000 x 720 window). Each "drag" moves the target through the viewer's API (what the
release of a gizmo calls; the browser-to-server hop of a real release, a local websocket message, is not in it)
to the next of a few reachable poses, then waits until the page shows the new motion. Per drag, from the viewer's
records and the page's clock (the same machine's):

* planning: ``snakehead.plan`` with the viewer's one HeadController;
* release -> plan done: planning plus waiting for the worker;
* plan done -> sent: the viewer's own work (the motion's frames, moving the nodes, sending the first frame);
* sent -> painted: the browser (the message waits for the frame being drawn, then the new frame is drawn; the
  page notes when "motion N playing" appears in its panel and takes the start of the second animation frame
  after it as painted);
* release -> painted: all of it; "not planning" is that minus planning: the viewer's and the browser's share.

Two runs: the planner as it is, and the planner replaced by the plans of the same poses made beforehand (0 s of
planning: what is left when plans take no time). The median and the max are over the drags.

    python bench/live_latency.py [--drags 10] [--robot ROBOT.toml]
"""
from __future__ import annotations

import argparse
import platform
import shutil
import sys
import time

import numpy as np

#: Poses the default robot's head reaches from its resting base (m, world; the head along +y): one per drag, in turn.
POSES = ((0.10, 0.55, 0.32), (0.05, 0.50, 0.32), (0.08, 0.52, 0.30), (0.12, 0.50, 0.34), (0.04, 0.54, 0.30))
FORWARD = (0.0, 1.0, 0.0)


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or shutil.which("chromium-browser")
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--window-size=1000,720", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)


def painted(driver, number: int, timeout: float = 120.0) -> float:
    """Epoch seconds when the page painted motion ``number``."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        entry = driver.execute_script(f"return (window.__motions || {{}})['{number}'] || null;")
        if entry and "painted" in entry:
            return entry["painted"] / 1000
        time.sleep(0.01)
    raise TimeoutError(f"the page did not show motion {number}")


def drags(live, driver, n: int) -> list[dict]:
    rows = []
    for k in range(n):
        time.sleep(0.5)  # a user lets go some time after the last motion started
        number = live.move_target(0, POSES[(k + 1) % len(POSES)], FORWARD)
        record = live.wait_for_plan(300)
        assert record.number == number and record.playing is not None, record
        shown = painted(driver, number)
        rows.append({"planning": record.planning_s, "release -> plan done": record.planned - record.released,
                     "plan done -> sent": record.playing - record.planned, "sent -> painted": shown - record.playing,
                     "release -> painted": shown - record.released,
                     "not planning": shown - record.released - record.planning_s})
    return rows


def table(title: str, rows: list[dict]) -> str:
    keys = list(rows[0])
    width = max(len(k) for k in keys)
    lines = [f"{title} ({len(rows)} drags)", f"  {'':{width}}  median s    max s"]
    for key in keys:
        v = np.array([r[key] for r in rows])
        lines.append(f"  {key:{width}}  {np.median(v):8.3f} {v.max():8.3f}")
    return "\n".join(lines)


def cached_planner(live):
    """snakehead.plan replaced by a lookup of plans of POSES made now (each target set's plan, ready at once)."""
    import dataclasses

    import snakehead.planning.planner as planner

    real = planner.plan
    made = {}
    for pose in POSES:
        scene = live.scene()
        moved = dataclasses.replace(scene.targets[0], position=np.array(pose), direction=np.array(FORWARD))
        made[pose] = real(dataclasses.replace(scene, targets=(moved,)), controller=live.controller)

    def lookup(scene, **_):
        return made[tuple(float(x) for x in scene.targets[0].position)]

    planner.plan = lookup
    return lambda: setattr(planner, "plan", real)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--drags", type=int, default=10)
    parser.add_argument("--robot", default=None, help="a robot file (default: the shipped robot)")
    parser.add_argument("--only", choices=("planner", "made"), default=None,
                        help="one run: the planner as it is, or plans made beforehand")
    args = parser.parse_args()
    from snakehead.scenes import Scene, Target
    from snakehead.viz.live import MOTION_WATCH_JS, LiveViewer

    scene = Scene(name="bench", targets=(Target("target", POSES[0], FORWARD, hold_s=1.0),))
    live = LiveViewer(scene, robot_file=args.robot, port=0)
    driver = browser()
    try:
        live.wait_for_plan(300)
        driver.get(live.url)  # with the session's token
        time.sleep(20)  # the page loads, the scene arrives and fades in (slow in SwiftShader)
        driver.execute_script(MOTION_WATCH_JS)
        print(f"python {platform.python_version()}, {platform.machine()}; headless Chromium (SwiftShader) 1000x720")
        if args.only in (None, "planner"):
            print(table("planner as it is", drags(live, driver, args.drags)), flush=True)
        if args.only in (None, "made"):
            restore = cached_planner(live)
            try:
                print(table("plans made beforehand (planning ~0 s)", drags(live, driver, args.drags)))
            finally:
                restore()
    finally:
        driver.quit()
        live.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
