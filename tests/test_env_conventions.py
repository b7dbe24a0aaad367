"""The environments follow Gymnasium's and PettingZoo's conventions (issue 41): int8 masks
that ``Discrete.sample(mask=...)`` takes, the AEC ``env()`` / ``raw_env()`` passing
PettingZoo's ``api_test``, ``state()`` / ``state_space``, ``player_0`` with the old name
still read, and ``spec.max_episode_steps`` on the registered env."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from pettingzoo.test import api_test  # noqa: E402
from pettingzoo.utils.wrappers import OrderEnforcingWrapper  # noqa: E402

from game.env import (  # noqa: E402
    ENV_ID,
    MAX_EPISODE_STEPS,
    PLAYER,
    PLAYER_CHANNELS,
    STATE_FEATURES,
    STATE_GUARD,
    StealthEnv,
    StealthParallelEnv,
    FlatObsWrapper,
    ImgObsWrapper,
    env,
    parallel_env,
    raw_env,
)


def test_masks_are_int8_and_discrete_sample_keeps_to_them() -> None:
    gym_env = StealthEnv("maze", world__duration=6.0)
    _, info = gym_env.reset(seed=0)
    space = gym_env.action_space
    space.seed(1)
    closed_seen = 0
    for _ in range(25):
        mask = info["action_mask"]
        assert mask.dtype == np.int8 and set(np.unique(mask)) <= {0, 1} and mask[0] == 1
        assert np.array_equal(gym_env.action_masks(), mask)
        closed_seen += int((mask == 0).sum())
        picks = {int(space.sample(mask=mask)) for _ in range(40)}
        assert picks <= set(np.flatnonzero(mask).tolist())
        _, _, term, trunc, info = gym_env.step(max(picks))
        if term or trunc:
            break
    assert closed_seen > 0  # maze's walls closed some action: the mask was not all ones
    penv = parallel_env("maze", world__guards=2)
    _, infos = penv.reset(seed=3)
    for agent in penv.agents:
        mask = infos[agent]["action_mask"]
        assert mask.dtype == np.int8
        assert int(penv.action_space(agent).sample(mask=mask)) in np.flatnonzero(mask)


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_aec_env_passes_pettingzoo_api_test(abstraction: str) -> None:
    api_test(env("maze", abstraction, world__duration=8.0), num_cycles=40)


def test_env_is_the_wrapped_raw_env_and_plays_the_parallel_episode() -> None:
    wrapped, raw = env("maze", world__guards=2), raw_env("maze", world__guards=2)
    assert isinstance(wrapped, OrderEnforcingWrapper) and not isinstance(raw, OrderEnforcingWrapper)
    assert isinstance(raw.unwrapped, StealthParallelEnv)  # the AEC env steps the parallel one
    penv = parallel_env("maze", world__guards=2)
    pobs, _ = penv.reset(seed=4)
    raw.reset(seed=4)
    assert raw.agent_selection == PLAYER and raw.possible_agents == penv.possible_agents
    assert np.array_equal(raw.observe(PLAYER), pobs[PLAYER])
    rng = np.random.default_rng(0)
    for _ in range(6):  # one move: every agent acts in turn, then the world plays it
        actions = {a: int(rng.integers(5)) for a in penv.agents}
        pobs, rewards, *_ = penv.step(actions)
        for agent in list(actions):
            assert raw.agent_selection == agent
            raw.step(actions[agent])
        for agent in penv.possible_agents:
            assert np.array_equal(raw.observe(agent), pobs[agent])
            assert raw.rewards[agent] == rewards[agent]
        assert np.array_equal(raw.state(), penv.state())


def test_state_is_everyone_true_position() -> None:
    penv = parallel_env("maze", world__guards=3)
    penv.reset(seed=2)
    for _ in range(4):
        penv.step({a: 2 for a in penv.agents})
    state = penv.state()
    assert state.dtype == np.float32 and penv.state_space.contains(state)
    assert state.shape == (len(STATE_FEATURES) + 3 * len(STATE_GUARD),)
    world, level = penv.match.world, penv.match.level
    width, height = level.cols * level.cell_size, level.rows * level.cell_size
    named = dict(zip(STATE_FEATURES, state.tolist(), strict=False))
    assert math.isclose(named["player_x"], world.player.pos[0] / width, rel_tol=1e-6)
    assert math.isclose(named["player_y"], world.player.pos[1] / height, rel_tol=1e-6)
    assert math.isclose(named["time"], world.t / penv.match.duration, rel_tol=1e-6)
    for i, guard in enumerate(world.guards):
        slot = state[len(STATE_FEATURES) + i * len(STATE_GUARD):][:len(STATE_GUARD)]
        fields = dict(zip(STATE_GUARD, slot.tolist(), strict=True))
        assert fields["active"] == 1.0
        assert math.isclose(fields["x"], guard.pos[0] / width, rel_tol=1e-6)
        assert math.isclose(fields["y"], guard.pos[1] / height, rel_tol=1e-6)
        assert math.isclose(fields["cos_heading"], math.cos(guard.heading), abs_tol=1e-6)
    # unlike the player's observation, the state holds the guards the player does not see
    assert len(penv.match.observer.perceived(world.view())) < len(world.guards)


def test_the_old_player_name_still_works_with_a_deprecation_warning() -> None:
    new, old = parallel_env("maze", world__guards=2), parallel_env("maze", world__guards=2)
    new.reset(seed=5)
    obs_old, _ = old.reset(seed=5)
    with pytest.warns(DeprecationWarning, match="'player' is deprecated.*'player_0'") as caught:
        first = obs_old["player"]
    assert caught[0].filename == __file__  # the warning points at the caller's line
    assert first is obs_old[PLAYER]
    assert "player" not in obs_old and set(obs_old) == set(old.agents)  # no extra agent
    for action in (2, 3, 0, 4):
        a = new.step({PLAYER: action, "guard_0": 1})
        with pytest.warns(DeprecationWarning) as caught:
            b = old.step({"player": action, "guard_0": 1})
        assert [w.filename for w in caught] == [__file__]
        assert np.array_equal(a[0][PLAYER], b[0][PLAYER]) and a[1] == b[1]
        with pytest.warns(DeprecationWarning):
            assert b[1]["player"] == a[1][PLAYER]
    with pytest.warns(DeprecationWarning) as caught:
        assert old.observation_space("player") is old.observation_space(PLAYER)
    assert caught[0].filename == __file__
    with pytest.warns(DeprecationWarning):
        assert old.action_space("player") is old.action_space(PLAYER)
    with pytest.warns(DeprecationWarning):
        assert np.array_equal(old.action_masks("player"), old.action_masks(PLAYER))
    with pytest.raises(ValueError, match="both 'player' and 'player_0'"):
        old.step({"player": 1, PLAYER: 2})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new name warns nothing
        new.step({PLAYER: 1})
        new.observation_space(PLAYER)
    with pytest.raises(KeyError):
        a[0]["guard_9"]


def test_the_registered_env_has_a_step_limit_that_can_be_changed() -> None:
    made = gymnasium.make(ENV_ID, level="maze")
    assert made.spec.max_episode_steps == MAX_EPISODE_STEPS == 1200
    one = made.unwrapped.match
    assert MAX_EPISODE_STEPS == round(one.duration / one.dt)  # the default episode, 1/20 s steps
    short = gymnasium.make(ENV_ID, level="maze", max_episode_steps=3)
    assert short.spec.max_episode_steps == 3
    short.reset(seed=0)
    flags = [short.step(0)[2:4] for _ in range(3)]
    assert flags[:2] == [(False, False)] * 2 and flags[2] == (False, True)  # cut at step 3
    unlimited = gymnasium.make(ENV_ID, level="maze", max_episode_steps=-1, world__duration=1.0)
    unlimited.reset(seed=0)
    steps, done = 0, False
    while not done:
        _, _, term, trunc, info = unlimited.step(0)
        steps, done = steps + 1, term or trunc
    assert math.isclose(info["t"], 1.0)  # the env's own clock ended it


@pytest.mark.parametrize("kind", ["dict", "image"])
def test_dict_and_image_observations_pass_check_env(kind: str) -> None:
    one = StealthEnv("maze", observation=kind, world__duration=6.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a checker warning is a failure here
        check_env(one, skip_render_check=True)


def test_the_wrappers_give_back_the_flat_and_the_image_observations() -> None:
    flat_env = StealthEnv("maze", obs_radius=3)
    as_flat = FlatObsWrapper(StealthEnv("maze", obs_radius=3, observation="dict"))
    as_image = ImgObsWrapper(StealthEnv("maze", obs_radius=3, observation="dict"))
    image_env = StealthEnv("maze", obs_radius=3, observation="image")
    assert as_flat.observation_space == flat_env.observation_space
    assert as_image.observation_space == image_env.observation_space
    assert image_env.observation_space.shape == (7, 7, len(PLAYER_CHANNELS))
    envs = (flat_env, as_flat, as_image, image_env)
    outs = [e.reset(seed=3)[0] for e in envs]
    rng = np.random.default_rng(2)
    for _ in range(30):
        flat, wrapped, img_w, img = outs
        assert np.array_equal(flat, wrapped) and wrapped.dtype == np.float32
        assert np.array_equal(img_w, img) and as_image.observation_space.contains(img)
        # the image is the flat window, channel-last: the player's own cell at the centre
        window = flat[:7 * 7 * len(PLAYER_CHANNELS)].reshape(len(PLAYER_CHANNELS), 7, 7)
        assert np.array_equal(img, window.transpose(1, 2, 0))
        assert img[3, 3, PLAYER_CHANNELS.index("player")] == 1.0
        action = int(rng.integers(5))
        steps = [e.step(action) for e in envs]
        outs = [s[0] for s in steps]
        assert len({(s[1], s[2], s[3]) for s in steps}) == 1  # the same play
        if steps[0][2] or steps[0][3]:
            break
    made = gymnasium.make(ENV_ID, level="maze", observation="dict")
    obs, _ = made.reset(seed=0)
    assert made.observation_space.contains(obs) and set(obs) == {"image", "features"}
    with pytest.raises(ValueError, match="unknown observation 'rgb'.*flat, dict, image"):
        StealthEnv("maze", observation="rgb")
    with pytest.raises(ValueError, match="observation='dict'"):
        ImgObsWrapper(StealthEnv("maze"))
