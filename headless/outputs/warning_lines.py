"""A :class:`~navmesh.errors.LevelWarning` reaches the ``stealth`` user as one line on stderr.

Python's default shows a warning as two lines (the file and line that issued it, then the
source line), which is noise for a user whose map lacks walls. :func:`install` makes every
LevelWarning print as ``stealth: warning: <file>: <field>: <problem>``, each distinct line
once per process (a command may load a level more than once), and leaves other warnings as
Python shows them.

>>> import io, warnings
>>> from navmesh.errors import LevelWarning
>>> err = io.StringIO()
>>> with warnings.catch_warnings():
...     install(err)
...     for _ in range(2):
...         warnings.warn(LevelWarning("m.tmx", "map", "no walls"))
>>> err.getvalue()
'stealth: warning: m.tmx: map: no walls\\n'
"""

from __future__ import annotations

import sys
import warnings
from typing import Any, TextIO

from navmesh.errors import LevelWarning

__all__ = ["install"]


def install(stream: TextIO | None = None) -> None:
    """Show LevelWarnings as one line on ``stream`` (default: the current ``sys.stderr``)."""
    shown = getattr(warnings.showwarning, "wrapped", warnings.showwarning)  # installed once
    printed: set[str] = set()

    def show(message: Any, category: type[Warning], filename: str, lineno: int,
             file: TextIO | None = None, line: str | None = None) -> None:
        if issubclass(category, LevelWarning):
            text = f"stealth: warning: {' '.join(str(message).split())}"
            if text not in printed:
                printed.add(text)
                print(text, file=stream or sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    show.wrapped = shown  # type: ignore[attr-defined]
    warnings.simplefilter("always", LevelWarning)
    warnings.showwarning = show
