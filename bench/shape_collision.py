"""Self-collision of a robot's collision shapes over ~500 random configurations: the core's convex-shape kernel on
Debian's FCL (snakehead.geometry.shapes: pruned minimum and every pair) against coal (pinocchio's collision
library, its Python bindings, one call per pair) on the same pairs: time per sample and the largest difference.
Prints a table; run: python bench/shape_collision.py [--robot default|sea|head6|mesh] [--samples 500]"""

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import snakehead
from snakehead.geometry.shapes import pair_distances, pair_min_distances
from snakehead.samples import published


def best_of(fn, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def coal_geometry(shape):
    import coal

    if shape.kind == "box":
        return coal.Box(*shape.size)
    if shape.kind == "cylinder":
        return coal.Cylinder(shape.size[0], shape.size[1])
    if shape.kind == "sphere":
        return coal.Sphere(shape.size[0])
    from scipy.spatial import ConvexHull

    hull = ConvexHull(shape.vertices)
    pts = coal.StdVec_Vec3s()
    for v in shape.vertices:
        pts.append(np.asarray(v, float))
    tris = coal.StdVec_Triangle()
    for a, b, c in hull.simplices:
        tris.append(coal.Triangle(int(a), int(b), int(c)))
    return coal.Convex(pts, tris)


def coal_min_distances(robot, frames, pairs):
    """One coal.distance call per pair and sample (signed distances; the smallest per sample)."""
    import coal

    geoms = [coal_geometry(s) for s in robot.geometry.shapes]
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    out = np.full(len(frames), np.inf)
    for t in range(len(frames)):
        poses = [frames[t, s.frame] @ s.origin for s in robot.geometry.shapes]
        tf = [coal.Transform3s(P[:3, :3], P[:3, 3]) for P in poses]
        for i, j in pairs:
            res.clear()
            out[t] = min(out[t], coal.distance(geoms[i], tf[i], geoms[j], tf[j], req, res))
    return out


def load(name):
    if name == "default":
        return snakehead.SnakeRobot.default()
    return snakehead.SnakeRobot.from_file(published.write_robot(name, Path(tempfile.mkdtemp()) / name))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", default="default")
    ap.add_argument("--samples", type=int, default=500)
    args = ap.parse_args()
    robot = load(args.robot)
    rng = np.random.default_rng(0)
    qs = rng.uniform(robot.lower, robot.upper, size=(args.samples, robot.n_joints))
    frames = robot.frames_many(qs)
    pairs = robot.self_collision_pairs
    S = robot.geometry
    t_min, pruned = best_of(lambda: pair_min_distances(frames, S, frames, S, pairs))
    t_all, every = best_of(lambda: pair_distances(frames, S, frames, S, pairs), repeats=1)
    few = min(args.samples, 50)
    t_coal, by_coal = best_of(lambda: coal_min_distances(robot, frames[:few], pairs), repeats=1)
    print(f"robot {args.robot}: {args.samples} configurations, {len(S.shapes)} shapes "
          f"({', '.join(sorted({s.kind for s in S.shapes}))}), {len(pairs)} pairs")
    print("| method | µs/sample |\n|---|---|")
    print(f"| snakehead kernel (FCL), pruned minimum | {1e6 * t_min / args.samples:.1f} |")
    print(f"| snakehead kernel (FCL), every pair | {1e6 * t_all / args.samples:.1f} |")
    print(f"| coal from Python, one call per pair ({few} samples) | {1e6 * t_coal / few:.1f} |")
    apart = by_coal > 0
    print(f"pruned == min of every pair: {np.allclose(pruned, every.min(axis=1), atol=1e-12)}; "
          f"largest |kernel - coal| where apart: {np.max(np.abs(pruned[:few] - by_coal)[apart], initial=0):.2e} m; "
          f"samples in contact (coal / kernel): {int((~apart).sum())} / {int((pruned[:few] <= 0).sum())}")


if __name__ == "__main__":
    main()
