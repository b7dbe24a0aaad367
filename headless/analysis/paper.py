"""The paper's published Table 3 (``targets/paper-table3.csv``) and when a design is the paper's.

The values are the paper's, per abstraction × guard mode × player policy; the report
overlays them on the aggregate figure when the results come from the paper's design (its
five levels, modes, policies and abstractions, any number of seeds, no plugin stimuli).

>>> values = paper_table3()
>>> values[("grid", "pf", "maxmin")]["captured"], values[("partition", "cheat", "maxmin")]["backtracks"]
(0.8, 44.2)
>>> is_paper_design({"level_names": ["arkham", "dishonored", "maze", "miami", "tlou"],
...                  "abstractions": ["grid"], "guards": ["pf"], "players": ["maxmin"]})
True
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

__all__ = ["PAPER_LEVELS", "PAPER_TABLE3", "is_paper_design", "paper_table3"]

PAPER_TABLE3 = Path(__file__).resolve().parent.parent / "targets" / "paper-table3.csv"
"""The paper's Table 3 as CSV: one row per abstraction, guard mode and player policy."""

PAPER_LEVELS = frozenset({"arkham", "dishonored", "maze", "miami", "tlou"})
"""The five levels of the paper's experiment."""

#: the CSV's column of a metric, where it is not the metric's own name
_COLUMN = {"captured": "capture_rate"}
_METRICS = ("captured", "capture_time", "captures", "coverage", "avg_guard_player_dist",
            "first_detect_time", "backtracks")


@cache
def paper_table3() -> dict[tuple[str, str, str], dict[str, float]]:
    """``{(abstraction, guards, player): {metric name: the paper's value}}``."""
    with PAPER_TABLE3.open(newline="", encoding="utf-8") as handle:
        return {(r["abstraction"], r["guards"], r["player"]):
                {m: float(r[_COLUMN.get(m, m)]) for m in _METRICS}
                for r in csv.DictReader(handle)}


def is_paper_design(design: Mapping[str, Any]) -> bool:
    """Whether ``design`` (a store's ``meta`` design) is the paper's: its five levels, and
    only abstractions, modes and policies the paper's table has; no plugin stimuli."""
    cells = paper_table3()
    known = [{key[k] for key in cells} for k in range(3)]
    wanted = [design.get("abstractions") or [], design.get("guards") or [],
              design.get("players") or []]
    return (set(design.get("level_names") or []) == PAPER_LEVELS
            and not design.get("stimuli")
            and all(w and set(w) <= k for w, k in zip(wanted, known)))
