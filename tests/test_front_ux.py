"""The game's flow, readability helpers, camera and recording, headless (dummy driver)."""

from __future__ import annotations

import json
import os
import re

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

from pathlib import Path

import numpy as np
import pygame
import pytest

from game.config import Config
from game.front.effects import NoiseRings, hearing_radius
from game.front.play import PlayGame, PlaySettings
from game.front.screenshots import SHOTS
from game.scene import SceneBuilder, vision_cone
from game.trial import TrialSpec, make_world
from navmesh.buildings import building_level
from navmesh.graph import graph_for
from navmesh.level import parse_level

ROOT = Path(__file__).resolve().parent.parent
HEIST = str(ROOT / "examples" / "heist.json")


@pytest.fixture(scope="module", autouse=True)
def display():
    pygame.display.init()
    pygame.font.init()
    yield
    pygame.display.quit()


def test_level_player_start_is_used_with_level_spawns() -> None:
    config = Config.load({"world.spawns": "level"})
    world = make_world(TrialSpec(HEIST, player="evade"), config, interactive=True)
    assert world.player.node == world.graph.node_at(2.5, 2.5)
    random = make_world(TrialSpec(HEIST, player="evade"), Config.load(), interactive=True)
    assert random.player.node == random.start_node() or random.player.node != world.player.node


def test_ready_screen_holds_the_clock_until_the_first_move(monkeypatch: pytest.MonkeyPatch) -> None:
    g = PlayGame(PlaySettings(HEIST), lockstep=True, size=(960, 800))
    try:
        g.run(30)
        assert g.state == "ready" and g.world.step_index == 0 and g.idle()
        assert g.options().panel is not None and "ready" in g.options().panel.title
        pressed = {pygame.K_d}
        monkeypatch.setattr(pygame.key, "get_pressed", lambda: type("P", (), {
            "__getitem__": lambda self, k: k in pressed})())
        g.run(5)
        assert g.state == "playing" and g.world.step_index == 5 and not g.idle()
    finally:
        g.close()


def test_collect_every_star_then_the_exit_wins() -> None:
    g = PlayGame(PlaySettings(HEIST, guards="random"), lockstep=True, size=(960, 800))
    try:
        g.start()
        world = g.world
        exit_area = world.level.exits[0].centroid
        world.place_player(world.graph.node_at(exit_area.x, exit_area.y))
        g.run(2)
        assert not world.done and g.state == "playing"  # the stars are still there
        for x, y in g.goal.collectibles:
            world.place_player(world.graph.node_at(x, y))
            g.run(1)
        assert g.goal.remaining == 0
        world.place_player(world.graph.node_at(exit_area.x, exit_area.y))
        g.run(1)
        assert world.done and g.state == "over" and g.outcome == "won"
        panel = g.options().panel
        assert panel is not None and panel.title == "ESCAPED"
        assert any("stars 2/2" in line for line in panel.lines)
    finally:
        g.close()


def test_recording_hands_a_human_row_and_trace_to_the_sink() -> None:
    got: list[tuple[dict, list[str]]] = []
    g = PlayGame(PlaySettings("tlou", guards="cheat", record=True,
                              overrides=("world.player_hp=0.3",)),
                 lockstep=True, size=(960, 800), on_session=lambda row, trace: got.append((row, list(trace))))
    try:
        g.start()
        while not g.world.done:
            g.run(60)
        g.run(1)
        assert len(got) == 1
        row, trace = got[0]
        assert row["player"] == "human" and row["key"].startswith("tlou/grid/cheat/human/capture/0/0/")
        assert row["metrics"]["captured"] is True and row["metrics"]["outcome"] == "caught"
        assert dict(row["overrides"]) == {"world.spawns": "level", "world.attack_needs_awareness": True,
                                          "awareness.enabled": True, "stimuli.takedown_range": 2.0,
                                          "world.player_hp": 0.3}
        assert len(row["visits"]) == g.world.graph.n and json.loads(trace[0])["t"] == 0.0
    finally:
        g.close()
    assert len(got) == 1  # closing does not store the same session twice


def test_noise_rings_appear_where_guards_hear_a_throw() -> None:
    g = PlayGame(PlaySettings("miami", autopilot="maxmin"), lockstep=True, size=(960, 800))
    try:
        world = g.world
        g.run(10)
        x, y = world.player.pos
        assert world.throw_decoy(x + 2.0, y)
        for _ in range(61):
            g.run(1)
            if g.rings.rings:
                break
        ring = g.rings.rings[0]
        assert ring.kind == "throw_landed" and ring.radius == pytest.approx(hearing_radius(world))
        assert ring.radius == pytest.approx(5 * world.graph.mean_edge_length)
    finally:
        g.close()


def test_camera_follows_zooms_and_the_static_layer_is_cached() -> None:
    level = building_level(60, 80, guards=4)
    path = Path(os.environ.get("TMPDIR", "/tmp")) / f"building-{os.getpid()}.json"
    path.write_text(json.dumps(level))
    g = PlayGame(PlaySettings(str(path), autopilot="maxmin"), lockstep=True, size=(960, 800))
    try:
        assert g.camera.zoom is None  # fits at >= 10 px per unit
        g.zoom(2.0)
        g.zoom(1.25)
        assert g.camera.zoom is not None and g.renderer.zoomed
        g.run(60)
        rebuilds = g.renderer.layers.rebuilds
        g.run(60)
        assert g.renderer.layers.rebuilds - rebuilds <= 2  # not once per frame
        px, py = g.renderer.to_screen(*g.world.player.pos)
        area = g.renderer.layout.world_rect
        assert area.collidepoint(px, py)  # the player stays in view
        for _ in range(10):
            g.zoom(0.5)
        assert g.camera.zoom is None and not g.renderer.zoomed
    finally:
        g.close()
        path.unlink()


def test_wall_buckets_cast_the_same_cones(monkeypatch: pytest.MonkeyPatch) -> None:
    import game.large.policy

    monkeypatch.setattr(game.large.policy, "BUCKET_MIN_WALLS", 10)  # buckets on a small level too
    level = parse_level(building_level(60, 80))
    builder = SceneBuilder(level, graph_for(level, "grid"), view_range=8.0, fov_deg=90.0)
    assert builder._buckets is not None
    rng = np.random.default_rng(1)
    for x, y in builder.static.nodes[rng.choice(len(builder.static.nodes), 25)]:
        heading = float(rng.uniform(-np.pi, np.pi))
        fast = builder.cone((x, y), heading, 8.0)
        full = vision_cone(builder._a, builder._d, builder._corners, (x, y), heading,
                           builder.half_fov, 8.0, builder.rays)
        np.testing.assert_allclose(fast, full)


def test_screenshot_command_makes_exactly_the_images_docs_show() -> None:
    shown = set(re.findall(r"\(img/(play-[^)]+\.png|replay-[^)]+\.png)\)",
                           (ROOT / "docs" / "play.md").read_text()))
    assert shown == set(SHOTS)


def test_replay_has_the_camera_and_minimap_of_the_game(tmp_path: Path) -> None:
    """A trace on a level too large for the window replays zoomed in, following the player;
    wheel and + / - zoom as in the game (Up / Down keep the speed)."""
    import io

    from game.front.replay import ReplayViewer
    from game.trace import load_trace
    from game.trial import run_trial
    from navmesh.level import load_level

    path = tmp_path / "building.json"
    path.write_text(json.dumps(building_level(120, 160, guards=4)))
    trace = io.StringIO()
    run_trial(TrialSpec(str(path), "grid", "pf", "maxmin", "capture", seed=0,
                        overrides=(("world.duration", 6.0),)), trace=trace)
    (tmp_path / "run.jsonl").write_text(trace.getvalue())
    viewer = ReplayViewer(load_trace(str(tmp_path / "run.jsonl")), load_level(str(path)), "grid",
                          speed=4.0, size=(960, 800))
    assert viewer.camera.zoom is not None and viewer.renderer.zoomed  # starts zoomed in
    viewer.run(40)
    area = viewer.renderer.layout.world_rect
    assert area.collidepoint(*viewer.renderer.to_screen(*viewer.focus()))
    before = viewer.camera.zoom
    pygame.event.post(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=1))
    viewer.run(1)
    assert viewer.camera.zoom > before
    for _ in range(12):
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_MINUS, mod=0, unicode="-"))
    viewer.run(1)
    assert viewer.camera.zoom is None and not viewer.renderer.zoomed  # the whole level again
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_UP, mod=0, unicode=""))
    viewer.run(1)
    assert viewer.speed == 8.0
