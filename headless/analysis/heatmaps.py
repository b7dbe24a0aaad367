"""Heatmaps of a results directory: per-node guard visits and attacks, CSVs and figures.

``heatmaps/{level}_{abstraction}_{mode}_{visit,attack}.csv``: the per-node counts summed
over every trial of that level, abstraction and guard mode (names made safe by
:func:`headless.outputs.filenames.output_path`).
``heatmaps/{level}_{abstraction}_{visit,attack}.{png,svg}``: the paper's side-by-side
figure, one panel per guard mode on **one colour scale** (log when the counts span
:data:`LOG_DECADES` decades or more), nodes without any event drawn in their own colour
(and a mode without any event marked "no events"), each panel framed in its mode's colour
(:mod:`headless.analysis.palette`). matplotlib is imported lazily and drawn through ``Figure`` (no
pyplot), so this works on headless machines.
"""

from __future__ import annotations

import csv
import math
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ai import GUARD_MODES

from ..outputs.filenames import output_path
from .palette import guard_colour
from .tables import ABSTRACTION_NAMES, GUARD_NAMES
from .tables import label as display

__all__ = ["HeatSums", "KINDS", "LOG_DECADES", "NO_EVENTS", "Panel", "WALL_COLOUR",
           "figure_count", "heatmap_panels", "sum_heatmaps", "write_heatmaps"]

WALL_COLOUR = "#3b3b3b"
NO_EVENTS = "#e8e8e8"
"""Colour of a node where nothing happened (count 0), below every colour scale."""
LOG_DECADES = 2
"""A log colour scale when the largest positive count is at least 10^this × the smallest."""
MAX_PANELS_PER_ROW = 5
#: kind -> (colour-bar label, colour map)
KINDS = {"visit": ("guard visits (sum)", "viridis"), "attack": ("attack: HP lost (sum)", "inferno")}


@dataclass
class _HeatSum:
    visits: np.ndarray
    attacks: np.ndarray
    trials: int = 0
    level_ref: str = ""

    def values(self, kind: str) -> np.ndarray:
        """The counts of ``kind`` (a key of :data:`KINDS`)."""
        return self.visits if kind == "visit" else self.attacks


@dataclass
class HeatSums:
    """Per (level, abstraction, guard mode) the summed per-node counts."""

    heat: dict[tuple[str, str, str], _HeatSum] = field(default_factory=dict)
    skipped: int = 0

    def add(self, trial: Mapping[str, Any], visits: Iterable[float] | None,
            attacks: Iterable[float] | None) -> None:
        """Add one trial's counts (a trial without them, or of another shape, is skipped)."""
        if visits is None or attacks is None:
            self.skipped += 1
            return
        key = (trial["level"], trial["abstraction"], trial["guards"])
        v, a = np.asarray(visits, dtype=np.float64), np.asarray(attacks, dtype=np.float64)
        heat = self.heat.get(key)
        if heat is None:
            heat = self.heat[key] = _HeatSum(np.zeros_like(v), np.zeros_like(a),
                                             level_ref=trial["level_ref"])
        if heat.visits.shape != v.shape or heat.attacks.shape != a.shape:
            self.skipped += 1  # the level changed between trials: keep the first shape
            return
        heat.visits += v
        heat.attacks += a
        heat.trials += 1


def sum_heatmaps(trials: Iterable[Mapping[str, Any]]) -> HeatSums:
    """:class:`HeatSums` of trials that carry ``visits`` and ``attacks`` lists."""
    sums = HeatSums()
    for trial in trials:
        sums.add(trial, trial.get("visits"), trial.get("attacks"))
    return sums


def _heat_value(x: float) -> str:
    if math.isnan(x):
        return ""
    return str(int(x)) if float(x).is_integer() else f"{x:.6g}"


def _write_heatmap_csv(path: Path, graph: Any, values: np.ndarray, rows: int, cols: int) -> None:
    """Grid: the rows x cols matrix (blank = wall); partition: one row per triangle."""
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        if graph.kind == "grid":
            grid = np.full((rows, cols), np.nan)
            grid[graph.node_cell[:, 0], graph.node_cell[:, 1]] = values
            writer.writerows([[_heat_value(x) for x in line] for line in grid])
            return
        writer.writerow(["triangle", "x", "y", "value"])
        for i, ((x, y), v) in enumerate(zip(graph.positions, values)):
            writer.writerow([i, f"{x:.6g}", f"{y:.6g}", _heat_value(v)])


def _norm(values: Sequence[np.ndarray]) -> tuple[Any, bool]:
    """One colour scale for every panel: log when the positive counts span
    :data:`LOG_DECADES` decades or more, linear otherwise; the scale starts above 0 (0 is
    drawn as "no events")."""
    from matplotlib.colors import LogNorm, Normalize

    positive = np.concatenate([v[v > 0] for v in values]) if values else np.zeros(0)
    if not len(positive):
        return Normalize(vmin=0.0, vmax=1.0), False
    low, high = float(positive.min()), float(positive.max())
    if high / low >= 10.0 ** LOG_DECADES:
        return LogNorm(vmin=low, vmax=high), True
    return Normalize(vmin=0.0, vmax=high), False


def _below(norm: Any, values: np.ndarray) -> np.ndarray:
    """``values`` with every 0 moved under the scale (drawn in the "no events" colour)."""
    floor = float(norm.vmin) / 2 if float(norm.vmin) > 0 else -1.0
    return np.where(values > 0, values, floor)


@dataclass(frozen=True)
class Panel:
    """One guard mode's counts on one level: a cell of the side-by-side figure."""

    mode: str
    values: np.ndarray
    trials: int


def heatmap_panels(level: Any, graph: Any, panels: Sequence[Panel], kind: str,
                   abstraction: str) -> Any:
    """The side-by-side figure of one level, abstraction and kind: one panel per mode, one
    colour scale for all, "no events" drawn as such, each mode framed in its colour."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    label, cmap_name = KINDS[kind]
    cols = min(len(panels), MAX_PANELS_PER_ROW)
    rows = math.ceil(len(panels) / cols)
    width, height = level.cols * level.cell_size, level.rows * level.cell_size
    aspect = height / width if width else 1.0
    panel_w = 3.0
    fig = Figure(figsize=(panel_w * cols + 1.3, rows * (panel_w * aspect + 0.5) + 0.9), dpi=110,
                 layout="constrained")
    norm, log = _norm([p.values for p in panels])
    cmap = colormaps[cmap_name].with_extremes(under=NO_EVENTS, bad=(0, 0, 0, 0))
    axes = [fig.add_subplot(rows, cols, k + 1) for k in range(len(panels))]
    image: Any = None
    for ax, panel in zip(axes, panels):
        ax.set_facecolor(WALL_COLOUR)
        shown = _below(norm, panel.values)
        if graph.kind == "grid":
            grid = np.full((level.rows, level.cols), np.nan)
            grid[graph.node_cell[:, 0], graph.node_cell[:, 1]] = shown
            image = ax.imshow(np.ma.masked_invalid(grid), cmap=cmap, norm=norm, origin="upper",
                              extent=(0, width, height, 0), interpolation="nearest")
        else:
            mesh = graph.mesh
            image = ax.tripcolor(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.triangles,
                                 facecolors=shown, cmap=cmap, norm=norm, edgecolors="face",
                                 linewidth=0.2)
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(level.walls, colors="black", linewidths=0.6))
        if not (panel.values > 0).any():
            ax.text(width / 2, height / 2, "no events", ha="center", va="center",
                    fontsize=11, color="black",
                    bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8})
        ax.set_xlim(0, width)
        ax.set_ylim(height, 0)  # y down, as in the level files
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        colour = guard_colour(panel.mode)
        for spine in ax.spines.values():
            spine.set_edgecolor(colour)
            spine.set_linewidth(3.0)
        ax.set_title(f"{display(GUARD_NAMES, panel.mode)} ({panel.trials} trials)",
                     fontsize=10, color=colour, fontweight="bold")
    scale = "log scale" if log else "linear scale"
    bar = fig.colorbar(image, ax=axes, fraction=0.03, pad=0.01, extend="min", shrink=0.9)
    bar.set_label(f"{label} ({scale}, shared by all panels)", fontsize=9)
    fig.legend(handles=[Patch(facecolor=NO_EVENTS, edgecolor="black", label="no events (0)"),
                        Patch(facecolor=WALL_COLOUR, edgecolor="black", label="wall")],
               loc="outside lower center", ncol=2, fontsize=9, frameon=False)
    printable = "".join(c if c.isprintable() else "?" for c in level.name)  # e.g. a NUL
    fig.suptitle(f"{printable} — {display(ABSTRACTION_NAMES, abstraction)}: {kind} heatmaps "
                 "(sum over trials, all player policies and scenarios)", fontsize=11)
    return fig


def write_heatmaps(sums: HeatSums, directory: Path, figures: bool = True,
                   tick: Callable[[], None] | None = None) -> list[Path]:
    """Heatmap CSVs per level x abstraction x guard mode and, with ``figures``, one
    side-by-side figure (PNG and SVG) per level x abstraction x kind; returns the files.
    ``tick`` is called after each figure (progress)."""
    from navmesh.graph import graph_for
    from navmesh.errors import LevelError
    from navmesh.level import load_level

    from .figures import save

    out = directory / "heatmaps"
    out.mkdir(exist_ok=True)
    written: list[Path] = []
    levels: dict[str, Any] = {}
    order = {mode: k for k, mode in enumerate(GUARD_MODES)}
    groups: dict[tuple[str, str], list[tuple[str, _HeatSum]]] = {}
    for (level_name, abstraction, mode), heat in sorted(sums.heat.items()):
        groups.setdefault((level_name, abstraction), []).append((mode, heat))
    for (level_name, abstraction), heats in groups.items():
        heats.sort(key=lambda item: (order.get(item[0], len(order)), item[0]))
        ref = heats[0][1].level_ref
        if level_name not in levels:
            try:
                levels[level_name] = load_level(ref)
            except LevelError as error:  # moved, or zones of a plugin the store does not name
                print(f"stealth: warning: {level_name}: heatmaps skipped ({error})",
                      file=sys.stderr)
                levels[level_name] = None
        level = levels[level_name]
        if level is None:
            continue
        graph = graph_for(level, abstraction)
        usable = []
        for mode, heat in heats:
            if graph.n != len(heat.visits):
                print(f"stealth: warning: {level_name} {abstraction} {mode}: the level has "
                      f"{graph.n} nodes now but the trials have {len(heat.visits)}; heatmap "
                      "skipped", file=sys.stderr)
                continue
            usable.append((mode, heat))
            for kind in KINDS:
                csv_path = output_path(out, level_name, abstraction, mode, kind, suffix=".csv")
                _write_heatmap_csv(csv_path, graph, heat.values(kind), level.rows, level.cols)
                written.append(csv_path)
        if not figures or not usable:
            continue
        for kind in KINDS:
            panels = [Panel(mode, heat.values(kind), heat.trials) for mode, heat in usable]
            fig = heatmap_panels(level, graph, panels, kind, abstraction)
            written += save(fig, output_path(out, level_name, abstraction, kind),
                            bbox_inches="tight", pad_inches=0.15)
            if tick is not None:
                tick()
    return written


def figure_count(sums: HeatSums) -> int:
    """How many heatmap figures :func:`write_heatmaps` draws for ``sums``."""
    return len(KINDS) * len({(level, abstraction) for level, abstraction, _ in sums.heat})
