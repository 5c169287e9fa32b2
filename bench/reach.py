"""The whole body's stable reachability map (snakehead reach) of the default robot: its time on one process and on
a local Dask cluster of 1, 2 and 4 workers (one thread each), and the agreement of full plans with it.

The one process's core uses every core in TRAC-IK's batches (snakehead.core_threads()); a Dask worker's core uses
one thread (Dask's workers set OMP_NUM_THREADS=1, which snakehead.threads follows), so the workers share the cores.
Dask's worker profiler is off (it costs ~7 % here).

    python bench/reach.py [--voxel 0.1] [--directions 12] [--workers 1 2 4] [--check 100] [--unpruned]

--unpruned adds a one-process run that solves every pose (compute_reach(prune=False): the map before the prunes of
solve.pose_bounds), side by side; every map must be equal to the first.

Prints a Markdown table. More workers than cores shows the overhead, not a speed-up (say how many cores there are).
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

import snakehead as sh
from snakehead import sweep_defaults as defaults
from snakehead.planning import whole_body_reach as reach


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--voxel", type=float, default=defaults.REACH_VOXEL_M)
    ap.add_argument("--directions", type=int, default=defaults.REACH_DIRECTIONS)
    ap.add_argument("--workers", type=int, nargs="*", default=[1, 2, 4])
    ap.add_argument("--check", type=int, default=100)
    ap.add_argument("--no-serial", action="store_true", help="skip the one-process run")
    ap.add_argument("--unpruned", action="store_true", help="also one process without the prunes")
    args = ap.parse_args()
    robot = sh.SnakeRobot.default()
    grid = reach.reach_grid(robot, args.voxel, args.directions)
    print(f"default robot, voxel {args.voxel} m, {args.directions} directions: {len(grid.ids)} voxels, at most "
          f"{reach.estimated_solves(robot, grid)} whole-body solves; {os.cpu_count()} cores; load "
          f"{os.getloadavg()[0]:.1f}\n")
    rows, maps = [], []
    if not args.no_serial:
        t = time.perf_counter()
        maps.append(reach.compute_reach(robot, voxel=args.voxel, directions=args.directions))
        rows.append((f"1 process ({sh.core_threads()} core thread{'' if sh.core_threads() == 1 else 's'})",
                     time.perf_counter() - t))
    if args.unpruned:
        t = time.perf_counter()
        maps.append(reach.compute_reach(robot, voxel=args.voxel, directions=args.directions, prune=False))
        rows.append(("1 process, unpruned (every pose solved)", time.perf_counter() - t))
    import dask
    from distributed import Client, LocalCluster

    # Dask's statistical profiler samples each worker's stack every 10 ms under the GIL: ~7 % of these runs' time
    dask.config.set({"distributed.worker.profile.enabled": False})
    for w in args.workers:
        with LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            threads = ",".join(map(str, sorted(set(client.run(sh.core_threads).values()))))  # imports snakehead there
            t = time.perf_counter()
            maps.append(reach.compute_reach(robot, voxel=args.voxel, directions=args.directions, executor=client))
            rows.append((f"Dask LocalCluster, {w} worker{'s' if w > 1 else ''} ({threads} core thread{'' if threads == '1' else 's'} each)",
                         time.perf_counter() - t))
        print(f"(done: {rows[-1][0]}, load {os.getloadavg()[0]:.1f})", flush=True)
    print("| run | time (s) | poses reached |")
    print("|---|---:|---:|")
    for (name, seconds), m in zip(rows, maps):
        print(f"| {name} | {seconds:.1f} | {100 * m.reached_units().mean():.1f} % |")
    same = [np.array_equal(maps[0].reached, m.reached) for m in maps[1:]]
    print(f"\nmaps equal to the first: {same}; load {os.getloadavg()[0]:.1f}")
    if args.check and maps:
        t = time.perf_counter()
        c = reach.check_reach(maps[0], robot, args.check, seed=0)
        print(f"\nspot check ({time.perf_counter() - t:.0f} s): {c.summary()}")
        for f in c.failures[:10]:
            print(f"  - {f[:160]}")


if __name__ == "__main__":
    main()
