"""Reports of a results directory (``stealth report DIR``): the paper's Table 3, heatmaps,
the aggregate figure, a flat CSV of every trial and a README.

Everything is written into DIR next to ``results.sqlite``:

* ``trials.csv`` — one row per finished trial (identity, seed, config hash, every metric,
  ``wall_time`` last);
* ``table.md`` / ``table.csv`` — paper Table 3: per abstraction, guard mode and player
  policy, mean ± std and a 95 % bootstrap confidence interval of the mean of each metric;
* ``heatmaps/{level}_{abstraction}_{mode}_{visit,attack}.{csv,png}`` — summed per-node
  visit and attack counts;
* ``aggregate_{abstraction}.png`` — the paper's "Aggregated performance" bar figure;
* ``failed.csv`` — only when some trial failed;
* ``README.md`` — what the files are and where our metrics differ from the paper's.

matplotlib is imported only here, lazily, and drawn through ``Figure`` + the Agg canvas
(no pyplot, no global backend switch), so reports work on headless machines and from a
notebook alike.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import zlib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import UserError
from .store import IDENTITY, METRIC_NAMES, STORE_NAME, ResultStore

__all__ = [
    "BOOTSTRAP_RESAMPLES",
    "BOOTSTRAP_SEED",
    "TABLE_METRICS",
    "Stat",
    "TableMetric",
    "bootstrap_ci",
    "cmd_report",
    "summarise",
    "table_rows",
    "write_report",
    "write_trials_csv",
]

BOOTSTRAP_RESAMPLES = 2000
"""Resamples of the percentile bootstrap of the mean."""

BOOTSTRAP_SEED = 20240917
"""Root of every bootstrap generator: ``SeedSequence([BOOTSTRAP_SEED, crc32(label)])``."""

GUARD_NAMES = {"cheat": "Cheat", "fsm": "FSM", "pf": "PotentialField", "random": "RandomWalk",
               "staleness": "Staleness"}
GUARD_SHORT = {"cheat": "C", "fsm": "FSM", "pf": "PF", "random": "RW", "staleness": "S"}
PLAYER_NAMES = {"maxmin": "MaxMin", "safetygraph": "SafetyGraph", "evade": "Evade"}
PLAYER_SHORT = {"maxmin": "MM", "safetygraph": "SG", "evade": "EV"}
ABSTRACTION_NAMES = {"grid": "Grid", "partition": "Partition"}


@dataclass(frozen=True)
class TableMetric:
    """One column of Table 3: where its values come from and how missing values count."""

    name: str           # column name (CSV-safe)
    title: str          # column title in Markdown and figures
    scenario: str       # trials it is computed from
    metric: str         # metric of the trial row
    censor: bool = False  # a missing time counts as the trial's full duration
    unit: str = ""


TABLE_METRICS: tuple[TableMetric, ...] = (
    TableMetric("CaptureRate", "CaptureRate", "capture", "captured"),
    TableMetric("CaptureTime", "CaptureTime", "capture", "capture_time", censor=True, unit="s"),
    TableMetric("CapturesInTime", "CapturesInTime", "fixed", "captures"),
    TableMetric("CoverageRate", "CoverageRate", "fixed", "coverage"),
    TableMetric("AvgGuardPlayerDist", "AvgGuard–PlayerDist", "fixed", "avg_guard_player_dist",
                unit="world units"),
    TableMetric("FirstDetectTime", "FirstDetectTime", "fixed", "first_detect_time", censor=True,
                unit="s"),
    TableMetric("BacktrackCount", "BacktrackCount", "fixed", "backtracks"),
)


# =========================================================================== statistics
@dataclass(frozen=True)
class Stat:
    """Summary of one table cell: n, mean, sample std (ddof=1) and the 95 % CI of the mean."""

    n: int
    mean: float
    std: float
    ci_low: float
    ci_high: float


def bootstrap_ci(values: Sequence[float] | np.ndarray, label: str,
                 resamples: int = BOOTSTRAP_RESAMPLES, level: float = 0.95) -> tuple[float, float]:
    """Percentile bootstrap confidence interval of the mean.

    The generator is ``PCG64(SeedSequence([BOOTSTRAP_SEED, zlib.crc32(label)]))`` and the
    resample indices are drawn as one ``integers(0, n, size=(resamples, n))`` matrix, so the
    interval of a table cell depends only on its own values and label.

    >>> bootstrap_ci([2.0, 2.0, 2.0], "x")
    (2.0, 2.0)
    """
    x = np.asarray(values, dtype=np.float64)
    n = len(x)
    if n == 0:
        return (math.nan, math.nan)
    rng = np.random.Generator(np.random.PCG64(
        np.random.SeedSequence([BOOTSTRAP_SEED, zlib.crc32(label.encode("utf-8"))])))
    means = x[rng.integers(0, n, size=(resamples, n))].mean(axis=1)
    tail = 100 * (1 - level) / 2
    low, high = np.percentile(means, [tail, 100 - tail])
    return (float(low), float(high))


def summarise(values: Sequence[float] | np.ndarray, label: str) -> Stat:
    """:class:`Stat` of a list of numbers (NaN/None-free); n = 0 gives NaNs."""
    x = np.asarray(values, dtype=np.float64)
    if len(x) == 0:
        return Stat(0, math.nan, math.nan, math.nan, math.nan)
    std = float(x.std(ddof=1)) if len(x) > 1 else math.nan
    low, high = bootstrap_ci(x, label)
    return Stat(len(x), float(x.mean()), std, low, high)


# =========================================================================== loading
def _order(names: Iterable[str], display: Mapping[str, str]) -> list[str]:
    """Names sorted by display name (the paper's tables are alphabetical)."""
    return sorted(set(names), key=lambda n: (display.get(n, n.title()).lower(), n))


def _label(table: Mapping[str, str], name: str) -> str:
    return table.get(name, name.title())


class _Durations:
    """Trial duration (``world.duration``) of an overrides mapping, cached."""

    def __init__(self) -> None:
        self.cache: dict[str, float] = {}

    def __call__(self, overrides: Mapping[str, Any]) -> float:
        key = json.dumps(overrides, sort_keys=True)
        if key not in self.cache:
            from game.config import Config

            self.cache[key] = float(Config.load(dict(overrides))["world.duration"])
        return self.cache[key]


def metric_value(trial: Mapping[str, Any], metric: TableMetric,
                 duration: float) -> float | None:
    """The number a trial contributes to a Table 3 column (None: it contributes nothing).

    ``captured`` counts as 1/0; a censored time that did not happen (no capture, no
    detection) counts as the trial's full duration, as in the paper.
    """
    value = trial.get(metric.metric)
    if value is None:
        return duration if metric.censor else None
    value = float(value)
    return value if math.isfinite(value) else None


def table_rows(trials: Sequence[Mapping[str, Any]], abstractions: Sequence[str] | None = None,
               ) -> list[dict[str, Any]]:
    """Table 3 as a list of rows ``{abstraction, guards, player, stats: {metric: Stat}}``."""
    durations = _Durations()
    groups: dict[tuple[str, str, str], dict[str, list[float]]] = {}
    for trial in trials:
        key = (trial["abstraction"], trial["guards"], trial["player"])
        cell = groups.setdefault(key, {m.name: [] for m in TABLE_METRICS})
        for metric in TABLE_METRICS:
            if trial["scenario"] != metric.scenario:
                continue
            value = metric_value(trial, metric, durations(trial["overrides"]))
            if value is not None:
                cell[metric.name].append(value)
    present = {a for a, _, _ in groups}
    order = [a for a in (abstractions or []) if a in present]
    order += sorted(present - set(order))
    guards = _order((g for _, g, _ in groups), GUARD_NAMES)
    players = _order((p for _, _, p in groups), PLAYER_NAMES)
    rows = []
    for abstraction in order:
        for guard in guards:
            for player in players:
                found = groups.get((abstraction, guard, player))
                if found is None:
                    continue
                stats = {name: summarise(values, f"{abstraction}/{guard}/{player}/{name}")
                         for name, values in found.items()}
                rows.append({"abstraction": abstraction, "guards": guard, "player": player,
                             "stats": stats})
    return rows


# =========================================================================== files
def _csv_value(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return str(value)


def write_trials_csv(trials: Sequence[Mapping[str, Any]], path: Path) -> None:
    """``trials.csv``: identity, seed, config hash, every metric, ``wall_time`` last."""
    extras = sorted({k for t in trials for k in t.get("extra_metrics", {})})
    columns = [*IDENTITY, "config_hash", *METRIC_NAMES, *extras, "wall_time"]
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for t in trials:
            merged = {**t, **t.get("extra_metrics", {})}
            writer.writerow([_csv_value(merged.get(c)) for c in columns])


def _fmt(x: float, digits: int = 2) -> str:
    return "–" if math.isnan(x) else f"{x:.{digits}f}"


def _cell(stat: Stat) -> str:
    if stat.n == 0:
        return "–"
    return f"{_fmt(stat.mean)} ± {_fmt(stat.std)} [{_fmt(stat.ci_low)}, {_fmt(stat.ci_high)}]"


def write_table(rows: Sequence[Mapping[str, Any]], directory: Path, trials_total: int) -> None:
    """``table.csv`` (every number) and ``table.md`` (the paper's layout) from :func:`table_rows`."""
    with (directory / "table.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        header = ["abstraction", "guards", "player", "GuardMode", "PlayerMode"]
        for m in TABLE_METRICS:
            header += [f"{m.name}_{part}" for part in ("n", "mean", "std", "ci_low", "ci_high")]
        writer.writerow(header)
        for row in rows:
            line = [row["abstraction"], row["guards"], row["player"],
                    _label(GUARD_NAMES, row["guards"]), _label(PLAYER_NAMES, row["player"])]
            for m in TABLE_METRICS:
                s = row["stats"][m.name]
                line += [str(s.n), *(_csv_value(v) for v in (s.mean, s.std, s.ci_low, s.ci_high))]
            writer.writerow(line)

    lines = [
        "# Table 3 — capture and fixed-time metrics",
        "",
        f"From {trials_total} finished trials, pooled over levels and seeds. Every cell is "
        "mean ± sample std [95 % bootstrap CI of the mean]. CaptureRate and CaptureTime come "
        "from capture-scenario trials, the other columns from fixed-time trials. CaptureTime "
        "counts an uncaptured trial as its full duration (60 s by default) and FirstDetectTime "
        "a trial without a detection likewise, as the paper's numbers do. CoverageRate is a "
        "true fraction in [0, 1] (the paper's partition coverage exceeds 1). See README.md.",
        "",
    ]
    titles = [m.title + (f" ({m.unit})" if m.unit == "s" else "") for m in TABLE_METRICS]
    for abstraction in dict.fromkeys(r["abstraction"] for r in rows):
        lines += [f"## {_label(ABSTRACTION_NAMES, abstraction)} environment", "",
                  "| GuardMode | PlayerMode | " + " | ".join(titles) + " |",
                  "|---|---|" + "---:|" * len(titles)]
        for row in rows:
            if row["abstraction"] != abstraction:
                continue
            cells = [_cell(row["stats"][m.name]) for m in TABLE_METRICS]
            lines.append(f"| {_label(GUARD_NAMES, row['guards'])} | "
                         f"{_label(PLAYER_NAMES, row['player'])} | " + " | ".join(cells) + " |")
        counts = sorted({(row["stats"]["CaptureRate"].n, row["stats"]["CoverageRate"].n)
                         for row in rows if row["abstraction"] == abstraction})
        text = ", ".join(f"{c} capture / {f} fixed-time" for c, f in counts)
        lines += ["", f"Trials per row: {text}.", ""]
    (directory / "table.md").write_text("\n".join(lines), encoding="utf-8")


# =========================================================================== heatmaps
@dataclass
class _HeatSum:
    visits: np.ndarray
    attacks: np.ndarray
    trials: int = 0
    level_ref: str = ""


@dataclass
class _Report:
    """Everything gathered in one pass over the store."""

    trials: list[dict[str, Any]] = field(default_factory=list)
    heat: dict[tuple[str, str, str], _HeatSum] = field(default_factory=dict)
    skipped_heat: int = 0


def _gather(store: ResultStore) -> _Report:
    report = _Report()
    for trial in store.trials(heatmaps=True):
        visits, attacks = trial.pop("visits"), trial.pop("attacks")
        report.trials.append(dict(trial))
        if visits is None or attacks is None:
            report.skipped_heat += 1
            continue
        key = (trial["level"], trial["abstraction"], trial["guards"])
        v, a = np.asarray(visits, dtype=np.float64), np.asarray(attacks, dtype=np.float64)
        heat = report.heat.get(key)
        if heat is None:
            heat = report.heat[key] = _HeatSum(np.zeros_like(v), np.zeros_like(a),
                                               level_ref=trial["level_ref"])
        if heat.visits.shape != v.shape or heat.attacks.shape != a.shape:
            report.skipped_heat += 1  # the level changed between trials: keep the first shape
            continue
        heat.visits += v
        heat.attacks += a
        heat.trials += 1
    return report


def _heat_value(x: float) -> str:
    if math.isnan(x):
        return ""
    return str(int(x)) if float(x).is_integer() else f"{x:.6g}"


def _write_heatmap_csv(path: Path, graph: Any, values: np.ndarray, rows: int, cols: int) -> np.ndarray | None:
    """Grid: the rows x cols matrix (blank = wall); partition: one row per triangle."""
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        if graph.kind == "grid":
            grid = np.full((rows, cols), np.nan)
            grid[graph.node_cell[:, 0], graph.node_cell[:, 1]] = values
            writer.writerows([[_heat_value(x) for x in line] for line in grid])
            return grid
        writer.writerow(["triangle", "x", "y", "value"])
        for i, ((x, y), v) in enumerate(zip(graph.positions, values)):
            writer.writerow([i, f"{x:.6g}", f"{y:.6g}", _heat_value(v)])
        return None


WALL_COLOUR = "#3b3b3b"


def _heatmap_png(path: Path, level: Any, graph: Any, values: np.ndarray, grid: np.ndarray | None,
                 title: str, label: str, cmap_name: str) -> None:
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    width, height = level.cols * level.cell_size, level.rows * level.cell_size
    aspect = height / width if width else 1.0
    fig = Figure(figsize=(7.0, max(3.4, min(9.5, 5.6 * aspect + 1.4))), dpi=110)
    ax = fig.add_subplot()
    cmap = colormaps[cmap_name].with_extremes(bad=WALL_COLOUR)
    top = float(np.nanmax(values)) if len(values) else 0.0
    norm = Normalize(vmin=0.0, vmax=top if top > 0 else 1.0)
    image: Any
    if grid is not None:
        image = ax.imshow(np.ma.masked_invalid(grid), cmap=cmap, norm=norm, origin="upper",
                          extent=(0, width, height, 0), interpolation="nearest")
    else:
        mesh = graph.mesh
        ax.set_facecolor(WALL_COLOUR)
        image = ax.tripcolor(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.triangles,
                             facecolors=values, cmap=cmap, norm=norm, edgecolors="face",
                             linewidth=0.2)
    ax.add_collection(LineCollection(level.walls, colors="black", linewidths=0.8))
    ax.set_xlim(0, width)
    ax.set_ylim(height, 0)  # y down, as in the level files
    ax.set_aspect("equal")
    ax.set_xlabel("x (world units)")
    ax.set_ylabel("y (world units)")
    ax.set_title(title, fontsize=10)
    bar = fig.colorbar(image, ax=ax, fraction=0.046 * min(max(aspect, 0.45), 2.0), pad=0.03)
    bar.set_label(label, fontsize=9)
    fig.savefig(path, bbox_inches="tight", pad_inches=0.15)


def write_heatmaps(report: _Report, directory: Path, figures: bool = True) -> list[Path]:
    """Heatmap CSVs (and PNGs) per level x abstraction x guard mode; returns the files."""
    from navmesh.graph import graph_for
    from navmesh.level import load_level

    out = directory / "heatmaps"
    out.mkdir(exist_ok=True)
    written: list[Path] = []
    levels: dict[str, Any] = {}
    for (level_name, abstraction, mode), heat in sorted(report.heat.items()):
        if level_name not in levels:
            levels[level_name] = load_level(heat.level_ref)
        level = levels[level_name]
        graph = graph_for(level, abstraction)
        if graph.n != len(heat.visits):
            print(f"stealth: warning: {level_name} {abstraction}: the level has {graph.n} nodes "
                  f"now but the trials have {len(heat.visits)}; heatmap skipped", file=sys.stderr)
            continue
        mode_name = _label(GUARD_NAMES, mode)
        for kind, values, label, cmap in (
            ("visit", heat.visits, "guard visits (sum)", "viridis"),
            ("attack", heat.attacks, "attack: HP lost (sum)", "inferno"),
        ):
            stem = f"{level_name}_{abstraction}_{mode}_{kind}"
            csv_path = out / f"{stem}.csv"
            grid = _write_heatmap_csv(csv_path, graph, values, level.rows, level.cols)
            written.append(csv_path)
            if figures:
                title = (f"{level_name} — {_label(ABSTRACTION_NAMES, abstraction)} — {mode_name}: "
                         f"{kind} heatmap\n(sum over {heat.trials} trials, all player policies "
                         "and scenarios)")
                png = out / f"{stem}.png"
                _heatmap_png(png, level, graph, values, grid, title, label, cmap)
                written.append(png)
    return written


# =========================================================================== aggregate figure
def write_aggregate(rows: Sequence[Mapping[str, Any]], directory: Path) -> list[Path]:
    """``aggregate_{abstraction}.png``: bars per guard mode x policy for every Table 3 metric."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure

    written = []
    palette = colormaps["tab10"]
    for abstraction in dict.fromkeys(r["abstraction"] for r in rows):
        cells = [r for r in rows if r["abstraction"] == abstraction]
        modes = list(dict.fromkeys(r["guards"] for r in cells))
        players = list(dict.fromkeys(r["player"] for r in cells))
        fig = Figure(figsize=(18, 7.5), dpi=100)
        grid = fig.add_gridspec(2, 5)
        # Top row: the capture experiment (and the legend); bottom row: the fixed-time one.
        panels = [fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])]
        panels += [fig.add_subplot(grid[1, i]) for i in range(5)]
        legend_ax = fig.add_subplot(grid[0, 2:])
        x = np.arange(len(cells))
        labels = [f"{GUARD_SHORT.get(r['guards'], r['guards'])}-"
                  f"{PLAYER_SHORT.get(r['player'], r['player'])}" for r in cells]
        colours = [palette(modes.index(r["guards"]) % 10) for r in cells]
        hatches = ["" if players.index(r["player"]) == 0 else "//" for r in cells]
        for ax, metric in zip(panels, TABLE_METRICS):
            stats = [r["stats"][metric.name] for r in cells]
            means = np.array([s.mean for s in stats])
            low = np.array([s.mean - s.ci_low for s in stats])
            high = np.array([s.ci_high - s.mean for s in stats])
            heights = np.nan_to_num(means)
            bars = ax.bar(x, heights, color=colours, edgecolor="black", linewidth=0.5,
                          yerr=np.nan_to_num(np.vstack([low, high])), capsize=3,
                          error_kw={"elinewidth": 0.8})
            for bar, hatch in zip(bars, hatches):
                bar.set_hatch(hatch)
            if np.all(np.isnan(means)):
                ax.text(0.5, 0.5, f"no {metric.scenario}-scenario trials", ha="center",
                        va="center", transform=ax.transAxes, color="grey")
            exp = "Capture exp." if metric.scenario == "capture" else "Fixed-time exp."
            ax.set_title(f"{metric.title} ({exp})", fontsize=10)
            ax.set_ylabel(metric.unit or ("fraction" if metric.name in ("CaptureRate",
                                                                        "CoverageRate")
                                          else "count"))
            ax.set_xticks(x, labels, rotation=60, fontsize=8)
            ax.grid(axis="y", alpha=0.3)
        legend_ax.axis("off")
        lines = [f"{GUARD_SHORT.get(m, m)} = {_label(GUARD_NAMES, m)}" for m in modes]
        lines += [f"{PLAYER_SHORT.get(p, p)} = {_label(PLAYER_NAMES, p)}"
                  + (" (plain bars)" if i == 0 else " (hatched bars)")
                  for i, p in enumerate(players)]
        lines += ["", "bar: mean over levels and seeds", "whiskers: 95 % bootstrap CI",
                  "of the mean", "uncaptured / undetected trials",
                  "count as the full duration"]
        legend_ax.text(0.0, 1.0, "\n".join(lines), va="top", fontsize=9, family="monospace")
        fig.suptitle(f"Aggregated performance — {_label(ABSTRACTION_NAMES, abstraction)} "
                     "environment (all levels and player policies)", fontsize=13)
        fig.tight_layout(rect=(0, 0, 1, 0.96))
        path = directory / f"aggregate_{abstraction}.png"
        fig.savefig(path)
        written.append(path)
    return written


# =========================================================================== README
def _readme(directory: Path, meta: Mapping[str, str], report: _Report, failed: int,
            files: Sequence[Path]) -> str:
    design = json.loads(meta.get("design", "{}"))
    total = meta.get("total_trials", "?")
    done = len(report.trials)
    names = sorted(str(p.relative_to(directory)) for p in files)
    heat = [n for n in names if n.startswith("heatmaps/")]
    lines = [
        f"# Results: preset `{meta.get('preset_name', '?')}`",
        "",
        f"{done} of {total} trials finished" + (f", {failed} failed" if failed else "")
        + f" (config hash `{meta.get('config_hash', '?')}`). Levels: "
        f"{', '.join(design.get('level_names', []))}; abstractions: "
        f"{', '.join(design.get('abstractions', []))}; guard modes: "
        f"{', '.join(design.get('guards', []))}; player policies: "
        f"{', '.join(design.get('players', []))}; scenarios: "
        f"{', '.join(design.get('scenarios', []))}; {len(design.get('seeds', []))} seeds; "
        f"root seed {design.get('root_seed', 0)}; overrides: "
        f"{json.dumps(design.get('set', {})) if design.get('set') else 'none'}.",
        "",
        "Regenerate with `stealth report " + str(directory) + "`; an unfinished sweep is resumed "
        "by running the same `stealth run` command again (finished trials are skipped).",
        "",
        "## Files",
        "",
        "| file | contents |",
        "|---|---|",
        f"| `{STORE_NAME}` | the store: one row per trial (SQLite; see docs/experiments.md) |",
        "| `trials.csv` | one row per finished trial: identity, seed, config hash, every "
        "metric, `wall_time` (s) last |",
        "| `table.md`, `table.csv` | paper Table 3: mean ± std and 95 % bootstrap CI per "
        "abstraction × guard mode × player policy (`table.csv` also has n per cell) |",
    ]
    for name in names:
        if name.startswith("aggregate_"):
            lines.append(f"| `{name}` | the paper's *Aggregated performance* figure: bars "
                         "(mean) with 95 % bootstrap CI whiskers per guard mode × policy |")
    if heat:
        lines.append(f"| `heatmaps/` ({len(heat)} files) | `{{level}}_{{abstraction}}_{{mode}}_"
                     "{visit,attack}.csv/.png`: per-node counts summed over every trial of "
                     "that level, abstraction and guard mode (all player policies, scenarios "
                     "and seeds). Grid CSV: rows × cols matrix, blank = wall. Partition CSV: "
                     "`triangle,x,y,value` per navmesh triangle (centroid). |")
    if failed:
        lines.append("| `failed.csv` | trials that raised: identity and the error text |")
    lines += [
        "",
        "## Metrics",
        "",
        "| column | trials | definition |",
        "|---|---|---|",
        "| CaptureRate | capture | fraction of trials in which the player lost all HP |",
        "| CaptureTime | capture | time of the capture (s); **an uncaptured trial counts as "
        "its full duration (60 s)**, which is what the paper's numbers imply (RandomWalk: "
        "58.18 s at rate 0.04) |",
        "| CapturesInTime | fixed | captures in 60 s (the player respawns after each) |",
        "| CoverageRate | fixed | fraction of walkable nodes (cells or triangles) any guard "
        "entered, in [0, 1] |",
        "| AvgGuard–PlayerDist | fixed | mean over physics steps of the shortest-path distance "
        "(world units) from the player's node to the closest guard's node |",
        "| FirstDetectTime | fixed | time of the first sighting (s); **a trial without one "
        "counts as its full duration** (the paper's RandomWalk 46 ± 23 s implies the same) |",
        "| BacktrackCount | fixed | guard moves to a node among that guard's last 5 nodes |",
        "",
        "Each cell: mean ± sample standard deviation (ddof = 1) [95 % percentile-bootstrap "
        f"confidence interval of the mean, {BOOTSTRAP_RESAMPLES} resamples, generator "
        f"`PCG64(SeedSequence([{BOOTSTRAP_SEED}, crc32(label)]))`, label = "
        "`abstraction/guards/player/column`]. Levels and seeds are pooled, as in the paper.",
        "",
        "Heatmap units: *visit* = number of times a guard entered the node; *attack* = "
        "guard-seconds during which a guard was in attack range of the player while the player "
        "stood on the node (= HP the player lost there).",
        "",
        "## Where these numbers differ from the paper",
        "",
        "* **Coverage is a true fraction in [0, 1].** The paper reports partition coverage "
        "above 1 (e.g. PF 1.72), which cannot be a fraction of nodes; ours counts each node "
        "once, so partition and grid coverage are on the same scale but not comparable to the "
        "paper's partition column.",
        "* CaptureTime and FirstDetectTime are censored at the trial duration (see above), not "
        "averaged over the trials where the event happened.",
        "* Distances are shortest-path distances on the node graph in world units (1 unit = 1 "
        "grid cell), on both abstractions.",
        "* The paper gives mean ± std only; the bootstrap intervals are ours.",
    ]
    if report.skipped_heat:
        lines += ["", f"{report.skipped_heat} trials had no usable per-node counts and are not "
                      "in the heatmaps."]
    return "\n".join(lines) + "\n"


# =========================================================================== entry points
def write_report(directory: str | Path, *, figures: bool = True) -> list[Path]:
    """Write every report file into ``directory`` (which holds ``results.sqlite``).

    ``figures=False`` skips the PNGs (the CSVs and Markdown are still written).
    Returns the paths written.
    """
    directory = Path(directory)
    store_path = directory / STORE_NAME
    if not store_path.is_file():
        raise UserError(f"{directory}: no {STORE_NAME} here (run `stealth run --out "
                        f"{directory}` first)")
    try:
        with ResultStore(store_path, readonly=True) as store:
            meta = store.meta()
            report = _gather(store)
            failures = list(store.trials(failed=True))
    except Exception as error:
        raise UserError(f"{store_path}: cannot read the results store ({error})") from None
    if not report.trials:
        raise UserError(f"{store_path}: no finished trials yet"
                        + (f" ({len(failures)} failed)" if failures else ""))

    written: list[Path] = []
    path = directory / "trials.csv"
    write_trials_csv(report.trials, path)
    written.append(path)

    design = json.loads(meta.get("design", "{}"))
    rows = table_rows(report.trials, design.get("abstractions"))
    write_table(rows, directory, len(report.trials))
    written += [directory / "table.md", directory / "table.csv"]

    failed_path = directory / "failed.csv"
    if failures:
        with failed_path.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["key", *IDENTITY, "error"])
            for f in failures:
                writer.writerow([f["key"], *(f[c] for c in IDENTITY), f["error"]])
        written.append(failed_path)
    elif failed_path.exists():
        failed_path.unlink()

    written += write_heatmaps(report, directory, figures=figures)
    if figures:
        written += write_aggregate(rows, directory)

    readme = directory / "README.md"
    readme.write_text(_readme(directory, meta, report, len(failures), written + [readme]),
                      encoding="utf-8")
    written.append(readme)
    return written


def cmd_report(args: argparse.Namespace) -> int:
    """``stealth report DIR``: write the report files into DIR and list them on stderr."""
    directory = Path(args.dir)
    if not directory.is_dir():
        raise UserError(f"{directory}: no such results directory")
    written = write_report(directory)
    pngs = sum(1 for p in written if p.suffix == ".png")
    print(f"stealth: wrote {len(written)} files ({pngs} figures) into {directory}; "
          f"start with {directory / 'README.md'}", file=sys.stderr)
    return 0
