#!/usr/bin/env python3
"""Benchmark: where the time of ``snakehead demo`` goes, stage by stage (the pipeline's own stage records).

Runs the demo's pipeline (both paper scenarios: plan -> MuJoCo -> figures, GIF and 3-D viewer page -> report)
into a temporary folder and prints a table: each stage's wall-clock seconds, the totals per kind of stage, and the
run's wall-clock and CPU time, with the machine and its load average before and after (the machine is shared:
say so beside any number). Not a test.

    python3 bench/demo_stages.py [--fast] [--serial] [--no-sim] [--cpu]

--serial runs everything in one process: the scenes one after the other, the figures after each simulation (the
pipeline's behaviour before it ran the scenes in lanes side by side, one a core). --cpu clocks each stage in CPU
seconds of the process that runs it (a lane's stages in the lane's): the work, which a shared machine inflates less
than the wall clock.

The stage times of the lanes (and of figure processes, when a lane has a core to spare) overlap: their sum is the
work, not the wall-clock time. The critical path is the longest lane: the stages before the lanes fork, then its
scenes' planning, outputs, MuJoCo and the figures of the dynamics.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import re
import tempfile
import time
from collections import defaultdict
from typing import Iterator

from snakehead.app.pipeline import Progress, Settings, run_scenes
from snakehead.app.report import cpu_name
from snakehead.scenes import paper_scene

# (what a stage's name contains, the kind it is counted as), the first that matches
KINDS = (("libraries", "imports before the lanes fork"), ("planning", "planning"), ("MuJoCo", "MuJoCo simulation"),
         ("momenta", "figures (momenta, ZMP)"), ("ZMP figure", "figures (momenta, ZMP)"),
         ("figures", "figures (snapshots, solution)"), ("animation", "GIF"), ("viewer", "3-D viewer page"),
         ("map", "map and G0"), ("ROS 2", "ROS 2 bag and joint trajectory"))


class CPUProgress(Progress):
    """The pipeline's stage records, each stage clocked in CPU seconds of the process it runs in."""

    @contextlib.contextmanager
    def stage(self, what: str) -> Iterator[None]:
        start = time.process_time()
        yield
        self.stages.append({"stage": what, "seconds": time.process_time() - start})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fast", action="store_true", help="the demo's --fast timing")
    parser.add_argument("--serial", action="store_true", help="no second process for the figures")
    parser.add_argument("--no-sim", action="store_true", help="skip MuJoCo")
    parser.add_argument("--cpu", action="store_true", help="stage clocks in CPU seconds, not wall-clock")
    args = parser.parse_args()
    load_before = os.getloadavg()
    cpu0 = os.times()
    progress = CPUProgress(quiet=True) if args.cpu else Progress(quiet=True)
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        run_scenes([paper_scene("spheres"), paper_scene("hole")], out, progress=progress, command="demo",
                   settings=Settings(fast=args.fast, simulate=not args.no_sim, parallel=not args.serial))
        wall = time.perf_counter() - t0
    cpu1 = os.times()
    load_after = os.getloadavg()
    print(f"snakehead demo{' --fast' if args.fast else ''}{' --no-sim' if args.no_sim else ''}, "
          f"{'serial' if args.serial else 'scenes in lanes'}; stage clocks in {'CPU' if args.cpu else 'wall'} s")
    print(f"{'stage':<78} {'s':>6}")
    totals: dict[str, float] = defaultdict(float)
    for st in progress.stages:
        print(f"{st['stage'][:78]:<78} {st['seconds']:6.1f}")
        for key, kind in KINDS:
            if key in st["stage"]:
                totals[kind] += st["seconds"]
                break
    print()
    for kind in dict.fromkeys(kind for _, kind in KINDS):
        if kind in totals:
            print(f"{'total: ' + kind:<78} {totals[kind]:6.1f}")
    children = (cpu1.children_user + cpu1.children_system) - (cpu0.children_user + cpu0.children_system)
    cpu = (cpu1.user + cpu1.system) - (cpu0.user + cpu0.system)
    print(f"{'wall-clock, end to end':<78} {wall:6.1f}")
    print(f"{'CPU time, this process (+ the lanes and figure processes)':<78} {cpu:6.1f} (+{children:.1f})")
    print(f"machine: {cpu_name()}, {os.cpu_count()} cores; load average before "
          f"{load_before[0]:.2f}, after {load_after[0]:.2f} (1 min)")
    stray = [st["stage"] for st in progress.stages if not any(re.search(k, st["stage"]) for k, _ in KINDS)]
    if stray:
        print("stages of no kind:", stray)


if __name__ == "__main__":
    main()
