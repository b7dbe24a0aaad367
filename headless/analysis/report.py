"""Reports of a results directory (``stealth report DIR``): the paper's Table 3, heatmaps,
the aggregate figure, a flat CSV of every trial and a README.

Everything is written into DIR next to ``results.sqlite``:

* ``trials.csv`` — one row per finished trial (identity, seed, config hash, every metric,
  ``wall_time`` last);
* ``table.md`` / ``table.csv`` — paper Table 3: per abstraction, guard mode and player
  policy, mean ± std and a 95 % bootstrap confidence interval of the mean of each metric;
* ``heatmaps/{level}_{abstraction}_{mode}_{visit,attack}.csv`` — summed per-node visit and
  attack counts; ``heatmaps/{level}_{abstraction}_{visit,attack}.{png,svg}`` — the modes
  side by side on one colour scale;
* ``aggregate_{abstraction}.{png,svg}`` — the paper's "Aggregated performance" bar figure,
  with the paper's values overlaid when the design is the paper's;
* ``factors.{md,csv}``, ``factors/*/table.md``, ``factor_*.png`` — only for a design with
  factors (:mod:`headless.analysis.factor_report`);
* ``sessions.md`` / ``sessions.csv`` — only for recorded play sessions
  (:mod:`headless.sessions.report`);
* ``failed.csv`` — only when some trial failed;
* ``README.md`` — what the files are and where our metrics differ from the paper's.

This module orchestrates: statistics in :mod:`headless.analysis.stats`, Table 3 and ``trials.csv`` in
:mod:`headless.analysis.tables`, heatmaps in :mod:`headless.analysis.heatmaps`, the aggregate figure in
:mod:`headless.analysis.figures`, the README in :mod:`headless.analysis.readme`; the metrics themselves come
from the registry :mod:`game.metrics`. matplotlib is imported lazily and drawn through
``Figure`` (no pyplot, no global backend switch), so reports work on headless machines.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path
from typing import Any

from navmesh.level import register_zone_kind

from ..outputs.clobber import plugin_files, refuse_inputs_all
from ..errors import UserError
from .factor_report import write_factor_report
from .figures import FORMATS, write_aggregate
from .heatmaps import HeatSums, figure_count, write_heatmaps
from .paper import is_paper_design, paper_table3
from ..progress import Progress
from .readme import metric_rules, readme
from ..sessions.report import write_session_report
from .stats import BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED, Stat, bootstrap_ci, summarise
from ..store import IDENTITY, STORE_NAME, ResultStore
from .tables import metric_value, table_columns, table_rows, write_table, write_trials_csv

__all__ = [
    "BOOTSTRAP_RESAMPLES",
    "BOOTSTRAP_SEED",
    "Stat",
    "bootstrap_ci",
    "cmd_report",
    "metric_value",
    "summarise",
    "table_columns",
    "table_rows",
    "write_report",
    "write_trials_csv",
]


def write_report(directory: str | Path, *, figures: bool = True,
                 progress: bool = False) -> list[Path]:
    """Write every report file into ``directory`` (which holds ``results.sqlite``).

    ``figures=False`` skips the figures (the CSVs and Markdown are still written);
    ``progress`` shows a progress bar of the figures on stderr. Returns the paths written.
    """
    directory = Path(directory)
    store_path = directory / STORE_NAME
    if not store_path.is_file():
        raise UserError(f"{directory}: no {STORE_NAME} here (run `stealth run --out "
                        f"{directory}` first)")
    try:
        with ResultStore(store_path, readonly=True) as store:
            meta = store.meta()
            trials, heat = [], HeatSums()
            for trial in store.trials(heatmaps=True):
                visits, attacks = trial.pop("visits"), trial.pop("attacks")
                trials.append(dict(trial))
                heat.add(trial, visits, attacks)
            failures = list(store.trials(failed=True))
    except Exception as error:
        raise UserError(f"{store_path}: cannot read the results store ({error})") from None
    if not trials:
        raise UserError(f"{store_path}: no finished trials yet"
                        + (f" ({len(failures)} failed)" if failures else ""))

    design = _design(meta, store_path)
    _register_stored_zone_kinds(meta, design, store_path)
    refuse_inputs_all("report", [directory / name for name in _FIXED_OUTPUTS],
                      [*{t.get("level") for t in trials}, *_plugin_files(design)])
    written: list[Path] = []
    path = directory / "trials.csv"
    write_trials_csv(trials, path)
    written.append(path)

    rows = table_rows(trials, design.get("abstractions"))
    rules = metric_rules(design)
    write_table(rows, directory, len(trials), rules["coverage"], rules["partition_coverage"])
    written += [directory / "table.md", directory / "table.csv"]

    failed_path = directory / "failed.csv"
    if failures:
        with failed_path.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["key", *IDENTITY, "error"])
            for f in failures:
                writer.writerow([f["key"], *(f[c] for c in IDENTITY), f["error"]])
        written.append(failed_path)
    elif failed_path.exists():
        failed_path.unlink()

    written += write_factor_report(trials, directory, design.get("abstractions"),
                                   figures=figures)
    written += write_session_report(trials, directory)
    abstractions = len(dict.fromkeys(r["abstraction"] for r in rows))
    bar = Progress(figure_count(heat) + abstractions, sys.stderr,
                   enabled=progress and figures, unit="figures")
    written += write_heatmaps(heat, directory, figures=figures, tick=lambda: bar.update(1))
    if figures:
        paper = paper_table3() if is_paper_design(design) else None
        written += write_aggregate(rows, directory, paper)
        bar.update(abstractions)
    bar.close()

    path = directory / "README.md"
    path.write_text(readme(directory, meta, len(trials), heat.skipped, len(failures),
                           written + [path]), encoding="utf-8")
    written.append(path)
    return written


_FIXED_OUTPUTS = ("trials.csv", "table.md", "table.csv", "failed.csv", "README.md",
                  "factors.md", "factors.csv", "sessions.md", "sessions.csv")


def _plugin_files(design: dict[str, Any]) -> list[str]:
    stimuli = design.get("stimuli", [])
    return plugin_files(s for s in stimuli if isinstance(s, str)) if isinstance(stimuli, list) else []


def _design(meta: dict[str, str], store_path: Path) -> dict[str, Any]:
    """The store's design (``meta.design``): a JSON object, or one line naming the store."""
    try:
        design = json.loads(meta.get("design", "{}"))
    except ValueError:
        raise UserError(f"{store_path}: meta.design is not JSON") from None
    if not isinstance(design, dict):
        raise UserError(f"{store_path}: meta.design is {type(design).__name__}, not an object")
    return design


MAX_ZONE_KINDS = 256
"""Most zone kinds a store may name (a hostile store must not make the report crawl)."""


def _register_stored_zone_kinds(meta: dict[str, str], design: dict[str, Any],
                                store_path: Path) -> None:
    """Let the levels use the zone kinds the sweep stored (``meta.zone_kinds``, data).

    A report never imports the plugins a store names: a results folder shared with a
    ``.py`` inside must not run it. A store written before the kinds were stored reports
    without them (a level using a plugin's zone kind then has no heatmap), after one note.
    """
    stored = meta.get("zone_kinds")
    if stored is None:
        if design.get("stimuli"):
            print(f"stealth: note: {store_path} predates stored zone kinds; its plugins are "
                  "not imported, so levels with their zones get no heatmap", file=sys.stderr)
        return
    try:
        kinds = json.loads(stored)
        if not isinstance(kinds, list):
            raise ValueError(f"a {type(kinds).__name__}")
        if len(kinds) > MAX_ZONE_KINDS:
            raise ValueError(f"{len(kinds)} kinds, more than {MAX_ZONE_KINDS}")
        for kind in kinds:
            register_zone_kind(kind)
    except ValueError as error:
        raise UserError(f"{store_path}: meta.zone_kinds is not a list of zone kinds ({error})"
                        ) from None


def cmd_report(args: argparse.Namespace) -> int:
    """``stealth report DIR``: write the report files into DIR and list them on stderr."""
    directory = Path(args.dir)
    if not directory.is_dir():
        raise UserError(f"{directory}: no such results directory")
    written = write_report(directory, progress=True)
    shown = sum(1 for p in written if p.suffix == f".{FORMATS[0]}")
    print(f"stealth: wrote {len(written)} files ({shown} figures, as "
          f"{' and '.join(FORMATS)}) into {directory}; "
          f"start with {directory / 'README.md'}", file=sys.stderr)
    return 0
