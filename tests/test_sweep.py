"""Sweeps: presets, the results store, resuming after a kill, executors agree, bad presets."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from game.trial import TrialSpec, identity_row
from headless import executors
from headless.cli import main
from headless.analysis.report import write_report
from headless.store import ResultStore
from headless.presets import bundled_preset_names, load_preset
from headless.progress import Progress
from headless.sweep import run_sweep

ROOT = Path(__file__).resolve().parent.parent

TINY = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["cheat", "random"]
players = ["evade"]
scenarios = ["capture", "fixed"]
seeds = {seeds}

[set]
"world.duration" = {duration}
"""


def env() -> dict[str, str]:
    """The environment of a ``python -m headless.cli`` subprocess (project on the path)."""
    path = os.environ.get("PYTHONPATH", "")
    return {**os.environ, "PYTHONPATH": str(ROOT) + (os.pathsep + path if path else "")}


def stealth(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "headless.cli", *args], env=env(),
                          capture_output=True, text=True, timeout=timeout)


def write_preset(tmp_path: Path, seeds: int = 2, duration: float = 10.0,
                 name: str = "tiny.toml") -> Path:
    path = tmp_path / name
    path.write_text(TINY.format(seeds=seeds, duration=duration))
    return path


def stored_rows(out: Path) -> dict[str, dict[str, Any]]:
    """Every stored trial by key, without the timing columns."""
    db = sqlite3.connect(out / "results.sqlite")
    db.row_factory = sqlite3.Row
    rows = [dict(r) for r in db.execute("SELECT * FROM trials")]
    db.close()
    for row in rows:
        row.pop("wall_time")
        row.pop("finished_at")
    return {row["key"]: row for row in rows}


def read_csv(path: Path, drop: tuple[str, ...] = ("wall_time",)) -> list[tuple[str, ...]]:
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    return sorted(tuple(v for k, v in row.items() if k not in drop) for row in rows)


# ------------------------------------------------------------------------- presets
def test_bundled_presets_expand_to_their_designs() -> None:
    paper, quick, smoke = load_preset("paper"), load_preset("quick"), load_preset("smoke")
    assert paper.n_trials == len(paper.specs()) == 10_000
    assert quick.n_trials == 1_000
    assert set(paper.guards) == {"pf", "random", "fsm", "staleness", "cheat"}
    assert set(paper.players) == {"maxmin", "safetygraph"}
    assert len(paper.level_names) == 5 and len(paper.seeds) == 50
    assert 0 < smoke.n_trials <= 60
    specs = paper.specs()
    assert len({s.key for s in specs}) == len(specs)
    assert specs == load_preset("paper").specs()  # deterministic order
    assert [s.seed for s in specs[:200]] == [0] * 200  # seeds outermost
    literal = load_preset("paper-pf-literal")
    assert literal.n_trials == 2_000 and literal.guards == ("pf",)
    literal_keys = {s.key.rsplit("/", 1)[0] for s in literal.specs()}
    paper_pf = {s.key.rsplit("/", 1)[0] for s in specs if s.guards == "pf"}
    assert literal_keys == paper_pf  # the same trials, only the PF extensions switched off


def test_preset_by_path_and_nested_overrides(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text('levels = ["maze"]\nabstractions = "grid"\nguards = ["cheat"]\n'
                    'players = ["evade"]\nscenarios = ["fixed"]\nseeds = [3, 7]\n'
                    'root_seed = 5\n[set]\nworld.duration = 10\npf.rho = 0.9\n')
    preset = load_preset(str(path))
    assert preset.name == "mine" and preset.seeds == (3, 7) and preset.root_seed == 5
    assert preset.overrides == (("pf.rho", 0.9), ("world.duration", 10.0))  # coerced
    assert [s.seed for s in preset.specs()] == [3, 7]
    assert all(s.root_seed == 5 for s in preset.specs())


BAD = [
    ('guards = ["cheat", "random"]', 'guards = ["cheat", "sniper"]', "guards", "sniper"),
    ('levels = ["maze"]', 'levels = ["maze", "atlantis"]', "levels", "atlantis"),
    ('levels = ["maze"]', 'levels = ["missing/level.json"]', "levels", "no such file"),
    ('players = ["evade"]', "players = []", "players", "empty"),
    ("seeds = 2", "seeds = 0", "seeds", "at least 1"),
    ('abstractions = ["grid"]', 'abstractions = ["hex"]', "abstractions", "hex"),
    ('scenarios = ["capture", "fixed"]', 'scenarios = ["heist"]', "scenarios", "heist"),
    ("seeds = 2", "seeds = 2\ncolour = 'red'", "colour", "unknown key"),
    ('"world.duration" = 10.0', '"world.duraton" = 10.0', "set", "world.duraton"),
    ('"world.duration" = 10.0', '"world.duration" = "long"', "set", "world.duration"),
]


@pytest.mark.parametrize(("old", "new", "field", "words"), BAD)
def test_bad_preset_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, field: str,
    words: str,
) -> None:
    text = write_preset(tmp_path).read_text()
    assert old in text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(old, new))
    out = tmp_path / "out"
    assert main(["run", "--preset", str(bad), "--out", str(out), "--workers", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("stealth: error: ") and "bad.toml" in err
    assert f": {field}: " in err and words in err
    assert not out.exists()


@pytest.mark.parametrize("case", ["unknown mode", "missing level", "empty design"])
def test_stealth_run_bad_preset_exits_2_at_once(tmp_path: Path, case: str) -> None:
    text = write_preset(tmp_path).read_text()
    text = {"unknown mode": text.replace('"random"', '"ninja"'),
            "missing level": text.replace('"maze"', '"nowhere"'),
            "empty design": text.replace('guards = ["cheat", "random"]', "guards = []")}[case]
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    out = tmp_path / "out"
    done = stealth("run", "--preset", str(bad), "--out", str(out), "--workers", "2")
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: ") and "bad.toml" in lines[0]
    assert "Traceback" not in done.stderr and done.stdout == ""
    assert not out.exists()


def test_unknown_preset_name_lists_bundled(capsys: pytest.CaptureFixture[str],
                                           tmp_path: Path) -> None:
    assert main(["run", "--preset", "nope", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "smoke" in err and "paper" in err
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------------- store
def test_store_never_duplicates_and_retries_failures(tmp_path: Path) -> None:
    spec = TrialSpec("maze", "grid", "cheat", "evade", "capture", 0)
    base = identity_row(spec)
    good = {**base, "metrics": {"captured": True, "capture_time": 3.5, "captures": 1,
                                "coverage": 0.5, "avg_guard_player_dist": 2.0,
                                "first_detect_time": 1.0, "backtracks": 2},
            "visits": [1, 2], "attacks": [0.0, 0.5], "wall_time": 0.1}
    with ResultStore(tmp_path / "results.sqlite") as store:
        store.add({**base, "error": "boom"})
        assert store.count() == (0, 1) and store.done_keys() == set()
        store.add(good)  # a failure is replaced by a later success
        store.add({**base, "error": "late failure"})  # a success is never replaced
        store.add(good)
        assert store.count() == (1, 0)
        (trial,) = store.trials(heatmaps=True)
        assert trial["captured"] is True and trial["capture_time"] == 3.5
        assert trial["visits"] == [1, 2] and trial["attacks"] == [0.0, 0.5]


# ------------------------------------------------------------------------- sweeps
def test_kill_mid_sweep_then_resume_equals_uninterrupted_run(tmp_path: Path) -> None:
    preset = write_preset(tmp_path, seeds=20, duration=20.0)
    total = load_preset(str(preset)).n_trials
    reference = tmp_path / "reference"
    result = run_sweep(load_preset(str(preset)), reference, workers=1, progress=False)
    assert result.finished == total

    out = tmp_path / "killed"
    args = [sys.executable, "-m", "headless.cli", "run", "--preset", str(preset),
            "--out", str(out), "--workers", "2"]
    process = subprocess.Popen(args, env=env(), stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, start_new_session=True)
    done = 0
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and process.poll() is None:
            try:
                db = sqlite3.connect(f"file:{out / 'results.sqlite'}?mode=ro", uri=True)
                done = db.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
                db.close()
            except sqlite3.Error:
                done = 0
            if done >= 4:
                break
            time.sleep(0.01)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)  # the sweep and its pool workers
        process.wait()
    assert process.returncode == -signal.SIGKILL, "the sweep finished before it was killed"
    partial = stored_rows(out)
    assert 0 < len(partial) < total

    rerun = stealth("run", "--preset", str(preset), "--out", str(out), "--workers", "2")
    assert rerun.returncode == 0, rerun.stderr
    assert f"{len(partial)} skipped" in rerun.stderr
    assert f"{total - len(partial)} finished" in rerun.stderr
    db = sqlite3.connect(out / "results.sqlite")
    assert db.execute("SELECT COUNT(*), COUNT(DISTINCT key) FROM trials").fetchone() == (total,
                                                                                        total)
    db.close()
    assert stored_rows(out) == stored_rows(reference)

    again = stealth("run", "--preset", str(preset), "--out", str(out), "--workers", "2")
    assert again.returncode == 0 and "nothing to do" in again.stderr


def test_smoke_is_identical_in_process_in_a_pool_and_on_dask(tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    outs = {name: tmp_path / name for name in ("one", "two", "dask")}
    done = stealth("run", "--preset", "smoke", "--out", str(outs["one"]), "--workers", "1")
    assert done.returncode == 0, done.stderr
    done = stealth("run", "--preset", "smoke", "--out", str(outs["two"]), "--workers", "2")
    assert done.returncode == 0, done.stderr
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster:
        done = stealth("run", "--preset", "smoke", "--out", str(outs["dask"]),
                       "--scheduler", cluster.scheduler_address)
    assert done.returncode == 0, done.stderr
    for out in outs.values():
        write_report(out, figures=False)  # the report's CSVs (test_report draws the figures)
    trials = [read_csv(out / "trials.csv") for out in outs.values()]
    assert len(trials[0]) == load_preset("smoke").n_trials
    assert trials[0] == trials[1] == trials[2]
    tables = [read_csv(out / "table.csv", drop=()) for out in outs.values()]
    assert tables[0] == tables[1] == tables[2]


def test_failed_trial_is_recorded_the_sweep_goes_on_and_a_rerun_retries_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    preset_path = write_preset(tmp_path, seeds=2, duration=5.0)
    real = executors.run_trial

    def flaky(spec: TrialSpec) -> dict[str, Any]:
        if spec.guards == "random" and spec.seed == 1:
            raise RuntimeError("simulated crash")
        return real(spec)

    monkeypatch.setattr(executors, "run_trial", flaky)
    out = tmp_path / "out"
    pymunk = ["--set", "world.engine=pymunk"]  # a trial of its own fails alone
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1",
                 *pymunk]) == 1
    err = capsys.readouterr().err
    assert "6 finished, 2 failed, 0 skipped" in err and "simulated crash" in err
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert store.count() == (6, 2)
        (failed, _) = store.trials(failed=True)
        assert "RuntimeError: simulated crash" in failed["error"]
        assert "Traceback" in failed["error"]

    monkeypatch.setattr(executors, "run_trial", real)
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1",
                 *pymunk]) == 0
    assert "2 finished, 0 failed, 6 skipped" in capsys.readouterr().err
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert store.count() == (8, 0)


def test_a_stored_rows_identity_is_the_specs_identity_row_failed_or_not(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    """A level file whose name is not its path: every stored row, a failure's too, has the
    level's name and the reference it was loaded from, as identity_row builds them."""
    level = json.loads((ROOT / "assets" / "levels" / "maze.json").read_text())
    level["name"] = "renamed-maze"
    (tmp_path / "my-level.json").write_text(json.dumps(level))
    preset_path = tmp_path / "file.toml"
    preset_path.write_text(TINY.format(seeds=1, duration=3.0).replace(
        'levels = ["maze"]', 'levels = ["my-level.json"]').replace(
        '"world.duration"', '"pf.rho" = 0.9\n"world.duration"'))
    real = executors.run_trial

    def flaky(spec: TrialSpec) -> dict[str, Any]:
        if spec.guards == "random":
            raise RuntimeError("simulated crash")
        return real(spec)

    monkeypatch.setattr(executors, "run_trial", flaky)
    out = tmp_path / "out"
    pymunk = ["--set", "world.engine=pymunk"]  # a trial of its own fails alone
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1",
                 *pymunk]) == 1
    capsys.readouterr()
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        stored = [*store.trials(), *store.trials(failed=True)]
    assert len(stored) == 4 and sum(1 for t in stored if t["error"]) == 2
    for trial in stored:
        spec = TrialSpec(trial["level_ref"], trial["abstraction"], trial["guards"],
                         trial["player"], trial["scenario"], trial["seed"],
                         tuple(sorted(trial["overrides"].items())), trial["root_seed"])
        expected = identity_row(spec, "renamed-maze")
        assert {k: trial[k] for k in expected} == expected
        assert trial["level_ref"] == str(tmp_path / "my-level.json")
        assert trial["factors"] == {}


def test_ctrl_c_keeps_committed_trials_and_says_how_to_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    preset_path = write_preset(tmp_path, seeds=3, duration=5.0)
    real, calls = executors.run_trial, []

    def interrupted(spec: TrialSpec) -> dict[str, Any]:
        calls.append(spec)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(spec)

    monkeypatch.setattr(executors, "run_trial", interrupted)
    out = tmp_path / "out"
    code = main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1",
                 "--set", "world.engine=pymunk"])  # trial by trial: the 4th is interrupted
    assert code == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "resume with: stealth run --preset" in err
    assert str(out) in err
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        assert store.count() == (3, 0)


def test_resume_refuses_a_different_design(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    run_sweep(load_preset(str(write_preset(tmp_path, seeds=1, duration=3.0))), out, workers=1,
              progress=False)
    before = stored_rows(out)
    # more seeds would grow the design (tests/test_experiments.py); another [set] is another
    other = write_preset(tmp_path, seeds=2, duration=4.0, name="other.toml")
    assert main(["run", "--preset", str(other), "--out", str(out), "--workers", "1"]) == 2
    assert "different design" in capsys.readouterr().err
    assert stored_rows(out) == before


def test_scheduler_without_dask_is_a_user_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # "not installed"
    out = tmp_path / "out"
    preset = write_preset(tmp_path)
    assert main(["run", "--preset", str(preset), "--out", str(out),
                 "--scheduler", "tcp://127.0.0.1:8786"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cluster" in err
    assert not out.exists()


def test_progress_redraws_on_a_terminal_and_prints_lines_otherwise() -> None:
    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    plain, tty = io.StringIO(), Tty()
    for stream in (plain, tty):
        bar = Progress(10, stream, interval=0.0)
        bar.update(5, 1, force=True)
        bar.update(5, force=True)
        bar.close()
    assert "\r" not in plain.getvalue() and plain.getvalue().count("\n") == 3
    assert "10/10 100%" in plain.getvalue() and "trials/s" in plain.getvalue()
    assert "ETA" in plain.getvalue() and "1 failed" in plain.getvalue()
    assert tty.getvalue().count("\r") == 3 and tty.getvalue().endswith("\n")


def test_workers_import_neither_pygame_nor_trimesh_nor_matplotlib() -> None:
    code = ("import sys; from game.trial import TrialSpec; from headless.executors import run_batch; "
            "rows = run_batch([TrialSpec('maze', 'grid', 'cheat', 'evade', 'capture', 0, "
            "(('world.duration', 2.0),))]); assert 'error' not in rows[0], rows[0]; "
            "print([m for m in ('pygame', 'trimesh', 'matplotlib') if m in sys.modules])")
    done = subprocess.run([sys.executable, "-c", code], env=env(), capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.skipif(__import__("multiprocessing").get_start_method() != "fork",
                    reason="the patched trial reaches the workers only through fork")
def test_a_dying_worker_stops_the_sweep_and_keeps_finished_trials(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    preset_path = write_preset(tmp_path, seeds=6, duration=5.0)
    real = executors.run_trial

    def dies(spec: TrialSpec) -> dict[str, Any]:
        if spec.seed == 5:
            os._exit(3)  # a crash no exception handler sees (segfault, OOM kill)
        return real(spec)

    monkeypatch.setattr(executors, "run_trial", dies)
    out = tmp_path / "out"
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "2",
                 "--set", "world.engine=pymunk"]) == 1  # trial by trial: seed 5's dies
    err = capsys.readouterr().err
    assert "a worker process died" in err and "resume with: stealth run" in err
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        finished, failed = store.count()
    assert 0 < finished < 24 and failed == 0


@pytest.mark.parametrize("name", bundled_preset_names())
def test_every_bundled_preset_loads_and_validates(name: str) -> None:
    preset = load_preset(name)  # every [set] key and value checked, the levels read
    assert preset.n_trials == len(preset.specs()) > 0


def test_paper_inferred_is_the_paper_design_with_its_stated_rules() -> None:
    paper, inferred = load_preset("paper"), load_preset("paper-inferred")
    assert inferred.n_trials == 10_000
    assert {k: v for k, v in inferred.design().items() if k != "set"} \
        == {k: v for k, v in paper.design().items() if k != "set"}
    stated = ("world.respawn", "pf.teammate_presence", "pf.revisit_penalty",
              "world.attack_needs_line_of_sight", "metrics.backtracks",
              "zones.dark_confidence_decay", "zones.concealment_confidence_decay",
              "zones.concealment_view_scale")
    ours, theirs = dict(inferred.overrides), dict(paper.overrides)
    assert {k: ours[k] for k in stated} == {k: theirs[k] for k in stated}
