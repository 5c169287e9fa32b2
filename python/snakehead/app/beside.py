"""Work run beside the caller (:class:`Beside`): in a forked child process on Linux, so that it runs on another
core -- the figures that need only the plan while MuJoCo simulates, a lane of scenes -- and at once elsewhere.

A child that dies or hangs is replaced by doing its work in the caller; an error in the child is raised in the
caller as the caller would have raised it.
"""
from __future__ import annotations

import gc
import multiprocessing
import os
import pickle
import signal
import sys
import traceback
from typing import Any, Callable

from .._errors import Infeasible, InputError, InputTypeError, InternalError
from .progress import Progress

__all__ = ["Beside", "FIGURE_PROCESS_TIMEOUT_S", "LANE_PROCESS_TIMEOUT_S", "STOP_GRACE_S"]

#: s: the longest the forked figure process may take before it is taken for hung; the figures are then drawn in
#: the main process.
FIGURE_PROCESS_TIMEOUT_S = 900.0
#: s: the same for a lane of scenes (:func:`~snakehead.app.pipeline.run_scenes`), which plans and simulates them
#: as well.
LANE_PROCESS_TIMEOUT_S = 4 * FIGURE_PROCESS_TIMEOUT_S
#: s a process beside this one has to stop after a Ctrl-C before it is killed.
STOP_GRACE_S = 5.0


class Beside:
    """Runs ``work(progress)`` beside the caller: in a forked child process on Linux, so that it runs on the second
    core (the figures that need only the plan while MuJoCo simulates; a lane of scenes,
    :func:`~snakehead.app.pipeline.run_scenes`); at once elsewhere, or with ``parallel=False``. :meth:`result`
    waits for its value (pickled back); the child's stage times join ``progress``, their names ending in
    ``suffix``. ``daemon=False`` lets the child fork children of its own (a lane draws its figures beside it)."""

    def __init__(self, work: Callable[[Progress], Any], progress: Progress, parallel: bool = True, *,
                 suffix: str = " [in a second process]", daemon: bool = True,
                 timeout_s: float | None = None) -> None:
        self.progress = progress
        self.work = work
        self.suffix = suffix
        self.timeout_s = FIGURE_PROCESS_TIMEOUT_S if timeout_s is None else timeout_s  # read now: tests shorten it
        self.proc = None
        if not (parallel and sys.platform.startswith("linux")):
            self._value = work(progress)
            return
        ctx = multiprocessing.get_context("fork")  # the child inherits the plan: nothing to pickle
        self.recv, send = ctx.Pipe(duplex=False)
        self.proc = ctx.Process(target=_child, args=(work, progress, send), name="snakehead-beside", daemon=daemon)
        # Every object alive now is moved out of the collector's reach before the fork, so that the child's
        # collections neither walk nor write the parent's objects (their pages stay shared, not copied).
        gc.freeze()
        try:
            self.proc.start()
        finally:
            gc.unfreeze()
        send.close()

    def stop(self) -> None:
        """Stop the child if it still runs (the caller was interrupted or failed): a Ctrl-C to it first, so that it
        stops its own children as this process does, then a kill after STOP_GRACE_S."""
        if self.proc is None or not self.proc.is_alive():
            return
        if self.proc.pid is not None:  # (started: it has one)
            os.kill(self.proc.pid, signal.SIGINT)
        self.proc.join(STOP_GRACE_S)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()

    def files(self) -> list[str]:
        """:meth:`result` of work that returns the names of the files it wrote."""
        return list(self.result())

    def result(self) -> Any:
        """The work's value: the child's (pickled back), or the work done here when the child died or hung; the
        child's error raised here."""
        if self.proc is None:
            return self._value
        try:
            answer: tuple[bool, Any, list[dict]] | None = (
                self.recv.recv() if self.recv.poll(self.timeout_s) else None)
        except EOFError:  # the forked child died (a fork of a process with threads can crash): run it here instead
            self.proc.join()
            self.progress.say(f"the process beside this one died (exit code {self.proc.exitcode}); doing its work "
                              "in this process instead")
            return self.work(self.progress)
        if answer is None:  # hung (a lock another thread held at the fork): stop it and run it here
            self.proc.kill()
            self.proc.join()
            self.progress.say(f"the process beside this one gave no answer in {self.timeout_s:g} s; doing its work "
                              "in this process instead")
            return self.work(self.progress)
        ok, value, stages = answer
        self.proc.join()
        self.progress.stages += [{**st, "stage": st["stage"] + self.suffix} for st in stages]
        if not ok:
            kind, message, error = value
            if isinstance(error, (Infeasible, InternalError, InputTypeError)):
                raise error  # snakehead's own fault, e.g. from planning in a lane: as this process would raise it
            if kind == "InputError":  # e.g. an output that could not be written: the same fault as in this process
                raise InputError(message)
            raise RuntimeError(f"the work beside this process failed: {message}")
        return value


def _child(work: Callable[[Progress], Any], progress: Progress, send: Any) -> None:
    """The child's side: run ``work`` and send back (ok, value or error, stage records)."""
    progress.stages = []
    try:
        send.send((True, work(progress), progress.stages))
    except BaseException as exc:  # noqa: BLE001 -- reported to the parent, which raises
        kind = "InputError" if isinstance(exc, InputError) else type(exc).__name__
        text = str(exc) if kind == "InputError" else f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"
        try:  # the error itself when it pickles (snakehead's do): the parent raises what this process raised
            error: BaseException | None = pickle.loads(pickle.dumps(exc)) if isinstance(exc, Exception) else None
        except Exception:  # noqa: BLE001 -- any error of pickling: the text then
            error = None
        send.send((False, (kind, text, error), progress.stages))
    finally:
        send.close()
