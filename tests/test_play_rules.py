"""``stealth play``'s own rules (issue 42), on a headless World and through the real front
under Xvfb: a guard hurts only a player it noticed (sees now, or saw within
``world.attack_memory``), the take-down reaches beyond the attack range, and none of it
reaches the headless defaults or the ``paper`` preset."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ai.view import GuardAI
from game.config import Config, play_defaults
from game.world import World
from navmesh.level import parse_level

ROOT = Path(__file__).resolve().parent.parent


class StayGuards(GuardAI):
    """Guards that never move (so only the heading says where they look)."""

    mode = "stay"

    def reset(self, graph, rng, n_guards) -> None:  # type: ignore[no-untyped-def]
        pass

    def decide(self, i, view) -> int:  # type: ignore[no-untyped-def]
        return int(view.guard_nodes[i])


ROOM = {"format": "stealth-level/1", "name": "room",
        "grid": ["#" * 11] + ["#" + "." * 9 + "#" for _ in range(9)] + ["#" * 11],
        "guards": [[5.5, 2.5]], "player": [8.5, 8.5]}


def _world(config: Config) -> World:
    world = World(parse_level(ROOM, "room.json"), "grid", StayGuards(), None, config=config,
                  scenario="capture", seed=0, interactive=True)
    world.player_input = (0.0, 0.0)
    return world


def _put(world: World, xy: tuple[float, float], heading: float) -> None:
    """The player at ``xy``; guard 0 at (5.5, 2.5) facing ``heading``."""
    world.player.place(xy)
    world.player.node = world.graph.node_at(*xy)
    world.guards[0].heading = heading


def _run(world: World, seconds: float, heading: float | None = None) -> None:
    for _ in range(round(seconds / world.dt)):
        if heading is not None:
            world.guards[0].heading = heading
        world.step()


PLAY = Config.for_play(["world.player_hp=3"])
PAPER = Config.load({"world.spawns": "level", "world.player_hp": 3.0})


def test_an_unaware_guard_in_range_does_no_damage_under_play_rules() -> None:
    """The player 1.0 behind a guard facing away (inside the 1.5 attack range): no damage in
    5 s with play's rules; the paper's rule (the headless default) hurts at once."""
    for config, hurt in ((PLAY, False), (PAPER, True)):
        world = _world(config)
        _put(world, (4.5, 2.5), heading=0.0)  # the guard faces +x, the player is at -x
        _run(world, 5.0, heading=0.0)
        assert world.seen_by == ()
        assert (world.hp < world.hp_max) is hurt, (config["world.attack_needs_awareness"], world.hp)
    assert world.done  # the paper's guard took all 3 HP in 3 s


def test_a_guard_that_noticed_hurts_and_stops_after_its_memory() -> None:
    """Facing the player it detects (after the awareness rises) and hurts; turned away it
    hurts for at most ``world.attack_memory`` more seconds after its last detection."""
    world = _world(Config.for_play(["world.player_hp=100"]))
    _put(world, (4.5, 2.5), heading=math.pi)  # facing the player
    _run(world, 3.0, heading=math.pi)
    assert world.seen_by == (0,) and world.hp < world.hp_max
    last_seen = world.t
    hp_turning = world.hp
    memory = float(world.config["world.attack_memory"])
    _run(world, memory + 2.0, heading=0.0)  # turned away (awareness may linger, then fades)
    assert world.seen_by == ()
    hp = world.hp
    _run(world, 3.0, heading=0.0)
    assert world.hp == hp < hp_turning  # it hurt on after turning, then stopped
    assert world.health.damage_steps * world.dt <= (world.t - last_seen) + 3.0 + 1e-9


def test_a_take_down_from_behind_reaches_beyond_the_attack_range() -> None:
    """1.8 behind the guard: outside its 1.5 attack range, inside play's 2.0 reach; the
    headless reach (1.0) refuses it."""
    world = _world(PLAY)
    _put(world, (3.7, 2.5), heading=0.0)
    assert math.dist(world.player.pos, world.guards[0].pos) > world.attack_range
    assert world.take_down() is True and not world.guards[0].active
    world = _world(PAPER)
    _put(world, (3.7, 2.5), heading=0.0)
    assert world.take_down() == "no guard within reach from behind"


def test_play_defaults_reach_neither_the_headless_defaults_nor_the_paper_preset() -> None:
    from headless.presets import load_preset

    paper = load_preset("paper")
    for config in (Config.defaults().as_dict(), paper.config):
        assert config["world.attack_needs_awareness"] is False
        assert config["awareness.enabled"] is False
        assert config["stimuli.takedown_range"] == 1.0
    assert paper.config_hash == "7647327243295999"  # as pinned before the play keys
    assert set(play_defaults()) == {"world.spawns", "world.attack_needs_awareness",
                                    "awareness.enabled", "stimuli.takedown_range"}
    assert Config.for_play(["world.attack_needs_awareness=false"])[
        "world.attack_needs_awareness"] is False  # --set still wins


def test_the_batch_engine_refuses_plays_rule() -> None:
    from game.trial import TrialSpec
    from headless.engines import check_covered
    from headless.errors import UserError

    spec = TrialSpec("miami", "grid", "pf", "maxmin", "capture", 0,
                     overrides=(("world.attack_needs_awareness", True),))
    with pytest.raises(UserError, match="attack_needs_awareness"):
        check_covered([spec])
    from headless.engines import split

    parts = split([spec], "auto")  # the default engine runs it on the reference instead
    assert parts.pymunk == [spec] and parts.batch == []
    assert "attack_needs_awareness" in parts.describe()


# ---------------------------------------------------------------- the real front (Xvfb)

_MISSING = [tool for tool in ("Xvfb",) if shutil.which(tool) is None]

_SESSION = textwrap.dedent("""
    import json, math, sys
    from game.front.play import PlayGame, PlaySettings
    from game.front.render import pygame
    sys.path.insert(0, {tests!r})
    from test_play_rules import StayGuards

    level, behind = sys.argv[1], float(sys.argv[2])
    game = PlayGame(PlaySettings(level, guards="random", overrides=tuple(sys.argv[3:])),
                    lockstep=False, size=(960, 640))
    assert pygame.display.get_driver() == "x11", pygame.display.get_driver()
    world = game.world
    world.guard_ai = StayGuards()
    guard = world.guards[0]
    for other in world.guards[1:]:
        world.down_guard(world.guards.index(other))  # one guard only: the scripted one
    world.player.place((guard.pos[0] - behind, guard.pos[1]))
    world.player.node = world.graph.node_at(*world.player.pos)
    guard.waypoints.clear()
    game.start()
    out = {{"hp": [], "t": []}}
    for _ in range(90):  # about 1.5 s of game time, in real time
        guard.heading = 0.0  # facing away from the player, at -x
        guard.waypoints.clear()
        game.frame(1 / 60)
        out["hp"].append(world.hp)
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_f, mod=0, unicode="f"))
    game.frame(1 / 60)
    out.update(active=guard.active, message=game.message, t=world.t, hp_max=world.hp_max,
               played=dict(game.sound.played))
    game.close()
    print(json.dumps(out))
""")


@pytest.mark.skipif(bool(_MISSING) and not os.environ.get("CI"), reason="needs Xvfb")
@pytest.mark.parametrize("overrides, hurt", [((), False),
                                             (("world.attack_needs_awareness=false",), True)])
def test_the_real_front_an_unaware_guard_does_no_damage_and_a_take_down_works(
        overrides: tuple[str, ...], hurt: bool, tmp_path: Path) -> None:
    """``stealth play``'s window (X11 on Xvfb): the player 1.2 behind a guard that faces
    away for 1.5 s of game time takes no damage, and F takes the guard down (1.2 is
    inside the 1.5 attack range: with the paper's rule set back, the same guard hurts)."""
    from game.front.xvfb import xvfb

    level = json.loads((ROOT / "examples" / "heist.json").read_text())
    guard = level["guards"][0]
    level.update(name="behind", guards=[guard], player=[guard[0] - 1.2, guard[1]])
    path = tmp_path / "behind.json"
    path.write_text(json.dumps(level))
    (tmp_path / "script.py").write_text(_SESSION.format(tests=str(ROOT / "tests")))
    with xvfb() as display:
        env = {**os.environ, "DISPLAY": display, "PYTHONPATH": str(ROOT),
               "SDL_AUDIODRIVER": "dummy", "STEALTHFIELD_DATA": str(tmp_path)}
        env.pop("SDL_VIDEODRIVER", None)
        done = subprocess.run([sys.executable, str(tmp_path / "script.py"), str(path), "1.2",
                               *overrides], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.splitlines()[-1])
    assert out["t"] > 1.0  # the session ran
    assert (min(out["hp"]) < out["hp_max"]) is hurt
    if not hurt:
        assert out["active"] is False and out["message"] == "take down: done"


# ---------------------------------------------------------------- replay to the true end


def test_a_replay_of_a_caught_session_ends_caught_at_its_capture_time(tmp_path: Path) -> None:
    """A recorded game caught between two AI ticks (cheat guards, 0.3 HP): its trace ends
    with the capture's moment, and ``stealth replay`` of it ends CAUGHT there, HP 0 (it
    stopped at the last whole tick, "END OF TRACE", with HP left), with the game's sounds."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
    from game.front.play import PlayGame, PlaySettings
    from game.front.replay import ReplayViewer
    from game.trace import load_trace
    from navmesh.level import load_level

    got: list[tuple[dict, list[str]]] = []
    game = PlayGame(PlaySettings("tlou", guards="cheat", record=True,
                                 overrides=("world.player_hp=0.3",)),
                    lockstep=True, size=(960, 800), on_session=lambda r, t: got.append((r, list(t))))
    try:
        game.start()
        while not game.world.done:
            game.run(30)
        game.run(1)
        capture = game.world.t
    finally:
        game.close()
    (row, lines), = got
    assert row["metrics"]["outcome"] == "caught"
    assert round(capture, 6) % 1.0 != 0  # between two AI ticks (1 s apart)
    path = tmp_path / "session.jsonl"
    path.write_text("".join(line + "\n" for line in lines))
    trace = load_trace(path)
    assert trace.lines[-1].t == pytest.approx(capture, abs=1e-6)
    assert trace.lines[-1].outcome == "caught" and trace.lines[-1].hp == pytest.approx(0, abs=1e-6)
    viewer = ReplayViewer(trace, load_level("tlou"), "grid", lockstep=True, speed=32.0,
                          config=game.config)
    frames = int(capture * 60 / 32) + 5
    viewer.run(frames)
    assert viewer.t == pytest.approx(capture, abs=1e-6)
    assert viewer.ending() == ("CAUGHT", "caught")
    assert viewer.playback.state(viewer.t)[4] == pytest.approx(0, abs=1e-6)  # HP 0 at the end
    played = viewer.sound.played  # with sound: the sighting, the hits, the end
    assert played["lose"] == 1 and played["win"] == 0
    assert played["sighting"] >= 1 and played["hurt"] >= 1
    viewer.run(5)
    assert played["lose"] == 1  # once
    viewer.close()


_REPLAY = textwrap.dedent("""
    import json, sys
    from game.front.play import PlayGame, PlaySettings
    from game.front.render import pygame
    from game.front.replay import ReplayViewer
    from game.trace import load_trace
    from navmesh.level import load_level

    got = []
    game = PlayGame(PlaySettings("tlou", guards="cheat", record=True,
                                 overrides=("world.player_hp=0.3",)),
                    lockstep=True, size=(960, 800), on_session=lambda r, t: got.append(list(t)))
    driver = pygame.display.get_driver()
    game.start()
    while not game.world.done:
        game.run(30)
    game.run(1)
    capture = game.world.t
    game.close()
    with open(sys.argv[1], "w") as handle:
        handle.write("".join(line + "\\n" for line in got[0]))
    viewer = ReplayViewer(load_trace(sys.argv[1]), load_level("tlou"), "grid", lockstep=True,
                          speed=32.0, config=game.config)
    viewer.run(int(capture * 60 / 32) + 5)
    out = dict(driver=driver, replay_driver=pygame.display.get_driver(), capture=capture,
               t=viewer.t, ending=list(viewer.ending()), hp=viewer.playback.state(viewer.t)[4],
               played=dict(viewer.sound.played))
    viewer.close()
    print(json.dumps(out))
""")


@pytest.mark.skipif(bool(_MISSING) and not os.environ.get("CI"), reason="needs Xvfb")
def test_the_real_front_replays_a_caught_session_to_caught(tmp_path: Path) -> None:
    """The same caught session played and replayed in an X11 window on Xvfb: the replay
    ends CAUGHT at the session's capture time (between two AI ticks), HP 0, with the sound
    of the end."""
    from game.front.xvfb import xvfb

    (tmp_path / "script.py").write_text(_REPLAY)
    with xvfb() as display:
        env = {**os.environ, "DISPLAY": display, "PYTHONPATH": str(ROOT),
               "SDL_AUDIODRIVER": "dummy", "STEALTHFIELD_DATA": str(tmp_path)}
        env.pop("SDL_VIDEODRIVER", None)
        done = subprocess.run([sys.executable, str(tmp_path / "script.py"),
                               str(tmp_path / "session.jsonl")], env=env, capture_output=True,
                              text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.splitlines()[-1])
    assert out["driver"] == out["replay_driver"] == "x11"
    assert round(out["capture"], 6) % 1.0 != 0  # between two AI ticks
    assert out["t"] == pytest.approx(out["capture"], abs=1e-6)
    assert out["ending"] == ["CAUGHT", "caught"] and out["hp"] == pytest.approx(0, abs=1e-6)
    assert out["played"]["lose"] == 1 and out["played"]["hurt"] >= 1


def test_a_headless_trace_of_a_capture_ends_caught_in_the_replay(tmp_path: Path) -> None:
    """``stealth sim --trace`` already wrote the final moment; its replay names it."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    from game.front.replay import ReplayViewer
    from game.trace import load_trace
    from game.trial import TrialSpec, run_trial
    from navmesh.level import load_level

    path = tmp_path / "t.jsonl"
    with path.open("w") as handle:
        row = run_trial(TrialSpec("tlou", "grid", "cheat", "maxmin", "capture", 0,
                                  overrides=(("world.player_hp", 0.3),)), trace=handle)
    trace = load_trace(path)
    viewer = ReplayViewer(trace, load_level("tlou"), "grid", lockstep=True)
    assert row["metrics"]["captured"] is True
    assert viewer.ending() == ("CAUGHT", "caught") and trace.lines[-1].outcome == ""


@pytest.mark.skipif(bool(_MISSING) and not os.environ.get("CI"), reason="needs Xvfb")
def test_every_action_and_hit_sounds_in_a_real_window(tmp_path: Path) -> None:
    """tests/test_front_menu.py's scripted session of every action and hit (the mixer
    calls counted) run again in an X11 window on Xvfb instead of SDL's dummy video."""
    from game.front.xvfb import xvfb

    with xvfb() as display:
        env = {**os.environ, "DISPLAY": display, "PYTHONPATH": str(ROOT),
               "SDL_VIDEODRIVER": "x11", "SDL_AUDIODRIVER": "dummy",
               "STEALTHFIELD_DATA": str(tmp_path), "STEALTH_TEST_VIDEO_DRIVER": "x11"}
        done = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:xdist", "-p", "no:cacheprovider",
             str(ROOT / "tests" / "test_front_menu.py") + "::test_every_action_and_hit_has_its_sound"],
            env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


def test_a_session_ended_on_a_tick_keeps_its_outcome_and_loads(tmp_path: Path) -> None:
    """A game that ends on an AI tick (time up at 2.0 s): the final line repeats that moment
    with the outcome, and the reader takes it as the last line (t still increasing)."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
    from game.front.play import PlayGame, PlaySettings
    from game.trace import load_trace

    got: list[list[str]] = []
    game = PlayGame(PlaySettings("maze", record=True, overrides=("world.duration=2",)),
                    lockstep=True, size=(960, 640), on_session=lambda r, t: got.append(list(t)))
    try:
        game.start()
        while not game.world.done:
            game.run(30)
        game.run(1)
    finally:
        game.close()
    (lines,) = got
    assert json.loads(lines[-1])["t"] == json.loads(lines[-2])["t"] == 2.0
    path = tmp_path / "s.jsonl"
    path.write_text("\n".join(lines) + "\n")
    trace = load_trace(path)
    assert [line.t for line in trace.lines] == [0.0, 1.0, 2.0]
    assert trace.lines[-1].outcome == "survived"
