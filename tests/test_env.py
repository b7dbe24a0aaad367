"""The RL environments (game/env.py): API conformance, seeding, step semantics, rendering."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")  # the `test` extra installs both
pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from pettingzoo.test import parallel_api_test, parallel_seed_test  # noqa: E402

from game.env import ENV_ID, REWARDS, SHAPING, StealthEnv, parallel_env  # noqa: E402
from game.trial import TrialSpec, make_world  # noqa: E402

ABSTRACTIONS = ("grid", "partition")
UNSHAPED = dict.fromkeys(SHAPING, 0.0)  # the game's own terms only


@pytest.mark.parametrize("abstraction", ABSTRACTIONS)
def test_pettingzoo_parallel_api(abstraction: str) -> None:
    env = parallel_env("maze", abstraction, world__duration=8.0)
    parallel_api_test(env, num_cycles=40)


@pytest.mark.parametrize("abstraction", ABSTRACTIONS)
def test_pettingzoo_seed(abstraction: str) -> None:
    parallel_seed_test(lambda: parallel_env("maze", abstraction, world__duration=8.0),
                       num_cycles=30)


@pytest.mark.parametrize("abstraction", ABSTRACTIONS)
def test_gymnasium_check_env(abstraction: str) -> None:
    env = StealthEnv("maze", abstraction=abstraction, world__duration=8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a checker warning is a failure here
        check_env(env, skip_render_check=True)


def test_registered_with_gymnasium() -> None:
    env = gymnasium.make(ENV_ID, level="maze", guards="fsm", world__duration=4.0)
    obs, info = env.reset(seed=5)
    assert env.observation_space.contains(obs) and info["seed"] == 5


def test_spaces_follow_the_abstraction() -> None:
    assert StealthEnv("maze").action_space.n == 5
    assert StealthEnv("maze", abstraction="partition").action_space.n == 9
    env = parallel_env("maze", world__guards=2, obs_radius=2, pad_observations=False)
    assert env.possible_agents == ["player_0", "guard_0", "guard_1"]
    # player: 3 channels of 5x5, 7 own features, 7 per guard, 3 per action;
    # guards: 5 channels, 7, 5 per guard, 3
    assert env.observation_space("player_0").shape == (3 * 25 + 7 + 2 * 7 + 5 * 3,)
    assert env.observation_space("guard_1").shape == (5 * 25 + 7 + 2 * 5 + 3,)
    padded = parallel_env("maze", world__guards=2, obs_radius=2)  # the default: one size
    assert all(padded.observation_space(a) == env.observation_space("guard_1")
               for a in padded.possible_agents)
    obs, _ = padded.reset(seed=0)
    own = StealthEnv("maze", world__guards=2, obs_radius=2)
    first, _ = own.reset(seed=0)
    assert np.array_equal(obs["player_0"][:len(first)], first)  # the player's layout, then zeros
    assert not obs["player_0"][len(first):].any()


def _rollout(env: StealthEnv, seed: int, actions: np.ndarray) -> tuple[list, list]:
    obs, _ = env.reset(seed=seed)
    seen, rewards = [obs], []
    for a in actions:
        obs, r, term, trunc, _ = env.step(int(a))
        seen.append(obs)
        rewards.append(r)
        if term or trunc:
            break
    return seen, rewards


@pytest.mark.parametrize("abstraction", ABSTRACTIONS)
def test_same_seed_same_episode(abstraction: str) -> None:
    actions = np.random.default_rng(7).integers(0, 9 if abstraction == "partition" else 5, 60)
    a = _rollout(StealthEnv("maze", abstraction=abstraction), 11, actions)
    b = _rollout(StealthEnv("maze", abstraction=abstraction), 11, actions)
    assert len(a[0]) == len(b[0])
    assert all(np.array_equal(x, y) for x, y in zip(a[0], b[0], strict=True))
    assert a[1] == b[1]
    c = _rollout(StealthEnv("maze", abstraction=abstraction), 12, actions)
    assert len(a[0]) != len(c[0]) or any(  # another seed, another episode
        not np.array_equal(x, y) for x, y in zip(a[0], c[0], strict=True))


def test_seedless_resets_continue_from_the_seed() -> None:
    env = StealthEnv("maze", world__duration=2.0)
    env.reset(seed=20)
    assert env.reset()[1]["seed"] == 21
    assert env.reset()[1]["seed"] == 22


def test_episode_starts_where_the_trial_of_that_seed_starts() -> None:
    """Spawns come from the trial's spawn generator: same guards and player start."""
    env = StealthEnv("maze", guards="pf")
    for seed in (0, 4):
        env.reset(seed=seed)
        trial = make_world(TrialSpec("maze", "grid", "pf", "maxmin", "capture", seed))
        assert env.match.world.player.pos == trial.player.pos
        assert [g.pos for g in env.match.world.guards] == [g.pos for g in trial.guards]
        assert [g.heading for g in env.match.world.guards] == [g.heading for g in trial.guards]


def test_a_grid_step_is_one_cell_and_stay_stays() -> None:
    env = StealthEnv("maze", guards="random", world__player_hp=1e6, rewards=UNSHAPED)  # never captured
    env.reset(seed=2)
    world = env.match.world
    moves = env.match.moves
    moved = 0
    for action in (1, 2, 3, 4, 0):
        start, before_t = world.player.node, world.t
        _, reward, *_ = env.step(action)
        expected = moves[start, action]
        assert world.player.node == expected
        assert np.allclose(world.player.pos, world.graph.positions[expected])
        if expected != start:
            moved += 1
            # one cell at 2.4 cells/s (capture scenario) takes 9 physics steps of 0.05 s
            assert math.isclose(world.t - before_t, 0.45)
        else:
            assert math.isclose(world.t - before_t, env.match.hold_steps * 0.05)
        assert math.isclose(reward, REWARDS["survival"] * (world.t - before_t))  # survival only
    assert moved >= 2


def test_capture_ends_the_episode_with_the_penalty() -> None:
    env = StealthEnv("maze", guards="cheat", world__guards=3, rewards=UNSHAPED)
    env.reset(seed=0)
    total, term, trunc, info = 0.0, False, False, {}
    while not (term or trunc):
        _, r, term, trunc, info = env.step(0)  # a player that never moves
        total += r
    assert term and not trunc and info["captures"] == 1 and info["hp"] <= 0
    expected = REWARDS["survival"] * info["t"] - REWARDS["hp"] * 3.0 - REWARDS["capture"]
    assert math.isclose(total, expected, abs_tol=1e-6)


def test_guard_agents_move_as_told_and_see_fields() -> None:
    env = parallel_env("maze", world__guards=2)
    obs, _ = env.reset(seed=3)
    world = env.match.world
    moves = env.match.moves
    guard_nodes = [g.node for g in world.guards]
    # the guards decide at their first arrival, which is the first physics step
    env.step({"player_0": 0, "guard_0": 2, "guard_1": 3})
    targets = [g.target for g in world.guards]
    assert targets == [moves[guard_nodes[0], 2], moves[guard_nodes[1], 3]]
    for _ in range(6):
        obs, rewards, *_ = env.step({"player_0": 0, "guard_0": 1, "guard_1": 4})
        assert rewards["guard_0"] == -rewards["player_0"]
    side = (2 * env.match.observer.radius + 1) ** 2
    confidence = obs["guard_0"][4 * side:5 * side]
    assert confidence.max() > 0  # the team's confidence field is observed


@pytest.mark.parametrize("abstraction", ABSTRACTIONS)
def test_rgb_array_render(abstraction: str) -> None:
    env = StealthEnv("maze", abstraction=abstraction, render_mode="rgb_array",
                     render_size=(320, 280))
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (280, 320, 3) and frame.dtype == np.uint8
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 5  # a real picture, not a blank
    env.step(1)
    assert env.render().shape == frame.shape  # the cached renderer draws the next frame
    penv = parallel_env("maze", render_mode="rgb_array", render_size=(200, 200))
    penv.reset(seed=0)
    assert penv.render().shape == (200, 200, 3)


def test_no_pygame_without_rendering() -> None:
    code = ("import sys, game.env as e; env = e.StealthEnv('maze'); env.reset(seed=0); "
            "env.step(1); print('pygame' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ}, check=True)
    assert out.stdout.strip() == "False"


def test_bad_options_are_clear() -> None:
    with pytest.raises(ValueError, match="abstraction"):
        StealthEnv("maze", abstraction="hex")
    with pytest.raises(ValueError, match="render_mode"):
        StealthEnv("maze", render_mode="ascii")
    with pytest.raises(ValueError, match="unknown config key"):
        StealthEnv("maze", world__gards=2)


def test_fixed_time_capture_respawns_and_counts_the_penalty() -> None:
    env = StealthEnv("maze", guards="cheat", scenario="fixed", world__duration=20.0,
                     rewards=UNSHAPED)
    env.reset(seed=0)
    total, term, trunc, info = 0.0, False, False, {}
    while not (term or trunc):
        _, r, term, trunc, info = env.step(0)
        total += r
    assert not term and trunc and info["captures"] >= 1 and math.isclose(info["t"], 20.0)
    lost = 3.0 * info["captures"] + (3.0 - info["hp"])
    expected = (REWARDS["survival"] * 20.0 - REWARDS["hp"] * lost
                - REWARDS["capture"] * info["captures"])
    assert math.isclose(total, expected, abs_tol=1e-6)


@pytest.mark.parametrize("action", [-1, 5, 1.7, "2", None, np.float64(1.0)])
def test_actions_outside_the_space_are_refused(action: object) -> None:
    env = StealthEnv("maze")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="invalid action"):
        env.step(action)
    assert env.step(np.int64(2))[4]["t"] > 0  # numpy integers are actions


def test_parallel_env_refuses_unknown_agents_and_bad_actions() -> None:
    env = parallel_env("maze", world__guards=2)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="unknown agent.*guard_7"):
        env.step({"player_0": 0, "guard_7": 1})
    with pytest.raises(ValueError, match="invalid action -1 for 'guard_0'"):
        env.step({"player_0": 0, "guard_0": -1})
    env.step({"player_0": 1, "guard_0": 2})


def test_action_masks_say_which_actions_move() -> None:
    env = StealthEnv("maze")
    _, info = env.reset(seed=0)
    moves = env.match.moves
    for _ in range(15):
        node = env.match.world.player.node
        mask = env.action_masks()
        assert np.array_equal(mask, info["action_mask"]) and mask[0]
        assert np.array_equal(mask[1:], moves[node, 1:] != node)
        _, _, term, trunc, info = env.step(int(np.flatnonzero(mask)[-1]))
        if term or trunc:
            break
    penv = parallel_env("maze", world__guards=2)
    _, infos = penv.reset(seed=1)
    g = penv.match.world.guards[1].node
    assert np.array_equal(infos["guard_1"]["action_mask"][1:], moves[g, 1:] != g)
    assert np.array_equal(penv.action_masks("guard_1"), infos["guard_1"]["action_mask"])


def test_player_observation_points_at_perceived_guards() -> None:
    """Guard slots are nearest first in view-range units; each action's safety is the path
    distance of its target from the nearest perceived guard."""
    from game.env import MOVE_FEATURES, PLAYER_CHANNELS, PLAYER_FEATURES, PLAYER_GUARD

    env = StealthEnv("maze", guards="cheat", world__player_hp=1e6)
    m = env.match
    side = (2 * m.observer.radius + 1) ** 2
    base = len(PLAYER_CHANNELS) * side + len(PLAYER_FEATURES)
    obs, _ = env.reset(seed=0)
    for _ in range(200):
        slots = obs[base:base + len(PLAYER_GUARD) * m.n_guards].reshape(m.n_guards, -1)
        if slots[0, 0] > 0:
            break
        obs, *_ = env.step(0)
    else:
        raise AssertionError("the cheating guards never came into view")
    w = m.world
    known = [j for j in range(m.n_guards) if m.observer.player_sees(w.view(), j)]
    dists = sorted(math.dist(w.guards[j].pos, w.player.pos) for j in known)
    assert np.allclose(slots[:len(known), 3], np.array(dists) / m.view_range, atol=1e-5)
    assert (slots[len(known):] == 0).all()
    moves = obs[base + len(PLAYER_GUARD) * m.n_guards:].reshape(-1, len(MOVE_FEATURES))
    near = m.graph.dist_from([w.guards[j].node for j in known]).min(axis=0)
    cap = 2 * m.view_range
    reach = np.minimum(near[m.moves[w.player.node]], cap)
    assert np.allclose(moves[:, 1], reach / cap, atol=1e-5)
    # gain: how much farther than staying each move's target lies, in moves (cells), ±1 at most
    assert moves[0, 2] == 0 and m.observer.edge == m.graph.mean_edge_length
    assert np.allclose(moves[:, 2], np.clip((reach - reach[0]) / m.observer.edge, -1, 1), atol=1e-5)
    assert set(np.round(moves[moves[:, 0] > 0, 2], 5)) <= {-1.0, 0.0, 1.0}  # grid: a cell a move


def test_gain_tells_the_moves_apart_as_safety_does_in_move_units() -> None:
    """``gain`` orders the actions as ``safety`` does (both measure the same distances), but a
    move's worth of distance is 1, not 1 / (2 × view range in cells) ≈ 0.08: a policy's
    first layer tells the safer move apart without weights of tens."""
    from game.env import MOVE_FEATURES

    env = StealthEnv("maze", guards="cheat", world__player_hp=1e6)
    obs, _ = env.reset(seed=1)
    k = len(MOVE_FEATURES) * env.action_space.n
    differed, done = 0, False
    while not done:
        moves = obs[-k:].reshape(-1, len(MOVE_FEATURES))
        safety, gain = moves[:, 1], moves[:, 2]
        assert np.array_equal(np.sign(np.round(safety - safety[0], 6)), np.sign(gain))
        differed += bool(np.ptp(safety) > 0)
        obs, _, term, trunc, _ = env.step(int(np.argmax(gain)))
        done = term or trunc
    assert differed > 10


def test_shaping_is_the_change_of_a_potential() -> None:
    """Same episode with and without the seen / proximity terms: per step, the difference
    is the drop of ``danger`` (seen + nearness of the nearest guard), so over an episode it
    sums to the first value minus the last and never pays a player to be caught sooner."""
    kw = {"guards": "cheat", "world__player_hp": 1e6}  # guards that come, a player never caught
    plain, shaped = StealthEnv("maze", rewards=UNSHAPED, **kw), StealthEnv("maze", **kw)
    plain.reset(seed=3)
    shaped.reset(seed=3)
    first = previous = shaped.match.danger()
    assert first == 0.0 or first > 0
    dangers = []
    for a in [0, 2, 2, 3, 1, 4, 0, 0, 2, 3] * 6:
        _, r0, *_ = plain.step(a)
        _, r1, *_ = shaped.step(a)
        now = shaped.match.danger()
        assert math.isclose(r1 - r0, previous - now, abs_tol=1e-9)
        previous = now
        dangers.append(now)
    m = shaped.match
    near = max(0.0, 1 - m.guard_distance() / m.view_range)
    assert math.isclose(now, REWARDS["seen"] * bool(m.world.seen_by) + REWARDS["proximity"] * near)
    assert max(dangers) > REWARDS["seen"]  # the cheating guards came near and saw the player


def test_vector_entry_point_steps_several_worlds() -> None:
    venv = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="vector_entry_point",
                              level="maze", world__duration=3.0)
    obs, info = venv.reset(seed=4)
    assert obs.shape == (2, *StealthEnv("maze").observation_space.shape)
    assert list(info["seed"]) == [4, 5]
    one, _ = StealthEnv("maze").reset(seed=5)
    assert np.array_equal(obs[1], one)
    assert venv.action_masks().shape == (2, 5)
    for _ in range(10):
        obs, rewards, *_ = venv.step(np.array([1, 2]))
    assert obs.shape[0] == 2 and rewards.shape == (2,)


def test_supersuit_vectorises_the_parallel_env_as_it_is() -> None:
    """docs/api.md: SuperSuit's PettingZoo → vector env wrappers need one observation size."""
    supersuit = pytest.importorskip("supersuit")  # the `test` extra installs it
    env = parallel_env("maze", world__guards=2, world__duration=3.0)
    venv = supersuit.concat_vec_envs_v1(supersuit.pettingzoo_env_to_vec_env_v1(env), 2,
                                        num_cpus=0, base_class="gymnasium")
    obs, _ = venv.reset(seed=0)
    assert venv.num_envs == 6 and obs.shape == (6, *env.observation_space("player_0").shape)
    for _ in range(15):
        obs, rewards, *_ = venv.step(np.zeros(6, dtype=np.int64))
    assert rewards.shape == (6,)


def test_supersuit_copies_of_a_new_env_play_their_own_seeds() -> None:
    """SuperSuit pickles one copy of the env per vector slot before any reset, and SB3 resets
    them seedless (its SuperSuit wrapper cannot seed): each copy draws its own first seed."""
    supersuit = pytest.importorskip("supersuit")
    env = parallel_env("maze", world__guards=2, world__duration=3.0)
    venv = supersuit.concat_vec_envs_v1(supersuit.pettingzoo_env_to_vec_env_v1(env), 2,
                                        num_cpus=0, base_class="gymnasium")
    _, infos = venv.reset()
    assert infos[0]["seed"] != infos[3]["seed"]  # rows 0 and 3: the two copies' players
