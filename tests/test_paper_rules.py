"""The paper's rules as config keys (issue 21, SPEC §11): ``world.respawn = "stay"``,
``world.decision_interval`` on both abstractions and ``player.safetygraph_goal = "paper"``;
each defaults to today's rule."""

from __future__ import annotations

import heapq
import itertools
import math
import subprocess
import sys
from typing import Any

import numpy as np
import pytest

from ai import search_kernels
from ai.players import SafetyGraphPlayer
from ai.view import WorldView
from game.config import Config
from game.errors import ConfigError
from game.spawns import respawn_node
from game.trial import TrialSpec, make_world, run_trial
from game.world import World, decision_interval
from navmesh.graph import NodeGraph

SHORT = (("world.duration", 12.0),)


def _spec(*settings: tuple[str, Any], level: str = "miami", abstraction: str = "grid",
          guards: str = "cheat", player: str = "maxmin", scenario: str = "fixed",
          seed: int = 1) -> TrialSpec:
    return TrialSpec(level, abstraction, guards, player, scenario, seed=seed,
                     overrides=tuple(settings))


# ---------------------------------------------------------------------------- the keys


def test_the_defaults_are_todays_rules() -> None:
    config = Config.defaults()
    assert config["world.respawn"] == "farthest"
    assert config["world.decision_interval"] == 0.0
    assert config["player.safetygraph_goal"] == "escape"


@pytest.mark.parametrize("key, value", [
    ("world.respawn", "home"), ("world.decision_interval", -0.1),
    ("world.decision_interval", 10.5), ("world.decision_interval", float("nan")),
    ("world.decision_interval", "soon"), ("player.safetygraph_goal", "far"),
    ("player.safetygraph_goal", True)])
def test_values_outside_the_declared_bounds_are_refused(key: str, value: Any) -> None:
    with pytest.raises(ConfigError, match=key.split(".")[1]):
        Config.load({key: value})


def test_a_bad_value_on_the_command_line_is_one_line_and_exit_2() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "headless.cli", "sim", "maze", "--set",
         "player.safetygraph_goal=far"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and result.stdout == ""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("stealth: error: player.safetygraph_goal")


# ---------------------------------------------------------------------------- respawn


def _play(world: World) -> tuple[list[tuple[float, float]], list[tuple[str, int, float]]]:
    """Run ``world`` to its end; the player's position after every step and its events."""
    positions = [world.player.pos]
    events: list[tuple[str, int, float]] = []
    world.on_tick = lambda w: events.extend((e.kind, e.node, e.t) for e in w.tick_events)
    while not world.done:
        world.step()
        positions.append(world.player.pos)
    return positions, events


def _longest_move(positions: list[tuple[float, float]]) -> float:
    return max(math.dist(a, b) for a, b in zip(positions, positions[1:]))


def test_stay_heals_in_place_and_every_depletion_counts_once() -> None:
    # every guard always in range: 3 HP at 3 guards x 1 HP/s is one depletion a second
    reach = (("world.attack_range", 1e6), ("world.attack_needs_line_of_sight", False))
    stay = make_world(_spec(("world.respawn", "stay"), *reach))
    positions, events = _play(stay)
    captures = [t for kind, _, t in events if kind == "capture"]
    assert captures == pytest.approx([float(k) for k in range(1, 61)])
    assert stay.metrics()["captures"] == 60
    assert stay.step_index == stay.total_steps  # the trial ran its 60 s and ended
    # no teleport: the player never moved farther in a step than it walks
    assert _longest_move(positions) <= stay.player_speed * stay.dt + 1e-9
    # the respawn is where the capture was
    kinds = [(kind, node) for kind, node, _ in events if kind in ("capture", "respawn")]
    assert all(c[1] == r[1] for c, r in zip(kinds[::2], kinds[1::2]))
    far = make_world(_spec(*reach))
    far_positions, _ = _play(far)
    assert far.metrics()["captures"] == 60
    assert _longest_move(far_positions) > 1.0  # "farthest" teleports (the contrast)


def test_stay_counts_one_capture_per_depletion_of_full_hp() -> None:
    world = make_world(_spec(("world.respawn", "stay")))
    lethal, damage, expected = world.health.lethal_steps, 0, 0
    while not world.done:
        attackers = world.attackers  # the guards in range hurt over the coming step
        world.step()
        damage += attackers
        if damage >= lethal:
            expected, damage = expected + 1, 0
        assert world.metrics()["captures"] == expected
    assert expected >= 2  # Cheat keeps hitting a player that stays (else this proves nothing)


def test_stay_changes_nothing_before_the_first_capture() -> None:
    farthest = run_trial(_spec())["metrics"]
    stay = run_trial(_spec(("world.respawn", "stay")))["metrics"]
    assert stay["capture_time"] == farthest["capture_time"] is not None
    assert stay["captures"] >= 2 * farthest["captures"]
    # the capture scenario ends at the first capture: the rule does not matter there
    assert (run_trial(_spec(("world.respawn", "stay"), scenario="capture"))["metrics"]
            == run_trial(_spec(scenario="capture"))["metrics"])


def test_respawn_node_stay_is_where_the_player_stands() -> None:
    world = make_world(_spec())
    args = (world.graph, world.guards, world.senses, world.view_range)
    rng = np.random.default_rng(3)
    assert respawn_node("stay", *args, rng, here=7) == 7
    assert rng.integers(1 << 30) == np.random.default_rng(3).integers(1 << 30)  # no draw
    with pytest.raises(ValueError, match="stay"):
        respawn_node("stay", *args, rng)


# ---------------------------------------------------------------------- decision tick


def _decision_times(spec: TrialSpec) -> tuple[list[float], list[float]]:
    """The times at which the guard AI and the player policy were asked for a decision."""
    world = make_world(spec)
    guards: list[float] = []
    player: list[float] = []
    assert world.player_policy is not None
    ask_guard, ask_player = world.guard_ai.decide, world.player_policy.decide

    def guard(i: int, view: WorldView) -> int:
        guards.append(view.t)
        return int(ask_guard(i, view))

    def policy(view: WorldView) -> int:
        player.append(view.t)
        return int(ask_player(view))

    world.guard_ai.decide = guard  # type: ignore[method-assign]
    world.player_policy.decide = policy  # type: ignore[method-assign]
    world.run()
    return guards, player


def _off_tick(times: list[float], interval: float) -> list[float]:
    return [t for t in times if abs(t / interval - round(t / interval)) > 1e-6]


@pytest.mark.parametrize("player", ["maxmin", "safetygraph"])
def test_the_decision_interval_gates_the_partition(player: str) -> None:
    base = _spec(*SHORT, level="maze", abstraction="partition", guards="pf", player=player)
    guards0, player0 = _decision_times(base)
    assert len(_off_tick(guards0 + player0, 1.0)) > len(guards0 + player0) / 3
    gated = _spec(*SHORT, ("world.decision_interval", 1.0), level="maze",
                  abstraction="partition", guards="pf", player=player)
    guards1, player1 = _decision_times(gated)
    assert guards1 and player1
    assert _off_tick(guards1, 1.0) == [] and _off_tick(player1, 1.0) == []
    assert len(guards1) <= 3 * 13 and len(guards1) < len(guards0)  # once per tick at most
    assert len(player1) <= 13 < len(player0)


def test_the_new_key_wins_over_the_grid_key_when_positive() -> None:
    both = _spec(*SHORT, ("world.grid_decision_interval", 0.5), ("world.decision_interval", 1.5),
                 level="maze", guards="pf")
    guards, player = _decision_times(both)
    assert guards and player and _off_tick(guards + player, 1.5) == []
    # 0 leaves the grid key in charge (tests/test_calibration_keys.py covers it alone)
    grid_only = _spec(*SHORT, ("world.grid_decision_interval", 0.5), level="maze", guards="pf")
    assert (run_trial(grid_only)["metrics"]
            == run_trial(_spec(*SHORT, ("world.grid_decision_interval", 0.5),
                               ("world.decision_interval", 0.0), level="maze",
                               guards="pf"))["metrics"])
    assert decision_interval({"decision_interval": 0.0, "grid_decision_interval": 0.5},
                             grid=True) == 0.5
    assert decision_interval({"decision_interval": 0.0, "grid_decision_interval": 0.5},
                             grid=False) == 0.0
    assert decision_interval({"decision_interval": 2.0, "grid_decision_interval": 0.5},
                             grid=True) == 2.0


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_an_interval_of_one_physics_step_is_no_gate(abstraction: str) -> None:
    step = float(Config.defaults()["world.physics_step"])
    plain = _spec(*SHORT, level="maze", abstraction=abstraction, guards="fsm",
                  player="safetygraph")
    every_step = _spec(*SHORT, ("world.decision_interval", step), level="maze",
                       abstraction=abstraction, guards="fsm", player="safetygraph")
    assert run_trial(plain)["metrics"] == run_trial(every_step)["metrics"]


def test_a_walking_agent_keeps_its_path_between_ticks() -> None:
    """On the partition a target farther than one tick's walk is not dropped at the tick:
    an agent is asked again only once it has arrived."""
    world = make_world(_spec(("world.decision_interval", 0.5), ("world.duration", 20.0),
                             level="maze", abstraction="partition", guards="cheat"))
    asked: list[bool] = []
    ask = world.guard_ai.decide

    def guard(i: int, view: WorldView) -> int:
        asked.append(bool(world.guards[i].waypoints))
        return int(ask(i, view))

    world.guard_ai.decide = guard  # type: ignore[method-assign]
    walked_through_a_tick = 0
    while not world.done:
        tick = world.step_index % world.steps_per_decision == 0
        walked_through_a_tick += tick and any(g.waypoints for g in world.guards)
        world.step()
    assert asked and not any(asked)
    assert walked_through_a_tick > 0  # some agent was mid-path at a tick (else it proves nothing)


# ------------------------------------------------------------------ SafetyGraph "paper"


def _paper(graph: NodeGraph, seed: int = 0, **params: Any) -> SafetyGraphPlayer:
    player = SafetyGraphPlayer({"safetygraph_goal": "paper", **params})
    player.reset(graph, np.random.default_rng(seed))
    return player


def _corridor(cols: int = 10) -> NodeGraph:
    return NodeGraph.from_grid(np.ones((1, cols), dtype=bool), 1.0)


def test_the_paper_goal_is_the_safest_node_without_a_far_side_rule() -> None:
    graph = _corridor()
    view = WorldView.at_nodes(graph, [2], 5)
    # equal speeds: S = 1.5 s on the player's node and every node behind it; a tie drawn
    goals = set()
    for seed in range(16):
        player = _paper(graph, seed)
        player.decide(view)
        goals.add(player.last_goal)
    assert goals <= {5, 6, 7, 8, 9} and len(goals) > 1
    # a faster player: S grows away from the guard, the end of the corridor is safest
    fast = _paper(graph, player_speed=2.4)
    assert fast.decide(view) == 6 and fast.last_goal == 9
    # cornered at a dead end, nothing is safer than where it stands: it stays
    assert _paper(graph).decide(WorldView.at_nodes(graph, [2], 9)) == 9


def test_the_paper_astar_finds_the_least_penalised_path() -> None:
    # a ring (tests/test_players.py): the guard on the top row, the goal at its right end
    occupancy = np.ones((3, 9), dtype=bool)
    occupancy[1, 1:8] = False
    graph = NodeGraph.from_grid(occupancy, 1.0)
    node, goal, guard = (int(graph.cell_node[0, c]) for c in (0, 8, 4))
    player = _paper(graph)
    safety, _ = player.safety(node, np.array([guard]))
    path = player.astar(node, goal, safety)
    assert path[0] == node and path[-1] == goal
    assert all(b in graph.neighbors[a] for a, b in zip(path, path[1:]))
    assert path[1] == int(graph.cell_node[1, 0])  # down and around, not past the guard
    # the same cost as the exact search of "escape" with margin 0
    escape = SafetyGraphPlayer({"safety_margin": 0.0})
    escape.reset(graph, np.random.default_rng(0))

    def cost(route: list[int]) -> float:
        return sum(math.dist(graph.positions[a], graph.positions[b])
                   * (1 + 4.0 * max(0.0, -float(safety[b]))) for a, b in zip(route, route[1:]))

    assert cost(path) == pytest.approx(cost(escape.route(node, goal, safety)))
    plain = _paper(graph, safety_penalty=0.0)
    assert len(plain.astar(node, goal, safety)) == 9  # no penalty: straight past the guard
    assert player.astar(node, node, safety) == [node]


def _python_astar(node: int, goal: int, indptr: np.ndarray, indices: np.ndarray,
                  lengths: np.ndarray, penalty: np.ndarray, heuristic: np.ndarray) -> list[int]:
    """The A* the compiled search replaced, kept as its oracle (heapq, dict costs)."""
    cost, parent, closed = {node: 0.0}, {}, set()
    counter = itertools.count()
    open_list = [(float(heuristic[node]), next(counter), node)]
    while open_list:
        _, _, u = heapq.heappop(open_list)
        if u == goal:
            path = [u]
            while path[-1] != node:
                path.append(parent[path[-1]])
            return path[::-1]
        if u in closed:
            continue
        closed.add(u)
        for e in range(indptr[u], indptr[u + 1]):
            v = int(indices[e])
            if v in closed:
                continue
            g = cost[u] + float(lengths[e] * penalty[v])
            if g < cost.get(v, math.inf):
                cost[v], parent[v] = g, u
                heapq.heappush(open_list, (g + float(heuristic[v]), next(counter), v))
    return [node]


def test_the_compiled_astar_is_the_python_search_with_its_ties() -> None:
    # open grids with many equally cheap routes (ties broken first in, first out), random
    # penalties, walls that cut some goals off: the compiled search returns the same path
    rng = np.random.default_rng(7)
    for trial in range(40):
        occupancy = rng.random((9, 11)) < 0.8  # True: free
        graph = NodeGraph.from_grid(occupancy, 1.0)
        player = _paper(graph)
        penalty = np.where(rng.random(graph.n) < 0.5, 1.0, 1.0 + rng.integers(0, 4, graph.n))
        for _ in range(5):
            node, goal = (int(v) for v in rng.integers(0, graph.n, 2))
            heuristic = np.linalg.norm(graph.positions - graph.positions[goal], axis=1)
            args = (player._indptr, player._indices, player._lengths, penalty.astype(float),
                    heuristic)
            compiled = search_kernels.astar(node, goal, *args).tolist()
            assert compiled == _python_astar(node, goal, *args), (trial, node, goal)


def test_the_paper_plan_is_made_once_per_decision_tick() -> None:
    graph = _corridor(12)
    player = _paper(graph, player_speed=2.4)
    plans: list[int] = []
    astar = player.astar

    def counted(node: int, goal: int, safety: np.ndarray) -> list[int]:
        plans.append(node)
        return astar(node, goal, safety)

    player.astar = counted  # type: ignore[method-assign]
    assert player.decide(WorldView.at_nodes(graph, [2], 5, decision_tick=0)) == 6
    # same tick, the guard has moved: the player walks on along its plan, no new search
    assert player.decide(WorldView.at_nodes(graph, [4], 6, decision_tick=0)) == 7
    assert plans == [5]
    # off its plan within the tick: a new plan from where it stands
    assert player.decide(WorldView.at_nodes(graph, [9], 3, decision_tick=0)) == 2
    assert plans == [5, 3]
    # a new tick: a new plan
    player.decide(WorldView.at_nodes(graph, [0], 2, decision_tick=1))
    assert plans == [5, 3, 2]


def test_the_paper_rule_ignores_the_margin_and_runs_on_both_abstractions() -> None:
    for abstraction in ("grid", "partition"):
        spec = _spec(*SHORT, ("player.safetygraph_goal", "paper"), abstraction=abstraction,
                     guards="pf", player="safetygraph", scenario="capture")
        wider = _spec(*SHORT, ("player.safetygraph_goal", "paper"),
                      ("player.safety_margin", 3.0), abstraction=abstraction, guards="pf",
                      player="safetygraph", scenario="capture")
        assert run_trial(spec)["metrics"] == run_trial(wider)["metrics"]


def test_in_a_trial_the_paper_player_follows_its_plan_between_ticks() -> None:
    world = make_world(_spec(("player.safetygraph_goal", "paper"), ("world.duration", 30.0),
                             level="maze", guards="random", player="safetygraph",
                             scenario="capture"))
    policy = world.player_policy
    assert isinstance(policy, SafetyGraphPlayer)
    decisions: list[int] = []
    plans: list[int] = []
    decide, astar = policy.decide, policy.astar

    def asked(view: WorldView) -> int:
        decisions.append(view.decision_tick)
        return int(decide(view))

    def planned(node: int, goal: int, safety: np.ndarray) -> list[int]:
        plans.append(world.step_index // world.steps_per_plan)
        return astar(node, goal, safety)

    policy.decide = asked  # type: ignore[method-assign]
    policy.astar = planned  # type: ignore[method-assign]
    world.run()
    assert len(set(decisions)) > 10 and len(decisions) > len(plans)  # steps along plans
    assert set(plans) == set(decisions)  # a plan in every tick it was asked in ...
    assert len(plans) == len(set(plans))  # ... and one only (it never left its plan here)
