"""headless.robustness: the paper's claims judged per factor cell on constructed stores whose
right answer is known (holds in one cell, reversed in another, a coin flip in a third)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from headless.errors import UserError
from headless.presets import load_preset
from headless.analysis.robustness import END, SECTION, START, judge, main, write_between_markers
from headless.store import STORE_NAME, ResultStore
from headless.tune.spec import load_tune_spec

GUARDS = ("cheat", "pf", "staleness", "fsm", "random")
#: capture rank (Cheat > PF > Staleness > FSM > RandomWalk, as the paper)
RANK = {"cheat": 4, "pf": 3, "staleness": 2, "fsm": 1, "random": 0}
#: fixed-time values where every claim holds: PF fewest backtracks, most coverage, and
#: Staleness more captures than PF
HOLDS: dict[str, dict[str, float]] = {"backtracks": {"cheat": 1, "pf": 5, "staleness": 20, "fsm": 25, "random": 150},
         "coverage": {"cheat": 0.3, "pf": 0.8, "staleness": 0.5, "fsm": 0.45, "random": 0.3},
         "captures": {"cheat": 9, "pf": 1, "staleness": 2, "fsm": 1, "random": 0}}
PARITY = {"cheat": 0, "pf": 1, "staleness": 0, "fsm": 1, "random": 0}
SEEDS = 40
#: what every claim does in each cell of the (speed, view) grid
MODES = {(1.6, 5.0): "holds", (1.6, 8.0): "fails", (2.4, 5.0): "undecided",
         (2.4, 8.0): "holds"}


def _metrics(guard: str, scenario: str, seed: int, mode: str) -> dict[str, Any]:
    if scenario == "capture":
        if mode == "holds":
            captured = seed % 5 < RANK[guard]
        elif mode == "fails":
            captured = seed % 5 < 4 - RANK[guard]
        else:  # adjacent modes of the order capture on alternate seeds: differences ±1
            captured = (seed + PARITY[guard]) % 2 == 0
        return {"captured": captured, "capture_time": 10.0 if captured else None}
    out: dict[str, Any] = {}
    for name, values in HOLDS.items():
        value = float(values[guard]) + 0.01 * (seed % 3)
        if mode == "fails":
            value = 200.0 - value
        elif mode == "undecided":
            value = 10.0 + (1.0 if (seed + PARITY[guard]) % 2 else -1.0)
        out[name] = int(round(value)) if name != "coverage" else value
    return out


def _trials(skip: frozenset[str] = frozenset()) -> list[dict[str, Any]]:
    rows = []
    for (speed, view), mode in MODES.items():
        for guard in GUARDS:
            for scenario in ("capture", "fixed"):
                for seed in range(SEEDS):
                    key = f"maze/grid/{guard}/maxmin/{scenario}/{seed}/{speed}/{view}"
                    if key in skip:
                        continue
                    rows.append({"key": key, "level": "maze", "level_ref": "maze",
                                 "abstraction": "grid", "guards": guard, "player": "maxmin",
                                 "scenario": scenario, "seed": seed, "root_seed": 0,
                                 "overrides": {}, "config_hash": "x",
                                 "metrics": _metrics(guard, scenario, seed, mode),
                                 "factors": {"world.player_speed": speed,
                                             "world.view_range": view}})
    return rows


def _store(tmp_path: Path, rows: list[dict[str, Any]]) -> Path:
    directory = tmp_path / "store"
    directory.mkdir()
    with ResultStore(directory / STORE_NAME) as store:
        for row in rows:
            store.add(row)
    return directory


def _stored(directory: Path) -> list[dict[str, Any]]:
    with ResultStore(directory / STORE_NAME, readonly=True) as store:
        return list(store.trials())


def test_every_claim_is_judged_as_constructed_in_every_cell(tmp_path: Path) -> None:
    keys, judgements = judge(_stored(_store(tmp_path, _trials())))
    assert keys == ("world.player_speed", "world.view_range")
    assert len(judgements) == 5 * len(MODES)  # five claims, one abstraction
    for j in judgements:
        assert j.outcome == MODES[j.cell], (j.claim.name, j.cell, j.verdicts)
        assert all(v.pairs == SEEDS for v in j.verdicts)
    got = {(j.claim.name, j.cell): j for j in judgements}
    order = got[("order", (1.6, 5.0))]
    assert [(v.a, v.b) for v in order.verdicts] == [("cheat", "pf"), ("pf", "staleness"),
                                                    ("staleness", "fsm"), ("fsm", "random")]
    assert all(v.mean == pytest.approx(0.2) for v in order.verdicts)  # 1 seed in 5
    # a failing claim shows a failing comparison: here every one is reversed
    fails = got[("backtracks", (1.6, 8.0))].decisive
    assert fails.outcome == "fails" and fails.high < 0
    # Staleness - PF on CapturesInTime: +1 where it holds (2 vs 1)
    assert got[("captures", (2.4, 8.0))].verdicts[0].mean == pytest.approx(1.0)


def test_a_partly_run_store_is_judged_on_its_complete_pairs(tmp_path: Path) -> None:
    skip = frozenset(f"maze/grid/pf/maxmin/fixed/{seed}/1.6/5.0" for seed in range(5))
    _, judgements = judge(_stored(_store(tmp_path, _trials(skip))))
    coverage = next(j for j in judgements if j.claim.name == "coverage" and j.cell == (1.6, 5.0))
    assert [v.pairs for v in coverage.verdicts] == [SEEDS - 5] * 3
    order = next(j for j in judgements if j.claim.name == "order" and j.cell == (1.6, 5.0))
    assert [v.pairs for v in order.verdicts] == [SEEDS] * 4  # capture trials all there


def test_a_design_without_two_numeric_factors_is_refused() -> None:
    rows = [{**r, "factors": {"world.view_range": r["factors"]["world.view_range"]}}
            for r in _trials()]
    with pytest.raises(UserError, match="exactly two numeric factors"):
        judge([{**r, **r["metrics"]} for r in rows])


def test_the_command_writes_the_tables_between_markers_and_the_figure(tmp_path: Path) -> None:
    directory = _store(tmp_path, _trials())
    doc = tmp_path / "results.md"
    doc.write_text("# Results\n\nkeep me\n", encoding="utf-8")
    figure = tmp_path / "img" / "robustness.png"
    assert main([str(directory), "--write", str(doc), "--figure", str(figure)]) == 0
    text = doc.read_text(encoding="utf-8")
    assert text.startswith("# Results\n\nkeep me\n") and text.rstrip().endswith(END)
    assert text.count(SECTION) == 1 and text.index(SECTION) < text.index(START)
    assert "| 1.6 (0.8) | 5 | ✓ " in text  # speed written with its ratio, a verdict mark
    assert "10 of 20 verdicts hold, 5 fail, 5 undecided" in text
    assert figure.stat().st_size > 10_000
    # a second write replaces the block, and text after the markers stays
    doc.write_text(text + "\nafter\n", encoding="utf-8")
    write_between_markers(doc, "new table")
    again = doc.read_text(encoding="utf-8")
    assert f"{START}\nnew table\n{END}" in again and again.endswith("\nafter\n")
    assert again.count(SECTION) == 1
    assert main([str(tmp_path / "nowhere")]) == 2


def test_the_bundled_robustness_preset_and_designer_files_fit_together() -> None:
    robustness = load_preset("paper-robustness")
    assert robustness.n_trials == 9 * 200 * len(robustness.seeds)
    assert [k for k, _ in robustness.factors] == ["world.player_speed", "world.view_range"]
    assert robustness.overrides == load_preset("paper").overrides
    study = load_tune_spec("designer-pf")
    held = load_preset("pf-designer-heldout")
    # the held-out preset runs exactly the study's held-out seeds of its design, with Staleness
    assert held.seeds == tuple(range(study.seeds_train, study.seeds_train + study.seeds_test))
    assert set(held.guards) == {*study.preset.guards, "staleness"}
    for field in ("level_names", "abstractions", "players", "scenarios", "overrides"):
        assert getattr(held, field) == getattr(study.preset, field), field
    assert all(p.key.startswith("pf.") for p in study.params)  # nothing a Staleness guard reads
