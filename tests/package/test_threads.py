"""The core's thread count (snakehead.threads): set per process, from the environment by default, taken by
TRAC-IK's batches without changing a seeded batch's solutions, and given to the workers of the pools snakehead makes
as their share of the cores."""
from __future__ import annotations

import argparse
import os
import subprocess
import sys

import numpy as np
import pytest

import snakehead as sh
from snakehead import limits
from snakehead import threads as ct


def test_set_and_restore() -> None:
    default = sh.core_threads()
    assert default >= 1
    try:
        sh.set_core_threads(1)
        assert sh.core_threads() == 1
        sh.set_core_threads(np.int64(2))
        assert sh.core_threads() == 2
    finally:
        sh.set_core_threads(None)
    assert sh.core_threads() == default


@pytest.mark.parametrize("bad", [0, -1, limits.MAX_THREADS + 1])
def test_out_of_range_is_input_error(bad: int) -> None:
    with pytest.raises(sh.InputError, match="threads"):
        sh.set_core_threads(bad)


@pytest.mark.parametrize("bad", [1.5, "2", True])
def test_not_an_integer_is_input_type_error(bad: object) -> None:
    with pytest.raises(sh.InputTypeError, match="threads"):
        sh.set_core_threads(bad)


def test_seeded_batch_is_the_same_on_one_thread() -> None:
    robot = sh.SnakeRobot.default()
    head = robot.head_chain
    ik = sh.TracIK.from_chain(head, seed=3)
    rng = np.random.default_rng(3)
    poses = np.array([head.fk(head.random_configuration(rng)) for _ in range(24)])
    starts = np.array([head.random_configuration(rng) for _ in range(24)])
    q_all, ok_all = ik.ik_many(poses, starts)
    try:
        sh.set_core_threads(1)
        q_one, ok_one = ik.ik_many(poses, starts)
    finally:
        sh.set_core_threads(None)
    assert ok_all.sum() >= 20
    np.testing.assert_array_equal(ok_one, ok_all)
    np.testing.assert_array_equal(q_one, q_all)


def _threads_in_child(env: dict) -> subprocess.CompletedProcess:
    clean = {k: v for k, v in os.environ.items() if k not in (ct.ENVIRONMENT_VARIABLE, "OMP_NUM_THREADS")}
    return subprocess.run([sys.executable, "-c", "import snakehead; print(snakehead.core_threads())"],
                          env={**clean, **env}, capture_output=True, text=True, timeout=120)


def test_environment_sets_the_default() -> None:
    assert _threads_in_child({ct.ENVIRONMENT_VARIABLE: "1"}).stdout.strip() == "1"
    assert _threads_in_child({"OMP_NUM_THREADS": "1"}).stdout.strip() == "1"  # as Dask's workers set it
    ours_first = _threads_in_child({ct.ENVIRONMENT_VARIABLE: "3", "OMP_NUM_THREADS": "1"})
    assert ours_first.stdout.strip() == "3"
    assert _threads_in_child({"OMP_NUM_THREADS": "4,2"}).stdout.strip() == str(os.cpu_count())  # not a count: ignored


def test_bad_environment_names_the_variable() -> None:
    r = _threads_in_child({ct.ENVIRONMENT_VARIABLE: "many"})
    assert r.returncode != 0
    assert "InputError" in r.stderr and ct.ENVIRONMENT_VARIABLE in r.stderr and "'many'" in r.stderr


def test_share_per_worker() -> None:
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    assert ct.share_per_worker(1) == cores
    assert ct.share_per_worker(cores) == 1
    assert ct.share_per_worker(4 * cores) == 1


def test_reach_pool_workers_take_their_share() -> None:
    from snakehead.app.commands import reach_executor

    args = argparse.Namespace(scheduler=None, workers=2)
    pool, close = reach_executor(args)
    try:
        got = {pool.submit(sh.core_threads).result(timeout=120) for _ in range(4)}
    finally:
        close()
    assert got == {ct.share_per_worker(2)}
