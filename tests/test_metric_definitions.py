"""The ``[metrics]`` keys (SPEC §11): every definition of coverage, backtracks and distance
is measured in every trial, the keyed columns follow the key, and no key changes the trace."""

from __future__ import annotations

import io
import json
import math
import sqlite3
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from game.config import Config
from game.metrics import RECENT_ENTRIES, Counters
from game.trial import TrialSpec, make_world, run_trial
from game.guard_sight import ViewCover, nodes_within
from headless.analysis.report import write_report
from headless.store import STORE_NAME, ResultStore
from headless.presets import load_preset
from headless.sweep import run_sweep

KEYS = {"coverage": ("visited", "seen", "per_guard"), "backtracks": ("targets", "entries"),
        "distance": ("path", "euclidean")}
KEYED = {"coverage": "coverage", "backtracks": "backtracks", "distance": "avg_guard_player_dist"}
COLUMN = {"visited": "coverage_visited", "seen": "coverage_seen", "per_guard": "coverage_per_guard",
          "targets": "backtracks_targets", "entries": "backtracks_entries", "path": "dist_path",
          "euclidean": "dist_euclidean"}


def _sim(level: str, abstraction: str, guards: str, *sets: str, seed: int = 0) -> dict[str, Any]:
    """One trial through the CLI, as the acceptance items state it."""
    command = [sys.executable, "-m", "headless.cli", "sim", level, "--guards", guards,
               "--abstraction", abstraction, "--scenario", "fixed", "--seed", str(seed), "--json"]
    for item in sets:
        command += ["--set", item]
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    metrics: dict[str, Any] = json.loads(done.stdout)["metrics"]
    return metrics


def _traced(spec: TrialSpec) -> tuple[str, Mapping[str, Any]]:
    handle = io.StringIO()
    row = run_trial(spec, trace=handle)
    return handle.getvalue(), row["metrics"]


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_a_metrics_key_changes_what_is_measured_never_the_trace(abstraction: str) -> None:
    base = dict(level="miami", abstraction=abstraction, guards="pf", player="maxmin",
                scenario="fixed", seed=3)
    trace, metrics = _traced(TrialSpec(**base, overrides=(("world.duration", 20.0),)))
    assert trace.count("\n") >= 20
    for key, values in KEYS.items():
        for value in values:
            overrides = (("world.duration", 20.0), (f"metrics.{key}", value))
            spec = TrialSpec(**base, overrides=overrides)
            other_trace, other = _traced(spec)
            assert other_trace == trace, f"metrics.{key} = {value} changed the trace"
            # every definition column is the same; the keyed column is the one named
            assert {k: v for k, v in other.items() if k != KEYED[key]} == {
                k: v for k, v in metrics.items() if k != KEYED[key]}
            assert other[KEYED[key]] == other[COLUMN[value]]


def test_seen_coverage_exceeds_visited_on_miami_grid_pf() -> None:
    seen = _sim("miami", "grid", "pf", "metrics.coverage=seen")
    visited = _sim("miami", "grid", "pf")
    assert seen["coverage"] == seen["coverage_seen"] > visited["coverage"]
    assert visited["coverage"] == visited["coverage_visited"]
    assert 0 < seen["coverage"] <= 1


def test_per_guard_coverage_is_at_least_visited_on_miami_partition() -> None:
    metrics = _sim("miami", "partition", "pf", "metrics.coverage=per_guard")
    assert metrics["coverage"] == metrics["coverage_per_guard"] >= metrics["coverage_visited"]
    assert metrics["coverage"] <= 3  # three guards, each at most every node


def test_euclidean_distance_is_at_most_the_path_distance_on_maze() -> None:
    metrics = _sim("maze", "grid", "pf", "metrics.distance=euclidean")
    assert metrics["avg_guard_player_dist"] == metrics["dist_euclidean"] <= metrics["dist_path"]
    assert metrics["dist_euclidean"] > 0


def test_backtracks_by_entries_runs_on_both_abstractions() -> None:
    grid = _sim("maze", "grid", "pf", "metrics.backtracks=entries")
    partition = _sim("maze", "partition", "pf", "metrics.backtracks=entries")
    assert grid["backtracks"] == grid["backtracks_entries"]
    assert partition["backtracks"] == partition["backtracks_entries"] > 0


def test_a_bad_metrics_value_is_one_line_and_exit_2() -> None:
    done = subprocess.run([sys.executable, "-m", "headless.cli", "sim", "maze", "--set",
                           "metrics.coverage=everything"], capture_output=True, text=True)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith("stealth: error: metrics.coverage")
    assert done.stderr.count("\n") == 1


# ---------------------------------------------------------------------- the counters
def test_an_entry_backtrack_is_a_node_among_the_guards_last_five_entries() -> None:
    m = Counters.for_nodes(10)
    for node in (0, 1, 0):          # straight back: one
        m.count_visit(node, guard=0)
    assert m.entry_backtracks == 1
    for node in (2, 3, 4, 5, 6):     # five new nodes push 0 and 1 out of guard 0's memory
        m.count_visit(node, guard=0)
    m.count_visit(1, guard=0)
    assert m.entry_backtracks == 1 and RECENT_ENTRIES == 5
    m.count_visit(6, guard=1)       # another guard's memory is its own
    assert m.entry_backtracks == 1
    m.count_visit(5, guard=0)       # 5 is among 0's last five (2..6, 1 -> 3, 4, 5, 6, 1)
    assert m.entry_backtracks == 2


def test_per_guard_coverage_sums_each_guards_share_and_may_exceed_one() -> None:
    m = Counters.for_nodes(4)
    for guard in range(3):
        for node in range(4):
            m.count_visit(node, guard)
    assert float(m.covered.mean()) == 1.0 and m.per_guard_coverage() == 3.0
    m2 = Counters.for_nodes(4)
    m2.count_visit(0, 0)
    m2.count_visit(1, 2)
    assert m2.per_guard_coverage() == 0.5 == float(m2.covered.mean())


def test_euclidean_samples_are_the_nearest_guard_and_skip_steps_without_guards() -> None:
    m = Counters.for_nodes(1)
    m.sample_euclidean((0.0, 0.0), [(3.0, 4.0), (6.0, 8.0)])
    m.sample_euclidean((0.0, 0.0), [])
    m.sample_euclidean((1.0, 1.0), [(1.0, 2.0)])
    assert m.mean_euclidean() == pytest.approx(3.0) and m.euclid_samples == 2
    assert Counters.for_nodes(1).mean_euclidean() is None


# ---------------------------------------------------------------------- the view cover
def _brute_seen(world: Any) -> np.ndarray:
    """Every node a guard perceives now by the world's one vision test, node by node."""
    out = np.zeros(world.graph.n, dtype=bool)
    reach = world.view_range * world.view_scale_at
    for g in world.guards:
        for k, (x, y) in enumerate(world.graph.positions.tolist()):
            if g.active and world.senses.perceives(g.pos, g.heading, (x, y), float(reach[k])):
                out[k] = True
    return out


@pytest.mark.parametrize("level,abstraction", [("maze", "grid"), ("tlou", "partition"),
                                                ("dishonored", "grid"), ("arkham", "partition")])
def test_seen_nodes_are_exactly_what_the_world_perceives(level: str, abstraction: str) -> None:
    world = make_world(TrialSpec(level=level, abstraction=abstraction, guards="pf",
                                 player="maxmin", scenario="fixed", seed=2))
    union = np.zeros(world.graph.n, dtype=bool)
    for _ in range(6):  # six AI ticks: the world's cover (its walls kept) and a fresh one
        for _ in range(world.steps_per_tick):
            world.step()
        now = _brute_seen(world)
        union |= now
        fresh = ViewCover(world.graph, world.senses, world.view_range * world.view_scale_at)
        fresh.observe(world.guards)
        assert now.any() and np.array_equal(fresh.seen, now)
        assert world.m.view_cover is not None and np.array_equal(world.m.view_cover.seen, union)
    assert (world.m.view_cover.blocker >= 0).any()  # occluded nodes were met and kept


@pytest.mark.parametrize("level,abstraction", [("maze", "grid"), ("miami", "partition")])
def test_nodes_within_is_a_superset_of_the_disc(level: str, abstraction: str) -> None:
    world = make_world(TrialSpec(level=level, abstraction=abstraction))
    graph, rng = world.graph, np.random.default_rng(0)
    lo, hi = graph.positions.min(axis=0) - 3, graph.positions.max(axis=0) + 3
    for _ in range(50):
        x, y = rng.uniform(lo, hi)
        radius = float(rng.uniform(0, 10))
        d = np.hypot(graph.positions[:, 0] - x, graph.positions[:, 1] - y)
        inside = set(np.flatnonzero(d <= radius).tolist())
        assert inside <= set(nodes_within(graph, float(x), float(y), radius).tolist())


def test_seen_coverage_grows_with_the_view_range() -> None:
    base = dict(level="maze", guards="random", player="maxmin", scenario="fixed", seed=1)
    blind = run_trial(TrialSpec(**base, overrides=(("world.view_range", 0.0),)))["metrics"]
    short = run_trial(TrialSpec(**base, overrides=(("world.view_range", 3.0),)))["metrics"]
    full = run_trial(TrialSpec(**base))["metrics"]
    # range 0: only the nodes whose centre a guard stood exactly on at a tick
    assert blind["coverage_seen"] <= blind["coverage_visited"]
    assert blind["coverage_seen"] < short["coverage_seen"] < full["coverage_seen"] <= 1


# ---------------------------------------------------------------------- stores and hashes
def test_metrics_keys_at_their_default_leave_the_config_hash_as_before() -> None:
    default = Config.defaults()
    assert Config.load(["metrics.coverage=visited"]).hash() == default.hash()
    assert Config.load(["metrics.coverage=seen"]).hash() != default.hash()
    assert Config.load(["metrics.distance=euclidean"]).hash() != Config.load(
        ["metrics.backtracks=entries"]).hash()


PRESET = """
levels = ["maze"]
abstractions = ["partition"]
guards = ["random"]
players = ["evade"]
scenarios = ["capture", "fixed"]
seeds = 2

[set]
"world.duration" = 4.0
"""


def test_an_older_store_without_the_definition_columns_reports_and_resumes(tmp_path: Path) -> None:
    (tmp_path / "tiny.toml").write_text(PRESET)
    preset = load_preset(str(tmp_path / "tiny.toml"))
    out = tmp_path / "out"
    run_sweep(preset, out, workers=1)
    path = out / STORE_NAME
    db = sqlite3.connect(path)  # as a store written before the definitions existed
    db.execute("DELETE FROM trials WHERE seed = (SELECT MAX(seed) FROM trials)")
    for column in COLUMN.values():
        db.execute(f"ALTER TABLE trials DROP COLUMN {column}")
    db.commit()
    db.close()
    write_report(out, figures=False)
    header = (out / "trials.csv").read_text().splitlines()[0].split(",")
    assert "coverage_seen" in header and "coverage" in header
    run_sweep(preset, out, workers=1)  # resumes: same config hash, the columns come back
    with ResultStore(path, readonly=True) as store:
        trials = list(store.trials())
    assert len(trials) == 4
    assert sum(t["coverage_seen"] is None for t in trials) == 2   # the old rows
    assert all(t["coverage_visited"] == t["coverage"] for t in trials
               if t["coverage_visited"] is not None)
    assert all(not math.isnan(t["coverage"]) for t in trials)


def test_the_report_names_the_coverage_and_distance_definition_in_use(tmp_path: Path) -> None:
    from headless.analysis.readme import metric_rules
    from headless.analysis.tables import write_table

    assert metric_rules({}) == {"coverage": "visited", "partition_coverage": "same",
                                "backtracks": "targets", "distance": "path"}
    rules = metric_rules({"set": {"metrics.coverage": "per_guard", "metrics.distance": "euclidean"}})
    assert rules == {"coverage": "per_guard", "partition_coverage": "same",
                     "backtracks": "targets", "distance": "euclidean"}
    write_table([], tmp_path, 0)
    assert "CoverageRate is a true fraction in [0, 1]" in (tmp_path / "table.md").read_text()
    write_table([], tmp_path, 0, "per_guard")
    assert "can exceed 1" in (tmp_path / "table.md").read_text()
