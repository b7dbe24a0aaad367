"""Played sessions in a report (``stealth report DIR`` of a ``stealth play --record DIR``).

A recorded session (``player = "human"``, :mod:`game.record`) stores its outcome as extra
metrics: ``outcome`` (``won``, ``caught``, ``survived``, ``time up``, or ``restarted`` /
``left`` / ``quit`` for a game abandoned after the first move), ``won``, ``collected``,
``collectibles`` and the optional ratings ``rating_challenge``, ``rating_fairness``,
``rating_naturalness`` (1–5). ``trials.csv`` has them as columns already (one per extra
metric); this module adds, only when the store holds sessions:

* ``sessions.csv`` — one row per session: identity, outcome, stars, ratings, and every
  Table 3 column of its scenario beside the mean of the comparison policies' trials on the
  same level, abstraction, guards, scenario and seed;
* ``sessions.md`` — per level, abstraction, guard mode and scenario: sessions, wins,
  outcomes, stars and mean ratings, then human against MaxMin / SafetyGraph on the same
  seeds (the Table 3 columns of that scenario).

A store without sessions gets neither file, so a paper report is unchanged.
"""

from __future__ import annotations

import csv
import json
import math
import statistics
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from game.metrics import TableColumn
from game.record import HUMAN, QUESTIONS

from ..analysis.tables import PLAYER_NAMES, csv_value, label, metric_value, table_columns

__all__ = ["SESSION_METRICS", "session_rows", "write_session_report"]

#: The extra metrics of a recorded session, in the order the report shows them.
SESSION_METRICS: tuple[str, ...] = ("outcome", "won", "collected", "collectibles",
                                    *(name for name, _ in QUESTIONS))

_Group = tuple[str, str, str, str]  # level, abstraction, guards, scenario


def _extra(trial: Mapping[str, Any], name: str) -> Any:
    return trial.get("extra_metrics", {}).get(name)


def _group(trial: Mapping[str, Any]) -> _Group:
    return (trial["level"], trial["abstraction"], trial["guards"], trial["scenario"])


def _duration(trial: Mapping[str, Any]) -> float:
    from game.config import Config

    return float(Config.load(dict(trial["overrides"]))["world.duration"])


def _columns(scenario: str) -> list[TableColumn]:
    return [c for c in table_columns() if c.scenario == scenario]


def _value(trial: Mapping[str, Any], column: TableColumn) -> float | None:
    return metric_value(trial, column, _duration(trial))


def _mean(values: Sequence[float | None]) -> float | None:
    kept = [v for v in values if v is not None and math.isfinite(v)]
    return statistics.fmean(kept) if kept else None


def session_rows(trials: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One flat row per session (``sessions.csv``): identity, session metrics, and for each
    Table 3 column of its scenario the session's value and the policies' mean on its seed."""
    sessions = [t for t in trials if t["player"] == HUMAN]
    policies: dict[tuple[_Group, int], dict[str, list[Mapping[str, Any]]]] = {}
    for t in trials:
        if t["player"] != HUMAN:
            policies.setdefault((_group(t), int(t["seed"])), {}).setdefault(t["player"], []).append(t)
    rows = []
    for s in sessions:
        row: dict[str, Any] = {"key": s["key"], "level": s["level"],
                               "abstraction": s["abstraction"], "guards": s["guards"],
                               "scenario": s["scenario"], "seed": s["seed"]}
        row.update({name: _extra(s, name) for name in SESSION_METRICS})
        others = policies.get((_group(s), int(s["seed"])), {})
        for column in _columns(s["scenario"]):
            row[column.name] = _value(s, column)
            for player in sorted(others):
                row[f"{player}_{column.name}"] = _mean([_value(t, column) for t in others[player]])
        rows.append(row)
    return rows


def _fmt(value: float | None, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _summary(sessions: Sequence[Mapping[str, Any]]) -> list[str]:
    lines = ["| level | abstraction | guards | scenario | sessions | won | outcomes | stars "
             "| " + " | ".join(name.removeprefix("rating_") for name, _ in QUESTIONS) + " |",
             "|---|---|---|---|---:|---:|---|---:|" + "---:|" * len(QUESTIONS)]
    groups: dict[_Group, list[Mapping[str, Any]]] = {}
    for s in sessions:
        groups.setdefault(_group(s), []).append(s)
    for (level, abstraction, guards, scenario), rows in sorted(groups.items()):
        won = sum(1 for s in rows if _extra(s, "won"))
        outcomes = Counter(str(_extra(s, "outcome") or "?") for s in rows)
        collected = sum(int(_extra(s, "collected") or 0) for s in rows)
        offered = sum(int(_extra(s, "collectibles") or 0) for s in rows)
        stars = f"{collected}/{offered}" if offered else "–"
        ratings = []
        for name, _ in QUESTIONS:
            given = [float(_extra(s, name)) for s in rows if _extra(s, name) is not None]
            ratings.append(f"{statistics.fmean(given):.1f} (n={len(given)})" if given else "–")
        text = ", ".join(f"{k} {n}" for k, n in sorted(outcomes.items()))
        lines.append(f"| {level} | {abstraction} | {guards} | {scenario} | {len(rows)} | "
                     f"{won} ({100 * won / len(rows):.0f} %) | {text} | {stars} | "
                     + " | ".join(ratings) + " |")
    return lines


def _comparison(trials: Sequence[Mapping[str, Any]], sessions: Sequence[Mapping[str, Any]]) -> list[str]:
    """Per group: human and each policy over the sessions' seeds, the scenario's columns."""
    lines: list[str] = []
    for group in sorted({_group(s) for s in sessions}):
        level, abstraction, guards, scenario = group
        seeds = {int(s["seed"]) for s in sessions if _group(s) == group}
        rows: dict[str, list[Mapping[str, Any]]] = {}
        for t in trials:
            if _group(t) == group and int(t["seed"]) in seeds:
                rows.setdefault(t["player"], []).append(t)
        columns = _columns(scenario)
        lines += ["", f"### {level}, {abstraction}, guards {guards}, {scenario} scenario "
                  f"(seeds {', '.join(map(str, sorted(seeds)))})", "",
                  "| player | trials | " + " | ".join(c.heading for c in columns) + " |",
                  "|---|---:|" + "---:|" * len(columns)]
        for player in sorted(rows, key=lambda p: (p != HUMAN, p)):
            cells = [_fmt(_mean([_value(t, c) for t in rows[player]])) for c in columns]
            lines.append(f"| {label(PLAYER_NAMES, player)} | {len(rows[player])} | "
                         + " | ".join(cells) + " |")
    return lines


def write_session_report(trials: Sequence[Mapping[str, Any]], directory: Path) -> list[Path]:
    """``sessions.csv`` and ``sessions.md`` when ``trials`` hold sessions (else nothing)."""
    sessions = [t for t in trials if t["player"] == HUMAN]
    paths = [directory / "sessions.csv", directory / "sessions.md"]
    if not sessions:
        for path in paths:
            if path.exists():
                path.unlink()
        return []
    rows = session_rows(trials)
    header = list(dict.fromkeys(k for row in rows for k in row))
    with paths[0].open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        for row in rows:
            writer.writerow([csv_value(row.get(k)) for k in header])
    text = ["# Played sessions", "",
            f"{len(sessions)} recorded session(s) (`player = human`, `stealth play --record`). "
            "*won*: every star picked up and the exit reached (`ESCAPED`; a level without "
            "an exit is survived, not won); *stars*: collectibles picked up / offered; ratings: mean of the "
            "1–5 answers to the post-game questions "
            + "; ".join(f"*{n.removeprefix('rating_')}*: {json.dumps(q)}" for n, q in QUESTIONS)
            + ". One row per session, with the policies on its seed beside it: "
            "`sessions.csv`.", "", *_summary(sessions), "",
            "## Human against the policies on the same seeds", "",
            "Means over the sessions and over the comparison trials (`stealth play --record` "
            "runs MaxMin and SafetyGraph once per session's level, guards, scenario and seed, "
            "in the same interactive world); Table 3's columns of the scenario.",
            *_comparison(trials, sessions), ""]
    paths[1].write_text("\n".join(text), encoding="utf-8")
    return paths
