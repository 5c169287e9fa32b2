#!/usr/bin/env python3
"""The retiming and the ZMP pass of plans to other base shapes and placements, two revisions side by side.

Each interpreter given runs a worker that plans the reachable-by-construction targets of a set (as bench/plan_speed.py:
default robot, ``HeadController(method="free_roll", seed=1)`` warmed up by one plan), keeping the path each plan
retimes (``retiming.timing.retime``'s waypoints and options) and the motion it checks (``planning.motion_checks.finish_checks``'s
t, q, qd, placement). Then, path by path and alternately between the workers, each times its own retiming of the path
and its own ZMP pass over the motion from scratch (``stability.dynamic_stability_with_clearance``, contact "ground",
nothing kept), and the pass again with the samples its motion shares with the first plan's (the lift) kept from a
check of that one at its own placement (``stability.KeptSamples``; a revision that takes a prefix over only at the
placement it was made at computes everything): process CPU, the best of ``--repeat``. Prints per set and worker the
median and total CPU of each, and the retimed motions' durations (which must not differ between revisions).

    python3 bench/lift_kernels.py --python OLD/bin/python NEW/bin/python [--sets shape,place] [--count 12]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

from _alternate import run_alternately  # bench/_alternate.py


def worker(kind: str, count: int, seed: int, repeat: int) -> None:
    import numpy as np

    import snakehead
    from snakehead.collision import path_proof
    from snakehead.dynamics import stability
    from snakehead.planning import motion_checks, waypoints
    from snakehead.retiming import timing
    from snakehead.samples.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)
    retimed: list[tuple] = []
    checked: list[tuple] = []
    real_retime, real_finish = waypoints.retime, motion_checks.finish_checks

    def keep_retime(robot: snakehead.SnakeRobot, waypoints: np.ndarray, base: object = None, **options: object) -> object:
        retimed.append((np.array(waypoints), base, options))
        return real_retime(robot, waypoints, base, **options)

    def keep_finish(robot: snakehead.SnakeRobot, base: object, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                    *args: object, **kwargs: object) -> object:
        checked.append((base, t, q, qd))
        return real_finish(robot, base, t, q, qd, *args, **kwargs)

    waypoints.retime, motion_checks.finish_checks = keep_retime, keep_finish
    try:
        for t in reachable_targets(controller, kind, count, np.random.default_rng(seed)):
            snakehead.plan([(t.position, t.direction)], controller=controller)
    finally:
        waypoints.retime, motion_checks.finish_checks = real_retime, real_finish
    print("ready", flush=True)
    for line in sys.stdin:
        k = int(line)
        W, base, options = retimed[k]
        best_retime = best_zmp = float("inf")
        for _ in range(repeat):
            cpu = time.process_time()
            motion = timing.retime(robot, W, base, **options)
            best_retime = min(best_retime, time.process_time() - cpu)
        where, t, q, qd = checked[k]
        made = path_proof.checker(robot, where)
        for _ in range(repeat):
            cpu = time.process_time()
            dyn, _ = stability.dynamic_stability_with_clearance(robot, t, q, where, qd, contact="ground", made=made)
            best_zmp = min(best_zmp, time.process_time() - cpu)
        # the same pass with the lift's part kept from the first plan's check (at its own placement): what a plan
        # gets when its lift was checked before at any placement of the base (the samples both motions begin with)
        where0, t0, q0, qd0 = checked[0]
        n = min(len(t), len(t0))
        differ = np.flatnonzero(np.any(q[:n] != q0[:n], axis=1) | np.any(qd[:n] != qd0[:n], axis=1) | (t[:n] != t0[:n]))
        rows = int(differ[0]) if len(differ) else n
        best_kept, resumed = float("inf"), 0
        if rows >= 2:
            kept = stability.KeptSamples(rows)
            stability.dynamic_stability_with_clearance(robot, t0, q0, where0, qd0, contact="ground", kept=kept)
            for _ in range(repeat):
                cpu = time.process_time()
                again, _ = stability.dynamic_stability_with_clearance(robot, t, q, where, qd, contact="ground",
                                                                      made=made, kept=kept)
                best_kept = min(best_kept, time.process_time() - cpu)
            resumed = kept.resumed
            assert again.stable == dyn.stable and abs(again.min_margin - dyn.min_margin) < 1e-9
        print(json.dumps({"retime": best_retime, "zmp": best_zmp, "samples": len(t), "duration": motion.duration,
                          "min_margin": dyn.min_margin, "zmp_kept": best_kept if resumed else best_zmp,
                          "resumed": resumed}), flush=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--python", nargs="+", required=True, help="interpreters, each with a snakehead installed")
    ap.add_argument("--sets", default="shape,place")
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.worker[0], int(args.worker[1]), int(args.worker[2]), int(args.worker[3]))
        return 0
    print("| set | python | paths | retime median CPU (ms) | retime total (ms) | ZMP pass median CPU (ms) | "
          "ZMP pass total (ms) | ZMP pass, lift kept from another plan: median (ms) | samples taken over (median) | "
          "median samples | motions' total duration (s) | least ZMP margin (mm) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for kind in args.sets.split(","):
        rows = run_alternately([[py, __file__, "--python", py, "--worker", kind, str(args.count), str(args.seed),
                                 str(args.repeat)] for py in args.python], args.count, kind)
        for py, r in zip(args.python, rows):
            retime, zmp = [1000 * x["retime"] for x in r], [1000 * x["zmp"] for x in r]
            kept = [1000 * x["zmp_kept"] for x in r]
            print(f"| {kind} | `{py}` | {len(r)} | {statistics.median(retime):.1f} | {sum(retime):.0f} | "
                  f"{statistics.median(zmp):.1f} | {sum(zmp):.0f} | {statistics.median(kept):.1f} | "
                  f"{statistics.median(x['resumed'] for x in r):.0f} | {statistics.median(x['samples'] for x in r):.0f} | "
                  f"{sum(x['duration'] for x in r):.3f} | {1000 * min(x['min_margin'] for x in r):.4f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
