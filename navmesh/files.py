"""Reading an input file safely: a regular file of bounded size, or a one-line refusal.

Every file the user names (a level, a preset, a trace) is read through :func:`read_regular`:
a FIFO, a device (``/dev/zero``), a socket or a directory is refused before a byte is read
— a FIFO is opened without blocking, so a path nobody writes to cannot hang the command —
and a file larger than the caller's limit is refused instead of read into memory; the read
itself is bounded too, so a file that grows while it is read cannot exhaust memory either.

>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> fifo = os.path.join(folder, "pipe")
>>> os.mkfifo(fifo)
>>> read_regular(fifo, 1024)
Traceback (most recent call last):
...
navmesh.files.FileRefused: is a FIFO (named pipe), not a regular file
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .errors import UserError

__all__ = ["FileRefused", "read_regular"]

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


# never wait for a FIFO's writer, never adopt a terminal as controlling tty
_FLAGS = os.O_RDONLY | (os.O_NONBLOCK | os.O_NOCTTY if os.name == "posix" else 0)


class FileRefused(UserError):
    """An input that is not a regular file or is too large; the message is the problem only
    (callers prefix the file and the field in their own error type)."""


def _mebibytes(n: int) -> str:
    return f"{n / 2**20:.0f} MiB" if n >= 2**20 else f"{n} bytes"


def read_regular(path: str | Path, limit: int) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes.

    Raises :class:`FileRefused` for another kind of file or a larger one; ``OSError``
    (``FileNotFoundError``, ``PermissionError``, ...) as :func:`open` does.
    """
    fd = os.open(path, _FLAGS)
    try:
        info = os.fstat(fd)
        for test, kind in _KINDS:
            if test(info.st_mode):
                raise FileRefused(f"is {kind}, not a regular file")
        if not stat.S_ISREG(info.st_mode):  # pragma: no cover - doors, whiteouts
            raise FileRefused("is not a regular file")
        if info.st_size > limit:
            raise FileRefused(f"is {_mebibytes(info.st_size)}, larger than the limit of "
                              f"{_mebibytes(limit)}")
        chunks: list[bytes] = []
        total = 0
        while total <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > limit:
            raise FileRefused(f"grew past the limit of {_mebibytes(limit)} while it was read")
        return b"".join(chunks)
    finally:
        os.close(fd)
