"""One place where failures become one ``stealth: error:`` line: the CLI's and the analyses'.

:func:`guarded` runs a command's body and turns a :class:`~navmesh.errors.StealthError` (a
user's mistake), an :class:`OSError` (disk full, missing file, a closed pipe: named by
:func:`os_error_line`), a file SQLite cannot read as a store, a ``SystemExit`` raised by
user code (a plugin calling ``sys.exit`` at import) and Ctrl-C into one line and an exit
code (2, or 130 for Ctrl-C). ``stealth`` (:func:`headless.cli.main`) and the analyses'
``python -m headless.X`` entry points use it, so none of them prints a traceback without
``--debug``. :class:`GuardedParser` is an argparse parser whose errors go the same way.
"""

from __future__ import annotations

import argparse
import errno
import io
import os
import sqlite3
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import NoReturn

from navmesh.errors import StealthError

from ..errors import UserError

__all__ = ["EXIT_INTERRUPTED", "EXIT_USER_ERROR", "GuardedParser", "UsageError", "guarded",
           "os_error_line"]

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130


class UsageError(UserError):
    """A command line argparse rejects (unknown option, bad choice, missing argument)."""


class GuardedParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one ``stealth: error: ...`` line (exit 2)."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def wants_debug(words: Sequence[str]) -> bool:
    """``--debug`` anywhere before ``--``."""
    words = list(words)
    return "--debug" in (words[:words.index("--")] if "--" in words else words)


def guarded(body: Callable[[], int], debug: bool = False) -> int:
    """``body()``'s exit code, or 2 after one ``stealth: error:`` line (130 on Ctrl-C).

    The body returns its code, so a ``SystemExit`` other than argparse's ``--help`` /
    ``--version`` (code 0, passed on) was raised by code it called, and is reported.
    """
    _tolerant_streams()
    try:
        return int(body())
    except StealthError as error:
        return _fail(str(error), debug)
    except BrokenPipeError:
        _detach_stdout()  # the reader is gone: nothing more can reach it
        return _fail("stdout: the reading end of the pipe was closed (EPIPE)", debug)
    except OSError as error:
        return _fail(os_error_line(error), debug)
    except sqlite3.DatabaseError as error:
        return _fail(f"results store: {error}", debug)
    except MemoryError:
        return _fail("out of memory", debug)
    except SystemExit as exit_:
        if exit_.code in (0, None):  # --help, --version: argparse's own exit, as it was
            raise
        return _fail(f"code called sys.exit({exit_.code!r}) (a plugin or user file?)", debug)
    except KeyboardInterrupt:
        print("stealth: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def os_error_line(error: OSError) -> str:
    """``FILE: what happened (ERRNO)`` for an OSError, e.g. ``/dev/full: No space left on
    device (ENOSPC)``.

    >>> os_error_line(IsADirectoryError(21, "Is a directory", "out/table.md"))
    'out/table.md: Is a directory (EISDIR)'
    """
    code = errno.errorcode.get(error.errno or 0)
    text = error.strerror or str(error) or type(error).__name__
    names = [str(f) for f in (error.filename, error.filename2) if f is not None]
    return (f"{' -> '.join(names)}: " if names else "") + text + (f" ({code})" if code else "")


def _fail(message: str, debug: bool) -> int:
    """Print the one ``stealth: error:`` line (after the traceback with ``--debug``)."""
    if debug:
        traceback.print_exc(file=sys.stderr)
    print(f"stealth: error: {' '.join(message.split())}", file=sys.stderr)
    return EXIT_USER_ERROR


def _tolerant_streams() -> None:
    """Under an ASCII locale a level or file name that ASCII cannot spell is printed with
    backslash escapes instead of ending the command with a UnicodeEncodeError."""
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")


def _detach_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass
