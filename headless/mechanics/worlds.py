"""The worlds of the mechanics experiment (``stealth mechanics``): PF worlds of the
``fixed`` scenario whose generators depend on (level, seed, tag) only, a player that
wanders, and stepping a world to a time; shared by :mod:`headless.mechanics.measures` (the paper's
mechanics) and :mod:`headless.mechanics.beyond` (those beyond it)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ai import make_guard_ai
from ai.view import PlayerPolicy, WorldView
from game.config import Config
from game.trial import TrialSpec
from game.trial import make_world as trial_world
from game.world import World
from navmesh.graph import NodeGraph

__all__ = ["BLIND", "Measures", "WanderPlayer", "active_guard_nodes", "make_world", "run_until"]

#: per measure, per arm ("on", "control", optionally "baseline"), one seed's value
Measures = dict[str, dict[str, float]]

#: guards cannot see and the player cannot be hurt: only the mechanic informs the guards
BLIND = {"world.view_range": 0.0, "world.attack_range": 0.0, "world.player_hp": 1.0e6}


class WanderPlayer(PlayerPolicy):
    """Walks at random without turning back, ignoring the guards.

    Its path depends only on its generator, so both arms of a pair walk the same path.
    """

    policy = "wander"

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        self.graph, self.rng, self.previous = graph, rng, -1

    def decide(self, view: WorldView) -> int:
        node = int(view.player_node)
        options = [int(v) for v in self.graph.neighbors[node] if v != self.previous]
        options = options or [int(v) for v in self.graph.neighbors[node]] or [node]
        self.previous = node
        return options[int(self.rng.integers(len(options)))]


def make_world(
    level: str, abstraction: str, seed: int, overrides: Mapping[str, Any], *,
    player: PlayerPolicy | None = None, tag: str = "mechanics",
) -> World:
    """A PF world of the ``fixed`` scenario whose generators depend on (level, seed, tag) only."""
    config = Config.load({k: str(v).lower() if isinstance(v, bool) else str(v)
                          for k, v in overrides.items()})
    spec = TrialSpec(level, abstraction, "pf", tag, "fixed", seed)
    return trial_world(spec, config, controllers=(make_guard_ai("pf", config.section("pf")), player))


def run_until(world: World, t_end: float, each_step: Callable[[World], None] | None = None) -> None:
    """Step ``world`` until ``t_end`` seconds (calling ``each_step`` after every step)."""
    while not world.done and world.t < t_end - 1e-9:
        world.step()
        if each_step is not None:
            each_step(world)


def active_guard_nodes(world: World) -> list[int]:
    return [g.node for g in world.guards if g.active]
