"""The batched cone drawing gives the pixels of one layer per cone (issue 25).

The reference below is the drawing the front end had before the batching, kept verbatim:
each cone on its own translucent layer, blitted, then its outline. Scenes of random cones
(overlapping ones, cones reaching off the map, seeing and not) are drawn both ways onto
the same noisy picture and compared pixel for pixel.
"""

from __future__ import annotations

import math
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import numpy as np
import pygame

from game.front import cones
from game.front.palette import CONE, CONE_EDGE, CONE_SEEING, CONE_SEEING_EDGE, HALO
from game.front.render import Layout, init_pygame
from game.ray_cast import vision_cone
from game.scene import GuardDrawing


def _reference(surface: pygame.Surface, guard: GuardDrawing, layout: Layout) -> None:
    """Renderer._draw_cone before the batching."""
    if not guard.active or len(guard.cone) < 3:
        return
    s, (ox, oy) = layout.scale, layout.origin
    pts = guard.cone * s + (ox, oy)
    lo = np.floor(pts.min(axis=0)).astype(int)
    hi = np.ceil(pts.max(axis=0)).astype(int) + 1
    area = layout.world_rect
    if hi[0] < area.left or hi[1] < area.top or lo[0] > area.right or lo[1] > area.bottom:
        return  # off screen
    size = (max(1, hi[0] - lo[0]), max(1, hi[1] - lo[1]))
    layer = pygame.Surface(size, pygame.SRCALPHA)
    local = (pts - lo).tolist()
    pygame.draw.polygon(layer, CONE_SEEING if guard.sees_player else CONE, local)
    surface.blit(layer, (int(lo[0]), int(lo[1])))
    edge = CONE_SEEING_EDGE if guard.sees_player else CONE_EDGE
    outline = pts.tolist()
    pygame.draw.lines(surface, HALO, True, outline, 4)
    pygame.draw.lines(surface, edge, True, outline, 2)


def _guards(rng: np.random.Generator, count: int, spread: float) -> list[GuardDrawing]:
    no_walls = np.zeros((0, 2))
    guards = []
    for _ in range(count):
        pos = (float(rng.uniform(-2, spread)), float(rng.uniform(-2, spread * 0.7)))
        heading = float(rng.uniform(0, 2 * math.pi))
        reach = float(rng.uniform(2, 8))
        cone = vision_cone(no_walls, no_walls, no_walls, pos, heading, math.pi / 4, reach, 40)
        guards.append(GuardDrawing(pos=pos, heading=heading, active=bool(rng.random() > 0.1),
                                   sees_player=bool(rng.random() > 0.7), state="patrol",
                                   cone=cone))
    return guards


def test_batched_cones_have_the_pixels_of_one_layer_per_cone() -> None:
    init_pygame()
    pygame.display.set_mode((640, 480))
    layout = Layout((640, 480), 50, 42, 17.3, (12, 61))
    rng = np.random.default_rng(11)
    noise = rng.integers(0, 255, size=(640, 480, 3), dtype=np.uint8)
    batched = 0
    for case in range(40):
        count, spread = int(rng.integers(1, 14)), float(rng.choice([12.0, 30.0, 60.0]))
        guards = _guards(rng, count, spread)
        want = pygame.surfarray.make_surface(noise).convert()
        got = want.copy()
        for surface in (want, got):
            surface.set_clip(layout.world_rect)
        for guard in guards:
            _reference(want, guard, layout)
        flushed: list[int] = []
        flush = cones._flush
        cones._flush = lambda surface, batch: (flushed.append(len(batch)), flush(surface, batch))[1]  # type: ignore[assignment]
        try:
            cones.draw_cones(got, guards, layout.scale, layout.origin, layout.world_rect)
        finally:
            cones._flush = flush  # type: ignore[assignment]
        batched += sum(1 for n in flushed if n > 1)
        assert np.array_equal(pygame.surfarray.array3d(got), pygame.surfarray.array3d(want)), case
    assert batched >= 5  # the cases did batch cones, not only draw them one by one
