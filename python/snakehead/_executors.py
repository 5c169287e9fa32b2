"""The one way work is spread over an executor: maps (``kinematics.reachability.compute``), many plans
(``planning.plan_many``) and the whole body's reach (``planning.whole_body_reach``).

An executor is any ``concurrent.futures.Executor`` (a thread or process pool, Dask's ``client.get_executor()``) or a
Dask ``distributed.Client`` itself (its executor is used). Tasks are module-level functions of picklable arguments,
so that process pools and Dask workers can run them; results come back as they finish.
"""
from __future__ import annotations

from concurrent.futures import Executor, as_completed
from typing import Any, Callable, Sequence

from ._errors import InputTypeError


def as_executor(executor: Any, what: str = "executor") -> Executor:
    """``executor`` as a ``concurrent.futures.Executor``: itself, or a Dask ``distributed.Client``'s executor;
    InputTypeError naming ``what`` otherwise."""
    if isinstance(executor, Executor):
        return executor
    get = getattr(executor, "get_executor", None)
    if type(executor).__module__.split(".")[0] == "distributed" and callable(get):
        return get()
    raise InputTypeError(f"{what} must be a concurrent.futures.Executor or a Dask distributed.Client, got "
                         f"{type(executor).__name__}")


def worker_count(executor: Any) -> int | None:
    """How many tasks the executor runs at once, when it says so (a pool's workers, a Dask client's threads)."""
    workers = getattr(executor, "_max_workers", None)
    if isinstance(workers, int) and workers > 0:
        return workers
    client = getattr(executor, "_client", executor)  # Dask's ClientExecutor keeps its client
    nthreads = getattr(client, "nthreads", None)
    if type(client).__module__.split(".")[0] == "distributed" and callable(nthreads):
        try:
            return max(1, sum(nthreads().values()))
        except Exception:  # a client that lost its scheduler: no count (the work itself will say why)
            return None
    return None


def run_tasks(executor: Executor, fn: Callable[..., Any], tasks: Sequence[tuple],
              done: Callable[[int, Any], None] | None = None) -> list:
    """``fn(*task)`` for every task on ``executor``; the results in the tasks' order. ``done(i, result)`` is called
    here as each task finishes (in the order they finish). The first exception a task raises (or ``done`` raises) is
    raised here, after the tasks not yet started are cancelled."""
    futures = {executor.submit(fn, *task): i for i, task in enumerate(tasks)}
    results: list = [None] * len(tasks)
    try:
        for f in as_completed(futures):
            i = futures[f]
            results[i] = f.result()
            if done is not None:
                done(i, results[i])
    finally:
        for f in futures:
            f.cancel()
    return results
