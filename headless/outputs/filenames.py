"""Output file names made from user data (level names, mode names), safe and unique.

Every writer that puts user data into a file name (the report's heatmaps and figures, the
mechanics files, the default results directory) asks :func:`output_path` for the path, so a
level named ``../../x``, ``a/b``, ``NUL`` or ``"\\x00"`` can neither crash a report nor write
outside its directory. Each part of a name becomes a **slug** of lower-case ASCII letters,
digits, ``.`` and ``-``; a part that is not its own slug also gets ``--`` and a hash of
the original, so two names whose slugs collide (``a/b``, ``a?b``, ``A-B``) still get two
files. Plain names (every bundled level and mode) keep their file names.

>>> safe_part("miami"), safe_part("../../x"), safe_part("a/b")
('miami', 'x--9cdf6a50100a', 'a-b--c14cddc033f6')
>>> safe_part("Münster")
'munster--9bc30489b635'
"""

from __future__ import annotations

import hashlib
import re
import unicodedata
from pathlib import Path

__all__ = ["output_path", "safe_part"]

_PLAIN = re.compile(r"[a-z0-9]+([.-][a-z0-9]+)*")
_UNSAFE = re.compile(r"[^a-z0-9.]+")
_MAX_SLUG = 48  # a few parts plus hashes stay far below the usual 255-byte name limit


def safe_part(text: str) -> str:
    """``text`` as one part of a file name: itself when it is already a plain slug
    (``[a-z0-9]`` runs joined by single ``.`` or ``-``, at most 48 characters), else its slug
    and ``--`` and 12 hex digits of its SHA-256 (``--`` never occurs in a plain slug, so a
    hashed name never equals a plain one)."""
    if len(text) <= _MAX_SLUG and _PLAIN.fullmatch(text):
        return text
    ascii_text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()
    slug = _UNSAFE.sub("-", ascii_text.lower())
    slug = re.sub(r"[.-]{2,}", "-", slug).strip(".-")[:_MAX_SLUG].strip(".-") or "name"
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:12]
    return f"{slug}--{digest}"


def output_path(directory: str | Path, *parts: str, suffix: str = "") -> Path:
    """``directory / "{part}_{part}...{suffix}"``, every part through :func:`safe_part`.

    The parts are joined with ``_``, which no safe part contains, so different parts give
    different names. Asserts the result is a file directly inside ``directory``.

    >>> output_path("out", "a/b", "grid", suffix=".csv").name
    'a-b--c14cddc033f6_grid.csv'
    """
    if not parts:
        raise ValueError("output_path: no name parts")
    base = Path(directory)
    path = base / ("_".join(safe_part(p) for p in parts) + suffix)
    assert path.parent == base and path.name not in ("", ".", ".."), path
    assert path.resolve().parent == base.resolve(), f"{path} would leave {base}"
    return path
