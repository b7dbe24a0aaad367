"""The player's best result per level and guard mode, kept between games in the user's data
directory (``platformdirs.user_data_dir("stealthfield")``, or ``$STEALTHFIELD_DATA``).

A result is ranked by outcome (escaped > survived > time up > caught > quit) and then by
time (a faster escape, a later capture). The file is written whole to a temporary file and
renamed, so a crash never leaves half a file; a file that cannot be read is left as it is
(never overwritten) and the chooser shows no best results.

>>> better({"outcome": "won", "time": 40.0}, {"outcome": "caught", "time": 59.0})
True
>>> better({"outcome": "won", "time": 40.0}, {"outcome": "won", "time": 35.0})
False
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["BestResults", "better", "data_dir", "describe"]

_RANK = {"won": 4, "survived": 3, "time up": 2, "caught": 1}
_MAX_BYTES = 1 << 20


def data_dir() -> Path:
    """Where the game keeps what it remembers of the player."""
    override = os.environ.get("STEALTHFIELD_DATA")
    if override:
        return Path(override)
    import platformdirs

    return Path(platformdirs.user_data_dir("stealthfield", appauthor=False))


def better(new: dict[str, Any], old: dict[str, Any] | None) -> bool:
    """Whether result ``new`` beats ``old`` (None: nothing yet)."""
    if old is None:
        return True
    rn, ro = _RANK.get(new["outcome"], 0), _RANK.get(old.get("outcome", ""), 0)
    if rn != ro:
        return rn > ro
    faster = new["outcome"] == "won"  # an escape: sooner is better; otherwise later
    return new["time"] < old["time"] if faster else new["time"] > old["time"]


def describe(result: dict[str, Any] | None) -> str:
    """One line for the chooser, e.g. ``"best: escaped in 41.2 s"``."""
    if result is None:
        return "best: not played yet"
    t = float(result.get("time", 0.0))
    words = {"won": f"escaped in {t:.1f} s", "survived": f"survived {t:.0f} s",
             "time up": f"time up at {t:.0f} s", "caught": f"caught after {t:.1f} s"}
    text = words.get(str(result.get("outcome")), str(result.get("outcome")))
    stars = result.get("stars")
    return f"best: {text}" + (f" · {stars} stars" if stars else "")


class BestResults:
    """The best results file: ``{level: {guard mode: result}}``."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path or data_dir() / "best.json"
        self.readable = True
        self.results: dict[str, dict[str, dict[str, Any]]] = {}
        try:
            if self.path.is_file() and self.path.stat().st_size <= _MAX_BYTES:
                loaded = json.loads(self.path.read_text(encoding="utf-8"))
                if not isinstance(loaded, dict):
                    raise ValueError("not an object")
                self.results = loaded
            elif self.path.exists():
                raise ValueError("not a regular file of at most 1 MiB")
        except (OSError, ValueError) as error:
            self.readable = False
            print(f"stealth: warning: {self.path}: best results not read ({error}); "
                  "they are not kept this time", file=sys.stderr)

    def best(self, level: str, mode: str) -> dict[str, Any] | None:
        """The best result on ``level`` against ``mode`` guards, if any."""
        entry = self.results.get(level, {}).get(mode)
        return entry if isinstance(entry, dict) else None

    def offer(self, level: str, mode: str, result: dict[str, Any]) -> bool:
        """Keep ``result`` if it beats the best so far; returns whether it did (and was saved)."""
        if not self.readable or not better(result, self.best(level, mode)):
            return False
        self.results.setdefault(level, {})[mode] = result
        tmp: str | None = None
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=".best-", suffix=".json")
            with os.fdopen(fd, "w", encoding="utf-8") as out:
                json.dump(self.results, out, indent=1, sort_keys=True)
            os.replace(tmp, self.path)
        except OSError as error:
            if tmp is not None and os.path.exists(tmp):
                os.unlink(tmp)
            print(f"stealth: warning: {self.path}: best result not saved ({error})",
                  file=sys.stderr)
            return False
        return True
