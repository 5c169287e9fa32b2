"""Self-collision speed: ``snakehead.geometry.collision.self_clearance`` (the separating-axis test in the C++ core,
``snakehead._core.box_pair_gaps``) against the numpy reference it replaced (tests/sat_reference.py), side by side
in one run, for T = 1, 100 and 1000 configurations of the default robot and of a generated 30-joint snake.
Prints a markdown table: best and median wall-clock time per call (ms), the speed-up, and how much of the C++
call is the forward kinematics both share (``robot.frames_many``). Not a test.

    python3 bench/collision.py [--repeat 15]
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from snakehead import SnakeRobot
from snakehead.app.report import cpu_name
from snakehead.geometry import collision as coll

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import sat_reference as ref  # noqa: E402  (the numpy reference lives with the tests)
from _robots import generated  # noqa: E402


def timed(fn, repeat: int) -> tuple[float, float]:
    """Best and median wall-clock time (ms) of ``fn()`` over ``repeat`` runs, after one warm-up run."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times), 1e3 * float(np.median(times))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=15, help="timed runs per cell (default 15)")
    args = ap.parse_args()
    robots = {"default (16 joints)": SnakeRobot.default(), "generated (30 joints)": generated(30, 0.15, 0.08, 0.5)}
    load_before = os.getloadavg()
    rows = []
    for name, robot in robots.items():
        rng = np.random.default_rng(0)
        for T in (1, 100, 1000):
            qs = np.array([robot.body.random_configuration(rng) for _ in range(T)])
            np.testing.assert_allclose(coll.self_clearance(robot, qs), ref.self_clearance(robot, qs), atol=1e-12)
            k = len(robot.boxed_links)
            pairs = (k - 1) * (k - 2) // 2
            numpy_best, numpy_med = timed(lambda: ref.self_clearance(robot, qs), args.repeat)
            cpp_best, cpp_med = timed(lambda: coll.self_clearance(robot, qs), args.repeat)
            fk_best, _ = timed(lambda: robot.frames_many(qs), args.repeat)
            rows.append((name, T, pairs, numpy_best, numpy_med, cpp_best, cpp_med, numpy_med / cpp_med,
                         100 * fk_best / cpp_best))
    load_after = os.getloadavg()
    print(f"# self_clearance, {time.strftime('%Y-%m-%d')}, {cpu_name()}, {os.cpu_count()} cores, load average "
          f"{load_before[0]:.1f} before, {load_after[0]:.1f} after; best / median of {args.repeat} runs (ms)\n")
    print("| robot                 |    T | pairs | numpy best | numpy median | C++ best | C++ median | speed-up (median) | FK share of C++ call |")
    print("|-----------------------|-----:|------:|-----------:|-------------:|---------:|-----------:|------------------:|---------------------:|")
    for name, T, pairs, nb, nm, cb, cm, speedup, fk in rows:
        print(f"| {name:21s} | {T:4d} | {pairs:5d} | {nb:10.3f} | {nm:12.3f} | {cb:8.3f} | {cm:10.3f} | "
              f"{speedup:17.1f} | {fk:19.0f} % |")


if __name__ == "__main__":
    main()
