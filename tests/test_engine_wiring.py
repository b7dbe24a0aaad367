"""``world.engine`` wired in (SPEC §12): a config key that is no part of a trial's identity.

The engines give equal results trial for trial, so the engine stays out of the config hash,
the trial key and the sweep's design; a row says which engine ran it. These tests need no
batch engine: what only the engine can show (its rows equal the reference's) is its own
tests' business.
"""

from __future__ import annotations

import json
import sqlite3
import sys
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

import game
from game.config import Config
from game.errors import ConfigError
from game.trial import TrialSpec, run_trial, trial_rngs
from headless.cli import main
from headless.errors import PresetError
from headless.executors import run_engine_batch
from headless.presets import load_preset
from headless.store import ResultStore
from headless.engines import batch_tasks

SHORT = (("world.duration", 2.0),)


# ------------------------------------------------------------------ the key and its identity
def test_the_engine_is_a_world_key_whose_default_is_auto() -> None:
    assert Config.defaults()["world.engine"] == "auto"
    assert Config.load(["world.engine=batch"])["world.engine"] == "batch"


def test_an_unknown_engine_is_refused_naming_the_key_and_the_engines() -> None:
    with pytest.raises(ConfigError, match=r"world\.engine = 'gpu': must be one of 'auto', 'pymunk', 'batch'"):
        Config.load(["world.engine=gpu"])


def test_the_engine_is_out_of_the_config_hash() -> None:
    assert Config.load(["world.engine=batch"]).hash() == Config.defaults().hash() \
        == "c53787ba3cd08da1"
    assert Config.load(["world.engine=pymunk"]).hash() == Config.defaults().hash()
    assert Config.load(["world.engine=auto"]).hash() == Config.defaults().hash()
    # still sensitive to everything else
    assert Config.load(["world.engine=batch", "pf.rho=0.9"]).hash() == "6e28a1d79ad34ffd"


def test_the_engine_is_out_of_the_trial_key_and_the_draws() -> None:
    plain = TrialSpec("maze", overrides=SHORT, factors=(("pf.rho", 0.9),))
    for engine in ("batch", "pymunk"):
        over = TrialSpec("maze", overrides=(("world.engine", engine), *SHORT),
                         factors=(("pf.rho", 0.9),))
        assert over.key == plain.key
        factor = TrialSpec("maze", overrides=SHORT,
                           factors=(("pf.rho", 0.9), ("world.engine", engine)))
        assert factor.key == plain.key
        draws = [g.integers(1 << 30) for g in trial_rngs(factor, "maze")]
        assert draws == [g.integers(1 << 30) for g in trial_rngs(plain, "maze")]
    # a design without the engine keeps its keys exactly as before
    assert TrialSpec("maze", overrides=SHORT).key == "maze/grid/pf/maxmin/capture/0/0/world.duration=2.0"


def test_sim_refuses_an_unknown_engine_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "maze", "--set", "world.engine=gpu"]) == 2
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert lines == ["stealth: error: world.engine = 'gpu': must be one of 'auto', 'pymunk', 'batch'"]
    assert captured.out == ""


def test_play_refuses_the_batch_engine_in_one_line_before_a_window_opens(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["play", "maze", "--set", "world.engine=batch"]) == 2
    captured = capsys.readouterr()
    assert _one_error_line(captured.err) == (
        'stealth: error: world.engine = "batch" does not cover stealth play (one game in '
        'real time); leave world.engine at "auto" or set "pymunk"')
    assert captured.out == ""


# ------------------------------------------------------------------ the batch engine's module
@pytest.fixture
def batch_module(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    """``game.batch`` to monkeypatch: the engine's own module, or a stand-in with its
    contract's names where the engine is not there (these tests never run it)."""
    try:
        import game.batch as module
    except ImportError:
        module = types.ModuleType("game.batch")
        module.MAX_BATCH = 256  # type: ignore[attr-defined]
        module.uncovered = lambda spec, config: None  # type: ignore[attr-defined]

        def run_trials(specs: Sequence[TrialSpec]) -> list[dict[str, Any]]:
            raise AssertionError("the batch engine is not there")

        module.run_trials = run_trials  # type: ignore[attr-defined]
        monkeypatch.setitem(sys.modules, "game.batch", module)
        monkeypatch.setattr(game, "batch", module, raising=False)
    return module


def _one_error_line(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1, text
    assert lines[0].startswith("stealth: error: "), text
    return lines[0]


TEAM = "team switches ([awareness] enabled)"
REFUSAL = (f'stealth: error: world.engine = "batch" does not cover {TEAM}; '
           'use world.engine = "pymunk"')

TINY = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["cheat", "random"]
players = ["evade"]
scenarios = ["capture"]
seeds = 2
{extra}
[set]
"world.duration" = 2.0
{set}
"""


def _preset(tmp_path: Path, extra: str = "", set_: str = "") -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY.format(extra=extra, set=set_))
    return path


# ------------------------------------------------------------------ presets
def test_the_engine_of_a_preset_is_no_part_of_its_design_or_keys(tmp_path: Path) -> None:
    plain = load_preset(str(_preset(tmp_path)))
    batch = load_preset(str(_preset(tmp_path, set_='"world.engine" = "batch"')))
    assert (plain.engine, batch.engine) == ("auto", "batch")
    assert batch.design() == plain.design() and batch.overrides == plain.overrides
    assert [s.key for s in batch.specs()] == [s.key for s in plain.specs()]
    assert batch.config_hash == plain.config_hash
    assert batch.config["world.engine"] == "batch"  # what the sweep's meta says it ran with
    by_set = load_preset(str(_preset(tmp_path)), {"world.engine": "batch"})  # --set, --config
    assert by_set.engine == "batch" and by_set.design() == plain.design()


def test_a_factor_names_one_engine_or_is_refused(tmp_path: Path) -> None:
    one = load_preset(str(_preset(tmp_path, extra='[factors]\n"world.engine" = ["batch"]\n')))
    assert one.engine == "batch" and one.factors == () and one.n_trials == 4
    with pytest.raises(PresetError, match=r"factors\.world\.engine: the engines give equal"):
        load_preset(str(_preset(tmp_path, extra='[factors]\n"world.engine" = '
                                                '["pymunk", "batch"]\n')))


def test_run_refuses_an_unknown_engine_in_one_line(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    code = main(["run", "--preset", str(_preset(tmp_path)), "--out", str(out),
                 "--set", "world.engine=gpu"])
    assert code == 2 and not out.exists()
    assert "world.engine = 'gpu': must be one of 'auto', 'pymunk', 'batch'" in _one_error_line(
        capsys.readouterr().err)


# ------------------------------------------------------------------ the sweep's batches
def _specs(levels: Sequence[str], abstractions: Sequence[str], seeds: int,
           overrides: Sequence[tuple[tuple[str, Any], ...]] = ((),)) -> list[TrialSpec]:
    return [TrialSpec(level, abstraction, guards, "evade", scenario, seed, over)
            for seed in range(seeds) for level in levels for abstraction in abstractions
            for guards in ("pf", "fsm") for scenario in ("capture", "fixed")
            for over in overrides]


def _group(spec: TrialSpec) -> tuple[Any, ...]:
    return spec.level, spec.abstraction, spec.overrides, spec.factors


def test_batch_tasks_group_level_abstraction_overrides_and_factors() -> None:
    overrides = ((), (("pf.rho", 0.9),))
    specs = _specs(["maze", "tlou"], ["grid", "partition"], 5, overrides)
    specs += [TrialSpec("maze", seed=s, factors=(("pf.rho", 0.8),)) for s in range(3)]
    tasks = batch_tasks(specs, workers=1, max_batch=256)
    assert sorted(s.key for task in tasks for s in task) == sorted(s.key for s in specs)
    assert all(len({_group(s) for s in task}) == 1 for task in tasks)  # one group a task
    assert len(tasks) == len({_group(s) for s in specs}) == 2 * 2 * 2 + 1  # one task a group
    mixed = tasks[0]  # seeds, guard modes and scenarios vary inside a task
    assert {s.seed for s in mixed} == set(range(5)) and {s.guards for s in mixed} == {"pf", "fsm"}
    assert {s.scenario for s in mixed} == {"capture", "fixed"}
    for task in tasks:  # in the sweep's order inside a task
        assert task == [s for s in specs if _group(s) == _group(task[0])]


def test_batch_tasks_hold_at_most_max_batch_and_spread_over_the_workers() -> None:
    specs = _specs(["maze"], ["grid"], 150)  # one group of 600 trials
    sizes = [len(t) for t in batch_tasks(specs, workers=1, max_batch=256)]
    assert sizes == [200, 200, 200]  # near-equal parts of at most 256
    sizes = [len(t) for t in batch_tasks(specs[:40], workers=2, max_batch=256)]
    assert sizes == [20, 20]  # fewer trials than 256 x 2: every worker gets a batch
    sizes = [len(t) for t in batch_tasks(specs[:41], workers=4, max_batch=8)]
    assert max(sizes) <= 8 and sum(sizes) == 41
    assert batch_tasks([], workers=2, max_batch=256) == []


def test_batch_tasks_take_the_groups_in_turn() -> None:
    specs = _specs(["maze", "tlou"], ["grid"], 4)  # two groups of 16
    tasks = batch_tasks(specs, workers=1, max_batch=8)
    assert [t[0].level for t in tasks] == ["maze", "tlou", "maze", "tlou"]
    assert [{s.seed for s in t} for t in tasks[:2]] == [{0, 1}, {0, 1}]


# ------------------------------------------------------------------ refusals
def test_run_refuses_an_uncovered_trial_in_one_line_and_writes_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], batch_module: types.ModuleType,
        monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[tuple[TrialSpec, Config]] = []

    def uncovered(spec: TrialSpec, config: Config) -> str | None:
        asked.append((spec, config))
        return TEAM if spec.guards == "random" else None

    monkeypatch.setattr(batch_module, "uncovered", uncovered)
    out = tmp_path / "out"
    code = main(["run", "--preset", str(_preset(tmp_path)), "--out", str(out),
                 "--workers", "1", "--set", "world.engine=batch"])
    captured = capsys.readouterr()
    assert code == 2 and _one_error_line(captured.err) == REFUSAL
    assert not out.exists()
    spec, config = asked[-1]
    assert spec.guards == "random" and config["world.engine"] == "batch"
    assert config["world.duration"] == 2.0  # the trial's own config


def test_run_on_the_reference_engine_never_asks_the_batch_engine(
        tmp_path: Path, batch_module: types.ModuleType, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    def refuse(spec: TrialSpec, config: Config) -> str:
        raise AssertionError("asked")

    monkeypatch.setattr(batch_module, "uncovered", refuse)
    out = tmp_path / "out"
    assert main(["run", "--preset", str(_preset(tmp_path)), "--out", str(out),
                 "--workers", "1", "--set", "world.engine=pymunk"]) == 0
    first = capsys.readouterr().err.splitlines()[0]
    assert first.endswith(f"-> {out} (engine pymunk)")
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert {t["engine"] for t in store.trials()} == {"pymunk"}


def test_auto_runs_what_the_batch_engine_covers_on_it_and_the_rest_on_pymunk(
        tmp_path: Path, batch_module: types.ModuleType, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(batch_module, "uncovered",
                        lambda spec, config: TEAM if spec.guards == "random" else None)
    out = tmp_path / "out"
    assert main(["run", "--preset", str(_preset(tmp_path)), "--out", str(out),
                 "--workers", "1"]) == 0  # the default engine: auto
    first = capsys.readouterr().err.splitlines()[0]
    assert first.endswith(f"-> {out} (engine auto: batch for 2 trials, pymunk for 2 (the "
                          f"batch engine does not cover {TEAM}))")
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        engines = {(t["guards"], t["engine"]) for t in store.trials()}
    assert engines == {("cheat", "batch"), ("random", "pymunk")}


def test_auto_says_batch_when_it_covers_every_trial(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["run", "--preset", str(_preset(tmp_path)), "--out", str(out),
                 "--workers", "1"]) == 0
    assert capsys.readouterr().err.splitlines()[0].endswith(f"-> {out} (engine auto: batch)")
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert {t["engine"] for t in store.trials()} == {"batch"}


def test_a_study_evaluates_on_both_engines_in_its_trials_order(
        batch_module: types.ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    from headless.executors import InlineExecutor
    from headless.tune.study import evaluate

    monkeypatch.setattr(batch_module, "uncovered",
                        lambda spec, config: TEAM if spec.guards == "random" else None)
    specs = [TrialSpec("maze", guards=g, seed=s, overrides=SHORT)
             for s in range(4) for g in ("cheat", "random")]
    rows = evaluate(InlineExecutor(), specs, 1, "auto")
    assert [r["key"] for r in rows] == [s.key for s in specs]
    assert [r["engine"] for r in rows] == ["batch", "pymunk"] * 4  # the batch's come first
    assert all(r["metrics"] == run_trial(s)["metrics"] for r, s in zip(rows, specs))


def test_run_on_the_batch_engine_maps_run_trials_over_its_batches(
        tmp_path: Path, batch_module: types.ModuleType, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    batches: list[list[str]] = []

    def run_trials(specs: Sequence[TrialSpec]) -> list[dict[str, Any]]:
        batches.append([s.key for s in specs])
        return [{**run_trial(s), "engine": "batch"} for s in specs]

    monkeypatch.setattr(batch_module, "run_trials", run_trials)
    monkeypatch.setattr(batch_module, "uncovered", lambda spec, config: None)
    out = tmp_path / "out"
    preset = _preset(tmp_path, set_='"world.engine" = "batch"')
    assert main(["run", "--preset", str(preset), "--out", str(out), "--workers", "1"]) == 0
    first = capsys.readouterr().err.splitlines()[0]
    assert first.endswith(f"-> {out} (engine batch)")
    assert len(batches) == 1 and len(batches[0]) == 4  # one level and abstraction: one batch
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert {t["engine"] for t in store.trials()} == {"batch"}
        assert store.meta()["design"] == json.dumps(load_preset(str(_preset(tmp_path))).design())


def test_a_batch_that_raises_becomes_error_rows_for_its_trials(
        batch_module: types.ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    specs = [TrialSpec("maze", seed=s) for s in range(3)]

    def broken(specs: Sequence[TrialSpec]) -> list[dict[str, Any]]:
        raise ValueError("out of lockstep")

    monkeypatch.setattr(batch_module, "run_trials", broken)
    rows = run_engine_batch(specs, {"maze": "maze"})
    assert [r["key"] for r in rows] == [s.key for s in specs]
    assert all(r["error"].startswith("ValueError: out of lockstep") for r in rows)
    assert all(r["engine"] == "batch" and r["level"] == "maze" for r in rows)
    monkeypatch.setattr(batch_module, "run_trials", lambda specs: [])  # rows missing
    rows = run_engine_batch(specs)
    assert len(rows) == 3 and all("answered 0 rows for 3 trials" in r["error"] for r in rows)


def test_sim_refuses_an_uncovered_trial_and_traces_in_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], batch_module: types.ModuleType,
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(batch_module, "uncovered", lambda spec, config: TEAM)
    assert main(["sim", "maze", "--set", "world.engine=batch", "--json"]) == 2
    captured = capsys.readouterr()
    assert _one_error_line(captured.err) == REFUSAL and captured.out == ""
    trace = tmp_path / "trace.jsonl"
    for option in (["--trace", str(trace)], ["--explain"]):
        assert main(["sim", "maze", "--set", "world.engine=batch", *option]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert line.startswith(f'stealth: error: world.engine = "batch" does not cover {option[0]}')
        assert line.endswith('(it writes no traces); use world.engine = "pymunk"')
    assert not trace.exists()


# ------------------------------------------------------------------ the store's engine column
def test_a_store_from_before_the_engine_column_resumes(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    preset = str(_preset(tmp_path))
    out = tmp_path / "out"
    assert main(["run", "--preset", preset, "--out", str(out), "--workers", "1"]) == 0
    path = out / "results.sqlite"
    with sqlite3.connect(path) as db:  # as a store written before the column existed
        db.execute("ALTER TABLE trials DROP COLUMN engine")
    with ResultStore(path, readonly=True) as store:  # readable as it is
        old = list(store.trials())
        assert len(old) == 4 and all("engine" not in t for t in old)
    assert main(["run", "--preset", preset, "--out", str(out), "--workers", "1",
                 "--seeds", "3"]) == 0
    assert "resuming: 4 of 6 trials already in" in capsys.readouterr().err
    with ResultStore(path, readonly=True) as store:
        engines = sorted((t["seed"], t["engine"] or "") for t in store.trials())
    assert [e for s, e in engines if s < 2] == [""] * 4  # the old rows: not known
    assert [e for s, e in engines if s == 2] == ["batch"] * 2  # auto: the batch engine covers them
