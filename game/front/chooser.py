"""The level chooser ``stealth play`` opens when it is run without a level.

Each level is a card: a thumbnail of its floor, walls, exits and guards, its goal (survive,
or reach the exit with its stars), and the player's best result against the chosen guard
mode (:mod:`game.front.best`). Up / down (or W / S) move the choice, Left / Right (A / D)
change the guard mode, Enter plays, Esc quits; the window sleeps between keys.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pygame

from ai import DEFAULT_GUARD_MODE

from navmesh.level import bundled_level_names, mission_names

from .best import BestResults, describe
from .keys import mode_order
from .palette import BACKGROUND, BLOCKED, EXIT_EDGE, FLOOR, GOOD, GUARD, TEXT, TEXT_DIM, WARN, WALL

__all__ = ["LevelCard", "LevelChooser", "thumbnail"]

THUMB = (160, 116)


def thumbnail(level: object, size: tuple[int, int] = THUMB) -> pygame.Surface:
    """A small picture of a level: floor, obstacles, walls, exits and guard spawns."""
    from shapely.geometry import MultiPolygon, Polygon

    surface = pygame.Surface(size)
    surface.fill(BLOCKED)
    walkable = getattr(level, "walkable")
    minx, miny, maxx, maxy = walkable.bounds
    scale = min((size[0] - 8) / max(maxx - minx, 1e-9), (size[1] - 8) / max(maxy - miny, 1e-9))
    ox = (size[0] - (maxx - minx) * scale) / 2 - minx * scale
    oy = (size[1] - (maxy - miny) * scale) / 2 - miny * scale

    def pts(coords: object) -> list[tuple[float, float]]:
        a = np.asarray(coords, dtype=float)[:, :2]
        return [(float(x), float(y)) for x, y in a * scale + (ox, oy)]

    polygons = walkable.geoms if isinstance(walkable, MultiPolygon) else [walkable]
    for poly in polygons:
        if not isinstance(poly, Polygon) or poly.is_empty:
            continue
        outline = pts(poly.exterior.coords)
        if len(outline) >= 3:
            pygame.draw.polygon(surface, FLOOR, outline)
            pygame.draw.lines(surface, WALL, True, outline, 1)
        for hole in poly.interiors:
            ring = pts(hole.coords)
            if len(ring) >= 3:
                pygame.draw.polygon(surface, BLOCKED, ring)
                pygame.draw.lines(surface, WALL, True, ring, 1)
    for area in getattr(level, "exits", ()):
        ring = pts(area.exterior.coords)
        if len(ring) >= 3:
            pygame.draw.polygon(surface, EXIT_EDGE, ring, 2)
    for gx, gy in np.asarray(getattr(level, "guards", ()), dtype=float).reshape(-1, 2):
        pygame.draw.circle(surface, GUARD, (gx * scale + ox, gy * scale + oy), 3)
    return surface



def play_levels() -> list[str]:
    """What the chooser lists and N / B cycle through: the collect-and-escape missions
    (``assets/missions``) first, then the bundled levels."""
    return mission_names() + bundled_level_names()

class LevelCard:
    """What the chooser shows of one level (read once)."""

    def __init__(self, name: str) -> None:
        from game.objectives import Objectives
        from navmesh.level import load_level

        self.name = name
        level = load_level(name)
        self.picture = thumbnail(level)
        goal = Objectives.of(level)
        stars = len(goal.collected)
        if goal.has_goal:
            self.goal = (f"pick up {stars} stars, then reach the exit" if stars
                         else "reach the exit")
        else:
            self.goal = "survive until the time is up"


class LevelChooser:
    """Level cards in a window; :meth:`run` returns the chosen level name or None, and
    :attr:`mode` is the guard mode chosen with it."""

    def __init__(self, screen: pygame.Surface, names: Sequence[str], mode: str = DEFAULT_GUARD_MODE,
                 best: BestResults | None = None) -> None:
        self.screen, self.names, self.index = screen, list(names), 0
        self.mode = mode if mode in mode_order() else mode_order()[0]
        self.best = best if best is not None else BestResults()
        self.cards = [LevelCard(name) for name in self.names]
        self.chosen: str | None = None
        self.running = True
        pygame.font.init()
        self.font = pygame.font.Font(None, 30)
        self.small = pygame.font.Font(None, 22)

    def handle(self, event: pygame.event.Event) -> None:
        """Move, change guards, choose or quit on one event."""
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_UP, pygame.K_w):
                self.index = (self.index - 1) % len(self.names)
            elif event.key in (pygame.K_DOWN, pygame.K_s):
                self.index = (self.index + 1) % len(self.names)
            elif event.key in (pygame.K_LEFT, pygame.K_a, pygame.K_RIGHT, pygame.K_d):
                step = -1 if event.key in (pygame.K_LEFT, pygame.K_a) else 1
                modes = mode_order()
                k = modes.index(self.mode) if self.mode in modes else 0
                self.mode = modes[(k + step) % len(modes)]
            elif event.key in (pygame.K_RETURN, pygame.K_KP_ENTER):
                self.chosen, self.running = self.names[self.index], False
            elif event.key == pygame.K_ESCAPE:
                self.running = False

    def draw(self) -> None:
        """The cards in a scrolling column, the chosen one framed."""
        screen = self.screen
        screen.fill(BACKGROUND)
        w, h = screen.get_size()
        title = self.font.render(f"Choose a level — guards: {self.mode}", True, GOOD)
        screen.blit(title, (24, 16))
        hint = self.small.render("Up / Down choose · Left / Right guards · Enter play · Esc quit",
                                 True, TEXT_DIM)
        screen.blit(hint, (24, h - 30))
        row = THUMB[1] + 16
        visible = max(1, (h - 100) // row)
        first = min(max(0, self.index - visible // 2), max(0, len(self.cards) - visible))
        for k, card in enumerate(self.cards[first:first + visible]):
            i = first + k
            y = 56 + k * row
            box = pygame.Rect(16, y - 6, w - 32, THUMB[1] + 12)
            if i == self.index:
                pygame.draw.rect(screen, (40, 42, 54), box)
                pygame.draw.rect(screen, WARN, box, 2)
            screen.blit(card.picture, (24, y))
            x = 24 + THUMB[0] + 20
            screen.blit(self.font.render(card.name, True, WARN if i == self.index else TEXT),
                        (x, y + 8))
            screen.blit(self.small.render(f"goal: {card.goal}", True, TEXT), (x, y + 44))
            best = describe(self.best.best(card.name, self.mode))
            screen.blit(self.small.render(best, True, GOOD if "not played" not in best else TEXT_DIM),
                        (x, y + 72))
        pygame.display.flip()

    def run(self, frames: int | None = None) -> str | None:
        """Until a choice or Esc (or ``frames`` frames, for tests); the chosen level name."""
        count = 0
        while self.running and (frames is None or count < frames):
            self.draw()
            event = pygame.event.wait(250) if frames is None else pygame.event.poll()
            if event.type != pygame.NOEVENT:
                self.handle(event)
                for more in pygame.event.get():
                    self.handle(more)
            count += 1
        return self.chosen
