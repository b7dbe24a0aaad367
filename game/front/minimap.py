"""The minimap: the whole level in a corner, with the camera's view, the player and the guards.

Shown while the camera does not show the whole level. The level image (walkable cells,
one pixel per cell, scaled down once) is cached, and so is the picture with the view
rectangle and the dots on it, in whole minimap pixels: a frame redraws it only when one of
them moved to another pixel, and otherwise blits it.
"""

from __future__ import annotations

import numpy as np
import pygame

from game.scene import Scene, StaticScene

from .palette import BLOCKED, FLOOR, GUARD, GUARD_ALERT, HALO, PLAYER, TEXT

__all__ = ["Minimap"]

#: The minimap's longer side in pixels.
SIZE = 180
#: The dark border around it, in pixels.
BORDER = 3

#: The marks on the minimap in its pixels: view rectangle, guards (x, y, seeing), player.
Marks = tuple[tuple[int, int, int, int], tuple[tuple[int, int, bool], ...], tuple[int, int]]


class Minimap:
    """A cached small image of one level and the per-frame marks on it."""

    def __init__(self, static: StaticScene) -> None:
        self.static = static
        k = SIZE / max(static.width, static.height)
        self.scale = k
        self.size = (max(8, round(static.width * k)), max(8, round(static.height * k)))
        self._image: pygame.Surface | None = None
        #: the last picture and the marks it shows
        self._picture: tuple[Marks, pygame.Surface] | None = None
        #: how often the picture was drawn (the rest of the frames blit the cached one)
        self.redraws = 0

    def _level_image(self) -> pygame.Surface:
        if self._image is None:
            occ = self.static.occupancy
            rgb = np.where(occ[..., None], np.array(FLOOR, np.uint8), np.array(BLOCKED, np.uint8))
            small = pygame.image.frombuffer(np.ascontiguousarray(rgb).tobytes(),
                                            (occ.shape[1], occ.shape[0]), "RGB")
            self._image = pygame.transform.smoothscale(small.convert(), self.size)
        return self._image

    def marks(self, scene: Scene, view: tuple[float, float, float, float]) -> Marks:
        """What the minimap shows besides the level, in its own whole pixels: the view
        rectangle, each active guard's dot and colour, the player's dot. The picture is
        redrawn only when this changes (a guard crosses a minimap pixel every few seconds)."""
        k = self.scale
        x0, y0, x1, y1 = view
        box = (round(x0 * k), round(y0 * k), max(2, round((x1 - x0) * k)), max(2, round((y1 - y0) * k)))
        guards = tuple((round(g.pos[0] * k), round(g.pos[1] * k), g.sees_player)
                       for g in scene.guards if g.active)
        px, py = scene.player.pos
        return box, guards, (round(px * k), round(py * k))

    def picture(self, marks: Marks) -> pygame.Surface:
        """The minimap with its dark border and ``marks`` (:meth:`marks`), cached while they
        stay the same."""
        if self._picture is not None and self._picture[0] == marks:
            return self._picture[1]
        w, h = self.size
        b = BORDER
        picture = self._picture[1] if self._picture is not None else pygame.Surface(
            (w + 2 * b, h + 2 * b)).convert()
        picture.fill(HALO)
        picture.blit(self._level_image(), (b, b))
        (bx, by, bw, bh), guards, (px, py) = marks
        pygame.draw.rect(picture, TEXT, pygame.Rect(b + bx, b + by, bw, bh), 1)
        for gx, gy, seeing in guards:
            pygame.draw.circle(picture, GUARD_ALERT if seeing else GUARD, (b + gx, b + gy), 2)
        pygame.draw.circle(picture, PLAYER, (b + px, b + py), 3)
        self._picture = (marks, picture)
        self.redraws += 1
        return picture

    def draw(self, surface: pygame.Surface, corner: tuple[int, int], scene: Scene,
             view: tuple[float, float, float, float]) -> pygame.Rect:
        """Draw at ``corner`` (bottom-right of the map area); returns its rectangle."""
        w, h = self.size
        rect = pygame.Rect(corner[0] - w - 8, corner[1] - h - 8, w, h)
        surface.blit(self.picture(self.marks(scene, view)), (rect.x - BORDER, rect.y - BORDER))
        return rect
