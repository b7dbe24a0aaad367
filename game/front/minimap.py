"""The minimap: the whole level in a corner, with the camera's view, the player and the guards.

Shown while the camera does not show the whole level. The level image (walkable cells,
one pixel per cell, scaled down once) is cached; every frame draws only the view
rectangle and a few dots.
"""

from __future__ import annotations

import numpy as np
import pygame

from game.scene import Scene, StaticScene

from .palette import BLOCKED, FLOOR, GUARD, GUARD_ALERT, HALO, PLAYER, TEXT

__all__ = ["Minimap"]

#: The minimap's longer side in pixels.
SIZE = 180


class Minimap:
    """A cached small image of one level and the per-frame marks on it."""

    def __init__(self, static: StaticScene) -> None:
        self.static = static
        k = SIZE / max(static.width, static.height)
        self.scale = k
        self.size = (max(8, round(static.width * k)), max(8, round(static.height * k)))
        self._image: pygame.Surface | None = None

    def _level_image(self) -> pygame.Surface:
        if self._image is None:
            occ = self.static.occupancy
            rgb = np.where(occ[..., None], np.array(FLOOR, np.uint8), np.array(BLOCKED, np.uint8))
            small = pygame.image.frombuffer(np.ascontiguousarray(rgb).tobytes(),
                                            (occ.shape[1], occ.shape[0]), "RGB")
            self._image = pygame.transform.smoothscale(small.convert(), self.size)
        return self._image

    def draw(self, surface: pygame.Surface, corner: tuple[int, int], scene: Scene,
             view: tuple[float, float, float, float]) -> pygame.Rect:
        """Draw at ``corner`` (bottom-right of the map area); returns its rectangle."""
        w, h = self.size
        rect = pygame.Rect(corner[0] - w - 8, corner[1] - h - 8, w, h)
        pygame.draw.rect(surface, HALO, rect.inflate(6, 6))
        surface.blit(self._level_image(), rect.topleft)
        k = self.scale
        x0, y0, x1, y1 = view
        pygame.draw.rect(surface, TEXT, pygame.Rect(rect.x + x0 * k, rect.y + y0 * k,
                                                    max(2, (x1 - x0) * k), max(2, (y1 - y0) * k)), 1)
        for g in scene.guards:
            if g.active:
                color = GUARD_ALERT if g.sees_player else GUARD
                pygame.draw.circle(surface, color, (rect.x + g.pos[0] * k, rect.y + g.pos[1] * k), 2)
        px, py = scene.player.pos
        pygame.draw.circle(surface, PLAYER, (rect.x + px * k, rect.y + py * k), 3)
        return rect
