"""MaxMin and SafetyGraph players on hand-built WorldViews over small grid graphs."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from ai import make_player_policy, search_kernels
from ai.players import MaxMinPlayer, SafetyGraphPlayer, move_sequences
from ai.view import PlayerPolicy, WorldView
from navmesh.graph import NodeGraph

POLICIES = ["maxmin", "safetygraph"]


def make_view(
    graph: NodeGraph, guards: Sequence[int], player: int, active: Sequence[bool] | None = None
) -> WorldView:
    return WorldView.at_nodes(graph, guards, player, active=active)


def policy(name: str, graph: NodeGraph, seed: int = 0, **params: object) -> PlayerPolicy:
    player = make_player_policy(name, params)
    player.reset(graph, np.random.default_rng(seed))
    return player


def open_grid(rows: int, cols: int) -> NodeGraph:
    return NodeGraph.from_grid(np.ones((rows, cols), dtype=bool), 1.0)


@pytest.mark.parametrize("name", POLICIES)
def test_player_runs_down_a_corridor_away_from_the_guard(name: str) -> None:
    graph = open_grid(1, 10)
    assert policy(name, graph).decide(make_view(graph, [2], 5)) == 6


@pytest.mark.parametrize("name", POLICIES)
def test_player_moves_away_from_a_nearby_guard_in_the_open(name: str) -> None:
    # every player cell of the central 5×5 of a 15×15 room, every guard 2..5 steps away:
    # there is always room to run, and the player's move always gains distance
    graph = open_grid(15, 15)
    player = policy(name, graph)
    checked = 0
    for node in (int(graph.cell_node[r, c]) for r in range(5, 10) for c in range(5, 10)):
        for guard in np.flatnonzero((graph.hops_from(node) >= 2) & (graph.hops_from(node) <= 5)):
            chosen = player.decide(make_view(graph, [int(guard)], node))
            assert graph.hops_between(node, chosen) == 1
            assert graph.dist_between(guard, chosen) > graph.dist_between(guard, node)
            checked += 1
    assert checked == 1400


@pytest.mark.parametrize("name", POLICIES)
def test_player_escapes_a_guard_walking_at_it(name: str) -> None:
    graph = open_grid(7, 12)
    player = policy(name, graph)
    guard, node = int(graph.cell_node[3, 0]), int(graph.cell_node[3, 3])
    for _ in range(6):  # the guard walks straight at the player, one cell per player move
        new = player.decide(make_view(graph, [guard], node))
        assert graph.dist_between(guard, new) >= graph.dist_between(guard, node)
        node = new
        guard = graph.step_towards(guard, node, 1.01)
    assert graph.dist_between(guard, node) >= 3


@pytest.mark.parametrize("name", POLICIES)
def test_player_is_deterministic_for_a_seed(name: str) -> None:
    graph = open_grid(8, 8)

    def run(seed: int) -> list[int]:
        player = policy(name, graph, seed)
        rng = np.random.default_rng(3)
        return [
            player.decide(make_view(graph, rng.choice(graph.n, 3, replace=False).tolist(), int(p)))
            for p in rng.choice(graph.n, 30)
        ]

    assert run(4) == run(4)


@pytest.mark.parametrize("name", POLICIES)
def test_inactive_guards_are_ignored(name: str) -> None:
    graph = open_grid(1, 10)
    # the guard at 8 is down; only the one at 2 counts, so the player still runs right
    assert policy(name, graph).decide(make_view(graph, [2, 8], 5, active=[True, False])) == 6
    assert policy(name, graph).decide(make_view(graph, [2], 5, active=[False])) == 5


def test_maxmin_enumerates_every_sequence_with_staying_put() -> None:
    graph = open_grid(7, 7)
    sequences = move_sequences(graph, 3)
    centre = int(graph.cell_node[3, 3])
    paths = sequences.from_node(centre)
    assert paths.shape == (125, 3)  # 5 options (4 neighbours + stay) per step
    assert np.all(graph.hops_between(centre, paths[:, 0]) <= 1)
    assert np.all(graph.hops_between(paths[:, 0], paths[:, 1]) <= 1)
    assert len({tuple(p) for p in paths.tolist()}) == 125
    # from a corner: stay, right, down; then 3 + 4 + 4 options
    assert move_sequences(open_grid(5, 5), 2).from_node(0).shape == (11, 2)


def test_maxmin_looks_ahead_out_of_a_dead_end() -> None:
    # a corridor (row 0) with a one-cell stub below column 5; the guard comes from the right.
    # One step ahead, "left" and "into the stub" are equally far from the guard; three
    # steps ahead the stub is a trap.
    occupancy = np.zeros((2, 10), dtype=bool)
    occupancy[0, :] = True
    occupancy[1, 5] = True
    graph = NodeGraph.from_grid(occupancy, 1.0)
    guard, node = int(graph.cell_node[0, 8]), int(graph.cell_node[0, 5])
    stub, left = int(graph.cell_node[1, 5]), int(graph.cell_node[0, 4])
    assert graph.dist_between(guard, stub) == graph.dist_between(guard, left)
    for seed in range(5):
        assert policy("maxmin", graph, seed).decide(make_view(graph, [guard], node)) == left
    greedy = {
        policy("maxmin", graph, seed, maxmin_depth=1).decide(make_view(graph, [guard], node))
        for seed in range(12)
    }
    assert greedy == {stub, left}


def test_safetygraph_goal_is_the_safest_place_it_reaches_first() -> None:
    graph = open_grid(1, 10)
    player = policy("safetygraph", graph)
    assert isinstance(player, SafetyGraphPlayer)
    player.decide(make_view(graph, [2], 5))
    # S = T_g − T_p = 1.5 s for every node right of the player; the farthest from the guard wins
    assert player.last_goal == 9
    assert player.last_safety is not None
    assert player.last_safety[5:] == pytest.approx([1.5] * 5)
    assert player.last_safety[3] == pytest.approx(-0.5)


def test_safetygraph_route_detours_around_unsafe_nodes() -> None:
    # a ring: the top row is the short way from the player (left end) to the goal (right
    # end), but the guard stands on it; the bottom way is 4 cells longer
    occupancy = np.ones((3, 9), dtype=bool)
    occupancy[1, 1:8] = False
    graph = NodeGraph.from_grid(occupancy, 1.0)
    node, goal, guard = (int(graph.cell_node[0, c]) for c in (0, 8, 4))
    player = policy("safetygraph", graph)
    assert isinstance(player, SafetyGraphPlayer)
    safety, _ = player.safety(node, np.array([guard]))
    route = player.route(node, goal, safety)
    assert len(route) == 13 and route[1] == int(graph.cell_node[1, 0])  # down and around
    plain = policy("safetygraph", graph, safety_penalty=0.0)
    assert isinstance(plain, SafetyGraphPlayer)
    assert plain.route(node, goal, safety) == graph.shortest_path(node, goal)  # straight past


def test_player_params_are_checked() -> None:
    with pytest.raises(ValueError, match="maxmin_dept"):
        make_player_policy("maxmin", {"maxmin_dept": 2})
    with pytest.raises(ValueError, match="guard_speed"):
        make_player_policy("safetygraph", {"guard_speed": 0})
    player = make_player_policy(
        "maxmin", {"maxmin_depth": 2, "guard_speed": 2.0, "player_speed": 2.4}
    )
    assert isinstance(player, MaxMinPlayer) and player.config.maxmin_depth == 2


def test_the_compiled_maxmin_score_is_the_array_rule_with_its_ties() -> None:
    # random distances with many exact ties (values on a coarse lattice, some unreachable):
    # the compiled scoring keeps the same first moves as the numpy rule it replaced
    rng = np.random.default_rng(11)
    for _ in range(300):
        n, depth = 30, int(rng.integers(1, 4))
        nearest = rng.integers(0, 6, n).astype(float) * 0.5
        nearest[rng.random(n) < 0.1] = np.inf
        paths = rng.integers(0, n, (int(rng.integers(1, 40)), depth))
        closing = 0.25 * np.arange(1, depth + 1)
        eps = float(rng.choice([0.0, 1e-9, 0.3]))
        along = nearest[paths] - closing
        score = along.min(axis=1)
        best = score >= score.max() - eps
        final = np.where(best, along[:, -1], -np.inf)
        best &= final >= final.max() - eps
        expected = np.unique(paths[best, 0])
        got = search_kernels.maxmin_firsts(nearest, paths, closing, eps)
        assert got.tolist() == expected.tolist()
