"""Issue 11 class 1: an interrupted sweep never blocks its own resume.

Only the *main* process is killed here (``kill -9`` or ``kill`` of its pid, as a user
does), never its process group: its pool workers must die with it and the results
directory's lock must be released by its death, so the same command run at once resumes.
"""

from __future__ import annotations

import os
import random
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from headless.errors import SweepError

ROOT = Path(__file__).resolve().parent.parent

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["pf", "random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds = 16

[set]
"world.duration" = 4.0
"""

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


def _env() -> dict[str, str]:
    path = os.environ.get("PYTHONPATH", "")
    return {**os.environ, "PYTHONPATH": str(ROOT) + (os.pathsep + path if path else "")}


def _command(*args: str) -> list[str]:
    return [sys.executable, "-m", "headless.cli", *args]


def _children(pid: int) -> list[int]:
    """The child pids of ``pid`` (Linux /proc), empty if it has none or is gone."""
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(word) for word in text.split()]


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _metric_rows(out: Path) -> dict[str, dict[str, Any]]:
    """Every stored trial by key, without its timing columns."""
    db = sqlite3.connect(out / "results.sqlite")
    db.row_factory = sqlite3.Row
    rows = [dict(r) for r in db.execute("SELECT * FROM trials")]
    db.close()
    for row in rows:
        del row["wall_time"], row["finished_at"]
    return {row["key"]: row for row in rows}


def _wait_gone(pids: list[int], seconds: float = 5.0) -> list[int]:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and any(_alive(p) for p in pids):
        time.sleep(0.02)
    return [p for p in pids if _alive(p)]


def _reap(pids: list[int]) -> None:
    """End processes this test started that outlived the test (the bug being tested)."""
    for pid in pids:
        if _alive(pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


@pytest.mark.skipif(not Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists(),
                    reason="needs Linux /proc children lists")
def test_ten_kills_at_random_moments_each_resume_at_once_to_the_uninterrupted_store(
    tmp_path: Path,
) -> None:
    preset = tmp_path / "tiny.toml"
    preset.write_text(PRESET)
    reference = tmp_path / "reference"
    done = subprocess.run(_command("run", "--preset", str(preset), "--out", str(reference),
                                   "--workers", "2"),
                          env=_env(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    expected = _metric_rows(reference)
    assert len(expected) == 32

    rng = random.Random(11)
    workers_seen: list[int] = []
    killed_mid_run = 0
    try:
        for round_ in range(10):
            out = tmp_path / f"killed{round_}"
            args = _command("run", "--preset", str(preset), "--out", str(out), "--workers", "2")
            process = subprocess.Popen(args, env=_env(), stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)
            # a third of the kills at any moment of the start-up (loading, creating the
            # store), the others at a random moment once the pool's workers run
            started = time.monotonic()
            moment = started + rng.uniform(0.1, 1.2) if round_ % 3 == 0 else started + 30
            children: list[int] = []
            while time.monotonic() < moment and process.poll() is None:
                children = _children(process.pid) or children
                if len(children) == 2 and moment > started + 20:
                    moment = time.monotonic() + rng.uniform(0.0, 0.4)
                time.sleep(0.01)
            try:  # a sweep may finish before its moment comes: then the rerun has nothing to do
                if process.poll() is None:
                    os.kill(process.pid, signal.SIGKILL if round_ % 5 else signal.SIGTERM)
            except ProcessLookupError:
                pass
            process.wait()
            workers_seen += children
            killed_mid_run += bool(children) and process.returncode < 0
            rerun = subprocess.run(args, env=_env(), capture_output=True, text=True,
                                   timeout=120)
            assert rerun.returncode == 0, f"round {round_}: {rerun.stderr}"
            assert _metric_rows(out) == expected, f"round {round_}"
            assert not _wait_gone(children), f"round {round_}: orphan workers {children}"
    finally:
        _reap(workers_seen)
    assert killed_mid_run >= 3, "too few kills landed while the pool was running"


@pytest.mark.skipif(not Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists(),
                    reason="needs Linux /proc children lists")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_mechanics_workers_die_with_their_parent(tmp_path: Path, sig: int) -> None:
    args = _command("mechanics", "--seeds", "40", "--workers", "2", "--out", str(tmp_path))
    process = subprocess.Popen(args, env=_env(), stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    children: list[int] = []
    try:
        deadline = time.monotonic() + 30
        while len(children) < 2 and time.monotonic() < deadline and process.poll() is None:
            children = _children(process.pid)
            time.sleep(0.02)
        assert len(children) == 2, "the mechanics pool never started"
        time.sleep(0.3)
        os.kill(process.pid, sig)
        process.wait()
        assert not _wait_gone(children), "mechanics workers outlived their parent"
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        _reap(children)


def test_a_forked_child_does_not_keep_the_lock(tmp_path: Path) -> None:
    """The lock belongs to the process that took it: a fork's copy of it is dropped."""
    from headless.outputs.dirlock import DirectoryLock

    lock = DirectoryLock(tmp_path)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: hold on for a while, as a busy pool worker would
        os.close(read)
        os.write(write, b"x")
        time.sleep(3)
        os._exit(0)
    try:
        os.close(write)
        assert os.read(read, 1) == b"x"
        with pytest.raises(SweepError, match="another sweep"):
            DirectoryLock(tmp_path)
        lock.close()
        DirectoryLock(tmp_path).close()  # free although the child still runs
    finally:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        os.close(read)
