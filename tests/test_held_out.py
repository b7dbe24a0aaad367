"""headless.held_out: a store's Table 3 on held-out seeds beside the paper's, cell by cell."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from headless.analysis.held_out import compare, distance, held_out_trials, main
from headless.tune.objective import aggregate, load_target
from headless.presets import load_preset
from headless.sweep import run_sweep

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["pf", "cheat"]
players = ["maxmin"]
scenarios = ["capture", "fixed"]
seeds = 3
[set]
"world.duration" = 4.0
"""


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("held")
    (folder / "p.toml").write_text(PRESET, encoding="utf-8")
    out = folder / "store"
    run_sweep(load_preset(str(folder / "p.toml")), out, workers=1, progress=False,
              stream=io.StringIO())
    return out


def test_only_the_held_out_seeds_count_and_cells_are_the_objectives(store: Path) -> None:
    trials = held_out_trials(store, 1)
    assert {t["seed"] for t in trials} == {1, 2} and len(trials) == 2 * 2 * 2
    target = load_target("paper-table3", store, {"abstractions": ["grid"],
                                                 "guards": ["pf", "cheat"],
                                                 "players": ["maxmin"],
                                                 "scenarios": ["capture", "fixed"]})
    compared = compare(trials, target)
    assert len(compared) == 2 * 7
    for r in compared:  # the tune objective's aggregate over the same trials
        same = [t for t in trials if t["guards"] == r.cell.guards]
        assert r.value == aggregate(same, r.cell.metric)
        assert r.within == (abs(r.value - r.cell.target) <= r.cell.tolerance)
    assert distance(compared) == pytest.approx(target.distance(trials)[0])


def test_the_table_goes_between_the_markers_with_errors(store: Path, tmp_path: Path) -> None:
    doc = tmp_path / "results.md"
    doc.write_text("a\n<!-- calibrated -->\nold\n<!-- /calibrated -->\nb\n", encoding="utf-8")
    figure = tmp_path / "errors.png"
    assert main([str(store), "--seeds-from", "1", "--baseline", str(store), "--figure",
                 str(figure), "--write", str(doc)]) == 0
    text = doc.read_text(encoding="utf-8")
    assert text.startswith("a\n<!-- calibrated -->\n")
    assert text.endswith("<!-- /calibrated -->\nb\n")
    assert "old" not in text and "held-out seeds 1–2" in text
    assert "| PotentialField | MaxMin | " in text and "(0.80, " in text  # the paper's PF rate
    assert "Capture-rate cells within ±0.10: " in text and "| all cells | " in text
    assert figure.stat().st_size > 0


def test_user_mistakes_are_one_line(store: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(store), "--seeds-from", "9"]) == 2
    assert capsys.readouterr().err.startswith("stealth: error: ")
    assert main([str(tmp_path / "nothing")]) == 2
    assert "no results.sqlite" in capsys.readouterr().err
    doc = tmp_path / "plain.md"
    doc.write_text("no markers\n", encoding="utf-8")
    assert main([str(store), "--write", str(doc)]) == 2
    assert doc.read_text(encoding="utf-8") == "no markers\n"
