"""Two stores compared trial by trial (headless.paired): pairs, means and differences."""

from __future__ import annotations

from pathlib import Path

import pytest

from headless.analysis.paired import main, paired_rows, paired_table
from headless.presets import load_preset
from headless.sweep import run_sweep

TINY = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["cheat"]
players = ["evade"]
scenarios = ["capture", "fixed"]
seeds = 3
[set]
"world.duration" = 8.0
{extra}
"""


def _sweep(tmp_path: Path, name: str, extra: str = "") -> Path:
    preset = tmp_path / f"{name}.toml"
    preset.write_text(TINY.format(extra=extra), encoding="utf-8")
    out = tmp_path / name
    run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    return out


def test_a_store_against_itself_differs_by_nothing_and_blind_guards_never_detect(
        tmp_path: Path) -> None:
    control = _sweep(tmp_path, "control")
    blind = _sweep(tmp_path, "blind", '"world.view_range" = 0.0')
    same = {(r["measure"], r["env"]): r for r in paired_rows(control, control)}
    assert same[("CaptureRate", "grid")]["pairs"] == 3
    assert all(r["difference"][0] == 0.0 for r in same.values())
    rows = {(r["measure"], r["env"]): r for r in paired_rows(blind, control)}
    assert rows[("FirstDetectTime", "both")]["arm"][0] == 60.0  # never detected: full 60 s
    assert rows[("FirstDetectTime", "both")]["pairs"] == 3


def test_the_command_prints_a_table_and_refuses_a_missing_store(tmp_path: Path) -> None:
    control = _sweep(tmp_path, "control")
    assert main([str(control), str(control), "--names", "a", "b"]) == 0
    assert main([str(control), str(tmp_path / "nowhere")]) == 2


def test_control_guards_pair_two_guard_modes_of_one_store(tmp_path: Path) -> None:
    preset = tmp_path / "two.toml"
    preset.write_text(TINY.format(extra="").replace('guards = ["cheat"]',
                                                    'guards = ["cheat", "random"]'),
                      encoding="utf-8")
    out = tmp_path / "two"
    run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    across = {(r["measure"], r["env"]): r
              for r in paired_rows(out, out, guards="cheat", control_guards="random")}
    cheat = {(r["measure"], r["env"]): r for r in paired_rows(out, out, guards="cheat")}
    walk = {(r["measure"], r["env"]): r for r in paired_rows(out, out, guards="random")}
    for key, row in across.items():
        assert row["pairs"] == 3
        assert row["arm"] == cheat[key]["arm"] and row["control"][0] == walk[key]["arm"][0]
        assert row["difference"][0] == pytest.approx(row["arm"][0] - row["control"][0])
    assert main([str(out), str(out), "--guards", "cheat", "--control-guards", "random"]) == 0
    assert main([str(out), str(out), "--control-guards", "random"]) == 2


def test_a_measure_without_pairs_has_no_row(tmp_path: Path) -> None:
    preset = tmp_path / "fixed.toml"
    preset.write_text(TINY.format(extra="").replace('scenarios = ["capture", "fixed"]',
                                                    'scenarios = ["fixed"]'), encoding="utf-8")
    out = tmp_path / "fixed"
    run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    table = paired_table(paired_rows(out, out))
    assert "CaptureRate" not in table and "| CapturesInTime | grid | 3 |" in table
