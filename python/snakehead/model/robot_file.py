"""Robot files: a snake robot described in TOML (read with the standard library's ``tomllib``).

::

    # my_snake.toml
    urdf = "my_snake.urdf"        # path relative to this file (required)
    root = "tail"                 # optional: the URDF's root link by default
    base_end = "base_end"         # the frame that ends the base part (P0)
    neck_end = "neck_end"         # the frame that ends the neck part (B0, the head's base frame)
    head_tip = "head_tip"         # the head link frame (its x-axis is the head's direction)
    map = "my_snake_head.npz"     # optional: the head's reachability map (relative to this file)

Any link or fixed marker frame of the URDF may be named. ``SnakeRobot.from_file(path)`` reads one.
"""
from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from pathlib import Path


from typing import Sequence

#: The keys of a robot file; the first four frame keys but ``root`` are required, with ``urdf``.
REQUIRED_KEYS = ("urdf", "base_end", "neck_end", "head_tip")
OPTIONAL_KEYS = ("root", "map")

#: A robot file is a few lines; anything larger is not one.
MAX_FILE_BYTES = 64 * 1024


@dataclass(frozen=True)
class RobotFile:
    """The contents of a robot file, its paths resolved against the file's folder."""

    path: Path
    urdf: str
    base_end: str
    neck_end: str
    head_tip: str
    root: str | None = None
    map: Path | None = None


def read_toml(path: str | os.PathLike, what: str) -> dict:
    """A small TOML file as a dict; ValueError naming the file for a missing, oversized or malformed one."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"a {what} path must be a str or os.PathLike, got {type(path).__name__}")
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{what} {os.fspath(p)!r} does not exist or is not a regular file")
    try:
        with open(p, "rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read {what} {os.fspath(p)!r}: {exc.strerror or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ValueError(f"{what} {os.fspath(p)!r} is larger than {MAX_FILE_BYTES} bytes")
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"{what} {os.fspath(p)!r} is not valid TOML: {exc}") from None


def check_keys(data: dict, required: Sequence[str], optional: Sequence[str], where: str) -> None:
    """ValueError for unknown or missing keys of a TOML table."""
    unknown = sorted(set(data) - set(required) - set(optional))
    if unknown:
        raise ValueError(f"{where}: unknown key{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                         f"(known: {', '.join(list(required) + list(optional))})")
    missing = [k for k in required if k not in data]
    if missing:
        raise ValueError(f"{where}: missing {', '.join(map(repr, missing))}")


def _string(data: dict, key: str, where: str) -> str:
    v = data[key]
    if not isinstance(v, str) or not v:
        raise ValueError(f"{where}: {key!r} must be a non-empty string, got {v!r}")
    return v


def read_robot_file(path: str | os.PathLike) -> RobotFile:
    """Read and check a robot file (see the module's docstring). ValueError names the file and the problem."""
    data = read_toml(path, "robot file")
    where = f"robot file {os.fspath(path)!r}"
    check_keys(data, REQUIRED_KEYS, OPTIONAL_KEYS, where)
    folder = Path(path).resolve().parent
    urdf = folder / _string(data, "urdf", where)
    if not urdf.is_file():
        raise ValueError(f"{where}: its urdf {os.fspath(urdf)!r} does not exist")
    map_path = None
    if "map" in data:
        map_path = folder / _string(data, "map", where)
        if not map_path.is_file():
            raise ValueError(f"{where}: its map {os.fspath(map_path)!r} does not exist")
    return RobotFile(path=Path(path), urdf=os.fspath(urdf), base_end=_string(data, "base_end", where),
                     neck_end=_string(data, "neck_end", where), head_tip=_string(data, "head_tip", where),
                     root=_string(data, "root", where) if "root" in data else None, map=map_path)


def write_robot_file(path: str | os.PathLike, *, urdf: str | os.PathLike, base_end: str, neck_end: str,
                     head_tip: str, root: str | None = None, map: str | os.PathLike | None = None) -> Path:
    """Write a robot file; ``urdf`` and ``map`` are written relative to the file's folder when they lie under it."""
    out = Path(path)
    folder = out.resolve().parent

    def rel(where: str | os.PathLike[str]) -> str:
        p = Path(where).resolve()
        try:
            return p.relative_to(folder).as_posix()
        except ValueError:
            return os.path.relpath(p, folder).replace(os.sep, "/")

    lines = [f"urdf = {_toml_string(rel(urdf))}"]
    if root is not None:
        lines.append(f"root = {_toml_string(root)}")
    lines += [f"base_end = {_toml_string(base_end)}", f"neck_end = {_toml_string(neck_end)}",
              f"head_tip = {_toml_string(head_tip)}"]
    if map is not None:
        lines.append(f"map = {_toml_string(rel(map))}")
    from .._files import write_text_atomic

    write_text_atomic(out, "\n".join(lines) + "\n")
    return out


def _toml_string(s: str) -> str:
    if not isinstance(s, str):
        raise TypeError(f"expected a str, got {type(s).__name__}")
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'
