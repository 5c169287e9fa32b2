"""Files, written so that a failure never leaves a half-written file (:func:`atomic_open`: a temporary file in the
same folder, flushed to disk, then renamed over the destination, an atomic step on POSIX file systems; or, by
:func:`write_new_file`, linked to a name nothing holds, never over a file; :func:`copy_into` copies a file into a
folder that way), and read without trusting them (:func:`read_npz`: .npz archives checked before anything is unpacked or allocated)."""
from __future__ import annotations

import contextlib
import math
import os
import re
import stat
import zipfile
import zlib
from pathlib import Path
from typing import IO, Any, Iterator

import numpy as np
from numpy.lib import format as npy

from ._errors import InputError
from ._validate import RESERVED_FILE_NAMES, input_file


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


#: Permissions of the files written here: as ``open`` would create them (mkstemp's are private, 0o600).
_FILE_MODE = 0o666 & ~_umask()


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "w", **kwargs: Any) -> Iterator[IO]:
    """Open a temporary file beside ``path`` for writing; on success it replaces ``path``, on any error it is
    removed and ``path`` is left as it was. ``mode`` is "w" (text; ``kwargs`` go to ``open``) or "wb"."""
    if mode not in ("w", "wb"):
        raise InputError(f"mode must be 'w' or 'wb', got {mode!r}")
    target = Path(path)
    if target.exists() and not target.is_file():  # the rename would replace a device, a FIFO, ...
        raise InputError(f"cannot write {str(target)!r}: it exists and is not a regular file")
    try:
        fd, tmp = _create_beside(target)
    except OSError as exc:
        raise InputError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, mode, **kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _FILE_MODE)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):  # a full disk, a folder removed meanwhile: where the output goes is wrong
            raise InputError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from exc
        raise


def _create_beside(target: Path) -> tuple[int, str]:
    """A new file in ``target``'s folder, made by this call (O_EXCL), with the permissions a plain ``open`` would
    give (0o666 less the umask; tempfile.mkstemp's 0o600 would end up on the destination)."""
    folder = target.parent if str(target.parent) else Path(".")
    for _ in range(100):
        tmp = str(folder / f".{target.name}.{os.urandom(6).hex()}.part")
        try:
            return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name beside {str(target)!r}")


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`atomic_open`)."""
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    return Path(path)


def write_new_file(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` as a new file, atomically and never over anything: a temporary file beside it,
    flushed to disk, then linked to ``path`` (a hard link is made only where nothing is: FileExistsError when
    ``path`` exists, a symbolic link included, and nothing is written); on any other failure no file is left at
    ``path`` and the error is an InputError "cannot write ..."."""
    target = Path(path)
    try:
        fd, tmp = _create_beside(target)
    except OSError as exc:
        raise InputError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _FILE_MODE)
        try:
            os.link(tmp, target)
        except FileExistsError:
            raise
        except OSError:  # a file system without hard links: create the file exclusively, written whole or removed
            _write_exclusive(target, data)
    except FileExistsError:
        raise
    except OSError as exc:
        raise InputError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from exc
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    return target


def _write_exclusive(target: Path, data: bytes) -> None:
    """``data`` in a new file ``target`` (O_EXCL, not through a symbolic link), removed if not written whole."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(target, flags, 0o666)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(target)
        raise


#: A copy's name (:func:`copy_into`): its source's, these characters only (others become "_"), its stem at most
#: this long.
_COPY_NAME_CHARS = re.compile(r"[^A-Za-z0-9_-]+")
_COPY_STEM_CHARS = 60
#: The names tried for a copy (``rock.stl``, ``rock-2.stl``, ... ``rock-100.stl``) before it is refused.
COPY_NAME_TRIES = 100


def copy_into(source: str | os.PathLike, folder: str | os.PathLike, what: str, max_bytes: int, *,
              taken: Path | None = None, kind: str = "file") -> Path:
    """A copy of the file ``source`` (a regular file of at most ``max_bytes`` bytes) in ``folder`` (an existing
    folder): its path. Named as its source (ASCII letters, digits, ``_`` and ``-``; others become ``_``; ``kind``
    prefixed to an empty or a device name) or, when a different file holds that name, ``NAME-2``, ``NAME-3``...; a
    regular file of that name with the same bytes is used as it is. Nothing is written over: a copy is a new file,
    written whole or not at all (:func:`write_new_file`), nor named ``taken`` (a file about to be written).
    InputError naming ``what`` if the source cannot be read or no name is free."""
    src, root = Path(source), Path(folder)
    data = input_file(src, what, max_bytes).read_bytes()
    stem, suffix = _copy_name(src, kind)
    for n in range(1, COPY_NAME_TRIES + 1):
        target = root / (f"{stem}{suffix}" if n == 1 else f"{stem}-{n}{suffix}")
        if target == taken:
            continue
        if _holds(target, data):
            return target
        try:
            return write_new_file(target, data)
        except FileExistsError:  # another file has the name: the next one
            continue
    raise InputError(f"{what} {os.fspath(src)!r} is not copied into {os.fspath(root)!r}: {stem}{suffix} to "
                     f"{stem}-{COPY_NAME_TRIES}{suffix} are all other files there")


def _copy_name(source: Path, kind: str) -> tuple[str, str]:
    """The stem and suffix a copy of ``source`` is named by (a portable name, not hidden, not a device name)."""
    stem = _COPY_NAME_CHARS.sub("_", source.stem).strip("_-")[:_COPY_STEM_CHARS] or kind
    if stem.lower() in RESERVED_FILE_NAMES:
        stem = f"{kind}_{stem}"
    suffix = source.suffix if re.fullmatch(r"\.[A-Za-z0-9]{1,10}", source.suffix) else ""
    return stem, suffix


def _holds(path: Path, data: bytes) -> bool:
    """Whether ``path`` is a regular file (not a link) holding ``data`` exactly."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return False
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(f.fileno())
        return stat.S_ISREG(info.st_mode) and info.st_size == len(data) and f.read(len(data) + 1) == data


def read_npz(path: str | os.PathLike, what: str, *, max_bytes: int) -> dict[str, np.ndarray]:
    """The arrays of a ``.npz`` archive (what ``numpy.savez`` writes), read without trusting the file.

    ``path`` must be a regular file of at most ``max_bytes`` bytes (:func:`snakehead._validate.input_file`); the
    archive's members, as its directory declares them, must be ``.npy`` arrays of at most ``max_bytes`` bytes in
    all, checked before anything is unpacked (a zip bomb of a few MB can declare gigabytes); each array's header
    must agree with its member's size before its memory is allocated; arrays of Python objects (pickles) are
    refused. Every failure -- an empty, truncated or corrupted file, a foreign one -- is an InputError (a ValueError)
    "cannot read {what} {path}: ..." naming, where it applies, the array: never EOFError, zipfile.BadZipFile or
    zlib.error.
    """
    p = input_file(path, what, max_bytes)
    where = f"cannot read {what} {os.fspath(p)!r}"
    try:
        archive = zipfile.ZipFile(p)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError) as exc:
        raise InputError(f"{where}: it is not a .npz archive (a zip of .npy arrays): {exc}") from None
    arrays: dict[str, np.ndarray] = {}
    with archive:
        members = archive.infolist()
        declared = sum(m.file_size for m in members)
        if declared > max_bytes:
            raise InputError(f"{where}: it would unpack to {declared} bytes, more than the {max_bytes} allowed (a "
                             "damaged file or a zip bomb)")
        for m in members:
            if m.is_dir() or not m.filename.endswith(".npy"):
                raise InputError(f"{where}: it holds {m.filename!r}, which is not a .npy array")
            key = m.filename[:-len(".npy")]
            if key in arrays:
                raise InputError(f"{where}: it holds the array {key!r} twice")
            try:
                with archive.open(m) as f:
                    arrays[key] = _read_npy(f, m.file_size)
            except ValueError as exc:
                raise InputError(f"{where}: its array {key!r} {exc}") from None
            except (zipfile.BadZipFile, zlib.error, OSError, EOFError, RuntimeError, NotImplementedError) as exc:
                raise InputError(f"{where}: its array {key!r} is damaged ({type(exc).__name__}: {exc})") from None
    return arrays


def _read_npy(f: IO[bytes], size: int) -> np.ndarray:
    """One .npy array from a stream that holds ``size`` bytes: its header checked against ``size`` first."""
    try:
        version = npy.read_magic(f)
    except ValueError as exc:
        raise InputError(f"is not a .npy array ({exc})") from None
    if version not in ((1, 0), (2, 0)):
        raise InputError(f"has an unsupported .npy format version {version}")
    try:
        read_header = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
        shape, fortran, dtype = read_header(f)
    except (ValueError, TypeError, SyntaxError, RecursionError, MemoryError) as exc:  # a Python literal, parsed safely
        raise InputError(f"has a damaged header ({exc})") from None
    if dtype.hasobject:
        raise InputError("holds Python objects (pickled), which are never read")
    if any(not isinstance(d, int) or d < 0 for d in shape):
        raise InputError(f"has an invalid shape {shape}")
    count = math.prod(shape)
    nbytes = count * dtype.itemsize
    if nbytes > size or count > size + 1:  # no more data than the member holds (itemsize 0: no more items)
        raise InputError(f"declares {shape} of {dtype} ({nbytes} bytes) but the archive holds {size} bytes for it")
    data = f.read(nbytes)
    if len(data) != nbytes:
        raise InputError(f"is truncated ({len(data)} of {nbytes} bytes)")
    if f.read(1):  # reading to the member's end also makes zipfile check its CRC
        raise InputError(f"holds more bytes than its header declares ({shape} of {dtype})")
    flat = np.frombuffer(data, dtype=dtype, count=count) if nbytes else np.zeros(count, dtype)
    return flat.reshape(shape, order="F" if fortran else "C").copy()
