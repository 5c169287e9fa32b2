"""What ``snakehead`` exits with (:mod:`snakehead.app.cli`'s docstring says when), and the error of a command line
whose options do not go together (:class:`UsageError`, exit status 2)."""
from __future__ import annotations

from .._errors import InputError

__all__ = ["EXIT_OK", "EXIT_UNSUCCESSFUL", "EXIT_BAD_INPUT", "EXIT_INTERNAL_ERROR", "EXIT_INTERRUPTED", "UsageError"]

#: Exit statuses: success; planned but not successfully (or no answer); bad input; a bug; interrupted (Ctrl-C).
EXIT_OK, EXIT_UNSUCCESSFUL, EXIT_BAD_INPUT, EXIT_INTERNAL_ERROR, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


class UsageError(InputError):
    """A mistake in the command line (options that do not go together): reported on stderr, exit status 2."""
