"""TRAC-IK in a forked child: a solver made (and used) by the parent may be used, destroyed and collected by a forked
child (os.fork, a fork-context process pool), and the parent's solver still works after.

The child neither uses nor joins the parent's worker threads (a forked child has none of them; joining them was a
SIGSEGV or a hang) and starts its own when it needs them (cpp/worker_pool.cpp, WorkerPool)."""
from __future__ import annotations

import faulthandler
import gc
import multiprocessing
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import snakehead
from snakehead import TracIK

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="fork is POSIX only")

#: s: a child that has not exited by then is taken for hung (it needs well under a second).
CHILD_DEADLINE_S = 120.0
TARGETS = 24
#: s: budget per solve, far above what a reachable target needs, so that a loaded machine does not fail one
TIMEOUT_S = 0.5


@pytest.fixture(scope="module")
def chain():
    return snakehead.SnakeRobot.default().head_chain


def reachable_targets(chain, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Poses of random configurations (reachable by construction) and the configurations."""
    rng = np.random.default_rng(seed)
    qs = np.array([chain.random_configuration(rng) for _ in range(count)])
    return np.array([chain.fk(q) for q in qs]), qs


def assert_solved(chain, poses: np.ndarray, q: np.ndarray, ok: np.ndarray) -> None:
    """Every target found, each solution within the limits and at its pose by forward kinematics (independent of the
    solver's own error)."""
    assert ok.all()
    for T, qk in zip(poses, q):
        assert np.all(qk >= chain.lower) and np.all(qk <= chain.upper)
        np.testing.assert_allclose(chain.fk(qk)[:3, 3], T[:3, 3], atol=1e-4)
        np.testing.assert_allclose(chain.fk(qk)[:3, :3], T[:3, :3], atol=1e-4)


def use(solver: TracIK, chain, seed: int) -> None:
    """Both ways the solver uses its workers: a batch (ik_many hands targets to them) and unseeded single calls
    (raced calls hand the SQP half to a worker once KDL-RR has not solved the target at once)."""
    poses, _ = reachable_targets(chain, TARGETS, seed)
    rng = np.random.default_rng(seed + 1)  # the starts: this call's own (the solver's generator has a lock that
    starts = np.array([chain.random_configuration(rng) for _ in poses])  # a thread may hold at a fork)
    q, ok = solver.ik_many(poses, starts)
    assert_solved(chain, poses, q, ok)
    for T in poses[:6]:
        qk = solver.ik(T, chain.random_configuration(rng))
        assert qk is not None
        np.testing.assert_allclose(chain.fk(qk)[:3, 3], T[:3, 3], atol=1e-4)


def wait_child(pid: int) -> int:
    """The child's exit status (its exit code, or -signal); kills it and fails if it has not exited in time."""
    end = time.monotonic() + CHILD_DEADLINE_S
    while time.monotonic() < end:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status)
        time.sleep(0.02)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    pytest.fail(f"the forked child did not exit within {CHILD_DEADLINE_S:g} s (hung)")


class Holder:
    """An object in a reference cycle: only the garbage collector frees it (and the solver it holds)."""

    def __init__(self, solver: TracIK) -> None:
        self.solver = solver
        self.me = self


def fork_and_run(child_work) -> int:
    """Runs ``child_work()`` in a forked child; its exit status (0: returned; 1: raised; -N: killed by signal N)."""
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # the child: never back into pytest
        code = 1
        try:
            child_work()
            code = 0
        except BaseException:  # noqa: BLE001 -- the child reports by its exit code
            import traceback

            traceback.print_exc()
        finally:
            os._exit(code)
    return wait_child(pid)


def test_a_forked_child_uses_destroys_and_collects_the_parents_solvers(chain):
    solver = TracIK.from_chain(chain, timeout=TIMEOUT_S)
    use(solver, chain, seed=1)  # the parent's workers exist and have worked
    gc.disable()  # the cycle below stays uncollected until the child collects it
    try:
        cyclic = TracIK.from_chain(chain, timeout=TIMEOUT_S)
        use(cyclic, chain, seed=2)
        Holder(cyclic)
        del cyclic

        def child() -> None:
            nonlocal solver
            use(solver, chain, seed=3)  # the parent's solver, in the child: workers of the child's own
            solver = None  # its last reference here: the destructor runs in the child
            assert gc.collect() > 0  # the cycle's solver is destroyed here too (pipeline.py's old SIGSEGV)
            fresh = TracIK.from_chain(chain, timeout=TIMEOUT_S)  # and a solver made in the child works
            use(fresh, chain, seed=4)

        assert fork_and_run(child) == 0
    finally:
        gc.enable()
        gc.collect()
    use(solver, chain, seed=5)  # the parent's solver still works after


def test_a_fork_while_other_threads_solve(chain):
    """Forks while threads of the parent keep the solver's workers busy (its queue's lock may be held at the
    fork): the child still solves and exits, and so does the parent's solver."""
    solver = TracIK.from_chain(chain, timeout=TIMEOUT_S)
    stop = threading.Event()
    errors: list[BaseException] = []

    def keep_solving(seed: int) -> None:
        try:
            while not stop.is_set():
                use(solver, chain, seed)
        except BaseException as exc:  # noqa: BLE001 -- reported by the test
            errors.append(exc)

    threads = [threading.Thread(target=keep_solving, args=(10 + k,)) for k in range(2)]
    for t in threads:
        t.start()
    try:
        for k in range(3):
            time.sleep(0.05)
            assert fork_and_run(lambda k=k: use(solver, chain, seed=20 + k)) == 0
    finally:
        stop.set()
        for t in threads:
            t.join()
    assert not errors, errors
    use(solver, chain, seed=30)


_POOL_SOLVER: TracIK | None = None  # inherited by the fork-context pool's workers


def _solve_in_worker(seed: int) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    assert _POOL_SOLVER is not None
    faulthandler.dump_traceback_later(CHILD_DEADLINE_S, exit=True)  # hung: the worker dies, the pool breaks
    try:
        poses, qs = reachable_targets(_POOL_SOLVER.chain, TARGETS, seed)
        q, ok = _POOL_SOLVER.ik_many(poses, qs[::-1])
    finally:
        faulthandler.cancel_dump_traceback_later()
    return os.getpid(), poses, q, ok


def test_a_fork_context_process_pool_uses_the_parents_solver(chain):
    global _POOL_SOLVER
    _POOL_SOLVER = TracIK.from_chain(chain, timeout=TIMEOUT_S)
    try:
        use(_POOL_SOLVER, chain, seed=40)
        with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
            answers = list(pool.map(_solve_in_worker, range(41, 45)))
        assert {pid for pid, *_ in answers} - {os.getpid()}  # solved in the children
        for _, poses, q, ok in answers:
            assert_solved(chain, poses, q, ok)
        use(_POOL_SOLVER, chain, seed=50)
    finally:
        _POOL_SOLVER = None


def test_a_fork_while_another_thread_draws_from_the_solvers_generator(chain):
    """numpy's generator lock is copied into a forked child as it was: held, when another thread of the parent was
    drawing starts then. The child renews each solver's generator (kinematics.ik._renew_generators), so it draws its
    own starts (ik_many without q_inits, random_configuration) and exits; the parent's generator is untouched."""
    solver = TracIK.from_chain(chain, timeout=TIMEOUT_S)
    poses, _ = reachable_targets(chain, 6, seed=7)
    lock = solver._rng.bit_generator.lock
    before = solver._rng.bit_generator.state

    def child() -> None:
        assert solver._rng.bit_generator.state == before  # the same stream, continued
        q = solver.random_configuration()
        assert np.all(q >= chain.lower) and np.all(q <= chain.upper)
        _, ok = solver.ik_many(poses)  # starts drawn from the generator
        assert ok.all()

    held, release = threading.Event(), threading.Event()

    def draw_slowly() -> None:  # a thread of the parent in the middle of a draw at the moment of the fork
        with lock:
            held.set()
            release.wait()

    drawer = threading.Thread(target=draw_slowly)
    drawer.start()
    held.wait()
    try:
        status = fork_and_run(child)
    finally:
        release.set()
        drawer.join()
    assert status == 0
    assert solver._rng.bit_generator.state == before
    assert solver._rng.bit_generator.lock is lock
