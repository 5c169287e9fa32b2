"""The closed loop from lying straight (``snakehead.closed_loop.loop.ClosedLoop``): gaits, the curl, the head phases, all in
MuJoCo, from random poses, on the robot's own sensors (``--sensing onboard``, the default) or with the outside fix.

``--poses`` poses (20), drawn with ``--seed``: the tail 0.5-2.5 m from the target's foot (uniform in distance and
bearing; 1.8-2.5 m for the poses with obstacles: a wall between needs room beside the 1.4 m body), the body along any heading, lying straight. The target is the paper's sphere 1 (-0.0405, 0.5443, 0.3) m,
head along +y, held 1 s (``--target`` X Y Z for another). Every other pose has obstacles in the way: a wall (a
0.8 x 0.05 x 0.3 m box, 0.5 m long where that does not fit) or two 0.25 m boxes, across the line from the start to where the body must lie before its
curl, where they touch neither (nor the bending state's footprint). Per pose: the distance, the obstacles, the
phases (gait runs, corrections), the tail's travel, the simulated time, the dead reckoning's largest error, the
fix's error, the head's error in MuJoCo after the final approach (position mm, direction deg; the head phases'
own, before it, in brackets), the smallest distance of the body to any obstacle over the run, and the wall time.
Success: the loop ran its head phases, the head ends within 2 mm and 1 deg of the target, the ZMP stayed inside,
and the body never touched an obstacle.

    python3 bench/loop.py [--poses 20] [--seed 7] [--robot default] [--sensing onboard|outside-fix] [--only 3 5]
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
from snakehead.closed_loop.loop import ClosedLoop
from snakehead.collision import body_collisions as coll
from snakehead.geometry.obstacles import BoxObstacle
from snakehead.locomotion import goals as lc
from snakehead.scenes import Scene

SPHERE_1 = (-0.0405, 0.5443, 0.3)
#: Starts with obstacles in the way are at least this far (m) from the target's foot (nearer, none fits between).
OBSTACLE_MIN_DISTANCE_M = 1.8
#: Obstacles must stay this far (m) from the start's body, the straight pose before the curl and the bending state.
KEEP_OUT_M = 0.15


def _obstacles_in_the_way(robot, start: BasePlacement, straight_goal: BasePlacement, q_bend, goal: BasePlacement,
                          rng: np.random.Generator, kind: str) -> list:
    """A wall or two boxes across the line between the start's middle and the straight goal's, touching none of
    the three bodies (KEEP_OUT_M); [] if none fits."""
    off = lc.chassis_offset(robot)
    a, b = lc.compose(start, off), lc.compose(straight_goal, off)
    p, q = np.array([a.x, a.y]), np.array([b.x, b.y])
    d = q - p
    n = np.array([-d[1], d[0]]) / (np.linalg.norm(d) + 1e-12)
    yaw = math.atan2(n[1], n[0])
    zero = np.zeros((1, robot.n_joints))
    for attempt in range(120):
        c = p + rng.uniform(0.2, 0.8) * d + rng.uniform(-0.2, 0.2) * n
        if kind == "wall":
            length = 0.8 if attempt < 60 else 0.5
            obs = [BoxObstacle.from_yaw([c[0], c[1], 0.15], [length, 0.05, 0.3], yaw)]
        else:
            s = rng.uniform(0.25, 0.4)
            obs = [BoxObstacle.from_yaw([*(c + s * n), 0.125], [0.25, 0.25, 0.25], yaw),
                   BoxObstacle.from_yaw([*(c - s * n), 0.125], [0.25, 0.25, 0.25], yaw)]
        dist = min(coll.collision_check(robot, zero, obs, start, exact_within=1.0).distance[0],
                   coll.collision_check(robot, zero, obs, straight_goal, exact_within=1.0).distance[0],
                   coll.collision_check(robot, np.asarray(q_bend)[None], obs, goal, exact_within=1.0).distance[0])
        if dist > KEEP_OUT_M:
            return obs
    return []


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=20)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--target", type=float, nargs=3, default=SPHERE_1)
    ap.add_argument("--robot", default="default", choices=sorted(ROBOTS))
    ap.add_argument("--sensing", choices=("onboard", "outside-fix"), default="onboard")
    ap.add_argument("--only", type=int, nargs="*", default=None, help="run only these pose numbers")
    ap.add_argument("--verbose", action="store_true", help="the loop's steps on stderr")
    ap.add_argument("--dry", action="store_true", help="only draw the poses and their obstacles")
    args = ap.parse_args()
    robot = ROBOTS[args.robot][1]()
    controller = HeadController(robot, seed=1)
    target = np.array(args.target, float)
    sensing = args.sensing.replace("-", " ")
    free = Scene.from_targets([(target, np.array([0.0, 1.0, 0.0]))], name="target", hold_s=1.0)
    nominal = ClosedLoop(free, controller=controller, sensing=sensing)
    goal = nominal.scene.base if nominal.scene.base is not None else BasePlacement()
    straight_goal = nominal.straight_start()
    from snakehead.planning.planner import bending_state

    q_bend = bending_state(controller, controller.q_initial)
    rng = np.random.default_rng(args.seed)
    print(f"robot {args.robot} ({ROBOTS[args.robot][0]}); target {target.tolist()} m along +y; sensing {sensing}; "
          f"seed {args.seed}; {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}\n")
    print("| # | start x, y (m), heading (deg) | distance (m) | obstacles | gait runs | corrections | tail travel (m) "
          "| simulated time (s) | dead reckoning max (mm) | fix (mm / deg) | head (mm) | head (deg) | min obstacle "
          "distance (mm) | success | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    t_all = time.perf_counter()
    for k in range(args.poses):
        kind = ("wall", "boxes")[(k // 2) % 2] if k % 2 else "none"
        distance = rng.uniform(0.5 if kind == "none" else OBSTACLE_MIN_DISTANCE_M, 2.5)
        bearing, heading = rng.uniform(-math.pi, math.pi, 2)
        start = BasePlacement(target[0] + distance * math.cos(bearing), target[1] + distance * math.sin(bearing),
                              heading)
        obstacles = ([] if kind == "none" else  # their own stream: the poses do not depend on them
                     _obstacles_in_the_way(robot, start, straight_goal, q_bend, goal,
                                           np.random.default_rng([args.seed, k]), kind))
        if args.only is not None and k not in args.only:
            continue
        label = kind if obstacles or kind == "none" else f"{kind}: none fits"
        head0 = f"| {k} | ({start.x:.2f}, {start.y:.2f}), {math.degrees(heading):.0f} | {distance:.2f} | {label} |"
        if args.dry:
            print(head0)
            continue
        scene = Scene.from_targets([(target, np.array([0.0, 1.0, 0.0]))], name="target", hold_s=1.0,
                                   obstacles=obstacles)
        loop = ClosedLoop(scene, controller=controller, sensing=sensing)
        t0 = time.perf_counter()
        try:
            run = loop.run(start, progress=(lambda text: print(f"  {text}", file=sys.stderr, flush=True))
                           if args.verbose else None)
        except (RuntimeError, ValueError) as exc:  # a diverged simulation; a start inside an obstacle
            print(f"{head0} failed: {exc} |", flush=True)
            rows.append(None)
            continue
        wall = time.perf_counter() - t0
        est = run.estimate_summary()
        fix = run.fixes[-1]["fix"] if run.fixes else None
        m = run.metrics
        gaits = sum(p.kind == "gait" for p in run.phases)
        fixed = "-" if fix is None else f"{1000 * fix['position_error_m']:.2f} / {fix['yaw_error_deg']:.3f}"
        dmin = run.min_obstacle_distance_m
        if m is not None:
            pos = m.get("final_position_error_m", m["position_error_m"])
            deg = m.get("final_direction_error_deg", m["direction_error_deg"])
            ok = pos <= 0.002 and deg <= 1.0 and m["zmp_inside"] and (dmin is None or dmin > 0)
            head = (f"{1000 * pos:.2f} ({1000 * m['position_error_m']:.1f}) | {deg:.3f} "
                    f"({m['direction_error_deg']:.2f})")
        else:
            ok, pos, deg = False, None, None
            head = f"- | - (failed: {run.failure})"
        print(f"{head0} {gaits} | {run.corrections} | {run.base_travel_m:.2f} | {run.total_time_s:.1f} | "
              f"{1000 * (est['max_position_error_m'] or 0.0):.0f} | {fixed} | {head} | "
              f"{'-' if dmin is None else f'{1000 * dmin:.0f}'} | {'yes' if ok else 'NO'} | {wall:.0f} |", flush=True)
        rows.append((run, wall, ok, pos, deg, dmin))
    done = [r for r in rows if r is not None and r[3] is not None]
    ran = len(rows)
    print(f"\n{sum(r[2] for r in done)}/{ran} succeeded (head within 2 mm and 1 deg after the final approach, the ZMP "
          "inside, no contact with an obstacle)")
    if done:
        pos = np.array([1000 * r[3] for r in done])
        deg = np.array([r[4] for r in done])
        walls = np.array([r[1] for r in done])
        dmins = [1000 * r[5] for r in done if r[5] is not None]
        print(f"head error median {np.median(pos):.2f} mm (max {pos.max():.2f}), {np.median(deg):.3f} deg "
              f"(max {deg.max():.3f}); min obstacle distance "
              f"{'-' if not dmins else f'{min(dmins):.0f} mm (median {np.median(dmins):.0f})'}; wall median "
              f"{np.median(walls):.0f} s (max {walls.max():.0f})")
    print(f"{time.perf_counter() - t_all:.0f} s wall in all; {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}, load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
