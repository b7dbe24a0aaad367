"""A results folder holds no ``results.lock``, ``-wal`` or ``-shm`` once ``stealth run`` and
``stealth report`` have ended (issue 41); while they run, the lock and the WAL journal
still do their work."""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path

import pytest

from headless.cli import main
from headless.errors import SweepError
from headless.outputs.dirlock import LOCK_NAME, DirectoryLock
from headless.store import STORE_NAME, ResultStore

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds = 2

[set]
"world.duration" = 1.0
"""
LEFTOVERS = (LOCK_NAME, f"{STORE_NAME}-wal", f"{STORE_NAME}-shm", f"{STORE_NAME}-journal")


def _journal_mode(path: Path) -> str:
    db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
    try:
        return str(db.execute("PRAGMA journal_mode").fetchone()[0])
    finally:
        db.close()


@pytest.mark.parametrize("workers", [1, 2])
def test_no_lock_or_journal_files_after_a_run_and_a_report(tmp_path: Path, workers: int) -> None:
    (tmp_path / "p.toml").write_text(PRESET)
    out = tmp_path / "out"
    assert main(["run", "--preset", str(tmp_path / "p.toml"), "--out", str(out),
                 "--workers", str(workers)]) == 0
    after_run = sorted(p.name for p in out.iterdir())
    assert STORE_NAME in after_run and not set(after_run) & set(LEFTOVERS), after_run
    assert _journal_mode(out / STORE_NAME) == "delete"
    assert main(["report", str(out)]) == 0
    after_report = sorted(p.name for p in out.iterdir())
    assert "table.md" in after_report and not set(after_report) & set(LEFTOVERS), after_report
    # resuming reopens it in WAL mode and leaves it clean again
    assert main(["run", "--preset", str(tmp_path / "p.toml"), "--out", str(out), "--seeds", "3"]) == 0
    assert not {p.name for p in out.iterdir()} & set(LEFTOVERS)
    with ResultStore(out / STORE_NAME, readonly=True) as store:
        assert store.count() == (3, 0)


def test_a_writer_closing_under_a_reader_keeps_wal_mode_and_the_reader_reads(tmp_path: Path) -> None:
    path = tmp_path / STORE_NAME
    writer = ResultStore(path)
    assert _journal_mode(path) == "wal"  # readers never block a running sweep
    writer.set_meta({"a": "1"})
    reader = ResultStore(path, readonly=True)
    writer.CLOSE_WAIT_MS = 50  # type: ignore[misc]
    writer.close()  # cannot leave WAL mode while the reader has the file open
    assert _journal_mode(path) == "wal" and reader.get_meta("a") == "1"
    reader.close()
    again = ResultStore(path)
    again.close()  # the next writer to close alone tidies up
    assert _journal_mode(path) == "delete"
    assert sorted(p.name for p in tmp_path.iterdir()) == [STORE_NAME]


def test_the_lock_file_goes_with_its_holder_and_still_excludes_others(tmp_path: Path) -> None:
    lock = DirectoryLock(tmp_path)
    assert (tmp_path / LOCK_NAME).read_text() == str(os.getpid())
    with pytest.raises(SweepError, match=f"another sweep is writing.*pid {os.getpid()}"):
        DirectoryLock(tmp_path)
    lock.close()
    assert not (tmp_path / LOCK_NAME).exists()
    with DirectoryLock(tmp_path):  # free again
        with pytest.raises(SweepError):
            DirectoryLock(tmp_path)
    assert not (tmp_path / LOCK_NAME).exists()


def test_a_lock_on_a_removed_file_is_not_taken_for_the_lock(tmp_path: Path) -> None:
    """A taker that opened the file just before its holder removed it must not lock that
    orphan and run beside the next taker: it sees the file is gone and locks the new one."""
    lock = DirectoryLock(tmp_path)
    stale = open(tmp_path / LOCK_NAME, encoding="ascii")  # opened before the holder lets go
    lock.close()
    try:
        assert not lock._is_current(stale)  # the removed file is not the lock any more
        fresh = DirectoryLock(tmp_path)
        assert fresh._handle is not None and fresh._is_current(fresh._handle)
        fresh.close()
    finally:
        stale.close()
