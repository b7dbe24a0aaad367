"""Generated parts of Markdown files: the text between two marker comments is replaced.

docs/results.md and docs/scale.md hold tables that commands regenerate (``headless.beside_paper``,
``headless.held_out``, ``headless.robustness``, ``benchmarks/scale.py``); the prose around
them is written by hand and kept.
"""

from __future__ import annotations

import re
from pathlib import Path

__all__ = ["replace_marked"]


def replace_marked(path: Path, begin: str, end: str, text: str) -> bool:
    """Replace what lies between the first ``begin`` and the next ``end`` marker of a
    Markdown file with ``text`` (markers kept, ``text`` right after ``begin`` and its line
    break); False, and the file untouched, when the markers are missing."""
    doc = path.read_text(encoding="utf-8")
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pattern.search(doc):
        return False
    path.write_text(pattern.sub(lambda _: f"{begin}\n{text}{end}", doc, count=1), encoding="utf-8")
    return True
