"""The exception for bad input: raised where input enters (files, the CLI, public functions), with one line that
names the file, field or argument. A ``ValueError``, so code that catches those keeps working."""
from __future__ import annotations


class InputError(ValueError):
    """The caller's input is wrong (the message says which and how); anything else raised on valid input is a bug."""
