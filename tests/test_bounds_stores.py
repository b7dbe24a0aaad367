"""Issue 11 class 6: stores and traces know which level they were made on.

A resume refuses a store whose level files changed (trial keys stay as they were, so older
stores resume); a trace names its level and its content hash and ends with the final
state; a replay on another level and a ``--trace`` onto an input file are refused.
"""

from __future__ import annotations

import io
import json
import os
import sqlite3
import sys
from pathlib import Path

import pytest

from game.trial import TrialSpec, run_trial
from headless.cli import main
from headless.errors import SweepError
from headless.presets import load_preset
from headless.sweep import run_sweep
from navmesh.level import load_level

ROOT = Path(__file__).resolve().parent.parent
MAZE = ROOT / "assets" / "levels" / "maze.json"

PRESET = """
levels = ["level.json"]
abstractions = ["grid"]
guards = ["random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds = 2

[set]
"world.duration" = 2.0
"""


def _one_error_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), stderr
    return lines[0]


@pytest.fixture()
def design(tmp_path: Path) -> Path:
    (tmp_path / "level.json").write_bytes(MAZE.read_bytes())
    preset = tmp_path / "preset.toml"
    preset.write_text(PRESET)
    return preset


def _interrupt(out: Path) -> None:
    """Drop the last trial from the store: what a sweep killed before it finished leaves."""
    db = sqlite3.connect(out / "results.sqlite")
    with db:
        db.execute("DELETE FROM trials WHERE key = (SELECT MAX(key) FROM trials)")
    db.close()


def test_a_resume_after_the_level_file_changed_is_refused(design: Path) -> None:
    out = design.parent / "out"
    run_sweep(load_preset(str(design)), out, workers=1, progress=False)
    _interrupt(out)
    level = design.parent / "level.json"
    data = json.loads(level.read_text())
    data["guards"] = [data["guards"][-1]]  # another geometry of the same name
    level.write_text(json.dumps(data))
    with pytest.raises(SweepError, match=r"level 'maze' .*level\.json\) changed since"):
        run_sweep(load_preset(str(design)), out, workers=1, progress=False)
    db = sqlite3.connect(out / "results.sqlite")
    assert db.execute("SELECT COUNT(*) FROM trials").fetchone()[0] == 1  # nothing mixed in
    db.close()


def test_a_store_without_level_digests_resumes_with_the_same_trial_keys(design: Path) -> None:
    fresh, old = design.parent / "fresh", design.parent / "old"
    run_sweep(load_preset(str(design)), fresh, workers=1, progress=False)
    run_sweep(load_preset(str(design)), old, workers=1, progress=False)
    _interrupt(old)
    db = sqlite3.connect(old / "results.sqlite")
    with db:  # a store written before the digests were kept
        db.execute("DELETE FROM meta WHERE key = 'level_digests'")
    db.close()
    result = run_sweep(load_preset(str(design)), old, workers=1, progress=False)
    assert (result.skipped, result.finished) == (1, 1)

    def keys(out: Path) -> set[str]:
        db = sqlite3.connect(out / "results.sqlite")
        found = {r[0] for r in db.execute("SELECT key FROM trials")}
        stored = db.execute("SELECT value FROM meta WHERE key = 'level_digests'").fetchone()
        db.close()
        assert stored is not None and str(design.parent / "level.json") in json.loads(stored[0])
        return found

    assert keys(old) == keys(fresh)


def _trace(spec: TrialSpec) -> tuple[list[dict[str, object]], dict[str, object]]:
    buffer = io.StringIO()
    row = run_trial(spec, trace=buffer)
    return [json.loads(line) for line in buffer.getvalue().splitlines()], row


def test_a_trace_names_its_level_and_content_hash_in_its_first_line() -> None:
    lines, _ = _trace(TrialSpec("maze", "partition", "random", "maxmin", "fixed", seed=1,
                                overrides=(("world.duration", 3.0),)))
    first = lines[0]
    assert first["level"] == "maze" and first["abstraction"] == "partition"
    assert first["level_digest"] == load_level("maze").digest
    for line in lines:  # SPEC §9's per-line shape is kept
        assert {"t", "player", "guards", "events"} <= set(line)


def test_a_trace_ends_with_the_final_state_of_a_capture_between_ai_ticks() -> None:
    lines, row = _trace(TrialSpec("maze", "grid", "cheat", "evade", "capture", seed=0))
    capture = row["metrics"]["capture_time"]
    assert row["metrics"]["captured"] and capture is not None
    assert capture != int(capture), "pick a trial whose capture falls between AI ticks"
    assert lines[-1]["t"] == pytest.approx(capture)
    assert lines[-1]["player"]["hp"] <= 0
    times = [line["t"] for line in lines]
    assert times == sorted(set(times))


def test_replaying_a_trace_on_another_level_is_refused(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    trace = tmp_path / "maze.jsonl"
    assert main(["sim", "maze", "--guards", "random", "--set", "world.duration=3",
                 "--trace", str(trace)]) == 0
    capsys.readouterr()
    edited = tmp_path / "maze.json"  # the same level name, another file content
    data = json.loads(MAZE.read_text())
    data["guards"] = data["guards"][:1]
    edited.write_text(json.dumps(data))
    for other in ("miami", str(edited)):
        assert main(["replay", str(trace), "--level", other, "--frames", "1"]) == 2
        assert "recorded on level maze" in _one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("how", ["same path", "hard link", "plugin"])
def test_trace_onto_an_input_file_is_refused_and_the_input_kept(
    tmp_path: Path, how: str, capsys: pytest.CaptureFixture[str],
) -> None:
    level = tmp_path / "level.json"
    level.write_bytes(MAZE.read_bytes())
    plugin = tmp_path / "plugin.py"
    plugin.write_text("from ai.stimuli import Stimulus\n\nclass Quiet(Stimulus):\n"
                      "    name = 'quiet'\n")
    target = {"same path": level, "plugin": plugin}.get(how, tmp_path / "link.json")
    if how == "hard link":
        os.link(level, target)
    before = level.read_bytes(), plugin.read_bytes()
    argv = ["sim", str(level), "--set", "world.duration=2", "--trace", str(target),
            "--stimulus", f"{plugin}:Quiet"]
    assert main(argv) == 2
    assert "is an input" in _one_error_line(capsys.readouterr().err)
    assert (level.read_bytes(), plugin.read_bytes()) == before


pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="hard links, POSIX paths")
