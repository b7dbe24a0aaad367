"""The names a user registers and the labels printed for them: one rule, checked when they
are registered (guard modes, player policies, stimuli, config sections, zone kinds).

A **name** is a word — a letter or ``_``, then letters, digits, ``_`` or ``-``, at most
:data:`MAX_NAME` characters — because it is typed on the command line (``--guards NAME``),
is a part of a trial's key (``level/abstraction/guards/...``), a config section (the
first part of ``--set SECTION.KEY=V`` and a TOML table) or a Tiled class. A **label** (a
display or short name) is one line of printable text of at most :data:`MAX_LABEL`
characters, because tables and figures print it in a cell.

>>> name_problem("patrol") is None, label_problem("Patrol (slow)") is None
(True, True)
>>> name_problem("a b")
"must be a word (letters, digits, '_' or '-', starting with a letter or '_'), got 'a b'"
"""

from __future__ import annotations

import re
from typing import Any

__all__ = ["MAX_LABEL", "MAX_NAME", "label_problem", "name_problem"]

MAX_NAME = 64
"""Most characters of a registered name."""
MAX_LABEL = 64
"""Most characters of a display or short name."""

_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:30]}…({len(value)} characters)"


def name_problem(value: Any) -> str | None:
    """Why ``value`` cannot be a registered name, or None if it can."""
    if not isinstance(value, str):
        return f"must be a string, got {type(value).__name__} {_shown(value)}"
    if len(value) > MAX_NAME:
        return f"must be at most {MAX_NAME} characters, got {_shown(value)}"
    if not _WORD.fullmatch(value):
        return ("must be a word (letters, digits, '_' or '-', starting with a letter or '_'), "
                f"got {_shown(value)}")
    return None


def label_problem(value: Any) -> str | None:
    """Why ``value`` cannot be a display or short name, or None if it can."""
    if not isinstance(value, str):
        return f"must be a string, got {type(value).__name__} {_shown(value)}"
    if not value.strip():
        return f"must be a non-empty line of text, got {_shown(value)}"
    if len(value) > MAX_LABEL:
        return f"must be at most {MAX_LABEL} characters, got {_shown(value)}"
    if not value.isprintable():
        return f"must be one line of printable characters, got {_shown(value)}"
    return None
