"""Reachability maps: time the sweep, check it against slow runs, compare the heads as Table 2 does.

    python bench/workspace.py                 # everything (about 10 min on 2 cores)
    python bench/workspace.py --only table2   # the shipped maps against the paper's Table 2 (instant)

Prints markdown tables (paste them into bench/RESULTS.md). Sections:
  table2     the shipped 7-DOF and 6-DOF maps against the paper's Table 2, and G0
  sweep      the target: a 0.05 m map of the 7-DOF head, 20 directions x 4 rolls, on all cores
  agreement  that map's indices against an independent slow run (each voxel alone, random initial
             guesses only, 5 ms per IK call) on a random sample of its voxels
  scaling    how the time grows with the number of voxels and of directions
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from snakehead import SnakeRobot, default_robot_file
from snakehead.app.report import cpu_name
from snakehead.kinematics import workspace as ws

ROBOT_FILES = {"head": "snake16.toml", "head6": "snake16_head6.toml"}  # beside the default robot
PAPER = {  # Table 2 and Section 2.2 of the paper
    "head": {"bins": [8.22, 15.87, 16.96, 25.80, 33.15], "max": 100.0, "above90": 14.79, "at100": 3.69},
    "head6": {"bins": [29.82, 31.28, 28.14, 10.76, 0.0], "max": 76.0, "above90": 0.0, "at100": 0.0},
}


def machine() -> str:
    return f"{cpu_name()}, {os.cpu_count()} cores, Python {platform.python_version()}"


def table2() -> None:
    print("\n### Table 2: the shipped maps against the paper\n")
    print("| head | voxels | [0,20) | [20,40) | [40,60) | [60,80) | [80,100] | max | > 90 | = 100 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for part, label in (("head", "7 DOF"), ("head6", "6 DOF")):
        m = ws.map_for(SnakeRobot.from_file(default_robot_file().with_name(ROBOT_FILES[part])))
        _, pct = m.histogram()
        d = m.indices
        print(f"| {label} (ours) | {len(m)} | " + " | ".join(f"{p:.2f} %" for p in pct)
              + f" | {d.max():.0f} | {100 * np.mean(d > 90):.2f} % | {100 * np.mean(d >= 100):.2f} % |")
        p = PAPER[part]
        print(f"| {label} (paper) | | " + " | ".join(f"{x:.2f} %" for x in p["bins"])
              + f" | {p['max']:.0f} | {p['above90']:.2f} % | {p['at100']:.2f} % |")
    m = ws.map_for(SnakeRobot.default())
    c = m.clusters(k=3)
    print(f"\nG0 of the 7-DOF head (rule '{c.rule}', neck_end frame): {np.round(c.center, 4).tolist()} m; "
          f"cluster sizes {c.sizes.tolist()}; centroids {np.round(c.centroids, 3).tolist()}")
    print(f"Shipped maps made by: `{m.command}`")


def sweep(robot, timeout: float) -> ws.ReachabilityMap:
    print(f"\n### The target sweep (7-DOF head, 0.05 m, 20 directions x 4 rolls, timeout {timeout * 1e3:g} ms)\n")
    t0 = time.perf_counter()
    m = ws.compute(robot, voxel=0.05, directions=20, rolls=4, timeout=timeout, progress=False)
    wall = time.perf_counter() - t0
    s = m.stats
    print("| voxels in hull | IK calls | frames rejected by reach bounds | wall time | threads | mean index |")
    print("|---|---|---|---|---|---|")
    print(f"| {len(m)} | {s['ik_calls']} | {s['cheap_exits']} | {wall:.1f} s | {s['threads']} | {m.indices.mean():.2f} |")
    return m


def agreement(robot, m: ws.ReachabilityMap, samples: int, slow_timeout: float) -> None:
    rng = np.random.default_rng(2024)
    pick = np.sort(rng.choice(len(m), size=min(samples, len(m)), replace=False))
    t0 = time.perf_counter()
    slow = ws.evaluate(robot, m.centers[pick], voxel=m.voxel_size, directions=m.params["directions"],
                       rolls=m.params["rolls"], timeout=slow_timeout, seed=99)
    wall = time.perf_counter() - t0
    fast = m.indices[pick]
    diff = fast - slow
    print(f"\n### Agreement with a slow run ({len(pick)} random voxels, each alone, random guesses only, "
          f"{slow_timeout * 1e3:g} ms per IK call; {wall:.0f} s)\n")
    print("| mean index (map) | mean index (slow) | mean map - slow | mean abs diff | max abs diff | "
          "voxels within 5 | within 10 | correlation |")
    print("|---|---|---|---|---|---|---|---|")
    print(f"| {fast.mean():.2f} | {slow.mean():.2f} | {diff.mean():+.2f} | {np.abs(diff).mean():.2f} | "
          f"{np.abs(diff).max():.0f} | {100 * np.mean(np.abs(diff) <= 5):.0f} % | {100 * np.mean(np.abs(diff) <= 10):.0f} % | "
          f"{np.corrcoef(fast, slow)[0, 1]:.3f} |")


def scaling(robot, timeout: float) -> None:
    print("\n### Scaling (7-DOF head, 4 rolls, all cores)\n")
    print("| voxel | directions | voxels | IK calls | time | time per voxel | time per direction |")
    print("|---|---|---|---|---|---|---|")
    for voxel, dirs in ((0.1, 20), (0.075, 20), (0.05, 20), (0.075, 10), (0.075, 40)):
        t0 = time.perf_counter()
        m = ws.compute(robot, voxel=voxel, directions=dirs, rolls=4, timeout=timeout, progress=False)
        t = time.perf_counter() - t0
        print(f"| {voxel} | {dirs} | {len(m)} | {m.stats['ik_calls']} | {t:.1f} s | {1e3 * t / len(m):.2f} ms | "
              f"{1e3 * t / len(m) / dirs:.3f} ms |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", choices=["table2", "sweep", "agreement", "scaling"], action="append")
    ap.add_argument("--timeout", type=float, default=3e-4, help="IK budget per call of the sweeps (s)")
    ap.add_argument("--samples", type=int, default=150, help="voxels of the agreement check")
    ap.add_argument("--slow-timeout", type=float, default=5e-3)
    args = ap.parse_args()
    todo = args.only or ["table2", "sweep", "agreement", "scaling"]
    robot = SnakeRobot.default()
    print(f"date {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}; load average "
          f"{os.getloadavg()[0]:.2f} at the start")
    if "table2" in todo:
        table2()
    m = None
    if "sweep" in todo or "agreement" in todo:
        m = sweep(robot, args.timeout)
    if "agreement" in todo:
        agreement(robot, m, args.samples, args.slow_timeout)
    if "scaling" in todo:
        scaling(robot, args.timeout)


if __name__ == "__main__":
    main()
