"""Servo gains in MuJoCo: the former uniform defaults (kp = 200 N m/rad, kd = 3 N m s/rad on every joint) against
the gains derived per joint from its load (``snakehead.sim.gains``), on the default robot and generated snakes from
light and short to heavy and long.

Three motions per robot, each simulated with both gain sets (PD + support-aware gravity compensation, 2 ms
control, 1 ms physics, the URDF's effort as torque limit):

* hold: the robot's initial configuration (base on its arc, neck and head raised) held 1 s: base slide, joint error;
* sway: the head joints sway +-0.12 rad about it (sin^2 over 2 s) then hold 0.3 s: head error at mid-sway and held;
* ground: lying flat, the yaw joints follow a travelling wave (0.5 rad, 0.5 Hz, one wave per body) for 2 s:
  the largest joint error (the joints drag the body over the ground against friction 0.8).

    python3 bench/sim_gains.py [--robots default,twenty,...]
"""
from __future__ import annotations

import argparse
import math
import platform
import time

import numpy as np
from _robots import ROBOTS  # bench/_robots.py

from snakehead import sim
from snakehead.backbone import initial_configuration
from snakehead.dynamics import stability


def sway(robot, q1, amplitude=0.12, period=2.0, dt=0.002):
    n = robot.n_joints
    head = np.arange(n) >= robot.parts.head.start
    delta = np.where(head, amplitude * np.where(np.arange(n) % 2 == 0, 1.0, -1.0), 0.0)
    t = np.arange(0.0, period + 1e-9, dt)
    q = np.clip(q1 + np.sin(np.pi * t / period)[:, None] ** 2 * delta, robot.lower, robot.upper)
    margin = min(stability.static_margin(robot, qk) for qk in q[::50])
    return t, q, margin


def ground_wave(robot, amplitude=0.5, frequency=0.5, duration=2.0, dt=0.002):
    t = np.arange(0.0, duration + 1e-9, dt)
    yaw = np.array([k == "yaw" for k in robot.joint_kinds])
    s = robot.joint_arc_lengths / robot.body_length
    ramp = np.clip(t / 0.5, 0.0, 1.0)[:, None]
    return t, ramp * amplitude * np.sin(2 * np.pi * (frequency * t[:, None] - s[None, :])) * yaw


def measure(robot, kp, kd):
    out = {}
    q1 = initial_configuration(robot)
    res = sim.simulate_trajectory(robot, np.array([0.0, 1.0]), np.array([q1, q1]), kp=kp, kd=kd)
    out["hold_slide_mm"] = 1e3 * res.base_slide_m
    out["hold_dq_deg"] = math.degrees(np.abs(res.q - res.q_ref).max())
    t, q, margin = sway(robot, q1)
    if margin > 0.005:
        res = sim.simulate_trajectory(robot, t, q, kp=kp, kd=kd, hold=0.3)
        rep = sim.compare(robot, t, q, res, targets=[t[-1] / 2, t[-1] + 0.3])
        out["sway_mid_mm"], out["sway_held_mm"] = (1e3 * e for e in rep["position_errors_m"])
        out["sway_deg"] = rep["direction_error_deg"]
    else:
        out["sway_mid_mm"] = out["sway_held_mm"] = out["sway_deg"] = float("nan")
    t, q = ground_wave(robot)
    res = sim.simulate_trajectory(robot, t, q, kp=kp, kd=kd)
    out["ground_dq_deg"] = math.degrees(np.abs(res.q - res.q_ref).max())
    out["ground_saturated"] = res.saturation_fraction
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", default=",".join(ROBOTS))
    args = ap.parse_args()
    print("| robot | gains | kp (N m/rad) | hold: slide (mm) | hold: joints (deg) | sway: head moving / held (mm) "
          "| sway: direction (deg) | ground: joints (deg) | ground: torque saturated |")
    print("|---|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for key in args.robots.split(","):
        label, make = ROBOTS[key]
        robot = make()
        derived_kp, derived_kd = sim.gains.default_gains(robot, armature=1e-3)
        for name, kp, kd in (("uniform 200 / 3", 200.0, 3.0), ("derived", derived_kp, derived_kd)):
            m = measure(robot, kp, kd)
            kps = f"{np.min(kp):.3g}-{np.max(kp):.3g}" if np.ndim(kp) else f"{kp:g}"
            print(f"| {key} ({label}) | {name} | {kps} | {m['hold_slide_mm']:.3f} | {m['hold_dq_deg']:.3f} | "
                  f"{m['sway_mid_mm']:.2f} / {m['sway_held_mm']:.2f} | {m['sway_deg']:.3f} | {m['ground_dq_deg']:.2f} | "
                  f"{m['ground_saturated']:.3f} |", flush=True)
    print(f"\n{time.perf_counter() - t0:.0f} s wall; {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}")


if __name__ == "__main__":
    main()
