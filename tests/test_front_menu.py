"""The pause menu (Esc), the slow walk and a sound for every action and hit (issue 42),
driven through the game's own event handling with SDL's dummy drivers; the mixer calls are
counted per sound kind (a stand-in Sound object), so nothing is heard or timed."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from ai.awareness import Awareness, AwarenessParams  # noqa: E402
from game.front.play import MENU, PlayGame, PlaySettings  # noqa: E402
from game.front.render import pygame  # noqa: E402
from mixer_calls import count_mixer_calls  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
HEIST = str(ROOT / "examples" / "heist.json")


@pytest.fixture(autouse=True)
def _dummy_audio(monkeypatch: pytest.MonkeyPatch, tmp_path: Path):  # type: ignore[no-untyped-def]
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    monkeypatch.setenv("STEALTHFIELD_DATA", str(tmp_path))  # best results of these games
    pygame.mixer.quit()
    yield
    pygame.mixer.quit()


def _key(game: PlayGame, *keys: int) -> None:
    for key in keys:
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key, mod=0))
        game.run(1)


class _Pressed:
    def __init__(self, keys: set[int]) -> None:
        self.keys = keys

    def __getitem__(self, key: int) -> bool:
        return key in self.keys


def test_esc_opens_a_pause_menu_that_resumes_restarts_sets_the_volume_and_quits() -> None:
    game = PlayGame(PlaySettings("maze"), lockstep=True, size=(960, 640))
    try:
        game.start()
        game.run(5)
        _key(game, pygame.K_ESCAPE)
        assert game.menu == 0 and game.paused and game.running
        steps = game.world.step_index
        game.run(5)
        assert game.world.step_index == steps  # paused under the menu
        panel = game.panel()
        assert panel is not None and panel.title == "PAUSED" and panel.choice == 0
        assert [line.split()[0] for line in panel.lines] == list(MENU)
        _key(game, pygame.K_DOWN, pygame.K_DOWN)  # Volume
        volume = game.sound.volume
        _key(game, pygame.K_RIGHT)
        assert game.sound.volume == pytest.approx(min(1.0, volume + 0.1))
        _key(game, pygame.K_LEFT, pygame.K_LEFT)
        assert game.sound.volume == pytest.approx(volume - 0.1)
        _key(game, pygame.K_DOWN, pygame.K_RETURN)  # Controls
        assert game.controls and any("slow walk" in line for line in game.panel().lines)
        _key(game, pygame.K_ESCAPE)  # back to the menu
        assert game.menu == 3 and not game.controls
        _key(game, pygame.K_ESCAPE)  # resume
        assert game.menu is None and not game.paused
        game.run(3)
        assert game.world.step_index == steps + 1 + 3  # the frame of the Esc key stepped too
        _key(game, pygame.K_ESCAPE, pygame.K_DOWN, pygame.K_RETURN)  # Restart
        assert game.menu is None and game.world.step_index == 0 and game.state == "ready"
        _key(game, pygame.K_ESCAPE, pygame.K_UP, pygame.K_RETURN)  # up from Resume: Quit
        assert not game.running
    finally:
        game.close()


def test_q_quits_and_esc_no_longer_does() -> None:
    game = PlayGame(PlaySettings("maze"), lockstep=True, size=(960, 640))
    try:
        _key(game, pygame.K_ESCAPE)
        assert game.running and game.menu == 0
        _key(game, pygame.K_q)
        assert not game.running
    finally:
        game.close()


def test_the_slow_walk_is_half_speed_quieter_and_half_as_noticeable(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl held with D: half the walking speed (0.5), the quiet footstep sound, and the
    "sneak" gait raising a guard's awareness half as fast as walking."""
    moved = {}
    for mods in (pygame.KMOD_LCTRL, 0):
        game = PlayGame(PlaySettings(HEIST, guards="random"), lockstep=True, size=(960, 640))
        try:
            calls = count_mixer_calls(game.sound)
            world = game.world
            start = np.array(world.player.pos)
            monkeypatch.setattr(pygame.key, "get_pressed", lambda: _Pressed({pygame.K_d}))
            monkeypatch.setattr(pygame.key, "get_mods", lambda mods=mods: mods)
            game.run(60)
            assert world.sneaking is bool(mods)
            moved[mods] = float(np.array(world.player.pos)[0] - start[0])
            quiet = game.sound.played["step_quiet"]
            assert (quiet > 0) is bool(mods) and calls["step_quiet"] == quiet
        finally:
            game.close()
    assert moved[pygame.KMOD_LCTRL] == pytest.approx(0.5 * moved[0], rel=0.05)
    aware = Awareness(AwarenessParams(), 1)
    assert aware.rate(4.0, 8.0, False, False, "sneak") == 0.5 * aware.rate(4.0, 8.0, False, False, "walk")


def test_every_action_and_hit_has_its_sound() -> None:
    """Through the game's keys and clicks on heist (stars, level decoys): a refused
    take-down, a throw, a decoy switched on, a star picked up, a take-down from behind and
    the hits of a guard that sees the player each call the mixer once per event."""
    game = PlayGame(PlaySettings(HEIST, guards="random"), lockstep=True, size=(960, 640))
    calls = count_mixer_calls(game.sound)
    world = game.world
    played = game.sound.played

    def put(xy: tuple[float, float]) -> None:
        world.player.place(xy)
        world.player.node = world.graph.node_at(*xy)

    try:
        expected = os.environ.get("STEALTH_TEST_VIDEO_DRIVER")  # test_play_rules: x11 on Xvfb
        assert expected is None or pygame.display.get_driver() == expected
        game.start()
        game.run(2)
        _key(game, pygame.K_f)  # nobody within reach
        assert played["denied"] == 1 and game.message.startswith("take down:")
        x, y = world.player.pos
        click = tuple(int(v) for v in game.renderer.to_screen(x + 2.0, y))
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=click))
        game.run(1)
        assert played["throw"] == 1
        put((9.5, 15.5))  # next to the level decoy at (9.5, 16.5)
        _key(game, pygame.K_e)
        assert played["decoy_on"] == 1, game.message
        put((18.5, 4.5))  # on a star
        game.run(1)
        assert played["pickup"] == 1
        from test_play_rules import StayGuards

        world.guard_ai = StayGuards()
        guard = world.guards[0]
        guard.waypoints.clear()
        guard.heading = 0.0
        put((guard.pos[0] - 1.2, guard.pos[1]))  # behind it, facing away
        _key(game, pygame.K_f)
        game.run(1)
        assert played["takedown"] == 1 and not guard.active
        other = next(g for g in world.guards if g.active)
        other.waypoints.clear()
        put((other.pos[0] - 1.0, other.pos[1]))
        for _ in range(240):  # it faces the player: awareness rises, then it hits
            other.heading = np.pi
            other.waypoints.clear()
            game.run(1)
            if world.done:
                break
        assert played["hurt"] >= 2 and world.hp < world.hp_max
    finally:
        game.close()
    for kind in ("denied", "throw", "decoy_on", "pickup", "takedown", "hurt"):
        assert calls[kind] == played[kind] >= 1, (kind, dict(calls), dict(played))


def test_a_throw_lands_where_clicked_within_the_range_drawn_while_aiming(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The pointer over the map with a throw ready: the range diamond and the landing cross
    are drawn; a click in range lands on the clicked point (its node gets the noise), one
    beyond it on the nearest node within range, where the cross said."""
    from game.actions import node_containing

    game = PlayGame(PlaySettings("maze", overrides=("stimuli.throw_cooldown=0",)),
                    lockstep=True, size=(960, 640))
    world = game.world
    monkeypatch.setattr(pygame.mouse, "get_focused", lambda: True)
    try:
        game.start()
        game.run(1)
        cs = world.level.cell_size
        prow, pcol = (int(v // cs) for v in world.player.pos[::-1])
        near = [int(n) for n in range(world.graph.n)
                if 2 <= abs(int(world.graph.positions[n][1] // cs) - prow)
                + abs(int(world.graph.positions[n][0] // cs) - pcol) <= 3]
        far = max(range(world.graph.n), key=lambda n: float(np.hypot(
            *(world.graph.positions[n] - np.array(world.player.pos)))))
        for node, inside in ((near[0], True), (far, False)):
            target = world.graph.positions[node] + (0.2 * cs, 0.1 * cs)
            pixel = tuple(int(round(v)) for v in game.renderer.to_screen(*target))
            clicked = game.renderer.to_world(*pixel)
            monkeypatch.setattr(pygame.mouse, "get_pos", lambda pixel=pixel: pixel)
            game.run(1)
            aim = game.aim()
            assert aim is not None
            diamond, point = aim
            assert len(diamond) == 4 and point is not None
            if inside:
                assert point == pytest.approx(clicked)
            else:
                assert point != pytest.approx(clicked)
                assert point in [tuple(p) for p in world.graph.positions.tolist()]
            pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=pixel))
            game.run(1)
            assert game.landed is not None and game.landed[:2] == pytest.approx(point)
            (event,) = [e for e in world.events if e.kind == "throw_landed"][-1:]
            landed_node = event.node
            assert (landed_node == node_containing(world, *clicked)) is inside
            assert game.sound.played["throw"] >= 1
            while any(e.kind == "throw_landed" for e in world.events):
                game.run(1)  # the AI tick takes the event
    finally:
        game.close()


def test_the_questionnaire_shows_the_result_and_each_answer() -> None:
    game = PlayGame(PlaySettings("tlou", guards="cheat", record=True, questions=True,
                                 overrides=("world.player_hp=0.3",)),
                    lockstep=True, size=(960, 640), on_session=lambda row, trace: None)
    try:
        game.start()
        while game.state == "playing":
            game.run(30)
        assert game.state == "questions"
        panel = game.panel()
        assert panel is not None and panel.title == "CAUGHT" and f"{game.world.t:.1f} s" in panel.lines[0]
        _key(game, pygame.K_4)
        panel = game.panel()
        assert panel is not None and panel.lines[1].endswith(": 4") and panel.choice == 2
        assert game.renderer.panel_box is not None  # drawn, beside the map
    finally:
        game.close()
