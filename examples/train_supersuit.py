"""SB3 PPO on the PettingZoo ``parallel_env`` through SuperSuit: one policy for player and guards.

    pip install 'stealthfield[rl]'                  # pettingzoo, supersuit, stable-baselines3
    python examples/train_supersuit.py              # maze, grid, capture, 3 guards; 10k steps
    python examples/train_supersuit.py --steps 50000 --level miami

docs/api.md's recipe as it is written there: ``pettingzoo_env_to_vec_env_v1`` turns the
parallel env into a vector env with one row per agent (player, guard_0, guard_1, guard_2),
``concat_vec_envs_v1(..., base_class="stable_baselines3")`` hands it to
``PPO("MlpPolicy", venv, n_steps=64, batch_size=64)``. Steps are SB3's: one per agent per
env step, so 10,000 steps are 2,500 moves of the player. One torch thread.

SuperSuit's SB3 wrapper has no ``seed()`` (``PPO(seed=...)`` raises AttributeError), so the
training seed goes to the wrapped env's first reset and to SB3's ``set_random_seed``.

Then the shared policy (deterministic) and uniformly random actions play the held-out seeds
0 … N−1 on either side, scored for the player with the game's reward alone (the guards'
reward is its negation): player policy or random × guards policy or random, paired per seed.
Prints a JSON summary last.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable

import numpy as np

from game.env import PLAYER, StealthParallelEnv, parallel_env
from train_ppo import paired  # beside this file

Policy = Callable[[np.ndarray, np.random.Generator], int]


def play_sides(env: StealthParallelEnv, player: Policy, guards: Policy,
               seeds: range) -> dict[str, np.ndarray]:
    """The player's survival time, captured flag and return on each seed."""
    out: dict[str, list[float]] = {"survival": [], "captured": [], "return": []}
    for seed in seeds:
        # one generator per side, so a random side plays the same actions whoever it meets
        player_rng, guard_rng = (np.random.default_rng([seed, side]) for side in (0, 1))
        obs, infos = env.reset(seed=seed)
        total = 0.0
        while env.agents:
            actions = {a: player(obs[a], player_rng) if a == PLAYER else guards(obs[a], guard_rng)
                       for a in env.agents}
            obs, rewards, _, _, infos = env.step(actions)
            total += rewards[PLAYER]
        out["survival"].append(infos[PLAYER]["t"])
        out["captured"].append(float(infos[PLAYER]["captures"] > 0))
        out["return"].append(total)
    return {k: np.asarray(v) for k, v in out.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--level", default="maze")
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--test-seeds", type=int, default=50)
    parser.add_argument("--train-seed", type=int, default=1000)
    args = parser.parse_args()

    import supersuit  # noqa: PLC0415
    import torch  # noqa: PLC0415
    from stable_baselines3 import PPO  # noqa: PLC0415
    from stable_baselines3.common.utils import set_random_seed  # noqa: PLC0415

    torch.set_num_threads(1)  # the machine is shared; SB3's MLP gains nothing from more
    venv = supersuit.concat_vec_envs_v1(supersuit.pettingzoo_env_to_vec_env_v1(
        parallel_env(args.level)), 1, num_cpus=0, base_class="stable_baselines3")
    venv.venv.reset(seed=args.train_seed)  # learn()'s seedless reset then plays the next seed
    set_random_seed(args.train_seed)
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=64)
    start = time.perf_counter()
    model.learn(args.steps)
    train_s = time.perf_counter() - start

    env = parallel_env(args.level, rewards={"seen": 0.0, "proximity": 0.0})
    n = int(env.action_space(PLAYER).n)
    seeds = range(args.test_seeds)
    sides: dict[str, Policy] = {
        "policy": lambda obs, rng: int(model.predict(obs, deterministic=True)[0]),
        "random": lambda obs, rng: int(rng.integers(n)),
    }
    start = time.perf_counter()
    results = {(p, g): play_sides(env, sides[p], sides[g], seeds) for p in sides for g in sides}
    eval_s = time.perf_counter() - start

    print(f"{args.level}, grid, capture, {len(env.possible_agents) - 1} guards; SuperSuit -> "
          f"PPO {model.num_timesteps} steps in {train_s:.0f} s; held-out seeds "
          f"0-{args.test_seeds - 1} ({eval_s:.0f} s)")
    print(f"{'player':8} {'guards':8} {'survival s':>10} {'capture rate':>12} {'return':>8}")
    for (p, g), r in results.items():
        print(f"{p:8} {g:8} {r['survival'].mean():10.2f} {r['captured'].mean():12.2f} "
              f"{r['return'].mean():8.2f}")
    summary: dict[str, object] = {
        "level": args.level, "steps": model.num_timesteps, "train_seconds": round(train_s, 1),
        "eval_seconds": round(eval_s, 1),
        "players": {f"{p}/{g}": {m: round(float(v.mean()), 3) for m, v in r.items()}
                    for (p, g), r in results.items()}}
    # the player side: policy - random as the player; the guard side: random - policy as the
    # guards (the player's return lower against the trained guards is the guards' gain)
    for name, a, b in (("player", ("policy", "policy"), ("random", "policy")),
                       ("player vs random guards", ("policy", "random"), ("random", "random")),
                       ("guards", ("random", "random"), ("random", "policy")),
                       ("guards vs policy player", ("policy", "random"), ("policy", "policy"))):
        for metric in ("survival", "return"):
            mean, lo, hi = paired(results[a][metric], results[b][metric])
            print(f"{name:23} gain, player {metric:8}: {mean:+.2f}  95% CI [{lo:+.2f}, {hi:+.2f}]")
            summary[f"{name}-{metric}"] = [round(mean, 3), round(lo, 3), round(hi, 3)]
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
