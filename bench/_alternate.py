"""Side-by-side runs for the benchmarks: worker processes that each plan the same targets, handed to them one at a
time and alternately, so that every worker sees the same load (bench/plan_speed.py, bench/tracking_fit.py).

A worker prints "ready" once set up, then for each index it reads on stdin one JSON line of what it measured.
"""
from __future__ import annotations

import json
import subprocess
import sys


def run_alternately(commands: list[list[str]], count: int, label: str) -> list[list[dict]]:
    """Starts a worker per command, hands the indices 0..count-1 to each in turn and returns each worker's rows."""
    procs = [subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True) for cmd in commands]
    for p in procs:
        if p.stdout is None or p.stdout.readline().strip() != "ready":
            raise SystemExit(f"a worker did not start: {p.args}")
    rows: list[list[dict]] = [[] for _ in procs]
    for i in range(count):
        for p, r in zip(procs, rows):
            assert p.stdin is not None and p.stdout is not None
            p.stdin.write(f"{i}\n")
            p.stdin.flush()
            r.append(json.loads(p.stdout.readline()))
        print(f"  {label} {i + 1}/{count}", file=sys.stderr, flush=True)
    for p in procs:
        assert p.stdin is not None
        p.stdin.close()
        p.wait()
    return rows
