"""Gaits in MuJoCo: how fast each one moves the body, which way, and how well the robot knows where it went.

Each gait (``snakehead.locomotion.gaits``, default parameters, 0.5 Hz, 1 s ramps) runs ``--cycles`` cycles from the body
lying straight, on the default robot and generated snakes, on the friction ground (``snakehead.closed_loop.GaitSimulator``:
friction 0.8, the servos' gains derived per joint). Per run: the virtual chassis' travel in body lengths per cycle
and its direction in the body's starting frame (+90 deg = to the left), the turn in deg per cycle, the highest box
point, the end tilt of the tail, and the pose estimate's error at the end (joint angles + a perfect IMU on the
mid-body link; contact odometry, ``snakehead.closed_loop.estimate``): root position (mm, and % of the distance the root
went) with the friction-balance odometry (the default) and with no-slip odometry (the same run, the other
estimator), and heading (deg).

    python3 bench/gaits.py [--cycles 3] [--robots default,twenty,pitch_first]
"""
from __future__ import annotations

import argparse
import platform
import time

import numpy as np
from _robots import ROBOTS  # bench/_robots.py

from snakehead import BasePlacement
from snakehead.closed_loop import GaitSimulator
from snakehead.locomotion.gaits import make_gait

RUNS = [("rolling", 1), ("rolling", -1), ("sidewinding", 1), ("sidewinding", -1), ("turning", 1), ("turning", -1),
        ("lateral_undulation", 1)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=float, default=3.0)
    ap.add_argument("--robots", default="default,twenty,pitch_first")
    args = ap.parse_args()
    print("| robot | gait | dir | body lengths / cycle | direction (deg) | turn (deg / cycle) | highest box (mm) "
          "| end tilt (deg) | estimate, friction: position (mm) | (% of root travel) | estimate, no-slip: position (mm) "
          "| (% of root travel) | estimate: heading (deg) | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    t_all = time.perf_counter()
    for key in args.robots.split(","):
        robot = ROBOTS[key][1]()
        sim = GaitSimulator(robot)
        no_slip = GaitSimulator(robot, odometry="no-slip")
        for name, direction in RUNS:
            gait = make_gait(name, direction)
            try:
                gait.check(robot)
            except ValueError as exc:
                print(f"| {key} | {name} | {direction:+d} | cannot run: {exc} |")
                continue
            t0 = time.perf_counter()
            run = sim.run(sim.lying(BasePlacement(0.3, -0.2, 0.7)), gait, args.cycles)
            wall = time.perf_counter() - t0
            other = no_slip.run(no_slip.lying(BasePlacement(0.3, -0.2, 0.7)), gait, args.cycles).estimate_error
            err = run.estimate_error
            root_travel = np.linalg.norm(run.truth.root[:2, 3] - run.start_truth.root[:2, 3])
            print(f"| {key} ({robot.n_joints} j, {robot.body_length:.2f} m) | {name} | {direction:+d} | "
                  f"{run.body_lengths_per_cycle(robot):.3f} | {run.travel_direction_deg:.1f} | "
                  f"{run.turn_deg_per_cycle:.1f} | {1e3 * run.height.max():.0f} | {run.truth.tilt_deg:.1f} | "
                  f"{1e3 * err['position_error_m']:.1f} | {100 * err['position_error_m'] / max(root_travel, 1e-9):.0f} | "
                  f"{1e3 * other['position_error_m']:.1f} | "
                  f"{100 * other['position_error_m'] / max(root_travel, 1e-9):.0f} | "
                  f"{err['yaw_error_deg']:.4f} | {wall:.1f} |", flush=True)
    print(f"\n{time.perf_counter() - t_all:.0f} s wall; {args.cycles:g} cycles at 0.5 Hz with 1 s ramps; "
          f"{platform.processor() or platform.machine()}, python {platform.python_version()}")


if __name__ == "__main__":
    main()
