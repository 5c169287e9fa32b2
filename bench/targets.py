#!/usr/bin/env python3
"""How often ``snakehead.plan`` reaches a head target, why it fails, and how long it takes.

Target sets (``snakehead.samples.targets``): reachable by construction with the planner's base shape ("same"),
with other flat base shapes ("shape"), with other placements ("place"), and random targets around the robot
("random"). For each target: ``snakehead.plan([(position, direction)])`` from the default placement; success,
the failure's reason (the whole-body solve's: out of reach / no stable pose / no clear pose, or the motion's
check that failed), the stage that solved it, whether the base had to be relocated, and the plan's wall time. A
sample of the successful plans is executed in MuJoCo (``snakehead.simulate``) with the head errors at the target
and the ZMP check.

    python3 bench/targets.py [--count 50] [--sim 20] [--robot ROBOT.toml | --generated NAME] [--seed 0] [--rows FILE] [--write]

Prints tables; with --write, puts them in bench/RESULTS.md (section "Targets") with the date and the machine.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

import snakehead
from snakehead.app.report import cpu_name
from snakehead.samples.targets import KINDS, random_targets, reachable_targets


def failure_cause(plan) -> str:
    if plan.success:
        return ""
    for tg in plan.targets:
        if not tg.solved:
            return tg.solution.reason or "not solved"
    text = plan.failure or ""
    for key, label in (("ZMP", "ZMP outside"), ("ground", "into the ground"), ("obstacle", "obstacle")):
        if key in text:
            return label
    return text[:40]


def run_set(controller, name: str, targets, sim_left: list, sim_rows: list, log=None) -> dict:
    rows = []
    for position, direction in targets:
        t0 = time.perf_counter()
        plan = snakehead.plan([(position, direction)], controller=controller)
        dt = time.perf_counter() - t0
        stage = plan.targets[0].solution.stage if plan.targets else None
        rows.append({"success": plan.success, "cause": failure_cause(plan), "time": dt, "stage": stage,
                     "relocated": plan.relocation is not None, "duration": plan.duration_s})
        if plan.success and sim_left[0] > 0:
            sim_left[0] -= 1
            s = snakehead.simulate(plan)
            sim_rows.append({"set": name, "position_mm": 1000 * s.position_error_m,
                             "direction_deg": s.direction_error_deg, "zmp_inside": s.zmp_inside,
                             "zmp_margin_mm": 1000 * s.metrics["zmp_min_margin_m"],
                             "slide_mm": 1000 * s.metrics["base_slide_m"]})
        if log is not None:  # one JSON line per target: runs of two releases compared target by target
            log.write(json.dumps({"set": name, "target": len(rows), **{k: rows[-1][k] for k in
                                  ("success", "cause", "time", "relocated", "duration")}}) + "\n")
            log.flush()
        print(f"  {name} {len(rows):3d}: {'ok ' if plan.success else 'NO '} {dt:6.2f} s "
              f"{stage or rows[-1]['cause']}{' (relocated)' if plan.relocation is not None else ''}",
              file=sys.stderr, flush=True)
    times = [r["time"] for r in rows]
    return {"set": name, "n": len(rows), "success": sum(r["success"] for r in rows),
            "median_s": statistics.median(times) if times else float("nan"), "max_s": max(times, default=float("nan")),
            "causes": Counter(r["cause"] for r in rows if not r["success"]),
            "stages": Counter(r["stage"] for r in rows if r["success"]),
            "relocated": sum(r["relocated"] for r in rows if r["success"]),
            "median_motion_s": statistics.median([r["duration"] for r in rows]) if rows else float("nan")}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=50, help="targets per set (default 50)")
    ap.add_argument("--sim", type=int, default=20, help="successful plans executed in MuJoCo (default 20)")
    ap.add_argument("--robot", default=None, help="a robot file (default: the shipped robot)")
    ap.add_argument("--generated", default=None, help="a generated snake of bench/_robots.py (e.g. twenty, "
                    "pitch_first), with a coarse map computed here (voxel twice the default, 6 directions, 1 roll)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sets", default=",".join(KINDS + ("random",)), help="comma-separated sets to run")
    ap.add_argument("--rows", default=None, help="also write each target's row (JSON lines) to this file")
    ap.add_argument("--write", action="store_true", help="write the tables into bench/RESULTS.md")
    args = ap.parse_args()
    if args.generated is not None:
        from _robots import ROBOTS  # bench/_robots.py

        from snakehead.kinematics import reachability as ws

        if args.generated not in ROBOTS:
            ap.error(f"--generated must be one of {', '.join(ROBOTS)}")
        robot = ROBOTS[args.generated][1]()
        print(f"computing a coarse map for {args.generated} ({ROBOTS[args.generated][0]})", file=sys.stderr)
        coarse = ws.compute(robot, voxel=2 * ws.default_map_options(robot)["voxel"], directions=6, rolls=1,
                            progress=False)
        controller = snakehead.HeadController(robot, coarse, method="free_roll", seed=1)
    else:
        robot = snakehead.SnakeRobot.default() if args.robot is None else snakehead.SnakeRobot.from_file(args.robot)
        controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    rng = np.random.default_rng(args.seed)
    sim_left, sim_rows, results = [args.sim], [], []
    snakehead.plan([(robot.head_pose(controller.q_initial)[:3, 3], robot.head_pose(controller.q_initial)[:3, 0])],
                   controller=controller)  # warm-up: caches of the controller (bending state, IK solvers)
    load0 = os.getloadavg()[0]
    log = open(args.rows, "w") if args.rows else None
    for name in args.sets.split(","):
        if name == "random":
            targets = random_targets(controller, args.count, rng)
        else:
            targets = [(t.position, t.direction) for t in reachable_targets(controller, name, args.count, rng)]
        results.append(run_set(controller, name, targets, sim_left, sim_rows, log))
    load1 = os.getloadavg()[0]
    if log is not None:
        log.close()

    which = f" --generated {args.generated}" if args.generated else f" --robot {args.robot}" if args.robot else ""
    lines = [f"`python3 bench/targets.py --count {args.count} --sim {args.sim} --seed {args.seed}{which}` on "
             f"{datetime.date.today()}, {cpu_name()} ({os.cpu_count()} cores), load {load0:.1f} -> {load1:.1f}; "
             f"robot {args.generated or robot.source or robot.urdf}.", "",
             "| set | planned | median plan time (s) | worst (s) | median motion (s) | stages | relocated | failures |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        stages = ", ".join(f"{k}: {v}" for k, v in r["stages"].most_common())
        causes = ", ".join(f"{k}: {v}" for k, v in r["causes"].most_common()) or "-"
        lines.append(f"| {r['set']} | {r['success']}/{r['n']} ({100 * r['success'] / max(r['n'], 1):.0f} %) | "
                     f"{r['median_s']:.2f} | {r['max_s']:.2f} | {r['median_motion_s']:.1f} | {stages} | "
                     f"{r['relocated']} | {causes} |")
    if sim_rows:
        pe = [r["position_mm"] for r in sim_rows]
        de = [r["direction_deg"] for r in sim_rows]
        lines += ["", f"MuJoCo, {len(sim_rows)} successful plans: head position error max {max(pe):.2f} mm "
                      f"(median {statistics.median(pe):.2f}), direction max {max(de):.3f} deg (median "
                      f"{statistics.median(de):.3f}); ZMP inside in {sum(r['zmp_inside'] for r in sim_rows)} (least margin "
                      f"{min(r['zmp_margin_mm'] for r in sim_rows):.2f} mm); "
                      f"base slide max {max(r['slide_mm'] for r in sim_rows):.2f} mm; within 2 mm and 1 deg: "
                      f"{sum(p <= 2 and d <= 1 for p, d in zip(pe, de))}/{len(sim_rows)}."]
    text = "\n".join(lines)
    print(text)
    if args.write:
        path = Path(__file__).with_name("RESULTS.md")
        body = path.read_text()
        head = "## Targets (bench/targets.py)"
        section = f"{head}\n\n{text}\n"
        if head in body:
            start = body.index(head)
            nxt = body.find("\n## ", start + len(head))
            body = body[:start] + section + (body[nxt:] if nxt >= 0 else "")
        else:
            body = body.rstrip() + "\n\n" + section
        path.write_text(body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
