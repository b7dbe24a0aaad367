"""The results-directory lock: one writing sweep at a time, released by its holder's death.

The lock is an OS lock (``fcntl.flock``) on ``DIR/results.lock``, so the kernel drops it
when the holding process ends, however it ends (``kill -9`` included) — no stale lock file
to clean up. A ``flock`` is shared by every process that inherits its file descriptor, so a
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
    """

    def __init__(self, folder: Path, what: str = "sweep") -> None:
        self.path = folder / LOCK_NAME
        self._handle: IO[str] | None = None
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not on POSIX: no lock
            return
        handle = open(self.path, "a+", encoding="ascii")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            raise SweepError(f"{folder}: another {what} is writing to this directory "
                             f"(pid {self._holder()})") from None
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        self._handle = handle
        _HELD.add(handle.fileno())

    def _holder(self) -> str:
        """The pid the holder wrote into the lock file (for the message only)."""
        try:
            return self.path.read_text(encoding="ascii").strip() or "?"
        except OSError:
            return "?"

    def close(self) -> None:
        """Release the lock (the kernel does it too when this process ends)."""
        if self._handle is not None:
            _HELD.discard(self._handle.fileno())
            self._handle.close()
            self._handle = None

    def __enter__(self) -> DirectoryLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
