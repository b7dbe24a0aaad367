"""Generated parts of Markdown files: the text between two marker comments is replaced.

docs/results.md and docs/scale.md hold tables that commands regenerate (``headless.beside_paper``,
``headless.held_out``, ``headless.robustness``, ``benchmarks/scale.py``); the prose around
them is written by hand and kept.
"""

from __future__ import annotations

import re
from pathlib import Path

from navmesh.files import FileRefused, read_regular

from ..errors import UserError

__all__ = ["MAX_MARKED_FILE", "replace_marked"]


#: the largest Markdown file whose marked part is replaced (docs/results.md is 60 KiB)
MAX_MARKED_FILE = 16 * 2**20


def replace_marked(path: Path, begin: str, end: str, text: str) -> bool:
    """Replace what lies between the first ``begin`` and the next ``end`` marker of a
    Markdown file with ``text`` (markers kept, ``text`` right after ``begin`` and its line
    break); False, and the file untouched, when the markers are missing. The file is read
    through :func:`navmesh.files.read_regular`, so a FIFO, a directory or a device is one
    :class:`~navmesh.errors.UserError` naming it, never a wait or a traceback."""
    try:
        doc = read_regular(path, MAX_MARKED_FILE).decode("utf-8")
    except FileRefused as refused:
        raise UserError(f"{path}: {refused}") from None
    except OSError as error:
        raise UserError(f"{path}: cannot read ({error.strerror or error})") from None
    except UnicodeDecodeError:
        raise UserError(f"{path}: not UTF-8 text") from None
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pattern.search(doc):
        return False
    path.write_text(pattern.sub(lambda _: f"{begin}\n{text}{end}", doc, count=1), encoding="utf-8")
    return True
