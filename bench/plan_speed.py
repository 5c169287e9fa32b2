#!/usr/bin/env python3
"""Plan time of two installed revisions of snakehead, side by side in one run.

Each Python interpreter given (e.g. two virtual environments with different revisions installed) runs a worker
process that plans the same reachable-by-construction targets (``snakehead.samples.targets.reachable_targets``,
default robot, ``HeadController(method="free_roll", seed=1)`` warmed up by one plan, as bench/targets.py); the
targets are handed to the workers one at a time, alternately, so that both see the same load. Prints per set: the
plans that succeeded, median and worst wall time, median CPU time of the process, the median motion duration, and
the median of the per-target wall-time ratios.

    python3 bench/plan_speed.py --python /path/to/old/venv/bin/python python3 [--sets same,shape,place] [--count 12]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

from _alternate import run_alternately  # bench/_alternate.py


def worker(kind: str, count: int, seed: int) -> None:
    import numpy as np

    import snakehead
    from snakehead.samples.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)  # warm-up, as bench/targets.py
    targets = reachable_targets(controller, kind, count, np.random.default_rng(seed))
    print("ready", flush=True)
    for line in sys.stdin:
        t = targets[int(line)]
        wall, cpu = time.perf_counter(), time.process_time()
        plan = snakehead.plan([(t.position, t.direction)], controller=controller)
        print(json.dumps({"ok": plan.success, "wall": time.perf_counter() - wall, "cpu": time.process_time() - cpu,
                          "motion": plan.duration_s}), flush=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--python", nargs="+", required=True, help="interpreters, each with a snakehead installed")
    ap.add_argument("--sets", default="same,shape,place")
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.worker[0], int(args.worker[1]), int(args.worker[2]))
        return 0
    print("| set | python | planned | median wall (s) | worst wall (s) | median CPU (s) | median motion (s) | "
          "median wall ratio to the first |")
    print("|---|---|---|---|---|---|---|---|")
    for kind in args.sets.split(","):
        rows = run_alternately([[py, __file__, "--python", py, "--worker", kind, str(args.count), str(args.seed)]
                                for py in args.python], args.count, kind)
        for py, r in zip(args.python, rows):
            wall = [x["wall"] for x in r]
            ratio = statistics.median(a["wall"] / b["wall"] for a, b in zip(rows[0], r))
            print(f"| {kind} | `{py}` | {sum(x['ok'] for x in r)}/{len(r)} | {statistics.median(wall):.3f} | "
                  f"{max(wall):.3f} | {statistics.median(x['cpu'] for x in r):.3f} | "
                  f"{statistics.median(x['motion'] for x in r):.1f} | {ratio:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
