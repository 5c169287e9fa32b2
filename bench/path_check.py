#!/usr/bin/env python3
"""The planner's path checks, the Python ones of the last release against the C++ batches, side by side in one run.

Plans reachable-by-construction targets (``snakehead.motion.targets.reachable_targets``, default robot,
``HeadController(method="free_roll", seed=1)``), records what the plans check (the paths of waypoints the moves check
and the timed motions the plan's end checks), then times on the same inputs, alternately:

* the end checks (``motion.planner._finish``): the Python ``dynamic_stability`` with the lowest points of the neck
  and head (as released) against ``geometry.path_check.finish_checks`` (one C++ pass);
* the path checks (``Waypoints.move``): the released ``_feasible`` at the ``_checked`` configurations (every
  MOVE_CHECK_STEP) against ``geometry.path_check.path_feasible`` (clearances proven between samples, static margin at
  the same configurations), and ``check_path`` alone at several first steps (configurations evaluated, time).

    python3 bench/path_check.py [--count 8] [--sets same,shape] [--repeat 3]
"""
from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, Callable

import numpy as np


def old_feasible(way: Any, qs: np.ndarray) -> np.ndarray:
    """The released ``_Waypoints._feasible`` (now ``Waypoints.feasible``) (Python over the core's per-call kernels), for comparison."""
    from snakehead.geometry import collision as coll
    from snakehead.margins import DETOUR_MARGIN

    clearance = coll.ground_clearance(way.robot, qs, way.base)[:, way.robot.lifted_links].min(axis=1)
    ok = clearance >= -coll.GROUND_TOLERANCE
    if ok.any():
        rows = np.flatnonzero(ok)
        ok[rows] = way._margins(qs[rows]) >= DETOUR_MARGIN
    if ok.any():
        rows = np.flatnonzero(ok)
        ok[rows] = coll.self_clearance(way.robot, qs[rows], way.base) > 0.0
    if way.obstacles and ok.any():
        rows = np.flatnonzero(ok)
        ok[rows] = coll.collision_check(way.robot, qs[rows], way.obstacles, way.base, exact_within=0.005).distance > 0.0
    return ok


def old_finish_checks(robot: Any, base: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> Any:
    """The released end checks: the Python dynamic_stability with the lowest points in the same pass."""
    from snakehead.dynamics import stability

    clearance = np.empty(len(t))

    def lowest(rows: slice, frames: np.ndarray) -> None:
        clearance[rows] = robot.lowest_z(frames, robot.lifted_links).min(axis=1)

    dyn = stability.dynamic_stability(robot, t, q, base, qd, contact="ground", with_frames=lowest)
    return dyn, clearance


def best_of(f: Callable[[], Any], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def record(count: int, sets: list[str], seed: int) -> tuple[list, list, Any]:
    """Plans the targets; returns the paths checked by moves (way, path, checked) and the timed motions."""
    import snakehead
    from snakehead.geometry import path_check
    from snakehead.motion.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)  # warm-up
    paths: list = []
    motions: list = []
    real_path, real_finish = path_check.path_feasible, path_check.finish_checks

    def spy_path(way: Any, path: np.ndarray, checked: np.ndarray, margin: float) -> bool:
        paths.append((way, np.array(path), np.array(checked)))
        return real_path(way, path, checked, margin)

    def spy_finish(robot: Any, base: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray, obstacles: Any,
                   contact: str) -> Any:
        motions.append((robot, base, t, q, qd))
        return real_finish(robot, base, t, q, qd, obstacles, contact)

    path_check.path_feasible, path_check.finish_checks = spy_path, spy_finish
    plans = []
    try:
        for kind in sets:
            for tg in reachable_targets(controller, kind, count, np.random.default_rng(seed)):
                plans.append(snakehead.plan([(tg.position, tg.direction)], controller=controller))
    finally:
        path_check.path_feasible, path_check.finish_checks = real_path, real_finish
    return paths, motions, plans


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=8)
    ap.add_argument("--sets", default="same,shape")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    from snakehead.geometry import path_check
    from snakehead.margins import DETOUR_MARGIN

    paths, motions, plans = record(args.count, args.sets.split(","), args.seed)
    print(f"{len(plans)} plans ({sum(p.success for p in plans)} succeeded), {len(motions)} timed motions, "
          f"{len(paths)} move paths checked\n")
    old_t, new_t, samples = [], [], []
    for robot, base, t, q, qd in motions:
        old_t.append(best_of(lambda: old_finish_checks(robot, base, t, q, qd), args.repeat))
        new_t.append(best_of(lambda: path_check.finish_checks(robot, base, t, q, qd, [], "ground"), args.repeat))
        samples.append(len(t))
    print("| end checks (_finish: ZMP, ground) | samples per plan (median) | median (ms) | total (ms) |")
    print("|---|---|---|---|")
    print(f"| Python (released) | {statistics.median(samples):.0f} | {1e3 * statistics.median(old_t):.1f} | "
          f"{1e3 * sum(old_t):.0f} |")
    print(f"| C++ (finish_checks) | {statistics.median(samples):.0f} | {1e3 * statistics.median(new_t):.1f} | "
          f"{1e3 * sum(new_t):.0f} |")
    print()
    old_p, new_p, agree, old_n = [], [], 0, 0
    for way, path, checked in paths:
        old_p.append(best_of(lambda: old_feasible(way, checked).all(), args.repeat))
        new_p.append(best_of(lambda: path_check.path_feasible(way, path, checked, DETOUR_MARGIN), args.repeat))
        agree += bool(old_feasible(way, checked).all()) == path_check.path_feasible(way, path, checked, DETOUR_MARGIN)
        old_n += len(checked)
    print("| move path checks | paths | configurations (released: all sampled) | total (ms) | verdicts equal |")
    print("|---|---|---|---|---|")
    print(f"| Python _feasible at _checked (released) | {len(paths)} | {old_n} | {1e3 * sum(old_p):.1f} | |")
    print(f"| path_feasible (proof + margins) | {len(paths)} | {old_n} margins | {1e3 * sum(new_p):.1f} | "
          f"{agree}/{len(paths)} |")
    print()
    print("| check_path first_step (rad) | configurations evaluated | proven | unproven | total (ms) | clear paths |")
    print("|---|---|---|---|---|---|")
    for step in (0.02, 0.05, 0.1, 0.2, 0.5):
        n = proven = unproven = clear = 0
        total = 0.0
        for way, path, _ in paths:
            total += best_of(lambda: path_check.check_path(way.robot, path, way.base, way.obstacles, first_step=step),
                             args.repeat)
            r = path_check.check_path(way.robot, path, way.base, way.obstacles, first_step=step)
            n, proven, unproven, clear = n + r.samples, proven + r.proven, unproven + r.unproven, clear + r.clear
        print(f"| {step:g} | {n} | {proven} | {unproven} | {1e3 * total:.1f} | {clear}/{len(paths)} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
