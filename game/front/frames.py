"""Frames of a world drawn without the interactive game: RGB arrays or a plain window.

The environments of :mod:`game.env` render through this module (imported lazily, only
when rendering is asked for), so the simulation core itself never imports pygame.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
import pygame

from game.scene import SceneBuilder

from .render import DrawOptions, Renderer, default_window_size, init_pygame

if TYPE_CHECKING:
    from game.world import World

__all__ = ["FrameRenderer"]


class FrameRenderer:
    """Draws one world's frames with the game's renderer, into an array or a window.

    ``mode`` is ``"rgb_array"`` (an off-screen surface, no window ever appears) or
    ``"human"`` (a window titled ``title``).
    """

    def __init__(self, builder: SceneBuilder, mode: str, size: tuple[int, int] | None = None,
                 title: str = "Stealthfield") -> None:
        if mode not in ("rgb_array", "human"):
            raise ValueError(f"render mode {mode!r}: expected 'rgb_array' or 'human'")
        if mode == "rgb_array":
            os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # no window for an array
        init_pygame()
        self.mode, self.builder = mode, builder
        shape = size or default_window_size(builder.static)
        if mode == "human":
            pygame.display.set_caption(title)
            self.target = pygame.display.set_mode(shape)
        else:
            if pygame.display.get_surface() is None:
                pygame.display.set_mode((1, 1), pygame.HIDDEN)  # pixel formats for convert()
            self.target = pygame.Surface(shape)
        self.renderer = Renderer(builder.static, shape)

    def draw(self, world: World) -> np.ndarray | None:
        """Draw the world now: an ``(h, w, 3)`` uint8 array, or ``None`` into the window."""
        self.renderer.draw(self.target, self.builder.from_world(world), DrawOptions(legend=False))
        if self.mode == "human":
            pygame.event.pump()
            pygame.display.flip()
            return None
        return np.ascontiguousarray(pygame.surfarray.array3d(self.target).swapaxes(0, 1))

    def close(self) -> None:
        """Close the window (an array renderer has none)."""
        if self.mode == "human":
            pygame.display.quit()
