"""Benchmark: momenta, ZMP and stability along a 36 s trajectory at the 2 ms control period (18,001 samples),
and the trajectory tools. Prints a table (best and median of repeated runs, wall-clock). Not a test.

    python3 bench/stability.py [--repeat 7]
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from snakehead import SnakeRobot
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability as st
from snakehead.geometry.obstacles import BoxObstacle
from snakehead.trajectory import cartesian as cart
from snakehead.trajectory import interpolation as interp


def stable_lift_motion(robot: SnakeRobot) -> tuple[np.ndarray, np.ndarray]:
    """A lift of the head that stays dynamically stable (the default robot's joints): the base curled in a tight
    arc, the neck and head curled on the ground inside it, lifted to stand over the arc (found by maximising the
    static margin of the raised configuration)."""
    q_start = np.zeros(robot.n_joints)
    q_start[0:7:2] = 0.9
    q_end = q_start.copy()
    q_start[8:16:2] = 0.9
    q_end[7:] = [-1.57, 0.266, -0.285, 0.451, -0.173, -0.021, 0.322, 0.051, 0.027]
    return q_start, q_end


def scenario(robot: SnakeRobot):
    """A 36 s, 5-waypoint joint-space motion like the paper's sphere scenario: curl the base tighter (the base
    moves), lift the head (stable_lift_motion), then turn and bend it twice."""
    q0, q1 = stable_lift_motion(robot)
    qa = q0.copy()
    qa[0:7:2] = 0.8
    q2 = q1.copy()
    q2[8] += 0.3
    q2[[10, 12]] += 0.2
    q3 = q1.copy()
    q3[8] -= 0.2
    q3[[9, 11]] += 0.2
    times = np.array([0.0, 6.0, 18.0, 27.0, 36.0])
    return interp.joint_trajectory(times, np.stack([qa, q0, q1, q2, q3]), dt=0.002)


def timeit(fn, repeat: int) -> tuple[float, float]:
    fn()  # warm-up
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return min(ts), float(np.median(ts))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    robot = SnakeRobot.default()
    traj = scenario(robot)
    t, q, qd = traj.t, traj.q, traj.qd
    T = len(t)
    q_moving_base = q.copy()
    q_const_base = q.copy()
    q_const_base[:, robot.parts.base] = q[-1, robot.parts.base]
    box = BoxObstacle([0.3, 0.4, 0.3], [0.1, 0.1, 0.1])
    rows = [
        ("frames_many (C++ FK, all frames)", T, lambda: robot.frames_many(q)),
        ("center_of_mass (Eq. 23)", T, lambda: st.center_of_mass(robot, q)),
        ("momenta_from_velocities, exact qdot (Eqs. 25-31)", T, lambda: st.momenta_from_velocities(robot, q, qd)),
        ("momenta, qdot by np.gradient", T, lambda: st.momenta(robot, t, q)),
        ("zmp (momenta + Eqs. 36-40)", T, lambda: st.zmp(robot, t, q)),
        ("dynamic_stability, fixed base", T, lambda: st.dynamic_stability(robot, t, q_const_base)),
        ("dynamic_stability, moving base (endpoints)", T, lambda: st.dynamic_stability(robot, t, q_moving_base)),
        ("dynamic_stability, moving base (footprint)", T,
         lambda: st.dynamic_stability(robot, t, q_moving_base, contact="footprint")),
        ("joint_trajectory (quintic spline, 2 ms)", T,
         lambda: interp.joint_trajectory([0, 6, 18, 27, 36], q[[0, 3000, 9000, 13500, -1]])),
        ("ground_clearance", T, lambda: coll.ground_clearance(robot, q)),
        ("collision_check, one box obstacle", T, lambda: coll.collision_check(robot, q, box)),
        ("cartesian_interpolation (Eqs. 41-44)", 1000,
         lambda: cart.cartesian_interpolation(robot, q[9000], q[-1], 1000)),
    ]
    print(f"machine: {platform.machine()} {platform.processor() or ''} {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}, numpy {np.__version__}")
    print(f"trajectory: {t[-1]:.0f} s at {1000 * (t[1] - t[0]):.0f} ms = {T} samples; repeat {args.repeat}\n")
    print(f"| {'operation':<50} | {'samples':>7} | {'best (ms)':>9} | {'median (ms)':>11} |")
    print(f"|{'-' * 52}|{'-' * 9}|{'-' * 11}|{'-' * 13}|")
    for name, n, fn in rows:
        best, med = timeit(fn, args.repeat)
        print(f"| {name:<50} | {n:>7} | {1000 * best:>9.1f} | {1000 * med:>11.1f} |")
    res = st.dynamic_stability(robot, t, q_moving_base)
    low = coll.ground_clearance(robot, q)[:, robot.lifted_links].min(axis=1)
    print(f"\nscenario: dynamically stable={res.stable}, min ZMP margin {res.min_margin * 1000:.1f} mm "
          f"at t = {t[res.argmin]:.2f} s; lowest neck/head box point {low.min() * 1000:.1f} mm "
          f"at t = {t[np.argmin(low)]:.2f} s (joint-space lift)")


if __name__ == "__main__":
    main()
