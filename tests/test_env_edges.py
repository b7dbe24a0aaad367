"""The environments' edges (issue 35): blind guards play, and what cannot be played is
refused at construction with a ValueError naming the argument."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from game.env import REWARDS, StealthEnv, StealthVectorEnv, parallel_env  # noqa: E402


@pytest.mark.parametrize("blind", [{"world__view_range": 0.0},
                                   {"scenario__capture__view_range_scale": 0.0}])
def test_blind_guards_play_to_the_end(blind: dict) -> None:
    """docs/config.md: zero view ranges are a legitimate experiment. Cheating guards walk
    onto the player, so the proximity term is met at distance 0 (its limit: 1 there, 0
    anywhere else) and every observation and reward stays finite."""
    env = StealthEnv("maze", guards="cheat", world__duration=20.0, **blind)
    assert env.match.view_range == 0.0
    env.reset(seed=0)
    term = trunc = False
    steps = 0
    while not (term or trunc):
        obs, reward, term, trunc, info = env.step(steps % 5)
        assert np.isfinite(obs).all() and math.isfinite(reward)
        m = env.match
        d = m.guard_distance()
        expected = REWARDS["seen"] * bool(m.world.seen_by) + REWARDS["proximity"] * (d == 0)
        assert m.danger() == expected
        steps += 1
    assert steps > 1 and (term or math.isclose(info["t"], 20.0))


@pytest.mark.parametrize("action", [True, False, np.True_, np.array(True)])
def test_booleans_are_not_actions(action: object) -> None:
    env = StealthEnv("maze")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="invalid action"):
        env.step(action)
    penv = parallel_env("maze", world__guards=1)
    penv.reset(seed=0)
    with pytest.raises(ValueError, match="invalid action .* for 'guard_0'"):
        penv.step({"player_0": 0, "guard_0": action})


@pytest.mark.parametrize("weight", [math.nan, math.inf, -math.inf, "1", None, True, 1e308, -2e6])
def test_reward_weights_must_be_finite_numbers(weight: object) -> None:
    with pytest.raises(ValueError, match="reward weight 'survival' must be a finite number"):
        StealthEnv("maze", rewards={"survival": weight})
    with pytest.raises(ValueError, match="reward weight 'hp'"):
        parallel_env("maze", rewards={"hp": weight})
    StealthEnv("maze", rewards={"survival": np.float32(0.5), "hp": 2})  # numbers are fine


@pytest.mark.parametrize("size", [(-5, 5), (0, 10), (10.5, 10), (10,), "640x480", (9000, 10),
                                  (True, 10)])
def test_render_size_is_refused_at_construction(size: object) -> None:
    with pytest.raises(ValueError, match="render_size must be"):
        StealthEnv("maze", render_mode="rgb_array", render_size=size)
    assert StealthEnv("maze", render_size=np.array([64, 48])).match.render_size == (64, 48)


def test_a_vanishing_player_speed_stays_put() -> None:
    """5e-324 is in the documented range (0, inf): the player cannot cross an edge within
    a step's limit, so every action holds it for that limit and it never moves."""
    env = StealthEnv("maze", world__player_speed=5e-324, world__duration=30.0)
    m = env.match
    assert m.hold_steps == m.max_steps
    env.reset(seed=0)
    start = tuple(m.world.player.pos)
    for action in (1, 2, 3):
        obs, reward, term, trunc, info = env.step(action)
        assert math.isfinite(reward) and np.isfinite(obs).all()
        if term or trunc:
            break
    assert tuple(m.world.player.pos) == pytest.approx(start, abs=1e-9)


@pytest.mark.parametrize(("options", "words"), [
    ({"obs_radius": 10**9}, "obs_radius must be a whole number of cells in [0, 256]"),
    ({"obs_radius": 2.5}, "obs_radius must be"),
    ({"obs_radius": True}, "obs_radius must be"),
    ({"obs_radius": "3"}, "obs_radius must be"),
    ({"rewards": []}, "rewards must be a dict"),
    ({"rewards": "survival"}, "rewards must be a dict"),
    ({"scenario": "nope"}, "unknown scenario 'nope'"),
    ({"overrides": "world.guards=2"}, "overrides must be a dict"),
])
def test_options_of_the_wrong_kind_are_refused_naming_them(options: dict, words: str) -> None:
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        StealthEnv("maze", **options)


def test_vector_and_parallel_options_are_checked() -> None:
    for n in (10**9, 0, 2.7, True):
        with pytest.raises(ValueError, match="num_envs must be a whole number in"):
            StealthVectorEnv(num_envs=n, level="maze")
    with pytest.raises(ValueError, match="pad_observations must be True or False"):
        parallel_env("maze", pad_observations="no")
