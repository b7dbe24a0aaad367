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

import importlib.util
import sys
import zlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import numpy as np

from navmesh.graph import UNREACHABLE_HOPS, NodeGraph
from navmesh.level import register_zone_kind

from . import plugin_call
from .errors import StimulusError
from .bounds import COUNT, FLAG, FRACTION, NON_NEGATIVE, UNIT, Bound
from .params import _Params
from .view import Event, GuardAI, WorldView

#: importlib.metadata entry-point group under which installed packages register stimuli
ENTRY_POINT_GROUP = "stealthfield.stimuli"


# ---------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class StimulusParams(_Params):
    """The ``[stimuli]`` section of the config: the paper's values (SPEC §5) are the defaults.

    The section's player-action keys (``throw_cooldown``, ``throw_radius``, ``decoy_reach``,
    ``takedown_range``) are the world's (``game.actions.ActionParams``), not these.
    """

    #: footstep noise while sprinting (and a thrown decoy's landing): −A·α^d up to max_hops
    noise_amplitude: float = 3.0
    noise_falloff: float = 0.6
    noise_max_hops: int = 5
    #: a noise layer is multiplied by this per second and dropped when its peak is below threshold
    noise_decay: float = 0.8
    noise_threshold: float = 0.1
    #: rain: every new noise's amplitude × this (3.0 → 1.5) and its falloff set to this
    rain_amplitude_scale: float = 0.5
    rain_falloff: float = 0.7
    #: weather at the start of a trial
    raining: bool = False
    #: static decoy: −A·β^d over the whole map, removed after guards stood on it this long
    decoy_amplitude: float = 5.0
    decoy_falloff: float = 0.8
    decoy_disarm_time: float = 3.0
    #: corpse: −A·γ^t·δ^d, removed after guards inspected it this long
    corpse_amplitude: float = 4.0
    corpse_decay: float = 0.95
    corpse_falloff: float = 0.7
    corpse_inspect_time: float = 10.0
    #: once a guard has found the body, the team's w_I stays at least this high until it is
    #: removed (our addition: the finder raises the alarm; 0 = the paper's layer alone)
    corpse_alert_weight: float = 0.9
    #: a guard within this many hops of a decoy or corpse counts as standing on / inspecting it
    inspect_hops: int = 1

    bounds = {
        "noise_amplitude": NON_NEGATIVE,
        "noise_falloff": UNIT,
        "noise_max_hops": COUNT,
        "noise_decay": UNIT,
        "noise_threshold": NON_NEGATIVE,
        "rain_amplitude_scale": NON_NEGATIVE,
        "rain_falloff": UNIT,
        "raining": FLAG,
        "decoy_amplitude": NON_NEGATIVE,
        "decoy_falloff": UNIT,
        "decoy_disarm_time": NON_NEGATIVE,
        "corpse_amplitude": NON_NEGATIVE,
        "corpse_decay": UNIT,
        "corpse_falloff": UNIT,
        "corpse_inspect_time": NON_NEGATIVE,
        "corpse_alert_weight": FRACTION,
        "inspect_hops": COUNT,
    }


class Sound(NamedTuple):
    """How loud a new noise is at its source and how much of it is left per hop."""

    amplitude: float
    falloff: float


# ---------------------------------------------------------------------------- context


@dataclass
class FieldContext:
    """What a stimulus may read about its trial: the graph, the parameters, the time.

    ``active`` is the set's current stimuli (weather consults it for :meth:`sound`); ``rng``
    is a generator derived from the trial's seed, for stimuli that need randomness.
    """

    graph: NodeGraph
    params: StimulusParams = field(default_factory=StimulusParams)
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    zones: Mapping[str, np.ndarray] = field(default_factory=dict)
    t: float = 0.0
    active: tuple[Stimulus, ...] = ()

    @property
    def n(self) -> int:
        return self.graph.n

    def hops_from(self, node: int, max_hops: int | None = None) -> np.ndarray:
        """Hop distance (BFS) from ``node`` to every node (a huge number where unreachable or,
        with ``max_hops``, farther: a large graph then only searches that far)."""
        return self.graph.hops_from(int(node), max_hops)

    def falloff(self, node: int, base: float, max_hops: int | None = None) -> np.ndarray:
        """``base ** d(node, ·)`` for every node; 0 where unreachable or beyond ``max_hops``.

        Multiply by ``−amplitude`` for an attractive layer, e.g. ``−3 · ctx.falloff(p, 0.6, 5)``.
        """
        hops = self.hops_from(node, max_hops)
        limit = UNREACHABLE_HOPS if max_hops is None else min(int(max_hops) + 1, UNREACHABLE_HOPS)
        inside = hops < limit
        return np.where(inside, float(base) ** np.where(inside, hops, 0).astype(np.float64), 0.0)

    def sound(self, base: Sound | None = None) -> Sound:
        """How a new noise sounds now: ``base`` (the configured noise) after every active
        stimulus's :meth:`Stimulus.affect_sound` (rain dampens it)."""
        sound = base or Sound(self.params.noise_amplitude, self.params.noise_falloff)
        for stimulus in self.active:
            if not stimulus.done:
                sound = plugin_call.call(stimulus, stimulus.affect_sound, sound)
                if not isinstance(sound, Sound):
                    raise StimulusError(f"{plugin_call.describe(stimulus)}: affect_sound() "
                                        f"returned {type(sound).__name__}, not a Sound")
        return sound

    def node_at(self, x: float, y: float) -> int:
        """The node at world point (x, y) (the nearest node for a point in a wall)."""
        return self.graph.node_at(float(x), float(y))


# ---------------------------------------------------------------------------- the API


#: the directions a :class:`Measure` may intend for a metric: up, down, or none declared
DIRECTIONS = (+1, -1, 0)


@dataclass(frozen=True)
class Measure:
    """How ``stealth mechanics --stimulus`` measures a mechanic against a paired control.

    Both arms run the same trials — same level, seed, guard spawns and generators — with
    the stimulus (arm ``on``) and without it (``control``): ``guards`` against ``player`` in
    ``scenario``, with the config ``overrides`` in both arms. Each of ``metrics`` is
    ``(trial metric name, intended direction)``: a name of the trial metrics
    (``game.metrics``: ``captured``, ``capture_time``, ``first_detect_time``, ``coverage``,
    ...; times of events that did not happen count as the trial's duration), and ``+1`` if
    the mechanic should raise it, ``-1`` lower it, ``0`` for no intended direction (the
    verdict then only says whether it changed). The default asks the question any new
    mechanic raises first: are the player's captures and detections different with it?

    >>> Measure(metrics=(("captured", +1),)).metrics
    (('captured', 1),)
    >>> Measure(metrics=(("captured", 2),))
    Traceback (most recent call last):
    ...
    ai.errors.StimulusError: measure: captured: the direction must be +1, -1 or 0, got 2
    """

    metrics: tuple[tuple[str, int], ...] = (
        ("first_detect_time", 0), ("captured", 0), ("capture_time", 0))
    guards: str = "pf"
    player: str = "maxmin"
    scenario: str = "capture"
    overrides: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if not self.metrics:
            raise StimulusError("measure: no metrics to measure")
        for metric, direction in self.metrics:
            if direction not in DIRECTIONS:
                raise StimulusError(f"measure: {metric}: the direction must be +1, -1 or 0, "
                                    f"got {direction!r}")


class Stimulus:
    """One mechanic instance: how it injects, how it decays, when it ends.

    Override what you need; every method has a harmless default.

    * :meth:`start` — called once when the stimulus joins a trial (precompute the layer).
    * :meth:`inject` — its layer now, shape ``(n,)``; ``≤ 0`` attracts guards, ``> 0``
      repels them; ``None`` for no layer (e.g. weather).
    * :meth:`decay` — advance its own clock by ``dt`` seconds (once per AI tick).
    * :attr:`done` — true when it should be removed (checked after every tick).
    * :meth:`on_event` / :meth:`on_tick` — react to world events and to the guards (e.g.
      "a guard stood on me for 3 s").
    * :attr:`information_weight_floor` — ask the guard AI to keep ``w_I`` at least this high
      while active (``None``: no request).
    * :meth:`affect_sound` — change how *new* noises sound while active (rain).

    ``node`` is where it is (``-1``: nowhere in particular); stimuli with ``marker`` set are
    drawn by the game and raise ``"guard_on"`` events when a guard steps onto their node.

    Two declarations concern a plugin as a whole:

    * :attr:`zone_kinds` — the level zone kinds the mechanic gives meaning to (e.g.
      ``("alarm",)``). Loading the plugin (:func:`load_stimulus`) registers each with
      :func:`navmesh.level.register_zone_kind`, so JSON and Tiled levels loaded afterwards
      may draw such zones; the stimulus finds their nodes in ``ctx.zones[kind]`` and its own
      hooks are what the zone does.
    * :attr:`measure` — how ``stealth mechanics --stimulus`` measures it (:class:`Measure`).
    """

    name: str = "stimulus"
    node: int = -1
    marker: bool = False
    zone_kinds: tuple[str, ...] = ()
    measure: Measure = Measure()
    #: the index of the level decoy this stimulus is (``-1``: none); the world asks it to
    #: tell whether that decoy is already on
    decoy: int = -1
    done: bool = False
    information_weight_floor: float | None = None

    def start(self, ctx: FieldContext) -> None:
        """Join a trial (default: nothing)."""

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        """The stimulus's contribution to the information field now (default: none)."""
        return None

    def decay(self, dt: float) -> None:
        """Let ``dt`` seconds pass (default: nothing)."""

    def on_event(self, event: Event) -> None:
        """A world event of this AI tick (default: ignored)."""

    def on_tick(self, view: WorldView, dt: float) -> None:
        """The world after this AI tick's events (default: ignored)."""

    def affect_sound(self, sound: Sound) -> Sound:
        """How a new noise sounds while this stimulus is active (default: unchanged)."""
        return sound

    def guard_layers(self, ctx: FieldContext) -> Mapping[int, tuple[np.ndarray, Mapping[str, Any]]]:
        """Field terms for single guards: guard index → (layer (n,), why) (default: none).

        Coordinated roles (:mod:`ai.roles`) give each guard its own pull this way; the set
        hands them to ``guard_ai.set_guard_information``.
        """
        return {}

    def describe(self) -> dict[str, Any]:
        """A JSON-able summary for traces."""
        return {"name": self.name, "node": int(self.node)}


class GuardPresence:
    """Seconds that active guards have spent within ``radius`` hops of ``node``.

    Sampled once per AI tick: a tick at which at least one active guard stands within the
    radius adds that tick's ``dt``. Used by the decoy (disarm) and the corpse (inspection).
    """

    def __init__(self, node: int, radius: int) -> None:
        self.node, self.radius, self.seconds = int(node), int(radius), 0.0

    def update(self, view: WorldView, dt: float) -> bool:
        """Add ``dt`` if a guard is near now; returns whether one is."""
        guards = np.asarray(view.guard_nodes, dtype=np.intp)
        if view.guard_active is not None:
            guards = guards[np.asarray(view.guard_active, dtype=bool)]
        near = bool(len(guards)) and bool(
            (view.graph.hops_from(self.node, self.radius)[guards] <= self.radius).any()
        )
        if near:
            self.seconds += dt
        return near


class Noise(Stimulus):
    """A decaying noise impulse: ``−level · α^d`` for ``d ≤ max_hops``, ``level ← level·decay^dt``.

    Footsteps (one per AI tick of sprinting) and a thrown decoy's landing. Removed when the
    level at the source drops below ``threshold``.
    """

    def __init__(
        self,
        node: int,
        amplitude: float = 3.0,
        falloff: float = 0.6,
        *,
        max_hops: int | None = 5,
        decay: float = 0.8,
        threshold: float = 0.1,
        name: str = "footstep",
        marker: bool = False,
    ) -> None:
        self.node, self.level, self.falloff = int(node), float(amplitude), float(falloff)
        self.max_hops, self.rate, self.threshold = max_hops, float(decay), float(threshold)
        self.name, self.marker = name, marker
        self.shape: np.ndarray | None = None

    def start(self, ctx: FieldContext) -> None:
        self.shape = ctx.falloff(self.node, self.falloff, self.max_hops)

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        return None if self.shape is None else -self.level * self.shape

    def decay(self, dt: float) -> None:
        self.level *= self.rate**dt

    @property
    def done(self) -> bool:  # type: ignore[override]
        return self.level < self.threshold

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": self.node, "level": round(self.level, 6)}


class StaticDecoy(Stimulus):
    """An activated level decoy: ``−A·β^d`` over the whole map, constant.

    Removed ("disarmed") once guards have stood within ``radius`` hops of it for
    ``disarm_time`` seconds (:class:`GuardPresence`).
    """

    name = "decoy"
    marker = True

    def __init__(
        self, node: int, amplitude: float = 5.0, falloff: float = 0.8, *,
        disarm_time: float = 3.0, radius: int = 1, decoy: int = -1,
    ) -> None:
        self.node, self.amplitude, self.falloff = int(node), float(amplitude), float(falloff)
        self.disarm_time, self.decoy = float(disarm_time), int(decoy)
        self.presence = GuardPresence(self.node, radius)
        self.layer: np.ndarray | None = None

    def start(self, ctx: FieldContext) -> None:
        self.layer = -self.amplitude * ctx.falloff(self.node, self.falloff)

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        return self.layer

    def on_tick(self, view: WorldView, dt: float) -> None:
        self.presence.update(view, dt)

    @property
    def done(self) -> bool:  # type: ignore[override]
        return self.presence.seconds >= self.disarm_time - 1e-9

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": self.node, "stood": round(self.presence.seconds, 6)}


class Corpse(Stimulus):
    """A guard's body: ``−A·γ^t·δ^d`` with t the seconds since the take-down.

    Removed once guards have inspected it (stood within ``radius`` hops) for
    ``inspect_time`` seconds in total. From the first tick a guard is within ``radius`` (the
    body is *found*) until its removal it asks for ``information_weight_floor = alert``:
    the finder alerts the team, and the body's pull outweighs the guards' own confidence
    long enough for the inspection (``alert = 0`` gives the paper's layer alone).
    """

    name = "corpse"
    marker = True

    def __init__(
        self, node: int, amplitude: float = 4.0, decay: float = 0.95, falloff: float = 0.7, *,
        inspect_time: float = 10.0, radius: int = 1, age: float = 0.0, guard: int = -1,
        alert: float = 0.0,
    ) -> None:
        self.node, self.rate, self.falloff = int(node), float(decay), float(falloff)
        self.level = float(amplitude) * self.rate ** max(0.0, age)
        self.inspect_time, self.guard, self.alert = float(inspect_time), int(guard), float(alert)
        self.presence = GuardPresence(self.node, radius)
        self.found = False
        self.shape: np.ndarray | None = None

    @property
    def information_weight_floor(self) -> float | None:  # type: ignore[override]
        return self.alert if self.found and self.alert > 0 else None

    def start(self, ctx: FieldContext) -> None:
        self.shape = ctx.falloff(self.node, self.falloff)

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        return None if self.shape is None else -self.level * self.shape

    def decay(self, dt: float) -> None:
        self.level *= self.rate**dt

    def on_tick(self, view: WorldView, dt: float) -> None:
        self.found = self.presence.update(view, dt) or self.found

    @property
    def done(self) -> bool:  # type: ignore[override]
        return self.presence.seconds >= self.inspect_time - 1e-9

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": self.node, "level": round(self.level, 6),
                "inspected": round(self.presence.seconds, 6)}


class Rain(Stimulus):
    """Weather: while it rains every new noise is quieter and dies out sooner.

    No layer of its own; :meth:`affect_sound` scales the amplitude (3.0 → 1.5) and sets the
    falloff (0.6 → 0.7). Ends on a ``"weather"`` event with ``rain`` false.
    """

    name = "rain"

    def __init__(self, amplitude_scale: float = 0.5, falloff: float = 0.7) -> None:
        self.amplitude_scale, self.rain_falloff = float(amplitude_scale), float(falloff)
        self.done = False

    def affect_sound(self, sound: Sound) -> Sound:
        return Sound(sound.amplitude * self.amplitude_scale, self.rain_falloff)

    def on_event(self, event: Event) -> None:
        if event.kind == "weather" and not event.data.get("rain", True):
            self.done = True


# ---------------------------------------------------------------------------- event rules

#: A rule turns one world event into new stimuli (or none).
Rule = Callable[[Event, FieldContext], "Stimulus | Iterable[Stimulus] | None"]


def _noise(event: Event, ctx: FieldContext, name: str, marker: bool) -> Noise:
    p = ctx.params
    sound = ctx.sound()
    age = max(0.0, ctx.t - event.t)
    return Noise(event.node, sound.amplitude * p.noise_decay**age, sound.falloff,
                 max_hops=p.noise_max_hops, decay=p.noise_decay, threshold=p.noise_threshold,
                 name=name, marker=marker)


def footstep_rule(event: Event, ctx: FieldContext) -> Noise:
    """``"sprint"`` → a footstep noise at the player's node (one per AI tick of sprinting)."""
    return _noise(event, ctx, "footstep", False)


def throw_rule(event: Event, ctx: FieldContext) -> Noise:
    """``"throw_landed"`` → one noise impulse at the landing node, like a footstep."""
    return _noise(event, ctx, "thrown_decoy", True)


def decoy_rule(event: Event, ctx: FieldContext) -> StaticDecoy:
    """``"decoy_activated"`` → the decoy's whole-map layer until guards disarm it."""
    p = ctx.params
    return StaticDecoy(event.node, p.decoy_amplitude, p.decoy_falloff,
                       disarm_time=p.decoy_disarm_time, radius=p.inspect_hops,
                       decoy=int(event.data.get("decoy", -1)))


def corpse_rule(event: Event, ctx: FieldContext) -> Corpse:
    """``"guard_down"`` → a corpse at the guard's node, aged from the take-down time."""
    p = ctx.params
    return Corpse(event.node, p.corpse_amplitude, p.corpse_decay, p.corpse_falloff,
                  inspect_time=p.corpse_inspect_time, radius=p.inspect_hops,
                  age=ctx.t - event.t, guard=int(event.data.get("guard", -1)),
                  alert=p.corpse_alert_weight)


def weather_rule(event: Event, ctx: FieldContext) -> Rain | None:
    """``"weather"`` with ``rain`` true → rain (unless it already rains)."""
    if not event.data.get("rain", False) or any(isinstance(s, Rain) and not s.done for s in ctx.active):
        return None
    return Rain(ctx.params.rain_amplitude_scale, ctx.params.rain_falloff)


#: The built-in registry: event kind → rule. ``"guard_on"`` has no rule of its own; it is
#: there for stimuli (``on_event``) and observers.
DEFAULT_RULES: dict[str, Rule] = {
    "sprint": footstep_rule,
    "throw_landed": throw_rule,
    "decoy_activated": decoy_rule,
    "guard_down": corpse_rule,
    "weather": weather_rule,
}


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
    ) -> None:
        self.ctx = FieldContext(
            graph, params or StimulusParams(),
            rng if rng is not None else np.random.default_rng(0), dict(zones or {}),
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
        self._active = [s for s in self._active if not s.done]
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


# ---------------------------------------------------------------------------- zones


@dataclass(frozen=True)
class Zone:
    """What a kind of level zone does (SPEC §5): lighting and concealment.

    ``confidence_decay``: per-second decay of C in the zone's cells instead of ρ (``None``:
    unchanged); ``view_scale``: factor on every guard's view range while the player stands
    in the zone. Where zones overlap, the fastest decay and the smallest scale apply.
    """

    kind: str
    confidence_decay: float | None = None
    view_scale: float = 1.0

    #: allowed values of the two settings; config keys ``zones.<kind>_<setting>`` (game.schema)
    bounds: ClassVar[Mapping[str, Bound]] = {"confidence_decay": UNIT, "view_scale": NON_NEGATIVE}

    def __post_init__(self) -> None:
        for name, bound in self.bounds.items():
            value = getattr(self, name)
            problem = None if value is None else bound.problem(value)
            if problem is not None:
                raise ValueError(f"zone {self.kind}: {name} {problem}, got {value!r}")


def zones_from_config(section: Mapping[str, Any]) -> dict[str, Zone]:
    """Zones from the ``[zones]`` config section: ``<kind>_confidence_decay``, ``<kind>_view_scale``."""
    kinds: dict[str, dict[str, float]] = {}
    for key, value in section.items():
        for suffix in ("_confidence_decay", "_view_scale"):
            if key.endswith(suffix):
                kinds.setdefault(key[: -len(suffix)], {})[suffix[1:]] = float(value)
    return {kind: Zone(kind, **values) for kind, values in kinds.items()}


def zone_view_scale(zones: Mapping[str, Zone], masks: Mapping[str, np.ndarray], n: int) -> np.ndarray:
    """Per node, the factor on the guards' view range while the player stands there."""
    scale = np.ones(n)
    for kind, mask in masks.items():
        zone = zones.get(kind)
        if zone is not None:
            scale = np.where(mask, np.minimum(scale, zone.view_scale), scale)
    return scale


def apply_zones(guard_ai: GuardAI, zones: Mapping[str, Zone], masks: Mapping[str, np.ndarray]) -> None:
    """Give every zone's cells its confidence decay, on a guard AI with that hook (PF).

    Slowest rates first, so where zones overlap the fastest decay wins.
    """
    rules: list[tuple[float, np.ndarray]] = []
    for kind, mask in masks.items():
        rate = zones[kind].confidence_decay if kind in zones else None
        if rate is not None and np.any(mask):
            rules.append((rate, mask))
    for rate, mask in sorted(rules, key=lambda item: -item[0]):
        guard_ai.set_confidence_decay(np.asarray(mask, dtype=bool), rate)


# ---------------------------------------------------------------------------- plugins

StimulusFactory = Callable[[], Stimulus]


def _load_file(path: Path) -> Any:
    resolved = path.resolve()
    name = f"stealthfield_stimulus_{zlib.crc32(str(resolved).encode()):08x}"
    mtime = resolved.stat().st_mtime_ns
    cached = sys.modules.get(name)
    if cached is not None and getattr(cached, "__stealthfield_mtime__", None) == mtime:
        return cached
    spec = importlib.util.spec_from_file_location(name, resolved)
    if spec is None or spec.loader is None:
        raise StimulusError(f"{path}: not a Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as error:  # the user's file: report it in one line
        del sys.modules[name]
        raise StimulusError(f"{path}: cannot load: {type(error).__name__}: {error}") from None
    module.__stealthfield_mtime__ = mtime  # type: ignore[attr-defined]
    return module


def _entry_point(name: str) -> Any:
    from importlib.metadata import entry_points

    found = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == name]
    if not found:
        known = sorted(ep.name for ep in entry_points(group=ENTRY_POINT_GROUP))
        hint = f" (installed: {', '.join(known)})" if known else " (none installed)"
        raise StimulusError(
            f"{name}: expected FILE.py:NAME or the name of an installed "
            f"{ENTRY_POINT_GROUP} entry point{hint}"
        )
    try:
        return found[0].load()
    except Exception as error:
        raise StimulusError(f"{name}: cannot load entry point: {error}") from None


def load_stimulus(spec: str) -> StimulusFactory:
    """The factory of a plugin stimulus: ``"path/to/file.py:Name"`` or an entry-point name.

    ``Name`` must be a :class:`Stimulus` subclass that can be created with no arguments, or
    a function of no arguments returning a :class:`Stimulus`; installed packages register
    either under the ``stealthfield.stimuli`` entry-point group. The factory is called once
    here to check it, and the zone kinds it declares (:attr:`Stimulus.zone_kinds`) are
    registered, so load plugins **before** the levels that use their zones. Raises
    :class:`StimulusError` (one line) otherwise.
    """
    text = str(spec).strip()
    path_text, sep, attr = text.rpartition(":")
    if sep and path_text and (path_text.endswith(".py") or "/" in path_text or "\\" in path_text):
        path = Path(path_text)
        if not attr.isidentifier():
            raise StimulusError(f"{text}: {attr!r} is not a Python name")
        if not path.is_file():
            raise StimulusError(f"{text}: no such file {path_text}")
        module = _load_file(path)
        if not hasattr(module, attr):
            raise StimulusError(f"{text}: {path_text} defines no {attr!r}")
        obj = getattr(module, attr)
    elif sep:
        raise StimulusError(f"{text}: expected FILE.py:NAME")
    else:
        obj = _entry_point(text)
    if isinstance(obj, type) and not issubclass(obj, Stimulus):
        raise StimulusError(f"{text}: {obj.__name__} is not a subclass of ai.stimuli.Stimulus")
    if not callable(obj):
        raise StimulusError(f"{text}: not a Stimulus subclass or a factory function")
    try:
        probe = obj()
    except Exception as error:
        raise StimulusError(
            f"{text}: cannot be created with no arguments: {type(error).__name__}: {error}"
        ) from None
    if not isinstance(probe, Stimulus):
        raise StimulusError(f"{text}: returned {type(probe).__name__}, not a Stimulus")
    _register_zone_kinds(text, probe)
    if not isinstance(probe.measure, Measure):
        raise StimulusError(f"{text}: measure must be an ai.stimuli.Measure, "
                            f"got {type(probe.measure).__name__}")
    return obj


def _register_zone_kinds(text: str, probe: Stimulus) -> None:
    """Let levels use the zone kinds ``probe`` declares (before any level is parsed)."""
    kinds = probe.zone_kinds
    if not isinstance(kinds, tuple) or not all(isinstance(k, str) for k in kinds):
        raise StimulusError(f"{text}: zone_kinds must be a tuple of strings, got {kinds!r}")
    for kind in kinds:
        try:
            register_zone_kind(kind)
        except ValueError as error:
            raise StimulusError(f"{text}: zone_kinds: {error}") from None


__all__ = [
    "DEFAULT_RULES",
    "DIRECTIONS",
    "ENTRY_POINT_GROUP",
    "Corpse",
    "FieldContext",
    "GuardPresence",
    "Measure",
    "Noise",
    "Rain",
    "Rule",
    "Sound",
    "StaticDecoy",
    "Stimulus",
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
    "throw_rule",
    "weather_rule",
    "zone_view_scale",
    "zones_from_config",
]
