"""``stealth mechanics --stimulus FILE.py:NAME``: a user's mechanic against a paired control.

Like the built-in mechanics (:mod:`headless.mechanics.measures`), every seed runs twice — the same
level, seed, guard spawns and generators (:func:`game.trial.trial_rngs` does not depend on
the stimuli), with the plugin (arm ``on``) and without it (``control``) — and every
measure is a mean with a 95 % bootstrap CI over seeds, the difference bootstrapped over
the pairs. What is measured is the plugin's declaration :attr:`ai.stimuli.Stimulus.measure`
(an :class:`ai.stimuli.Measure`: guard mode, player policy, scenario, config overrides and
the trial metrics with their intended directions); the default compares captures and
first detections. Writes the same three files as the built-in experiment.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ai import guard_mode, player_policy
from ai.stimuli import Measure, load_stimulus
from game.config import Config
from game.errors import ConfigError
from game.metrics import Metric, registered_metrics
from game.trial import TrialSpec, run_trial
from game.scenarios import SCENARIOS
from navmesh.level import load_level

from ..errors import UserError
from .measures import Row
from .run import effects_table, refuse_arguments, run_jobs, summarise, write_results

__all__ = ["check_measure", "measure_label", "plugin_measures", "run_plugin_job",
           "cmd_stimulus_effect"]


def check_measure(plugin: str, measure: Measure) -> dict[str, Metric]:
    """The metrics ``measure`` names, everything else it names checked (one-line errors)."""
    known = {m.name: m for m in registered_metrics()}
    metrics = {}
    for name, _ in measure.metrics:
        if name not in known:
            raise UserError(f"{plugin}: measure: unknown metric {name!r} "
                            f"(choose from {', '.join(known)})")
        metrics[name] = known[name]
    guard_mode(measure.guards)
    player_policy(measure.player)
    if measure.scenario not in SCENARIOS:
        raise UserError(f"{plugin}: measure: unknown scenario {measure.scenario!r} "
                        f"(choose from {', '.join(SCENARIOS)})")
    try:
        Config.load(dict(measure.overrides))
    except ConfigError as error:
        raise UserError(f"{plugin}: measure: overrides: {error}") from None
    return metrics


def measure_label(stimulus: str, metric: Metric, duration: float) -> str:
    """The row title of one measured metric, e.g. ``tripwire: captured (share)``."""
    if metric.kind == "bool":
        what = f"{metric.name} (share)"
    elif metric.censor:
        what = f"{metric.name}, {metric.unit} (censored at {duration:g})"
    else:
        what = f"{metric.name}, {metric.unit}" if metric.unit else metric.name
    return f"{stimulus}: {what}"


def _value(metric: Metric, value: Any, duration: float) -> float:
    if value is None:
        return duration if metric.censor else math.nan
    return float(value)


def plugin_measures(plugin: str) -> tuple[Measure, dict[str, int]]:
    """The plugin's :class:`Measure` and ``{row title: intended direction}``."""
    probe = load_stimulus(plugin)()
    measure = probe.measure
    metrics = check_measure(plugin, measure)
    duration = float(Config.load(dict(measure.overrides))["world.duration"])
    expected = {measure_label(probe.name, metrics[name], duration): direction
                for name, direction in measure.metrics}
    return measure, expected


def run_plugin_job(job: tuple[str, str, str, int]) -> list[Row]:
    """One (plugin, level, abstraction, seed): both arms. Top-level, picklable."""
    plugin, level, abstraction, seed = job
    probe = load_stimulus(plugin)()  # registers its zone kinds in this process first
    measure = probe.measure
    metrics = check_measure(plugin, measure)
    rows: list[Row] = []
    for arm, stimuli in (("on", (plugin,)), ("control", ())):
        spec = TrialSpec(level, abstraction, measure.guards, measure.player, measure.scenario,
                         seed, overrides=tuple(measure.overrides), stimuli=stimuli)
        row = run_trial(spec)
        duration = float(row["config"]["world.duration"])
        for name, _ in measure.metrics:
            metric = metrics[name]
            rows.append((measure_label(probe.name, metric, duration), seed, arm,
                         _value(metric, row["metrics"][name], duration)))
    return rows


def markdown(plugins: Sequence[str], measures: Sequence[Measure], summaries: Any, level: str,
             abstraction: str, seeds: int, seconds: float) -> str:
    """The effects table with a line saying what ran."""
    arms = "; ".join(f"{p}: {m.guards} guards, {m.player} player, {m.scenario} scenario"
                     + (", " + ", ".join(f"{k}={v}" for k, v in m.overrides) if m.overrides
                        else "")
                     for p, m in zip(plugins, measures))
    lines = [
        f"Level {level}, {abstraction}; {arms}; {seeds} paired seeds (with the stimulus vs "
        f"without it); mean [95 % bootstrap CI over seeds]; computed in {seconds:.0f} s.",
        "",
        *effects_table(summaries),
    ]
    return "\n".join(lines) + "\n"


def cmd_stimulus_effect(args: argparse.Namespace) -> int:
    """``stealth mechanics --stimulus ...``: measure each plugin, write the files, print."""
    refused = refuse_arguments(args)
    if refused is not None:
        return refused
    plugins = list(dict.fromkeys(args.stimulus))
    declared = [plugin_measures(p) for p in plugins]  # before the level: its zone kinds
    level = load_level(args.level)
    expected: dict[str, int] = {}
    for _, by_title in declared:
        expected.update(by_title)
    jobs = [(p, args.level, args.abstraction, s) for s in range(args.seeds) for p in plugins]
    rows, seconds = run_jobs(run_plugin_job, jobs, args.workers)
    summaries = summarise(rows, expected)
    table = markdown(plugins, [m for m, _ in declared], summaries, level.name,
                     args.abstraction, args.seeds, seconds)
    out = Path(args.out)
    write_results(out, rows, summaries, table)
    print(table, end="")
    print(f"stealth: wrote {out / 'mechanics.md'}, mechanics.csv and mechanics_trials.csv",
          file=sys.stderr)
    return 0
