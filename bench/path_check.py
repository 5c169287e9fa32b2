#!/usr/bin/env python3
"""The planner's path checks, the Python ones of the last release against the C++ batches, side by side in one run.

Plans reachable-by-construction targets (``snakehead.samples.targets.reachable_targets``, default robot,
``HeadController(method="free_roll", seed=1)``), records what the plans check (the paths of waypoints the moves check
and the timed motions the plan's end checks), then times on the same inputs, alternately:

* the end checks (``planning.planner._finish``): the Python ``dynamic_stability`` with the lowest points of the neck
  and head (as released) against ``planning.motion_checks.finish_checks`` (one C++ pass), from scratch and with the
  lift's part kept from an earlier plan (``stability.KeptSamples``, as ``Waypoints.finish_checks`` does);
* the clearances of the timed motions between their samples: every 2 ms sample (``sample_clearances``, as the end
  checks did) against ``check_motion`` (coarse samples, the total-variation bound) at several first steps, with an
  obstacle box beside each motion's head path;
* the path checks (``Waypoints.move``): the released ``_feasible`` at the ``_checked`` configurations (every
  MOVE_CHECK_STEP) against ``planning.motion_checks.path_feasible`` (clearances proven between samples, static margin at
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
    from snakehead.collision import body_collisions as coll
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
    from snakehead.planning import motion_checks
    from snakehead.samples.targets import reachable_targets

    robot = snakehead.SnakeRobot.default()
    controller = snakehead.HeadController(robot, method="free_roll", seed=1)
    H = robot.head_pose(controller.q_initial)
    snakehead.plan([(H[:3, 3], H[:3, 0])], controller=controller)  # warm-up
    paths: list = []
    motions: list = []
    real_path, real_finish = motion_checks.path_feasible, motion_checks.finish_checks

    def spy_path(way: Any, path: np.ndarray, checked: np.ndarray, margin: float) -> bool:
        paths.append((way, np.array(path), np.array(checked)))
        return real_path(way, path, checked, margin)

    def spy_finish(robot: Any, base: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray, obstacles: Any,
                   contact: str, **kwargs: Any) -> Any:
        kept = kwargs.get("kept")
        motions.append((robot, base, t, q, qd, kept.samples if kept is not None else 0))
        return real_finish(robot, base, t, q, qd, obstacles, contact, **kwargs)

    motion_checks.path_feasible, motion_checks.finish_checks = spy_path, spy_finish
    plans = []
    try:
        for kind in sets:
            for tg in reachable_targets(controller, kind, count, np.random.default_rng(seed)):
                plans.append(snakehead.plan([(tg.position, tg.direction)], controller=controller))
    finally:
        motion_checks.path_feasible, motion_checks.finish_checks = real_path, real_finish
    return paths, motions, plans


def end_checks(motions: list, repeat: int) -> None:
    """The end checks of the recorded motions: released Python, the C++ pass from scratch and resumed."""
    from snakehead.collision import path_proof as path_check
    from snakehead.dynamics import stability
    from snakehead.planning import motion_checks

    rows: dict[str, list[float]] = {"old": [], "scratch": [], "kept": [], "zmp": [], "zmp kept": [], "proof": []}
    samples, taken = [], 0
    for robot, base, t, q, qd, lift_rows in motions:
        made = path_check.checker(robot, base)
        kept = stability.KeptSamples(lift_rows) if lift_rows else None
        if kept is not None:  # as an earlier plan from this base leaves it
            stability.dynamic_stability_with_clearance(robot, t, q, base, qd, made=made, kept=kept)
        rows["old"].append(best_of(lambda: old_finish_checks(robot, base, t, q, qd), repeat))
        rows["scratch"].append(best_of(lambda: motion_checks.finish_checks(robot, base, t, q, qd, [], "ground", made=made),
                                       repeat))
        rows["kept"].append(best_of(lambda: motion_checks.finish_checks(robot, base, t, q, qd, [], "ground", made=made,
                                                                     kept=kept), repeat))
        rows["zmp"].append(best_of(lambda: stability.dynamic_stability_with_clearance(robot, t, q, base, qd, made=made),
                                   repeat))
        rows["zmp kept"].append(best_of(lambda: stability.dynamic_stability_with_clearance(
            robot, t, q, base, qd, made=made, kept=kept), repeat))
        rows["proof"].append(best_of(lambda: path_check.check_motion(robot, q, base, made=made), repeat))
        samples.append(len(t))
        taken += kept.resumed if kept is not None else 0
    print(f"| end checks (_finish: ZMP, ground; {len(motions)} motions, median {statistics.median(samples):.0f} samples, "
          f"{taken / max(1, sum(samples)):.0%} of the samples' ZMP part kept) | median (ms) | total (ms) |")
    print("|---|---|---|")
    for key, label in (("old", "Python (released): ZMP and ground at every sample"),
                       ("scratch", "finish_checks from scratch: ZMP and ground at every sample, check_motion"),
                       ("kept", "finish_checks, the lift's ZMP part kept (as plans from one base)"),
                       ("zmp", "of which the ZMP pass from scratch"), ("zmp kept", "of which the ZMP pass, kept"),
                       ("proof", "of which check_motion (ground, self between the samples)")):
        print(f"| {label} | {1e3 * statistics.median(rows[key]):.1f} | {1e3 * sum(rows[key]):.0f} |")
    print()


def between_samples(motions: list, repeat: int) -> None:
    """Ground, self and an obstacle beside the head's path: every 2 ms sample against check_motion's proof."""
    from snakehead.collision import path_proof as path_check
    from snakehead.geometry import BoxObstacle

    print("| clearances of the timed motions, an obstacle beside the head | configurations evaluated | proven clear "
          "| total (ms) |")
    print("|---|---|---|---|")
    cases = []
    for robot, base, t, q, qd, _ in motions:
        head = robot.frames_many(q[len(q) // 2:len(q) // 2 + 1], base)[0, -1, :3, 3]
        box = BoxObstacle(centre=head + [0.0, 0.15, 0.0], size=(0.1, 0.05, 0.1))
        cases.append((robot, base, q, [box], path_check.checker(robot, base, [box])))
    total = sum(best_of(lambda: path_check.sample_clearances(r, q, b, o, made=m), repeat) for r, b, q, o, m in cases)
    clear = sum(bool((path_check.sample_clearances(r, q, b, o, made=m)[2] > 0).all()) for r, b, q, o, m in cases)
    print(f"| every sample (sample_clearances: ground, self, obstacle) | {sum(len(c[2]) for c in cases)} | "
          f"{clear}/{len(cases)} at the samples | {1e3 * total:.1f} |")
    for step in (0.05, 0.1, 0.2, 0.4):
        total, n, clear = 0.0, 0, 0
        for r, b, q, o, m in cases:
            total += best_of(lambda: path_check.check_motion(r, q, b, o, first_step=step, made=m), repeat)
            report = path_check.check_motion(r, q, b, o, first_step=step, made=m)
            n, clear = n + report.samples, clear + report.clear
        print(f"| check_motion, first_step {step:g} rad | {n} | {clear}/{len(cases)} | {1e3 * total:.1f} |")
    print()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=8)
    ap.add_argument("--sets", default="same,shape")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    from snakehead.collision import path_proof as path_check
    from snakehead.margins import DETOUR_MARGIN
    from snakehead.planning import motion_checks

    paths, motions, plans = record(args.count, args.sets.split(","), args.seed)
    print(f"{len(plans)} plans ({sum(p.success for p in plans)} succeeded), {len(motions)} timed motions, "
          f"{len(paths)} move paths checked\n")
    end_checks(motions, args.repeat)
    between_samples(motions, args.repeat)
    old_p, new_p, agree, old_n = [], [], 0, 0
    for way, path, checked in paths:
        old_p.append(best_of(lambda: old_feasible(way, checked).all(), args.repeat))
        new_p.append(best_of(lambda: motion_checks.path_feasible(way, path, checked, DETOUR_MARGIN), args.repeat))
        agree += bool(old_feasible(way, checked).all()) == motion_checks.path_feasible(way, path, checked, DETOUR_MARGIN)
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
