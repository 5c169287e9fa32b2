"""What the pipeline says as it goes: stage lines on stderr with their times (:class:`Progress`), a line per target
as it is planned (:func:`plan_progress_line`) and a scenario's outcome in a few words (:func:`outcome_line`)."""
from __future__ import annotations

import contextlib
import sys
import time
from typing import TYPE_CHECKING, Any, Iterator

if TYPE_CHECKING:
    from ..planning.plan_result import PlanProgress

__all__ = ["Progress", "outcome_line", "plan_progress_line"]


class Progress:
    """Stage lines on stderr (``[  12.3 s] what ...`` / ``... done in 1.2 s``) and a record of the stage times."""

    def __init__(self, quiet: bool = False, stream: Any = None) -> None:
        self.t0 = time.perf_counter()
        self.quiet = quiet
        self.stream = stream
        self.stages: list[dict] = []

    def elapsed(self) -> float:
        """s since this record began."""
        return time.perf_counter() - self.t0

    def say(self, text: str) -> None:
        """A line on the stream (stderr by default) after the time since the start, unless quiet. Written in one
        write with its line end: a process beside this one stopped by a Ctrl-C leaves no line without its end."""
        if not self.quiet:
            stream = self.stream or sys.stderr
            stream.write(f"[{self.elapsed():7.1f} s] {text}\n")
            stream.flush()

    @contextlib.contextmanager
    def stage(self, what: str) -> Iterator[None]:
        """The work in the ``with`` block as a stage: a line when it begins and when it ends, its time recorded."""
        self.say(f"{what} ...")
        start = time.perf_counter()
        yield
        dt = time.perf_counter() - start
        self.stages.append({"stage": what, "seconds": dt})
        self.say(f"{what}: done in {dt:.1f} s")


def outcome_line(success: bool, failure: str | None, relocation: dict | None) -> str:
    """A scenario's outcome in a few words: success (saying so when the base had to move first) or the failure."""
    if not success:
        return f"NOT successful: {failure}"
    if relocation is None:
        return "success"
    return (f"success after relocating the base {relocation['distance_m']:.2f} m "
            f"({relocation['reason']}; --no-relocation forbids it)")


def plan_progress_line(record: PlanProgress) -> str:
    """One line for a ``plan(progress=...)`` record: "target 3/100 'name': solved in 0.21 s" (or why it was not
    solved), or the stage that begins."""
    if record.kind == "target":
        what = (f"solved in {record.seconds:.2f} s" if record.solved else
                f"NOT solved in {record.seconds:.2f} s: {record.message}")
        return f"target {record.index}/{record.count} {record.name!r}: {what}"
    return f"{record.message} ..."
