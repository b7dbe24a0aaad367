"""The report of a design with factors: Table 3 per factor combination, figures per factor.

For a store whose trials carry factor values (SPEC §10) ``stealth report DIR`` also writes

* ``factors/<combination>/table.{md,csv}`` — Table 3 of the trials of one combination of
  factor levels (pooled over levels and seeds, like the main table);
* ``factors.csv`` — every combination's Table 3 rows in one file, one column per factor;
* ``factors.md`` — the combinations and where their tables are;
* ``factor_<key>_<abstraction>.png`` — for a numeric factor with two or more levels, each
  Table 3 column's mean against the factor's value with its 95 % bootstrap CI, one line per
  guard mode (pooled over player policies and the other factors' levels).

A design without factors gets none of these (and its report is unchanged).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .reproducible import save_figure
from .stats import Stat, summarise
from .tables import (GUARD_NAMES, ABSTRACTION_NAMES, _Durations, csv_value, label, metric_value,
                     table_columns, table_rows, write_table)

__all__ = ["combination_name", "factor_series", "numeric_factors", "write_factor_report"]

Combination = tuple[tuple[str, Any], ...]


def combination_name(combination: Combination) -> str:
    """A folder name for a combination of factor levels.

    >>> combination_name((("pf.rho", 0.9), ("world.guard_speed", 2.0)))
    'pf.rho=0.9__world.guard_speed=2.0'
    """
    text = "__".join(f"{k}={v}" for k, v in combination)
    return re.sub(r"[^A-Za-z0-9._=-]+", "-", text) or "none"


def _combinations(trials: Sequence[Mapping[str, Any]]) -> dict[Combination, list[Mapping[str, Any]]]:
    groups: dict[Combination, list[Mapping[str, Any]]] = {}
    for trial in trials:
        combination = tuple(sorted(trial.get("factors", {}).items()))
        groups.setdefault(combination, []).append(trial)
    return dict(sorted(groups.items(), key=lambda item: [repr(v) for _, v in item[0]]))


def numeric_factors(trials: Sequence[Mapping[str, Any]]) -> dict[str, list[float]]:
    """Factors whose levels are all numbers (not booleans), with two or more levels, sorted."""
    levels: dict[str, set[Any]] = {}
    for trial in trials:
        for key, value in trial.get("factors", {}).items():
            levels.setdefault(key, set()).add(value)
    return {key: sorted(float(v) for v in values) for key, values in sorted(levels.items())
            if len(values) > 1
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)}


def factor_series(trials: Sequence[Mapping[str, Any]], key: str, abstraction: str,
                  ) -> dict[str, dict[str, list[tuple[float, Stat]]]]:
    """``{column: {guard mode: [(factor value, Stat), ...]}}`` of one abstraction's trials."""
    durations = _Durations()
    cells: dict[tuple[str, str, float], list[float]] = {}
    for trial in trials:
        if trial["abstraction"] != abstraction or key not in trial.get("factors", {}):
            continue
        x = float(trial["factors"][key])
        duration = durations({**trial["overrides"], **trial["factors"]})
        for column in table_columns():
            if trial["scenario"] != column.scenario:
                continue
            value = metric_value(trial, column, duration)
            if value is not None:
                cells.setdefault((column.name, trial["guards"], x), []).append(value)
    series: dict[str, dict[str, list[tuple[float, Stat]]]] = {}
    for (name, guard, x), values in sorted(cells.items()):
        stat = summarise(values, f"{abstraction}/{guard}/{key}={x}/{name}")
        series.setdefault(name, {}).setdefault(guard, []).append((x, stat))
    return series


def _figure(trials: Sequence[Mapping[str, Any]], key: str, abstraction: str, path: Path) -> bool:
    from matplotlib.figure import Figure

    series = factor_series(trials, key, abstraction)
    columns = [c for c in table_columns() if c.name in series]
    if not columns:
        return False
    per_row = min(4, len(columns))
    rows = -(-len(columns) // per_row)
    fig = Figure(figsize=(3.8 * per_row, 3.2 * rows), dpi=100)
    for i, column in enumerate(columns):
        ax = fig.add_subplot(rows, per_row, i + 1)
        for guard, points in sorted(series[column.name].items(),
                                    key=lambda item: label(GUARD_NAMES, item[0])):
            xs = [x for x, _ in points]
            means = [s.mean for _, s in points]
            low = [s.mean - s.ci_low for _, s in points]
            high = [s.ci_high - s.mean for _, s in points]
            ax.errorbar(xs, means, yerr=[low, high], marker="o", capsize=3,
                        label=label(GUARD_NAMES, guard))
        ax.set_title(column.title, fontsize=9)
        ax.set_xlabel(key, fontsize=8)
        ax.tick_params(labelsize=7)
        if i == 0:
            ax.legend(fontsize=7)
    fig.suptitle(f"{label(ABSTRACTION_NAMES, abstraction)}: Table 3 against {key} "
                 "(mean, 95 % bootstrap CI)")
    fig.tight_layout()
    save_figure(fig, path)
    return True


def write_factor_report(trials: Sequence[Mapping[str, Any]], directory: Path,
                        abstractions: Sequence[str] | None = None, *,
                        figures: bool = True) -> list[Path]:
    """Write the factor files of the module docstring into ``directory``; the paths written."""
    groups = _combinations(trials)
    if list(groups) == [()]:
        return []
    written: list[Path] = []
    keys = sorted({k for combination in groups for k, _ in combination})
    index = ["# Table 3 per factor combination", "",
             f"Factors: {', '.join(keys)}. Each table pools its combination's trials over "
             "levels and seeds, like table.md.", "",
             "| " + " | ".join(keys) + " | trials | table |",
             "|" + "---|" * (len(keys) + 2)]
    with (directory / "factors.csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        columns = table_columns()
        header = [*keys, "abstraction", "guards", "player"]
        for c in columns:
            header += [f"{c.name}_{part}" for part in ("n", "mean", "std", "ci_low", "ci_high")]
        writer.writerow(header)
        for combination, subset in groups.items():
            values = dict(combination)
            folder = directory / "factors" / combination_name(combination)
            folder.mkdir(parents=True, exist_ok=True)
            rows = table_rows(subset, abstractions)
            write_table(rows, folder, len(subset))
            written += [folder / "table.md", folder / "table.csv"]
            index.append("| " + " | ".join(csv_value(values.get(k)) for k in keys)
                         + f" | {len(subset)} | [table](factors/{folder.name}/table.md) |")
            for row in rows:
                line = [csv_value(values.get(k)) for k in keys]
                line += [row["abstraction"], row["guards"], row["player"]]
                for c in columns:
                    s = row["stats"][c.name]
                    line += [str(s.n), *(csv_value(v) for v in
                                         (s.mean, s.std, s.ci_low, s.ci_high))]
                writer.writerow(line)
    written.append(directory / "factors.csv")
    (directory / "factors.md").write_text("\n".join(index) + "\n", encoding="utf-8")
    written.append(directory / "factors.md")
    if figures:
        present = list(dict.fromkeys(t["abstraction"] for t in trials))
        for key in numeric_factors(trials):
            for abstraction in present:
                path = directory / f"factor_{key}_{abstraction}.png"
                if _figure(trials, key, abstraction, path):
                    written.append(path)
    return written
