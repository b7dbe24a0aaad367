"""Scripted player policies (SPEC §4): MaxMin, SafetyGraph, and a simple evader.

Both paper policies run at every player decision (about twice a second) in thousands of
trials, so everything that depends only on the graph is precomputed once per graph and
cached: MaxMin's move sequences per start node, SafetyGraph's edge list.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping
from types import ModuleType
from typing import Any

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra

from navmesh.graph import Neighbours, NodeGraph

from .fields import active_guard_nodes
from .params import PlayerParams
from .view import PlayerPolicy, WorldView, move_horizon


class EvadePlayer(PlayerPolicy):
    """Greedy one-step evader: the neighbour farthest (shortest path) from the nearest guard.

    The simplest sensible opponent; useful for tests because its choice is easy to predict.
    Ties are broken with the trial's generator.
    """

    policy = "evade"

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        self.graph, self.rng = graph, rng

    def decide(self, view: WorldView) -> int:
        node = view.player_node
        options = np.append(self.graph.neighbors[node], node)
        guards = np.asarray(view.guard_nodes)
        if view.guard_active is not None:
            guards = guards[np.asarray(view.guard_active, dtype=bool)]
        if len(guards) == 0:
            return node
        safety = self.graph.dist_from(options)[:, guards].min(axis=1)
        best = np.flatnonzero(safety >= safety.max() - 1e-9)
        return int(options[best[self.rng.integers(len(best))]])


# ---------------------------------------------------------------------------- MaxMin


class MoveSequences:
    """All move sequences of a fixed depth from each node (neighbours or stay), built lazily."""

    def __init__(self, graph: NodeGraph, depth: int) -> None:
        self.depth = depth
        nb = Neighbours.from_lists(graph.neighbors)
        count = np.diff(nb.indptr)
        width = int(count.max(initial=0)) + 1
        #: (n, width) options per node: itself first, then its neighbours, padded with -1
        self.options = np.full((graph.n, width), -1, dtype=np.intp)
        self.options[:, 0] = np.arange(graph.n)
        owner = np.repeat(np.arange(graph.n), count)
        self.options[owner, 1 + np.arange(len(nb.indices)) - nb.indptr[owner]] = nb.indices
        self._from: dict[int, np.ndarray] = {}

    def from_node(self, node: int) -> np.ndarray:
        """(m, depth) array: every sequence of ``depth`` moves from ``node`` (node excluded)."""
        paths = self._from.get(node)
        if paths is None:
            paths = np.array([[node]], dtype=np.intp)
            for _ in range(self.depth):
                nxt = self.options[paths[:, -1]]
                valid = nxt >= 0
                rows = np.repeat(np.arange(len(paths)), valid.sum(axis=1))
                paths = np.column_stack([paths[rows], nxt[valid]])
            paths = paths[:, 1:]
            paths.flags.writeable = False
            self._from[node] = paths
        return paths


_SEQUENCES: weakref.WeakKeyDictionary[NodeGraph, dict[int, MoveSequences]] = (
    weakref.WeakKeyDictionary()
)


def move_sequences(graph: NodeGraph, depth: int) -> MoveSequences:
    """The cached move-sequence table of ``graph`` for ``depth``."""
    per_graph = _SEQUENCES.setdefault(graph, {})
    if depth not in per_graph:
        per_graph[depth] = MoveSequences(graph, depth)
    return per_graph[depth]


def _search_kernels() -> ModuleType:
    """The compiled searches (:mod:`ai.search_kernels`), imported at first use: numba costs
    a second of start-up that a game without a MaxMin or SafetyGraph player need not pay."""
    from . import search_kernels

    return search_kernels


class MaxMinPlayer(PlayerPolicy):
    """Look ``maxmin_depth`` moves ahead; keep the sequence whose closest guard stays farthest.

    Every sequence of moves to a neighbour or staying put is scored by
    ``min_k (d_k − k·s)``: ``d_k`` is the shortest-path distance from the k-th node of the
    sequence to the nearest active guard, ``s = mean edge length × guard_speed /
    player_speed`` is how far a guard can close in per player move (pessimistic: every
    guard is assumed to approach at full speed; ``s = 0`` with ``maxmin_guards_advance``
    off, i.e. static guards). The best score wins, then the largest distance at the end of
    the sequence; remaining ties between first moves are drawn with the trial's generator.
    """

    policy = "maxmin"

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.config = PlayerParams.from_mapping(self.params)

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        c = self.config
        self.graph, self.rng = graph, rng
        self.sequences = move_sequences(graph, c.maxmin_depth)
        step = (
            graph.mean_edge_length * c.guard_speed / c.player_speed
            if c.maxmin_guards_advance
            else 0.0
        )
        self.closing = step * np.arange(1, c.maxmin_depth + 1)
        self.reach = c.maxmin_depth * graph.max_edge_length

    def decide(self, view: WorldView) -> int:
        node = int(view.player_node)
        guards = active_guard_nodes(view)
        if len(guards) == 0:
            return node
        # (n,) distance to the closest guard, promised on the nodes the sequences can reach
        nearest = self.graph.nearest_dist(guards, around=node, reach=self.reach)
        # score = min over the sequence of (distance − closing), compiled (ai.search_kernels)
        first = _search_kernels().maxmin_firsts(nearest, self.sequences.from_node(node),
                                                self.closing, self.config.tie_eps)
        return int(first[0] if len(first) == 1 else first[self.rng.integers(len(first))])


# ---------------------------------------------------------------------------- SafetyGraph


class SafetyGraphPlayer(PlayerPolicy):
    """Plan towards the safest reachable node, avoiding nodes where guards would be first.

    Per decision: ``T_g(n) = min_g dist(g, n) / guard_speed`` and ``T_p(n) = dist(p, n) /
    player_speed`` (arrival times), safety ``S = T_g − T_p``. The goal is the node with the
    largest ``T_g`` among the nodes with ``S ≥ safety_margin`` — the place farthest from
    the guards that the player still reaches comfortably first (ties: larger S, then the
    generator); if no node is that safe, the node with the largest S. (The argmax of S alone
    is degenerate: by the triangle inequality it is the player's own node when the speeds
    are equal.) The path is a Dijkstra search from the player (A* with a zero heuristic;
    the graph is small) with edge costs ``length × (1 + safety_penalty × max(0,
    safety_margin − S(head)))``; among equally cheap routes the one with the safest first
    node is taken. The answer is the farthest node along that path within the move
    horizon (one neighbour on the grid).

    ``safetygraph_goal = "paper"`` is the paper's description and nothing more (docs/ai.md
    quotes it): the goal is the reachable node of greatest S (:meth:`paper_goal`; no
    far-side rule, margin 0), the path an A* search with the straight-line heuristic and
    edge costs ``length × (1 + safety_penalty × max(0, −S(head)))`` (:meth:`astar`), planned
    once per decision tick (``WorldView.decision_tick``) and followed between ticks.
    ``safetygraph_goal = "local"`` is that, with the goal the node of greatest S within
    ``safetygraph_hops`` hops of the player (:meth:`local_goal`; SPEC §12).
    """

    policy = "safetygraph"

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.config = PlayerParams.from_mapping(self.params)

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        self.graph, self.rng = graph, rng
        adjacency = graph.adjacency.tocsr()
        self._indptr, self._indices = adjacency.indptr, adjacency.indices
        self._rows = np.repeat(np.arange(graph.n), np.diff(adjacency.indptr))
        self._lengths = adjacency.data.astype(np.float64)
        self.horizon = move_horizon(graph, self.config.r_edge_factor)
        self.last_safety: np.ndarray | None = None
        self.last_goal: int | None = None
        #: "paper": the A* path of the current decision tick and that tick's index
        self.plan: list[int] = []
        self.plan_tick: int | None = None

    def safety(self, player: int, guards: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(S, T_g) per node for the player at ``player`` and guards at ``guards``."""
        c = self.config
        guard_time = self.graph.nearest_dist(guards) / c.guard_speed
        with np.errstate(invalid="ignore"):  # inf − inf on a disconnected graph: NaN = unreachable
            return guard_time - self.graph.dist_from(player) / c.player_speed, guard_time

    def decide(self, view: WorldView) -> int:
        node = int(view.player_node)
        guards = active_guard_nodes(view)
        if len(guards) == 0:
            return node
        if self.config.safetygraph_goal in ("paper", "local"):
            return self._decide_paper(view, node, guards)
        safety, guard_time = self.safety(node, guards)
        goal = self.choose_goal(node, safety, guard_time)
        self.last_safety, self.last_goal = safety, goal
        if goal == node:
            return node
        return self._step_along(self.route(node, goal, safety))

    def choose_goal(self, node: int, safety: np.ndarray, guard_time: np.ndarray) -> int:
        """The reachable node with the largest T_g among those with S ≥ margin (see the class)."""
        c = self.config
        reachable = self.graph.reachable_from(node)
        safe = reachable & (safety >= c.safety_margin)
        if safe.any():
            primary, secondary = np.where(safe, guard_time, -np.inf), safety
        else:
            primary, secondary = np.where(reachable, safety, -np.inf), guard_time
        best = primary >= primary.max() - c.tie_eps
        secondary = np.where(best, secondary, -np.inf)
        goals = np.flatnonzero(secondary >= secondary.max() - c.tie_eps)
        return int(goals[0] if len(goals) == 1 else goals[self.rng.integers(len(goals))])

    def route(self, node: int, goal: int, safety: np.ndarray) -> list[int]:
        """Least-cost path node→goal; entering v costs ``length × (1 + k·max(0, margin − S(v)))``.

        Computed backwards (cost to the goal from every node), so the first step can be
        chosen among all equally cheap routes: the safest first node wins, then the
        generator. Later steps follow the search tree.
        """
        c = self.config
        deficit = np.where(np.isfinite(safety), c.safety_margin - safety, 0.0)
        penalty = 1.0 + c.safety_penalty * np.maximum(0.0, deficit)
        n = self.graph.n
        # reverse graph: the edge stored at (u, v) is the move v → u, which enters u
        reverse = sparse.csr_matrix(
            (self._lengths * penalty[self._rows], self._indices, self._indptr), shape=(n, n)
        )
        to_goal, successor = dijkstra(reverse, indices=goal, return_predecessors=True)
        if not np.isfinite(to_goal[node]):
            return [node]
        lo, hi = self._indptr[node], self._indptr[node + 1]
        options = self._indices[lo:hi]
        totals = self._lengths[lo:hi] * penalty[options] + to_goal[options]
        cheapest = totals <= totals.min() * (1 + 1e-9) + 1e-12
        safest = np.where(cheapest, safety[options], -np.inf)
        best = options[safest >= safest.max() - c.tie_eps]
        first = int(best[0] if len(best) == 1 else best[self.rng.integers(len(best))])
        path = [node, first]
        while path[-1] != goal:
            path.append(int(successor[path[-1]]))
        return path

    # -------------------------------------------------------- the paper's text only

    def _decide_paper(self, view: WorldView, node: int, guards: np.ndarray) -> int:
        """``safetygraph_goal = "paper"``: at the first decision of a decision tick
        (``view.decision_tick``) plan with :meth:`paper_goal` and :meth:`astar`; until the
        next tick, step along that plan from wherever the player stands on it (re-plan
        early only when it is off the plan, e.g. a stuck body re-routed)."""
        if view.decision_tick != self.plan_tick or node not in self.plan:
            safety, _ = self.safety(node, guards)
            goal = (self.local_goal(node, safety) if self.config.safetygraph_goal == "local"
                    else self.paper_goal(node, safety))
            self.last_safety, self.last_goal = safety, goal
            self.plan, self.plan_tick = self.astar(node, goal, safety), view.decision_tick
        path = self.plan[self.plan.index(node):]
        return self._step_along(path)

    def paper_goal(self, node: int, safety: np.ndarray) -> int:
        """The reachable node of greatest safety S (ties within ``tie_eps``: the generator).

        With equal speeds S(v) ≤ S(player) for every v (triangle inequality), so the ties
        are the player's own node and the nodes it shields from its nearest guard (those
        whose shortest path from that guard runs through the player); a cornered player has
        only its own node and stands still.
        """
        reachable = self.graph.reachable_from(node) & ~np.isnan(safety)
        score = np.where(reachable, safety, -np.inf)
        goals = np.flatnonzero(score >= score.max() - self.config.tie_eps)  # inf: unguarded
        return int(goals[0] if len(goals) == 1 else goals[self.rng.integers(len(goals))])

    def local_goal(self, node: int, safety: np.ndarray) -> int:
        """``safetygraph_goal = "local"``: :meth:`paper_goal` among the nodes within
        ``safetygraph_hops`` hops of the player (its own node included; ties within
        ``tie_eps``: the generator)."""
        inside, _ = self.graph.hop_ball(node, self.config.safetygraph_hops)
        score = np.where(np.isnan(safety[inside]), -np.inf, safety[inside])
        goals = inside[score >= score.max() - self.config.tie_eps]
        return int(goals[0] if len(goals) == 1 else goals[self.rng.integers(len(goals))])

    def astar(self, node: int, goal: int, safety: np.ndarray) -> list[int]:
        """A* from ``node`` to ``goal``: entering v costs ``length × (1 + safety_penalty ×
        max(0, −S(v)))`` (margin 0), heuristic the straight-line distance to the goal
        (admissible: no edge is shorter than the straight line between its nodes). Ties in
        the open list go first in, first out, so the result is a function of the inputs."""
        if node == goal:
            return [node]
        deficit = np.where(np.isfinite(safety), -safety, 0.0)  # unguarded / unreachable: none
        penalty = 1.0 + self.config.safety_penalty * np.maximum(0.0, deficit)
        positions = self.graph.positions
        heuristic = np.linalg.norm(positions - positions[goal], axis=1)
        path: list[int] = _search_kernels().astar(node, goal, self._indptr, self._indices,
                                                  self._lengths, penalty, heuristic).tolist()
        return path

    def _step_along(self, path: list[int]) -> int:
        """The farthest node on ``path`` within the move horizon (at least one step)."""
        if len(path) == 1:
            return path[0]
        steps = np.linalg.norm(np.diff(self.graph.positions[path], axis=0), axis=1)
        within = np.flatnonzero(np.cumsum(steps) <= self.horizon + 1e-9)
        return int(path[1 + (int(within[-1]) if len(within) else 0)])


__all__ = ["EvadePlayer", "MaxMinPlayer", "SafetyGraphPlayer", "MoveSequences", "move_sequences"]
