#!/usr/bin/env python3
"""The tracking interpolation's fit: numpy (tests/tracking_reference.py, the code the core replaced) against the core
(``_core.TrackingFit``), side by side in one run.

Two worker processes (one fitting with numpy, one with the core; default robot, ``HeadController(method="free_roll",
seed=1)`` warmed up by one plan, as bench/plan_speed.py) plan the same reachable-by-construction targets
(``snakehead.samples.targets.reachable_targets``), handed to them one at a time, alternately, so that both see the
same load. Each worker records every ``tracking_interpolation`` call its plans make. Prints per set: the plans that
succeeded, median and worst wall time, the median motion duration, the worst relative difference of the motion
durations and of the plans' sum |q| (inf where the sample counts differ), the calls and the median time per call;
then every recorded call timed in this process with each implementation (the fastest of 3 runs each) and the largest
difference of their q.

    python3 bench/tracking_fit.py [--sets same,shape] [--count 12]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _alternate import run_alternately  # noqa: E402  (bench/_alternate.py)

MODES = ("numpy", "core")


def worker(mode: str, kind: str, count: int, seed: int) -> None:
    import contextlib

    import numpy as np
    from tracking_reference import numpy_tracking

    import snakehead
    from snakehead.planning import waypoints
    from snakehead.samples.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    with numpy_tracking() if mode == "numpy" else contextlib.nullcontext():
        snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)  # warm-up, as bench/targets.py
        targets = reachable_targets(controller, kind, count, np.random.default_rng(seed))
        inner = waypoints.tracking_interpolation
        calls: list[float] = []
        args: list[list] = []

        def timed(robot_, qa, qb, n, base=None):  # type: ignore[no-untyped-def]
            clock = time.perf_counter()
            out = inner(robot_, qa, qb, n, base)
            calls.append(time.perf_counter() - clock)
            args.append([np.asarray(qa).tolist(), np.asarray(qb).tolist(), int(n),
                         None if base is None else [base.x, base.y, base.yaw]])
            return out

        waypoints.tracking_interpolation = timed  # type: ignore[assignment]
        print("ready", flush=True)
        for line in sys.stdin:
            t = targets[int(line)]
            calls.clear()
            args.clear()
            wall = time.perf_counter()
            plan = snakehead.plan([(t.position, t.direction)], controller=controller)
            print(json.dumps({"ok": plan.success, "wall": time.perf_counter() - wall, "motion": plan.duration_s,
                              "samples": len(plan.q), "q_sum": float(np.abs(plan.q).sum()),
                              "calls": list(calls), "args": list(args)}), flush=True)


def per_call(recorded: list[list]) -> list[str]:
    """The recorded calls timed with each implementation in this process (fastest of 3), and their q's difference."""
    import numpy as np
    from tracking_reference import tracking_interpolation_numpy

    import snakehead
    from snakehead.trajectory.cartesian import tracking_interpolation

    robot = snakehead.SnakeRobot.default()
    times: dict[str, list[float]] = {m: [] for m in MODES}
    worst = 0.0
    for qa, qb, n, base in recorded:
        place = None if base is None else snakehead.BasePlacement(*base)
        out = {}
        for mode, fn in zip(MODES, (tracking_interpolation_numpy, tracking_interpolation)):
            best = np.inf
            for _ in range(3):
                clock = time.perf_counter()
                out[mode] = fn(robot, np.array(qa), np.array(qb), n, place)
                best = min(best, time.perf_counter() - clock)
            times[mode].append(best)
        worst = max(worst, float(np.abs(out["numpy"].q - out["core"].q).max()))
    rows = ["| implementation | calls | median per call (ms) | total (ms) | speed-up |", "|---|---|---|---|---|"]
    for mode in MODES:
        t = times[mode]
        rows.append(f"| {mode} | {len(t)} | {1e3 * statistics.median(t):.2f} | {1e3 * sum(t):.1f} | "
                    f"{statistics.median(a / b for a, b in zip(times['numpy'], t)):.1f} |")
    rows.append(f"\nlargest |q_numpy - q_core| over the calls: {worst:.2e} rad")
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sets", default="same,shape")
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.worker[0], args.worker[1], int(args.worker[2]), int(args.worker[3]))
        return 0
    print("| set | fit | planned | median wall (s) | worst wall (s) | median motion (s) | worst motion rel. diff. | "
          "worst plan sum abs(q) rel. diff. | fit calls | median fit per call (ms) | median fit per plan (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    recorded: list[list] = []
    for kind in args.sets.split(","):
        rows = run_alternately([[sys.executable, __file__, "--worker", mode, kind, str(args.count), str(args.seed)]
                                for mode in MODES], args.count, kind)
        same = [a["ok"] == b["ok"] for a, b in zip(*rows)]
        rel = max((abs(a["motion"] - b["motion"]) / max(abs(a["motion"]), 1e-12)
                   for a, b in zip(*rows) if a["ok"] and b["ok"]), default=0.0)
        same_q = max((abs(a["q_sum"] - b["q_sum"]) / max(a["q_sum"], 1e-12) if a["samples"] == b["samples"] else float("inf")
                      for a, b in zip(*rows)), default=0.0)
        for mode, r in zip(MODES, rows):
            calls = [c for x in r for c in x["calls"]]
            print(f"| {kind} | {mode} | {sum(x['ok'] for x in r)}/{len(r)} | "
                  f"{statistics.median(x['wall'] for x in r):.2f} | {max(x['wall'] for x in r):.2f} | "
                  f"{statistics.median(x['motion'] for x in r):.2f} | {rel:.1e} (same success: {all(same)}) | {same_q:.1e} | "
                  f"{len(calls)} | {1e3 * statistics.median(calls) if calls else 0.0:.1f} | "
                  f"{1e3 * statistics.median(sum(x['calls']) for x in r):.1f} |", flush=True)
        recorded += [a for x in rows[1] for a in x["args"]]
    print()
    print("\n".join(per_call(recorded)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
