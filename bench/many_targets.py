#!/usr/bin/env python3
"""Many targets in one scene: wall time and peak memory of ``snakehead plan --scene S --no-sim`` per target count.

The scenes hold targets reachable by construction (``snakehead.samples.targets.reachable_targets``, kind "same":
head poses of stable, collision-free whole-body configurations from the planner's own base), each held
``--hold`` s, visited in the order drawn. Each count runs the command line in a fresh process
(``python -m snakehead plan --scene S --no-sim --out D``) under ``/usr/bin/time -v`` (peak RSS of the process and
of the child that draws the figures, whichever is larger); the table gives the targets, the plan's 2 ms samples
(from ``report.json``), the wall time, the peak memory and how many targets were solved.

    python3 bench/many_targets.py [--counts 10,50,100] [--hold 0.2] [--seed 0] [--out /tmp/many_targets]
    python3 bench/many_targets.py --scene-only 100 --out scene.toml     # just write a scene

Prints a Markdown table (targets, samples, seconds, peak MiB); the results go into bench/RESULTS.md by hand.
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def write_scene(path: Path, count: int, hold_s: float = 0.2, seed: int = 0) -> Path:
    """A scene file of ``count`` targets reachable by construction on the default robot (see the module)."""
    import snakehead
    from snakehead.samples.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot)
    targets = reachable_targets(controller, "same", count, np.random.default_rng(seed))
    lines = [f'name = "many{count}"', f'description = "{count} reachable targets"', ""]
    for k, t in enumerate(targets):
        lines += ["[[targets]]", f'name = "t{k + 1:04d}"',
                  f"position = [{', '.join(repr(float(v)) for v in t.position)}]",
                  f"direction = [{', '.join(repr(float(v)) for v in t.direction)}]",
                  f"hold_s = {hold_s!r}", ""]
    path.write_text("\n".join(lines))
    return path


def run(scene: Path, out: Path) -> dict:
    """``snakehead plan --scene scene --no-sim --out out`` under /usr/bin/time -v: wall s, peak MiB, the report."""
    cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "snakehead", "plan", "--scene", str(scene), "--no-sim",
           "--out", str(out)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr)
    peak_mib = int(m.group(1)) / 1024 if m else float("nan")
    report = None
    if (out / "report.json").is_file():
        report = json.loads((out / "report.json").read_text())
    return {"wall": wall, "peak_mib": peak_mib, "report": report, "rc": proc.returncode,
            "stderr": proc.stderr}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--counts", default="10,50,100", help="target counts (default 10,50,100)")
    ap.add_argument("--hold", type=float, default=0.2, help="hold_s of every target (default 0.2)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="/tmp/many_targets", help="working folder (scenes and outputs)")
    ap.add_argument("--scene-only", type=int, default=None, metavar="N", help="write a scene of N targets to --out")
    ap.add_argument("--verbose", action="store_true", help="show each run's progress lines")
    args = ap.parse_args()
    if args.scene_only is not None:
        print(write_scene(Path(args.out), args.scene_only, args.hold, args.seed))
        return 0
    work = Path(args.out)
    work.mkdir(parents=True, exist_ok=True)
    rows = []
    print("| targets | solved | samples | motion (s) | wall (s) | peak RSS (MiB) | exit |")
    print("|--:|--:|--:|--:|--:|--:|--:|")
    for count in (int(c) for c in args.counts.split(",")):
        scene = write_scene(work / f"many{count}.toml", count, args.hold, args.seed)
        r = run(scene, work / f"out{count}")
        if args.verbose:
            print(r["stderr"], file=sys.stderr)
        entry = next(iter(r["report"]["scenarios"].values())) if r["report"] else None
        samples = entry["samples"] if entry else 0
        solved = sum(1 for t in entry["targets"] if t.get("solved", True)) if entry else 0
        motion = entry["duration_s"] if entry else float("nan")
        rows.append((count, solved, samples, motion, r["wall"], r["peak_mib"], r["rc"]))
        print(f"| {count} | {solved} | {samples} | {motion:.1f} | {r['wall']:.1f} | {r['peak_mib']:.0f} | {r['rc']} |",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
