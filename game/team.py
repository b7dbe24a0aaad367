"""The guard team's mechanics beyond the paper, switched on in config (docs/ai.md).

``[awareness]``, ``[alert]``, ``[radio]`` and ``[roles]`` each have ``enabled = false`` by
default (and in the paper presets), so a trial is the paper's unless a switch is on.
:class:`TeamRules` reads those sections once per world and wires what is on into the
world's existing channels: graded perception (:mod:`ai.awareness`) between the senses and
``seen_by``, and alert phases (:mod:`ai.alert`), the radio (:mod:`ai.radio`) and roles
(:mod:`ai.roles`) as stimuli of the world's :class:`~ai.stimuli.StimulusSet`. The guard AI
sees only its declared hooks.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from ai.alert import AlertParams, AlertPhases
from ai.awareness import Awareness, AwarenessParams, suspicion_rule
from ai.params import Params
from ai.radio import Radio, RadioParams
from ai.roles import RoleParams, Roles
from ai.stimuli import StimulusSet

from .errors import ConfigError

if TYPE_CHECKING:
    import numpy as np

    from ai.view import Event

    from .agents import Agent

#: config sections with an ``enabled`` switch, in the order they are wired
SECTIONS = ("awareness", "alert", "radio", "roles")


def _params(config: Any, section: str, cls: type[Params]) -> Any | None:
    """``cls`` from the section without its switch, or None when the switch is off."""
    values = config.section(section)
    if not values.pop("enabled", False):
        return None
    try:
        return cls.from_mapping(values)
    except ValueError as error:
        raise ConfigError(f"[{section}]: {error}") from None


class TeamWorld(Protocol):
    """What the team rules read of the world they serve (a :class:`game.world.World` is
    one; this module never imports the world, which owns the rules)."""

    @property
    def player(self) -> Agent: ...

    @property
    def guards(self) -> Sequence[Agent]: ...

    @property
    def zones(self) -> Mapping[str, np.ndarray]: ...

    @property
    def events(self) -> list[Event]: ...

    @property
    def t(self) -> float: ...

    @property
    def dt(self) -> float: ...

    @property
    def step_index(self) -> int: ...

    @property
    def player_moved(self) -> bool: ...

    @property
    def sprinting(self) -> bool: ...

    @property
    def sneaking(self) -> bool: ...

    @property
    def guard_speed(self) -> float: ...

    def view_reach(self) -> float: ...


@dataclass
class TeamRules:
    """What of graded perception, alert phases, radio and roles is on in one world."""

    awareness: Awareness | None = None
    alert: AlertPhases | None = None
    radio: Radio | None = None
    roles: Roles | None = None

    @classmethod
    def build(cls, config: Any, n_guards: int, stimuli: StimulusSet) -> TeamRules:
        """Read the four sections; add the switched-on stimuli to ``stimuli``."""
        rules = cls()
        aware = _params(config, "awareness", AwarenessParams)
        if aware is not None:
            rules.awareness = Awareness(aware, n_guards)
            stimuli.register("suspicion", suspicion_rule(aware))
        alert = _params(config, "alert", AlertParams)
        if alert is not None:
            rules.alert = AlertPhases(alert)
            stimuli.add(rules.alert)
        radio = _params(config, "radio", RadioParams)
        if radio is not None:
            rules.radio = Radio(radio)
            stimuli.add(rules.radio)
        roles = _params(config, "roles", RoleParams)
        if roles is not None:
            rules.roles = Roles(roles)
            stimuli.add(rules.roles)
        return rules

    def detect(self, world: TeamWorld, perceived: Sequence[int]) -> tuple[int, ...]:
        """The guards that detect the player now: ``perceived`` itself (the paper) or,
        with graded perception, those whose awareness crossed the threshold."""
        if self.awareness is None:
            return tuple(perceived)
        px, py = world.player.pos
        node = world.player.node
        distances = [math.hypot(g.pos[0] - px, g.pos[1] - py) for g in world.guards]
        reach = world.view_reach()
        dark = bool(world.zones["dark"][node]) if "dark" in world.zones else False
        concealed = bool(world.zones["concealment"][node]) if "concealment" in world.zones else False
        gait = ("still" if not world.player_moved else "sprint" if world.sprinting
                else "sneak" if world.sneaking else "walk")
        dt = world.dt if world.step_index > 0 else 0.0
        return self.awareness.update(perceived, distances, reach, dark, concealed, gait, node, dt)

    def before_tick(self, world: TeamWorld) -> None:
        """At an AI tick, before the stimuli: the glimpses become ``"suspicion"`` events."""
        if self.awareness is not None:
            world.events.extend(self.awareness.suspicions(world.t))

    def after_stimuli(self, world: TeamWorld) -> None:
        """After the stimuli's tick: the alert phase sets the guards' speed."""
        if self.alert is not None:
            for guard in world.guards:
                guard.speed = world.guard_speed * self.alert.speed_scale

    def trace_fields(self, world: TeamWorld) -> tuple[dict[str, Any], list[dict[str, Any]]]:
        """Extra trace fields: top level (``phase``) and per guard (``awareness``, ``role``)."""
        top: dict[str, Any] = {}
        if self.alert is not None:
            top["phase"] = self.alert.phase
        per_guard: list[dict[str, Any]] = [{} for _ in world.guards]
        if self.awareness is not None:
            for extra, meter in zip(per_guard, self.awareness.meters(), strict=True):
                extra["awareness"] = meter
        if self.roles is not None:
            for i, extra in enumerate(per_guard):
                extra["role"] = self.roles.role_of(i)
        return top, per_guard


__all__ = ["SECTIONS", "TeamRules", "TeamWorld"]
