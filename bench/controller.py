#!/usr/bin/env python3
"""Benchmark of the segmented head control (issue 6): HeadController.solve on the paper's targets and on
random reachable targets, with both head methods (the paper's rotated frames, and free roll).

Random targets: the base on its initial arc, random neck and head joints within the limits; the head
frame they give (position and x-axis) is the target, so every target is reachable by the whole robot
(the controller still has to find it through the neck strategy of Eqs. 18-22). Prints a table.

    python3 bench/controller.py [--targets 500] [--seed 0]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from snakehead import SnakeRobot
from snakehead.app.report import cpu_name
from snakehead.scenes import paper_scene
from snakehead.solve.head_controller import HeadController


def run(controller: HeadController, targets) -> dict:
    times, ok, pos, ang, stable = [], [], [], [], []
    for p, d in targets:
        t0 = time.perf_counter()
        sol = controller.solve(p, d)
        times.append(time.perf_counter() - t0)
        ok.append(sol.success)
        stable.append(sol.static_stable)
        if sol.success:
            pos.append(sol.position_error)
            ang.append(sol.direction_error)
    times = np.array(times) * 1e3
    return {
        "n": len(targets), "success": float(np.mean(ok)) * 100, "stable": float(np.mean(stable)) * 100,
        "median_ms": float(np.median(times)), "mean_ms": float(np.mean(times)), "p95_ms": float(np.percentile(times, 95)),
        "max_pos_mm": float(np.max(pos) * 1e3) if pos else float("nan"),
        "max_dir_deg": float(np.max(ang)) if ang else float("nan"),
    }


def random_targets(robot: SnakeRobot, q_initial: np.ndarray, n: int, rng: np.random.Generator):
    out = []
    while len(out) < n:
        q = q_initial.copy()
        sl = slice(robot.parts.neck.start, robot.parts.head.stop)
        q[sl] = rng.uniform(robot.lower[sl], robot.upper[sl])
        T = robot.head_pose(q)
        if T[2, 3] < 0.05:  # targets at least 5 cm off the ground (about half of the draws)
            continue
        out.append((T[:3, 3], T[:3, 0]))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--targets", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    robot = SnakeRobot.default()
    rng = np.random.default_rng(args.seed)
    spheres, hole = paper_scene("spheres"), paper_scene("hole")
    paper = [(t.position, t.direction) for t in spheres.reported] + [(hole.obstacles[0].centre, hole.obstacles[0].normal)]
    print(f"# HeadController.solve, {cpu_name()}, {time.strftime('%Y-%m-%d')}")
    print("| method | targets | n | success % | statically stable % | median ms | mean ms | p95 ms "
          "| max position error mm | max direction error deg |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for method in ("free_roll", "rotated"):
        controller = HeadController(robot, method=method, seed=args.seed)
        rnd = random_targets(robot, controller.q_initial, args.targets, rng)
        for label, targets in (("paper (spheres, hole)", paper), ("random reachable", rnd)):
            r = run(controller, targets)
            print(f"| {method} | {label} | {r['n']} | {r['success']:.1f} | {r['stable']:.1f} | {r['median_ms']:.2f} "
                  f"| {r['mean_ms']:.2f} | {r['p95_ms']:.2f} | {r['max_pos_mm']:.4f} | {r['max_dir_deg']:.4f} |")


if __name__ == "__main__":
    main()
