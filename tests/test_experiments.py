"""Experiments as designs (SPEC §10): factors, growing designs, --config, sim --from."""

from __future__ import annotations

import json
import os
import sqlite3
from pathlib import Path
from typing import Any

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # replay --trial, before pygame loads

from game.trial import trial_rngs  # noqa: E402
from headless.cli import main
from headless.errors import UserError
from headless.tune.expr import parse_constraint, parse_expression
from headless.presets import load_preset
from headless.analysis.report import write_report
from headless.store import ResultStore
from headless.sweep import run_sweep

DESIGN = """
levels = {levels}
abstractions = {abstractions}
guards = {guards}
players = ["maxmin"]
scenarios = ["capture", "fixed"]
seeds = {seeds}
[set]
"world.duration" = 4.0
{factors}
"""


def write(tmp_path: Path, name: str = "d.toml", *, levels: str = '["maze"]',
          abstractions: str = '["grid"]', guards: str = '["pf", "random"]', seeds: int = 1,
          factors: str = "") -> Path:
    path = tmp_path / name
    path.write_text(DESIGN.format(levels=levels, abstractions=abstractions, guards=guards,
                                  seeds=seeds, factors=factors))
    return path


def rows(out: Path) -> dict[str, dict[str, Any]]:
    db = sqlite3.connect(out / "results.sqlite")
    db.row_factory = sqlite3.Row
    found = {r["key"]: dict(r) for r in db.execute("SELECT * FROM trials")}
    db.close()
    for row in found.values():
        row.pop("wall_time")
        row.pop("finished_at")
    return found


# ------------------------------------------------------------------------ factors
def test_factors_cross_the_design_and_are_part_of_the_identity(tmp_path: Path) -> None:
    preset = load_preset(str(write(tmp_path, seeds=2, factors='[factors]\n'
                                   '"world.guard_speed" = [2, 3.0]\n"pf.rho" = [0.9, 0.95, 0.99]')))
    specs = preset.specs()
    assert preset.n_trials == len(specs) == 2 * 2 * 2 * 2 * 3  # seeds guards scen speed rho
    assert len({s.key for s in specs}) == len(specs)
    assert preset.factors == (("pf.rho", (0.9, 0.95, 0.99)), ("world.guard_speed", (2.0, 3.0)))
    one = specs[0]
    assert one.key.endswith("/factors=pf.rho=0.9,world.guard_speed=2.0")
    assert one.settings["world.guard_speed"] == 2.0 and one.settings["world.duration"] == 4.0
    # spawns are paired across factor levels, the controllers' draws are not
    other = next(s for s in specs if s.factors != one.factors and s.seed == one.seed
                 and s.guards == one.guards and s.scenario == one.scenario)
    a, b = trial_rngs(one, "maze"), trial_rngs(other, "maze")
    assert a[0].random() == b[0].random()
    assert a[1].random() != b[1].random()


def test_a_design_without_factors_keeps_todays_keys_seeds_and_design() -> None:
    spec = load_preset("smoke").specs()[0]
    assert spec.key == "maze/grid/pf/maxmin/capture/0/0/world.duration=20.0"
    # the draws today's main gives this identity (computed with the code before factors)
    guards, player = trial_rngs(spec, "maze")[1:]
    assert (guards.integers(1 << 30), player.integers(1 << 30)) == (53453475, 872286324)
    assert "factors" not in load_preset("smoke").design()


@pytest.mark.parametrize("factors, problem", [
    ('"world.nope" = [1.0]', "unknown config key"),
    ('"world.guard_speed" = "fast"', "non-empty list"),
    ('"world.guard_speed" = []', "non-empty list"),
    ('"world.guard_speed" = [2.0, "x"]', "expected"),
    ('"world.guard_speed" = [2.0, 2]', "listed twice"),
    ('"world.duration" = [3.0]', "also in [set]"),
])
def test_bad_factors_are_one_line_errors(tmp_path: Path, factors: str, problem: str,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, factors="[factors]\n" + factors)
    assert main(["run", "--preset", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stealth: error: ") and problem in err and err.count("\n") == 1


# ------------------------------------------------------------------------ growing
def test_growing_a_design_runs_only_the_missing_trials(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    small = write(tmp_path, "small.toml", factors='[factors]\n"world.guard_speed" = [2.0]')
    assert main(["run", "--preset", str(small), "--out", str(out), "--workers", "1"]) == 0
    before = rows(out)
    assert len(before) == 4
    grown = write(tmp_path, "grown.toml", factors='[factors]\n"world.guard_speed" = [2.0, 3.0]')
    assert main(["run", "--preset", str(grown), "--out", str(out), "--workers", "1",
                 "--seeds", "2"]) == 0
    assert "12 finished, 0 failed, 4 skipped" in capsys.readouterr().err
    after = rows(out)
    assert len(after) == 16 and all(after[k] == v for k, v in before.items())
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        design = json.loads(store.meta()["design"])
        assert design["seeds"] == [0, 1] and design["factors"] == {"world.guard_speed": [2.0, 3.0]}
    # fewer seeds afterwards: nothing to run, the stored design keeps its union
    assert main(["run", "--preset", str(small), "--out", str(out), "--workers", "1"]) == 0
    assert "nothing to do" in capsys.readouterr().err
    # a real change is refused, the store untouched
    other = write(tmp_path, "other.toml", guards='["pf", "cheat"]',
                  factors='[factors]\n"world.guard_speed" = [2.0]')
    assert main(["run", "--preset", str(other), "--out", str(out), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert "different design" in err and "guards differ" in err
    keys = write(tmp_path, "keys.toml", factors='[factors]\n"world.view_range" = [6.0]')
    assert main(["run", "--preset", str(keys), "--out", str(out), "--workers", "1"]) == 2
    assert "factors differ" in capsys.readouterr().err
    assert rows(out) == after


def test_a_store_from_before_factors_resumes(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """A store as today's main writes it (no factors column) is resumed, not refused."""
    preset_path = write(tmp_path, seeds=2)
    out = tmp_path / "out"
    run_sweep(load_preset(str(preset_path)).with_seeds(1), out, workers=1, progress=False)
    db = sqlite3.connect(out / "results.sqlite")
    db.execute("ALTER TABLE trials DROP COLUMN factors")  # the old schema
    db.commit()
    db.close()
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1",
                 "--seeds", "1"]) == 0
    assert "nothing to do" in capsys.readouterr().err
    assert main(["run", "--preset", str(preset_path), "--out", str(out), "--workers", "1"]) == 0
    assert "4 finished, 0 failed, 4 skipped" in capsys.readouterr().err


# ------------------------------------------------------------------------ --config
def test_config_file_overrides_like_set(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "c.toml"
    config.write_text('[world]\nduration = 3.0\n"guard_speed" = 2.5\n')
    assert main(["sim", "maze", "--json", "--config", str(config), "--set",
                 "world.guard_speed=3"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["config"]["world.duration"] == 3.0
    assert document["config"]["world.guard_speed"] == 3.0  # --set wins over the file
    config.write_text('"world.nope" = 1\n')
    assert main(["sim", "maze", "--config", str(config)]) == 2
    err = capsys.readouterr().err
    assert "world.nope: unknown config key" in err and err.count("\n") == 1


# ------------------------------------------------------------------------ sim --from
def test_sim_from_reproduces_stored_rows_exactly(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, levels='["maze", "miami"]', abstractions='["grid", "partition"]',
                 guards='["pf", "fsm", "cheat"]', factors='[factors]\n"pf.rho" = [0.9]')
    out = tmp_path / "out"
    run_sweep(load_preset(str(path)), out, workers=1, progress=False)
    write_report(out, figures=False)
    header = (out / "trials.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "key" and "pf.rho" in header
    with ResultStore(out / "results.sqlite", readonly=True) as store:
        stored = list(store.trials())
    assert len(stored) == 24
    for trial in stored:
        assert main(["sim", "--from", str(out), "--trial", trial["key"], "--json"]) == 0
        captured = capsys.readouterr()
        document = json.loads(captured.out)
        assert "identical to the stored row" in captured.err
        assert document["key"] == trial["key"] and document["factors"] == {"pf.rho": 0.9}
        for name, value in document["metrics"].items():
            assert value == trial[name], (trial["key"], name)
    assert main(["sim", "--from", str(out), "--trial", "nope"]) == 2
    assert "no finished trial with this key" in capsys.readouterr().err
    assert main(["sim", "maze", "--from", str(out), "--trial", stored[0]["key"]]) == 2
    capsys.readouterr()
    shot = tmp_path / "shot.png"
    assert main(["replay", str(out), "--trial", stored[-1]["key"], "--frames", "3",
                 "--screenshot", str(shot)]) == 0
    assert shot.stat().st_size > 0


# ------------------------------------------------------------------------ expressions
def test_expressions_are_arithmetic_over_metric_names_only() -> None:
    values = {"captures": 4.0, "backtracks": 10.0}
    assert parse_expression("captures - 0.05*backtracks").evaluate(
        lambda n, s: values[n]) == pytest.approx(3.5)
    assert parse_expression("pf.captures - staleness.captures").names == (
        ("captures", ("pf",)), ("captures", ("staleness",)))
    assert parse_constraint("backtracks >= 12").evaluate(lambda n, s: values[n]) == 2.0
    for bad in ("__import__('os').system('x')", "captures if 1 else 2", "[captures]",
                "captures.__class__()", "'a'", "1 + 2", "captures <= 1"):
        with pytest.raises(UserError):
            parse_expression(bad)
    with pytest.raises(UserError):
        parse_constraint("captures")
