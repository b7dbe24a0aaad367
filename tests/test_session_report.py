"""Recorded sessions in ``stealth report``: outcome columns, sessions.md / sessions.csv."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from game.config import Config
from game.record import HUMAN, Recording
from game.trial import TrialSpec, make_world
from headless.analysis.report import write_report
from headless.sessions.report import write_session_report
from headless.sessions.record import SessionStore

SHORT = ("world.duration=4",)


def _session(outcome: dict, ratings: dict | None = None, seed: int = 0) -> tuple[dict, list[str]]:
    """A short scripted session on tlou (the evade policy plays the human's part)."""
    config = Config.load({"world.spawns": "level"}).with_overrides(SHORT)
    spec = TrialSpec("tlou", guards="cheat", player="evade", seed=seed)
    world = make_world(spec, config, interactive=True)
    identity = TrialSpec("tlou", guards="cheat", player=HUMAN, seed=seed,
                         overrides=(("world.spawns", "level"), ("world.duration", 4.0)))
    recording = Recording(identity, config)
    recording.attach(world)
    world.run()
    return recording.finish(world, outcome, ratings), list(recording.trace_lines())


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("sessions")
    sink = SessionStore(folder, SHORT)
    sink(*_session({"won": True, "outcome": "won", "collected": 2, "collectibles": 2},
                   {"rating_challenge": 4, "rating_fairness": 2, "rating_naturalness": 5}))
    sink(*_session({"won": False, "outcome": "caught", "collected": 1, "collectibles": 2}))
    write_report(folder, figures=False)
    return folder


def _csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def test_trials_csv_has_the_session_outcome_as_columns(store: Path) -> None:
    rows = _csv(store / "trials.csv")
    human = [r for r in rows if r["player"] == HUMAN]
    assert sorted(r["outcome"] for r in human) == ["caught", "won"]
    assert {r["won"] for r in human} == {"true", "false"}
    assert sorted(r["collected"] for r in human) == ["1", "2"]
    assert sorted(r["rating_challenge"] for r in human) == ["", "4"]
    assert all(r["outcome"] == "" for r in rows if r["player"] != HUMAN)


def test_sessions_csv_puts_the_policies_on_the_same_seed_beside_each_session(store: Path) -> None:
    rows = _csv(store / "sessions.csv")
    assert len(rows) == 2 and {r["outcome"] for r in rows} == {"won", "caught"}
    for row in rows:
        assert row["CaptureRate"] in ("0.0", "1.0")
        assert row["maxmin_CaptureRate"] in ("0.0", "1.0")
        assert row["safetygraph_CaptureRate"] in ("0.0", "1.0")


def test_sessions_md_summarises_outcomes_ratings_and_the_comparison(store: Path) -> None:
    text = (store / "sessions.md").read_text()
    summary = next(line for line in text.splitlines() if line.startswith("| tlou |"))
    cells = [c.strip() for c in summary.strip("|").split("|")]
    assert cells[:8] == ["tlou", "grid", "cheat", "capture", "2", "1 (50 %)", "caught 1, won 1", "3/4"]
    assert cells[8:] == ["4.0 (n=1)", "2.0 (n=1)", "5.0 (n=1)"]
    assert "| Human | 2 |" in text and "| MaxMin | 1 |" in text and "| SafetyGraph | 1 |" in text
    assert "sessions.md" in (store / "README.md").read_text()
    assert "| Human |" in (store / "table.md").read_text()


def test_a_store_without_sessions_gets_no_session_files(tmp_path: Path) -> None:
    (tmp_path / "sessions.md").write_text("stale")
    trial = {"key": "k", "level": "tlou", "abstraction": "grid", "guards": "pf",
             "player": "maxmin", "scenario": "capture", "seed": 0, "overrides": {}}
    assert write_session_report([trial], tmp_path) == []
    assert not (tmp_path / "sessions.md").exists()


def test_replay_of_a_session_plays_its_recorded_trace(store: Path, monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    from headless.cli import main

    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    key = next(r["key"] for r in _csv(store / "trials.csv") if r["player"] == HUMAN)
    assert main(["replay", str(store), "--trial", key, "--frames", "5"]) == 0
    assert "5 frames" in capsys.readouterr().err
