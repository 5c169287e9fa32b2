#!/usr/bin/env python3
"""Benchmark: writing the ROS 2 bag (``NAME.mcap``) and the JointTrajectory YAML of the paper's two scenarios.

Plans the demo's scenes (``spheres``, ``hole``; the demo's ``--fast`` changes only its animations), then writes each
one's bag and YAML ``--repeat`` times into a temporary folder (``snakehead.app.ros_bag``) and prints per scene: the
motion's duration and samples, the median wall-clock and CPU seconds of each writer and the files' sizes, with the
machine and its load average (the machine may be shared: say so beside any number). Not a test.

    python3 bench/ros_bag.py [--repeat 3]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

from snakehead import HeadController, SnakeRobot, plan
from snakehead.app import ros_bag
from snakehead.app.report import cpu_name
from snakehead.scenes import paper_scene


def timed(write, *args) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    write(*args)
    return time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="writes per file (default 3; the median is shown)")
    args = parser.parse_args()
    controller = HeadController(SnakeRobot.default(), seed=1)
    print(f"{cpu_name()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} before")
    print("| scene   | motion (s) | samples | bag wall / CPU (s) | bag (MB) | YAML wall / CPU (s) | YAML (MB) |")
    print("|---------|------------|---------|--------------------|----------|---------------------|-----------|")
    with tempfile.TemporaryDirectory() as out:
        for name in ("spheres", "hole"):
            p = plan(paper_scene(name), controller=controller)
            bag, yml = Path(out) / f"{name}.mcap", Path(out) / f"{name}_joint_trajectory.yaml"
            b = [timed(ros_bag.write_plan_bag, p, bag) for _ in range(args.repeat)]
            y = [timed(ros_bag.write_joint_trajectory, p, yml) for _ in range(args.repeat)]
            med = [statistics.median(x) for x in zip(*b)] + [statistics.median(x) for x in zip(*y)]
            print(f"| {name:7s} | {p.duration_s:10.1f} | {len(p.t):7d} | {med[0]:8.2f} / {med[1]:<7.2f} | "
                  f"{bag.stat().st_size / 1e6:8.1f} | {med[2]:9.2f} / {med[3]:<7.2f} | {yml.stat().st_size / 1e6:9.1f} |")
    print(f"load average {os.getloadavg()[0]:.1f} after")


if __name__ == "__main__":
    main()
