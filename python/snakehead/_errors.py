"""snakehead's error taxonomy: whose fault is it?

* :class:`InputError` -- the caller's input is wrong: a file, a field, a command-line option or an argument of a
  public function. Raised where input enters, with one line that names what was wrong and how. It is a
  ``ValueError``; :class:`InputTypeError`, for a value of the wrong kind (text where a number is needed), is also a
  ``TypeError``, so code that catches either keeps working. The command line exits 2 for these, and only for these.
* :class:`InternalError` -- an invariant of snakehead itself is broken on valid input: a bug. Raised through
  :func:`invariant`. The command line exits 3 for it, as for any other exception.
* :class:`Infeasible` -- valid input for which a computation has no answer: no stable curl on this base, no timing
  of a path within the robot's limits, no shape of the up curve that fits. Not the caller's fault and not a bug; the
  planner turns it into a failed result whose ``failure`` says why (the command line exits 1), as it does for a
  target out of reach or a relocation out of range.
"""
from __future__ import annotations

import functools
from contextvars import ContextVar
from typing import Any, Callable, TypeVar, cast

F = TypeVar("F", bound=Callable[..., Any])


class InputError(ValueError):
    """The caller's input is wrong (the message says which and how); anything else raised on valid input is a bug."""


class InputTypeError(InputError, TypeError):
    """An input of the wrong kind (text, a bool or None where a number is needed): an :class:`InputError` that is
    also a ``TypeError``."""


class Infeasible(Exception):
    """Valid input for which a computation found no answer (the message says which and why): a failed result, not
    an error of the caller's and not a bug. Deliberately not a ``ValueError``: code that catches it means it."""


class MotionTooLong(Infeasible):
    """A motion that would last longer than a plan may (``snakehead._validate.MAX_SAMPLES`` samples at the control
    period): valid targets whose moves turn out too long. No slower timing is tried for it."""


class InternalError(AssertionError):
    """A broken invariant of snakehead on valid input: a bug in snakehead, never the caller's fault."""


def invariant(condition: object, message: str) -> None:
    """Raise :class:`InternalError` with ``message`` unless ``condition`` holds. Unlike ``assert`` it is kept
    under ``python -O``: internal functions state what they rely on with it, not with input errors."""
    if not condition:
        raise InternalError(message)


# --- entry points: where input is checked once -------------------------------------------------------------------
_entry_state: ContextVar[list[bool] | None] = ContextVar("snakehead_entry_state", default=None)


def entry_point(func: F) -> F:
    """Mark ``func`` as a public entry point that checks its input once, then calls :func:`inputs_checked`. From
    that call on, an :class:`InputError` raised inside (an internal step refusing a value the library computed) is
    a bug: it leaves ``func`` as :class:`InternalError`, never as the caller's fault."""

    @functools.wraps(func)
    def checked_once(*args: Any, **kwargs: Any) -> Any:
        state = [False]
        token = _entry_state.set(state)
        try:
            return func(*args, **kwargs)
        except InputError as exc:
            if not state[0]:
                raise
            raise InternalError(f"{func.__name__}: an internal step refused a value snakehead computed ({exc}); "
                                "this is a bug") from exc
        finally:
            _entry_state.reset(token)

    return cast(F, checked_once)


def inputs_checked() -> None:
    """Say, inside an :func:`entry_point`, that its input is checked: any InputError from here on is a bug."""
    state = _entry_state.get()
    if state is not None:
        state[0] = True
