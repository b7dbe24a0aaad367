"""Where the screens and the HUD go (issue 42): from a 960-px window up, the ready screen,
the pause menu and the end screen stand in a column beside the map, never over it, and
the HUD's texts (its row, the legend, the last message) never overlap one another or the
map; the player shows over a guard."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.front.play import PlayGame, PlaySettings  # noqa: E402
from game.front.render import pygame  # noqa: E402
from navmesh.level import bundled_level_names  # noqa: E402

SIZES = [(960, 640), (1280, 860), (1700, 1000)]


@pytest.fixture(autouse=True)
def _data(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setenv("STEALTHFIELD_DATA", str(tmp_path))


def _map_rect(game: PlayGame) -> pygame.Rect:
    """The level's drawn extent on screen, clipped to the map area."""
    r = game.renderer
    (x0, y0), (x1, y1) = r.to_screen(0, 0), r.to_screen(r.static.width, r.static.height)
    return pygame.Rect(round(x0), round(y0), round(x1 - x0), round(y1 - y0)).clip(r.layout.world_rect)


def _clear(game: PlayGame) -> None:
    box = game.renderer.panel_box
    assert box is not None
    assert not box.colliderect(_map_rect(game)), (box, _map_rect(game))
    assert game.screen.get_rect().contains(box)
    hud = game.renderer.hud_boxes
    for i, a in enumerate(hud):
        assert a.bottom <= game.renderer.layout.world_rect.top, a  # above the map
        assert game.screen.get_rect().contains(a)
        for b in hud[i + 1:]:
            assert not a.colliderect(b), (a, b)


@pytest.mark.parametrize("size", SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
@pytest.mark.parametrize("level", bundled_level_names())
def test_screens_stand_beside_the_map_and_the_hud_texts_apart(level: str,
                                                            size: tuple[int, int]) -> None:
    game = PlayGame(PlaySettings(level, overrides=("world.duration=0.5",)), lockstep=True,
                    size=size)
    try:
        game.flash("a long message: take down: no guard within reach from behind")
        game.run(1)
        assert game.state == "ready"
        _clear(game)
        game.start()
        game.run(2)
        assert game.renderer.panel_box is None  # playing: the map has the whole width
        full = _map_rect(game)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0))
        game.run(1)
        assert game.menu == 0
        _clear(game)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0))
        game.run(1)
        while not game.world.done:
            game.run(10)
        game.run(1)
        assert game.state == "over"
        _clear(game)
        assert full.width >= _map_rect(game).width  # it made room
    finally:
        game.close()


def test_the_player_shows_on_a_guard_standing_on_it() -> None:
    """A guard standing on the player: the pixel beside the player's centre is the
    player's colour (the guard's disc, marks and labels are drawn before it)."""
    from game.front.palette import PLAYER

    game = PlayGame(PlaySettings("maze"), lockstep=True, size=(960, 640))
    try:
        world = game.world
        guard = world.guards[0]
        world.player.place(guard.pos)
        game.run(1)
        x, y = (round(v) for v in game.renderer.to_screen(*world.player.pos))
        assert tuple(game.screen.get_at((x + 2, y))[:3]) == PLAYER
    finally:
        game.close()
