"""The results-directory lock: one writing sweep at a time, released by its holder's death.

The lock is an OS lock (``fcntl.flock``) on ``DIR/results.lock``, so the kernel drops it
when the holding process ends, however it ends (``kill -9`` included) — a file left by a
killed holder locks nothing. A holder that ends normally removes the file before it lets
go, so a finished results directory has no ``results.lock``; a taker checks that the file
it locked is still the one at the path (else it locked a removed file) and tries again. A ``flock`` is shared by every process that inherits its file descriptor, so a
pool worker forked while the lock is held would keep it alive after its parent dies; every
lock taken here is therefore closed in a forked child (:func:`os.register_at_fork`), and
only the process that took it holds it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import IO

from ..errors import SweepError

__all__ = ["LOCK_NAME", "DirectoryLock"]

LOCK_NAME = "results.lock"
"""File name of the lock inside a results directory."""

_ATTEMPTS = 50  # tries to lock the file at the path while holders keep removing theirs
_HELD: set[int] = set()  # file descriptors of the locks this process holds


def _close_in_child() -> None:
    """After a fork: the child drops its copies of the parent's locks (the parent keeps them)."""
    for fd in list(_HELD):
        try:
            os.close(fd)
        except OSError:
            pass
    _HELD.clear()


if os.name == "posix":
    os.register_at_fork(after_in_child=_close_in_child)


class DirectoryLock:
    """An exclusive lock on a results directory; :class:`SweepError` if another process has it.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with DirectoryLock(folder):
    ...     (folder / LOCK_NAME).is_file()
    True
    >>> (folder / LOCK_NAME).exists()
    False
    """

    def __init__(self, folder: Path, what: str = "sweep") -> None:
        self.path = folder / LOCK_NAME
        self._handle: IO[str] | None = None
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not on POSIX: no lock
            return
        for _ in range(_ATTEMPTS):
            handle = open(self.path, "a+", encoding="ascii")
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                handle.close()
                raise SweepError(f"{folder}: another {what} is writing to this directory "
                                 f"(pid {self._holder()})") from None
            if self._is_current(handle):
                break
            handle.close()  # the holder removed the file between our open and our lock
        else:  # pragma: no cover - a removal race lost _ATTEMPTS times in a row
            raise SweepError(f"{folder}: could not lock {LOCK_NAME} (it keeps being removed)")
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        self._handle = handle
        _HELD.add(handle.fileno())

    def _is_current(self, handle: IO[str]) -> bool:
        """The locked file is the one at :attr:`path` (not one a holder has just removed)."""
        try:
            here, there = os.fstat(handle.fileno()), os.stat(self.path)
        except OSError:
            return False
        return (here.st_dev, here.st_ino) == (there.st_dev, there.st_ino)

    def _holder(self) -> str:
        """The pid the holder wrote into the lock file (for the message only)."""
        try:
            return self.path.read_text(encoding="ascii").strip() or "?"
        except OSError:
            return "?"

    def close(self) -> None:
        """Remove the lock file, then release the lock (the kernel releases it too when
        this process ends, but leaves the file)."""
        if self._handle is not None:
            try:
                os.unlink(self.path)  # while still locked: no taker holds this file
            except OSError:
                pass
            _HELD.discard(self._handle.fileno())
            self._handle.close()
            self._handle = None

    def __enter__(self) -> DirectoryLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
