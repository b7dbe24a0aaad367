"""Staleness as Al Enezi & Verbrugge's dynamic patrol (``staleness.model = "view"``), the
guards' sight that feeds it (game.guard_sight), and who investigates a sighting
(``fsm.investigate``). docs/ai.md "FSM and Staleness"."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pymunk
import pytest

from ai.baselines import FSMGuards, StalenessGuards
from ai.view import WorldView
from game.agents import build_space
from game.config import Config, ConfigError
from game.guard_sight import GuardSight
from game.senses import Senses
from game.trial import TrialSpec, run_trial
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import load_level


def open_grid(rows: int, cols: int) -> NodeGraph:
    return NodeGraph.from_grid(np.ones((rows, cols), dtype=bool), 1.0)


def view_of(graph: NodeGraph, guards: list[int], player: int, *, t: float = 0.0,
            sight: list[list[int]] | None = None, **fields: object) -> WorldView:
    view = WorldView.at_nodes(graph, guards, player, t=t, **fields)
    if sight is not None:
        view.guard_sight = tuple(np.array(s, dtype=np.int64) for s in sight)
    return view


# ---------------------------------------------------------------------------- sight


@pytest.mark.parametrize("name,abstraction", [("miami", "grid"), ("tlou", "partition")])
def test_guard_sight_is_the_worlds_vision_rule(name: str, abstraction: str) -> None:
    """Same nodes as asking Senses.perceives of every node (range by zone, cone, pymunk ray)."""
    level = load_level(name)
    graph = graph_for(level, abstraction, 0.3)
    senses = Senses(build_space(level), 90.0)
    reach = np.linspace(4.0, 9.0, graph.n)  # a range per node, as zones make it
    sight = GuardSight(graph, senses, reach, level.walls)
    rng = np.random.default_rng(3)
    seen_total = 0
    for k in rng.choice(graph.n, 40, replace=False):
        pos = (float(graph.positions[k, 0]), float(graph.positions[k, 1]))
        heading = float(rng.uniform(-np.pi, np.pi))
        expected = [j for j in range(graph.n) if senses.perceives(
            pos, heading, (float(graph.positions[j, 0]), float(graph.positions[j, 1])), reach[j])]
        assert sight.seen_by(pos, heading).tolist() == expected
        seen_total += len(expected)
    assert seen_total > 40  # the cones saw more than the guards' own nodes


def test_walls_block_the_sight() -> None:
    graph = open_grid(1, 6)
    wall = np.array([[[3.0, 0.0], [3.0, 1.0]]])
    sight = GuardSight(graph, Senses(pymunk.Space(), 90.0), np.full(6, 10.0), wall)
    assert sight.seen_by((0.5, 0.5), 0.0).tolist() == [0, 1, 2]
    assert sight.seen_by((5.5, 0.5), np.pi).tolist() == [3, 4, 5]
    assert sight.seen_by((2.5, 0.5), np.pi).tolist() == [0, 1, 2]  # facing away from the wall


# ---------------------------------------------------------------------------- view staleness


def test_view_staleness_resets_everything_a_guard_sees() -> None:
    graph = open_grid(1, 8)
    guards = StalenessGuards({"model": "view"})
    guards.reset(graph, np.random.default_rng(0), 2)
    guards.tick(view_of(graph, [0, 7], 3, sight=[[0, 1, 2], []]), 1.0)
    assert guards.staleness.tolist() == [0, 0, 0, 1, 1, 1, 1, 0]
    guards.tick(view_of(graph, [0, 7], 3, sight=[[], [5, 6, 7]]), 1.0)
    assert guards.staleness.tolist() == [0, 1, 1, 2, 2, 0, 0, 0]


def test_node_staleness_ignores_what_guards_see() -> None:
    graph = open_grid(1, 8)
    guards = StalenessGuards({"model": "node"})
    guards.reset(graph, np.random.default_rng(0), 1)
    assert not guards.wants_guard_sight() and StalenessGuards().wants_guard_sight()
    guards.tick(view_of(graph, [0], 3, sight=[[0, 1, 2]]), 1.0)
    assert guards.staleness.tolist() == [0, 1, 1, 1, 1, 1, 1, 1]


def test_view_target_trades_staleness_against_path_distance() -> None:
    graph = open_grid(1, 21)
    guards = StalenessGuards({"model": "view", "distance_weight": 0.5})
    guards.reset(graph, np.random.default_rng(0), 1)
    guards.staleness[:] = 10.0
    guards.staleness[20] = 14.0  # 4 s staler, 10 cells farther than node 10's neighbours
    guards.decide(0, view_of(graph, [10], 0))
    assert guards.guards[0].target in (9, 11)  # 10 - 0.5·1 beats 14 - 0.5·10
    guards.staleness[20] = 16.0  # now 16 - 5 = 11 > 9.5
    guards.guards[0].target = None
    guards.decide(0, view_of(graph, [10], 0))
    assert guards.guards[0].target == 20


def test_equally_stale_targets_are_drawn_with_the_seeded_generator() -> None:
    graph = open_grid(1, 21)
    picks = set()
    for seed in range(12):
        guards = StalenessGuards({"model": "view", "distance_weight": 0.0})
        guards.reset(graph, np.random.default_rng(seed), 1)
        guards.staleness[:] = 5.0
        guards.decide(0, view_of(graph, [10], 0))
        picks.add(guards.guards[0].target)
    assert len(picks) > 3 and 10 not in picks
    again = StalenessGuards({"model": "view", "distance_weight": 0.0})
    again.reset(graph, np.random.default_rng(0), 1)
    again.staleness[:] = 5.0
    first = StalenessGuards({"model": "view", "distance_weight": 0.0})
    first.reset(graph, np.random.default_rng(0), 1)
    first.staleness[:] = 5.0
    assert again.decide(0, view_of(graph, [10], 0)) == first.decide(0, view_of(graph, [10], 0))
    assert again.guards[0].target == first.guards[0].target


def test_guards_spread_their_targets() -> None:
    graph = open_grid(1, 30)
    guards = StalenessGuards({"model": "view", "distance_weight": 0.0, "spread_radius": 6.0})
    guards.reset(graph, np.random.default_rng(1), 2)
    guards.staleness[:] = 1.0
    guards.staleness[[25, 27]] = 9.0  # two stale spots close together
    guards.decide(0, view_of(graph, [0, 1], 29))
    guards.decide(1, view_of(graph, [0, 1], 29))
    first, second = guards.guards[0].target, guards.guards[1].target
    assert first in (25, 27)
    assert second is not None and abs(second - first) > 6  # not the spot beside the other's
    # with no room to spread, only the other's exact target is ruled out
    tight = StalenessGuards({"model": "view", "distance_weight": 0.0, "spread_radius": 100.0})
    tight.reset(graph, np.random.default_rng(1), 2)
    tight.staleness[:] = 1.0
    tight.staleness[[25, 27]] = 9.0
    tight.decide(0, view_of(graph, [0, 1], 29))
    tight.decide(1, view_of(graph, [0, 1], 29))
    assert {tight.guards[0].target, tight.guards[1].target} == {25, 27}


def test_a_target_in_sight_is_done() -> None:
    graph = open_grid(1, 12)
    guards = StalenessGuards({"model": "view"})
    guards.reset(graph, np.random.default_rng(0), 1)
    guards.staleness[:] = 3.0
    guards.staleness[11] = 30.0
    guards.decide(0, view_of(graph, [0], 5))
    assert guards.guards[0].target == 11
    guards.tick(view_of(graph, [4], 5, sight=[[4, 5, 6, 7, 8, 9, 10, 11]]), 1.0)
    assert guards.guards[0].target is None  # looked at from afar: the next decision picks anew
    guards.decide(0, view_of(graph, [4], 5))
    assert guards.guards[0].target in (0, 1, 2, 3)


# ---------------------------------------------------------------------------- investigate


@pytest.mark.parametrize("cls", [FSMGuards, StalenessGuards])
def test_local_investigate_reaches_only_guards_near_the_sighting(cls: type) -> None:
    graph = open_grid(1, 40)
    # 5·0.9^d ≥ 1 up to d = 15 hops from the sighting at node 21 (14 and 18 hops away)
    for rule, expected in (("team", ["investigate", "investigate"]),
                           ("local", ["investigate", "patrol"])):
        guards = cls({"investigate": rule, "model": "node"} if cls is StalenessGuards
                     else {"investigate": rule})
        guards.reset(graph, np.random.default_rng(0), 3)
        guards.tick(view_of(graph, [7, 39, 20], 21, seen_by=(2,), sighting=21), 1.0)
        assert [guards.state_name(0), guards.state_name(1)] == expected
        assert guards.state_name(2) == "chase"


def test_local_investigate_depth_follows_the_falloff() -> None:
    graph = open_grid(1, 40)
    guards = FSMGuards({"investigate": "local", "information_falloff": 0.5})
    guards.reset(graph, np.random.default_rng(0), 3)  # 5·0.5^d ≥ 1 up to d = 2
    guards.tick(view_of(graph, [18, 17, 30], 20, seen_by=(2,), sighting=20), 1.0)
    assert (guards.state_name(0), guards.state_name(1)) == ("investigate", "patrol")


# ---------------------------------------------------------------------------- config


def test_the_keys_are_declared_with_their_choices() -> None:
    config = Config.defaults()
    assert config["staleness.model"] == "view" and config["fsm.investigate"] == "team"
    assert Config.load(["staleness.model=node", "fsm.investigate=local"])["staleness.model"] == "node"
    for bad in ("staleness.model=seen", "fsm.investigate=all", "staleness.distance_weight=-1",
                "staleness.distance_weight=101", "fsm.information_falloff=1.5"):
        with pytest.raises(ConfigError):
            Config.load([bad])


def test_a_bad_model_on_the_command_line_is_one_line() -> None:
    done = subprocess.run([sys.executable, "-m", "headless.cli", "sim", "miami", "--guards",
                           "staleness", "--set", "staleness.model=vision"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith("stealth: error: ") and done.stderr.count("\n") == 1


# ---------------------------------------------------------------------------- paired trials


def test_view_staleness_differs_from_the_fsm_on_paired_seeds() -> None:
    """Same spawns (common random numbers), fixed-time grid trials against MaxMin: the view
    model covers more than the FSM's random patrol; the node rule hardly differs from it."""
    rows = {}
    for level in ("miami", "maze"):
        for seed in (0, 1, 2):
            for guards, over in (("fsm", ()), ("staleness", ()),
                                 ("staleness", (("staleness.model", "node"),))):
                spec = TrialSpec(level=level, guards=guards, player="maxmin", scenario="fixed",
                                 seed=seed, overrides=over)
                rows[level, seed, guards, bool(over)] = run_trial(spec)["metrics"]
    pairs = [(level, seed) for level in ("miami", "maze") for seed in (0, 1, 2)]
    view = np.array([rows[p + ("staleness", False)]["coverage"] - rows[p + ("fsm", False)]["coverage"]
                     for p in pairs])
    node = np.array([rows[p + ("staleness", True)]["coverage"] - rows[p + ("fsm", False)]["coverage"]
                     for p in pairs])
    assert view.mean() >= 0.05 and (view > 0).all()
    assert view.mean() > node.mean() + 0.05
    detect = [(rows[p + ("staleness", False)]["first_detect_time"],
               rows[p + ("fsm", False)]["first_detect_time"]) for p in pairs]
    assert sum(a != b for a, b in detect) >= len(pairs) // 2
