#!/usr/bin/env python3
"""Fingerprints of a fixed set of plans: the guard of a refactoring that must keep every plan bit for bit.

Plans a fixed set of targets with :func:`snakehead.plan` and prints one SHA-256 per plan over what the plan holds
(times, joint angles and rates, states, ZMP, clearances, success, failure text, base, relocation) and one over all.
The set: the default robot with targets reachable by construction from its own base shape ("same"), from other
base shapes ("shape") and from other placements ("place"), the published styles' sample snakes, the scenes
shipped with the package, and a plan started from a given base shape (``base_shape``: the closed loop's entry).
Controllers are seeded (``seed=1``): an unseeded TRAC-IK races its solvers on the clock.

    python3 bench/plan_hashes.py --save before.json     # record
    python3 bench/plan_hashes.py --check before.json    # compare: exit 1 and the names that differ

The digests depend on the machine's BLAS and thread count: compare runs on one machine only.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from importlib import resources
from pathlib import Path

import numpy as np

import snakehead

sys.path.insert(0, str(Path(__file__).parent))
from _robots import published_style  # noqa: E402

STYLES = ("sea", "reu", "mesh", "xacro", "one_joint_neck", "head6", "cad", "reu_reversed")


def _targets_module():
    try:
        from snakehead.samples import targets
    except ImportError:  # before the layout of issue 36
        from snakehead.samples import targets  # type: ignore[no-redef]
    return targets


def plan_digest(plan) -> str:
    """One SHA-256 over every number and word the plan holds."""
    h = hashlib.sha256()

    def add(x) -> None:
        h.update(np.ascontiguousarray(np.asarray(x, dtype=float)).tobytes())

    for a in (plan.t, plan.q, plan.qd, plan.ground_clearance, plan.stability.zmp, plan.stability.margin):
        add(a)
    if plan.obstacle_distance is not None:
        add(plan.obstacle_distance)
    add([plan.base.x, plan.base.y, plan.base.yaw])
    for label, t, q in plan.states:
        h.update(str(label).encode())
        add([t])
        add(q)
    for tg in plan.targets:
        h.update(repr((tg.solved, getattr(tg.solution, "stage", None), getattr(tg.solution, "reason", None))).encode())
    h.update(repr((plan.success, plan.failure, plan.timing_failure, plan.out_of_range)).encode())
    if plan.relocation is not None:
        h.update(repr(plan.relocation).encode())
    return h.hexdigest()


def cases():
    """(name, thunk) for every plan of the set."""
    targets = _targets_module()
    default = snakehead.HeadController(snakehead.SnakeRobot.default(), seed=1)
    rng = np.random.default_rng(36)
    for kind, count in (("same", 4), ("shape", 3), ("place", 3)):
        for i, t in enumerate(targets.reachable_targets(default, kind, count, rng)):
            yield f"default/{kind}/{i}", (lambda t=t: snakehead.plan([(t.position, t.direction)], controller=default))
    for style in STYLES:
        controller = snakehead.HeadController(published_style(style), seed=1)
        rng = np.random.default_rng(7)
        for kind in ("same", "shape"):
            for i, t in enumerate(targets.reachable_targets(controller, kind, 1, rng)):
                yield f"{style}/{kind}/{i}", (lambda t=t, c=controller: snakehead.plan([(t.position, t.direction)],
                                                                                        controller=c))
    scenes = resources.files("snakehead") / "scenes"
    for name in ("hole.toml", "spheres.toml"):
        yield f"scene/{name}", (lambda p=scenes / name: snakehead.plan(str(p), controller=default))
    first = next(iter(targets.reachable_targets(default, "shape", 1, np.random.default_rng(3))))
    yield "start/base_shape", lambda: snakehead.plan([(first.position, first.direction)], controller=default,
                                                     base_shape=first.q)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--save", type=Path)
    ap.add_argument("--check", type=Path)
    args = ap.parse_args()
    digests: dict[str, str] = {}
    t0 = time.perf_counter()
    for name, thunk in cases():
        plan = thunk()
        digests[name] = plan_digest(plan)
        print(f"{name:28s} {'ok ' if plan.success else 'FAIL'} {digests[name][:16]}", flush=True)
    total = hashlib.sha256("".join(digests.values()).encode()).hexdigest()
    print(f"{len(digests)} plans in {time.perf_counter() - t0:.0f} s; all: {total[:16]}")
    if args.save:
        args.save.write_text(json.dumps(digests, indent=1) + "\n")
    if args.check:
        before = json.loads(args.check.read_text())
        differ = sorted(k for k in before.keys() | digests.keys() if before.get(k) != digests.get(k))
        print("same as " + str(args.check) if not differ else "DIFFERENT: " + ", ".join(differ))
        return 1 if differ else 0
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
