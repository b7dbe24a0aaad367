"""A store's Table 3 on held-out seeds beside a target table (the paper's), cell by cell.

``python -m headless.held_out DIR --seeds-from K`` reads the trials of ``DIR/results.sqlite``
whose seed is at least K (the seeds a ``stealth tune`` study did not train on), aggregates
them as Table 3 and the tune objective do (:func:`headless.tune.objective.aggregate`) and prints,
per abstraction, a table whose cells are "ours (paper, error)" with ✓ where the error is
within the objective's tolerance (±0.10 for CaptureRate, ±25 % otherwise), then the share of
cells within tolerance per column and the capture-rate cells. ``--baseline DIR2`` adds the
same figures for another store on exactly the same seeds (e.g. the uncalibrated ``paper``
preset); ``--figure PNG`` draws each cell's error in tolerances; ``--write FILE`` replaces
the part of FILE between ``<!-- calibrated -->`` and ``<!-- /calibrated -->``
(docs/results.md).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .reproducible import save_figure
from ..commands.failure import GuardedParser, guarded, wants_debug
from .beside_paper import COLUMNS
from ..outputs.clobber import refuse_inputs_all
from ..errors import UserError
from .markers import replace_marked
from ..tune.objective import Cell, Target, aggregate, load_target
from ..store import ResultStore
from .tables import ABSTRACTION_NAMES, GUARD_NAMES, PLAYER_NAMES

__all__ = ["Compared", "compare", "distance", "held_out_markdown", "held_out_trials", "main",
           "plot_errors", "run"]

_BEGIN, _END = "<!-- calibrated -->", "<!-- /calibrated -->"


@dataclass(frozen=True)
class Compared:
    """One target cell with our value on the held-out seeds."""

    cell: Cell
    value: float

    @property
    def error(self) -> float:
        """Ours minus the target."""
        return self.value - self.cell.target

    @property
    def scaled(self) -> float:
        """The error in tolerances (|scaled| <= 1: within tolerance)."""
        return self.error / self.cell.tolerance if math.isfinite(self.value) else math.inf

    @property
    def within(self) -> bool:
        """Whether the cell is within the tolerance."""
        return abs(self.scaled) <= 1.0

    def describe_error(self) -> str:
        """The error as the tolerance reads it: absolute for a rate, relative otherwise."""
        if not math.isfinite(self.value):
            return "–"
        if self.cell.metric == "captured":
            return f"{self.error:+.2f}"
        return f"{100 * self.error / self.cell.target:+.0f} %" if self.cell.target else "–"


def held_out_trials(directory: Path, seeds_from: int) -> list[dict[str, Any]]:
    """The finished trials of the store in ``directory`` whose seed is ``>= seeds_from``."""
    path = directory / "results.sqlite"
    if not path.is_file():
        raise UserError(f"{directory}: no results.sqlite (run stealth run --out {directory})")
    with ResultStore(path, readonly=True) as store:
        trials = [dict(t) for t in store.trials() if int(t["seed"]) >= seeds_from]
    if not trials:
        raise UserError(f"{directory}: no finished trial with seed >= {seeds_from}")
    return trials


def compare(trials: Sequence[Mapping[str, Any]], target: Target) -> list[Compared]:
    """Every target cell with the trials' Table 3 value (grouped first: one pass each)."""
    groups: dict[tuple[str, str, str], list[Mapping[str, Any]]] = {}
    for trial in trials:
        key = (trial["abstraction"], trial["guards"], trial["player"])
        groups.setdefault(key, []).append(trial)
    return [Compared(c, aggregate(groups.get((c.abstraction, c.guards, c.player), []), c.metric))
            for c in target.cells]


def _target_for(trials: Sequence[Mapping[str, Any]], name: str) -> Target:
    design = {"abstractions": sorted({t["abstraction"] for t in trials}),
              "guards": sorted({t["guards"] for t in trials}),
              "players": sorted({t["player"] for t in trials}),
              "scenarios": sorted({t["scenario"] for t in trials})}
    return load_target(name, Path.cwd(), design)


def _share(rows: Sequence[Compared]) -> str:
    if not rows:  # e.g. a capture-rate column of a store without capture-scenario cells
        return "– (no cells)"
    within = sum(r.within for r in rows)
    return f"{within}/{len(rows)} ({within / len(rows):.0%})"


def distance(rows: Sequence[Compared]) -> float:
    """The tune objective of these cells (:meth:`headless.tune.objective.Target.distance`)."""
    scaled = [r.scaled if math.isfinite(r.scaled) else 10.0 for r in rows]
    return sum(e * e for e in scaled) / len(scaled) if scaled else math.nan


def held_out_markdown(ours: Sequence[Compared], seeds: str,
                      baseline: Sequence[Compared] | None = None) -> str:
    """The Markdown of the module docstring for compared cells (and a baseline's)."""
    by = {(r.cell.abstraction, r.cell.guards, r.cell.player, r.cell.metric): r for r in ours}
    lines: list[str] = []
    for abstraction in dict.fromkeys(r.cell.abstraction for r in ours):
        lines += [f"**{ABSTRACTION_NAMES.get(abstraction, abstraction)}**, {seeds} — each cell: "
                  "ours (paper, error); ✓ within tolerance", "",
                  "| GuardMode | PlayerMode | " + " | ".join(c for c, _ in COLUMNS) + " |",
                  "|---|---|" + "---:|" * len(COLUMNS)]
        pairs = dict.fromkeys((r.cell.guards, r.cell.player) for r in ours
                              if r.cell.abstraction == abstraction)
        for guards, player in pairs:
            cells = []
            for _, metric in COLUMNS:
                r = by.get((abstraction, guards, player, metric))
                cells.append("" if r is None else f"{r.value:.2f} ({r.cell.target:.2f}, "
                             f"{r.describe_error()}){' ✓' if r.within else ''}")
            lines.append(f"| {GUARD_NAMES.get(guards, guards)} | "
                         f"{PLAYER_NAMES.get(player, player)} | " + " | ".join(cells) + " |")
        lines.append("")
    label = "calibrated" if baseline is not None else "ours"
    head = f"| column | {label} |" + (" defaults |" if baseline is not None else "")
    lines += ["Cells within tolerance (±0.10 for CaptureRate, ±25 % otherwise), "
              f"{seeds}:", "", head, "|---|---:|" + ("---:|" if baseline is not None else "")]
    for column, metric in (*COLUMNS, ("all cells", "")):
        mine = [r for r in ours if not metric or r.cell.metric == metric]
        row = f"| {column} | {_share(mine)} |"
        if baseline is not None:
            row += f" {_share([r for r in baseline if not metric or r.cell.metric == metric])} |"
        lines.append(row)
    lines += ["", f"Capture-rate cells, {seeds}:", "",
              "| env | GuardMode | PlayerMode | paper | " + label + " | error |"
              + (" defaults |" if baseline is not None else ""),
              "|---|---|---|---:|---:|---:|" + ("---:|" if baseline is not None else "")]
    base = {(r.cell.abstraction, r.cell.guards, r.cell.player, r.cell.metric): r
            for r in baseline or []}
    for r in ours:
        if r.cell.metric != "captured":
            continue
        c = r.cell
        row = (f"| {c.abstraction} | {GUARD_NAMES.get(c.guards, c.guards)} | "
               f"{PLAYER_NAMES.get(c.player, c.player)} | {c.target:.2f} | {r.value:.2f} | "
               f"{r.describe_error()}{' ✓' if r.within else ''} |")
        if baseline is not None:
            b = base.get((c.abstraction, c.guards, c.player, c.metric))
            row += f" {'' if b is None else f'{b.value:.2f}'} |"
        lines.append(row)
    within = [r for r in ours if r.cell.metric == "captured"]
    lines += ["", f"Capture-rate cells within ±0.10: {_share(within)}. The tune objective "
              f"(mean of (error / tolerance)² over the cells): {distance(ours):.2f}"
              + (f" (defaults: {distance(baseline):.2f})" if baseline is not None else "") + "."]
    return "\n".join(lines) + "\n"


def plot_errors(ours: Sequence[Compared], path: Path, title: str) -> None:
    """Each cell's error in tolerances, one panel per abstraction (clipped to ±4; the
    cells within tolerance are framed)."""
    import numpy as np
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    abstractions = list(dict.fromkeys(r.cell.abstraction for r in ours))
    fig = Figure(figsize=(11.0, 4.6 * len(abstractions)), dpi=100)
    for k, abstraction in enumerate(abstractions):
        mine = [r for r in ours if r.cell.abstraction == abstraction]
        pairs = list(dict.fromkeys((r.cell.guards, r.cell.player) for r in mine))
        metrics = [m for _, m in COLUMNS]
        grid = np.full((len(pairs), len(metrics)), np.nan)
        for r in mine:
            grid[pairs.index((r.cell.guards, r.cell.player)), metrics.index(r.cell.metric)] = (
                max(-4.0, min(4.0, r.scaled)))
        ax = fig.add_subplot(len(abstractions), 1, k + 1)
        image = ax.imshow(grid, cmap="RdBu_r", norm=TwoSlopeNorm(0.0, -4.0, 4.0), aspect="auto")
        for r in mine:
            i, j = pairs.index((r.cell.guards, r.cell.player)), metrics.index(r.cell.metric)
            ax.text(j, i, f"{r.value:.2f}\n({r.cell.target:.2f})", ha="center", va="center",
                    fontsize=7, color="white" if abs(r.scaled) > 2.5 else "black")
            if r.within:
                ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.0,
                                       edgecolor="black"))
        ax.set_xticks(range(len(metrics)), [c for c, _ in COLUMNS], fontsize=8)
        ax.set_yticks(range(len(pairs)), [f"{GUARD_NAMES.get(g, g)} / {PLAYER_NAMES.get(p, p)}"
                                          for g, p in pairs], fontsize=8)
        ax.set_title(f"{ABSTRACTION_NAMES.get(abstraction, abstraction)}: (ours − paper) / "
                     "tolerance; framed = within tolerance; ours (paper)", fontsize=9)
        fig.colorbar(image, ax=ax, shrink=0.9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m headless.held_out``: its exit code; every failure one ``stealth: error:`` line
    (:func:`headless.commands.failure.guarded`, as for ``stealth``)."""
    words = list(sys.argv[1:] if argv is None else argv)
    return guarded(lambda: run(words), wants_debug(words))


def run(argv: Sequence[str], prog: str = "python -m headless.held_out") -> int:
    """The analysis of the command line ``argv``, unguarded: :func:`main` guards it, and so
    does ``stealth analyse`` (``prog`` names the command in the help)."""
    parser = GuardedParser(prog=prog, description=__doc__.split("\n\n")[0])
    parser.add_argument("dir", type=Path, help="a results directory (results.sqlite)")
    parser.add_argument("--seeds-from", type=int, default=0, metavar="K",
                        help="only trials with seed >= K (the held-out seeds)")
    parser.add_argument("--target", default="paper-table3",
                        help="a target table (bundled name or CSV path; default paper-table3)")
    parser.add_argument("--baseline", type=Path, default=None,
                        help="another results directory compared on the same seeds")
    parser.add_argument("--figure", type=Path, default=None, help="write the error figure here")
    parser.add_argument("--write", type=Path, default=None,
                        help="replace the marked part of this Markdown file instead of printing")
    args = parser.parse_args(argv)
    try:
        if args.seeds_from < 0:
            raise UserError(f"--seeds-from: must be at least 0, got {args.seeds_from}")
        refuse_inputs_all("--figure/--write", [p for p in (args.figure, args.write) if p],
                          [args.dir / "results.sqlite", args.baseline and args.baseline / "results.sqlite"])
        trials = held_out_trials(args.dir, args.seeds_from)
        target = _target_for(trials, args.target)
        ours = compare(trials, target)
        if not ours:
            raise UserError(f"{args.dir}: no cell of the target {args.target!r} has trials of "
                            "these abstractions, guard modes and player policies")
        baseline = None
        seeds = sorted({int(t["seed"]) for t in trials})
        if args.baseline is not None:  # on exactly our seeds (a store still running has fewer)
            baseline = compare([t for t in held_out_trials(args.baseline, args.seeds_from)
                                if int(t["seed"]) in set(seeds)], target)
        label = (f"held-out seeds {seeds[0]}–{seeds[-1]}" if len(seeds) > 1
                 else f"seed {seeds[0]}")
        text = held_out_markdown(ours, label, baseline)
        if args.write is None:
            sys.stdout.write(text)
        elif not replace_marked(args.write, _BEGIN, _END, text):  # first: it may be refused
            raise UserError(f"{args.write}: no {_BEGIN} ... {_END} markers")
        if args.figure is not None:
            plot_errors(ours, args.figure, f"{args.dir.name}, {label}")
        return 0
    except (UserError, OSError) as error:
        print(f"stealth: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
