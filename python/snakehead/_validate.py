"""Input checks shared by every public function, one per kind of input: numpy in, a clear error out.

A value of the wrong kind (a str, a bool, None where a number is needed) is a TypeError; a value of the right
kind that is wrong (NaN, out of range, too large, the wrong shape) is a ValueError. Every message names the
argument and says what was wrong. Durations and sizes have upper limits (:data:`MAX_DURATION_S`,
:data:`MAX_SAMPLES`): a value that would run for days or allocate without bound is refused at once.
"""
from __future__ import annotations

import numbers
import os
import stat
import unicodedata
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ._errors import InputError, InputTypeError
from .limits import MAX_TIMEOUT_S

ORTHONORMAL_TOLERANCE = 1e-6

#: The longest duration (s) any argument may ask for: one day, the C++ core's limit on timeouts
#: (:data:`snakehead.limits.MAX_TIMEOUT_S`). A plan, a simulation or a gait run of more than a day is a mistake.
MAX_DURATION_S = MAX_TIMEOUT_S

#: The most samples a trajectory, a simulation's record or a sampled curve may have: 2000 s at the 2 ms control
#: period, ~130 MB for a 16-joint robot's joint angles in float64. Beyond it an allocation would exhaust memory.
MAX_SAMPLES = 1_000_000


def _shown(x: Any) -> str:
    """``repr(x)`` cut short for messages (an int of 10**400 has 401 digits)."""
    text = repr(x)
    return text if len(text) <= 60 else text[:40] + "..." + text[-10:]


def _not_a_number(x: Any) -> bool:
    """Text, a bool or None: values that numpy would turn into numbers (or NaN) but that are not numbers."""
    return x is None or isinstance(x, (str, bytes, bool, np.bool_))


def finite_array(x: npt.ArrayLike, name: str, shape: tuple | None = None) -> np.ndarray:
    """``x`` as a float64 array; ValueError unless finite and (when given) of ``shape`` (None = any size).

    TypeError for text, booleans or None (numpy would read ``"1"`` and True as 1.0, None as NaN)."""
    if type(x) is np.ndarray and x.dtype == np.float64:  # the common case inside the library: shape and finiteness
        return _shaped_finite(x, name, shape)
    if _not_a_number(x):
        raise InputTypeError(f"{name} must be numbers, got {type(x).__name__} {_shown(x)}")
    try:
        raw = x if isinstance(x, np.ndarray) else np.asarray(x)
    except (TypeError, ValueError, OverflowError) as exc:  # e.g. ragged nested lists
        raise InputError(f"{name} must be an array of numbers: {exc}") from None
    if raw.dtype.kind in "USb" or (raw.dtype.kind == "O" and any(_not_a_number(v) for v in raw.flat)):
        what = "booleans" if raw.dtype.kind == "b" else "text" if raw.dtype.kind in "US" else "None or text"
        raise InputTypeError(f"{name} must be numbers, got {what}")
    if raw.dtype.kind in "cmMV":  # numpy would drop the imaginary part (with a warning only), or read dates
        raise InputTypeError(f"{name} must be real numbers, got {raw.dtype}")
    try:
        a = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:  # None, complex, objects, ints beyond a float
        raise InputError(f"{name} must be an array of numbers: {exc}") from None
    return _shaped_finite(a, name, shape)


def _shaped_finite(a: np.ndarray, name: str, shape: tuple | None) -> np.ndarray:
    """:func:`finite_array`'s last checks of a float64 array: its shape (when given) and every value finite."""
    if shape is not None:
        if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
            want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"{name} has shape {a.shape}; expected {want}")
    if not np.isfinite(a).all():
        raise InputError(f"{name} contains NaN or inf")
    return a


def joint_vector(q: npt.ArrayLike, n: int, name: str = "q") -> np.ndarray:
    """A 1-D float64 vector of ``n`` finite joint values."""
    return finite_array(q, name, (n,))


def within_limits(q: npt.ArrayLike, lower: npt.ArrayLike, upper: npt.ArrayLike, name: str = "q",
                  tolerance: float = 1e-9) -> np.ndarray:
    """Joint values ``q`` (n,) or (T, n), finite, within [lower - tolerance, upper + tolerance]; ValueError naming
    the first value outside (a start or a state outside the limits would be carried into a result)."""
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    a = finite_array(q, name)
    if a.ndim not in (1, 2) or a.shape[-1] != lo.shape[-1]:
        raise InputError(f"{name} has shape {a.shape}; expected ({lo.shape[-1]},)" +
                         ("" if a.ndim == 1 else f" or (T, {lo.shape[-1]})"))
    bad = np.argwhere((a < lo - tolerance) | (a > hi + tolerance))
    if len(bad):
        at = tuple(int(i) for i in bad[0])
        j = at[-1]
        where = f"{name}[{', '.join(map(str, at))}]"
        raise InputError(f"{where} = {a[at]:.6g} is outside the joint limits [{lo[j]:.6g}, {hi[j]:.6g}]")
    return a


def vector3(v: npt.ArrayLike, name: str) -> np.ndarray:
    return finite_array(v, name, (3,))


#: The largest coordinate (m) of a point in the world (a target, an obstacle, a base): a kilometre. Snakes crawl a
#: few metres; beyond this, the planner's arithmetic (squared distances, figure extents) would lose all precision.
MAX_COORDINATE_M = 1000.0


def world_position(v: npt.ArrayLike, name: str) -> np.ndarray:
    """A point (3,) in the world: finite, each coordinate within +-:data:`MAX_COORDINATE_M`."""
    a = vector3(v, name)
    if np.abs(a).max() > MAX_COORDINATE_M:
        raise InputError(f"{name} = {np.array2string(a, precision=4)} m is farther than {MAX_COORDINATE_M:g} m from "
                         "the world's origin (the most any coordinate may be)")
    return a


def unit_vector3(v: npt.ArrayLike, name: str) -> np.ndarray:
    a = vector3(v, name)
    scale = float(np.abs(a).max())  # divided out first: the norm of a huge finite vector overflows to inf
    if scale * float(np.linalg.norm(a / scale)) < 1e-12 if scale > 0 else True:
        raise InputError(f"{name} has zero length; a direction is needed")
    a = a / scale
    return a / np.linalg.norm(a)


def position_direction_pairs(positions: npt.ArrayLike, directions: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, bool]:
    """Poses given as positions and directions, (3,) or (K, 3) each: (K, 3) positions, (K, 3) unit directions and
    whether one pose was given. ValueError for wrong shapes, NaN or inf, unequal counts or a zero direction."""
    p = finite_array(positions, "positions")
    d = finite_array(directions, "directions")
    single = p.ndim == 1 and d.ndim == 1
    p, d = np.atleast_2d(p), np.atleast_2d(d)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"positions must have shape (3,) or (K, 3), got {np.shape(positions)}")
    if d.ndim != 2 or d.shape[1] != 3:
        raise InputError(f"directions must have shape (3,) or (K, 3), got {np.shape(directions)}")
    if len(p) != len(d):
        raise InputError(f"{len(p)} positions but {len(d)} directions; give one direction per position")
    scale = np.abs(d).max(axis=1)  # divided out first: the norm of a huge finite vector overflows to inf
    d = d / np.where(scale > 0, scale, 1.0)[:, None]
    norm = np.linalg.norm(d, axis=1)
    if np.any(scale * norm < 1e-12):
        raise InputError(f"directions must be non-zero; direction {int(np.argmin(scale * norm))} has zero length")
    return p, d / norm[:, None], single


def pose(T: npt.ArrayLike, name: str = "pose") -> np.ndarray:
    """A 4x4 homogeneous transform with an orthonormal, right-handed rotation."""
    a = finite_array(T, name, (4, 4))
    if not np.allclose(a[3], (0.0, 0.0, 0.0, 1.0), atol=1e-9):
        raise InputError(f"{name} last row must be [0, 0, 0, 1], got {a[3].tolist()}")
    rotation_matrix(a[:3, :3], name + " rotation")
    return a


def rotation_matrix(R: npt.ArrayLike, name: str = "rotation") -> np.ndarray:
    a = finite_array(R, name, (3, 3))
    err = np.abs(a.T @ a - np.eye(3)).max()
    if err > ORTHONORMAL_TOLERANCE or np.linalg.det(a) < 0:
        raise InputError(f"{name} is not a rotation (orthonormality error {err:.2e}, det {np.linalg.det(a):+.3f})")
    return a


def real_number(x: Any, name: str) -> float:
    """``x`` as a float: an int, a float, a numpy number or a 0-d numeric array. TypeError for anything else
    (bool, str, None, complex, a sequence); ValueError for an int too large for a float. NaN and inf pass
    (see :func:`finite_float`)."""
    if isinstance(x, np.ndarray) and x.ndim == 0 and x.dtype.kind in "iuf":
        x = x[()]
    if _not_a_number(x) or not isinstance(x, numbers.Real):
        raise InputTypeError(f"{name} must be a real number, got {type(x).__name__} {_shown(x)}")
    try:
        return float(x)
    except OverflowError:
        raise InputError(f"{name} is too large for a float, got {_shown(x)}") from None


def finite_float(x: Any, name: str) -> float:
    """``x`` as a finite float (:func:`real_number`); ValueError naming ``name`` for NaN or inf."""
    v = real_number(x, name)
    if not np.isfinite(v):
        raise InputError(f"{name} must be finite, got {_shown(x)}")
    return v


def positive(x: Any, name: str, *, maximum: float | None = None) -> float:
    """``x`` as a positive finite float, at most ``maximum`` when given; ValueError naming ``name`` otherwise."""
    v = finite_float(x, name)
    if v <= 0:
        raise InputError(f"{name} must be a positive finite number, got {_shown(x)}")
    if maximum is not None and v > maximum:
        raise InputError(f"{name} must be at most {maximum:g}, got {_shown(x)}")
    return v


def non_negative(x: Any, name: str, *, maximum: float | None = None) -> float:
    """``x`` as a finite float >= 0, at most ``maximum`` when given; ValueError naming ``name`` otherwise."""
    v = finite_float(x, name)
    if v < 0:
        raise InputError(f"{name} must be >= 0, got {_shown(x)}")
    if maximum is not None and v > maximum:
        raise InputError(f"{name} must be at most {maximum:g}, got {_shown(x)}")
    return v


def duration(x: Any, name: str, *, allow_zero: bool = False, maximum: float = MAX_DURATION_S) -> float:
    """A duration in seconds: finite, > 0 (>= 0 with ``allow_zero``) and at most ``maximum`` (one day)."""
    v = finite_float(x, name)
    if v < 0 or (v == 0 and not allow_zero):
        raise InputError(f"{name} must be {'>= 0' if allow_zero else '> 0'} s, got {_shown(x)}")
    if v > maximum:
        raise InputError(f"{name} must be at most {maximum:g} s, got {_shown(x)}")
    return v


def integer(n: Any, name: str, *, least: int | None = None, most: int | None = None) -> int:
    """``n`` as an int within [least, most]: an int or a numpy integer (TypeError for bool, float, str...)."""
    if isinstance(n, np.ndarray) and n.ndim == 0 and n.dtype.kind in "iu":
        n = n[()]
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)):
        raise InputTypeError(f"{name} must be an integer, got {type(n).__name__} {_shown(n)}")
    v = int(n)
    if (least is not None and v < least) or (most is not None and v > most):
        bounds = (f"between {least} and {most}" if least is not None and most is not None else
                  f">= {least}" if least is not None else f"<= {most}")
        raise InputError(f"{name} must be {bounds}, got {_shown(n)}")
    return v


def sample_count(span: float, step: float, name: str, *, maximum: int = MAX_SAMPLES, unit: str = "s") -> int:
    """How many samples a ``span`` takes at ``step`` (both ends included; both in ``unit``), ValueError when more
    than ``maximum``: the check before an allocation (or a loop) whose size the caller's numbers decide."""
    span, step = finite_float(span, f"{name} ({unit})"), positive(step, f"{name}'s step ({unit})")
    steps = span / step
    if not steps <= maximum - 1:  # also NaN
        raise InputError(f"{name}: {span:g} {unit} in steps of {step:g} {unit} is {steps + 1:.3g} samples; at most "
                         f"{maximum} (shorten it or take longer steps)")
    return int(np.floor(max(steps, 0.0) + 1e-9)) + 1


def sequence(x: Any, name: str) -> tuple:
    """``x`` (a list, tuple or other iterable but text, bytes or a mapping) as a tuple; TypeError otherwise (Python's
    own "'NoneType' object is not iterable" does not say which argument)."""
    if isinstance(x, (str, bytes, Mapping)) or not isinstance(x, Iterable):
        raise InputTypeError(f"{name} must be a sequence, got {type(x).__name__} {_shown(x)}")
    return tuple(x)


#: The longest name (characters) of a target, a phase or anything else named in the outputs: shown in figure titles,
#: legends and tables, where a longer one would only be cut off or stretch the figure.
MAX_NAME_CHARS = 200

#: The longest name (UTF-8 bytes) that goes into a file name (a scene's: ``NAME_trajectory.csv``, ``NAME.html``...).
MAX_NAME_BYTES = 100

#: Unicode categories that no name may hold: control characters (Cc: newline, tab, NUL, escape, DEL, C1 controls),
#: format characters (Cf: zero-width spaces and joiners, bidirectional overrides, the soft hyphen), lone surrogates
#: (Cs: not text at all) and line and paragraph separators (Zl, Zp). A name is one line of visible text.
NAME_FORBIDDEN_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Zl", "Zp"})

#: What a name that names files may not hold besides: path separators, and what Windows refuses in a file name
#: (":" would write an NTFS alternate stream), so that an output folder can be copied anywhere.
FILE_NAME_FORBIDDEN = frozenset('/\\<>:"|?*')

#: Device names that Windows reserves with any suffix (``NUL.html`` is the null device there), compared caseless.
RESERVED_FILE_NAMES = frozenset({"con", "prn", "aux", "nul", *(f"com{i}" for i in range(1, 10)),
                                 *(f"lpt{i}" for i in range(1, 10))})


def _char(c: str) -> str:
    """A character as a message shows it: ``U+000A`` and its Unicode name where it has one."""

    kind = {"Cc": "a control character", "Cs": "a lone surrogate"}.get(unicodedata.category(c), "")
    name = unicodedata.name(c, "") or kind
    return f"U+{ord(c):04X}" + (f" ({name})" if name else "")


def _forbidden_chars(text: str, allowed: str = "") -> list[str]:

    return sorted({c for c in text if c not in allowed and unicodedata.category(c) in NAME_FORBIDDEN_CATEGORIES})


def name_text(name: Any, what: str, *, max_chars: int = MAX_NAME_CHARS) -> str:
    """A name from the user (a target's, a scene's): a str of 1 to ``max_chars`` characters, not only whitespace,
    without characters of :data:`NAME_FORBIDDEN_CATEGORIES` (newline, tab, NUL, escape, zero-width and bidirectional
    marks, surrogates...). Everything else printable is a valid name -- ``$``, ``\\``, ``<script>``, ``|``, backticks,
    any script or emoji -- and every writer shows it literally (escaped for matplotlib, Markdown, HTML). Returned
    unchanged; :class:`InputTypeError` for a non-str, :class:`InputError` naming ``what`` otherwise."""
    _text(name, what, "", max_chars, "a name is one line of printable text (no control, format or line-separator "
          "characters)")
    if not name.strip():
        raise InputError(f"{what} must be a name (visible text), got {name!r}")
    return name


def display_text(text: Any, what: str, *, max_chars: int = 10_000) -> str:
    """Free text shown in the outputs (a scene's description, in figure titles and the viewer's page): a str of at
    most ``max_chars`` characters that may hold newlines and tabs but no other character of
    :data:`NAME_FORBIDDEN_CATEGORIES` (escape sequences would reach the terminal, a surrogate fails every writer)."""
    return _text(text, what, "\n\t", max_chars, "only newlines and tabs of the control characters are kept in text")


def _text(text: Any, what: str, allowed: str, max_chars: int, rule: str) -> str:
    """``text`` if it is a str of at most ``max_chars`` characters without forbidden characters (but ``allowed``);
    else the error, ending with ``rule``."""
    if not isinstance(text, str):
        raise InputTypeError(f"{what} must be a str, got {type(text).__name__} {_shown(text)}")
    bad = _forbidden_chars(text, allowed=allowed)
    if bad:
        raise InputError(f"{what} {_shown(text)} holds {', '.join(map(_char, bad))}: {rule}")
    if len(text) > max_chars:
        raise InputError(f"{what} is {len(text)} characters long; at most {max_chars}")
    return text


def file_name_part(name: Any, what: str) -> str:
    """A name that becomes part of a file name (``out / f"{name}_trajectory.csv"``): a :func:`name_text` without
    path separators or the characters Windows refuses in file names (:data:`FILE_NAME_FORBIDDEN`), not "." or "..",
    not a reserved device name (:data:`RESERVED_FILE_NAMES`, with or without a suffix), at most
    :data:`MAX_NAME_BYTES` bytes in UTF-8. Anything else could write outside the output folder, fail half-way
    through the outputs, or make an output folder that cannot be copied to another system."""
    if isinstance(name, str) and name in (".", ".."):
        raise InputError(f"{what} must be a name, got {name!r}")
    if isinstance(name, str) and name:
        bad = sorted({c for c in name if c in FILE_NAME_FORBIDDEN})
        if bad:
            raise InputError(f"{what} {_shown(name)} holds {', '.join(map(repr, bad))}: it names files, so it may "
                             "not hold path separators or the characters < > : \" | ? *")
    name_text(name, what, max_chars=MAX_NAME_BYTES)
    if name.split(".")[0].rstrip(" ").lower() in RESERVED_FILE_NAMES:
        raise InputError(f"{what} {_shown(name)} is a device name on Windows (NUL.html is not a file there); it "
                         "names files, so choose another")
    size = len(name.encode("utf-8"))  # name_text refused surrogates: it encodes
    if size > MAX_NAME_BYTES:
        raise InputError(f"{what} is {size} bytes long in UTF-8; at most {MAX_NAME_BYTES} (it names files)")
    return name


def file_name_key(name: str) -> str:
    """What two names that name files must not share: names equal under Unicode normalisation and case folding
    ("Hole" and "hole", "é" composed and decomposed) are one file on macOS's and Windows's file systems."""

    return unicodedata.normalize("NFC", unicodedata.normalize("NFD", name).casefold())


def input_file(path: Any, what: str, max_bytes: int) -> Path:
    """A file to read: a path (str or os.PathLike; TypeError otherwise) to an existing regular file of at most
    ``max_bytes`` bytes. Checked without opening it: a FIFO would block, /dev/zero would be read forever, a
    directory or a device is not a file. Otherwise ValueError "cannot read {what} {path}: {why}"."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputTypeError(f"{what} must be a path (str or os.PathLike), got {type(path).__name__}")
    text = os.fspath(path)
    if isinstance(text, bytes):
        raise InputTypeError(f"{what} must be a str path, got bytes")
    if "\0" in text:
        raise InputError(f"cannot read {what} {text!r}: the path holds a NUL character")
    problem, info = _file_problem(text)
    if problem is not None or info is None:
        raise InputError(f"cannot read {what} {text!r}: {problem}")
    if info.st_size > max_bytes:
        raise InputError(f"cannot read {what} {text!r}: it is {info.st_size} bytes; at most {max_bytes} are read")
    return Path(text)


def _file_problem(path: str) -> tuple[str | None, os.stat_result | None]:
    """Why ``path`` is not a regular file to read (None when it is), and its stat."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return "it does not exist", None
    except (OSError, ValueError) as exc:
        return str(getattr(exc, "strerror", None) or exc), None
    if not stat.S_ISREG(info.st_mode):
        kind = ("a directory" if stat.S_ISDIR(info.st_mode) else "a FIFO" if stat.S_ISFIFO(info.st_mode) else
                "a character device" if stat.S_ISCHR(info.st_mode) else "a block device" if stat.S_ISBLK(info.st_mode)
                else "a socket" if stat.S_ISSOCK(info.st_mode) else "not a regular file")
        return f"it is {kind}, not a regular file", info
    return None, info


def file_problem(path: str | os.PathLike) -> str | None:
    """Why ``path`` is not an existing regular file ("it does not exist", "it is a directory, ..."), or None."""
    return _file_problem(os.fspath(path))[0]
