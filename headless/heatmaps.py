"""Heatmaps of a results directory: per-node guard visits and attacks, CSV and PNG.

``heatmaps/{level}_{abstraction}_{mode}_{visit,attack}.{csv,png}``: the per-node counts
summed over every trial of that level, abstraction and guard mode (names made safe by
:func:`headless.filenames.output_path`). matplotlib is imported
lazily and drawn through ``Figure`` (no pyplot), so this works on headless machines.
"""

from __future__ import annotations

import csv
import math
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .filenames import output_path
from .tables import ABSTRACTION_NAMES, GUARD_NAMES
from .tables import label as display

__all__ = ["HeatSums", "WALL_COLOUR", "sum_heatmaps", "write_heatmaps"]

WALL_COLOUR = "#3b3b3b"


@dataclass
class _HeatSum:
    visits: np.ndarray
    attacks: np.ndarray
    trials: int = 0
    level_ref: str = ""


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


def write_heatmaps(sums: HeatSums, directory: Path, figures: bool = True) -> list[Path]:
    """Heatmap CSVs (and PNGs) per level x abstraction x guard mode; returns the files."""
    from navmesh.graph import graph_for
    from navmesh.level import load_level

    out = directory / "heatmaps"
    out.mkdir(exist_ok=True)
    written: list[Path] = []
    levels: dict[str, Any] = {}
    for (level_name, abstraction, mode), heat in sorted(sums.heat.items()):
        if level_name not in levels:
            levels[level_name] = load_level(heat.level_ref)
        level = levels[level_name]
        graph = graph_for(level, abstraction)
        if graph.n != len(heat.visits):
            print(f"stealth: warning: {level_name} {abstraction}: the level has {graph.n} nodes "
                  f"now but the trials have {len(heat.visits)}; heatmap skipped", file=sys.stderr)
            continue
        mode_name = display(GUARD_NAMES, mode)
        for kind, values, label, cmap in (
            ("visit", heat.visits, "guard visits (sum)", "viridis"),
            ("attack", heat.attacks, "attack: HP lost (sum)", "inferno"),
        ):
            csv_path = output_path(out, level_name, abstraction, mode, kind, suffix=".csv")
            grid = _write_heatmap_csv(csv_path, graph, values, level.rows, level.cols)
            written.append(csv_path)
            if figures:
                shown = "".join(c if c.isprintable() else "?" for c in level_name)
                title = (f"{shown} — {display(ABSTRACTION_NAMES, abstraction)} — {mode_name}: "
                         f"{kind} heatmap\n(sum over {heat.trials} trials, all player policies "
                         "and scenarios)")
                png = csv_path.with_suffix(".png")
                _heatmap_png(png, level, graph, values, grid, title, label, cmap)
                written.append(png)
    return written
