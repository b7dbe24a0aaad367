"""Issue 24 class 2: values in range one by one, unbounded work together, refused up front.

A trial's physics steps (``world.duration / world.physics_step``, and the interactive step),
a design's trials × steps and the smoothing kernel's node pairs (``pf.kernel_radius``) are
bounded before anything runs, with one line naming the key — wherever the values come from:
``--set``, a preset's ``[set]`` or ``[factors]``, a store row re-run by ``sim --from``.
"""

from __future__ import annotations

import json
import sqlite3
import time
from pathlib import Path

import numpy as np
import pytest

import ai.kernel as fields
from ai.errors import WorkBudgetError
from ai.fields import kernel_matrix
from game.budget import MAX_DESIGN_STEPS, MAX_TRIAL_STEPS
from game.config import Config
from game.errors import ConfigError
from headless.cli import main
from headless.errors import PresetError
from headless.presets import load_preset
from navmesh.graph import BallTooLarge, graph_for, hop_ball_pairs
from navmesh.level import load_level


def _one_line(capsys: pytest.CaptureFixture[str], *needles: str) -> str:
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), lines
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize(("setting", "key"), [
    ("world.physics_step=1e-300", "world.physics_step"),
    ("world.duration=1e15", "world.duration"),
    ("world.physics_step_interactive=1e-9", "world.physics_step_interactive = 1e-09"),
])
def test_a_trial_of_too_many_steps_is_refused_at_once(setting, key, capsys):
    start = time.monotonic()
    assert main(["sim", "maze", "--set", setting]) == 2
    _one_line(capsys, key, "more than the limit of")
    assert time.monotonic() - start < 10


def test_the_budget_is_a_rule_of_every_config():
    with pytest.raises(ConfigError, match="world.duration / world.physics_step"):
        Config.load({"world.duration": 1e15})
    Config.load({"world.duration": MAX_TRIAL_STEPS * 0.05})  # exactly at the limit


def test_a_kernel_radius_past_the_diameter_costs_the_diameter():
    graph = graph_for(load_level("maze"), "grid")
    start = time.monotonic()
    huge = kernel_matrix(graph, 0.8, 10**7)
    assert time.monotonic() - start < 5
    enough = kernel_matrix(graph, 0.8, graph.n)  # no hop distance exceeds n - 1
    assert (huge != enough).nnz == 0
    rows, _, hops = hop_ball_pairs(graph, 10**7)
    assert hops.max() < graph.n and np.bincount(rows).min() > 1


def test_a_kernel_over_the_pair_budget_names_the_key(monkeypatch, capsys):
    graph = graph_for(load_level("maze"), "grid")
    with pytest.raises(BallTooLarge):
        hop_ball_pairs(graph, 50, max_pairs=graph.n * 10)
    monkeypatch.setattr(fields, "MAX_KERNEL_PAIRS", graph.n * 10)
    with pytest.raises(WorkBudgetError, match=r"pf.kernel_radius = 50: .* more than the limit"):
        kernel_matrix(graph, 0.8, 50)
    assert main(["sim", "maze", "--set", "pf.kernel_radius=50"]) == 2
    _one_line(capsys, "pf.kernel_radius = 50")


def _preset(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "design.toml"
    path.write_text('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["random"]\n'
                    'players = ["maxmin"]\nscenarios = ["capture"]\n' + body)
    return path


def test_a_factor_level_of_too_many_steps_is_refused_before_the_design_runs(tmp_path):
    path = _preset(tmp_path, 'seeds = 1\n[factors]\n"world.duration" = [20.0, 1e15]\n')
    with pytest.raises(PresetError, match=r"factors.world.duration: world.duration / world.physics_step = 1e\+15"):
        load_preset(path)
    both = _preset(tmp_path, 'seeds = 1\n[factors]\n"world.duration" = [20.0, 1001.0]\n'
                             '"world.physics_step" = [0.05, 0.001]\n')
    with pytest.raises(PresetError, match="1001 / 0.001 = 1e\\+06"):
        load_preset(both)  # each level alone is fine, 1000 s at 1 ms together is not


def test_a_design_of_too_many_steps_in_all_is_refused(tmp_path):
    seeds = MAX_DESIGN_STEPS // MAX_TRIAL_STEPS + 1
    path = _preset(tmp_path, f'seeds = {seeds}\n[set]\n"world.duration" = '
                             f'{MAX_TRIAL_STEPS * 0.05}\n')
    with pytest.raises(PresetError, match="physics steps in all, more than the limit"):
        load_preset(path)


def test_a_store_row_carrying_absurd_values_is_refused_by_sim_from(tmp_path, capsys):
    preset = _preset(tmp_path, 'seeds = 1\n[set]\n"world.duration" = 1.0\n')
    out = tmp_path / "out"
    assert main(["run", "--preset", str(preset), "--out", str(out), "--workers", "1"]) == 0
    capsys.readouterr()
    with sqlite3.connect(out / "results.sqlite") as db:
        key, overrides = db.execute("SELECT key, overrides FROM trials").fetchone()
        tampered = {**json.loads(overrides), "world.physics_step": 1e-300}
        db.execute("UPDATE trials SET overrides = ? WHERE key = ?", (json.dumps(tampered), key))
    start = time.monotonic()
    assert main(["sim", "--from", str(out), "--trial", key]) == 2
    _one_line(capsys, "world.physics_step")
    assert time.monotonic() - start < 10
