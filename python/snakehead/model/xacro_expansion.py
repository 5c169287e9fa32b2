"""Expanding a ``.xacro`` description with the PyPI ``xacro`` package, without letting the file run code.

By default a description is not trusted: xacro expands it (macros, properties, blocks, conditionals, includes,
``$(arg)``, YAML) but every ``${...}`` and ``$(eval ...)`` goes to :mod:`.safe_expression` instead of Python's
``eval``; ``$(find PKG)`` is the robot's ``[packages]`` folder (or ROS_PACKAGE_PATH's); ``$(env)``, ``$(optenv)``
and ``$(cwd)``, which read the machine's state, are refused; includes and ``xacro.load_yaml`` read only files
inside the robot's folders (:class:`.robot_folders.RobotFolders`), resolved through symbolic links.

``trusted=True`` (``SnakeRobot(..., trust_xacro=True)``, ``--trust-xacro``) is xacro as it is, for a description
the user wrote or reviewed: Python expressions, the environment, any file.

xacro keeps its state in module globals, so expansions take turns (one lock); the hooks are put in for one
expansion and taken out after it.
"""
from __future__ import annotations

import contextlib
import os
import threading
from pathlib import Path
from typing import Any, Iterator, Mapping

import xacro
from xacro.substitution_args import convert_value

from .._errors import InputError
from .robot_folders import MAX_DESCRIPTION_BYTES, RobotFolders
from .safe_expression import ExpressionError, Namespace, evaluate

__all__ = ["TRUST_HINT", "expand_xacro"]

#: What the error says when a description asks for what only a trusted one may do.
TRUST_HINT = ("if you trust this description, load it with trust_xacro=True (snakehead --trust-xacro); "
              "see SECURITY.md")

_LOCK = threading.Lock()


def expand_xacro(path: Path, args: Mapping[str, str], folders: RobotFolders, *, trusted: bool = False) -> str:
    """The URDF text of the xacro file ``path`` expanded with ``args`` (name -> string). Raises InputError naming
    the file for a bad or refused description."""
    with _LOCK, _hooks(xacro, folders, trusted):
        try:
            doc = xacro.process_file(os.fspath(path), mappings=dict(args))
            return str(doc.toxml())
        except Exception as exc:  # xacro raises its own, the XML parser's and the evaluator's exceptions
            message = " ".join(str(exc).split()) or type(exc).__name__
            raise InputError(f"xacro file {os.fspath(path)!r}: {message}") from None
        finally:
            xacro.all_includes.clear()


@contextlib.contextmanager
def _hooks(xacro: Any, folders: RobotFolders, trusted: bool) -> Iterator[None]:
    """xacro's evaluator, substitution args and file reader replaced for one expansion, then put back."""
    original = {name: getattr(xacro, name) for name in ("safe_eval", "eval_extension", "parse")}
    hooks = _Hooks(xacro, original, folders, trusted)
    xacro.eval_extension = hooks.extension
    if not trusted:
        xacro.safe_eval = hooks.evaluate
        xacro.parse = hooks.parse
    try:
        yield
    finally:
        for name, value in original.items():
            setattr(xacro, name, value)


class _Hooks:
    """The functions put into xacro for one expansion."""

    def __init__(self, xacro: Any, original: dict[str, Any], folders: RobotFolders, trusted: bool) -> None:
        self.xacro, self.original, self.folders, self.trusted = xacro, original, folders, trusted
        names = xacro._global_symbols["xacro"]  # noqa: SLF001 (xacro has no public table; its version is pinned)
        self.functions = Namespace(arg=self.arg, load_yaml=self.load_yaml, abs_filename=xacro.abs_filename_spec,
                                   dotify=xacro.YamlDictWrapper, tokenize=xacro.tokenize,
                                   **{k: names[k] for k in ("message", "warning", "error", "fatal")})
        # the names ${...} reads besides the properties: the xacro namespace, and its older names used directly
        self.names = {"xacro": self.functions, "load_yaml": self.load_yaml, "abs_filename": xacro.abs_filename_spec,
                      "dotify": xacro.YamlDictWrapper}

    # --- ${...} -------------------------------------------------------------------------------------
    def evaluate(self, expr: str, globals: Any, locals: Any = None) -> Any:
        symbols = globals if locals is None else locals
        try:
            return evaluate(expr, lambda name: _property(self.xacro, symbols, name), self.names)
        except ExpressionError as exc:
            raise self.xacro.XacroException(f"{exc} ({TRUST_HINT})") from None

    def arg(self, name: str) -> Any:
        return self.xacro.substitution_args_context["arg"][name]

    def load_yaml(self, filename: str) -> Any:
        path = self.folders.inside(self.xacro.abs_filename_spec(str(filename)), "xacro.load_yaml's file",
                                   MAX_DESCRIPTION_BYTES)
        return self.xacro.load_yaml(os.fspath(path))

    # --- includes -------------------------------------------------------------------------------------
    def parse(self, inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:
            where = "the included file" if len(self.xacro.filestack) > 1 else "the xacro file"
            try:
                path = self.folders.inside(os.path.join(self.xacro.root_dir, filename), where, MAX_DESCRIPTION_BYTES)
            except InputError as exc:
                raise self.xacro.XacroException(str(exc)) from None
            return self.original["parse"](None, os.fspath(path))
        return self.original["parse"](inp, filename)

    # --- $(...) ---------------------------------------------------------------------------------------
    def extension(self, s: str) -> Any:
        command, _, rest = s[2:-1].strip().partition(" ")
        rest = rest.strip()
        if command == "find":
            return os.fspath(self.folders.package_folder(rest, f"$(find {rest})"))
        if command == "arg":
            return self._arg_value(rest)
        if command == "dirname":
            return os.path.dirname(os.path.abspath(self.xacro.filestack[-1] or "."))
        if self.trusted:
            return self.original["eval_extension"](s)
        if command == "eval":
            return self._eval(rest)
        raise self.xacro.XacroException(f"{s} is not allowed: an untrusted description may use $(arg), $(find), "
                                        f"$(dirname) and $(eval) ({TRUST_HINT})")

    def _arg_value(self, name: str) -> Any:
        args = self.xacro.substitution_args_context.get("arg", {})
        if name not in args:
            raise self.xacro.XacroException(f"undefined xacro argument {name!r}: declare it with <xacro:arg> or "
                                            "give it in xacro_args")
        return args[name]

    def _eval(self, text: str) -> str:
        args = self.xacro.substitution_args_context.get("arg", {})

        def lookup(name: str) -> Any:
            if name in ("true", "false"):
                return name == "true"
            return convert_value(args[name], "auto")

        extra = {"arg": lambda name: convert_value(self._arg_value(name), "auto"),
                 "dirname": lambda: self.extension("$(dirname)")}
        try:
            return str(evaluate(text, lookup, extra))
        except ExpressionError as exc:
            raise self.xacro.XacroException(f"$(eval {text}): {exc} ({TRUST_HINT})") from None


def _property(xacro: Any, symbols: Any, name: str) -> Any:
    """The value of the description's property ``name`` in xacro's scope ``symbols`` (KeyError if it defines none):
    xacro's own global names (its builtins) are not read from there."""
    table = symbols
    while isinstance(table, xacro.Table) and table is not table.root:
        if dict.__contains__(table, name):
            return table[name]  # xacro evaluates a lazy property here, through the hooks
        table = table.parent
    raise KeyError(name)
