"""The guards' view cones on the map: a translucent fill, then a white outline on a dark halo.

Batched: the points of every cone are moved to the screen in one operation, and the fills
of consecutive cones whose boxes (outlines included) do not meet are drawn into one layer
and blitted once, before their outlines. Where no two cones of a batch meet, every pixel
gets the same blends in the same order as with a layer per cone, so the picture is the
same (tests/test_front_cones.py compares the pixels with the one-layer-per-cone drawing).
A batch's layer stays under twice the area of its cones' own boxes: cones far apart are
cheaper as two small layers than as one large one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pygame

from game.scene import GuardDrawing

from .palette import CONE, CONE_EDGE, CONE_SEEING, CONE_SEEING_EDGE, HALO

__all__ = ["draw_cones"]

#: Pixels an outline reaches beyond its cone's box (the 4-px halo), kept apart in a batch.
OUTLINE_REACH = 3

#: a cone on the screen: its guard, its points in pixels, its box (lo, hi)
_Placed = tuple[GuardDrawing, np.ndarray, np.ndarray, np.ndarray]


def draw_cones(surface: pygame.Surface, guards: Sequence[GuardDrawing], scale: float,
               origin: tuple[float, float], area: pygame.Rect) -> None:
    """Every active guard's cone, in guard order, moved to the screen by ``scale`` and
    ``origin`` (pixels = world × scale + origin); cones wholly outside ``area`` are skipped."""
    shown = [g for g in guards if g.active and len(g.cone) >= 3]
    if not shown:
        return
    s, (ox, oy) = scale, origin
    every = np.concatenate([g.cone for g in shown]) * s + (ox, oy)
    ends = np.cumsum([len(g.cone) for g in shown])[:-1]
    batch: list[_Placed] = []
    for guard, pts in zip(shown, np.split(every, ends)):
        lo = np.floor(pts.min(axis=0)).astype(int)
        hi = np.ceil(pts.max(axis=0)).astype(int) + 1
        if hi[0] < area.left or hi[1] < area.top or lo[0] > area.right or lo[1] > area.bottom:
            continue  # off screen
        if batch and not _fits(batch, lo, hi):
            _flush(surface, batch)
            batch = []
        batch.append((guard, pts, lo, hi))
    _flush(surface, batch)


def _flush(surface: pygame.Surface, batch: list[_Placed]) -> None:
    """The fills of ``batch`` in one layer (one blit), then each cone's outline."""
    if not batch:
        return
    lo = np.min([b[2] for b in batch], axis=0)
    hi = np.max([b[3] for b in batch], axis=0)
    layer = pygame.Surface((max(1, int(hi[0] - lo[0])), max(1, int(hi[1] - lo[1]))),
                           pygame.SRCALPHA)
    for guard, pts, own, _ in batch:
        # the cone's own local points first, as a layer of its own had them, then moved
        # by a whole number of pixels into the joint layer
        local = ((pts - own) + (own - lo)).tolist()
        pygame.draw.polygon(layer, CONE_SEEING if guard.sees_player else CONE, local)
    surface.blit(layer, (int(lo[0]), int(lo[1])))
    for guard, pts, _, _ in batch:
        outline = pts.tolist()
        pygame.draw.lines(surface, HALO, True, outline, 4)
        pygame.draw.lines(surface, CONE_SEEING_EDGE if guard.sees_player else CONE_EDGE,
                          True, outline, 2)


def _fits(batch: list[_Placed], lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether a cone with box ``lo``-``hi`` joins ``batch``: it meets none of its boxes
    (outlines included) and the joint layer stays under twice their own areas."""
    r = OUTLINE_REACH
    areas = int((hi[0] - lo[0]) * (hi[1] - lo[1]))
    jlo, jhi = lo.copy(), hi.copy()
    for _, _, blo, bhi in batch:
        if (lo[0] - r < bhi[0] + r and blo[0] - r < hi[0] + r
                and lo[1] - r < bhi[1] + r and blo[1] - r < hi[1] + r):
            return False
        areas += int((bhi[0] - blo[0]) * (bhi[1] - blo[1]))
        jlo, jhi = np.minimum(jlo, blo), np.maximum(jhi, bhi)
    return int((jhi[0] - jlo[0]) * (jhi[1] - jlo[1])) <= 2 * areas
