"""The terrain query's speed: heights, normals, signed distances and capsule clearances of many points at once on a
heightfield and a triangle mesh (snakehead.terrain, the C++ core's bounding-box tree), on 1 thread and on the core's
threads; and the tree against brute force over every triangle (numpy, trimesh.triangles.closest_point) on a few
points, to show what the tree buys.

    python3 bench/terrain_query.py [--points 100000] [--grid 256] [--triangles 20000] [--repeat 5]

Prints a Markdown table (best of --repeat runs, microseconds per point and points per second).
"""
from __future__ import annotations

import argparse
import time
from typing import Callable

import numpy as np

from snakehead import threads
from snakehead.terrain import HeightfieldTerrain, MeshTerrain, TerrainQueries


def best_time(call: Callable[[], object], repeat: int) -> float:
    """The shortest of ``repeat`` wall-clock times (s) of ``call``."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def heightfield(n: int) -> HeightfieldTerrain:
    """An n x n grid of a rough surface over 4 x 4 m (bumps of a few cm)."""
    x = np.linspace(-2, 2, n)
    rng = np.random.default_rng(0)
    h = 0.05 * np.sin(3 * x)[:, None] * np.cos(2 * x)[None, :] + rng.uniform(-0.005, 0.005, (n, n))
    return HeightfieldTerrain(h, np.array([4.0, 4.0]), np.array([-2.0, -2.0, 0.0]))


def mesh(triangles: int) -> MeshTerrain:
    """A jittered, rough open surface of about ``triangles`` triangles over 4 x 4 m (its vertices moved off the grid
    so that it is not a heightfield in disguise)."""
    n = int(np.sqrt(triangles / 2)) + 1
    rng = np.random.default_rng(1)
    x, y = np.meshgrid(np.linspace(-2, 2, n), np.linspace(-2, 2, n), indexing="ij")
    step = 4 / (n - 1)
    x = x + rng.uniform(-0.3, 0.3, x.shape) * step
    y = y + rng.uniform(-0.3, 0.3, y.shape) * step
    z = 0.05 * np.sin(3 * x) * np.cos(2 * y) + rng.uniform(-0.01, 0.01, x.shape)
    p = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]).ravel()
    faces = np.concatenate([np.column_stack([p, p + n, p + n + 1]), np.column_stack([p, p + n + 1, p + 1])])
    return MeshTerrain(np.column_stack([x.ravel(), y.ravel(), z.ravel()]), faces)


def queries(terrain: TerrainQueries, points: np.ndarray) -> dict[str, Callable[[], object]]:
    ends = points + np.array([0.0865, 0.0, 0.0])
    radii = np.full(len(points), 0.0215)
    return {"height": lambda: terrain.height(points[:, :2]), "normal": lambda: terrain.normal(points[:, :2]),
            "signed_distance": lambda: terrain.signed_distance(points),
            "capsule_clearance": lambda: terrain.core.capsule_clearance(points, ends, radii)}


def brute_force(terrain: MeshTerrain, points: np.ndarray) -> None:
    """Every point against every triangle (trimesh.triangles.closest_point), the closest kept."""
    import trimesh  # only the comparison needs it

    triangles = terrain.vertices[terrain.faces]
    for p in points:
        closest = trimesh.triangles.closest_point(triangles, np.repeat(p[None], len(triangles), axis=0))
        np.min(np.linalg.norm(closest - p, axis=1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--grid", type=int, default=256)
    parser.add_argument("--triangles", type=int, default=20_000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    rng = np.random.default_rng(2)
    points = np.column_stack([rng.uniform(-2, 2, (args.points, 2)), rng.uniform(-0.1, 0.4, args.points)])
    build = {}
    start = time.perf_counter()
    hf = heightfield(args.grid)
    build["heightfield"] = time.perf_counter() - start
    start = time.perf_counter()
    m = mesh(args.triangles)
    build["mesh"] = time.perf_counter() - start
    terrains = {f"heightfield {args.grid}x{args.grid} ({len(hf.core.faces)} triangles)": hf,
                f"mesh ({len(m.faces)} triangles)": m}
    all_threads = threads.core_threads()
    print(f"{args.points} points; best of {args.repeat}; core threads: 1 and {all_threads}; build (tree and "
          f"pseudonormals): heightfield {build['heightfield'] * 1e3:.0f} ms, mesh {build['mesh'] * 1e3:.0f} ms\n")
    print("| terrain | query | threads | µs / point | points / s |")
    print("|---|---|---:|---:|---:|")
    for name, terrain in terrains.items():
        for query, call in queries(terrain, points).items():
            for n in sorted({1, all_threads}):
                threads.set_core_threads(n)
                t = best_time(call, args.repeat)
                print(f"| {name} | {query} | {n} | {t / args.points * 1e6:.3f} | {args.points / t:,.0f} |")
    threads.set_core_threads(all_threads)
    few = points[:20]
    t_brute = best_time(lambda: brute_force(m, few), 1) / len(few)
    threads.set_core_threads(1)
    t_tree = best_time(lambda: m.signed_distance(points), 1) / len(points)
    threads.set_core_threads(all_threads)
    print(f"\nsigned distance on the mesh, 1 thread: the tree {t_tree * 1e6:.2f} µs / point; brute force over every "
          f"triangle (trimesh.triangles.closest_point, {len(few)} points) {t_brute * 1e6:.0f} µs / point: "
          f"{t_brute / t_tree:,.0f} x")


if __name__ == "__main__":
    main()
