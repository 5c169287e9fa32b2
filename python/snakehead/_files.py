"""Writing files so that a failure never leaves a half-written file: write a temporary file in the same folder,
flush it to disk, then rename it over the destination (an atomic step on POSIX file systems)."""
from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any, IO, Iterator



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
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    target = Path(path)
    if target.exists() and not target.is_file():  # the rename would replace a device, a FIFO, ...
        raise OSError(f"{str(target)!r} exists and is not a regular file")
    fd, tmp = _create_beside(target)
    try:
        with os.fdopen(fd, mode, **kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _FILE_MODE)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
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
