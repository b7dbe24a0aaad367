"""Game feel (issue 25): sounds per event kind, silence without an audio device, the
awareness mark, the paused sign over every screen, the chooser's cards and best results."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.front import render as render_module
from game.front.best import BestResults
from game.front.chooser import LevelChooser, thumbnail
from game.front.palette import FLOOR
from game.front.play import PlayGame, PlaySettings
from game.front.render import pygame
from game.front.sound import SoundBoard
from mixer_calls import count_mixer_calls

SIZE = (640, 520)


@pytest.fixture(autouse=True)
def _dummy_audio(monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    """Each test opens SDL's dummy audio device afresh (another test of the same process may
    have closed the mixer or pointed SDL elsewhere)."""
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    pygame.mixer.quit()
    yield
    pygame.mixer.quit()


def test_a_scripted_session_plays_every_sound_event() -> None:
    game = PlayGame(PlaySettings("miami", autopilot="maxmin", overrides=(
        "awareness.enabled=true", "alert.enabled=true", "world.duration=30")),
        lockstep=True, size=SIZE)
    calls = count_mixer_calls(game.sound)
    world = game.world
    try:
        game.run(120)  # walking
        world.sprinting = True
        game.run(120)
        world.toggle_rain()
        x, y = world.player.pos
        world.throw_decoy(x + 2.0, y + 1.0)
        game.run(90)
        world.down_guard(0)
        game.run(90)
        while not world.done:
            game.run(60)
        game.run(2)
    finally:
        game.close()
    played = game.sound.played
    for kind in ("step", "step_sprint", "rain", "decoy_landed", "takedown", "suspicion",
                 "sighting", "phase"):
        assert played[kind] >= 1, (kind, dict(played))
        assert calls[kind] == played[kind], (kind, dict(calls), dict(played))
    assert played["win"] + played["lose"] == 1 == calls["win"] + calls["lose"]


def test_mute_stops_the_mixer_calls_but_not_the_count() -> None:
    pygame.display.init()
    board = SoundBoard()
    calls = count_mixer_calls(board)
    assert board.toggle_mute() is True
    board.play("sighting")
    assert board.played["sighting"] == 1 and calls["sighting"] == 0
    board.toggle_mute()
    board.play("sighting")
    assert calls["sighting"] == 1
    assert board.change_volume(+1.0) == 1.0 and board.change_volume(-2.0) == 0.0


def test_without_an_audio_device_the_game_plays_silently(tmp_path: Path) -> None:
    code = ("from game.front.play import PlayGame, PlaySettings\n"
            "g = PlayGame(PlaySettings('miami', autopilot='maxmin'), lockstep=True, size=(480, 400))\n"
            "g.run(200)\n"
            "assert not g.sound.available\n"
            "assert g.sound.played['step'] > 0\n"
            "g.close()\nprint('ok', g.world.step_index)\n")
    env = dict(os.environ, SDL_AUDIODRIVER="no-such-audio-device", SDL_VIDEODRIVER="dummy",
               STEALTHFIELD_DATA=str(tmp_path))
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split()[-2:] == ["ok", "200"]
    assert "Traceback" not in result.stderr and "error" not in result.stderr.lower()


def test_no_sound_card_and_no_sound_server_means_no_mixer_and_no_lines() -> None:
    """On Linux with no driver asked for, no /dev/snd and no sound server, the board does
    not try the device (ALSA would print a dozen lines); anything else is tried."""
    from game.front.sound import audio_device_likely

    def nothing(path: str) -> bool:
        return False

    bare = {"XDG_RUNTIME_DIR": "/run/user/1000"}
    if sys.platform.startswith("linux"):
        assert not audio_device_likely(bare, nothing)
        assert audio_device_likely(bare, lambda path: path == "/dev/snd")
        assert audio_device_likely(bare, lambda path: path == "/run/user/1000/pulse/native")
        assert audio_device_likely(bare, lambda path: path == "/run/user/1000/pipewire-0")
        assert not audio_device_likely({}, lambda path: path.endswith("/pulse/native"))
    assert audio_device_likely({**bare, "SDL_AUDIODRIVER": "dummy"}, nothing)
    assert audio_device_likely({**bare, "PULSE_SERVER": "tcp:host"}, nothing)
    if sys.platform.startswith("linux") and not os.path.exists("/dev/snd"):
        # this machine has no card: the whole game says nothing of audio on stderr
        code = ("from game.front.play import PlayGame, PlaySettings\n"
                "g = PlayGame(PlaySettings('miami'), lockstep=True, size=(320, 240))\n"
                "g.run(5)\nassert not g.sound.available\ng.close()\n")
        env = {k: v for k, v in os.environ.items()
               if k not in ("SDL_AUDIODRIVER", "PULSE_SERVER", "XDG_RUNTIME_DIR")}
        env["SDL_VIDEODRIVER"] = "dummy"
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                env=env, timeout=120)
        assert result.returncode == 0, result.stderr
        assert "ALSA" not in result.stderr and "audio" not in result.stderr.lower()


def test_the_paused_sign_shows_over_the_ready_screen(monkeypatch: pytest.MonkeyPatch) -> None:
    titles: list[str] = []
    real = render_module.draw_panel

    def spy(surface, area, panel, avoid=None):  # type: ignore[no-untyped-def]
        titles.append(panel.title)
        return real(surface, area, panel, avoid)

    monkeypatch.setattr(render_module, "draw_panel", spy)
    game = PlayGame(PlaySettings("miami"), lockstep=True, size=SIZE)
    try:
        game.run(1)
        assert game.state == "ready" and "PAUSED" not in titles
        game._key(pygame.K_SPACE)
        titles.clear()
        game.run(1)
        assert game.state == "ready" and titles == ["miami: ready", "PAUSED"]
    finally:
        game.close()


def test_a_human_game_keeps_its_best_result_and_a_worse_one_does_not_replace_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("STEALTHFIELD_DATA", str(tmp_path))
    game = PlayGame(PlaySettings("miami", overrides=("world.duration=2",)), lockstep=True,
                    size=SIZE)
    try:
        game.start()
        while not game.world.done:
            game.run(30)
        game.run(1)
    finally:
        game.close()
    saved = json.loads((tmp_path / "best.json").read_text())
    assert saved["miami"]["pf"]["outcome"] == "survived"
    best = BestResults(tmp_path / "best.json")
    assert not best.offer("miami", "pf", {"outcome": "caught", "time": 1.0, "stars": 0})
    assert best.offer("miami", "pf", {"outcome": "won", "time": 1.0, "stars": 0})


def test_an_unreadable_best_file_is_never_overwritten(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "best.json"
    path.mkdir()  # cannot be read as a file (root reads through a chmod 000)
    best = BestResults(path)
    assert not best.offer("maze", "pf", {"outcome": "won", "time": 3.0, "stars": 0})
    assert path.is_dir() and not list(path.iterdir())
    assert capsys.readouterr().err.count("\n") == 1


def test_the_chooser_shows_cards_changes_guards_and_reads_best_results(tmp_path: Path) -> None:
    pygame.display.init()
    best = BestResults(tmp_path / "best.json")
    best.offer("maze", "fsm", {"outcome": "survived", "time": 60.0, "stars": 0})
    screen = pygame.display.set_mode((800, 700))
    chooser = LevelChooser(screen, ["maze", "miami"], best=best)
    chooser.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_RIGHT))
    chooser.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_RIGHT))
    assert chooser.mode == "fsm"
    assert best.best("maze", chooser.mode) is not None and best.best("miami", "fsm") is None
    chooser.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_DOWN))
    chooser.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_RETURN))
    assert chooser.run(frames=1) == "miami"
    assert [card.goal for card in chooser.cards] == ["survive until the time is up"] * 2
    picture = chooser.cards[0].picture
    floor = sum(picture.get_at((x, y))[:3] == FLOOR
                for x in range(0, picture.get_width(), 4) for y in range(0, picture.get_height(), 4))
    assert floor > 100


def test_a_level_with_an_exit_says_so_on_its_card() -> None:
    from game.front.chooser import LevelCard

    pygame.display.init()
    heist = Path(__file__).resolve().parents[1] / "examples" / "heist.json"
    card = LevelCard(str(heist))
    assert "reach the exit" in card.goal
