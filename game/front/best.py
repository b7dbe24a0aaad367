"""The player's best result per level and guard mode, kept between games in the user's data
directory (``platformdirs.user_data_dir("stealthfield")``, or ``$STEALTHFIELD_DATA``).

A result is ranked by outcome (escaped > survived > time up > caught > quit) and then by
time (a faster escape, a later capture). The file is written whole to a temporary file and
renamed, so a crash never leaves half a file. A file that is not the game's — not JSON, too
deep or too large, or JSON of another shape — is set aside as ``best.json.corrupt`` (one
warning line; nothing is lost) and play goes on from no best results; one that cannot be
read at all (no permission, a directory, a FIFO) is left as it is, never overwritten, and
nothing is kept that session. Any JSON value may stand anywhere in the file (an object or a
list where a number or a word belongs, at any depth): the shape check compares types before
values, so nothing it reads can raise. Either way the chooser shows no best results.

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
_MAX_TIME = 1e9  # seconds of game time a result may name (a trial's limit is 5 × 10^4 s)


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


def _json_kind(value: Any) -> str:
    """``value``'s JSON type name, for a warning."""
    kinds = {dict: "an object", list: "an array", str: "a string", bool: "a boolean",
             type(None): "null", int: "a number", float: "a number"}
    return kinds.get(type(value), type(value).__name__)


def _shape_problem(loaded: Any) -> str | None:
    """What makes ``loaded`` other than ``{level: {mode: result}}`` (None: nothing).

    A result is an object with an ``outcome`` the game writes (a key of ``_RANK``), a
    ``time`` in [0, 10^9] s and, if any, a whole number ``stars`` >= 0: what :func:`better`
    and :func:`describe` read. Names in the message are cut to 30 characters.
    """
    if not isinstance(loaded, dict):
        return f"{_json_kind(loaded)}, not an object"
    for level, modes in loaded.items():
        if not isinstance(modes, dict):
            return f"{level!r:.30} is {_json_kind(modes)}, not an object of guard modes"
        for mode, result in modes.items():
            where = f"{level!r:.30}/{mode!r:.30}"
            if not isinstance(result, dict):
                return f"{where} is {_json_kind(result)}, not a result"
            outcome, time, stars = result.get("outcome"), result.get("time"), result.get("stars", 0)
            if not isinstance(outcome, str) or outcome not in _RANK:  # an object or list is unhashable
                shown = repr(outcome)[:30]
                return f"{where}: outcome {shown} is not one of {', '.join(_RANK)}"
            if isinstance(time, bool) or not isinstance(time, (int, float)) or not 0 <= time <= _MAX_TIME:
                shown = repr(time) if len(repr(time)) <= 30 else repr(time)[:12] + "…"
                return f"{where}: time {shown} is not a number of seconds in [0, {_MAX_TIME:g}]"
            if stars is not None and (isinstance(stars, bool) or not isinstance(stars, int) or stars < 0):
                return f"{where}: stars {stars!r:.30} is not a whole number >= 0"
    return None


class BestResults:
    """The best results file: ``{level: {guard mode: result}}``."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path or data_dir() / "best.json"
        self.readable = True
        self.results: dict[str, dict[str, dict[str, Any]]] = {}
        try:
            if not self.path.exists():
                return
            if not self.path.is_file():
                raise OSError("not a regular file")
            if self.path.stat().st_size > _MAX_BYTES:
                problem: str | None = "larger than 1 MiB"
            else:
                text = self.path.read_bytes()
                try:
                    loaded = json.loads(text.decode("utf-8"))
                    problem = _shape_problem(loaded)
                except RecursionError:
                    problem = "nested too deeply"
                except ValueError as error:  # UnicodeDecodeError is one
                    problem = f"not JSON: {str(error)[:80]}"
            if problem is None:
                self.results = loaded
            else:
                self._set_aside(problem)
        except OSError as error:
            self.readable = False
            print(f"stealth: warning: {self.path}: best results not read ({error}); "
                  "they are not kept this time", file=sys.stderr)

    def _set_aside(self, problem: str) -> None:
        """Rename the unusable file to ``<name>.corrupt`` (``.corrupt-2``, ... when that is
        taken: an older one is kept) and go on from no best results; one warning line says
        where it went. An OSError leaves the file as it is (the caller's branch)."""
        aside = self.path.with_name(self.path.name + ".corrupt")
        for n in range(2, 100):
            if not os.path.lexists(aside):
                break
            aside = self.path.with_name(f"{self.path.name}.corrupt-{n}")
        os.replace(self.path, aside)
        print(f"stealth: warning: {self.path}: not a best-results file ({problem}); "
              f"set aside as {aside.name}, starting afresh", file=sys.stderr)

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
