"""Self-collision of the default robot's boxes, ~500 random configurations: the separating-axis lower bound
(_core.box_pair_min_gaps) against the exact signed distances of the convex-shape kernel
(_core.shape_pair_min_distances). Prints a table; run: python bench/shape_collision.py"""

import time

import numpy as np

import snakehead
from snakehead import _core


def best_of(fn, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def main(samples=500):
    robot = snakehead.SnakeRobot.default()
    rng = np.random.default_rng(0)
    lower, upper = robot.lower, robot.upper
    qs = rng.uniform(lower, upper, size=(samples, robot.n_joints))
    frames = robot.frames_many(qs)
    links = robot.boxed_links
    pairs = np.stack(np.triu_indices(len(links), k=2), axis=1)
    boxes = frames[:, links] @ robot.box_origins[links]
    half = 0.5 * robot.box_sizes[links]
    shapes = _core.ShapeSet(["box"] * len(links), np.asarray(links), robot.box_origins[links],
                            robot.box_sizes[links], [None] * len(links))
    t_sat, sat = best_of(lambda: _core.box_pair_min_gaps(boxes[..., :3, 3], boxes[..., :3, :3], half, pairs))
    t_fcl, exact = best_of(lambda: _core.shape_pair_min_distances(frames, shapes, frames, shapes, pairs))
    t_all, every = best_of(lambda: _core.shape_pair_distances(frames, shapes, frames, shapes, pairs), repeats=1)
    print(f"{samples} configurations, {len(links)} boxes, {len(pairs)} pairs")
    print(f"{'method':40s} {'us/sample':>10s}")
    print(f"{'box_pair_min_gaps (SAT lower bound)':40s} {1e6 * t_sat / samples:10.1f}")
    print(f"{'shape_pair_min_distances (exact, pruned)':40s} {1e6 * t_fcl / samples:10.1f}")
    print(f"{'shape_pair_distances (exact, all pairs)':40s} {1e6 * t_all / samples:10.1f}")
    print(f"ratio pruned / SAT: {t_fcl / t_sat:.2f}")
    print(f"largest |exact - SAT|: {np.max(np.abs(exact - sat)):.3e} m; exact >= SAT everywhere: "
          f"{bool(np.all(exact >= sat - 1e-9))}; pruned == min of all: {np.allclose(exact, every.min(axis=1), atol=1e-12)}")


if __name__ == "__main__":
    main()
