"""Time-optimal retiming of the paper's two scenarios (snakehead.retiming.timing.retime) against the fixed speed.

For each scenario (snakehead.scenes.paper_scene: "spheres", "hole") the planner's states (today timed at a fixed
0.12 rad/s) are retimed under a sweep of limits; each retimed motion is simulated in MuJoCo
(snakehead.sim.simulate_trajectory: PD + support-aware gravity compensation at 2 ms) and compared with the plan at
its targets' retimed times (snakehead.sim.compare). Prints markdown tables: duration, what binds, the retiming's
run time, the simulated head errors against the paper's, momentum errors, ZMP, base slide.

    python3 bench/timing.py                       # the sweep below, both scenarios, MuJoCo for each
    python3 bench/timing.py --accelerations 1 --velocity-shares 0.5 --no-sim
    python3 bench/timing.py --accelerations 4 --velocity-shares 1 --zmp-margins 0.005 0.01 0.015 --interpolations
    python3 bench/timing.py --solvers --no-sim --accelerations 2 --velocity-shares 0.5 --interpolations
                                                  # + toppra against the core's TOPP-RA, side by side (needs toppra)
"""
from __future__ import annotations

import argparse
import contextlib
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import snakehead
from snakehead.dynamics import stability
from snakehead.retiming import gridpoints, timing
from snakehead.scenes import paper_scene

#: The paper's Section 4: durations (s) and simulated head errors (mm, deg).
PAPER = {"spheres": dict(duration=36.0, position_mm=1.8, direction_deg=0.76),
         "hole": dict(duration=23.0, position_mm=1.39, direction_deg=0.95)}


def cpu_name() -> str:
    try:
        from snakehead.app.report import cpu_name as name

        return name()
    except Exception:  # pragma: no cover - the report's reader is optional here
        return platform.processor() or "unknown CPU"


def scenario(name: str) -> dict:
    """The plan of a paper scenario: its states, their fixed-speed times, the reported targets and their states."""
    clock = time.perf_counter()
    plan = snakehead.plan(paper_scene(name))
    labels = [label for label, _, _ in plan.states]
    targets = [(labels.index(tg.name), tg.position, tg.direction) for tg in plan.targets]
    return dict(plan=plan, q=np.array([q for _, _, q in plan.states]), times=np.array([t for _, t, _ in plan.states]),
                targets=targets, plan_s=time.perf_counter() - clock)


def run(name: str, sc: dict, *, simulate: bool, **limits) -> dict:
    plan = sc["plan"]
    holds = np.diff(sc["times"])  # the plan's pauses (repeated states) keep their length
    stops = [k for k, _, _ in sc["targets"]]  # the head comes to rest at each reported target
    clock = time.perf_counter()
    traj = timing.retime(plan.robot, sc["q"], plan.base, hold_s=holds, stops=stops, **limits)
    solve_s = time.perf_counter() - clock
    dyn = stability.dynamic_stability(plan.robot, traj.t, traj.q, plan.base, traj.qd, contact="ground")
    row = dict(duration=traj.duration, solve_s=solve_s, check=traj.check, zmp_planned_mm=1000 * dyn.min_margin,
               notes=traj.notes)
    if simulate:
        from snakehead.sim import compare, simulate_trajectory

        clock = time.perf_counter()
        result = simulate_trajectory(plan.robot, traj.t, traj.q, plan.base, obstacles=list(plan.obstacles))
        targets = [(float(traj.waypoint_times[k]), p, d) for k, p, d in sc["targets"]]
        m = compare(plan.robot, traj.t, traj.q, result, targets=targets, base=plan.base)
        row.update(sim_s=time.perf_counter() - clock, position_mm=1000 * m["position_error_m"],
                   direction_deg=m["direction_error_deg"], zmp_inside=m["zmp_inside"],
                   zmp_sim_mm=1000 * m["zmp_min_margin_m"], slide_mm=1000 * m["base_slide_m"],
                   dP=m["max_linear_momentum_magnitude_error"], dL=m["max_angular_momentum_magnitude_error"],
                   torque=m["max_torque_nm"])
    return row


class SolveClock:
    """Wraps a grid solver (gridpoints.solve_grid's signature): the run time and gridpoints of each call."""

    def __init__(self, solve: Callable) -> None:
        self.solve, self.times, self.points = solve, [], []

    def __call__(self, robot: Any, points: Any, limits: Any) -> Any:
        clock = time.perf_counter()
        out = self.solve(robot, points, limits)
        self.times.append(time.perf_counter() - clock)
        self.points.append(len(points.s))
        return out


def solver_rows(name: str, sc: dict, repeats: int) -> list[str]:
    """toppra (the code the core replaced: tests/topp_reference.py) and the core's TOPP-RA on the scenario's path
    and on its whole plan, in this run: per grid solve (median), all solves, the retime (without the check of every
    sample, as the planner calls it), the motion, the plan (the fastest of the repeats, at most 3)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from topp_reference import toppra_solve_grid, toppra_solver

    plan = sc["plan"]
    holds, stops = np.diff(sc["times"]), [k for k, _, _ in sc["targets"]]
    rows = []
    for solver, solve in (("toppra", toppra_solve_grid), ("core", gridpoints.solve_grid)):
        best: dict = {}
        for _ in range(repeats):  # the fastest of the repeats (the machine is shared)
            clock_ = SolveClock(solve)
            with toppra_solver(clock_):
                start = time.perf_counter()
                traj = timing.retime(plan.robot, sc["q"], plan.base, hold_s=holds, stops=stops, check_samples=False)
                total = time.perf_counter() - start
            if not best or total < best["total"]:
                best = dict(total=total, clock=clock_, duration=traj.duration)
        plan_s = np.inf
        for _ in range(min(repeats, 3)):
            with toppra_solver(solve) if solver == "toppra" else contextlib.nullcontext():
                start = time.perf_counter()
                full = snakehead.plan(paper_scene(name))
                plan_s = min(plan_s, time.perf_counter() - start)
        c = best["clock"]
        rows.append(f"| {name} | {solver} | {len(c.times)} | {int(np.median(c.points))} | "
                    f"{1000 * statistics.median(c.times):.1f} | {1000 * sum(c.times):.0f} | {1000 * best['total']:.0f} | "
                    f"{best['duration']:.3f} | {plan_s:.2f} | {full.duration_s:.2f} |")
    return rows


def binds(check) -> str:
    shares = sorted(check.binding.items(), key=lambda kv: -kv[1])
    return ", ".join(f"{k} {100 * v:.0f} %" for k, v in shares if v >= 0.01) or "-"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", nargs="+", default=["spheres", "hole"])
    ap.add_argument("--accelerations", nargs="+", type=float, default=[0.5, 1.0, 2.0, 4.0],
                    help="joint acceleration limits to sweep (rad/s^2)")
    ap.add_argument("--velocity-shares", nargs="+", type=float, default=[0.5, 1.0],
                    help="shares of the URDF's velocity limits to sweep")
    ap.add_argument("--zmp-margins", nargs="+", type=float, default=[timing.ZMP_MARGIN], help="m, swept")
    ap.add_argument("--friction", type=float, default=timing.FRICTION)
    ap.add_argument("--no-sim", action="store_true", help="skip MuJoCo")
    ap.add_argument("--solvers", action="store_true",
                    help="also compare toppra and the core's TOPP-RA side by side (needs toppra: the test extra)")
    ap.add_argument("--repeats", type=int, default=3, help="retimes per solver in --solvers (the fastest counts)")
    ap.add_argument("--interpolations", nargs="*", default=["monotone", "spline"],
                    help="paths compared at the default limits")
    args = ap.parse_args()
    print(f"{time.strftime('%Y-%m-%d %H:%M')}, {cpu_name()} ({os.cpu_count()} CPU), load average "
          f"{os.getloadavg()[0]:.1f}, Python {platform.python_version()}")
    scenarios = {name: scenario(name) for name in args.scenarios}
    for name, sc in scenarios.items():
        line = (f"\n{name}: {len(sc['q'])} states, fixed-speed plan {sc['plan'].duration_s:.1f} s "
                f"(planned in {sc['plan_s']:.1f} s)")
        if not args.no_sim:
            fixed = snakehead.simulate(sc["plan"])
            line += (f", simulated head error {1000 * fixed.position_error_m:.2f} mm / "
                     f"{fixed.direction_error_deg:.3f} deg, ZMP inside {fixed.zmp_inside}")
        print(line + f"; the paper's {PAPER[name]['duration']:.0f} s, {PAPER[name]['position_mm']} mm / "
              f"{PAPER[name]['direction_deg']} deg", flush=True)

    if args.solvers:
        print("\n### TOPP-RA: toppra (seidel) against the core, the scenario's states retimed at the default limits "
              f"(fastest of {args.repeats}; retime without the sample check)\n")
        print("| scenario | solver | grid solves | gridpoints (median) | per solve (ms, median) | all solves (ms) | "
              "retime (ms) | motion (s) | whole plan (s) | plan's motion (s) |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for name, sc in scenarios.items():
            for row in solver_rows(name, sc, args.repeats):
                print(row, flush=True)

    print(f"\n### Limits swept (monotone path; torque {timing.TORQUE_SHARE} x URDF effort; friction {args.friction})\n")
    head = ("| scenario | acc (rad/s^2) | vel (x URDF) | ZMP margin (mm) | duration (s) | retime (s) | binds | planned ZMP (mm) |"
            + ("" if args.no_sim else " head error (mm / deg) | sim ZMP inside (min mm) | slide (mm) | "
               "dP / dL error | max torque (N m) | within the paper's |"))
    print(head)
    print("|" + "|".join("---" for _ in head.split("|")[1:-1]) + "|")
    for name, sc in scenarios.items():
        for zm in args.zmp_margins:
            for vs in args.velocity_shares:
                for acc in args.accelerations:
                    row = run(name, sc, simulate=not args.no_sim, acceleration_limit=acc,
                              velocity_limit=vs * sc["plan"].robot.velocity_limit, zmp_margin=zm,
                              friction=args.friction)
                    line = (f"| {name} | {acc:g} | {vs:g} | {1000 * zm:g} | {row['duration']:.2f} | "
                            f"{row['solve_s']:.1f} | {binds(row['check'])} | {row['zmp_planned_mm']:.1f} |")
                    if not args.no_sim:
                        p = PAPER[name]
                        ok = (row["duration"] <= p["duration"] and row["position_mm"] <= p["position_mm"]
                              and row["direction_deg"] <= p["direction_deg"] and row["zmp_inside"])
                        line += (f" {row['position_mm']:.2f} / {row['direction_deg']:.3f} | "
                                 f"{'yes' if row['zmp_inside'] else 'no'} ({row['zmp_sim_mm']:.2f}) | "
                                 f"{row['slide_mm']:.2f} | {row['dP']:.3f} / {row['dL']:.4f} | {row['torque']:.2f} | "
                                 f"{'yes' if ok else 'no'} |")
                    print(line, flush=True)

    if not args.interpolations:
        return
    print("\n### Path through the waypoints (default limits)\n")
    print("| scenario | path | duration (s) | retime (s) | worst velocity / acceleration / torque (x limit) |")
    print("|---|---|---|---|---|")
    for name, sc in scenarios.items():
        for interp in args.interpolations:
            try:
                row = run(name, sc, simulate=False, interpolation=interp)
            except ValueError as exc:
                print(f"| {name} | {interp} | - | - | {exc} |")
                continue
            c = row["check"]
            print(f"| {name} | {interp} | {row['duration']:.2f} | {row['solve_s']:.1f} | "
                  f"{c.velocity_ratio:.3f} / {c.acceleration_ratio:.3f} / {c.torque_ratio:.3f} |")


if __name__ == "__main__":
    main()
