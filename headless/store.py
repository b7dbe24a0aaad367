"""The results store of a sweep: one SQLite file, one row per finished trial.

``DIR/results.sqlite`` (stdlib :mod:`sqlite3`, WAL journal) holds

* ``trials`` — one row per trial, keyed by :attr:`game.trial.TrialSpec.key`: the trial's
  identity, seed, config hash, one column per registered metric (:mod:`game.metrics`;
  opening an older store adds the columns of metrics registered since), the per-node ``visits`` and
  ``attacks`` lists (zlib-compressed JSON, ``json.loads(zlib.decompress(blob))``), the error
  text (``NULL`` on success), the wall time and when it finished;
* the trial's factor values (``factors``, JSON; ``{}`` without factors, SPEC §10);
* ``engine``, the engine that ran the trial (``world.engine``, SPEC §12: ``pymunk`` or
  ``batch``; no part of the key, the engines giving equal results; ``NULL`` in the rows of a
  store written before the column, which opening it for writing adds);
* ``meta`` — key/value text: the preset (its TOML text and its expanded design as JSON),
  the config hash and ``level_digests`` (the SHA-256 of every level file, by level
  reference), so ``stealth report`` knows the design and a resumed sweep can check that it
  continues the same experiment on the same geometry.

Every finished trial is committed at once, so a sweep killed at any moment loses at most
the trials still running. Only the sweep's main process writes; readers (``stealth
report``, a notebook) may read while it runs: the WAL journal lets them. Closing the writer
checkpoints the journal and returns the file to SQLite's ``DELETE`` journal, which removes
``results.sqlite-wal`` and ``-shm``: a finished store is one file, and a reader of it
creates no journal files (a store left in WAL mode — a killed sweep, or one written before
issue 41 — keeps them until the next writer on it closes).

>>> import tempfile, pathlib
>>> with ResultStore(pathlib.Path(tempfile.mkdtemp()) / "results.sqlite") as store:
...     store.count()
(0, 0)
"""

from __future__ import annotations

import json
import math
import sqlite3
import zlib
from collections.abc import Iterator, Mapping
from datetime import datetime, timezone
from pathlib import Path
from types import TracebackType
from typing import Any

from game.metrics import Metric, registered_metrics

from .errors import SweepError

__all__ = ["IDENTITY", "STORE_NAME", "ResultStore", "StoredTrial", "metric_columns", "pack",
           "stored_value", "unpack"]

STORE_NAME = "results.sqlite"
"""File name of the store inside a results directory."""

IDENTITY: tuple[str, ...] = ("level", "abstraction", "guards", "player", "scenario", "seed",
                             "root_seed")
"""Identity columns of a trial (with ``config_hash`` they say exactly what ran)."""


def metric_columns() -> tuple[tuple[str, str], ...]:
    """``(name, SQL type)`` of every registered metric: the store's metric columns (SPEC §7/§9).

    Any other metric a trial reports goes to ``extra_metrics``.
    """
    return tuple((m.name, m.sql_type) for m in registered_metrics())


_TABLE = """
CREATE TABLE IF NOT EXISTS trials (
    key TEXT PRIMARY KEY,
    level TEXT NOT NULL,
    level_ref TEXT NOT NULL,
    abstraction TEXT NOT NULL,
    guards TEXT NOT NULL,
    player TEXT NOT NULL,
    scenario TEXT NOT NULL,
    seed INTEGER NOT NULL,
    root_seed INTEGER NOT NULL,
    overrides TEXT NOT NULL,
    config_hash TEXT,
    {metrics},
    extra_metrics TEXT,
    visits BLOB,
    attacks BLOB,
    error TEXT,
    wall_time REAL,
    finished_at TEXT NOT NULL,
    factors TEXT,
    engine TEXT
);
CREATE TABLE IF NOT EXISTS meta (
    key TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
"""

#: the columns of a row's identity (:func:`game.trial.identity_row`; its ``stimuli`` are in
#: the key), and those of them kept as JSON (``{}`` for a row without)
_IDENTITY_COLUMNS: tuple[str, ...] = ("key", "level_ref", *IDENTITY, "overrides", "factors")
_JSON_IDENTITY: tuple[str, ...] = ("overrides", "factors")
_HEAD: tuple[str, ...] = ("key", "level", "level_ref", "abstraction", "guards", "player",
                          "scenario", "seed", "root_seed", "overrides", "config_hash")
_TAIL: tuple[str, ...] = ("extra_metrics", "visits", "attacks", "error", "wall_time",
                          "finished_at", "factors", "engine")


def _upsert(columns: tuple[str, ...]) -> str:
    # A key is written once: a success is never overwritten, a failure is replaced by a later
    # attempt (a rerun retries failed trials), and the key is never duplicated.
    return (
        f"INSERT INTO trials ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))}) "
        f"ON CONFLICT(key) DO UPDATE SET "
        + ", ".join(f"{c} = excluded.{c}" for c in columns if c != "key")
        + " WHERE trials.error IS NOT NULL"
    )


def pack(values: list[Any] | None) -> bytes | None:
    """A list of numbers as zlib-compressed JSON (how ``visits`` and ``attacks`` are stored)."""
    if values is None:
        return None
    return zlib.compress(json.dumps(values, separators=(",", ":")).encode(), 6)


def unpack(blob: bytes | None) -> list[Any] | None:
    """The inverse of :func:`pack`."""
    if blob is None:
        return None
    return json.loads(zlib.decompress(blob))


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


def stored_value(value: Any) -> Any:
    """A metric as the store keeps it (booleans as 0/1, non-finite floats as NULL)."""
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _json_column(trial: Mapping[str, Any], column: str, empty: str, kind: type) -> Any:
    """A JSON column's value, which must decode to ``kind`` (ValueError naming it if not)."""
    text = trial.get(column)
    try:
        value = json.loads(text or empty)
    except (ValueError, TypeError):
        raise ValueError(f"column {column} is not JSON: {str(text)[:40]!r}") from None
    if not isinstance(value, kind):
        raise ValueError(f"column {column} is {type(value).__name__}, not {kind.__name__}")
    return value


class StoredTrial(dict[str, Any]):
    """One ``trials`` row as a dict; ``visits``/``attacks`` already decoded to lists."""


class ResultStore:
    """The SQLite results store of one results directory (see the module docstring).

    Open it with ``ResultStore(path)``; ``readonly=True`` never creates or changes the file.
    """

    #: how long closing waits for readers to let go before it leaves the store in WAL mode
    CLOSE_WAIT_MS = 2000

    def __init__(self, path: str | Path, *, readonly: bool = False) -> None:
        self.path = Path(path)
        self.readonly = readonly
        #: the metrics registered when the store was opened: its metric columns
        self.metrics: tuple[Metric, ...] = registered_metrics()
        if readonly:
            uri = f"{self.path.resolve().as_uri()}?mode=ro"
            self.db = sqlite3.connect(uri, uri=True, timeout=30.0)
        else:
            self.db = sqlite3.connect(self.path, timeout=30.0)
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")  # WAL: durable against a killed process
            kinds = ", ".join(f"{m.name} {m.sql_type}" for m in self.metrics)
            self.db.executescript(_TABLE.format(metrics=kinds))
            self._add_missing_columns()
            self.db.commit()
        self.db.row_factory = sqlite3.Row
        present = {r[1] for r in self.db.execute("PRAGMA table_info(trials)")}
        self._has_trials = bool(present)
        #: metric columns the file has (a read-only older store may lack new ones)
        self.metric_names = tuple(m.name for m in self.metrics if m.name in present)
        self.columns = (*_HEAD, *self.metric_names,
                        *(c for c in _TAIL if c in present))

    def _add_missing_columns(self) -> None:
        """A store written before a metric was registered gets its column (NULL so far)."""
        present = {r[1] for r in self.db.execute("PRAGMA table_info(trials)")}
        for m in self.metrics:
            if m.name not in present:
                self.db.execute(f"ALTER TABLE trials ADD COLUMN {m.name} {m.sql_type}")
        if "factors" not in present:  # a store written before designs had factors
            self.db.execute("ALTER TABLE trials ADD COLUMN factors TEXT")
        if "engine" not in present:  # a store written before rows said their engine
            self.db.execute("ALTER TABLE trials ADD COLUMN engine TEXT")

    # ------------------------------------------------------------------ context manager
    def __enter__(self) -> ResultStore:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """Close the connection (everything written is already committed).

        A writer first leaves WAL mode (a checkpoint, then SQLite deletes ``-wal`` and
        ``-shm``), so no journal file stays beside a finished store; while another
        connection still has the file open that fails after :attr:`CLOSE_WAIT_MS` and the
        store stays in WAL mode, intact, its journal files kept for that reader.
        """
        if not self.readonly:
            try:
                self.db.execute(f"PRAGMA busy_timeout = {self.CLOSE_WAIT_MS}")
                self.db.execute("PRAGMA journal_mode = DELETE")
            except sqlite3.Error:
                pass
        self.db.close()

    # ------------------------------------------------------------------ meta
    def get_meta(self, key: str) -> str | None:
        """A ``meta`` value, or None."""
        row = self.db.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return None if row is None else str(row[0])

    def set_meta(self, values: Mapping[str, str]) -> None:
        """Write ``meta`` values (replacing old ones) and commit."""
        with self.db:
            self.db.executemany(
                "INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", list(values.items())
            )

    def meta(self) -> dict[str, str]:
        """Every ``meta`` value (none in a file whose creation was killed before its tables)."""
        if self.db.execute(
            "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'meta'"
        ).fetchone() is None:
            return {}
        return {r[0]: r[1] for r in self.db.execute("SELECT key, value FROM meta")}

    # ------------------------------------------------------------------ trials
    def done_keys(self) -> set[str]:
        """Keys of the trials that finished without error (a rerun skips these)."""
        return {r[0] for r in self.db.execute("SELECT key FROM trials WHERE error IS NULL")}

    def count(self) -> tuple[int, int]:
        """``(finished, failed)`` trial counts."""
        row = self.db.execute(
            "SELECT COUNT(*) - COUNT(error), COUNT(error) FROM trials"
        ).fetchone()
        return int(row[0]), int(row[1])

    def add(self, row: Mapping[str, Any]) -> None:
        """Record one trial row (from :func:`game.trial.run_trial`, or a failure) and commit.

        The row's identity is the one :func:`game.trial.identity_row` built, kept as it is
        (its mappings as sorted JSON); a failed trial has ``error`` (text) and no metrics.
        An existing successful row with the same key is kept as it is.
        """
        metrics = dict(row.get("metrics") or {})
        extra = {k: v for k, v in metrics.items() if k not in self.metric_names}
        values = {
            **{c: row[c] for c in _IDENTITY_COLUMNS if c not in _JSON_IDENTITY},
            **{c: json.dumps(dict(row.get(c) or {}), sort_keys=True) for c in _JSON_IDENTITY},
            "config_hash": row.get("config_hash"),
            **{name: stored_value(metrics.get(name)) for name in self.metric_names},
            "extra_metrics": json.dumps(extra, sort_keys=True) if extra else None,
            "visits": pack(row.get("visits")),
            "attacks": pack(row.get("attacks")),
            "error": row.get("error"),
            "wall_time": row.get("wall_time"),
            "finished_at": _now(),
            "engine": row.get("engine"),
        }
        with self.db:
            self.db.execute(_upsert(self.columns), [values[c] for c in self.columns])

    def trials(self, *, failed: bool = False, heatmaps: bool = False) -> Iterator[StoredTrial]:
        """Finished trials (or, with ``failed=True``, the failed ones) in identity order.

        ``visits``/``attacks`` are decoded only with ``heatmaps=True``.
        """
        where = "error IS NOT NULL" if failed else "error IS NULL"
        columns = [c for c in self.columns if heatmaps or c not in ("visits", "attacks")]
        order = ", ".join((*IDENTITY, "key"))  # key: factor levels of one identity in order
        query = f"SELECT {', '.join(columns)} FROM trials WHERE {where} ORDER BY {order}"
        if not self._has_trials:
            raise SweepError(f"{self.path}: not a results store (it has no trials table)")
        for r in self.db.execute(query):
            trial = StoredTrial(zip(columns, tuple(r)))
            try:
                self._decode(trial, heatmaps)
            except (ValueError, TypeError, zlib.error) as error:  # a hand-edited or foreign row
                raise SweepError(f"{self.path}: trial {trial.get('key')!r}: "
                                 f"{' '.join(str(error).split())}") from None
            yield trial

    def _decode(self, trial: StoredTrial, heatmaps: bool) -> None:
        """Turn one row's stored text into values, refusing what no sweep writes (a metric
        that is text, a JSON column that is not JSON)."""
        for m in self.metrics:
            value = trial.get(m.name)
            if m.name not in self.metric_names:
                trial[m.name] = None  # an older read-only store without the column
            elif value is None:
                continue
            elif isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"metric {m.name} holds {str(value)[:40]!r}, not a number")
            elif m.kind == "bool":
                trial[m.name] = bool(value)
        trial["overrides"] = _json_column(trial, "overrides", "{}", dict)
        trial["extra_metrics"] = _json_column(trial, "extra_metrics", "{}", dict)
        trial["factors"] = _json_column(trial, "factors", "{}", dict)
        if heatmaps:
            trial["visits"] = unpack(trial["visits"])
            trial["attacks"] = unpack(trial["attacks"])
