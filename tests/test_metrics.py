"""The metric registry: a metric registered by an extension reaches every output, and an
older store gains the columns of metrics registered since it was written."""

from __future__ import annotations

import csv
import sqlite3
from collections.abc import Iterator
from pathlib import Path

import pytest

from game.metrics import Metric, metric_names, register_metric, unregister_metric
from game.trial import TrialSpec, identity_row
from headless.analysis.figures import aggregate_figure, layout
from headless.analysis.report import table_columns, table_rows, write_report
from headless.store import ResultStore
from headless.sweep import load_preset, run_sweep

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["cheat", "random"]
players = ["evade"]
scenarios = ["capture", "fixed"]
seeds = 2

[set]
"world.duration" = 6.0
"""

#: the test-only world extension: how many distinct nodes the guards entered
VISITED = Metric("visited_nodes", lambda world: int(world.m.covered.sum()), kind="int",
                 column="VisitedNodes", definition="distinct nodes any guard entered")


@pytest.fixture
def visited_metric() -> Iterator[Metric]:
    register_metric(VISITED)
    try:
        yield VISITED
    finally:
        unregister_metric(VISITED.name)


def test_core_registry_is_the_spec_metrics_in_order() -> None:
    assert metric_names() == ("captured", "capture_time", "captures", "coverage",
                              "avg_guard_player_dist", "first_detect_time", "backtracks",
                              # SPEC §11: every definition of the keyed ones
                              "coverage_visited", "coverage_seen", "coverage_per_guard",
                              "backtracks_targets", "backtracks_entries", "dist_path",
                              "dist_euclidean",
                              # SPEC §12: the coverage readings the paper's numbers may select
                              "coverage_area", "coverage_seen_area", "coverage_seen_per_guard")
    with pytest.raises(ValueError, match="already registered"):
        register_metric(Metric("captures", lambda w: 0))
    with pytest.raises(ValueError, match="core metric"):
        unregister_metric("coverage")


def test_registered_metric_reaches_store_csv_table_and_figure(
    tmp_path: Path, visited_metric: Metric,
) -> None:
    preset = tmp_path / "tiny.toml"
    preset.write_text(PRESET)
    out = tmp_path / "out"
    result = run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    assert result.finished == 8 and result.failed == 0
    write_report(out)

    with ResultStore(out / "results.sqlite", readonly=True) as store:
        stored = list(store.trials())
    assert all(isinstance(t["visited_nodes"], int) and t["visited_nodes"] > 0 for t in stored)
    assert all(t["extra_metrics"] == {} for t in stored)  # a real column, not an extra

    with (out / "trials.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [int(r["visited_nodes"]) for r in rows] == [t["visited_nodes"] for t in stored]
    assert list(rows[0])[-2:] == ["visited_nodes", "wall_time"]

    md = (out / "table.md").read_text()
    header = next(line for line in md.splitlines() if line.startswith("| GuardMode"))
    assert header.rstrip().endswith("| BacktrackCount | VisitedNodes |")
    assert "| VisitedNodes | fixed | distinct nodes any guard entered |" in (
        out / "README.md").read_text()

    # eight panels: none dropped (the old fixed 2 x 5 grid had room for seven)
    names = [c.name for c in table_columns()]
    assert len(names) == 8 and names[-1] == "VisitedNodes"
    shape = layout(table_columns())
    assert (shape.rows, shape.cols, shape.legend) == (3, 5, (0, 2))  # 2 capture, 6 fixed
    fig = aggregate_figure(table_rows(stored), "grid")
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert len(titles) == 8 and titles[-1] == "VisitedNodes (Fixed-time exp.)"
    assert (out / "aggregate_grid.png").stat().st_size > 10_000


def test_layout_has_a_cell_for_every_panel_and_the_legend() -> None:
    columns = table_columns()
    for extra in range(0, 9):
        cols = list(columns) + [c for i in range(extra) for c in Metric(
            f"m{i}", lambda w: 0, column=f"M{i}").table_columns()]
        shape = layout(cols)
        cells = list(shape.panels)
        legend = [(shape.legend[0], shape.legend[1] + k) for k in range(shape.legend_cols)]
        assert len(set(cells + legend)) == len(cells) + len(legend)  # nothing overlaps
        assert all(r < shape.rows and c < shape.cols for r, c in cells + legend)


def _row(seed: int, **extra: object) -> dict:
    spec = TrialSpec("maze", "grid", "cheat", "evade", "fixed", seed)
    return {**identity_row(spec),
            "metrics": {"captured": False, "capture_time": None, "captures": 0,
                        "coverage": 0.5, "avg_guard_player_dist": 2.0,
                        "first_detect_time": None, "backtracks": 1, **extra},
            "wall_time": 0.1}


def test_an_older_store_gains_new_metric_columns_and_resumes(tmp_path: Path) -> None:
    path = tmp_path / "results.sqlite"
    with ResultStore(path) as store:  # written before the metric existed
        store.add(_row(0))
    register_metric(VISITED)
    try:
        with ResultStore(path, readonly=True) as store:  # read-only: no column, no change
            (old,) = store.trials()
            assert old["visited_nodes"] is None
        columns = {r[1] for r in sqlite3.connect(path).execute("PRAGMA table_info(trials)")}
        assert "visited_nodes" not in columns
        with ResultStore(path) as store:  # resuming adds the column
            store.add(_row(1, visited_nodes=7))
            rows = {t["seed"]: t for t in store.trials()}
        assert rows[0]["visited_nodes"] is None and rows[1]["visited_nodes"] == 7
        assert rows[1]["extra_metrics"] == {}
    finally:
        unregister_metric(VISITED.name)
    with ResultStore(path) as store:  # without the metric the column is simply not read
        assert {t["seed"] for t in store.trials()} == {0, 1}
