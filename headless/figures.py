"""The aggregate figure: ``aggregate_{abstraction}.png``, the paper's "Aggregated performance".

One bar panel per Table 3 column (:func:`headless.tables.table_columns`), bars per guard
mode × player policy with 95 % bootstrap CI whiskers. The grid is derived from the columns:
one band of rows per scenario (capture first, as in the paper), at most
:data:`MAX_COLUMNS` panels a row, and the legend in the first free cells (or a row of its
own) — so a registered metric adds a panel instead of being dropped.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from game.metrics import TableColumn

from .filenames import output_path
from .tables import ABSTRACTION_NAMES, GUARD_NAMES, GUARD_SHORT, PLAYER_NAMES, PLAYER_SHORT, label
from .tables import table_columns

__all__ = ["MAX_COLUMNS", "Layout", "aggregate_figure", "layout", "write_aggregate"]

MAX_COLUMNS = 5
"""Most panels in one row of the figure."""


@dataclass(frozen=True)
class Layout:
    """Where each panel and the legend go: ``(row, col)`` cells of a ``rows × cols`` grid;
    the legend spans ``legend_cols`` cells from ``legend``."""

    rows: int
    cols: int
    panels: tuple[tuple[int, int], ...]
    legend: tuple[int, int]
    legend_cols: int


def layout(columns: Sequence[TableColumn]) -> Layout:
    """The grid of the aggregate figure for these columns.

    >>> from game.metrics import registered_metrics
    >>> cols = [c for m in registered_metrics() for c in m.table_columns()]
    >>> shape = layout(cols)
    >>> shape.rows, shape.cols, shape.legend, shape.legend_cols   # 2 capture + 5 fixed panels
    (2, 5, (0, 2), 3)
    """
    bands: dict[str, int] = {}
    for c in columns:
        bands[c.scenario] = bands.get(c.scenario, 0) + 1
    order = sorted(bands, key=lambda s: (s != "capture", list(bands).index(s)))
    cols = max(1, min(MAX_COLUMNS, max(bands.values(), default=1)))
    cells: dict[str, list[tuple[int, int]]] = {}
    row = 0
    free: tuple[int, int] | None = None
    for scenario in order:
        count = bands[scenario]
        cells[scenario] = [(row + k // cols, k % cols) for k in range(count)]
        last = count % cols
        if free is None and last and cols - last >= 1:
            free = (row + count // cols, last)
        row += math.ceil(count / cols)
    if free is None:
        free, row = (row, 0), row + 1
    taken = {s: iter(v) for s, v in cells.items()}
    panels = tuple(next(taken[c.scenario]) for c in columns)
    return Layout(row, cols, panels, free, cols - free[1])


def aggregate_figure(rows: Sequence[Mapping[str, Any]], abstraction: str) -> Any:
    """The matplotlib ``Figure`` of one abstraction's rows of :func:`headless.tables.table_rows`.

    Its first axes are the metric panels in :func:`table_columns` order, the last one the
    legend.
    """
    from matplotlib import colormaps
    from matplotlib.figure import Figure

    columns = table_columns()
    shape = layout(columns)
    palette = colormaps["tab10"]
    cells = [r for r in rows if r["abstraction"] == abstraction]
    modes = list(dict.fromkeys(r["guards"] for r in cells))
    players = list(dict.fromkeys(r["player"] for r in cells))
    fig = Figure(figsize=(3.6 * shape.cols, 3.75 * shape.rows), dpi=100)
    grid = fig.add_gridspec(shape.rows, shape.cols)
    panels = [fig.add_subplot(grid[r, c]) for r, c in shape.panels]
    lr, lc = shape.legend
    legend_ax = fig.add_subplot(grid[lr, lc:lc + shape.legend_cols])
    x = np.arange(len(cells))
    labels = [f"{GUARD_SHORT.get(r['guards'], r['guards'])}-"
              f"{PLAYER_SHORT.get(r['player'], r['player'])}" for r in cells]
    colours = [palette(modes.index(r["guards"]) % 10) for r in cells]
    hatches = ["" if players.index(r["player"]) == 0 else "//" for r in cells]
    for ax, column in zip(panels, columns):
        stats = [r["stats"][column.name] for r in cells]
        means = np.array([s.mean for s in stats])
        low = np.array([s.mean - s.ci_low for s in stats])
        high = np.array([s.ci_high - s.mean for s in stats])
        bars = ax.bar(x, np.nan_to_num(means), color=colours, edgecolor="black", linewidth=0.5,
                      yerr=np.nan_to_num(np.vstack([low, high])), capsize=3,
                      error_kw={"elinewidth": 0.8})
        for bar, hatch in zip(bars, hatches):
            bar.set_hatch(hatch)
        if np.all(np.isnan(means)):
            ax.text(0.5, 0.5, f"no {column.scenario}-scenario trials", ha="center",
                    va="center", transform=ax.transAxes, color="grey")
        exp = "Capture exp." if column.scenario == "capture" else "Fixed-time exp."
        ax.set_title(f"{column.title} ({exp})", fontsize=10)
        ax.set_ylabel(column.metric.axis_label)
        ax.set_xticks(x, labels, rotation=60, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    legend_ax.axis("off")
    lines = [f"{GUARD_SHORT.get(m, m)} = {label(GUARD_NAMES, m)}" for m in modes]
    lines += [f"{PLAYER_SHORT.get(p, p)} = {label(PLAYER_NAMES, p)}"
              + (" (plain bars)" if i == 0 else " (hatched bars)")
              for i, p in enumerate(players)]
    lines += ["", "bar: mean over levels and seeds", "whiskers: 95 % bootstrap CI",
              "of the mean", "uncaptured / undetected trials", "count as the full duration"]
    legend_ax.text(0.0, 1.0, "\n".join(lines), va="top", fontsize=9, family="monospace")
    fig.suptitle(f"Aggregated performance — {label(ABSTRACTION_NAMES, abstraction)} "
                 "environment (all levels and player policies)", fontsize=13)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    return fig


def write_aggregate(rows: Sequence[Mapping[str, Any]], directory: Path) -> list[Path]:
    """``aggregate_{abstraction}.png`` per abstraction of ``rows``; returns the files."""
    written = []
    for abstraction in dict.fromkeys(r["abstraction"] for r in rows):
        path = output_path(directory, "aggregate", abstraction, suffix=".png")
        aggregate_figure(rows, abstraction).savefig(path)
        written.append(path)
    return written
