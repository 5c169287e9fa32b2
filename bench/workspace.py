"""Reachability maps: Table 2, the sweep against the previous release, agreement with slow runs, queries.

    python bench/workspace.py --previous PREV/workspace_gen     # everything (about 25 min on 2 cores)
    python bench/workspace.py --only table2                     # the shipped maps against the paper (instant)

PREV/workspace_gen is the previous release's sweep, built apart, e.g.
    git worktree add /tmp/prev a81ff88 && cmake -S /tmp/prev -B /tmp/prev/build -DSNAKEHEAD_BUILD_TESTS=OFF \
        && cmake --build /tmp/prev/build --target workspace_gen

Prints markdown tables (paste them into bench/RESULTS.md). Sections:
  table2     the shipped 7-DOF and 6-DOF maps (the paper's boundary) against the paper's Table 2, and G0
  sweep      the previous release's workspace_gen and this one's, one after the other on all cores, with the same
             options and the convex hull (so both evaluate the same voxels): the target map (7-DOF head, 0.05 m,
             20 directions x 4 rolls, 0.3 ms) and the shipped maps' options (20 x 10 rolls, 1 ms); then this
             one's shipped 7-DOF map as shipped (the boundary)
  agreement  both target maps against one independent slow run (each voxel alone, every frame from random
             guesses, 5 ms per IK call) on the same random voxels
  queries    reachable() of the shipped 7-DOF maps (the Table 2 map and the poses map) against TRAC-IK (roll free,
             3 starts of 20 ms) on random poses inside their voxels: agreement, false positives and negatives;
             time per pose in a batch of 100,000
  inverse    time of inverse() and base_placements() per target, and how often the best placement's head
             reaches the target by TRAC-IK
"""
from __future__ import annotations

import argparse
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from snakehead import SnakeRobot, TracIK, default_robot_file
from snakehead import sweep_defaults as defaults
from snakehead.app.report import cpu_name
from snakehead.kinematics import base_placement as bp
from snakehead.kinematics import reachability as ws

ROBOT_FILES = {"head": "snake16.toml", "head6": "snake16_head6.toml"}  # beside the default robot
PAPER = {  # Table 2 and Section 2.2 of the paper
    "head": {"bins": [8.22, 15.87, 16.96, 25.80, 33.15], "max": 100.0, "above90": 14.79, "at100": 3.69},
    "head6": {"bins": [29.82, 31.28, 28.14, 10.76, 0.0], "max": 76.0, "above90": 0.0, "at100": 0.0},
}
TARGET = dict(voxel=defaults.HEAD_VOXEL_M, directions=defaults.HEAD_DIRECTIONS, rolls=defaults.HEAD_ROLLS,
              timeout=defaults.HEAD_TIMEOUT_S)  # the defaults of a head map
SHIPPED = dict(voxel=0.05, directions=20, rolls=10, timeout=1e-3)
FREE_ROLL = [0.0, 0.0, 0.0, np.inf, 0.0, 0.0]


def machine() -> str:
    return f"{cpu_name()}, {os.cpu_count()} cores, Python {platform.python_version()}"


def shipped_map(part: str) -> ws.ReachabilityMap:
    return ws.map_for(SnakeRobot.from_file(default_robot_file().with_name(ROBOT_FILES[part])))


def table2() -> None:
    print("\n### Table 2: the shipped maps against the paper\n")
    print("| head | voxels | [0,20) | [20,40) | [40,60) | [60,80) | [80,100] | max | > 90 | = 100 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for part, label in (("head", "7 DOF"), ("head6", "6 DOF")):
        m = shipped_map(part)
        _, pct = m.histogram()
        d = m.indices
        print(f"| {label} (ours) | {len(m)} | " + " | ".join(f"{p:.2f} %" for p in pct)
              + f" | {d.max():.0f} | {100 * np.mean(d > 90):.2f} % | {100 * np.mean(d >= 100):.2f} % |")
        p = PAPER[part]
        print(f"| {label} (paper) | | " + " | ".join(f"{x:.2f} %" for x in p["bins"])
              + f" | {p['max']:.0f} | {p['above90']:.2f} % | {p['at100']:.2f} % |")
        print(f"| {label}: ours - paper | | " + " | ".join(f"{a - b:+.2f}" for a, b in zip(pct, p["bins"])) + " | | | |")
    for part in ("head", "head6"):
        m = shipped_map(part)
        print(f"\n{part}: hull {m.params['hull']}, shrink {m.params['shrink']}, alpha {m.stats['alpha']:.4f} m, "
              f"{m.stats['hull_facets']} boundary triangles, {len(m)} voxels; made by `{m.command}`")
    c = shipped_map("head").clusters(k=3)
    print(f"\nG0 of the 7-DOF head (rule '{c.rule}', neck_end frame): {np.round(c.center, 4).tolist()} m; "
          f"cluster sizes {c.sizes.tolist()}; centroids {np.round(c.centroids, 3).tolist()}")


def run_gen(exe: str, out: Path, base: str, options: dict, extra=()) -> tuple[float, float]:
    """(wall s, CPU s of the child) of one workspace_gen run."""
    args = [exe, "--urdf", str(default_robot_file().with_name("snake16.urdf")), "--base", base, "--tip", "head_tip",
            "--out", str(out), "--quiet", "--voxel", str(options["voxel"]), "--directions", str(options["directions"]),
            "--rolls", str(options["rolls"]), "--timeout", str(options["timeout"]), *extra]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(args, check=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def sweep(previous: str, folder: Path) -> dict:
    new = str(Path(sys.executable).with_name("workspace_gen"))
    print("\n### The sweep: the previous release and this one, one after the other (7-DOF head, all cores)\n")
    print("| options | hull | release | voxels | IK calls | wall time | CPU time | mean index | wall ratio | CPU ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    maps = {}
    labels = {"target": TARGET, "shipped": SHIPPED}
    for name, options in ((f"{label}: {o['directions']} x {o['rolls']} rolls, {o['timeout'] * 1e3:g} ms", o)
                          for label, o in labels.items()):
        rows = {}
        for release, exe, extra in (("previous", previous, ()), ("this", new, ("--hull", "convex"))):
            out = folder / f"{release}-{options['rolls']}.npz"
            wall, cpu = run_gen(exe, out, "neck_end", options, extra)
            m = ws.load(out)
            rows[release] = (wall, cpu, m)
            maps[(release, options["rolls"])] = m
        for release in ("previous", "this"):
            wall, cpu, m = rows[release]
            ratio = "" if release == "previous" else (f"{rows['previous'][0] / wall:.2f} x | "
                                                       f"{rows['previous'][1] / cpu:.2f} x")
            print(f"| {name} | convex | {release} | {len(m)} | {m.stats['ik_calls']} | {wall:.1f} s | {cpu:.1f} s | "
                  f"{m.indices.mean():.2f} | {ratio or ' | '} |")
    wall, cpu = run_gen(new, folder / "this-boundary.npz", "neck_end", SHIPPED)
    m = ws.load(folder / "this-boundary.npz")
    print(f"| shipped: 20 x 10 rolls, 1 ms | boundary | this | {len(m)} | {m.stats['ik_calls']} | {wall:.1f} s | "
          f"{cpu:.1f} s | {m.indices.mean():.2f} | | |")
    same = maps[("previous", 4)], maps[("this", 4)]
    d = same[1].indices - same[0].indices
    print(f"\nTarget maps, this release - previous, voxel by voxel: mean {d.mean():+.2f}, mean abs {np.abs(d).mean():.2f}, "
          f"max abs {np.abs(d).max():.0f}, within 5: {100 * np.mean(np.abs(d) <= 5):.1f} %")
    return maps


def agreement(robot, maps: dict, samples: int, slow_timeout: float) -> None:
    ref = maps[("previous", 4)]
    rng = np.random.default_rng(2024)
    pick = np.sort(rng.choice(len(ref), size=min(samples, len(ref)), replace=False))
    t0 = time.perf_counter()
    slow = ws.evaluate(robot, ref.centers[pick], voxel=ref.voxel_size, directions=TARGET["directions"],
                       rolls=TARGET["rolls"], timeout=slow_timeout,
                       seed=99)
    wall = time.perf_counter() - t0
    print(f"\n### Agreement of the target maps with a slow run ({len(pick)} random voxels, each alone, every frame "
          f"from random guesses, {slow_timeout * 1e3:g} ms per IK call; {wall:.0f} s)\n")
    print("| release | mean index (map) | mean index (slow) | mean map - slow | mean abs diff | max abs diff | "
          "within 5 | within 10 | correlation |")
    print("|---|---|---|---|---|---|---|---|---|")
    for release in ("previous", "this"):
        m = maps[(release, 4)]
        fast = m.indices[np.searchsorted(m.voxel_ids, ref.voxel_ids[pick])]
        diff = fast - slow
        print(f"| {release} | {fast.mean():.2f} | {slow.mean():.2f} | {diff.mean():+.2f} | {np.abs(diff).mean():.2f} | "
              f"{np.abs(diff).max():.0f} | {100 * np.mean(np.abs(diff) <= 5):.1f} % | "
              f"{100 * np.mean(np.abs(diff) <= 10):.1f} % | {np.corrcoef(fast, slow)[0, 1]:.4f} |")


def random_poses(m: ws.ReachabilityMap, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """Positions uniform in the map's voxels (inside its hull), directions uniform on the sphere."""
    rows = rng.integers(0, len(m), n)
    p = m.centers[rows] + rng.uniform(-0.5, 0.5, (n, 3)) * m.voxel_size
    d = rng.normal(size=(n, 3))
    return p, d / np.linalg.norm(d, axis=1, keepdims=True)


def queries(robot, n: int) -> None:
    maps = {"snake16_head7.npz (20 directions x 10 rolls)": shipped_map("head"),
            "snake16_head7_poses.npz (60 directions, roll free)":
                ws.load(default_robot_file().with_name("snake16_head7_poses.npz"))}
    m = next(iter(maps.values()))
    rng = np.random.default_rng(11)
    p, d = random_poses(m, n, rng)  # the maps share their voxels (the same boundary)
    frames = np.array([ws.approach_frame(a, b) for a, b in zip(p, d)])
    t0 = time.perf_counter()
    truth = np.zeros(n, dtype=bool)
    for seed in (1, 2, 3):  # three independent starts of 20 ms each, roll free
        ik = TracIK.from_chain(robot.head_chain, timeout=0.02, bounds=FREE_ROLL, seed=seed)
        left = np.nonzero(~truth)[0]
        truth[left] = ik.ik_many(frames[left])[1]
    wall = time.perf_counter() - t0
    print(f"\n### reachable() against TRAC-IK ({n} random poses uniform in the shipped 7-DOF maps' voxels, directions "
          f"uniform; TRAC-IK with the roll free, 3 starts of 20 ms: {100 * truth.mean():.1f} % reachable; {wall:.0f} s)\n")
    print("| map | query | agreement | false positives (map yes, IK no) | false negatives (map no, IK yes) |")
    print("|---|---|---|---|---|")
    for label, mm in maps.items():
        for name, kw in (("nearest voxel and direction", {"interpolate": False}), ("interpolated (the default)", {})):
            said = mm.reachable(p, d, **kw)
            print(f"| {label} | {name} | {100 * np.mean(said == truth):.1f} % | {100 * np.mean(said & ~truth):.1f} % | "
                  f"{100 * np.mean(~said & truth):.1f} % |")
    big_p, big_d = random_poses(m, 100_000, rng)
    print("\n| map | query | batch | best of 5 | per pose |")
    print("|---|---|---|---|---|")
    for label, mm in maps.items():
        for name, kw in (("nearest voxel and direction", {"interpolate": False}), ("interpolated (the default)", {})):
            mm.reachable(big_p[:10], big_d[:10], **kw)  # build the map's lookup tables once
            best = min(_timed(lambda: mm.reachable(big_p, big_d, **kw)) for _ in range(5))
            print(f"| {label} | {name} | 100,000 | {1e3 * best:.1f} ms | {1e6 * best / 100_000:.2f} us |")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def inverse(robot, n: int) -> None:
    m = shipped_map("head")
    rng = np.random.default_rng(5)
    t0 = time.perf_counter()
    frames, neck_q = bp.neck_frames(robot)
    prep = time.perf_counter() - t0
    targets = [(np.array([rng.uniform(0.6, 1.2), rng.uniform(-0.4, 0.4), rng.uniform(0.1, 0.5)]),
                rng.normal(size=3)) for _ in range(n)]
    t_inv, t_place, reached, found = [], [], 0, 0
    ik = TracIK.from_chain(robot.head_chain, timeout=0.02, bounds=FREE_ROLL, seed=4)
    from snakehead.backbone.initial import initial_configuration

    q0 = initial_configuration(robot)
    for p, d in targets:
        d = d / np.linalg.norm(d)
        t_inv.append(_timed(lambda: m.inverse(p, d, rolls=8, limit=200)))
        t0 = time.perf_counter()
        c = bp.placements_from_frames(m, frames, neck_q, p, d, limit=20)
        t_place.append(time.perf_counter() - t0)
        if len(c) == 0:
            continue
        found += 1
        q = q0.copy()
        q[robot.parts.neck] = c.neck_q[0]
        B0 = robot.frame(q, robot.parts.neck_end, c.placements()[0])
        reached += ik.ik_ex(np.linalg.solve(B0, ws.approach_frame(p, d)))[0]
    print(f"\n### Inverse reachability ({n} random targets 0.6-1.2 m ahead of the default placement, 0.1-0.5 m high, "
          "random directions; shipped 7-DOF map)\n")
    print("| step | median | max |")
    print("|---|---|---|")
    print(f"| neck frames of the robot (once per robot and base shape: 7 x 7 neck samples) | {1e3 * prep:.0f} ms | |")
    print(f"| map.inverse (200 best (voxel, direction) pairs x 8 turns) | {1e3 * np.median(t_inv):.2f} ms | "
          f"{1e3 * np.max(t_inv):.2f} ms |")
    print(f"| base placements (49 neck samples x 72 yaws, 20 best) | {1e3 * np.median(t_place):.1f} ms | "
          f"{1e3 * np.max(t_place):.1f} ms |")
    print(f"\nTargets with a placement: {found} of {n}; the best placement's head reaches the target by TRAC-IK "
          f"(roll free, 20 ms): {reached} of {found}.")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", choices=["table2", "sweep", "agreement", "queries", "inverse"], action="append")
    ap.add_argument("--previous", help="the previous release's workspace_gen (sweep, agreement)")
    ap.add_argument("--samples", type=int, default=300, help="voxels of the agreement check")
    ap.add_argument("--slow-timeout", type=float, default=5e-3)
    ap.add_argument("--poses", type=int, default=2000, help="poses of the reachable() check")
    ap.add_argument("--targets", type=int, default=50, help="targets of the inverse reachability timing")
    args = ap.parse_args()
    todo = args.only or ["table2", "sweep", "agreement", "queries", "inverse"]
    if ("sweep" in todo or "agreement" in todo) and not args.previous:
        ap.error("the sweep and agreement sections need --previous (the previous release's workspace_gen)")
    robot = SnakeRobot.default()
    print(f"date {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}; load average "
          f"{os.getloadavg()[0]:.2f} at the start")
    if "table2" in todo:
        table2()
    with tempfile.TemporaryDirectory() as tmp:
        maps = sweep(args.previous, Path(tmp)) if ("sweep" in todo or "agreement" in todo) else {}
        if "agreement" in todo:
            agreement(robot, maps, args.samples, args.slow_timeout)
    if "queries" in todo:
        queries(robot, args.poses)
    if "inverse" in todo:
        inverse(robot, args.targets)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
