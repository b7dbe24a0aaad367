"""The Optuna study file of ``stealth tune`` (``DIR/study.db``), opened without tracebacks.

A study directory is written by one ``tune`` at a time (:class:`~headless.outputs.dirlock.DirectoryLock`
on ``DIR/results.lock``: a second run on the same directory is refused in one line, and the
lock goes with its holder's death). A ``study.db`` that is not an SQLite file is refused
before Optuna opens it, and whatever SQLAlchemy raises later (a full disk, a damaged file)
becomes one :class:`~headless.errors.SweepError` line naming the file.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

from ..errors import SweepError

__all__ = ["STUDY_FILE", "check_study_file", "study_errors"]

STUDY_FILE = "study.db"
"""File name of the Optuna study inside a study directory."""

_SQLITE_HEADER = b"SQLite format 3\x00"


def check_study_file(path: Path) -> None:
    """Refuse a ``study.db`` that exists but is not an SQLite database (nor empty).

    >>> import tempfile
    >>> bad = Path(tempfile.mkdtemp()) / STUDY_FILE
    >>> _ = bad.write_bytes(b"not a database at all")
    >>> check_study_file(bad)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    headless.errors.SweepError: ...study.db: not an Optuna study (not an SQLite file); ...
    """
    if not path.exists():
        return
    if not path.is_file():
        raise SweepError(f"{path}: not an Optuna study (not a regular file)")
    try:
        with path.open("rb") as handle:
            head = handle.read(len(_SQLITE_HEADER))
    except OSError as error:
        raise SweepError(f"{path}: cannot read ({error.strerror or error})") from None
    if head and head != _SQLITE_HEADER:
        raise SweepError(f"{path}: not an Optuna study (not an SQLite file); use another "
                         "--out or delete that file")


@contextlib.contextmanager
def study_errors(path: Path) -> Iterator[None]:
    """Turn SQLAlchemy's (and Optuna's storage) errors inside the block into one SweepError line naming ``path``."""
    from optuna.exceptions import StorageInternalError
    from sqlalchemy.exc import SQLAlchemyError

    try:
        yield
    except (SQLAlchemyError, StorageInternalError) as error:
        cause = getattr(error, "orig", None) or error
        text = " ".join(str(cause).split()) or type(cause).__name__
        raise SweepError(f"{path}: the Optuna study cannot be used ({text})") from None
