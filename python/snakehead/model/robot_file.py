"""Robot files: a snake robot described in TOML (read with the standard library's ``tomllib``).

::

    # my_snake.toml
    urdf = "my_snake.urdf"        # path relative to this file (required); a .xacro file is expanded
    xacro_args = { modules = 12 } # optional: the xacro file's arguments
    root = "tail"                 # optional: the URDF's root link by default
    base_end = "base_end"         # the frame that ends the base part (P0)
    neck_end = "neck_end"         # the frame that ends the neck part (B0, the head's base frame)
    head_tip = "head_tip"         # the head link frame
    head_axis = "x"               # optional: head_tip's axis that points where the head looks ("x", "y", "z", "-z"...)
    map = "my_snake_head.npz"     # optional: the head's reachability map (relative to this file)
    inertia = "from_shapes"       # optional: recompute <inertial> from the collision shapes (default "urdf")
    density = 1200.0              # optional, with from_shapes: kg/m^3 (default: each link's URDF mass)

    [packages]                    # optional: package://NAME/... mesh paths (relative to this file); then
    my_snake_description = "."    # ROS_PACKAGE_PATH

    [limits]                      # optional; needed for continuous joints: [lower, upper] rad
    joint_3 = [-1.57, 1.57]

    [home]                        # optional: joint angles (rad) at which the body lies straight (default 0);
    joint_2 = 0.035               # a branch joint (a passive wheel) named here is held at this value

Any link or fixed marker frame of the URDF may be named. The parts are the joints between the frames: base =
root -> base_end, neck = base_end -> neck_end, head = neck_end -> head_tip (a frame named by a link's name sits at
that link's origin, which is on the joint that moves it). ``SnakeRobot.from_file(path)`` reads one.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from .._errors import InputError, InputTypeError
from .._files import write_text_atomic
from .._validate import file_problem, input_file
from .body_frame import HEAD_AXES
from .mass_properties import check_inertia_source

__all__ = ["REQUIRED_KEYS", "OPTIONAL_KEYS", "MAX_FILE_BYTES", "default_robot_file", "default_urdf_path", "RobotFile",
           "read_toml", "check_keys", "read_robot_file", "write_robot_file", "path_from", "toml_string"]

#: The keys of a robot file; the first four frame keys but ``root`` are required, with ``urdf``.
REQUIRED_KEYS = ("urdf", "base_end", "neck_end", "head_tip")
OPTIONAL_KEYS = ("root", "map", "head_axis", "xacro_args", "packages", "limits", "home", "inertia", "density")

#: A robot file is a few lines; anything larger is not one.
MAX_FILE_BYTES = 64 * 1024


def default_robot_file() -> Path:
    """Path of the shipped robot file ``snake16.toml`` (package data; the source tree's copy when run in place)."""
    for folder in (Path(__file__).resolve().parents[1] / "urdf", Path(__file__).resolve().parents[3] / "urdf"):
        if (folder / "snake16.toml").exists():
            return folder / "snake16.toml"
    raise FileNotFoundError("snake16.toml is neither installed with the package nor in the source tree")


def default_urdf_path() -> Path:
    """Path of the shipped ``snake16.urdf`` (beside :func:`default_robot_file`)."""
    return default_robot_file().with_name("snake16.urdf")


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
    head_axis: str = "x"
    xacro_args: dict | None = None
    packages: dict | None = None
    limits: dict | None = None
    home: dict | None = None
    inertia: str = "urdf"
    density: float | None = None


def read_toml(path: str | os.PathLike, what: str, max_bytes: int = MAX_FILE_BYTES) -> dict:
    """A small TOML file (at most ``max_bytes``) as a dict; ValueError naming the file for a missing, oversized or
    malformed one."""
    p = input_file(path, what, max_bytes)
    try:
        with open(p, "rb") as f:
            raw = f.read(max_bytes + 1)
    except OSError as exc:
        raise InputError(f"cannot read {what} {os.fspath(p)!r}: {exc.strerror or exc}") from None
    if len(raw) > max_bytes:
        raise InputError(f"{what} {os.fspath(p)!r} is larger than {max_bytes} bytes")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{what} {os.fspath(p)!r} is not UTF-8 text: {exc}") from None
    try:  # a byte-order mark (Windows editors write one) is not part of the TOML
        return tomllib.loads(text.removeprefix("\ufeff"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{what} {os.fspath(p)!r} is not valid TOML: {exc}") from None
    except RecursionError:  # tomllib parses nested arrays and tables recursively
        raise InputError(f"{what} {os.fspath(p)!r} nests arrays or tables too deeply to be read") from None


def check_keys(data: dict, required: Sequence[str], optional: Sequence[str], where: str) -> None:
    """ValueError for unknown or missing keys of a TOML table."""
    unknown = sorted(set(data) - set(required) - set(optional))
    if unknown:
        raise InputError(f"{where}: unknown key{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))} "
                         f"(known: {', '.join(list(required) + list(optional))})")
    missing = [k for k in required if k not in data]
    if missing:
        raise InputError(f"{where}: missing {', '.join(map(repr, missing))}")


def _string(data: dict, key: str, where: str) -> str:
    v = data[key]
    if not isinstance(v, str) or not v:
        raise InputError(f"{where}: {key!r} must be a non-empty string, got {v!r}")
    return v


def _kept_inside(path: Path, inside: Path | None, where: str, key: str) -> Path:
    """``path`` when ``inside`` is None or it lies inside ``inside`` once links are resolved; else InputError."""
    if inside is not None and not path.resolve().is_relative_to(inside.resolve()):
        raise InputError(f"{where}: its {key} {os.fspath(path)!r} is outside the folder {os.fspath(inside)!r} of the "
                         "scene file that names this robot; a robot reached through a scene reads only files there")
    return path


def read_robot_file(path: str | os.PathLike, inside: Path | None = None) -> RobotFile:
    """Read and check a robot file (see the module's docstring). ValueError names the file and the problem.
    ``inside``: a folder its urdf, map and packages must lie in (a robot named by an untrusted scene file: the
    scene's folder); None for a robot file the user gives."""
    data = read_toml(path, "robot file")
    where = f"robot file {os.fspath(path)!r}"
    check_keys(data, REQUIRED_KEYS, OPTIONAL_KEYS, where)
    folder = Path(path).resolve().parent
    urdf = _kept_inside(folder / _string(data, "urdf", where), inside, where, "urdf")
    if (problem := file_problem(urdf)) is not None:
        raise InputError(f"{where}: its urdf {os.fspath(urdf)!r}: {problem}")
    map_path = None
    if "map" in data:
        map_path = _kept_inside(folder / _string(data, "map", where), inside, where, "map")
        if (problem := file_problem(map_path)) is not None:
            raise InputError(f"{where}: its map {os.fspath(map_path)!r}: {problem}")
    return RobotFile(path=Path(path), urdf=os.fspath(urdf), base_end=_string(data, "base_end", where),
                     neck_end=_string(data, "neck_end", where), head_tip=_string(data, "head_tip", where),
                     root=_string(data, "root", where) if "root" in data else None, map=map_path,
                     head_axis=_head_axis(data, where),
                     xacro_args=_xacro_args(data, where), packages=_packages(data, folder, where, inside),
                     limits=_limits(data, where), home=_home(data, where), **_inertia(data, where))


def _inertia(data: dict, where: str) -> dict:
    """``inertia`` ("urdf" or "from_shapes") and ``density`` (kg/m^3, only with "from_shapes"), checked."""
    inertia, density = check_inertia_source(data.get("inertia", "urdf"), data.get("density"), where)
    return {"inertia": inertia, "density": density}


def _table(data: dict, key: str, where: str) -> dict:
    v = data.get(key, {})
    if not isinstance(v, dict):
        raise InputError(f"{where}: {key!r} must be a table, got {v!r}")
    return v


def _xacro_args(data: dict, where: str) -> dict | None:
    args = _table(data, "xacro_args", where)
    for k, v in args.items():
        if isinstance(v, bool) or not isinstance(v, (str, int, float)):
            raise InputError(f"{where}: xacro_args.{k} must be a string or a number, got {v!r}")
    return dict(args) or None


def _packages(data: dict, folder: Path, where: str, inside: Path | None = None) -> dict | None:
    out = {}
    for name, value in _table(data, "packages", where).items():
        if not isinstance(value, str) or not value:
            raise InputError(f"{where}: packages.{name} must be a folder (a non-empty string), got {value!r}")
        path = _kept_inside(folder / value, inside, where, f"packages.{name}")
        if not path.is_dir():
            raise InputError(f"{where}: packages.{name} = {value!r}: {os.fspath(path)!r} is not a folder")
        out[name] = path
    return out or None


def _limits(data: dict, where: str) -> dict | None:
    out = {}
    for joint, value in _table(data, "limits", where).items():
        ok = isinstance(value, list) and len(value) == 2 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        if not ok or not (math.isfinite(value[0]) and math.isfinite(value[1]) and value[0] < value[1]):
            raise InputError(f"{where}: limits.{joint} must be [lower, upper] in rad with lower < upper, got {value!r}")
        out[joint] = (float(value[0]), float(value[1]))
    return out or None


def _head_axis(data: dict, where: str) -> str:
    value = data.get("head_axis", "x")
    if value not in HEAD_AXES:
        raise InputError(f"{where}: 'head_axis' must be one of {', '.join(HEAD_AXES)} (the head_tip frame's axis that "
                         f"points where the head looks), got {value!r}")
    return value


def _home(data: dict, where: str) -> dict | None:
    out = {}
    for joint, value in _table(data, "home", where).items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"{where}: home.{joint} must be an angle in rad (a finite number), got {value!r}")
        out[joint] = float(value)
    return out or None


def write_robot_file(path: str | os.PathLike, *, urdf: str | os.PathLike, base_end: str, neck_end: str,
                     head_tip: str, root: str | None = None, map: str | os.PathLike | None = None) -> Path:
    """Write a robot file; ``urdf`` and ``map`` are written relative to the file's folder when they lie under it."""
    out = Path(path)
    folder = out.resolve().parent
    lines = [f"urdf = {toml_string(path_from(folder, urdf))}"]
    if root is not None:
        lines.append(f"root = {toml_string(root)}")
    lines += [f"base_end = {toml_string(base_end)}", f"neck_end = {toml_string(neck_end)}",
              f"head_tip = {toml_string(head_tip)}"]
    if map is not None:
        lines.append(f"map = {toml_string(path_from(folder, map))}")
    write_text_atomic(out, "\n".join(lines) + "\n")
    return out


def path_from(folder: Path, where: str | os.PathLike[str]) -> str:
    """``where`` as a file written in ``folder`` names it: relative to ``folder`` (with "/"), "../" where needed."""
    p = Path(where).resolve()
    try:
        return p.relative_to(folder).as_posix()
    except ValueError:
        return os.path.relpath(p, folder).replace(os.sep, "/")


def toml_string(s: str) -> str:
    """``s`` as a TOML basic string: quotes, backslashes and control characters escaped (a name holding a newline
    or a quote must read back as itself, never end the string early or add a key)."""
    if not isinstance(s, str):
        raise InputTypeError(f"expected a str, got {type(s).__name__}")
    out = []
    for c in s:
        if c in '"\\':
            out.append("\\" + c)
        elif ord(c) < 32 or ord(c) == 127:
            out.append(f"\\u{ord(c):04x}")
        elif 0xD800 <= ord(c) <= 0xDFFF:
            raise InputError(f"{s!r} is not valid text (a lone surrogate)")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'
