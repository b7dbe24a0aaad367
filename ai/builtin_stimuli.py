"""The built-in mechanics (SPEC §5): noise, decoys, corpses, rain and the rules that make them.

Each class is a :class:`~ai.stimulus.Stimulus`; each rule turns one world event into new
stimuli, and :data:`DEFAULT_RULES` is the registry a :class:`~ai.stimuli.StimulusSet` starts with.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .stimulus import FieldContext, Rule, Sound, Stimulus, register_stimulus, seal_built_in
from .view import Event, WorldView


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


@register_stimulus
class Footstep(Noise):
    """A footstep while sprinting: a :class:`Noise` the game does not draw."""

    name = "footstep"
    display = "footstep noise"
    short = "footstep"

    def __init__(self, node: int, amplitude: float = 3.0, falloff: float = 0.6,
                 **kwargs: Any) -> None:
        super().__init__(node, amplitude, falloff, name=self.name, marker=False, **kwargs)


@register_stimulus
class ThrownNoise(Noise):
    """A thrown decoy's landing: a :class:`Noise` like a footstep, drawn where it landed."""

    name = "thrown_decoy"
    display = "thrown decoy"
    short = "throw"
    marker = True

    def __init__(self, node: int, amplitude: float = 3.0, falloff: float = 0.6,
                 **kwargs: Any) -> None:
        super().__init__(node, amplitude, falloff, name=self.name, marker=True, **kwargs)


@register_stimulus
class StaticDecoy(Stimulus):
    """An activated level decoy: ``−A·β^d`` over the whole map, constant.

    Removed ("disarmed") once guards have stood within ``radius`` hops of it for
    ``disarm_time`` seconds (:class:`GuardPresence`).
    """

    name = "decoy"
    display = "static decoy"
    short = "decoy"
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


@register_stimulus
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


@register_stimulus
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


def _noise(event: Event, ctx: FieldContext, kind: type[Footstep | ThrownNoise]) -> Noise:
    p = ctx.params
    sound = ctx.sound()
    age = max(0.0, ctx.t - event.t)
    return kind(event.node, sound.amplitude * p.noise_decay**age, sound.falloff,
                max_hops=p.noise_max_hops, decay=p.noise_decay, threshold=p.noise_threshold)


def footstep_rule(event: Event, ctx: FieldContext) -> Noise:
    """``"sprint"`` → a footstep noise at the player's node (one per AI tick of sprinting)."""
    return _noise(event, ctx, Footstep)


def throw_rule(event: Event, ctx: FieldContext) -> Noise:
    """``"throw_landed"`` → one noise impulse at the landing node, like a footstep."""
    return _noise(event, ctx, ThrownNoise)


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


seal_built_in()  # the mechanics above keep their names: a plugin named "corpse" is refused
