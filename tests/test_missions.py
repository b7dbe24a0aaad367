"""The bundled missions (issue 42): collect-and-escape levels first in ``stealth play``'s
chooser and its N / B cycle, in no preset, each valid and winnable."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.config import Config  # noqa: E402
from game.objectives import Objectives  # noqa: E402
from game.schema import check_level  # noqa: E402
from navmesh.level import bundled_level_names, load_level, mission_names  # noqa: E402


def test_three_missions_come_first_and_are_in_no_preset() -> None:
    from game.front.chooser import play_levels
    from headless.presets import load_preset

    missions = mission_names()
    assert len(missions) >= 3 and {"heist", "vault", "warehouse"} <= set(missions)
    assert play_levels()[:len(missions)] == missions
    assert play_levels()[len(missions):] == bundled_level_names()
    assert not set(missions) & set(bundled_level_names())
    paper = load_preset("paper")
    assert not any(m in str(level) for m in missions for level in paper.levels)


@pytest.mark.parametrize("name", mission_names())
def test_a_mission_is_a_valid_collect_and_escape_level_and_can_be_won(
        name: str, monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    level = load_level(name)  # a bare name finds assets/missions
    check_level(Config.for_play(), level)
    goal = Objectives.of(level)
    assert goal.has_goal and len(goal.collected) >= 2 and level.exits
    monkeypatch.setenv("STEALTHFIELD_DATA", str(tmp_path))
    from game.front.play import PlayGame, PlaySettings

    game = PlayGame(PlaySettings(name, guards="random"), lockstep=True, size=(960, 640))
    try:
        game.start()
        world = game.world
        spots = [tuple(p) for p in game.goal.collectibles]
        exit_area = level.exits[0].centroid
        spots.append((exit_area.x, exit_area.y))
        for x, y in spots:  # a script walks there (teleported node by node)
            world.place_player(world.graph.node_at(x, y))
            game.run(2)
        game.run(1)
        assert game.outcome == "won", (game.outcome, game.goal.remaining)
    finally:
        game.close()
