"""Stimuli and zones: stealth mechanics as layers of the information field (SPEC §5).

The paper's seven mechanics (§"Extensible Stealth-Mechanism Simulation") and any mechanic a
user writes are **stimuli**: small objects that know how they inject into the information
field, how they decay and when they end. The guard AI never learns which mechanic it is
looking at; it reads two generic hooks of :class:`~ai.view.GuardAI` (no-ops by default;
a mode opts in with ``hears_stimuli()``) that a :class:`StimulusSet` drives once per AI tick:

* ``guard_ai.set_extra_information(layer)`` — the sum of every active stimulus's layer (n,), added to
  I inside the potential (PF, eq. 5) or read as information (FSM, Staleness). Layers are
  ``≤ 0`` where they attract guards: the paper's positive amplitudes enter as ``−A·α^d``.
* ``guard_ai.set_information_weight_floor(floor)`` — the largest ``information_weight_floor``
  any active stimulus asks for (PF: ``w_I`` never falls below it; modes without weights
  keep the default no-op). This is how an alarm puts guards on alert.

A **zone** (:class:`Zone`) is the static counterpart: it says what it does to the
confidence decay of its cells and to the guards' view range when the player stands in it.

Distances are hop distances on the node graph (``graph.hops_from``), as everywhere in the fields.

This module holds the set; it re-exports the API (:mod:`ai.stimulus`), the built-in
mechanics (:mod:`ai.builtin_stimuli`), zones (:mod:`ai.zones`) and plugin loading
(:mod:`ai.plugins`), so ``from ai.stimuli import Stimulus`` stays the plugin authors' import.

>>> import numpy as np
>>> from navmesh.graph import NodeGraph
>>> graph = NodeGraph.from_grid(np.ones((1, 7), bool), 1.0)
>>> stimuli = StimulusSet(graph)
>>> noise = stimuli.add(Noise(node=0, amplitude=3.0, falloff=0.6))
>>> stimuli.layer().round(3).tolist()   # −3·0.6^d up to 5 hops, 0 beyond
[-3.0, -1.8, -1.08, -0.648, -0.389, -0.233, 0.0]
>>> noise.decay(1.0); round(noise.level, 3)   # × 0.8 per second
2.4
"""


from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from navmesh.graph import NodeGraph

from . import plugin_call
from .builtin_stimuli import (
    DEFAULT_RULES, Corpse, Footstep, GuardPresence, Noise, Rain, StaticDecoy, ThrownNoise,
    corpse_rule, decoy_rule, footstep_rule, throw_rule, weather_rule,
)
from .errors import StimulusError
from .plugins import ENTRY_POINT_GROUP, StimulusFactory, load_stimulus
from .stimulus import (
    DIRECTIONS, STIMULUS_TYPES, FieldContext, Measure, Rule, Sound, Stimulus, StimulusParams,
    register_stimulus, unregister_stimulus,
)
from .view import Event, GuardAI, WorldView
from .zones import Zone, apply_zones, zone_view_scale, zones_from_config


# ---------------------------------------------------------------------------- the set


class StimulusSet:
    """The stimuli of one trial, owned by the world; drives the guard AI's generic hooks.

    Once per AI tick (:meth:`tick`, before the guard AI's own tick): every active stimulus
    decays by ``dt``; the tick's events go to every active stimulus's ``on_event`` and then
    to the registry's rule for their kind, which may create new stimuli; every stimulus sees
    the world (``on_tick``); finished ones are removed; the sum of the layers is assigned to
    ``guard_ai.set_extra_information`` and the largest weight floor to
    ``guard_ai.set_information_weight_floor`` — for every guard AI whose
    :meth:`~ai.view.GuardAI.hears_stimuli` says so.
    """

    def __init__(
        self,
        graph: NodeGraph,
        params: StimulusParams | None = None,
        *,
        guard_ai: GuardAI | None = None,
        rng: np.random.Generator | None = None,
        zones: Mapping[str, np.ndarray] | None = None,
        rules: Mapping[str, Rule] | None = None,
        config: Mapping[str, Any] | None = None,
    ) -> None:
        self.ctx = FieldContext(
            graph, params or StimulusParams(),
            rng if rng is not None else np.random.default_rng(0), dict(zones or {}),
            config=config if config is not None else {},
        )
        self.rules: dict[str, Rule] = dict(DEFAULT_RULES if rules is None else rules)
        self.guard_ai = guard_ai
        self._active: list[Stimulus] = []
        self._pushed_zero = True
        self._pushed_floor = 0.0
        self._pushed_guards: frozenset[int] = frozenset()

    @property
    def active(self) -> tuple[Stimulus, ...]:
        """The stimuli currently in the trial, oldest first."""
        return tuple(self._active)

    def __len__(self) -> int:
        return len(self._active)

    # ------------------------------------------------------------------ registry
    def register(self, kind: str, rule: Rule) -> None:
        """Make events of ``kind`` create stimuli with ``rule`` (replaces an existing rule)."""
        self.rules[kind] = rule

    def disable(self, kind: str) -> None:
        """Events of ``kind`` create nothing any more (e.g. a control arm without corpses)."""
        self.rules.pop(kind, None)

    # ------------------------------------------------------------------ life cycle
    def add(self, stimulus: Stimulus) -> Stimulus:
        """Start ``stimulus`` in this trial and return it."""
        if not isinstance(stimulus, Stimulus):
            raise TypeError(f"expected a Stimulus, got {type(stimulus).__name__}")
        plugin_call.call(stimulus, stimulus.start, self.ctx)
        self._active.append(stimulus)
        self.ctx.active = tuple(self._active)
        return stimulus

    def handle(self, event: Event) -> list[Stimulus]:
        """Dispatch one event: to the active stimuli, then to its kind's rule."""
        for stimulus in self._active:
            plugin_call.call(stimulus, stimulus.on_event, event)
        rule = self.rules.get(event.kind)
        if rule is None:
            return []
        made = rule(event, self.ctx)
        if made is None:
            return []
        made = [made] if isinstance(made, Stimulus) else list(made)
        return [self.add(s) for s in made]

    def tick(self, view: WorldView, dt: float) -> None:
        """One AI tick: decay, events, ``on_tick``, removal, hooks (see the class docstring)."""
        self.ctx.t = float(view.t)
        for stimulus in self._active:
            plugin_call.call(stimulus, stimulus.decay, dt)
        for event in view.events:
            self.handle(event)
        for stimulus in self._active:
            plugin_call.call(stimulus, stimulus.on_tick, view, dt)
        self._active = [s for s in self._active if not plugin_call.is_done(s)]
        self.ctx.active = tuple(self._active)
        self.refresh()

    # ------------------------------------------------------------------ outputs
    def layer(self) -> np.ndarray:
        """The sum of the active stimuli's layers (n,)."""
        total = np.zeros(self.ctx.n)
        for stimulus in self._active:
            values = plugin_call.checked_layer(
                stimulus, plugin_call.call(stimulus, stimulus.inject, self.ctx), self.ctx.n)
            if values is not None:
                total += values
        return total

    def weight_floor(self) -> float:
        """The largest information-weight floor the active stimuli ask for (0: none)."""
        floors = [
            plugin_call.checked_number(s, "information_weight_floor",
                                       s.information_weight_floor, 0.0, 1.0)
            for s in self._active if s.information_weight_floor is not None
        ]
        return max(floors, default=0.0)

    def refresh(self) -> None:
        """Assign the layer sum and the weight floor to the guard AI's hooks, if it has them."""
        guards = self.guard_ai
        if guards is None:
            return
        if not guards.hears_stimuli():
            return
        if self._active or not self._pushed_zero:
            layer = self.layer()
            guards.set_extra_information(layer)
            self._pushed_zero = not layer.any()
        floor = self.weight_floor()
        if floor != self._pushed_floor:
            guards.set_information_weight_floor(floor)
            self._pushed_floor = floor
        personal: dict[int, tuple[np.ndarray, Mapping[str, Any]]] = {}
        for stimulus in self._active:
            personal.update(stimulus.guard_layers(self.ctx))
        for i in sorted(self._pushed_guards - personal.keys()):
            guards.set_guard_information(i, None)
        for i, (values, why) in sorted(personal.items()):
            guards.set_guard_information(i, values, why)
        self._pushed_guards = frozenset(personal)

    def markers(self) -> list[Stimulus]:
        """Active stimuli the game draws (decoys, corpses, landed throws)."""
        return [s for s in self._active if s.marker and s.node >= 0]

    def marked_nodes(self) -> frozenset[int]:
        """Nodes of the marker stimuli ("guard_on" events fire when a guard steps on one)."""
        return frozenset(int(s.node) for s in self.markers())


__all__ = [
    "DEFAULT_RULES",
    "DIRECTIONS",
    "STIMULUS_TYPES",
    "ENTRY_POINT_GROUP",
    "Corpse",
    "FieldContext",
    "Footstep",
    "GuardPresence",
    "Measure",
    "Noise",
    "Rain",
    "Rule",
    "Sound",
    "StaticDecoy",
    "Stimulus",
    "ThrownNoise",
    "StimulusError",
    "StimulusFactory",
    "StimulusParams",
    "StimulusSet",
    "Zone",
    "apply_zones",
    "corpse_rule",
    "decoy_rule",
    "footstep_rule",
    "load_stimulus",
    "register_stimulus",
    "throw_rule",
    "unregister_stimulus",
    "weather_rule",
    "zone_view_scale",
    "zones_from_config",
]
