"""Where agents start (SPEC §7): guard spawn nodes and the player's start / respawn node."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from navmesh.graph import NodeGraph
from navmesh.level import Level

from .agents import Agent
from .schema import SPAWN_RULES
from .senses import Senses


def guard_spawn_nodes(graph: NodeGraph, level: Level, rng: np.random.Generator, count: int,
                      spawns: str) -> list[int]:
    """``spawns = "random"``: ``count`` distinct nodes drawn with ``rng`` (at most n − 1);
    ``"level"``: the nodes of the level's guard spawn points."""
    if spawns == "level":
        return [graph.node_at(x, y) for x, y in level.guards]
    if spawns != "random":
        raise ValueError(f"world.spawns: expected one of {SPAWN_RULES}, got {spawns!r}")
    count = min(count, graph.n - 1)
    return [int(v) for v in rng.choice(graph.n, size=count, replace=False)]


def level_start_node(graph: NodeGraph, level: Level, spawns: str) -> int | None:
    """``spawns = "level"`` and a level that declares ``player``: the node of that point;
    otherwise None (the player starts at :func:`start_node`)."""
    if spawns != "level" or level.player is None:
        return None
    return graph.node_at(*level.player)


def start_node(graph: NodeGraph, guards: Sequence[Agent], senses: Senses, view_range: float,
               rng: np.random.Generator) -> int:
    """The node farthest (min shortest path) from every active guard, out of their sight.

    Nodes any active guard could see now (:meth:`Senses.visible_points`) are excluded
    unless that leaves none; ties are broken with ``rng``.
    """
    active = [g for g in guards if g.active]
    if not active:
        return int(rng.integers(graph.n))
    score = graph.nearest_dist(np.array([g.node for g in active]))
    visible = np.zeros(graph.n, dtype=bool)
    for g in active:
        visible |= senses.visible_points(g.pos, g.heading, graph.positions, view_range)
    if not visible.all():
        score = np.where(visible, -np.inf, score)
    best = np.flatnonzero(score >= score.max() - 1e-9)
    return int(best[rng.integers(len(best))])


__all__ = ["guard_spawn_nodes", "level_start_node", "start_node"]
