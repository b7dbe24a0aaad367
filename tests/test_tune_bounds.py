"""``stealth tune`` is bounded (issue 35): never beside a results store, at most
MAX_STUDY_TRIALS trials, and the study's trials × physics steps within the sweeps' budget;
each refusal is one line before anything is written."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from game.budget import MAX_DESIGN_STEPS
from headless.tune.study import MAX_STUDY_TRIALS
from test_tune import SPEC as TINY_SPEC

pytest.importorskip("optuna")

ROOT = Path(__file__).resolve().parent.parent
# the tiny study of test_tune.py: maze, grid, pf × maxmin, capture and fixed, 1 + 1 seeds
SPEC = TINY_SPEC


def _tune(tmp_path: Path, *args: str, spec: str = SPEC) -> subprocess.CompletedProcess[str]:
    path = tmp_path / "spec.toml"
    path.write_text(spec)
    return subprocess.run([sys.executable, "-m", "headless.cli", "tune", str(path), *args],
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


def _refused(done: subprocess.CompletedProcess[str], words: str) -> None:
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("stealth: error: ") and done.stderr.count("\n") == 1
    assert words in done.stderr, done.stderr


def test_a_results_store_directory_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "run"
    out.mkdir()
    (out / "results.sqlite").write_bytes(b"")
    _refused(_tune(tmp_path, "--out", str(out), "--trials", "1"), "holds a results store")
    assert sorted(p.name for p in out.iterdir()) == ["results.sqlite"]


@pytest.mark.parametrize("trials", [str(10**12), str(MAX_STUDY_TRIALS + 1), "0"])
def test_trials_beyond_the_limit_are_refused(tmp_path: Path, trials: str) -> None:
    _refused(_tune(tmp_path, "--out", str(tmp_path / "out"), "--trials", trials),
             f"--trials: expected a number of trials in [1, {MAX_STUDY_TRIALS}]")
    assert not (tmp_path / "out").exists()


def test_the_study_steps_are_within_the_sweeps_budget(tmp_path: Path) -> None:
    """10,000 Optuna trials × 2 scenarios × 2,000 seeds of 60-s trials (1,200 steps) = 4.8e10
    steps > 2e9."""
    spec = SPEC.replace('"world.duration" = 3.0', "").replace("seeds_train = 1",
                                                              "seeds_train = 2000")
    assert "seeds_train = 2000" in spec and "world.duration" not in spec
    _refused(_tune(tmp_path, "--out", str(tmp_path / "out"), "--trials", "10000", spec=spec),
             f"physics steps in all, more than the limit of {MAX_DESIGN_STEPS}")
    assert not (tmp_path / "out").exists()


def test_a_searched_duration_counts_at_its_longest(tmp_path: Path) -> None:
    """A duration searched up to 50,000 s is 10^6 steps a trial: 10,000 trials exceed it."""
    spec = SPEC.replace('"world.guard_speed" = {low = 1.5, high = 3.0}',
                        '"world.duration" = {low = 1.0, high = 50000.0}').replace(
                            '"world.duration" = 3.0', "")
    assert '"world.duration" = {low' in spec
    _refused(_tune(tmp_path, "--out", str(tmp_path / "out"), "--trials", "10000", spec=spec),
             "physics steps in all")
    assert not (tmp_path / "out").exists()


def test_run_refuses_a_study_directory(tmp_path: Path) -> None:
    """The converse: `stealth run --out` a study's directory would make the study refused."""
    out = tmp_path / "study"
    out.mkdir()
    (out / "study.db").write_bytes(b"")
    done = subprocess.run([sys.executable, "-m", "headless.cli", "run", "--preset", "smoke",
                           "--out", str(out), "--workers", "1"], capture_output=True, text=True,
                          timeout=60, env={**os.environ, "PYTHONPATH": str(ROOT)})
    _refused(done, "holds a study (study.db of stealth tune)")
    assert sorted(p.name for p in out.iterdir()) == ["study.db"]
