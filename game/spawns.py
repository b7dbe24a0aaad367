"""Where agents start (SPEC §7): guard spawn nodes and the player's start / respawn node."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from navmesh.graph import NodeGraph
from navmesh.level import Level

from .agents import Agent
from .schema import RESPAWN_RULES, SPAWN_RULES
from .senses import Senses


def guard_spawn_nodes(graph: NodeGraph, level: Level, rng: np.random.Generator, count: int,
                      spawns: str) -> list[int]:
    """``spawns = "random"``: ``count`` distinct nodes drawn with ``rng`` (at most n − 1);
    ``"level"``: the nodes of the level's guard spawn points — or, for a level without any
    (a Tiled map without guard objects, which warns when loaded), random ones as above."""
    if spawns == "level" and level.guards:
        return [graph.node_at(x, y) for x, y in level.guards]
    if spawns not in SPAWN_RULES:
        raise ValueError(f"world.spawns: expected one of {SPAWN_RULES}, got {spawns!r}")
    count = min(count, graph.n - 1)
    return [int(v) for v in rng.choice(graph.n, size=count, replace=False)]


def level_start_node(graph: NodeGraph, level: Level, spawns: str) -> int | None:
    """``spawns = "level"`` and a level that declares ``player``: the node of that point;
    otherwise None (the player starts at :func:`start_node`)."""
    if spawns != "level" or level.player is None:
        return None
    return graph.node_at(*level.player)


def _seen(graph: NodeGraph, active: Sequence[Agent], senses: Senses,
          view_range: float) -> np.ndarray:
    """The nodes any of ``active`` could see now (:meth:`Senses.visible_points`)."""
    visible = np.zeros(graph.n, dtype=bool)
    for g in active:
        visible |= senses.visible_points(g.pos, g.heading, graph.positions, view_range)
    return visible


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
    visible = _seen(graph, active, senses, view_range)
    if not visible.all():
        score = np.where(visible, -np.inf, score)
    best = np.flatnonzero(score >= score.max() - 1e-9)
    return int(best[rng.integers(len(best))])


def hidden_node(graph: NodeGraph, guards: Sequence[Agent], senses: Senses, view_range: float,
                rng: np.random.Generator) -> int:
    """A node drawn uniformly with ``rng`` among those no active guard sees now (among all
    nodes when every node is seen): ``world.respawn = "random"``, a player that may come
    back anywhere, near a guard's back too, but never in a guard's view."""
    active = [g for g in guards if g.active]
    visible = _seen(graph, active, senses, view_range)
    candidates = np.flatnonzero(~visible) if not visible.all() else np.arange(graph.n)
    return int(candidates[rng.integers(len(candidates))])


def respawn_node(rule: str, graph: NodeGraph, guards: Sequence[Agent], senses: Senses,
                 view_range: float, rng: np.random.Generator, *, here: int | None = None) -> int:
    """Where a player captured in the fixed-time scenario comes back (``world.respawn``):
    ``"farthest"`` is :func:`start_node` (SPEC §7), ``"random"`` :func:`hidden_node`,
    ``"stay"`` the node ``here`` it was captured on (no draw from ``rng``)."""
    if rule == "stay":
        if here is None:
            raise ValueError("world.respawn = 'stay' needs the node the player stands on")
        return here
    if rule == "farthest":
        return start_node(graph, guards, senses, view_range, rng)
    if rule == "random":
        return hidden_node(graph, guards, senses, view_range, rng)
    raise ValueError(f"world.respawn: expected one of {RESPAWN_RULES}, got {rule!r}")


__all__ = ["guard_spawn_nodes", "hidden_node", "level_start_node", "respawn_node", "start_node"]
