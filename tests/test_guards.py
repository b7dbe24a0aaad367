"""Guard modes on hand-built WorldViews over small grid graphs (no physics world needed).

The loop is the world's contract in miniature: ``tick`` once per AI tick, and between
ticks every guard decides twice (a guard at 2 cells/s reaches a neighbouring cell in half
a second) and is moved straight to the node it chose.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

import numpy as np
import pytest
from scipy.spatial import Delaunay

from ai import guard_mode, make_guard_ai
from ai.baselines import FSMGuards, StalenessGuards
from ai.pf import PotentialFieldGuards
from ai.view import GuardAI, WorldView
from navmesh.graph import NodeGraph
from game.config import Config


def make_view(
    graph: NodeGraph,
    guards: Sequence[int],
    player: int,
    *,
    t: float = 0.0,
    seen_by: Sequence[int] = (),
    sighting: int | None = None,
) -> WorldView:
    return WorldView.at_nodes(graph, guards, player, t=t, seen_by=tuple(seen_by),
                              sighting=sighting)


def simulate(
    ai: GuardAI, graph: NodeGraph, guards: list[int], player: int, ticks: int
) -> np.ndarray:
    """Run ``ticks`` AI ticks with two decisions per guard in between; (steps, guards) nodes."""
    history = [list(guards)]
    for k in range(ticks):
        for _ in range(2):
            for i in range(len(guards)):
                guards[i] = ai.decide(i, make_view(graph, guards, player, t=k))
            history.append(list(guards))
        ai.tick(make_view(graph, guards, player, t=k + 1), 1.0)
    return np.array(history)


def open_grid(rows: int, cols: int) -> NodeGraph:
    return NodeGraph.from_grid(np.ones((rows, cols), dtype=bool), 1.0)


def corridor(length: int) -> NodeGraph:
    return open_grid(1, length)


# ---------------------------------------------------------------------------- potential field


def test_pf_guard_heads_for_a_fresh_sighting() -> None:
    graph = open_grid(7, 7)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    node, target = 0, 48
    guards.tick(make_view(graph, [node], target, sighting=target), 1.0)
    distances = [int(graph.hops_between(node, target))]
    for step in range(12):
        node = guards.decide(0, make_view(graph, [node], target, t=1 + step / 2))
        distances.append(int(graph.hops_between(node, target)))
        if step % 2:
            guards.tick(make_view(graph, [node], target, t=1 + step / 2), 1.0)
    assert distances == list(range(12, -1, -1))  # one cell closer at every decision


@pytest.mark.parametrize("start", [[44, 45], [39, 38], [0, 1], [97, 98]])
def test_pf_guards_spread_out_instead_of_following(start: list[int]) -> None:
    graph = open_grid(10, 10)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(3), 2)
    history = simulate(guards, graph, list(start), player=0, ticks=30)
    apart = graph.hops_between(history[:, 0], history[:, 1])
    # Two followers would stay within one hop all the time. Confidence and teammate
    # presence push them apart; the revisit penalty (eq. 10) trades a little of that for
    # coverage (start [39, 38]: within one hop 21 % of the time instead of 11 %).
    assert apart.mean() > 5.0
    assert (apart <= 1).mean() < 0.25
    assert len(np.unique(history)) / graph.n > 0.4


def test_pf_teammate_presence_zero_is_the_papers_kernel() -> None:
    graph = open_grid(6, 6)
    guards = PotentialFieldGuards({"teammate_presence": 0.0})
    guards.reset(graph, np.random.default_rng(0), 2)
    guards.tick(make_view(graph, [7, 9], 30), 1.0)
    guards.decide(0, make_view(graph, [7, 9], 30))
    report = guards.explain(0)
    assert report is not None
    kernel = guards.fields()["K"]
    for c in report["candidates"]:
        assert c["C_live"] == 0.0 and c["K"] == kernel[c["node"]]


def test_pf_teammate_presence_repels_from_a_teammate() -> None:
    graph = corridor(9)

    def picks(params: dict[str, float]) -> set[int]:
        chosen = set()
        for seed in range(12):
            guards = PotentialFieldGuards(params)
            guards.reset(graph, np.random.default_rng(seed), 2)
            guards.tick(make_view(graph, [4, 4], 0), 1.0)  # both at 4: a symmetric field
            chosen.add(guards.decide(0, make_view(graph, [4, 5], 0)))  # guard 1 has moved to 5
        return chosen

    assert picks({"teammate_presence": 0.0}) == {3, 5}  # the paper's field alone: a tie
    assert picks({}) == {3}  # the teammate's presence at 5 decides it
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    guards.tick(make_view(graph, [4, 4], 0), 1.0)
    guards.decide(0, make_view(graph, [4, 5], 0))
    report = guards.explain(0)
    assert report is not None and report["teammates"] == [5]
    live = {c["node"]: c["C_live"] for c in report["candidates"]}
    assert live == pytest.approx({3: 0.64, 5: 1.0})  # C0 · 0.8^d from the teammate at 5


def test_pf_moves_to_a_grid_neighbour_every_decision() -> None:
    graph = open_grid(6, 6)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(1), 3)
    history = simulate(guards, graph, [0, 17, 35], player=20, ticks=10)
    steps = graph.hops_between(history[:-1], history[1:])
    assert np.all(steps == 1)


def test_pf_is_deterministic_for_a_seed() -> None:
    graph = open_grid(8, 8)

    def run(seed: int) -> np.ndarray:
        guards = PotentialFieldGuards()
        guards.reset(graph, np.random.default_rng(seed), 3)
        return simulate(guards, graph, [0, 7, 63], player=30, ticks=15)

    assert np.array_equal(run(5), run(5))


def test_pf_explain_is_consistent_and_json_able() -> None:
    graph = open_grid(6, 6)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    assert guards.explain(0) is None
    guards.tick(make_view(graph, [0, 35], 15, sighting=15), 1.0)
    guards.extra_information = np.where(np.arange(graph.n) == 5, -2.0, 0.0)
    winner = guards.decide(0, make_view(graph, [0, 35], 15, t=1.0))
    report = guards.explain(0)
    assert report is not None
    json.dumps(report)
    assert report["node"] == 0 and report["winner"] == winner and report["guard"] == 0
    assert sorted(c["node"] for c in report["candidates"]) == [1, 6]
    w = report["weights"]
    assert w["w_I"] + w["w_C"] + w["w_N"] == pytest.approx(1.0)
    for c in report["candidates"]:
        assert c["P"] == pytest.approx(
            w["w_I"] * (c["I"] + c["I_extra"])
            + w["w_C"] * (c["C"] + c["C_live"])
            + w["w_N"] * c["N"]
        )
    best = min(c["K"] for c in report["candidates"])
    winner_k = next(c["K"] for c in report["candidates"] if c["node"] == winner)
    assert winner_k == best
    assert report["tie_broken"] is False and report["tied"] == [winner]
    fields = guards.fields()
    assert set(fields) == {"I", "I_extra", "C", "N", "P", "K"}
    for c in report["candidates"]:  # the team field plus the teammate's presence
        assert c["P"] == pytest.approx(fields["P"][c["node"]] + w["w_C"] * c["C_live"])
        assert c["C_live"] > 0


def test_pf_explain_reports_a_broken_tie() -> None:
    graph = corridor(5)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    guards.tick(make_view(graph, [2], 0), 1.0)
    guards.decide(0, make_view(graph, [2], 0))
    report = guards.explain(0)
    assert report is not None and report["tie_broken"] is True and sorted(report["tied"]) == [1, 3]


def test_pf_first_decision_sees_its_own_confidence() -> None:
    graph = corridor(5)
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    guards.decide(0, make_view(graph, [1], 4))  # before any tick: the field is ticked with dt = 0
    assert guards.fields()["C"] == pytest.approx([0.8, 1.0, 0.8, 0.64, 0.512])


def test_pf_on_a_partition_graph_chooses_among_candidates() -> None:
    rng = np.random.default_rng(2)
    points = rng.random((80, 2)) * [12.0, 8.0]
    mesh = Delaunay(points)
    graph = NodeGraph(
        kind="partition",
        positions=points[mesh.simplices].mean(axis=1),
        neighbors=tuple(np.sort(row[row >= 0]) for row in mesh.neighbors),
    )
    guards = PotentialFieldGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    nodes = [0, 50]
    for k in range(10):
        guards.tick(make_view(graph, nodes, 10, t=k), 1.0)
        for i in range(2):
            choice = guards.decide(i, make_view(graph, nodes, 10, t=k))
            assert choice in guards.field.candidates(nodes[i]).tolist()
            nodes[i] = choice


def test_pf_rejects_unknown_parameters() -> None:
    with pytest.raises(ValueError, match="gama_I"):
        make_guard_ai("pf", {"gama_I": 0.5})


def test_config_sections_match_the_parameter_classes() -> None:
    config = Config.defaults()
    for mode in ("pf", "fsm", "staleness"):
        assert config.section(guard_mode(mode).section)
        make_guard_ai(mode, config.section(guard_mode(mode).section))


# ---------------------------------------------------------------------------- FSM


def test_fsm_state_timeline_follows_the_paper_timers() -> None:
    graph = corridor(30)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    g1 = 25
    timeline: dict[int, str] = {}

    def tick(t: int, g0: int, **kwargs: object) -> None:
        guards.tick(make_view(graph, [g0, g1], 14, t=t, **kwargs), 1.0)  # type: ignore[arg-type]
        timeline[t] = guards.state_name(0)

    tick(1, 10, seen_by=(1,), sighting=14)  # guard 1 sees the player at 14
    assert guards.state_name(1) == "chase"
    tick(2, 12)  # walking to the spot
    tick(3, 14)  # arrived: the 3-s search starts
    tick(4, 14)
    tick(5, 14)
    tick(6, 14)  # searched 3 s
    for t in range(7, 12):
        tick(t, 14)  # Return (the guard is held still, so only the 5-s cap ends it)
    assert timeline == {
        1: "investigate",
        2: "investigate",
        3: "investigate",
        4: "investigate",
        5: "investigate",
        6: "return",
        7: "return",
        8: "return",
        9: "return",
        10: "return",
        11: "patrol",
    }
    assert guards.guards[0].route_node == 10


def test_fsm_patrol_investigate_chase_return_patrol() -> None:
    graph = corridor(30)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    states = []
    views = [
        dict(seen_by=(1,), sighting=14),  # t=1 another guard sees the player: investigate
        dict(seen_by=(0,), sighting=13),  # t=2 this guard sees it: chase
        dict(),  # t=3 unseen 1 s
        dict(),  # t=4 unseen 2 s: return
        dict(),
        dict(),
        dict(),
        dict(),  # t=5..8
        dict(),  # t=9: 5 s in return: patrol
    ]
    for t, extra in enumerate(views, start=1):
        g0 = 10 if t == 1 else 12  # left its patrol at 10; held at 12 from then on
        guards.tick(make_view(graph, [g0, 25], 13, t=t, **extra), 1.0)  # type: ignore[arg-type]
        states.append(guards.state_name(0))
    assert states == ["investigate", "chase", "chase", "return"] + ["return"] * 4 + ["patrol"]


def test_fsm_chase_gives_up_after_chase_max() -> None:
    graph = corridor(30)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    states = {}
    for t in range(1, 18):
        g0 = 12 if t == 1 else 13  # chase starts at 12; the route point is 12
        guards.tick(make_view(graph, [g0], 14, t=t, seen_by=(0,), sighting=14), 1.0)
        states[t] = guards.state_name(0)
    assert all(states[t] == "chase" for t in range(1, 11))
    assert states[11] == "return"  # 10 s of chase, although the player is still in sight
    assert all(states[t] == "return" for t in range(11, 16))  # gave up: ignores the player
    assert states[16] == "patrol" and states[17] == "chase"


def test_fsm_moves_towards_the_goal_of_each_state() -> None:
    graph = corridor(30)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 2)
    nodes = [10, 25]
    guards.tick(make_view(graph, nodes, 20, t=1, seen_by=(1,), sighting=20), 1.0)
    assert guards.decide(0, make_view(graph, nodes, 20, t=1)) == 11  # investigate: to the spot
    guards.tick(make_view(graph, [11, 25], 20, t=2, seen_by=(0,), sighting=17), 1.0)
    assert guards.decide(0, make_view(graph, [11, 25], 17, t=2, seen_by=(0,))) == 12  # chase
    for t in (3, 4):
        guards.tick(make_view(graph, [12, 25], 17, t=t), 1.0)
    assert guards.state_name(0) == "return"
    assert guards.decide(0, make_view(graph, [12, 25], 17, t=4)) == 11  # back to the route (10)


def test_fsm_guard_that_sees_the_player_chases_at_once() -> None:
    graph = corridor(30)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    assert guards.decide(0, make_view(graph, [10], 14, seen_by=(0,))) == 11
    assert guards.state_name(0) == "chase"


def test_fsm_patrol_targets_are_distinct_and_moves_are_single_cells() -> None:
    graph = open_grid(6, 6)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(4), 3)
    history = simulate(guards, graph, [0, 5, 30], player=20, ticks=12)
    assert np.all(graph.hops_between(history[:-1], history[1:]) <= 1)
    targets = [g.target for g in guards.guards]
    assert len(set(targets)) == 3


def test_fsm_investigates_a_strong_stimulus_layer_only() -> None:
    graph = corridor(20)
    guards = FSMGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    # footstep-like layer −3·0.6^d around node 8: 3·0.6² = 1.08 ≥ 1 at d = 2, 0.648 at d = 3
    layer = -3.0 * 0.6 ** graph.hops_from(8).astype(float)
    guards.extra_information = layer
    guards.tick(make_view(graph, [5], 0), 1.0)  # d = 3: too faint
    assert guards.state_name(0) == "patrol"
    guards.tick(make_view(graph, [6], 0), 1.0)  # d = 2: heard
    assert guards.state_name(0) == "investigate" and guards.guards[0].spot == 8


# ---------------------------------------------------------------------------- Staleness


def test_staleness_grows_and_resets_where_guards_stand() -> None:
    graph = corridor(6)
    guards = StalenessGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    for t, node in enumerate([0, 1, 2], start=1):
        guards.tick(make_view(graph, [node], 5, t=t), 1.0)
    assert guards.staleness.tolist() == [2.0, 1.0, 0.0, 3.0, 3.0, 3.0]
    guards.tick(make_view(graph, [2], 5, t=4), 0.5)
    assert guards.staleness.tolist() == [2.5, 1.5, 0.0, 3.5, 3.5, 3.5]


def test_staleness_guard_heads_for_the_stalest_region() -> None:
    graph = open_grid(3, 10)
    guards = StalenessGuards()
    guards.reset(graph, np.random.default_rng(0), 1)
    # the guard has swept the right half (columns 5..9) for 15 ticks; the left half is stale
    right = [int(graph.cell_node[r, c]) for c in range(5, 10) for r in range(3)]
    for t, node in enumerate(right, start=1):
        guards.tick(make_view(graph, [node], 0, t=t), 1.0)
    start = int(graph.cell_node[1, 5])
    first = guards.decide(0, make_view(graph, [start], 0, t=16))
    target = guards.guards[0].target
    assert target is not None and graph.node_cell[target][1] < 5
    assert guards.staleness[target] == guards.staleness.max() == 15.0
    assert graph.hops_between(first, target) == graph.hops_between(start, target) - 1  # on its way there


def test_staleness_guards_never_share_a_target() -> None:
    graph = open_grid(4, 4)
    guards = StalenessGuards()
    guards.reset(graph, np.random.default_rng(7), 3)
    nodes = [0, 1, 2]
    for i in range(3):
        guards.decide(i, make_view(graph, nodes, 15))
    targets = [g.target for g in guards.guards]
    assert len(set(targets)) == 3


# ---------------------------------------------------------------------------- Random and Cheat


def test_cheat_steps_along_the_shortest_path() -> None:
    occupancy = np.array([[1, 1, 1, 1, 1], [1, 0, 0, 0, 1], [1, 1, 1, 0, 1]], dtype=bool)
    graph = NodeGraph.from_grid(occupancy, 1.0)
    guards = make_guard_ai("cheat")
    guards.reset(graph, np.random.default_rng(0), 1)
    start, player = int(graph.cell_node[2, 2]), int(graph.cell_node[2, 4])
    node, path = start, [start]
    while node != player:
        node = guards.decide(0, make_view(graph, [node], player))
        path.append(node)
    assert path == graph.shortest_path(start, player)


def test_random_walk_moves_to_a_neighbour() -> None:
    graph = open_grid(4, 4)
    guards = make_guard_ai("random")
    guards.reset(graph, np.random.default_rng(0), 1)
    for _ in range(20):
        assert guards.decide(0, make_view(graph, [5], 0)) in graph.neighbors[5].tolist()
