"""``stealth tune``: a tiny study runs, writes its outputs, resumes after a kill, and gives
the same best parameters when run twice with the same sampler seed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from game.config_file import read_config_file
from headless.cli import main
from headless.tune.objective import load_target
from headless.tune.spec import load_tune_spec

pytest.importorskip("optuna")

ROOT = Path(__file__).resolve().parent.parent
SPEC = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["pf"]
players = ["maxmin"]
scenarios = ["capture", "fixed"]
seeds_train = 1
seeds_test = 1
sampler_seed = 3
[set]
"world.duration" = 3.0
[search]
"world.guard_speed" = {low = 1.5, high = 3.0}
"pf.rho" = {choices = [0.9, 0.95]}
[objective]
maximize = "coverage - 0.01*backtracks"
constraints = ["backtracks <= 50"]
"""


def spec(tmp_path: Path) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(SPEC)
    return path


def tune(path: Path, out: Path, trials: int) -> int:
    return main(["tune", str(path), "--out", str(out), "--trials", str(trials), "--workers", "1"])


def test_a_tiny_study_writes_its_outputs_and_is_reproducible(tmp_path: Path) -> None:
    path = spec(tmp_path)
    assert tune(path, tmp_path / "a", 3) == 0
    assert tune(path, tmp_path / "b", 3) == 0
    for name in ("best.toml", "study.csv", "report.md", "history.png", "params.png"):
        assert (tmp_path / "a" / name).stat().st_size > 0, name
    best = read_config_file(tmp_path / "a" / "best.toml")  # a valid --config file
    assert set(best) == {"world.guard_speed", "pf.rho"}
    assert best == read_config_file(tmp_path / "b" / "best.toml")
    assert (tmp_path / "a" / "study.csv").read_text() == (tmp_path / "b" / "study.csv").read_text()
    report = (tmp_path / "a" / "report.md").read_text()
    assert "held-out seeds" in report and "importances" in report
    # growing the study by more trials runs only those
    assert tune(path, tmp_path / "a", 4) == 0
    assert len((tmp_path / "a" / "study.csv").read_text().splitlines()) == 1 + 4


def test_a_killed_study_resumes_to_the_same_result(tmp_path: Path) -> None:
    path = spec(tmp_path)
    reference = tmp_path / "ref"
    assert tune(path, reference, 3) == 0
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen(
        [sys.executable, "-m", "headless.cli", "tune", str(path), "--out", str(out),
         "--trials", "3", "--workers", "1"], env=env, stderr=subprocess.PIPE, text=True)
    assert process.stderr is not None
    for line in process.stderr:  # kill it after its first trial, in the middle of the next
        if "tune trial 0" in line:
            process.send_signal(signal.SIGKILL)
            break
    process.wait(timeout=60)
    assert process.returncode == -signal.SIGKILL
    assert not (out / "best.toml").exists() and (out / "study.db").exists()
    assert tune(path, out, 3) == 0
    assert read_config_file(out / "best.toml") == read_config_file(reference / "best.toml")
    states = [line.split(",")[1] for line in (out / "study.csv").read_text().splitlines()[1:]]
    assert states.count("COMPLETE") == 3


@pytest.mark.parametrize("change, problem", [
    (('maximize = "coverage - 0.01*backtracks"', 'maximize = "coverage + os.system"'), "metric"),
    (('maximize = "coverage - 0.01*backtracks"', 'maximize = "nope"'), "not a metric"),
    (('maximize = "coverage - 0.01*backtracks"', 'maximize = "cheat.coverage"'),
     "no guard mode"),
    (('{low = 1.5, high = 3.0}', '{low = 3.0, high = 1.5}'), "low < high"),
    (('"world.guard_speed"', '"world.nope"'), "unknown config key"),
    (("seeds_train = 1", "seeds_train = 0"), "seeds_train"),
])
def test_bad_specs_are_one_line_errors(tmp_path: Path, change: tuple[str, str], problem: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.replace(*change))
    assert tune(path, tmp_path / "out", 1) == 2
    err = capsys.readouterr().err
    assert err.startswith("stealth: error:") and problem in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_the_paper_table_is_a_target(tmp_path: Path) -> None:
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.replace('maximize = "coverage - 0.01*backtracks"\n'
                                 'constraints = ["backtracks <= 50"]',
                                 'target = "paper-table3"'))
    loaded = load_tune_spec(path)
    assert loaded.target is not None
    # grid/pf/maxmin, both scenarios: 7 cells of the paper's Table 3
    assert {(c.metric, c.target) for c in loaded.target.cells} >= {("captured", 0.80),
                                                                  ("backtracks", 2.94)}
    assert len(loaded.target.cells) == 7
    capture = next(c for c in loaded.target.cells if c.metric == "captured")
    assert capture.tolerance == 0.10
    assert tomllib.loads(path.read_text())["objective"]["target"] == "paper-table3"
    design = {"abstractions": ("grid",), "guards": ("pf",), "players": ("maxmin",),
              "scenarios": ("capture",)}
    assert len(load_target("paper-table3", tmp_path, design).cells) == 2


def test_a_special_file_as_spec_is_refused_in_one_line(tmp_path: Path) -> None:
    import os

    from headless.tune.spec import load_tune_spec
    from navmesh.errors import StealthError

    fifo = tmp_path / "spec.toml"
    os.mkfifo(fifo)
    with pytest.raises(StealthError, match="is a FIFO"):
        load_tune_spec(fifo)  # refused at once, never blocks on the pipe
