"""The pygame front end, headless: every level and overlay, cones against walls, replay, CLI.

Runs under SDL's dummy video driver (set here, before pygame is imported), in lockstep:
one physics step of 1/60 s per frame.
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

from pathlib import Path

import numpy as np
import pygame
import pytest
import shapely

from game.front.play import PlayGame, PlaySettings
from game.front.render import DrawOptions, Renderer
from game.front.replay import Playback, detect_abstraction, load_trace
from game.scene import OVERLAYS, Scene, SceneBuilder
from game.trial import TrialSpec, run_trial
from headless.cli import main
from navmesh.graph import graph_for
from navmesh.level import load_level

LEVELS = ["arkham", "dishonored", "miami", "maze", "tlou"]
ABSTRACTION = {"arkham": "grid", "dishonored": "partition", "miami": "grid",
               "maze": "partition", "tlou": "grid"}
FRAMES_PER_OVERLAY = 40
#: distinct colours in the legend row with a colour bar (text alone has far fewer)
LEGEND_COLOURS = 120


@pytest.fixture(scope="module", autouse=True)
def display():
    pygame.display.init()
    pygame.font.init()
    yield
    pygame.display.quit()


def game(level: str = "miami", start: bool = True, **settings) -> PlayGame:
    """A lockstep game past its ready screen (``start=False``: still on it)."""
    g = PlayGame(PlaySettings(level, **settings), lockstep=True, size=(960, 800))
    if start:
        g.start()
    return g


def pixels(surface: pygame.Surface) -> np.ndarray:
    """(width, height, 3) copy of a surface's colours."""
    return pygame.surfarray.array3d(surface)


def render(renderer: Renderer, scene: Scene, options: DrawOptions | None = None) -> np.ndarray:
    surface = pygame.Surface(renderer.layout.size).convert()
    renderer.draw(surface, scene, options or DrawOptions())
    return pixels(surface)


def at(image: np.ndarray, renderer: Renderer, x: float, y: float) -> np.ndarray:
    px, py = renderer.to_screen(x, y)
    return image[int(px), int(py)].astype(int)


# ---------------------------------------------------------------------------- every level


@pytest.mark.parametrize("level", LEVELS)
def test_every_level_plays_with_every_overlay(level: str) -> None:
    g = game(level, autopilot="maxmin", abstraction=ABSTRACTION[level], show_plans=True)
    try:
        frames = checked = 0
        for key in OVERLAYS:
            if key != "none":
                pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_o))
            g.run(FRAMES_PER_OVERLAY)
            frames += FRAMES_PER_OVERLAY
            assert g.overlay == key
            shot = pixels(g.screen)
            assert len(np.unique(shot[::7, ::7].reshape(-1, 3), axis=0)) > 20  # not a blank
            if g.world.done:
                continue
            scene = g.scene
            assert scene is not None and scene.overlay == key
            if key in ("C", "N", "P", "K"):
                # The overlay recolours the floor: compare with the same frame without it,
                # at nodes away from the agents and their cones.
                assert scene.layer is not None and scene.layer.key == key
                plain = render(g.renderer, g.builder.from_world(g.world, "none"))
                nodes = _quiet_nodes(scene, g.builder.static.nodes)
                changed = [np.abs(at(shot, g.renderer, *p) - at(plain, g.renderer, *p)).sum() > 30
                           for p in nodes]
                assert np.mean(changed) > 0.5, key
                checked += 1
                legend = shot[:, 30:42].reshape(-1, 3)  # second HUD row: title, bar, min/max
                assert len(np.unique(legend, axis=0)) > LEGEND_COLOURS
        assert checked == 4  # C, N, P, K each compared with the plain frame
        assert g.world.step_index == frames  # one physics step per frame
        assert math.isclose(g.world.dt, 1 / 60)
    finally:
        g.close()


def _quiet_nodes(scene: Scene, nodes: np.ndarray) -> list[np.ndarray]:
    """Nodes at least 1.5 units from every agent and outside every cone."""
    agents = np.array([g.pos for g in scene.guards] + [scene.player.pos])
    far = np.hypot(*(nodes[:, None, :] - agents[None]).transpose(2, 0, 1)).min(axis=1) >= 1.5
    for g in scene.guards:
        if len(g.cone) >= 3:
            far &= ~shapely.contains_xy(shapely.Polygon(g.cone).buffer(0.3), nodes[:, 0], nodes[:, 1])
    return list(nodes[far])


# ---------------------------------------------------------------------------- information overlay


def test_information_overlay_changes_after_a_sighting() -> None:
    g = game("miami", guards="pf", overlay="I")
    try:
        world, graph = g.world, g.world.graph
        g.run(1)
        before = g.scene
        assert before.layer is not None and before.layer.vmin == 0.0 == before.layer.vmax
        for _ in range(50):  # step into plain sight of guard 0 until it sees the player
            guard = world.guards[0]
            spot = next(
                int(n) for n in np.argsort(graph.dist_from(guard.node))
                if 2.0 <= graph.dist_between(guard.node, n) <= 4.0
                and world.sees(guard, tuple(graph.positions[n]))
            )
            world.player.place(tuple(graph.positions[spot]))
            world.player.node = spot
            g.run(1)
            if world.seen_by:
                break
        assert world.seen_by
        g.run(60)  # the next AI tick applies the sighting to I
        after = g.scene
        assert after.layer is not None and after.layer.vmin < -4.0
        # Draw both frames without guards: the floor next to the sighting turns warm.
        seen = int(np.argmin(after.layer.values))
        neighbour = next(graph.positions[v] for v in graph.neighbors[seen]
                         if np.hypot(*(graph.positions[v] - world.player.pos)) > 0.6)
        colours = [at(render(g.renderer, dataclasses.replace(s, guards=())), g.renderer, *neighbour)
                   for s in (before, after)]
        (r0, _, b0), (r1, _, b1) = colours
        assert r1 - b1 > 100 and r1 - b1 > (r0 - b0) + 100, colours
    finally:
        g.close()


def test_modes_without_fields_show_a_note() -> None:
    g = game("tlou", guards="fsm", overlay="K")
    try:
        g.run(2)
        assert g.scene.layer is None and "fsm" in g.scene.field_note
    finally:
        g.close()


# ---------------------------------------------------------------------------- cones and walls


def _guard_facing_a_wall(level_name: str = "miami"):
    """A grid cell with a wall 2 cells to its right and walkable floor beyond that wall."""
    level = load_level(level_name)
    occ = level.occupancy
    rows, cols = occ.shape
    for r in range(rows):
        for c in range(cols - 5):
            if occ[r, c] and occ[r, c + 1] and not occ[r, c + 2] and occ[r, c + 3] and occ[r, c + 4]:
                return (c + 0.5, r + 0.5), (c + 1.5, r + 0.5), (c + 3.5, r + 0.5)
    raise AssertionError("no wall to face")


def test_cone_stops_at_a_wall() -> None:
    g = game("miami", guards="pf")
    try:
        world = g.world
        here, near, far = _guard_facing_a_wall()
        guard = world.guards[0]
        guard.place(here)
        guard.heading = 0.0
        world.guards[1].active = world.guards[2].active = False
        world.player.place((far[0] + 0.5, far[1]))  # behind the wall: hidden
        scene = g.builder.from_world(world)
        cone = shapely.Polygon(scene.guards[0].cone)
        assert cone.contains(shapely.Point(near)) and not cone.contains(shapely.Point(far))
        with_cone = render(g.renderer, dataclasses.replace(scene, guards=scene.guards[:1]))
        without = render(g.renderer, dataclasses.replace(scene, guards=()))
        assert np.abs(at(with_cone, g.renderer, *near) - at(without, g.renderer, *near)).sum() > 40
        assert np.array_equal(at(with_cone, g.renderer, *far), at(without, g.renderer, *far))
    finally:
        g.close()


@pytest.mark.parametrize("level", ["dishonored", "arkham"])
def test_cone_agrees_with_world_vision(level: str) -> None:
    """A point is inside a drawn cone exactly when World.sees says the guard sees it."""
    g = game(level, guards="random")
    try:
        world = g.world
        hidden = np.flatnonzero(~world.zones["concealment"])[0]  # full view range applies
        world.player.place(tuple(world.graph.positions[hidden]))
        world.player.node = int(hidden)
        rng = np.random.default_rng(1)
        builder: SceneBuilder = g.builder
        checked = 0
        for guard in world.guards:
            for heading in np.linspace(-math.pi, math.pi, 6, endpoint=False):
                guard.heading = float(heading)
                cone = shapely.Polygon(builder.cone(guard.pos, guard.heading, world.view_range))
                points = guard.pos + rng.uniform(-world.view_range, world.view_range, (150, 2))
                for p in points:
                    point = shapely.Point(p)
                    if cone.exterior.distance(point) < 0.05 or not world.level.contains(*p):
                        continue
                    assert cone.contains(point) == world.sees(guard, (float(p[0]), float(p[1])))
                    checked += 1
        assert checked > 500
    finally:
        g.close()


# ---------------------------------------------------------------------------- keys and game over


def test_keys_toggle_overlay_pause_and_mode() -> None:
    g = game("tlou")
    try:
        for key in (pygame.K_TAB, pygame.K_m, pygame.K_g, pygame.K_f, pygame.K_SPACE):
            pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=key))
        g.run(3)
        assert (g.overlay, g.show_mesh, g.show_plans, g.paused) == ("I", True, True, True)
        assert g.world.step_index == 0  # paused from the first frame on
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_3))
        g.run(1)
        assert g.state == "ready" and g.world.step_index == 0  # a restart waits for a move
        g.start()
        g.run(9)
        assert g.mode == "fsm" and g.world.guard_ai.mode == "fsm" and not g.paused
        assert g.world.step_index == 9
    finally:
        g.close()


def test_mechanic_keys_call_the_world() -> None:
    g = game("miami", guards="pf")
    try:
        world = g.world
        rain = bool(world.raining)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_r))
        g.run(1)
        assert world.raining != rain and g.scene.rain == world.raining
        assert g.message.startswith("rain:")
        x, y = world.player.pos
        click = tuple(int(v) for v in g.renderer.to_screen(x + 1.0, y))
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=click))
        g.run(1)
        assert g.message.startswith("throw decoy:")
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_f))
        g.run(1)
        assert g.message.startswith("take down:")
    finally:
        g.close()


def test_keyboard_moves_and_sprints_the_player(monkeypatch: pytest.MonkeyPatch) -> None:
    g = game("tlou", guards="random")
    try:
        world = g.world
        start = np.array(world.player.pos)
        keys = {pygame.K_d: (1, 0), pygame.K_a: (-1, 0), pygame.K_s: (0, 1), pygame.K_w: (0, -1)}
        key, direction = next(  # a direction with 1.2 units of free floor
            (k, np.array(d)) for k, d in keys.items()
            if world.level.walkable.contains(shapely.LineString([start, start + 1.2 * np.array(d)]).buffer(0.35))
        )
        monkeypatch.setattr(pygame.key, "get_pressed", lambda: _Pressed({key}))
        monkeypatch.setattr(pygame.key, "get_mods", lambda: pygame.KMOD_LSHIFT)
        g.run(12)
        assert world.sprinting and world.player_input == tuple(float(v) for v in direction)
        moved = float((np.array(world.player.pos) - start) @ direction)
        expected = 12 * world.dt * world.player_speed * world.sprint_factor
        assert moved == pytest.approx(expected, rel=0.05)
    finally:
        g.close()


def test_real_time_mode_steps_by_elapsed_time_and_resizes() -> None:
    g = PlayGame(PlaySettings("maze"), lockstep=False, size=(960, 800))
    g.start()
    try:
        g.frame(3.5 * g.world.dt)
        assert g.world.step_index == 3  # the remaining half step waits for the next frame
        g.frame(1.0)  # a stalled frame: at most MAX_CATCH_UP (0.5 s) caught up, not 1 s
        assert g.world.step_index == 3 + 30
        small = pygame.Surface((640, 480)).convert()
        g.renderer.draw(small, g.builder.from_world(g.world))
        static = g.builder.static
        for corner in [(0, 0), (static.width, static.height)]:
            px, py = g.renderer.to_screen(*corner)
            assert 0 <= px <= 640 and Renderer.HUD_HEIGHT <= py <= 480
    finally:
        g.close()


class _Pressed:
    def __init__(self, keys: set[int]) -> None:
        self.keys = keys

    def __getitem__(self, key: int) -> bool:
        return key in self.keys


def test_capture_ends_the_game_and_enter_restarts() -> None:
    g = game("tlou", guards="cheat", overrides=("world.player_hp=0.3",))
    try:
        for _ in range(40):
            g.run(60)
            if g.world.done:
                break
        assert g.world.done and g.scene.status == "captured"
        opts = g.options()
        assert g.state == "over" and opts.panel is not None and opts.panel.title == "CAUGHT"
        assert any("captures 1" in line for line in opts.panel.lines)  # the trial's metrics
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_RETURN))
        g.run(1)
        assert not g.world.done and g.state == "ready" and g.world.step_index == 0
    finally:
        g.close()


# ---------------------------------------------------------------------------- replay


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = {}
    folder = tmp_path_factory.mktemp("traces")
    for abstraction in ("grid", "partition"):
        buffer = io.StringIO()
        spec = TrialSpec("miami", abstraction, "fsm", "maxmin", "fixed", seed=2,
                         overrides=(("world.duration", "12"),))
        run_trial(spec, trace=buffer)
        path = folder / f"{abstraction}.jsonl"
        path.write_text(buffer.getvalue())
        out[abstraction] = path
    return out


def test_replay_detects_the_abstraction_and_interpolates_inside_walls(traces) -> None:
    level = load_level("miami")
    graphs = {name: graph_for(level, name) for name in ("grid", "partition")}
    for abstraction, path in traces.items():
        trace = load_trace(path)
        assert detect_abstraction(trace, graphs) == abstraction
        playback = Playback(trace, level)
        for t in np.linspace(playback.start, playback.end, 57):
            _, guards, player, _, hp = playback.state(float(t))
            for x, y in [p for p, _ in guards] + [player]:
                assert level.contains(x, y)
            assert 0 <= hp <= 3


def test_replay_cli_runs_and_saves_a_screenshot(traces, tmp_path: Path, capsys) -> None:
    shot = tmp_path / "replay.png"
    code = main(["replay", str(traces["partition"]), "--level", "miami", "--frames", "90",
                 "--speed", "4", "--plans", "--screenshot", str(shot)])
    assert code == 0 and shot.stat().st_size > 1000
    assert pygame.image.load(str(shot)).get_size()[0] >= 900


def _bad_trace(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.jsonl"
    path.write_text(text)
    return path


GOOD_LINE = {"t": 0.0, "player": {"pos": [1.5, 1.5], "hp": 3.0},
             "guards": [{"pos": [2.5, 2.5], "heading": 0.0, "sees_player": False}], "events": []}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty trace"),
        ("not json\n", "line 1: not JSON"),
        ("[1, 2]\n", "line 1: expected an object"),
        (json.dumps({**GOOD_LINE, "player": {"hp": 3}}) + "\n", "missing field 'pos'"),
        (json.dumps({**GOOD_LINE, "guards": [{"pos": [1, 2]}]}) + "\n", "sees_player"),
        (json.dumps({**GOOD_LINE, "t": "x"}) + "\n", "t: expected a finite number"),
        (json.dumps(GOOD_LINE) + "\n" + json.dumps(GOOD_LINE) + "\n", "does not increase"),
    ],
)
def test_broken_traces_are_one_line_errors(tmp_path: Path, capsys, text: str, message: str) -> None:
    code = main(["replay", str(_bad_trace(tmp_path, text)), "--level", "miami", "--frames", "1"])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err


def test_replay_without_a_level_asks_for_one(traces, tmp_path: Path, capsys) -> None:
    # a trace from before traces named their level: the first line without the header fields
    lines = traces["grid"].read_text().splitlines()
    first = {k: v for k, v in json.loads(lines[0]).items()
             if k not in ("level", "level_digest", "abstraction")}
    old = tmp_path / "old.jsonl"
    old.write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    assert main(["replay", str(old), "--frames", "1"]) == 2
    err = capsys.readouterr().err
    assert "--level" in err and len(err.strip().splitlines()) == 1
    assert main(["replay", str(tmp_path / "missing.jsonl"), "--level", "miami"]) == 2
    assert "no such file" in capsys.readouterr().err


# ---------------------------------------------------------------------------- play command line


def test_play_cli_headless_screenshot(tmp_path: Path, capsys) -> None:
    shot = tmp_path / "play.png"
    code = main(["play", "miami", "--autopilot", "maxmin", "--overlay", "kernel", "--frames", "30",
                 "--mesh", "--screenshot", str(shot)])
    assert code == 0 and shot.stat().st_size > 1000
    assert "30 frames" in capsys.readouterr().err
    assert main(["play", "miami", "--overlay", "bogus", "--frames", "1"]) == 2
    assert "unknown overlay" in capsys.readouterr().err
