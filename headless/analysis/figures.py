"""The aggregate figure: ``aggregate_{abstraction}.png``, the paper's "Aggregated performance".

One bar panel per Table 3 column (:func:`headless.analysis.tables.table_columns`), bars per guard
mode × player policy with 95 % bootstrap CI whiskers. The grid is derived from the columns:
one band of rows per scenario (capture first, as in the paper), at most
:data:`MAX_COLUMNS` panels a row, and the legend in the first free cells (or a row of its
own) — so a registered metric adds a panel instead of being dropped. Each mode has its
colour of :mod:`headless.analysis.palette`; when the design is the paper's (:mod:`headless.analysis.paper`)
the paper's published value of each bar is drawn on it as a black diamond. Written as PNG
and SVG.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from game.metrics import TableColumn

from .reproducible import save_figure
from ..outputs.filenames import output_path
from .palette import guard_colour
from .tables import ABSTRACTION_NAMES, GUARD_NAMES, GUARD_SHORT, PLAYER_NAMES, PLAYER_SHORT, label
from .tables import table_columns

__all__ = ["FORMATS", "MAX_COLUMNS", "Layout", "aggregate_figure", "layout", "write_aggregate"]

FORMATS = ("png", "svg")
"""Every report figure is written in these formats."""

#: the paper's values, ``{(abstraction, guards, player): {metric name: value}}``
Paper = Mapping[tuple[str, str, str], Mapping[str, float]]

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


def aggregate_figure(rows: Sequence[Mapping[str, Any]], abstraction: str,
                     paper: Paper | None = None) -> Any:
    """The matplotlib ``Figure`` of one abstraction's rows of :func:`headless.analysis.tables.table_rows`.

    Its first axes are the metric panels in :func:`table_columns` order, the last one the
    legend. With ``paper``, each bar whose cell and metric the paper reports gets the
    paper's value as a marker.
    """
    from matplotlib.figure import Figure

    columns = table_columns()
    shape = layout(columns)
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
    colours = [guard_colour(r["guards"]) for r in cells]
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
        if paper is not None:
            theirs = np.array([paper.get((abstraction, r["guards"], r["player"]), {})
                               .get(column.metric.name, np.nan) for r in cells])
            if np.isfinite(theirs).any():
                ax.plot(x, theirs, linestyle="none", marker="D", markersize=5,
                        markerfacecolor="black", markeredgecolor="white", zorder=5)
        if np.all(np.isnan(means)):
            ax.text(0.5, 0.5, f"no {column.scenario}-scenario trials", ha="center",
                    va="center", transform=ax.transAxes, color="grey")
        exp = "Capture exp." if column.scenario == "capture" else "Fixed-time exp."
        ax.set_title(f"{column.title} ({exp})", fontsize=10)
        ax.set_ylabel(column.metric.axis_label)
        ax.set_xticks(x, labels, rotation=60, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    legend_ax.axis("off")
    _legend(legend_ax, modes, players, paper is not None)
    fig.suptitle(f"Aggregated performance — {label(ABSTRACTION_NAMES, abstraction)} "
                 "environment (all levels and player policies)", fontsize=13)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    return fig


def _legend(ax: Any, modes: Sequence[str], players: Sequence[str], paper: bool) -> None:
    """The legend cell: a swatch per mode (its palette colour), plain / hatched per
    policy, the paper's marker, and how to read a bar."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles: list[Any] = [Patch(facecolor=guard_colour(m), edgecolor="black",
                                label=f"{GUARD_SHORT.get(m, m)} = {label(GUARD_NAMES, m)}")
                          for m in modes]
    handles += [Patch(facecolor="white", edgecolor="black", hatch="" if i == 0 else "//",
                      label=f"{PLAYER_SHORT.get(p, p)} = {label(PLAYER_NAMES, p)}")
                for i, p in enumerate(players)]
    if paper:
        handles.append(Line2D([], [], linestyle="none", marker="D", markersize=6,
                              markerfacecolor="black", markeredgecolor="white",
                              label="the paper's value (Table 3)"))
    ax.legend(handles=handles, loc="upper left", fontsize=9, frameon=False,
              bbox_to_anchor=(0.0, 1.0))
    notes = ["bar: mean over levels and seeds", "whiskers: 95 % bootstrap CI",
             "of the mean", "uncaptured / undetected trials", "count as the full duration"]
    ax.text(0.5, 1.0, "\n".join(notes), va="top", fontsize=9, transform=ax.transAxes)


def save(fig: Any, stem: Path, **kwargs: Any) -> list[Path]:
    """``fig`` as ``stem.png`` and ``stem.svg`` (:data:`FORMATS`); returns the files."""
    paths = [stem.with_name(f"{stem.name}.{fmt}") for fmt in FORMATS]
    for path in paths:
        save_figure(fig, path, **kwargs)
    return paths


def write_aggregate(rows: Sequence[Mapping[str, Any]], directory: Path,
                    paper: Paper | None = None) -> list[Path]:
    """``aggregate_{abstraction}.png`` and ``.svg`` per abstraction of ``rows`` (with the
    paper's values when given); returns the files."""
    written = []
    for abstraction in dict.fromkeys(r["abstraction"] for r in rows):
        written += save(aggregate_figure(rows, abstraction, paper),
                        output_path(directory, "aggregate", abstraction))
    return written
