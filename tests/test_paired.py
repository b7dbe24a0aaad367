"""Two stores compared trial by trial (headless.paired): pairs, means and differences."""

from __future__ import annotations

from pathlib import Path

from headless.paired import main, paired_rows
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
