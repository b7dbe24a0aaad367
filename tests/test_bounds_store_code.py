"""Issue 24 class 2: opening someone's results never runs their code.

``stealth report DIR`` reads what it needs of a design's plugins (their zone kinds) from the
store, where the sweep wrote them as data; it never imports a plugin the store names. An
older store without the data is reported without it after one note; a design that is not
JSON and a metric column holding text are one line.
"""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from headless.presets import load_preset
from headless.sweep import run_sweep

ROOT = Path(__file__).resolve().parents[1]
EVIL = "import pathlib\npathlib.Path(__file__).with_name('RAN').write_text('pwned')\n"


@pytest.fixture()
def shared(tmp_path: Path) -> Path:
    """A results folder made with the tripwire plugin, shared with a hostile tripwire.py."""
    shutil.copy(ROOT / "examples" / "tripwire.py", tmp_path / "tripwire.py")
    shutil.copy(ROOT / "examples" / "alarm_maze.tmj", tmp_path / "alarm_maze.tmj")
    (tmp_path / "p.toml").write_text(
        'levels = ["alarm_maze.tmj"]\nabstractions = ["grid"]\nguards = ["random"]\n'
        'players = ["maxmin"]\nscenarios = ["fixed"]\nseeds = 1\n'
        'stimuli = ["tripwire.py:Tripwire"]\n[set]\n"world.duration" = 1.0\n')
    out = tmp_path / "out"
    run_sweep(load_preset(str(tmp_path / "p.toml")), out, workers=1, progress=False)
    (tmp_path / "tripwire.py").write_text(EVIL)  # what the store names is now someone's code
    (out / "evil.py").write_text(EVIL)
    db = sqlite3.connect(out / "results.sqlite")
    with db:  # the store names a plugin relative to the folder, as `cd DIR && report .` resolves
        design = json.loads(db.execute("SELECT value FROM meta WHERE key='design'").fetchone()[0])
        design["stimuli"] = [*design["stimuli"], "evil.py:Evil"]
        db.execute("UPDATE meta SET value=? WHERE key='design'", (json.dumps(design),))
    db.close()
    return out


def _report(directory: Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "headless.cli", "report", str(directory)],
                          capture_output=True, text=True, timeout=120, env=env, cwd=cwd)


def _set_meta(out: Path, key: str, value: str | None) -> None:
    db = sqlite3.connect(out / "results.sqlite")
    with db:
        if value is None:
            db.execute("DELETE FROM meta WHERE key=?", (key,))
        else:
            db.execute("UPDATE meta SET value=? WHERE key=?", (value, key))
    db.close()


def test_a_report_imports_no_plugin_the_store_names(shared: Path) -> None:
    assert json.loads(sqlite3.connect(shared / "results.sqlite").execute(
        "SELECT value FROM meta WHERE key='zone_kinds'").fetchone()[0])[-1] == "alarm"
    done = _report(Path("."), cwd=shared)
    assert done.returncode == 0, done.stderr
    assert not (shared / "RAN").exists() and not (shared.parent / "RAN").exists()
    # the plugin's zone kind came from the store: the level with alarm zones got its heatmaps
    assert list((shared / "heatmaps").glob("*alarm*_visit.csv")), done.stderr


def test_an_old_store_without_zone_kinds_is_reported_after_one_note(shared: Path) -> None:
    _set_meta(shared, "zone_kinds", None)
    done = _report(shared, cwd=shared)
    assert done.returncode == 0, done.stderr
    assert not (shared / "RAN").exists() and not (shared.parent / "RAN").exists()
    notes = [line for line in done.stderr.splitlines() if line.startswith("stealth: note:")]
    assert len(notes) == 1 and "not imported" in notes[0]
    assert (shared / "table.md").is_file()


@pytest.mark.parametrize(("key", "value", "words"), [
    ("design", "{not json", "meta.design is not JSON"),
    ("design", "[1, 2]", "meta.design is list"),
    ("zone_kinds", '" alarm"', "meta.zone_kinds is not a list"),
    ("zone_kinds", json.dumps([f"k{i}" for i in range(100_000)]), "more than 256"),
    ("zone_kinds", '[" alarm"]', "a zone kind must be a word"),
], ids=["not-json", "a-list", "a-string", "many-kinds", "bad-kind"])
def test_a_bad_design_is_one_line(shared: Path, key: str, value: str, words: str) -> None:
    _set_meta(shared, key, value)
    done = _report(shared, cwd=shared.parent)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [done.stderr.strip()], done.stderr
    assert words in done.stderr and done.stderr.startswith("stealth: error: ")


def test_a_text_metric_is_one_line(shared: Path) -> None:
    db = sqlite3.connect(shared / "results.sqlite")
    with db:
        db.execute("UPDATE trials SET captures = 'lots'")
    db.close()
    before = (shared / "results.sqlite").read_bytes()
    done = _report(shared, cwd=shared.parent)
    assert done.returncode == 2 and "metric captures holds 'lots', not a number" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert (shared / "results.sqlite").read_bytes() == before
