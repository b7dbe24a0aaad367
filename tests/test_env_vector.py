"""The vector env (game.env.vector) on the batch engine: sub-env i is the single env of
seed s + i, step for step (EnvPool's alignment test), with Gymnasium's NEXT_STEP autoreset,
partial resets and the step limit."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from gymnasium.vector import AutoresetMode  # noqa: E402

from game.env import ENV_ID, MAX_EPISODE_STEPS, StealthEnv, StealthVectorEnv  # noqa: E402


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, dict):
        return all(np.array_equal(a[k], b[k]) for k in a)
    return bool(np.array_equal(a, b))


def _row(obs: Any, i: int) -> Any:
    return {k: v[i] for k, v in obs.items()} if isinstance(obs, dict) else obs[i]


@pytest.mark.parametrize("level, abstraction, guards, observation, n", [
    ("miami", "grid", "pf", "flat", 6),
    ("tlou", "partition", "cheat", "dict", 4),
    ("arkham", "grid", "fsm", "image", 5),
])
def test_each_sub_env_is_the_single_env_of_its_seed_step_for_step(
        level: str, abstraction: str, guards: str, observation: str, n: int) -> None:
    options = {"level": level, "abstraction": abstraction, "guards": guards,
               "observation": observation, "world__duration": 25.0}
    vec = StealthVectorEnv(n, **options)
    assert vec.engine == "batch"
    obs, info = vec.reset(seed=40)
    checked = [0, n // 2, n - 1]  # the first, one inside, the last
    singles = {i: StealthEnv(**options) for i in checked}
    for i, env in singles.items():
        first, one_info = env.reset(seed=40 + i)
        assert _same(first, _row(obs, i)) and info["seed"][i] == one_info["seed"] == 40 + i
    rng = np.random.default_rng(2)
    running = set(checked)
    ends = []
    while running:
        actions = rng.integers(0, vec.single_action_space.n, n)
        obs, rewards, terminated, truncated, info = vec.step(actions)
        for i in sorted(running):
            one, reward, term, trunc, one_info = singles[i].step(int(actions[i]))
            assert _same(one, _row(obs, i))
            assert (rewards[i], terminated[i], truncated[i]) == (reward, term, trunc)
            assert np.array_equal(info["action_mask"][i], one_info["action_mask"])
            assert info["t"][i] == one_info["t"] and info["hp"][i] == one_info["hp"]
            if term or trunc:
                running.discard(i)
                ends.append(term)
    assert True in ends  # some episode ended in a capture, not only by the clock


def test_an_ended_sub_env_resets_at_the_next_step_with_the_next_seed_of_its_own() -> None:
    vec = StealthVectorEnv(3, level="maze", world__duration=2.0)
    assert vec.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
    vec.reset(seed=10)
    ended = np.zeros(3, dtype=bool)
    while not ended.all():
        _, _, terminated, truncated, _ = vec.step(np.ones(3, dtype=np.int64))
        ended |= terminated | truncated
        if (terminated | truncated).any():
            break
    done = terminated | truncated
    obs, rewards, terminated, truncated, info = vec.step(np.ones(3, dtype=np.int64))
    for i in np.flatnonzero(done):
        # the step after the end: the action is not played, the next episode starts
        assert rewards[i] == 0.0 and not terminated[i] and not truncated[i]
        assert info["seed"][i] == 10 + i + 3 and info["t"][i] == 0.0  # no seed played twice
        assert np.array_equal(obs[i], StealthEnv("maze", world__duration=2.0).reset(
            seed=int(10 + i + 3))[0])


def test_a_partial_reset_resets_only_the_masked_sub_envs() -> None:
    vec = StealthVectorEnv(4, level="maze")
    vec.reset(seed=0)
    for _ in range(3):
        before, *_ , before_info = vec.step(np.full(4, 2, dtype=np.int64))
    mask = np.array([False, True, False, True])
    obs, info = vec.reset(seed=100, options={"reset_mask": mask})
    assert info["_seed"].tolist() == mask.tolist()
    assert info["seed"][1] == 101 and info["seed"][3] == 103
    assert np.array_equal(obs[~mask], before[~mask])  # the others keep their episode
    assert np.array_equal(obs[1], StealthEnv("maze").reset(seed=101)[0])
    t = vec.step(np.zeros(4, dtype=np.int64))[4]["t"]
    assert t[0] > before_info["t"][0] and t[1] < t[0]  # the reset ones started over
    with pytest.raises(ValueError, match="reset_mask must be a bool array"):
        vec.reset(options={"reset_mask": [1, 0, 1, 0]})


def test_the_step_limit_truncates_as_time_limit_does() -> None:
    vec = StealthVectorEnv(2, max_episode_steps=2, level="maze")
    vec.reset(seed=0)
    truncated = [vec.step(np.zeros(2, dtype=np.int64))[3].tolist() for _ in range(2)]
    assert truncated == [[False, False], [True, True]]
    made = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                              level="maze")
    assert isinstance(made, StealthVectorEnv) and made.limit == MAX_EPISODE_STEPS
    assert gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                              level="maze", max_episode_steps=-1).limit is None
    with pytest.raises(ValueError, match="max_episode_steps must be"):
        gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                           level="maze", max_episode_steps=0)


def test_the_reference_engine_plays_the_same_moves() -> None:
    # world.engine = "pymunk" (or a rule the batch engine does not cover under "auto"):
    # each world steps on its own, the same episodes
    options = {"level": "maze", "world__duration": 6.0}
    batch = StealthVectorEnv(3, **options)
    reference = StealthVectorEnv(3, world__engine="pymunk", **options)
    uncovered = StealthVectorEnv(3, stimuli__raining=True, **options)
    assert (batch.engine, reference.engine, uncovered.engine) == ("batch", "pymunk", "pymunk")
    with pytest.raises(ValueError, match="does not cover rain"):
        StealthVectorEnv(3, stimuli__raining=True, world__engine="batch", **options)
    a, _ = batch.reset(seed=5)
    b, _ = reference.reset(seed=5)
    assert np.array_equal(a, b)
    rng = np.random.default_rng(0)
    for _ in range(12):
        actions = rng.integers(0, 5, 3)
        one, two = batch.step(actions), reference.step(actions)
        for x, y in zip(one[:4], two[:4], strict=True):
            assert np.array_equal(x, y)


def test_wrong_actions_and_calls_are_refused_naming_them() -> None:
    vec = StealthVectorEnv(2, level="maze")
    with pytest.raises(RuntimeError, match="before reset"):
        vec.step(np.zeros(2, dtype=np.int64))
    vec.reset(seed=0)
    with pytest.raises(ValueError, match="actions must have shape"):
        vec.step(np.zeros(3, dtype=np.int64))
    with pytest.raises(ValueError, match="invalid action 7 for sub-env 1"):
        vec.step(np.array([0, 7]))
    with pytest.raises(ValueError, match="does not render"):
        StealthVectorEnv(2, level="maze", render_mode="rgb_array")
    assert vec.action_masks().shape == (2, 5)


def test_same_step_autoreset_starts_the_next_episode_in_the_step_that_ended_one() -> None:
    # Gymnasium's SAME_STEP (what SB3's VecEnv expects): the last observation and info of
    # the ended episode in info["final_obs"] / info["final_info"], the next one's first
    # observation in its place
    options = {"level": "maze", "world__duration": 2.0}
    vec = StealthVectorEnv(3, autoreset_mode="SameStep", **options)
    assert vec.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
    reference = StealthVectorEnv(3, **options)
    vec.reset(seed=10)
    reference.reset(seed=10)
    ones = np.ones(3, dtype=np.int64)
    while True:
        obs, rewards, terminated, truncated, info = vec.step(ones)
        last, expected, *_ = reference.step(ones)
        assert np.array_equal(rewards, expected)
        if (terminated | truncated).any():
            break
        assert np.array_equal(obs, last)
    for i in np.flatnonzero(terminated | truncated):
        assert np.array_equal(info["final_obs"][i], last[i])
        assert info["final_info"]["t"][i] == 2.0 and info["t"][i] == 0.0
        assert info["seed"][i] == 13 + i and np.array_equal(
            obs[i], StealthEnv(**options).reset(seed=int(13 + i))[0])
    with pytest.raises(ValueError, match="autoreset_mode must be"):
        StealthVectorEnv(2, level="maze", autoreset_mode="Disabled")
