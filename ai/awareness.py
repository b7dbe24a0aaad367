"""Graded perception: per-guard awareness instead of instant detection (beyond the paper).

The world's senses still answer "does guard i perceive the player now" (range × zone
scale, cone, clear line: :mod:`game.senses`); with graded perception on, a perception
only *raises* the guard's awareness ``a ∈ [0, threshold]``, by ``rate · dt`` per physics
step, where

``rate = rise_rate · (1 + proximity_gain · (1 − d / reach)) · light · cover · gait``

* ``d / reach`` — how deep inside the view range the player is (0 at the guard, 1 at the
  edge of the zone-scaled range);
* ``light`` — ``dark_factor`` when the player's node is in a dark zone, else 1;
* ``cover`` — ``concealment_factor`` in concealment, else 1;
* ``gait`` — ``gait_still``, ``gait_walk`` or ``gait_sprint`` (the player did not move,
  moved, moved while sprinting this step).

A guard that does not perceive the player loses ``decay_rate · dt`` (not below 0). A guard
*detects* — what the paper does at once — while it perceives the player with
``a ≥ threshold``. A perceiving guard below the threshold but at or above
``suspicion_level`` has a *glimpse*: once per AI tick the world raises a ``"suspicion"``
event at the glimpsed node, which :func:`suspicion_rule` turns into a weak noise-like
information stimulus ``−suspicion_amplitude · suspicion_falloff^hops`` (decaying like a
noise). So graded perception lives entirely in the stimuli: the guard AI is unchanged.

Worked example (the defaults, a walking player 4 units away in the dark, reach 8):
``rate = 1.0 · (1 + 2 · 0.5) · 0.5 · 1 · 1 = 1.0`` per second, so the guard detects after
1 s of continuous view (20 physics steps of 0.05 s).

>>> aw = Awareness(AwarenessParams(), n_guards=1)
>>> aw.rate(distance=4.0, reach=8.0, dark=True, concealed=False, gait="walk")
1.0
>>> [aw.update((0,), [4.0], 8.0, True, False, "walk", node=7, dt=0.05) for _ in range(20)][-2:]
[(), (0,)]
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .bounds import COUNT, NON_NEGATIVE, POSITIVE, UNIT
from .params import Params
from .stimuli import FieldContext, Noise, Rule
from .view import Event

GAITS = ("still", "walk", "sprint", "sneak")
#: awareness within this of the threshold counts as crossing it (float sums of dt)
EPS = 1e-9


@dataclass(frozen=True)
class AwarenessParams(Params):
    """The ``[awareness]`` config section (``enabled`` is the world's switch)."""

    threshold: float = 1.0
    #: awareness per second at the edge of the range, lit, uncovered, walking
    rise_rate: float = 1.0
    #: extra rate at distance 0: factor ``1 + proximity_gain · (1 − d/reach)``
    proximity_gain: float = 2.0
    #: awareness lost per second without perception
    decay_rate: float = 0.25
    dark_factor: float = 0.5
    concealment_factor: float = 0.5
    gait_still: float = 0.5
    gait_walk: float = 1.0
    gait_sprint: float = 2.0
    #: the slow walk (stealth play's Ctrl / C): half as noticeable as walking
    gait_sneak: float = 0.5
    #: a perceiving guard at or above this (below the threshold) has a glimpse
    suspicion_level: float = 0.2
    #: the suspicion stimulus: −A · falloff^hops up to max_hops, × decay per second
    suspicion_amplitude: float = 2.0
    suspicion_falloff: float = 0.7
    suspicion_max_hops: int = 4
    suspicion_decay: float = 0.8

    bounds = {
        "threshold": POSITIVE, "rise_rate": POSITIVE, "proximity_gain": NON_NEGATIVE,
        "decay_rate": NON_NEGATIVE, "dark_factor": NON_NEGATIVE,
        "concealment_factor": NON_NEGATIVE, "gait_still": NON_NEGATIVE,
        "gait_walk": NON_NEGATIVE, "gait_sprint": NON_NEGATIVE, "gait_sneak": NON_NEGATIVE,
        "suspicion_level": NON_NEGATIVE, "suspicion_amplitude": NON_NEGATIVE,
        "suspicion_falloff": UNIT, "suspicion_max_hops": COUNT,
        "suspicion_decay": UNIT,
    }


class Awareness:
    """Awareness levels of a guard team, updated once per physics step by the world."""

    def __init__(self, params: AwarenessParams, n_guards: int) -> None:
        self.params = params
        self.level = np.zeros(n_guards)
        #: guard → node of its last glimpse since the last AI tick
        self.glimpses: dict[int, int] = {}

    def rate(self, distance: float, reach: float, dark: bool, concealed: bool, gait: str) -> float:
        """Awareness gained per second of perception (the module's formula)."""
        p = self.params
        depth = 1.0 - min(1.0, distance / reach) if reach > 0 else 0.0
        gaits = {"still": p.gait_still, "walk": p.gait_walk, "sprint": p.gait_sprint,
                 "sneak": p.gait_sneak}
        return (p.rise_rate * (1.0 + p.proximity_gain * depth)
                * (p.dark_factor if dark else 1.0)
                * (p.concealment_factor if concealed else 1.0) * gaits[gait])

    def update(self, perceived: Sequence[int], distances: Sequence[float], reach: float,
               dark: bool, concealed: bool, gait: str, node: int, dt: float) -> tuple[int, ...]:
        """One physics step: raise the perceiving guards, decay the others; the detectors.

        ``distances`` are every guard's distance to the player; ``node`` is the player's.
        """
        p = self.params
        seen = set(perceived)
        detected = []
        for i in range(len(self.level)):
            if i in seen:
                gain = self.rate(float(distances[i]), reach, dark, concealed, gait) * dt
                self.level[i] = min(p.threshold, self.level[i] + gain)
                if self.level[i] >= p.threshold - EPS:
                    detected.append(i)
                    self.glimpses.pop(i, None)
                elif self.level[i] >= p.suspicion_level - EPS:
                    self.glimpses[i] = int(node)
            else:
                self.level[i] = max(0.0, self.level[i] - p.decay_rate * dt)
        return tuple(detected)

    def suspicions(self, t: float) -> list[Event]:
        """The ``"suspicion"`` events of the glimpses since the last call (one per guard)."""
        events = [Event("suspicion", node, t, {"guard": i, "awareness": round(float(self.level[i]), 6)})
                  for i, node in sorted(self.glimpses.items())]
        self.glimpses = {}
        return events

    def meters(self) -> list[float]:
        """Each guard's awareness as a fraction of the threshold, for HUD and traces."""
        return [round(float(a) / self.params.threshold, 4) for a in self.level]


def suspicion_rule(params: AwarenessParams) -> Rule:
    """The stimulus rule of ``"suspicion"`` events: a weak noise at the glimpsed node."""

    def rule(event: Event, ctx: FieldContext) -> Noise:
        return Noise(event.node, params.suspicion_amplitude, params.suspicion_falloff,
                     max_hops=params.suspicion_max_hops, decay=params.suspicion_decay,
                     threshold=0.1, name="suspicion")

    return rule


__all__ = ["GAITS", "Awareness", "AwarenessParams", "suspicion_rule"]
