"""Dynamics check demo: raise the default robot's head in MuJoCo and compare with the plan (paper Section 4).

Plan (joint space, on the default robot, base at BasePlacement()): from a flat curled pose (base arc of yaw
joints at 0.879 rad, neck turned inwards, all pitch joints 0) the head part rises to a pose 0.42 m high (target A,
hold), then moves its head to a second pose (target B, hold). Both lifted poses and the joint-space path between
them keep the CoM inside the base's support polygon. The plan is interpolated by
``snakehead.trajectory.interpolation.joint_interpolation`` at 2 ms (quintic segments if that module is absent), then tracked by
``snakehead.sim.simulate_trajectory`` (PD + support-aware gravity compensation, 2 ms control, 1 ms physics), and compared
with ``snakehead.sim.compare``. Prints the table; writes the three figures with ``--out``.

    python3 bench/sim_demo.py [--out DIR] [--kp 200 --kd 3] [--torque-limit 10]   # gains default: per joint
"""
from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from snakehead import BasePlacement, SnakeRobot, sim
from snakehead.dynamics import stability
from snakehead.sim import tracking

Q_A = np.array([0.879, 0.0, 0.879, 0.0, 0.879, 0.0, 0.879, 0.0,
                1.485, -1.208, 0.151, -0.2, 0.292, 0.977, -0.451, 0.599])
Q_B = Q_A + np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 0.15, 0.3, 0.1, -0.3, -0.2, 0.3, 0.2])
PITCH = [7, 9, 11, 13, 15]

PAPER = {  # Section 4: spheres / hole
    "position_error_m": (1.8e-3, 1.39e-3),
    "direction_error_deg": (0.76, 0.95),
    # "the maximum errors of the angular and linear momentum magnitudes": beside our magnitude rows
    "max_angular_momentum_magnitude_error": (0.0383, 0.0416),
    "max_linear_momentum_magnitude_error": (0.216, 0.195),
    "zmp_inside": (True, True),
}


def plan(dt: float = 0.002):
    q0 = Q_A.copy()
    q0[PITCH] = 0.0
    times = [0.0, 4.0, 5.0, 8.0, 9.0]
    waypoints = np.array([q0, Q_A, Q_A, Q_B, Q_B])
    try:
        from snakehead.trajectory.interpolation import joint_interpolation
        t, q = joint_interpolation(times, waypoints, dt=dt)
        how = "snakehead.trajectory.interpolation.joint_interpolation"
    except (ImportError, AttributeError):
        ts, qs = [np.zeros(1)], [waypoints[:1]]
        for k in range(len(times) - 1):
            T = times[k + 1] - times[k]
            tt = np.arange(dt, T + 1e-9, dt)
            s = tt / T
            h = 10 * s**3 - 15 * s**4 + 6 * s**5
            ts.append(times[k] + tt)
            qs.append(waypoints[k] + h[:, None] * (waypoints[k + 1] - waypoints[k]))
        t, q = np.concatenate(ts), np.vstack(qs)
        how = "quintic segments (bench/sim_demo.py)"
    return t, q, times, how


def gain_text(values) -> str:
    values = np.asarray(values, float)
    return f"{values[0]:g}" if np.all(values == values[0]) else f"{values.min():.3g}..{values.max():.3g} (per joint)"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="directory for the figures (PNG)")
    ap.add_argument("--kp", type=float, default=None, help="N m/rad, every joint (default: per joint, sim.gains)")
    ap.add_argument("--kd", type=float, default=None, help="N m s/rad, every joint (default: per joint, sim.gains)")
    ap.add_argument("--torque-limit", type=float, default=10.0,
                    help="N m; the URDF's 3 N m cannot lift the head part (see RESULTS.md)")
    ap.add_argument("--gravity-compensation", default="supported", choices=tracking.GRAVITY_COMPENSATION)
    args = ap.parse_args()

    robot = SnakeRobot.default()
    base = BasePlacement()
    t, q, times, how = plan()
    ds = stability.dynamic_stability(robot, t, q, base)
    print(f"plan: {len(t)} samples, {t[-1]:.1f} s, {how}; planned ZMP min margin {ds.min_margin * 1e3:.1f} mm "
          f"(endpoints polygon), head A at {robot.head_pose(Q_A, base)[:3, 3].round(3)}, "
          f"B at {robot.head_pose(Q_B, base)[:3, 3].round(3)}")
    t0 = time.perf_counter()
    res = sim.simulate_trajectory(robot, t, q, base, kp=args.kp, kd=args.kd, torque_limit=args.torque_limit,
                       gravity_compensation=args.gravity_compensation)
    wall = time.perf_counter() - t0
    rep = sim.compare(robot, t, q, res, targets=[times[2], times[4]])
    print(f"simulated {res.t[-1] - res.t[0]:.1f} s in {wall:.2f} s wall "
          f"({len(res.t)} control ticks of {res.settings['control_dt'] * 1e3:.0f} ms, "
          f"physics {res.settings['timestep'] * 1e3:.0f} ms); kp {gain_text(res.settings['kp'])} N m/rad, kd {gain_text(res.settings['kd'])} N m s/rad, "
          f"torque limit {args.torque_limit} N m, gravity compensation {args.gravity_compensation}")
    print()
    print(f"| {'quantity':<40} | {'ours':>12} | {'paper spheres':>13} | {'paper hole':>10} |")
    print(f"|{'-' * 42}|{'-' * 14}|{'-' * 15}|{'-' * 12}|")

    def row(label, key, scale=1.0, fmt="{:.3f}"):
        ours = rep[key]
        ours_s = str(ours) if isinstance(ours, bool) else fmt.format(ours * scale)
        p = PAPER.get(key)
        ps = ["-", "-"] if p is None else [str(v) if isinstance(v, bool) else fmt.format(v * scale) for v in p]
        print(f"| {label:<40} | {ours_s:>12} | {ps[0]:>13} | {ps[1]:>10} |")

    row("head position error (mm), max of A, B", "position_error_m", 1e3, "{:.2f}")
    row("head direction error (deg), max of A, B", "direction_error_deg", 1.0, "{:.2f}")
    row("max |L_sim - L_plan| (kg m^2/s)", "max_angular_momentum_error", 1.0, "{:.4f}")
    row("max ||L_sim| - |L_plan|| (kg m^2/s)", "max_angular_momentum_magnitude_error", 1.0, "{:.4f}")
    row("max |P_sim - P_plan| (kg m/s)", "max_linear_momentum_error", 1.0, "{:.4f}")
    row("max ||P_sim| - |P_plan|| (kg m/s)", "max_linear_momentum_magnitude_error", 1.0, "{:.4f}")
    row("simulated ZMP inside support polygon", "zmp_inside")
    row("ZMP min margin (mm, footprint polygon)", "zmp_min_margin_m", 1e3, "{:.1f}")
    row("base slide (mm)", "base_slide_m", 1e3, "{:.2f}")
    row("base lift (mm)", "base_lift_m", 1e3, "{:.2f}")
    row("max joint torque (N m)", "max_torque_nm", 1.0, "{:.2f}")
    row("torque saturation (fraction of samples)", "torque_saturation_fraction", 1.0, "{:.4f}")
    print()
    print("per target: position (mm)", np.round(np.array(rep["position_errors_m"]) * 1e3, 2).tolist(),
          "direction (deg)", np.round(rep["direction_errors_deg"], 2).tolist())
    print("peak |tau| per joint (N m):", np.abs(res.tau).max(axis=0).round(2).tolist())
    print(f"machine: {platform.processor() or platform.machine()}, {platform.system()}, "
          f"python {platform.python_version()}")
    if args.out:
        from pathlib import Path

        from snakehead.viz import dynamics_figures as dynamics
        from snakehead.viz import save

        P, L = stability.momenta(robot, t, q, base)
        for name, fig in (("sim_momenta", dynamics.plot_momenta(t, P, L, simulated=res)),
                          ("sim_zmp", dynamics.plot_zmp(robot, t, q, base=base, simulated=res, contact="footprint"))):
            print("wrote", save(fig, Path(args.out) / f"{name}.png"))


if __name__ == "__main__":
    main()
