"""The minimap's picture is cached and redrawn only when a mark moves to another pixel."""

from __future__ import annotations

import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import dataclasses

import numpy as np
import pygame

from game.front.minimap import Minimap
from game.front.render import init_pygame
from game.scene import GuardDrawing, PlayerDrawing, Scene, StaticScene
from navmesh.graph import graph_for
from navmesh.level import load_level


def _scene(static: StaticScene, guard_x: float) -> Scene:
    guards = (GuardDrawing(pos=(guard_x, 5.0), heading=0.0, active=True, sees_player=False,
                           state="patrol", cone=np.zeros((0, 2))),)
    return Scene(static=static, t=0.0, duration=60.0, guards=guards,
                 player=PlayerDrawing(pos=(3.0, 4.0), heading=0.0, hp=3, hp_max=3))


def test_the_minimap_is_redrawn_only_when_a_mark_changes_pixel() -> None:
    init_pygame()
    screen = pygame.display.set_mode((400, 300))
    level = load_level("dishonored")
    static = StaticScene.from_level(level, graph_for(level, "grid"))
    cached, fresh = Minimap(static), Minimap(static)
    view = (2.0, 1.0, 12.0, 9.0)
    step = 0.2 / cached.scale  # a fifth of a minimap pixel
    for k in range(12):
        scene = _scene(static, 6.0 + k * step)
        screen.fill((0, 0, 0))
        cached.draw(screen, (390, 290), scene, view)
        got = pygame.surfarray.array3d(screen)
        fresh._picture = None  # the same marks drawn from scratch
        screen.fill((0, 0, 0))
        fresh.draw(screen, (390, 290), scene, view)
        assert np.array_equal(got, pygame.surfarray.array3d(screen)), k
    assert 2 <= cached.redraws <= 4  # 12 frames, the guard crossed 2-3 pixels
    moved = dataclasses.replace(_scene(static, 6.0), seen_by=())
    before = cached.redraws
    cached.draw(screen, (390, 290), moved, (3.0, 1.0, 13.0, 9.0))  # the view moved on
    assert cached.redraws == before + 1
