"""Reports: files, Table 3 layout, numbers checked by hand, heatmaps and real PNGs."""

from __future__ import annotations

import csv
import math
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from game.trial import TrialSpec, identity_row
from headless.cli import main
from headless.analysis.report import (
    BOOTSTRAP_RESAMPLES,
    BOOTSTRAP_SEED,
    table_columns,
    write_report,
)
from headless.store import ResultStore
from headless.presets import load_preset
from headless.sweep import run_sweep
from navmesh.graph import graph_for
from navmesh.level import load_level

PRESET = """
levels = ["maze", "miami"]
abstractions = ["grid", "partition"]
guards = ["cheat", "random"]
players = ["evade"]
scenarios = ["capture", "fixed"]
seeds = 2

[set]
"world.duration" = 10.0
"""


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A real tiny sweep (32 short trials) with its report written through the CLI."""
    base = tmp_path_factory.mktemp("report")
    preset = base / "tiny.toml"
    preset.write_text(PRESET)
    out = base / "out"
    result = run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    assert result.finished == 32 and result.failed == 0
    assert main(["report", str(out)]) == 0
    return out


def read(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


# ------------------------------------------------------------------------- files
def test_report_writes_every_file(swept: Path) -> None:
    for name in ("trials.csv", "table.md", "table.csv", "README.md", "aggregate_grid.png",
                 "aggregate_partition.png", "aggregate_grid.svg", "aggregate_partition.svg"):
        assert (swept / name).is_file(), name
    for level in ("maze", "miami"):
        for abstraction in ("grid", "partition"):
            for kind in ("visit", "attack"):
                for mode in ("cheat", "random"):
                    name = f"{level}_{abstraction}_{mode}_{kind}.csv"
                    assert (swept / "heatmaps" / name).is_file(), name
                for suffix in ("png", "svg"):  # the modes side by side, one figure
                    name = f"{level}_{abstraction}_{kind}.{suffix}"
                    assert (swept / "heatmaps" / name).is_file(), name
    assert not list((swept / "heatmaps").glob("*_cheat_*.png"))
    assert (swept / "aggregate_grid.svg").read_text().lstrip().startswith("<?xml")
    assert not (swept / "failed.csv").exists()
    readme = (swept / "README.md").read_text()
    assert "32 of 32 trials finished" in readme
    assert "true fraction in [0, 1]" in readme and "above 1" in readme
    assert "aggregate_partition.png" in readme and "heatmaps/" in readme
    # it points only at what an installed wheel has: no docs/ files (the wheel ships none)
    assert "docs/" not in readme and "python -m pydoc headless.store" in readme


def test_trials_csv_has_one_row_per_trial_and_wall_time_last(swept: Path) -> None:
    rows = read(swept / "trials.csv")
    assert len(rows) == 32
    columns = list(rows[0])
    assert columns[:9] == ["key", "level", "abstraction", "guards", "player", "scenario",
                           "seed", "root_seed", "config_hash"]  # SPEC §10: a key column
    assert columns[-1] == "wall_time"
    assert [c for c in columns if "time" in c and c != "wall_time"] == [
        "capture_time", "first_detect_time"]
    assert {"captured", "captures", "coverage", "avg_guard_player_dist", "backtracks"} <= set(
        columns)
    assert {r["captured"] for r in rows} <= {"true", "false"}
    assert all(0.0 <= float(r["coverage"]) <= 1.0 for r in rows)


def test_table_has_the_paper_layout(swept: Path) -> None:
    rows = read(swept / "table.csv")
    assert [(r["abstraction"], r["GuardMode"], r["PlayerMode"]) for r in rows] == [
        ("grid", "Cheat", "Evade"), ("grid", "RandomWalk", "Evade"),
        ("partition", "Cheat", "Evade"), ("partition", "RandomWalk", "Evade")]
    for metric in table_columns():
        for part in ("n", "mean", "std", "ci_low", "ci_high"):
            assert f"{metric.name}_{part}" in rows[0]
    assert all(r["CaptureRate_n"] == "4" and r["CoverageRate_n"] == "4" for r in rows)
    md = (swept / "table.md").read_text()
    assert md.index("## Grid environment") < md.index("## Partition environment")
    header = next(line for line in md.splitlines() if line.startswith("| GuardMode"))
    assert [c.strip() for c in header.strip("|").split("|")] == [
        "GuardMode", "PlayerMode", "CaptureRate", "CaptureTime (s)", "CapturesInTime",
        "CoverageRate", "AvgGuard–PlayerDist", "FirstDetectTime (s)", "BacktrackCount"]
    assert "| Cheat | Evade | " in md and " ± " in md and "uncaptured" in md


def test_heatmap_csvs_match_the_store_and_the_level(swept: Path) -> None:
    with ResultStore(swept / "results.sqlite", readonly=True) as store:
        trials = list(store.trials(heatmaps=True))
    maze = load_level("maze")
    for abstraction in ("grid", "partition"):
        graph = graph_for(maze, abstraction)
        chosen = [t for t in trials if t["level"] == "maze" and t["abstraction"] == abstraction
                  and t["guards"] == "random"]
        assert len(chosen) == 4
        visits = np.sum([t["visits"] for t in chosen], axis=0)
        path = swept / "heatmaps" / f"maze_{abstraction}_random_visit.csv"
        if abstraction == "grid":
            with path.open(newline="") as handle:
                grid = list(csv.reader(handle))
            assert len(grid) == maze.rows and all(len(r) == maze.cols for r in grid)
            blank = np.array([[cell == "" for cell in r] for r in grid])
            assert np.array_equal(blank, ~maze.occupancy)
            for node, (r, c) in enumerate(graph.node_cell):
                assert float(grid[r][c]) == visits[node]
        else:
            rows = read(path)
            assert len(rows) == len(graph.mesh.triangles) == graph.n
            assert [float(r["value"]) for r in rows] == visits.tolist()
            assert float(rows[0]["x"]) == pytest.approx(graph.positions[0][0], abs=1e-4)


def test_pngs_are_real_non_blank_images(swept: Path) -> None:
    from matplotlib.image import imread

    pngs = [swept / "aggregate_grid.png", swept / "aggregate_partition.png",
            swept / "heatmaps" / "miami_grid_visit.png",
            swept / "heatmaps" / "miami_partition_attack.png",
            swept / "heatmaps" / "maze_partition_visit.png"]
    for path in pngs:
        image = imread(path)
        assert image.ndim == 3 and image.shape[0] >= 300 and image.shape[1] >= 400, path
        rgb = image[..., :3].reshape(-1, 3)
        assert rgb.std() > 0.05, path
        packed = (rgb * 255).astype(np.int64) @ np.array([65536, 256, 1])
        assert len(np.unique(packed)) > 20, path  # colour bar, data, text


# ------------------------------------------------------------------------- numbers
def _bootstrap(values: list[float], label: str) -> tuple[float, float]:
    """The documented procedure, written out again."""
    seq = np.random.SeedSequence([BOOTSTRAP_SEED, zlib.crc32(label.encode())])
    rng = np.random.Generator(np.random.PCG64(seq))
    x = np.array(values)
    means = np.array([x[row].mean() for row in
                      rng.integers(0, len(x), size=(BOOTSTRAP_RESAMPLES, len(x)))])
    return float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


def _hand_stats(values: list[float]) -> tuple[float, float]:
    mean = sum(values) / len(values)
    std = math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
    return mean, std


def _add(store: ResultStore, n_nodes: int, guards: str, scenario: str, seed: int,
         **metrics: Any) -> None:
    spec = TrialSpec("maze", "grid", guards, "maxmin", scenario, seed)
    store.add({
        **identity_row(spec), "config_hash": "x", "wall_time": 0.5,
        "metrics": {"captured": False, "capture_time": None, "captures": 0, "coverage": 0.0,
                    "avg_guard_player_dist": None, "first_detect_time": None, "backtracks": 0,
                    **metrics},
        "visits": [seed] * n_nodes, "attacks": [0.0] * n_nodes,
    })


def test_table_numbers_match_a_hand_computation(tmp_path: Path) -> None:
    n_nodes = graph_for(load_level("maze"), "grid").n
    with ResultStore(tmp_path / "results.sqlite") as store:
        capture = [(True, 12.5), (False, None), (True, 30.0), (True, 7.25), (False, None)]
        for seed, (captured, time) in enumerate(capture):
            _add(store, n_nodes, "pf", "capture", seed, captured=captured, capture_time=time,
                 captures=int(captured))
        fixed = [(3, 0.5, 10.0, None, 4), (0, 0.75, 12.5, 20.0, 2), (7, 0.625, None, 5.5, 9)]
        for seed, (captures, coverage, dist, detect, back) in enumerate(fixed):
            _add(store, n_nodes, "pf", "fixed", seed, captures=captures, coverage=coverage,
                 avg_guard_player_dist=dist, first_detect_time=detect, backtracks=back)
        _add(store, n_nodes, "cheat", "capture", 0, captured=True, capture_time=4.0)
        store.set_meta({"design": '{"abstractions": ["grid"]}', "total_trials": "9"})
    write_report(tmp_path, figures=False)

    rows = {r["guards"]: r for r in read(tmp_path / "table.csv")}
    assert list(rows) == ["cheat", "pf"]  # Cheat before PotentialField, as in the paper
    expected = {
        "CaptureRate": [1.0, 0.0, 1.0, 1.0, 0.0],
        "CaptureTime": [12.5, 60.0, 30.0, 7.25, 60.0],  # uncaptured = the full 60 s
        "CapturesInTime": [3.0, 0.0, 7.0],
        "CoverageRate": [0.5, 0.75, 0.625],
        "AvgGuardPlayerDist": [10.0, 12.5],  # a missing distance is left out
        "FirstDetectTime": [60.0, 20.0, 5.5],  # no detection = the full 60 s
        "BacktrackCount": [4.0, 2.0, 9.0],
    }
    pf = rows["pf"]
    for name, values in expected.items():
        mean, std = _hand_stats(values)
        low, high = _bootstrap(values, f"grid/pf/maxmin/{name}")
        assert int(pf[f"{name}_n"]) == len(values), name
        assert float(pf[f"{name}_mean"]) == pytest.approx(mean, rel=1e-12), name
        assert float(pf[f"{name}_std"]) == pytest.approx(std, rel=1e-12), name
        assert float(pf[f"{name}_ci_low"]) == pytest.approx(low, rel=1e-12), name
        assert float(pf[f"{name}_ci_high"]) == pytest.approx(high, rel=1e-12), name
        assert min(values) <= low <= mean <= high <= max(values), name
    assert pf["CaptureTime_mean"] == repr(169.75 / 5)

    cheat = rows["cheat"]  # one capture trial, no fixed-time trials
    assert cheat["CaptureRate_n"] == "1" and float(cheat["CaptureTime_mean"]) == 4.0
    assert cheat["CaptureTime_std"] == "" and float(cheat["CaptureTime_ci_low"]) == 4.0
    assert cheat["CoverageRate_n"] == "0" and cheat["CoverageRate_mean"] == ""

    md = (tmp_path / "table.md").read_text()
    mean, std = _hand_stats(expected["CaptureTime"])
    low, high = _bootstrap(expected["CaptureTime"], "grid/pf/maxmin/CaptureTime")
    assert f"{mean:.2f} ± {std:.2f} [{low:.2f}, {high:.2f}]" in md
    assert "| Cheat | MaxMin | 1.00 ± – [1.00, 1.00] | 4.00 ± – [4.00, 4.00] | – |" in md

    heat = tmp_path / "heatmaps" / "maze_grid_pf_visit.csv"
    with heat.open(newline="") as handle:
        values = {cell for row in csv.reader(handle) for cell in row}
    assert values == {"", str(sum(range(5)) + sum(range(3)))}  # seeds summed per node


def test_failed_trials_are_listed(tmp_path: Path) -> None:
    n_nodes = graph_for(load_level("maze"), "grid").n
    with ResultStore(tmp_path / "results.sqlite") as store:
        _add(store, n_nodes, "pf", "capture", 0, captured=True, capture_time=3.0)
        store.add({**identity_row(TrialSpec("maze", "grid", "pf", "maxmin", "fixed", 1), key="k"),
                   "error": "RuntimeError: boom\nTraceback ..."})
    write_report(tmp_path, figures=False)
    (failed,) = read(tmp_path / "failed.csv")
    assert failed["key"] == "k" and failed["error"].startswith("RuntimeError: boom")
    assert "1 failed" in (tmp_path / "README.md").read_text()


def test_report_errors_are_one_line_exit_2(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["report", str(tmp_path / "nowhere")]) == 2
    assert main(["report", str(tmp_path)]) == 2
    ResultStore(tmp_path / "results.sqlite").close()
    assert main(["report", str(tmp_path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and all(line.startswith("stealth: error: ") for line in lines)
    assert "no such results directory" in lines[0] and "no results.sqlite" in lines[1]
    assert "no finished trials" in lines[2]


# ------------------------------------------------------------------------- comparable figures
def test_report_shows_progress_on_stderr(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    n_nodes = graph_for(load_level("maze"), "grid").n
    with ResultStore(tmp_path / "results.sqlite") as store:
        _add(store, n_nodes, "pf", "capture", 0, captured=True, capture_time=3.0)
    assert main(["report", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "3/3 100%" in err and "figures/s" in err  # 2 heatmap figures + 1 aggregate


def test_a_mode_keeps_its_colour_whatever_the_report_holds() -> None:
    from matplotlib.colors import to_hex

    from headless.analysis.figures import aggregate_figure
    from headless.analysis.palette import guard_colour
    from headless.analysis.stats import Stat

    def rows(modes: list[str]) -> list[dict[str, Any]]:
        stat = Stat(4, 1.0, 0.1, 0.9, 1.1)
        return [{"abstraction": "grid", "guards": m, "player": "maxmin",
                 "stats": {c.name: stat for c in table_columns()}} for m in modes]

    def bar_colours(modes: list[str]) -> dict[str, str]:
        ax = aggregate_figure(rows(modes), "grid").axes[0]
        return {m: to_hex(bar.get_facecolor()) for m, bar in zip(modes, ax.patches)}

    one, other = bar_colours(["pf", "cheat"]), bar_colours(["cheat", "random", "pf"])
    assert one["pf"] == other["pf"] == guard_colour("pf")
    assert one["cheat"] == other["cheat"] == guard_colour("cheat") != guard_colour("pf")
    assert len({guard_colour(m) for m in ("pf", "random", "fsm", "staleness", "cheat")}) == 5


def _panels(values: dict[str, np.ndarray]) -> Any:
    from headless.analysis.heatmaps import Panel, heatmap_panels

    level = load_level("maze")
    graph = graph_for(level, "grid")
    panels = [Panel(mode, np.resize(v, graph.n).astype(float), 3) for mode, v in values.items()]
    return heatmap_panels(level, graph, panels, "visit", "grid")


def test_heatmap_panels_share_one_scale_log_when_counts_span_decades() -> None:
    from matplotlib.colors import LogNorm

    fig = _panels({"pf": np.array([1.0, 5.0, 0.0]), "cheat": np.array([3000.0, 0.0])})
    norms = [ax.images[0].norm for ax in fig.axes if ax.images]
    assert len(norms) == 2 and all(n is norms[0] for n in norms)
    assert isinstance(norms[0], LogNorm) and (norms[0].vmin, norms[0].vmax) == (1.0, 3000.0)
    titles = [ax.get_title() for ax in fig.axes if ax.images]
    assert titles == ["PotentialField (3 trials)", "Cheat (3 trials)"]  # registry order
    fig = _panels({"pf": np.array([1.0, 5.0]), "cheat": np.array([2.0, 0.0])})
    norm = fig.axes[0].images[0].norm
    assert not isinstance(norm, LogNorm) and (norm.vmin, norm.vmax) == (0.0, 5.0)


def test_no_events_are_drawn_as_such() -> None:
    from matplotlib.colors import to_hex

    from headless.analysis.heatmaps import NO_EVENTS

    fig = _panels({"pf": np.array([0.0]), "random": np.array([2.0, 0.0])})
    empty, some = (ax for ax in fig.axes if ax.images)
    assert "no events" in [t.get_text() for t in empty.texts]
    assert "no events" not in [t.get_text() for t in some.texts]
    image = some.images[0]
    rgba = image.cmap(image.norm(image.get_array()))  # every drawn node's colour
    level = load_level("maze")
    walkable = level.occupancy
    zero_cells = rgba[walkable][1::2]  # the resized values alternate 2, 0 along the nodes
    assert {to_hex(c) for c in zero_cells} == {to_hex(NO_EVENTS)}
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["no events (0)", "wall"]


def test_the_paper_values_are_overlaid_only_on_the_papers_design() -> None:
    from headless.analysis.figures import aggregate_figure
    from headless.analysis.paper import is_paper_design, paper_table3
    from headless.analysis.stats import Stat

    stat = Stat(4, 0.5, 0.1, 0.4, 0.6)
    rows = [{"abstraction": "grid", "guards": m, "player": p,
             "stats": {c.name: stat for c in table_columns()}}
            for m in ("pf", "cheat") for p in ("maxmin", "safetygraph")]
    paper = paper_table3()
    fig = aggregate_figure(rows, "grid", paper)
    (markers,) = [line for line in fig.axes[0].lines if line.get_marker() == "D"]
    assert list(markers.get_ydata()) == [0.80, 0.80, 0.95, 0.95]  # CaptureRate: PF, Cheat
    assert not [line for line in aggregate_figure(rows, "grid").axes[0].lines
                if line.get_marker() == "D"]
    design = {"level_names": ["arkham", "dishonored", "maze", "miami", "tlou"],
              "abstractions": ["grid", "partition"], "guards": ["pf", "cheat"],
              "players": ["maxmin"]}
    assert is_paper_design(design)
    assert not is_paper_design({**design, "level_names": ["maze", "miami"]})
    assert not is_paper_design({**design, "players": ["evade"]})
    assert not is_paper_design({**design, "stimuli": ["x.py:Y"]})
