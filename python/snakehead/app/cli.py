"""snakehead: plan how a snake robot raises its head to a position and direction while its body stays stable.

The command is snakehead (also python -m snakehead). Subcommands:

  info        describe a robot (default: the shipped one; --robot FILE for yours)
  demo        the paper's two scenarios of Section 4 end to end, with figures, animations and a report
  plan        head targets (--position/--direction, or --scene FILE) with the same outputs
  workspace   compute a reachability map of a robot's head (Algorithm 1) into a .npz file
  reach       compute the whole body's stable reachability map (where a stable pose puts the head) into a .npz file
  view        the interactive 3-D viewer of the output of plan or demo, served to a web browser; --live plans
              as you drag the head's targets

Exit status:
  0    success
  1    a scenario or target was planned but not successfully (the outputs are written all the same), or valid input has no answer (snakehead.Infeasible: e.g. a robot whose neck and head cannot rise)
  2    bad arguments, bad input files, or outputs that cannot be written: snakehead.InputError, and only it (one line on stderr says which)
  3    an internal error: any other exception, a bug in snakehead (one line on stderr; please report it with its traceback)
  130  interrupted (Ctrl-C; but view, which runs until Ctrl-C, then exits with 0)
Errors are one line on stderr, never a traceback; set SNAKEHEAD_TRACEBACK=1 to see the Python traceback.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys

from .._errors import Infeasible, InputError
from .cli_options import OneLineParser, add_commands
from .exit_status import EXIT_BAD_INPUT, EXIT_INTERNAL_ERROR, EXIT_INTERRUPTED, EXIT_OK, EXIT_UNSUCCESSFUL, UsageError

__all__ = ["main", "build_parser", "MAX_ERROR_CHARS", "EXIT_OK", "EXIT_UNSUCCESSFUL", "EXIT_BAD_INPUT",
           "EXIT_INTERNAL_ERROR", "EXIT_INTERRUPTED", "UsageError"]

#: The longest error line printed (a message quoting a whole file or array is cut, its end kept).
MAX_ERROR_CHARS = 400


def build_parser() -> argparse.ArgumentParser:
    """The command line: this module's docstring as its help, one sub-command per command
    (:func:`.cli_options.add_commands`)."""
    parser = OneLineParser(prog="snakehead", description=__doc__.split("\n\n")[0],
                           epilog=__doc__.split("\n\n", 1)[1],
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add_commands(sub)
    return parser


def _traceback_wanted() -> bool:
    """Whether SNAKEHEAD_TRACEBACK asks for Python's traceback instead of the one error line."""
    return os.environ.get("SNAKEHEAD_TRACEBACK", "") not in ("", "0")


def _one_line(exc: BaseException) -> str:
    """The error's message on one line of at most :data:`MAX_ERROR_CHARS` characters (its end kept)."""
    text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip()) or type(exc).__name__
    return text if len(text) <= MAX_ERROR_CHARS else text[:MAX_ERROR_CHARS - 60] + " ... " + text[-55:]


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default: ``sys.argv[1:]``); returns the exit status (see the module)."""
    command = "snakehead"
    try:
        parser = build_parser()
        args = parser.parse_args(argv)  # bad arguments: one line and SystemExit(2)
        command = f"snakehead {args.command}"
        return int(args.func(args))
    except KeyboardInterrupt:
        if argv is None:  # the program (not a call from Python) exits now: a Ctrl-C that arrives while the
            # interpreter shuts down (threads joined, files closed) would kill it by the signal instead of 130
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        print(f"{command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except InputError as exc:  # what the user gave (or where outputs go) is wrong
        if _traceback_wanted():
            raise
        print(f"{command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Infeasible as exc:  # valid input with no answer (outside a plan, whose failures are in its report)
        if _traceback_wanted():
            raise
        print(f"{command}: not possible: {_one_line(exc)}", file=sys.stderr)
        return EXIT_UNSUCCESSFUL
    except Exception as exc:  # noqa: BLE001 -- anything else is a bug: one line, the traceback on request
        if _traceback_wanted():
            raise
        print(f"{command}: internal error ({type(exc).__name__}: {_one_line(exc)}); this is a bug in snakehead: run "
              "again with SNAKEHEAD_TRACEBACK=1 to see the traceback, and report it", file=sys.stderr)
        return EXIT_INTERNAL_ERROR
