"""How many threads the C++ core's batch work uses in this process (TRAC-IK's batches, a workspace sweep without a
thread count, Newton-Euler along a path and a motion's ZMP check): all hardware threads by default.

A process that is one of several workers on a machine should use its share, so that the workers together use the
cores once instead of each using all of them (as joblib caps BLAS threads in its workers). The default follows the
environment, as BLAS and OpenMP libraries do: ``SNAKEHEAD_NUM_THREADS``, else ``OMP_NUM_THREADS`` (Dask's workers
set it to 1; ``distributed.nanny.pre-spawn-environ``), else every hardware thread. The process pools snakehead
makes itself (``snakehead reach --workers N``) give each worker ``share_per_worker(N)``.
"""
from __future__ import annotations

import os
from typing import Any

from . import _core, limits
from ._validate import integer

__all__ = ["core_threads", "set_core_threads", "share_per_worker", "ENVIRONMENT_VARIABLE"]

#: Sets the default for a process (a whole number in [1, limits.MAX_THREADS]).
ENVIRONMENT_VARIABLE = "SNAKEHEAD_NUM_THREADS"


def core_threads() -> int:
    """The threads the core's batch work may use in this process (>= 1)."""
    return int(_core.core_threads())


def set_core_threads(n: Any) -> None:
    """Let the core's batch work use ``n`` threads in this process (1..``limits.MAX_THREADS``; None: the default
    from the environment). InputError otherwise."""
    _core.set_core_threads(0 if n is None else integer(n, "threads", least=1, most=limits.MAX_THREADS))


def share_per_worker(workers: int) -> int:
    """The threads each of ``workers`` worker processes on this machine should use: its share of the cores this
    process may run on (>= 1)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, cores // max(1, int(workers)))
