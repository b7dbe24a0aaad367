"""``stealth play --record DIR``: played sessions into a results store, next to the policies.

Every finished session (a row from :mod:`game.record`, ``player = "human"``) is added to
``DIR/results.sqlite`` and its trace written to ``DIR/sessions/<session>.jsonl`` (for
``stealth replay``). For each session's level, abstraction, guards, scenario and seed the
comparison policies (:data:`COMPARE`: MaxMin and SafetyGraph) are run once in the same
interactive world and stored too, so ``stealth report DIR`` shows human and policy rows
on the same level and seeds.
"""

from __future__ import annotations

import os
import re
import sqlite3
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from game.config import Config
from game.record import policy_row
from game.trial import TrialSpec

from ..errors import UserError
from ..store import STORE_NAME, ResultStore

__all__ = ["COMPARE", "SessionStore", "session_trace"]

#: The player policies every recorded session is compared with.
COMPARE: tuple[str, ...] = ("maxmin", "safetygraph")


def session_trace(directory: str | Path, key: str) -> Path:
    """Where the trace of session ``key`` is kept: ``DIR/sessions/<key as a file name>.jsonl``
    (``stealth replay DIR --trial KEY`` plays it: a human session cannot be re-simulated)."""
    name = re.sub(r"[^A-Za-z0-9_.=-]+", "_", key)
    return Path(directory) / "sessions" / f"{name}.jsonl"


def _check_existing(directory: Path) -> None:
    """Refuse, before a game is played, what would lose its session at the end: a
    ``sessions`` that is not a folder, a store file that is not a regular SQLite file."""
    sessions, store = directory / "sessions", directory / STORE_NAME
    if (sessions.exists() or sessions.is_symlink()) and not sessions.is_dir():
        raise UserError(f"--record {directory}: {sessions} is not a folder")
    if not (store.exists() or store.is_symlink()):
        return
    if not store.is_file():
        raise UserError(f"--record {directory}: {store} is not a regular file")
    try:
        with ResultStore(store, readonly=True):
            pass
    except sqlite3.DatabaseError as error:
        raise UserError(f"--record {directory}: {store} is not a results store ({error})") from None


class SessionStore:
    """Writes sessions (and their comparison trials) into one results directory."""

    def __init__(self, directory: str | Path, overrides: Sequence[str] = ()) -> None:
        """Checks that ``directory`` can be made, and makes nothing: the folders come with
        the first session, so a game refused (a bad key, a bad level) leaves no trace."""
        self.directory = Path(directory)
        if self.directory.exists() and not self.directory.is_dir():
            raise UserError(f"--record {directory}: not a folder")
        parent = self.directory
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
            raise UserError(f"--record {directory}: cannot create the folder "
                            f"({parent} is not a writable folder)")
        _check_existing(self.directory)
        self.overrides = tuple(overrides)
        self.stored: list[str] = []

    def __call__(self, row: Mapping[str, Any], trace: Sequence[str]) -> None:
        """Store one session row, its trace, and the comparison policies' trials."""
        try:
            (self.directory / "sessions").mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise UserError(f"--record {self.directory}: cannot create the folder ({error})") from None
        session_trace(self.directory, str(row["key"])).write_text(
            "".join(line + "\n" for line in trace), encoding="utf-8")
        with ResultStore(self.directory / STORE_NAME) as store:
            store.add(row)
            done = store.done_keys()
            config = Config.for_play(self.overrides)
            for player in COMPARE:
                spec = TrialSpec(
                    level=str(row["level_ref"]), abstraction=str(row["abstraction"]),
                    guards=str(row["guards"]), player=player, scenario=str(row["scenario"]),
                    seed=int(row["seed"]), overrides=tuple(dict(row["overrides"]).items()),
                )
                if spec.key + "/interactive" not in done:
                    # a 60-s trial: a moment on a paper level, a minute or so at 10^6 cells
                    print(f"stealth: session {row['key']}: the {player} trial on the same "
                          "level and seed, for the report's comparison ...",
                          file=sys.stderr, flush=True)
                    store.add(policy_row(spec, config))
        self.stored.append(str(row["key"]))
