"""On-map signs of what the guards hear: noise rings and rain.

* :class:`NoiseRings` — when the guards hear a noise (the player's footsteps while
  sprinting, a thrown decoy landing: the ``sprint`` and ``throw_landed`` events of an AI
  tick), a ring grows around its source to the distance the noise carries — the
  stimulus's hop reach (``noise_max_hops``, shorter when amplitude × falloff^h drops below
  ``noise_threshold``; rain lowers the amplitude) times the graph's mean edge length — and
  fades out over :data:`RING_SECONDS`.
* :func:`draw_rain` — light streaks over the map while it rains.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pygame

from game.world import World

from .palette import HALO, NOISE, RAIN

__all__ = ["RING_SECONDS", "NoiseRings", "Ring", "draw_rain", "hearing_radius"]

RING_SECONDS = 1.2
_NOISES = ("sprint", "throw_landed")


def hearing_radius(world: World) -> float:
    """How far (world units) a new noise carries now: its hop reach × mean edge length."""
    p = world.stimulus_params
    amplitude, falloff = p.noise_amplitude, p.noise_falloff
    if world.raining:
        amplitude, falloff = amplitude * p.rain_amplitude_scale, p.rain_falloff
    hops = float(p.noise_max_hops)
    if 0 < falloff < 1 and amplitude > p.noise_threshold > 0:
        hops = min(hops, math.floor(math.log(p.noise_threshold / amplitude) / math.log(falloff)))
    return max(0.0, hops) * world.graph.mean_edge_length


@dataclass(frozen=True)
class Ring:
    """One heard noise: where, how far it carries, when it was heard (game seconds)."""

    x: float
    y: float
    radius: float
    t: float
    kind: str


class NoiseRings:
    """The rings of the noises heard in the last :data:`RING_SECONDS` of one world."""

    def __init__(self) -> None:
        self.rings: list[Ring] = []
        self._seen: object = None

    def observe(self, world: World) -> None:
        """Add a ring for every noise of the world's latest AI tick (once per tick)."""
        events = world.tick_events
        if events is not self._seen:
            self._seen = events
            radius = hearing_radius(world)
            for e in events:
                if e.kind not in _NOISES:
                    continue
                if "x" in e.data:
                    x, y = float(e.data["x"]), float(e.data["y"])
                else:
                    x, y = (float(v) for v in world.graph.positions[e.node])
                self.rings.append(Ring(x, y, radius, world.t, e.kind))
        self.rings = [r for r in self.rings if world.t - r.t < RING_SECONDS]

    def draw(self, surface: pygame.Surface, to_screen: object, scale: float, t: float) -> None:
        """Draw the live rings (``to_screen`` maps a world point to a pixel)."""
        assert callable(to_screen)
        for ring in self.rings:
            age = max(0.0, min(1.0, (t - ring.t) / RING_SECONDS))
            radius = ring.radius * scale * (0.35 + 0.65 * min(1.0, age * 2.5))
            center = to_screen(ring.x, ring.y)
            width = 3 if age < 0.6 else 2
            pygame.draw.circle(surface, HALO, center, radius, width + 2)
            pygame.draw.circle(surface, NOISE, center, radius, width)


_STREAKS = np.random.default_rng(7).random((160, 2))


def draw_rain(surface: pygame.Surface, area: pygame.Rect, t: float) -> None:
    """Rain streaks over ``area``, moving with the game clock ``t`` (deterministic)."""
    layer = pygame.Surface(area.size, pygame.SRCALPHA)
    w, h = area.size
    fall = (t * 0.9) % 1.0
    for fx, fy in _STREAKS:
        x = fx * w
        y = ((fy + fall) % 1.0) * h
        pygame.draw.line(layer, RAIN, (x, y), (x - 4, y + 14), 1)
    surface.blit(layer, area.topleft)
