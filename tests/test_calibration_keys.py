"""The world keys the calibration to the paper searches (issue 12): ``world.respawn`` and
``world.grid_decision_interval``, each defaulting to today's behaviour; and ``replay
--trial`` drawing the stored trial's own configuration."""

from __future__ import annotations

import argparse
import os
from typing import Any

import numpy as np
import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # replay_trial opens a (dummy) window

from game.config import Config  # noqa: E402
from game.errors import ConfigError  # noqa: E402
from game.spawns import hidden_node, respawn_node, start_node  # noqa: E402
from game.trial import TrialSpec, make_world, run_trial  # noqa: E402
from game.world import World  # noqa: E402

SHORT = (("world.duration", 12.0),)


def _decision_times(spec: TrialSpec) -> tuple[list[float], list[float]]:
    """The times at which the guard AI and the player policy were asked for a decision."""
    world = make_world(spec)
    guards: list[float] = []
    player: list[float] = []
    assert world.player_policy is not None
    ask_guard, ask_player = world.guard_ai.decide, world.player_policy.decide

    def guard(i: int, view: Any) -> int:
        guards.append(view.t)
        return int(ask_guard(i, view))

    def policy(view: Any) -> int:
        player.append(view.t)
        return int(ask_player(view))

    world.guard_ai.decide = guard  # type: ignore[method-assign]
    world.player_policy.decide = policy  # type: ignore[method-assign]
    world.run()
    return guards, player


def _off_tick(times: list[float], interval: float) -> list[float]:
    return [t for t in times if abs(t / interval - round(t / interval)) > 1e-6]


def test_the_defaults_are_todays_rules() -> None:
    config = Config.defaults()
    assert config["world.respawn"] == "farthest"
    assert config["world.grid_decision_interval"] == 0.0


@pytest.mark.parametrize("key, value", [("world.respawn", "near"), ("world.respawn", 1),
                                        ("world.grid_decision_interval", -0.5),
                                        ("world.grid_decision_interval", float("nan"))])
def test_values_outside_the_declared_bounds_are_refused(key: str, value: Any) -> None:
    with pytest.raises(ConfigError, match=key.split(".")[1]):
        Config.load({key: value})


def test_a_grid_decision_interval_gates_decisions_to_its_ticks() -> None:
    spec = TrialSpec("maze", "grid", "pf", "maxmin", "fixed", seed=1, overrides=SHORT)
    guards0, player0 = _decision_times(spec)
    # decide on arrival: a guard at 2 u/s crosses a cell in 0.5 s, so most decisions fall
    # between whole seconds
    assert len(_off_tick(guards0, 1.0)) > len(guards0) / 3
    gated = TrialSpec("maze", "grid", "pf", "maxmin", "fixed", seed=1,
                      overrides=SHORT + (("world.grid_decision_interval", 1.0),))
    guards1, player1 = _decision_times(gated)
    assert guards1 and player1
    assert _off_tick(guards1, 1.0) == [] and _off_tick(player1, 1.0) == []
    # one cell per tick at most: at most one decision per guard per tick (3 guards)
    assert len(guards1) <= 3 * 13 and len(guards1) < len(guards0)
    assert len(player1) <= 13 < len(player0)


def test_the_gate_is_grid_only_and_one_step_is_no_gate() -> None:
    base = TrialSpec("maze", "partition", "pf", "maxmin", "capture", seed=2, overrides=SHORT)
    gated = TrialSpec("maze", "partition", "pf", "maxmin", "capture", seed=2,
                      overrides=SHORT + (("world.grid_decision_interval", 1.0),))
    assert run_trial(base)["metrics"] == run_trial(gated)["metrics"]
    grid = TrialSpec("maze", "grid", "fsm", "safetygraph", "fixed", seed=3, overrides=SHORT)
    step = float(Config.defaults()["world.physics_step"])
    every_step = TrialSpec("maze", "grid", "fsm", "safetygraph", "fixed", seed=3,
                           overrides=SHORT + (("world.grid_decision_interval", step),
                                              ("world.respawn", "farthest")))
    assert run_trial(grid)["metrics"] == run_trial(every_step)["metrics"]


def _respawns(spec: TrialSpec) -> list[tuple[int, bool]]:
    """(node, whether some active guard saw it at that moment) of every respawn."""
    world = make_world(spec)
    seen: list[tuple[int, bool]] = []
    place = world.place_player

    def placed(node: int, *, forget_detection: bool = False) -> None:
        visible = any(world.senses.perceives(g.pos, g.heading, world.locomotion.node_point(node),
                                             world.view_range)
                      for g in world.guards if g.active)
        seen.append((node, visible))
        place(node, forget_detection=forget_detection)

    world.place_player = placed  # type: ignore[method-assign]
    world.run()
    return seen


def test_random_respawns_are_hidden_deterministic_and_not_the_farthest_rule() -> None:
    settings = (("world.respawn", "random"),)
    spec = TrialSpec("miami", "grid", "cheat", "maxmin", "fixed", seed=0, overrides=settings)
    first = _respawns(spec)
    assert len(first) >= 2  # Cheat captures the player several times in 60 s
    assert not any(visible for _, visible in first)
    assert _respawns(spec) == first  # a function of the trial's identity
    farthest = TrialSpec("miami", "grid", "cheat", "maxmin", "fixed", seed=0,
                         overrides=())
    assert [n for n, _ in _respawns(farthest)] != [n for n, _ in first]
    # the player's and guards' generators are untouched: the first capture is the same
    assert (run_trial(spec)["metrics"]["capture_time"]
            == run_trial(farthest)["metrics"]["capture_time"])


def _world(scenario: str = "fixed") -> World:
    return make_world(TrialSpec("maze", "grid", "random", "maxmin", scenario, seed=4))


def test_hidden_node_draws_uniformly_among_unseen_nodes() -> None:
    world = _world()
    g = world.graph
    visible = np.zeros(g.n, dtype=bool)
    for guard in world.guards:
        visible |= world.senses.visible_points(guard.pos, guard.heading, g.positions,
                                               world.view_range)
    assert visible.any() and not visible.all()
    rng = np.random.default_rng(7)
    draws = [hidden_node(g, world.guards, world.senses, world.view_range, rng)
             for _ in range(4000)]
    assert not visible[draws].any()
    counts = np.bincount(draws, minlength=g.n)[~visible]
    hidden = int((~visible).sum())
    assert (counts > 0).sum() > 0.95 * hidden  # spread over the hidden nodes ...
    assert counts.max() < 6 * 4000 / hidden  # ... none favoured
    # every node seen (view range huge, cone full): any node may come back
    everything = Config.load({"world.fov_deg": 360.0, "world.view_range": 1e6,
                              "world.attack_needs_line_of_sight": False})
    wide = make_world(TrialSpec("maze", "grid", "random", "maxmin", "fixed", seed=4), everything)
    node = hidden_node(wide.graph, wide.guards, wide.senses, 1e6, np.random.default_rng(0))
    assert 0 <= node < wide.graph.n


def test_respawn_node_dispatches_on_the_rule() -> None:
    world = _world()
    args = (world.graph, world.guards, world.senses, world.view_range)
    a = respawn_node("farthest", *args, np.random.default_rng(1))
    assert a == start_node(*args, np.random.default_rng(1))
    b = respawn_node("random", *args, np.random.default_rng(1))
    assert b == hidden_node(*args, np.random.default_rng(1))
    with pytest.raises(ValueError, match="world.respawn"):
        respawn_node("near", *args, np.random.default_rng(1))


def test_replay_of_a_stored_trial_draws_its_own_view_range(monkeypatch: pytest.MonkeyPatch,
                                                           tmp_path: Any) -> None:
    from game.front import replay

    made: list[Any] = []
    real = replay.ReplayViewer.__init__

    def spy(self: Any, *args: Any, **kwargs: Any) -> None:
        real(self, *args, **kwargs)
        made.append(self)

    monkeypatch.setattr(replay.ReplayViewer, "__init__", spy)
    spec = TrialSpec("maze", "grid", "random", "maxmin", "fixed", seed=0,
                     overrides=(("world.duration", 2.0), ("world.attack_range", 2.0)),
                     factors=(("world.view_range", 5.0),))
    shot = tmp_path / "shot.png"
    args = argparse.Namespace(trace="", trial="k", speed=1.0, frames=2, screenshot=str(shot),
                              level=None, abstraction=None, scenario=None, mesh=False,
                              plans=False)
    assert replay.replay_trial(spec, args) == 0
    assert made and made[0].view_range == 5.0 and made[0].attack_range == 2.0
