"""The level chooser ``stealth play`` opens when it is run without a level.

Up / down (or W / S) move the choice, Enter plays it, Esc quits; the window sleeps between
keys (it is idle by definition).
"""

from __future__ import annotations

from collections.abc import Sequence

import pygame

from .palette import BACKGROUND, GOOD
from .screens import Panel, draw_panel

__all__ = ["LevelChooser"]


class LevelChooser:
    """A list of level names in a window; :meth:`run` returns the chosen one or None."""

    def __init__(self, screen: pygame.Surface, names: Sequence[str]) -> None:
        self.screen, self.names, self.index = screen, list(names), 0
        self.chosen: str | None = None
        self.running = True

    def handle(self, event: pygame.event.Event) -> None:
        """Move, choose or quit on one event."""
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_UP, pygame.K_w):
                self.index = (self.index - 1) % len(self.names)
            elif event.key in (pygame.K_DOWN, pygame.K_s):
                self.index = (self.index + 1) % len(self.names)
            elif event.key in (pygame.K_RETURN, pygame.K_KP_ENTER):
                self.chosen, self.running = self.names[self.index], False
            elif event.key == pygame.K_ESCAPE:
                self.running = False

    def draw(self) -> None:
        """The list as a panel."""
        self.screen.fill(BACKGROUND)
        draw_panel(self.screen, self.screen.get_rect(), Panel(
            "Choose a level", self.names, GOOD, choice=self.index,
            hint="Up / Down choose · Enter play · Esc quit"))
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
