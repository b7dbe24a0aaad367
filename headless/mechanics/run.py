"""Running and summarising the mechanics experiment (``stealth mechanics``; docs/mechanics.md).

The mechanic definitions (each one's paired measurement) are in :mod:`headless.mechanics.measures`;
this module runs their jobs in a process pool, bootstraps the paired differences, and writes
``mechanics.md``, ``mechanics.csv`` and ``mechanics_trials.csv``.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from navmesh.level import load_level

from ..errors import UserError
from ..outputs.clobber import level_file, refuse_inputs_all
from .measures import BOOTSTRAP, DRAW_DISTANCES, EXPECTED, MECHANICS, Row, run_job
from ..executors import check_workers, process_pool
from ..outputs.filenames import output_path
from ..progress import Progress
from ..analysis.stats import mean_or_nan, percentile_ci


# ---------------------------------------------------------------------------- statistics


def bootstrap_ci(values: np.ndarray, rng: np.random.Generator, n: int = BOOTSTRAP) -> tuple[float, float]:
    """95 % percentile bootstrap CI of the mean of ``values`` (resampling seeds) with ``rng``."""
    return percentile_ci(values, rng, n)


@dataclass
class Summary:
    """One measure over the seeds: both arms and their paired difference, with CIs."""

    measure: str
    n: int
    on: float
    on_ci: tuple[float, float]
    control: float
    control_ci: tuple[float, float]
    diff: float
    diff_ci: tuple[float, float]
    expected: int

    @property
    def verdict(self) -> str:
        """``yes`` when the difference's CI lies wholly on the intended side of 0 (with no
        intended side, ``expected`` 0: ``changed`` when it lies wholly on either side)."""
        if self.n == 0:
            return "no data"
        if self.expected == 0:
            return "changed" if self.diff_ci[0] * self.diff_ci[1] > 0 else "no clear change"
        if self.expected * self.diff_ci[0] > 0 and self.expected * self.diff_ci[1] > 0:
            return "yes"
        if self.expected * self.diff > 0:
            return "same way, CI spans 0"
        return "NO"


def _arms(rows: Sequence[Row]) -> dict[str, dict[int, dict[str, float]]]:
    table: dict[str, dict[int, dict[str, float]]] = {}
    for measure, seed, arm, value in rows:
        table.setdefault(measure, {}).setdefault(seed, {})[arm] = value
    return table


def _rng() -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(20240101)))


def summarise(rows: Sequence[Row], expected_by_measure: Mapping[str, int] = EXPECTED) -> list[Summary]:
    """Per measure of ``expected_by_measure`` (default :data:`EXPECTED`, the built-in
    mechanics'): means, bootstrap CIs and the paired difference."""
    rng = _rng()
    table = _arms(rows)
    out = []
    for measure, expected in expected_by_measure.items():
        pairs = np.array(
            [(a["on"], a["control"]) for _, a in sorted(table.get(measure, {}).items())
             if math.isfinite(a.get("on", math.nan)) and math.isfinite(a.get("control", math.nan))],
            dtype=float,
        ).reshape(-1, 2)
        on, control = pairs[:, 0], pairs[:, 1]

        mean = mean_or_nan
        out.append(Summary(measure, len(pairs), mean(on), bootstrap_ci(on, rng), mean(control),
                           bootstrap_ci(control, rng), mean(on - control),
                           bootstrap_ci(on - control, rng), expected))
    return out


def draw_curve(rows: Sequence[Row]) -> list[dict[str, Any]]:
    """Per distance d: the share of footsteps that drew a guard, per sound (rain/clear/none)."""
    rng = _rng()
    table = _arms(rows)
    out = []
    for d in DRAW_DISTANCES:
        per_seed = table.get(f"curve: footstep {d} hops away draws a guard", {})
        entry: dict[str, Any] = {"d": d}
        for arm, sound in (("baseline", "none"), ("control", "clear"), ("on", "rain")):
            values = np.array([a[arm] for a in per_seed.values()
                               if math.isfinite(a.get(arm, math.nan))])
            entry[sound] = (float(values.mean()) if len(values) else math.nan,
                            bootstrap_ci(values, rng), len(values))
        out.append(entry)
    return out


def draw_distance(curve: Sequence[Mapping[str, Any]], sound: str, share: float = 0.5) -> int:
    """The largest d such that at every d' ≤ d at least ``share`` of the footsteps drew a
    guard (0: not even at 1 hop)."""
    best = 0
    for entry in curve:
        value = entry[sound][0]
        if not (math.isfinite(value) and value >= share):
            break
        best = int(entry["d"])
    return best


def _fmt(value: float, ci: tuple[float, float]) -> str:
    if not math.isfinite(value):
        return "–"
    return f"{value:.2f} [{ci[0]:.2f}, {ci[1]:.2f}]"


def effects_table(summaries: Sequence[Summary]) -> list[str]:
    """The Markdown lines of the effects table: one row per measure."""
    lines = [
        "| measure | n | mechanic on | control | on − control | intended | as intended |",
        "|---|---|---|---|---|---|---|",
    ]
    arrows = {1: "↑", -1: "↓", 0: "any"}
    for s in summaries:
        lines.append(f"| {s.measure} | {s.n} | {_fmt(s.on, s.on_ci)} | "
                     f"{_fmt(s.control, s.control_ci)} | {_fmt(s.diff, s.diff_ci)} | "
                     f"{arrows[s.expected]} | {s.verdict} |")
    return lines


def markdown(summaries: Sequence[Summary], curve: Sequence[Mapping[str, Any]], level: str,
             abstraction: str, seeds: int, seconds: float) -> str:
    """The results as Markdown: the effects table and the footstep draw curve."""
    lines = [
        f"Level {level}, {abstraction}, PF guards, {seeds} paired seeds; mean [95 % bootstrap "
        f"CI over seeds]; computed in {seconds:.0f} s.",
        "",
        *effects_table(summaries),
    ]
    if curve:
        lines += [
            "",
            "Share of single footsteps d hops from the nearest guard that draw a guard onto "
            "their source within d/2 + 3 s:",
            "",
            "| d (hops) | no noise | clear | rain |",
            "|---|---|---|---|",
        ]
        for entry in curve:
            cells = [_fmt(entry[s][0], entry[s][1]) for s in ("none", "clear", "rain")]
            lines.append(f"| {entry['d']} | " + " | ".join(cells) + " |")
        lines += [
            "",
            f"Draw distance (largest d up to which at least half the footsteps draw a guard): "
            f"no noise {draw_distance(curve, 'none')}, clear {draw_distance(curve, 'clear')}, "
            f"rain {draw_distance(curve, 'rain')} hops.",
        ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- running


def run_mechanics(
    seeds: int = 30, level: str = "miami", abstraction: str = "grid", workers: int | None = None,
    mechanics: Sequence[str] | None = None, progress: bool = True,
) -> tuple[list[Row], float]:
    """Every (mechanic, seed) with all its arms; returns the rows and the seconds it took."""
    names = list(mechanics or MECHANICS)
    jobs = [(m, level, abstraction, s) for s in range(seeds) for m in names]
    return run_jobs(run_job, jobs, workers, progress)


Job = tuple[str, str, str, int]


def run_jobs(func: Callable[[Job], list[Row]], jobs: Sequence[Job], workers: int | None,
             progress: bool = True) -> tuple[list[Row], float]:
    """Every job through ``func`` (top-level, picklable) in a process pool of ``workers``
    (1: in-process) with a progress bar on stderr; the rows sorted, and the seconds it took."""
    started = time.perf_counter()
    rows: list[Row] = []
    workers = workers or min(len(jobs), os.cpu_count() or 1)
    bar = Progress(len(jobs), sys.stderr, enabled=progress, unit="jobs")
    if workers <= 1:
        for job in jobs:
            rows.extend(func(job))
            bar.update(1)
    else:
        with process_pool(workers) as pool:
            for result in pool.map(func, jobs, chunksize=2):
                rows.extend(result)
                bar.update(1)
    bar.close()
    rows.sort(key=lambda r: (r[0], r[1], r[2]))
    return rows, time.perf_counter() - started


def write_results(out: Path, rows: Sequence[Row], summaries: Sequence[Summary], table: str) -> None:
    """``mechanics.md``, ``mechanics.csv`` (one row per measure), ``mechanics_trials.csv``."""
    out.mkdir(parents=True, exist_ok=True)
    output_path(out, "mechanics", suffix=".md").write_text("# Measured effects of the stealth mechanics\n\n" + table,
                                      encoding="utf-8")
    with output_path(out, "mechanics", suffix=".csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["measure", "n", "on", "on_lo", "on_hi", "control", "control_lo",
                         "control_hi", "diff", "diff_lo", "diff_hi", "intended", "as_intended"])
        for s in summaries:
            writer.writerow([s.measure, s.n, s.on, *s.on_ci, s.control, *s.control_ci, s.diff,
                             *s.diff_ci, "up" if s.expected > 0 else "down", s.verdict])
    with output_path(out, "mechanics", "trials", suffix=".csv").open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["measure", "seed", "arm", "value"])
        writer.writerows(rows)


MAX_SEEDS = 10_000
"""Most paired seeds per mechanic ``stealth mechanics --seeds`` runs (30 by default)."""


MIN_WALKABLE = 16
"""Fewest walkable cells a level needs for the mechanics (a decoy 8 hops from the guards)."""


def check_mechanics_level(level: Any, name: str) -> None:
    """Refuse, before any trial, a level the built-in mechanics cannot be measured on: the
    dark and concealment measurements place the player in such a zone, the decoy walks
    guards to a far node."""
    missing = [kind for kind in ("dark", "concealment") if not level.zones.get(kind)]
    if missing:
        raise UserError(f"--level {name}: the mechanics need a {' and a '.join(missing)} "
                        f"zone; this level has none")
    walkable = int(level.occupancy.sum())
    if walkable < MIN_WALKABLE or not level.guards:
        raise UserError(f"--level {name}: the mechanics need at least {MIN_WALKABLE} walkable "
                        f"cells and a guard; this level has {walkable} and {len(level.guards)}")


def refuse_arguments(args: argparse.Namespace) -> int | None:
    """The checks of ``stealth mechanics`` with or without ``--stimulus``: 2 (after the
    one-line message) for too few seeds, else None; a bad ``--workers`` raises."""
    if args.seeds < 2:
        print("stealth: error: --seeds: need at least 2 seeds", file=sys.stderr)
        return 2
    if args.seeds > MAX_SEEDS:
        raise UserError(f"--seeds: at most {MAX_SEEDS} paired seeds per mechanic, got {args.seeds}")
    if args.workers is not None:
        check_workers(args.workers)
    return None


def cmd_mechanics(args: argparse.Namespace) -> int:
    """``stealth mechanics`` (without ``--stimulus``, :mod:`headless.mechanics.stimulus_effect`): run
    the paired experiment, write the files, print the table."""
    refused = refuse_arguments(args)
    if refused is not None:
        return refused
    try:
        level = load_level(args.level)
    except ValueError as error:
        print(f"stealth: error: {error}", file=sys.stderr)
        return 2
    check_mechanics_level(level, args.level)
    refuse_inputs_all("--out", [output_path(Path(args.out), *name, suffix=suffix) for name, suffix
                                in ((("mechanics",), ".md"), (("mechanics",), ".csv"),
                                    (("mechanics", "trials"), ".csv"))],
                      [level_file(args.level)])
    Path(args.out).mkdir(parents=True, exist_ok=True)  # an OSError now, not after the trials
    rows, seconds = run_mechanics(args.seeds, args.level, args.abstraction, args.workers)
    table = markdown(summarise(rows), draw_curve(rows), level.name, args.abstraction,
                     args.seeds, seconds)
    write_results(Path(args.out), rows, summarise(rows), table)
    print(table, end="")
    print(f"stealth: wrote {Path(args.out) / 'mechanics.md'}, mechanics.csv and "
          f"mechanics_trials.csv", file=sys.stderr)
    return 0


__all__ = ["cmd_mechanics", "draw_curve", "refuse_arguments", "run_jobs", "run_mechanics",
           "summarise"]
