"""Independent numpy references for the geometry layer's tests: box corners and dense surface samples of every
shape kind, in the world, from a robot's frames."""
from __future__ import annotations

import numpy as np

SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)  # (8, 3)


def box_corners(robot, frames, links):
    """(T, P, 3) the corners of every box shape of ``links`` in the world, from frames (T, n_links, 4, 4)."""
    out = []
    for s in robot.geometry.shapes:
        if s.kind == "box" and s.frame in set(np.asarray(links).tolist()):
            B = frames[:, s.frame] @ s.origin
            out.append(np.einsum("tij,cj->tci", B[:, :3, :3], SIGNS * s.size / 2) + B[:, None, :3, 3])
    return np.concatenate(out, axis=1)


def surface_samples(shape, n=48):
    """Points on the surface of a shape (its own frame): a box's faces, a cylinder's rims and side, a sphere's
    surface, a convex shape's vertices (its hull's extreme points)."""
    if shape.kind == "box":
        g = np.linspace(-1, 1, 9)
        grid = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
        grid = grid[np.abs(grid).max(axis=1) == 1]
        return grid * shape.size / 2
    if shape.kind == "cylinder":
        r, length = shape.size[0], shape.size[1]
        a = 2 * np.pi * np.arange(n) / n
        z = np.linspace(-length / 2, length / 2, 7)
        return np.stack([np.tile(r * np.cos(a), len(z)), np.tile(r * np.sin(a), len(z)), np.repeat(z, n)], axis=1)
    if shape.kind == "sphere":
        v = np.random.default_rng(0).normal(size=(4000, 3))
        return shape.size[0] * v / np.linalg.norm(v, axis=1, keepdims=True)
    return np.asarray(shape.vertices)


def lowest_z_by_sampling(robot, frames, link):
    """The lowest sampled world z of a link's shapes, (T,)."""
    z = []
    for s in robot.geometry.shapes:
        if s.frame == link:
            B = frames[:, link] @ s.origin
            z.append((np.einsum("tj,pj->tp", B[:, 2, :3], surface_samples(s)) + B[:, 2, 3][:, None]).min(axis=1))
    return np.min(z, axis=0)
