"""The README of a results directory: what each file is and where our metrics differ.

The metric table is generated from the metric registry (:mod:`game.metrics`): one line per
Table 3 column with its scenario and definition.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

from game.config import Config
from game.metrics import registered_metrics

from .paper import is_paper_design
from .stats import BOOTSTRAP_RESAMPLES, BOOTSTRAP_SEED
from ..store import STORE_NAME
from .tables import table_columns

__all__ = ["metric_rules", "readme"]


def metric_rules(design: Mapping[str, object]) -> dict[str, str]:
    """The ``[metrics]`` keys (SPEC §11) a design's trials ran with: its ``set`` or the
    defaults."""
    fixed = design.get("set") or {}
    assert isinstance(fixed, Mapping)
    defaults = Config.defaults().section("metrics")
    return {name: str(fixed.get(f"metrics.{name}", value)) for name, value in defaults.items()}


_COVERAGE = {
    "visited": "* **Coverage is a true fraction in [0, 1].** The paper reports partition coverage "
               "above 1 (e.g. PF 1.72), which cannot be a fraction of nodes; ours counts each node "
               "once, so partition and grid coverage are on the same scale but not comparable to "
               "the paper's partition column.",
    "seen": "* **Coverage is the fraction of nodes seen** (`metrics.coverage = seen`): inside "
            "some guard's view at an AI tick, in [0, 1].",
    "per_guard": "* **Coverage is summed over guards** (`metrics.coverage = per_guard`): each "
                 "guard's fraction of nodes entered, summed, so it can exceed 1 as the paper's "
                 "partition column does.",
    "area": "* **Coverage is the fraction of the walkable area entered** (`metrics.coverage = "
            "area`): nodes weighted by their area, in [0, 1].",
    "seen_area": "* **Coverage is the fraction of the walkable area seen** (`metrics.coverage = "
                 "seen_area`): nodes inside some guard's view at an AI tick, weighted by their "
                 "area, in [0, 1].",
    "seen_per_guard": "* **Coverage is summed over guards' views** (`metrics.coverage = "
                      "seen_per_guard`): each guard's fraction of nodes it saw at an AI tick, "
                      "summed, so it can exceed 1 as the paper's partition column does.",
}
#: the columns of every definition (game.metrics)
_DEFINED = ("coverage_", "backtracks_", "dist_")
_DISTANCE = {
    "path": "* Distances are shortest-path distances on the node graph in world units (1 unit = 1 "
            "grid cell), on both abstractions.",
    "euclidean": "* Distances are straight-line distances between the player's and the nearest "
                 "guard's bodies in world units (`metrics.distance = euclidean`).",
}


def readme(directory: Path, meta: Mapping[str, str], done: int, skipped_heat: int, failed: int,
           files: Sequence[Path]) -> str:
    """The README text: design, files, metrics, differences from the paper."""
    design = json.loads(meta.get("design", "{}"))
    total = meta.get("total_trials", "?")
    names = sorted(str(p.relative_to(directory)) for p in files)
    heat = [n for n in names if n.startswith("heatmaps/")]
    lines = [
        f"# Results: preset `{meta.get('preset_name', '?')}`",
        "",
        f"{done} of {total} trials finished" + (f", {failed} failed" if failed else "")
        + f" (config hash `{meta.get('config_hash', '?')}`). Levels: "
        f"{', '.join(design.get('level_names', []))}; abstractions: "
        f"{', '.join(design.get('abstractions', []))}; guard modes: "
        f"{', '.join(design.get('guards', []))}; player policies: "
        f"{', '.join(design.get('players', []))}; scenarios: "
        f"{', '.join(design.get('scenarios', []))}; {len(design.get('seeds', []))} seeds; "
        f"root seed {design.get('root_seed', 0)}; overrides: "
        f"{json.dumps(design.get('set', {})) if design.get('set') else 'none'}.",
        "",
        "Regenerate with `stealth report " + str(directory) + "`; an unfinished sweep is resumed "
        "by running the same `stealth run` command again (finished trials are skipped).",
        "",
        "## Files",
        "",
        "| file | contents |",
        "|---|---|",
        f"| `{STORE_NAME}` | the store: one row per trial (SQLite; its tables: "
        "`python -m pydoc headless.store`, shipped with the package) |",
        "| `trials.csv` | one row per finished trial: identity, seed, config hash, every "
        "metric, `wall_time` (s) last |",
        "| `table.md`, `table.csv` | paper Table 3: mean ± std and 95 % bootstrap CI per "
        "abstraction × guard mode × player policy (`table.csv` also has n per cell) |",
    ]
    paper = is_paper_design(design)
    rules = metric_rules(design)
    for name in names:
        if name.startswith("aggregate_"):
            lines.append(f"| `{name}` | the paper's *Aggregated performance* figure: bars "
                         "(mean) with 95 % bootstrap CI whiskers per guard mode × policy"
                         + ("; black diamonds: the paper's Table 3 values" if paper else "")
                         + " |")
    if heat:
        lines.append(f"| `heatmaps/` ({len(heat)} files) | `{{level}}_{{abstraction}}_{{mode}}_"
                     "{visit,attack}.csv`: per-node counts summed over every trial of "
                     "that level, abstraction and guard mode (all player policies, scenarios "
                     "and seeds). Grid CSV: rows × cols matrix, blank = wall. Partition CSV: "
                     "`triangle,x,y,value` per navmesh triangle (centroid). "
                     "`{level}_{abstraction}_{visit,attack}.png/.svg`: the guard modes side "
                     "by side on one colour scale (log when the counts span two decades or "
                     "more); light grey = no events. |")
    lines.append("| | Each guard mode has one colour in every figure (PotentialField blue, "
                 "RandomWalk orange, FSM green, Staleness red, Cheat purple). |")
    if "sessions.md" in names:
        lines.append("| `sessions.md`, `sessions.csv` | recorded play sessions (`player = human`): "
                     "outcome, stars, ratings, and human against the policies on the same "
                     "seeds |")
    if failed:
        lines.append("| `failed.csv` | trials that raised: identity and the error text |")
    lines += [
        "",
        "## Metrics",
        "",
        "| column | trials | definition |",
        "|---|---|---|",
        *(f"| {c.title} | {c.scenario} | {c.metric.definition} |" for c in table_columns()),
        "",
        "`trials.csv` also has every definition of the keyed metrics (SPEC §11; the keys "
        f"here: {', '.join(f'`metrics.{k} = {v}`' for k, v in rules.items())}): "
        + "; ".join(f"`{m.name}` = {m.definition}" for m in registered_metrics()
                    if m.column is None and m.name.startswith(_DEFINED)) + ".",
        "",
        "Each cell: mean ± sample standard deviation (ddof = 1) [95 % percentile-bootstrap "
        f"confidence interval of the mean, {BOOTSTRAP_RESAMPLES} resamples, generator "
        f"`PCG64(SeedSequence([{BOOTSTRAP_SEED}, crc32(label)]))`, label = "
        "`abstraction/guards/player/column`]. Levels and seeds are pooled, as in the paper.",
        "",
        "Heatmap units: *visit* = number of times a guard entered the node; *attack* = "
        "guard-seconds during which a guard was in attack range of the player while the player "
        "stood on the node (= HP the player lost there).",
        "",
        "## Where these numbers differ from the paper",
        "",
        _COVERAGE.get(rules["coverage"], _COVERAGE["visited"]),
        *(() if rules.get("partition_coverage", "same") in ("same", rules["coverage"]) else (
            "* **The partition has its own coverage reading** (`metrics.partition_coverage = "
            f"{rules['partition_coverage']}`; the grid's is the line above), the column "
            f"`coverage_{rules['partition_coverage']}` of trials.csv.",)),
        "* CaptureTime and FirstDetectTime are censored at the trial duration (see above), not "
        "averaged over the trials where the event happened.",
        _DISTANCE.get(rules["distance"], _DISTANCE["path"]),
        "* The paper gives mean ± std only; the bootstrap intervals are ours.",
    ]
    if skipped_heat:
        lines += ["", f"{skipped_heat} trials had no usable per-node counts and are not "
                      "in the heatmaps."]
    return "\n".join(lines) + "\n"
