"""Table 3 and the flat trial list: ``trials.csv``, ``table.csv``, ``table.md``.

The columns come from the metric registry (:mod:`game.metrics`): every registered metric
with a Table 3 ``column`` is a column, computed from the trials of its scenario(s).
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ai import GUARD_MODES, PLAYER_POLICIES, Names
from game.metrics import TableColumn, metric_names, registered_metrics

from .stats import Stat, summarise
from ..store import IDENTITY

__all__ = ["ABSTRACTION_NAMES", "GUARD_NAMES", "GUARD_SHORT", "PLAYER_NAMES", "PLAYER_SHORT",
           "label", "metric_value", "table_columns", "table_rows", "write_table",
           "write_trials_csv"]

#: the registered modes' and policies' names (:mod:`ai`), read live: a mode registered
#: later has its label in every table and figure
GUARD_NAMES = Names(GUARD_MODES, "display")
GUARD_SHORT = Names(GUARD_MODES, "short")
PLAYER_NAMES = Names(PLAYER_POLICIES, "display")
PLAYER_SHORT = Names(PLAYER_POLICIES, "short")
ABSTRACTION_NAMES = {"grid": "Grid", "partition": "Partition"}


def table_columns() -> tuple[TableColumn, ...]:
    """Table 3's columns: every registered metric's, in registration order."""
    return tuple(c for m in registered_metrics() for c in m.table_columns())


def _order(names: Iterable[str], display: Mapping[str, str]) -> list[str]:
    """Names sorted by display name (the paper's tables are alphabetical)."""
    return sorted(set(names), key=lambda n: (display.get(n, n.title()).lower(), n))


def label(table: Mapping[str, str], name: str) -> str:
    """Display name of ``name`` (its title case when the table does not know it)."""
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


def metric_value(trial: Mapping[str, Any], column: TableColumn,
                 duration: float) -> float | None:
    """The number a trial contributes to a Table 3 column (None: it contributes nothing).

    ``captured`` counts as 1/0; a censored time that did not happen (no capture, no
    detection) counts as the trial's full duration, as in the paper.
    """
    value = trial.get(column.metric.name)
    if value is None:
        value = trial.get("extra_metrics", {}).get(column.metric.name)
    if value is None:
        return duration if column.metric.censor else None
    value = float(value)
    return value if math.isfinite(value) else None


def table_rows(trials: Sequence[Mapping[str, Any]], abstractions: Sequence[str] | None = None,
               ) -> list[dict[str, Any]]:
    """Table 3 as a list of rows ``{abstraction, guards, player, stats: {column: Stat}}``."""
    columns = table_columns()
    durations = _Durations()
    groups: dict[tuple[str, str, str], dict[str, list[float]]] = {}
    for trial in trials:
        key = (trial["abstraction"], trial["guards"], trial["player"])
        cell = groups.setdefault(key, {c.name: [] for c in columns})
        for column in columns:
            if trial["scenario"] != column.scenario:
                continue
            settings = {**trial["overrides"], **trial.get("factors", {})}
            value = metric_value(trial, column, durations(settings))
            if value is not None:
                cell[column.name].append(value)
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


def csv_value(value: Any) -> str:
    """A value as a CSV cell: blank for None/NaN, true/false, repr of floats."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return str(value)


def write_trials_csv(trials: Sequence[Mapping[str, Any]], path: Path) -> None:
    """``trials.csv``: key, identity, one column per factor, config hash, every metric,
    ``wall_time`` last."""
    names = metric_names()
    extras = sorted({k for t in trials for k in t.get("extra_metrics", {}) if k not in names})
    factors = sorted({k for t in trials for k in t.get("factors", {})})
    columns = ["key", *IDENTITY, *factors, "config_hash", *names, *extras, "wall_time"]
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for t in trials:
            merged = {**t.get("extra_metrics", {}), **t.get("factors", {}),
                      **{k: v for k, v in t.items() if v is not None}}
            writer.writerow([csv_value(merged.get(c)) for c in columns])


def _fmt(x: float, digits: int = 2) -> str:
    return "–" if math.isnan(x) else f"{x:.{digits}f}"


def _cell(stat: Stat) -> str:
    if stat.n == 0:
        return "–"
    return f"{_fmt(stat.mean)} ± {_fmt(stat.std)} [{_fmt(stat.ci_low)}, {_fmt(stat.ci_high)}]"


#: what table.md says of CoverageRate, by ``metrics.coverage`` (SPEC §11)
COVERAGE_NOTES = {
    "visited": "CoverageRate is a true fraction in [0, 1] (the paper's partition coverage "
               "exceeds 1).",
    "seen": "CoverageRate is the fraction of nodes inside some guard's view at an AI tick "
            "(`metrics.coverage = seen`), in [0, 1].",
    "per_guard": "CoverageRate is each guard's fraction of nodes entered, summed over the "
                 "guards (`metrics.coverage = per_guard`), so it can exceed 1 as the paper's "
                 "partition coverage does.",
    "area": "CoverageRate is the fraction of the walkable area in the nodes a guard entered "
            "(`metrics.coverage = area`), in [0, 1].",
    "seen_area": "CoverageRate is the fraction of the walkable area in the nodes inside some "
                 "guard's view at an AI tick (`metrics.coverage = seen_area`), in [0, 1].",
    "seen_per_guard": "CoverageRate is each guard's fraction of nodes inside its own view at "
                      "an AI tick, summed over the guards (`metrics.coverage = "
                      "seen_per_guard`), so it can exceed 1 as the paper's partition coverage "
                      "does.",
}


def coverage_note(coverage: str, partition_coverage: str = "same") -> str:
    """What table.md says of CoverageRate under the ``[metrics]`` keys (SPEC §11, §12)."""
    note = COVERAGE_NOTES.get(coverage, COVERAGE_NOTES["visited"])
    if partition_coverage in ("same", coverage):
        return note
    own = COVERAGE_NOTES.get(partition_coverage, COVERAGE_NOTES["visited"])
    return (f"On the grid: {note} On the partition (`metrics.partition_coverage = "
            f"{partition_coverage}`): {own}")


def write_table(rows: Sequence[Mapping[str, Any]], directory: Path, trials_total: int,
                coverage: str = "visited", partition_coverage: str = "same") -> None:
    """``table.csv`` (every number) and ``table.md`` (the paper's layout) from :func:`table_rows`;
    ``coverage``, ``partition_coverage``: the trials' ``metrics.*`` keys, which the table's
    note names."""
    columns = table_columns()
    with (directory / "table.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        header = ["abstraction", "guards", "player", "GuardMode", "PlayerMode"]
        for m in columns:
            header += [f"{m.name}_{part}" for part in ("n", "mean", "std", "ci_low", "ci_high")]
        writer.writerow(header)
        for row in rows:
            line = [row["abstraction"], row["guards"], row["player"],
                    label(GUARD_NAMES, row["guards"]), label(PLAYER_NAMES, row["player"])]
            for m in columns:
                s = row["stats"][m.name]
                line += [str(s.n), *(csv_value(v) for v in (s.mean, s.std, s.ci_low, s.ci_high))]
            writer.writerow(line)

    lines = [
        "# Table 3 — capture and fixed-time metrics",
        "",
        f"From {trials_total} finished trials, pooled over levels and seeds. Every cell is "
        "mean ± sample std [95 % bootstrap CI of the mean]. CaptureRate and CaptureTime come "
        "from capture-scenario trials, the other columns from fixed-time trials. CaptureTime "
        "counts an uncaptured trial as its full duration (60 s by default) and FirstDetectTime "
        "a trial without a detection likewise, as the paper's numbers do. "
        + coverage_note(coverage, partition_coverage) + " See README.md.",
        "",
    ]
    titles = [m.heading for m in columns]
    for abstraction in dict.fromkeys(r["abstraction"] for r in rows):
        lines += [f"## {label(ABSTRACTION_NAMES, abstraction)} environment", "",
                  "| GuardMode | PlayerMode | " + " | ".join(titles) + " |",
                  "|---|---|" + "---:|" * len(titles)]
        for row in rows:
            if row["abstraction"] != abstraction:
                continue
            cells = [_cell(row["stats"][m.name]) for m in columns]
            lines.append(f"| {label(GUARD_NAMES, row['guards'])} | "
                         f"{label(PLAYER_NAMES, row['player'])} | " + " | ".join(cells) + " |")
        counts = sorted({(_n(row, "CaptureRate"), _n(row, "CoverageRate"))
                         for row in rows if row["abstraction"] == abstraction})
        text = ", ".join(f"{c} capture / {f} fixed-time" for c, f in counts)
        lines += ["", f"Trials per row: {text}.", ""]
    (directory / "table.md").write_text("\n".join(lines), encoding="utf-8")


def _n(row: Mapping[str, Any], column: str) -> int:
    stat = row["stats"].get(column)
    return stat.n if stat is not None else 0
