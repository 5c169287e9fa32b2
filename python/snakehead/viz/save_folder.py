"""Where the live viewer's page may write: one folder, fixed when the viewer starts (``snakehead view --live
--save-dir DIR``, default :data:`DEFAULT_SAVE_DIR` in the current directory).

A web client names a file and nothing more (:func:`bare_name`): letters, digits, ``_``, ``-``, spaces and dots, at
most :data:`MAX_NAME_CHARS` characters, not hidden, no folder separators, no ``..``, ``.toml`` added when missing.
:class:`SaveFolder` writes only into its folder, never over a file this session did not write (a new file is
created exclusively: ``O_EXCL``, so an existing file, a symlink or a name taken meanwhile is refused; a file the
session wrote is replaced whole, and only while it is still the file the session wrote), at most
:data:`MAX_SAVED_FILES` files per session, and tells the client only the bare name -- never the folder, never an
operating system's error text (which would tell a client what exists on the server). What went wrong is logged
on the server.
"""
from __future__ import annotations

import contextlib
import logging
import os
import re
import threading
from pathlib import Path

from .._errors import InputError, InputTypeError
from .._files import atomic_open

__all__ = ["DEFAULT_SAVE_DIR", "SCENE_FILE_SUFFIX", "MAX_NAME_CHARS", "MAX_SAVED_FILES", "bare_name", "SaveFolder"]

LOG = logging.getLogger("snakehead.viz.server")

#: The folder (in the current directory) the live viewer saves into unless ``--save-dir`` names another.
DEFAULT_SAVE_DIR = "snakehead-scenes"
#: The suffix every saved scene file gets.
SCENE_FILE_SUFFIX = ".toml"
#: Characters of a file name a client may give (with the suffix).
MAX_NAME_CHARS = 100
#: Files one viewer session may create in its folder (saving one of them again does not count).
MAX_SAVED_FILES = 100
#: A bare name: starts with a letter, digit or "_", ends with one or "-"; letters, digits, "_", "-", " " and "."
#: between (ASCII only: no look-alike letters, no separators of any platform).
_NAME = re.compile(r"[A-Za-z0-9_](?:[A-Za-z0-9_ .-]*[A-Za-z0-9_-])?")
#: Names Windows reserves for devices, refused on every platform (a scene file is shared between machines).
_DEVICES = {"con", "prn", "aux", "nul", *(f"com{k}" for k in range(1, 10)), *(f"lpt{k}" for k in range(1, 10))}


def bare_name(name: object) -> str:
    """``name`` as the file name a client may save to, ``.toml`` added when it does not end so; InputError (naming
    the rule broken, not the name) for anything else: a path, a hidden name, ``..``, other characters, too long."""
    if not isinstance(name, str):
        raise InputTypeError(f"the file name must be text, got {type(name).__name__}")
    stem = name[:-len(SCENE_FILE_SUFFIX)] if name.lower().endswith(SCENE_FILE_SUFFIX) else name
    if not stem:
        raise InputError("the file name is empty: give a name such as my_scene.toml")
    if "/" in stem or "\\" in stem or ":" in stem:
        raise InputError("the file name must be a bare name, without a folder (scenes are saved in the viewer's "
                         "save folder)")
    if stem.startswith("."):
        raise InputError("the file name must not start with a dot (no hidden files)")
    if ".." in stem:
        raise InputError("the file name must not hold '..'")
    if len(stem) + len(SCENE_FILE_SUFFIX) > MAX_NAME_CHARS:
        raise InputError(f"the file name is longer than {MAX_NAME_CHARS} characters")
    if not _NAME.fullmatch(stem):
        raise InputError("the file name may hold letters, digits, '_', '-', spaces and dots (not first or last) "
                         "only")
    if stem.split(".")[0].strip().lower() in _DEVICES:
        raise InputError("the file name is a device name on Windows (CON, NUL, COM1, ...): choose another")
    return stem + SCENE_FILE_SUFFIX


class SaveFolder:
    """The one folder a viewer session saves into (``folder``: resolved now, created at the first save), and the
    files it wrote there. :meth:`write` puts text in a file of a bare name; :attr:`written`: those names."""

    def __init__(self, folder: str | os.PathLike | None = None) -> None:
        if folder is not None and not isinstance(folder, (str, os.PathLike)):
            raise InputTypeError(f"save_dir must be a folder's path, got {type(folder).__name__}")
        path = Path(DEFAULT_SAVE_DIR if folder is None else folder).expanduser()
        if not str(path):
            raise InputError("save_dir is empty: give a folder")
        self.folder = path.resolve()
        if self.folder.exists() and not self.folder.is_dir():
            raise InputError(f"save_dir {str(folder)!r} exists and is not a folder")
        self._written: dict[str, tuple[int, int]] = {}  # name -> (device, inode) of the file written
        self._lock = threading.Lock()

    @property
    def written(self) -> list[str]:
        with self._lock:
            return list(self._written)

    def write(self, name: object, text: str) -> str:
        """Write ``text`` (UTF-8) into the file ``name`` (see :func:`bare_name`) of the folder; the bare name.
        InputError, in words a web client may read, if it is not written."""
        bare = bare_name(name)
        with self._lock:
            if bare not in self._written and len(self._written) >= MAX_SAVED_FILES:
                raise InputError(f"this session has saved {MAX_SAVED_FILES} files already: save over one of them")
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
                target = self.folder / bare
                if bare in self._written:
                    self._written[bare] = self._replace(target, text, self._written[bare])
                else:
                    self._written[bare] = self._create(target, text)
            except FileExistsError:
                raise InputError(f"{bare} exists and was not saved by this session: choose another name") from None
            except (OSError, InputError) as exc:  # the details (a path, the OS's words) stay on the server
                LOG.warning("could not save %s in %s: %s", bare, self.folder, exc)
                raise InputError(f"{bare} could not be written (the server's log says why)") from None
        return bare

    @staticmethod
    def _create(target: Path, text: str) -> tuple[int, int]:
        """A new file (O_EXCL: nothing there before, a symlink included), written whole or removed."""
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        fd = os.open(target, flags, 0o666)
        try:
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
                f.flush()
                os.fsync(f.fileno())
                stat = os.fstat(f.fileno())
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(target)
            raise
        return stat.st_dev, stat.st_ino

    @staticmethod
    def _replace(target: Path, text: str, mine: tuple[int, int]) -> tuple[int, int]:
        """The session's own file replaced whole (a new file renamed over it), if it is still the session's: a file
        put in its place by anyone else is not touched."""
        try:
            stat = os.lstat(target)
        except FileNotFoundError:  # removed meanwhile: a new file again
            return SaveFolder._create(target, text)
        if (stat.st_dev, stat.st_ino) != mine:
            raise FileExistsError(str(target))
        with atomic_open(target, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        new = os.lstat(target)
        return new.st_dev, new.st_ino
