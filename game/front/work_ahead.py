"""The work a game frame does beyond its fixed part, sized by the frame's measured budget.

:class:`WorkAhead` joins :class:`~game.front.frame_budget.FrameBudget` (pure: how much time
is left) to what uses it: the stripes a large level's new field values are composed in
(:class:`~game.front.layers.StaticLayers`) and the guard AI's work ahead
(:meth:`~ai.view.GuardAI.prepare`), told first which nodes the guards stand on and head for
(:meth:`~ai.view.GuardAI.expect`). None of it changes a result, only when work is done.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .frame_budget import FrameBudget

if TYPE_CHECKING:
    from game.world import World

    from .layers import StaticLayers

__all__ = ["WorkAhead"]


class WorkAhead:
    """One game window's extra work per frame (see the module docstring)."""

    def __init__(self, budget: FrameBudget | None = None) -> None:
        self.budget = budget or FrameBudget()
        #: whether the last frame's work ahead left work over
        self.behind = False
        #: the guard AI last told, and the nodes it was told
        self._expected: tuple[int, tuple[int, ...]] = (0, ())

    def before_draw(self, layers: StaticLayers) -> None:
        """Stripes for the next new field values: the last composition's cost over the
        spare of a typical frame (only where the layers compose in stripes)."""
        if layers.striped:
            layers.stripes = self.budget.stripes(layers.compose_cost)

    def after_frame(self, world: World, took: float, idle: bool) -> None:
        """The frame's fixed part took ``took`` seconds: record it, then (unless idle) let
        the guard AI work ahead for the spare the budget gives."""
        self.budget.observe(took)
        if idle:
            return
        nodes = tuple(n for g in world.guards if g.active for n in (g.node, g.target))
        if (id(world.guard_ai), nodes) != self._expected:  # a restart has a new guard AI
            self._expected = (id(world.guard_ai), nodes)
            world.guard_ai.expect(nodes)
        spare = self.budget.spare(took, self.behind)
        if spare > 0:  # none in a spike: not even the one ring a search makes per call
            self.behind = bool(world.guard_ai.prepare(spare))
