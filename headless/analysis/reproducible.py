"""Figures saved byte for byte the same on every run (``stealth report`` twice: same files).

matplotlib salts the ids of an SVG's elements with a random value and stamps SVG and PDF
files with the date; :func:`save_figure` fixes the salt (``svg.hashsalt``) and drops the
dates and version stamps, for every format, so a report of the same store is reproducible.
Every figure of :mod:`headless` is saved through it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import UserError

__all__ = ["HASH_SALT", "save_figure"]

HASH_SALT = "stealthfield"
"""The fixed ``svg.hashsalt``."""

_METADATA: dict[str, dict[str, Any]] = {
    "svg": {"Date": None, "Creator": None},
    "pdf": {"CreationDate": None, "ModDate": None, "Creator": None, "Producer": None},
    "png": {"Software": None},
}


def save_figure(fig: Any, path: str | Path, **kwargs: Any) -> None:
    """``fig.savefig(path, **kwargs)`` with a fixed SVG salt and no dates in the file. A
    ``path`` that is a directory is a :class:`~navmesh.errors.UserError` (matplotlib would
    write ``path.png`` beside it without a word)."""
    import matplotlib

    if Path(path).is_dir():
        raise UserError(f"{path}: is a directory; a figure is written to a file (e.g. "
                        f"{Path(path) / 'figure.png'})")

    kind = Path(path).suffix.lstrip(".").lower() or str(matplotlib.rcParams["savefig.format"])
    metadata = {**_METADATA.get(kind, {}), **kwargs.pop("metadata", {})}
    with matplotlib.rc_context({"svg.hashsalt": HASH_SALT}):
        fig.savefig(path, metadata=metadata or None, **kwargs)
