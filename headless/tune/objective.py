"""What a ``stealth tune`` trial scores: metric expressions or the distance to a target table.

The rows of one evaluation (``run_trial`` rows of the design at one point of the search
space) are aggregated as Table 3 aggregates them (:func:`headless.analysis.tables.metric_value`:
``captured`` as 1/0, censored times as the full duration), then read by the objective:

* an :class:`~headless.tune.expr.Expression` over metric names (``capture_rate`` is ``captured``),
  each the mean over the trials of its scenario, narrowed by selectors (``pf.captures``);
* or a **target table** (``abstraction, guards, player`` and one column per metric, as
  ``headless/targets/paper-table3.csv``, the paper's Table 3): the mean over its cells of
  ``(error / tolerance)²`` with tolerance 0.10 for a rate (``captured``) and 25 % of the
  target value otherwise — so a cell within the issue's tolerance adds at most 1.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from game.metrics import TableColumn, registered_metrics

from ..errors import UserError
from .expr import Expression
from ..analysis.tables import _Durations, metric_value, table_columns

__all__ = ["ALIASES", "TARGETS_DIR", "Cell", "Target", "aggregate", "as_trials", "load_target",
           "lookup_for", "check_names"]

TARGETS_DIR = Path(__file__).resolve().parent.parent / "targets"
"""Bundled target tables (``paper-table3.csv``)."""

ALIASES = {"capture_rate": "captured"}
"""Objective names that are another metric's (the paper's column names)."""

RATE_TOLERANCE = 0.10
RELATIVE_TOLERANCE = 0.25


def _columns_by_metric() -> dict[str, list[TableColumn]]:
    by: dict[str, list[TableColumn]] = {}
    for column in table_columns():
        by.setdefault(column.metric.name, []).append(column)
    return by


def check_names(expression: Expression, selectors: set[str], scenarios: Sequence[str],
                where: str) -> None:
    """Every metric of ``expression`` exists and every selector names part of the design."""
    by = _columns_by_metric()
    for name, chosen in expression.names:
        metric = ALIASES.get(name, name)
        if metric not in by:
            known = ", ".join(sorted([*by, *ALIASES]))
            raise UserError(f"{where}: {name!r} is not a metric (metrics: {known})")
        if not any(c.scenario in scenarios for c in by[metric]):
            raise UserError(f"{where}: {name} needs a scenario the design does not run "
                            f"({', '.join(c.scenario for c in by[metric])})")
        for selector in chosen:
            if selector not in selectors:
                raise UserError(f"{where}: {selector!r} in {selector}.{name} is no guard mode, "
                                "player policy, abstraction or level of the design")


def as_trials(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """``run_trial`` rows shaped like stored trials (metrics at the top level)."""
    return [{**row, **row["metrics"], "extra_metrics": {}, "factors": row.get("factors", {})}
            for row in rows]


def aggregate(trials: Sequence[Mapping[str, Any]], metric: str,
              selectors: tuple[str, ...] = ()) -> float:
    """Mean of ``metric`` (Table 3's way) over the trials matching every selector (NaN: none)."""
    metric = ALIASES.get(metric, metric)
    durations = _Durations()
    values: list[float] = []
    for column in _columns_by_metric().get(metric, []):
        for trial in trials:
            if trial["scenario"] != column.scenario:
                continue
            if any(s not in (trial["guards"], trial["player"], trial["abstraction"],
                             trial["level"]) for s in selectors):
                continue
            value = metric_value(trial, column,
                                 durations({**trial["overrides"], **trial.get("factors", {})}))
            if value is not None:
                values.append(value)
    return sum(values) / len(values) if values else math.nan


def lookup_for(trials: Sequence[Mapping[str, Any]]) -> Any:
    """The ``lookup(name, selectors)`` an :class:`Expression` reads these trials through."""
    def lookup(name: str, selectors: tuple[str, ...]) -> float:
        return aggregate(trials, name, selectors)
    return lookup


@dataclass(frozen=True)
class Cell:
    """One cell of a target table: where, which metric, the target value."""

    abstraction: str
    guards: str
    player: str
    metric: str
    target: float

    @property
    def tolerance(self) -> float:
        """±0.10 for a rate, ±25 % of the target otherwise (never below 0.01)."""
        rate = any(m.name == self.metric and m.aggregate == "rate" for m in registered_metrics())
        return RATE_TOLERANCE if rate else max(0.01, RELATIVE_TOLERANCE * abs(self.target))


@dataclass(frozen=True)
class Target:
    """A target table: its file and cells."""

    path: Path
    cells: tuple[Cell, ...]

    def compare(self, trials: Sequence[Mapping[str, Any]]) -> list[tuple[Cell, float]]:
        """Every cell with the trials' value in it."""
        return [(c, aggregate(trials, c.metric, (c.abstraction, c.guards, c.player)))
                for c in self.cells]

    def distance(self, trials: Sequence[Mapping[str, Any]]) -> tuple[float, float]:
        """``(mean squared normalised error, share of cells within tolerance)``; a cell the
        trials give no value for counts as a large error."""
        errors = [((value - c.target) / c.tolerance) if math.isfinite(value) else 10.0
                  for c, value in self.compare(trials)]
        if not errors:
            return math.nan, math.nan
        return (sum(e * e for e in errors) / len(errors),
                sum(1 for e in errors if abs(e) <= 1.0) / len(errors))


def load_target(name: str, base: Path, design: Mapping[str, Sequence[str]]) -> Target:
    """A target table: a path (relative to the spec file) or a bundled name (``paper-table3``).

    Only the cells of the design's abstractions, guard modes and player policies count.
    """
    path = Path(name)
    if not path.is_absolute():
        path = base / path
    if not path.is_file() and (TARGETS_DIR / f"{name}.csv").is_file():
        path = TARGETS_DIR / f"{name}.csv"
    if not path.is_file():
        raise UserError(f"objective.target {name}: no such file (bundled: "
                        + ", ".join(p.stem for p in sorted(TARGETS_DIR.glob("*.csv"))) + ")")
    by = _columns_by_metric()
    cells = []
    with path.open(newline="", encoding="utf-8") as handle:
        for number, row in enumerate(csv.DictReader(handle), start=2):
            where = (row.get("abstraction"), row.get("guards"), row.get("player"))
            if None in where:
                raise UserError(f"{path}: line {number}: needs abstraction, guards, player")
            if (where[0] not in design["abstractions"] or where[1] not in design["guards"]
                    or where[2] not in design["players"]):
                continue
            for key, text in row.items():
                if key in ("abstraction", "guards", "player") or text in (None, ""):
                    continue
                metric = ALIASES.get(key, key)
                if metric not in by:
                    raise UserError(f"{path}: column {key!r} is not a metric")
                if not any(c.scenario in design["scenarios"] for c in by[metric]):
                    continue
                try:
                    value = float(text)
                except ValueError:
                    raise UserError(f"{path}: line {number}: {key}: not a number: "
                                    f"{text!r}") from None
                cells.append(Cell(str(where[0]), str(where[1]), str(where[2]), metric, value))
    if not cells:
        raise UserError(f"{path}: no cell of the table is in the design")
    return Target(path, tuple(cells))
