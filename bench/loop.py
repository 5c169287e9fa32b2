"""The closed loop from lying straight (``snakehead.sim.loop.ClosedLoop``): gaits, the curl, the head phases, all in
MuJoCo, from random poses.

``--poses`` poses, drawn with ``--seed``: the tail 0.5-2 m from the target's foot (uniform in distance and bearing),
the body along any heading, lying straight. The target is the paper's sphere 1 (-0.0405, 0.5443, 0.3) m, head along
+y, held 1 s (``--target`` X Y Z for another). Per pose: the distance, the phases (gaits and curls, corrections), how
far the tail travelled, the simulated time of the whole sequence, the dead reckoning's largest error (after any
ground phase) and the fix's, and the head's error in MuJoCo at the target against the target (position mm,
direction deg), the simulated ZMP inside the support polygon during the head phases, and the wall time.

    python3 bench/loop.py [--poses 10] [--seed 7] [--robot default]
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time

import numpy as np

from _robots import ROBOTS  # bench/_robots.py
from snakehead import BasePlacement, HeadController
from snakehead.scenes import Scene
from snakehead.sim.loop import ClosedLoop

SPHERE_1 = (-0.0405, 0.5443, 0.3)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=10)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--target", type=float, nargs=3, default=SPHERE_1)
    ap.add_argument("--robot", default="default", choices=sorted(ROBOTS))
    ap.add_argument("--verbose", action="store_true", help="the loop's steps on stderr")
    args = ap.parse_args()
    robot = ROBOTS[args.robot][1]()
    controller = HeadController(robot, seed=1)
    target = np.array(args.target, float)
    scene = Scene.from_targets([(target, np.array([0.0, 1.0, 0.0]))], name="target", hold_s=1.0)
    loop = ClosedLoop(scene, controller=controller)
    rng = np.random.default_rng(args.seed)
    print(f"robot {args.robot} ({ROBOTS[args.robot][0]}); target {target.tolist()} m along +y; seed {args.seed}; {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}\n")
    print("| # | start x, y (m), heading (deg) | distance (m) | gait runs | curls | corrections | tail travel (m) "
          "| simulated time (s) | dead reckoning max (mm) | fix (mm / deg) | head (mm) | head (deg) | ZMP inside "
          "| wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    t_all = time.perf_counter()
    for k in range(args.poses):
        distance = rng.uniform(0.5, 2.0)
        bearing, heading = rng.uniform(-math.pi, math.pi, 2)
        start = BasePlacement(target[0] + distance * math.cos(bearing), target[1] + distance * math.sin(bearing),
                              heading)
        t0 = time.perf_counter()
        try:
            run = loop.run(start, progress=(lambda text: print(f"  {text}", file=sys.stderr, flush=True))
                           if args.verbose else None)
        except RuntimeError as exc:  # a diverged simulation
            print(f"| {k} | ({start.x:.2f}, {start.y:.2f}), {math.degrees(heading):.0f} | {distance:.2f} | "
                  f"failed: {exc} |", flush=True)
            rows.append(None)
            continue
        wall = time.perf_counter() - t0
        est = run.estimate_summary()
        fix = run.fixes[-1]["fix"] if run.fixes else None
        m = run.metrics
        gaits = sum(p.kind == "gait" for p in run.phases)
        curls = sum(p.kind == "curl" for p in run.phases)
        fixed = "-" if fix is None else f"{1000 * fix['position_error_m']:.2f} / {fix['yaw_error_deg']:.3f}"
        head = (f"{1000 * m['position_error_m']:.2f} | {m['direction_error_deg']:.3f} | {m['zmp_inside']}"
                if m is not None else f"- | - | failed: {run.failure}")
        print(f"| {k} | ({start.x:.2f}, {start.y:.2f}), {math.degrees(heading):.0f} | {distance:.2f} | {gaits} | "
              f"{curls} | {run.corrections} | {run.base_travel_m:.2f} | {run.total_time_s:.1f} | "
              f"{1000 * (est['max_position_error_m'] or 0.0):.0f} | "
              f"{fixed} | "
              f"{head} | {wall:.0f} |", flush=True)
        rows.append((run, wall))
    done = [item for item in rows if item is not None and item[0].metrics is not None]
    within = [r for r, _ in done if r.metrics["position_error_m"] <= 0.002 and r.metrics["direction_error_deg"] <= 1.0
              and r.metrics["zmp_inside"]]
    if done:
        pos = np.array([1000 * r.metrics["position_error_m"] for r, _ in done])
        deg = np.array([r.metrics["direction_error_deg"] for r, _ in done])
        total = np.array([r.total_time_s for r, _ in done])
        walls = np.array([w for _, w in done])
        print(f"\n{len(within)}/{args.poses} within 2 mm and 1 deg with the ZMP inside; head error median "
              f"{np.median(pos):.2f} mm (max {pos.max():.2f}), {np.median(deg):.3f} deg (max {deg.max():.3f}); "
              f"simulated time median {np.median(total):.0f} s (max {total.max():.0f}); wall median "
              f"{np.median(walls):.0f} s (max {walls.max():.0f})")
    print(f"{time.perf_counter() - t_all:.0f} s wall in all; {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}, load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
