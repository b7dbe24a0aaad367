"""Stable-Baselines3 PPO on ``stealthfield/Stealth-v0``, compared with random and always-stay.

    pip install 'stealthfield[rl]'             # gymnasium, pettingzoo, stable-baselines3, ...
    python examples/train_ppo.py               # miami, grid, capture, PF guards; 60k steps
    python examples/train_ppo.py --steps 20000 --test-seeds 20 --level maze

Plain SB3 on the environment's default options: ``PPO("MlpPolicy", make_vec_env(ENV_ID,
n_envs=2))`` with SB3's default hyper-parameters, training on seeds 1000, 1001, ... (the
vector env's seed), one torch thread. The trained policy (deterministic), uniformly random
actions and always-stay (action 0) then play the held-out seeds 0 … N−1; the same seed is the
same spawn for all three, so the comparison is paired per seed. Reported per player: the
mean survival time (s, 60 when never caught), the capture rate and the mean return of the
unshaped reward (survival, HP, capture terms only), then the paired differences with a
95 % t interval. Prints a JSON summary last.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable

import numpy as np

import game.env  # noqa: F401  (registers the environment)
from game.env import ENV_ID, StealthEnv

Policy = Callable[[np.ndarray, np.random.Generator], int]


def play(env: StealthEnv, policy: Policy, seeds: range) -> dict[str, np.ndarray]:
    """Survival time, captured flag and unshaped return of ``policy`` on each seed."""
    out: dict[str, list[float]] = {"survival": [], "captured": [], "return": []}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        obs, info = env.reset(seed=seed)
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, info = env.step(policy(obs, rng))
            total += reward
            done = terminated or truncated
        out["survival"].append(info["t"])
        out["captured"].append(float(info["captures"] > 0))
        out["return"].append(total)
    return {k: np.asarray(v) for k, v in out.items()}


def paired(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """Mean of ``a - b`` and its 95 % t interval."""
    from scipy import stats  # noqa: PLC0415

    d = a - b
    half = float(stats.t.ppf(0.975, len(d) - 1) * d.std(ddof=1) / math.sqrt(len(d)))
    return float(d.mean()), float(d.mean() - half), float(d.mean() + half)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--level", default="miami")
    parser.add_argument("--steps", type=int, default=60_000)
    parser.add_argument("--test-seeds", type=int, default=50)
    parser.add_argument("--train-seed", type=int, default=1000)
    parser.add_argument("--save", help="write the trained model here (.zip)")
    args = parser.parse_args()

    import torch  # noqa: PLC0415
    from stable_baselines3 import PPO  # noqa: PLC0415
    from stable_baselines3.common.env_util import make_vec_env  # noqa: PLC0415

    torch.set_num_threads(1)  # the machine is shared; SB3's MLP gains nothing from more
    venv = make_vec_env(ENV_ID, n_envs=2, seed=args.train_seed, env_kwargs={"level": args.level})
    model = PPO("MlpPolicy", venv, seed=args.train_seed, verbose=0)
    start = time.perf_counter()
    model.learn(total_timesteps=args.steps)
    train_s = time.perf_counter() - start
    if args.save:
        model.save(args.save)

    # the unshaped reward: the one that scores the game (shaping only guides learning)
    env = StealthEnv(args.level, rewards={"seen": 0.0, "proximity": 0.0})
    n = env.action_space.n
    seeds = range(args.test_seeds)
    players: dict[str, Policy] = {
        "ppo": lambda obs, rng: int(model.predict(obs, deterministic=True)[0]),
        "random": lambda obs, rng: int(rng.integers(n)),
        "stay": lambda obs, rng: 0,
    }
    start = time.perf_counter()
    results = {name: play(env, policy, seeds) for name, policy in players.items()}
    eval_s = time.perf_counter() - start

    # SB3 trains whole rollouts (2 envs x 2,048 steps): 60,000 asked are 61,440 trained
    print(f"{args.level}, grid, capture, PF guards; PPO {model.num_timesteps} steps in "
          f"{train_s:.0f} s; held-out seeds 0-{args.test_seeds - 1} ({eval_s:.0f} s)")
    print(f"{'player':8} {'survival s':>10} {'capture rate':>12} {'return':>8}")
    for name, r in results.items():
        print(f"{name:8} {r['survival'].mean():10.2f} {r['captured'].mean():12.2f} "
              f"{r['return'].mean():8.2f}")
    summary: dict[str, object] = {"level": args.level, "steps": model.num_timesteps,
                                  "train_seconds": round(train_s, 1),
                                  "players": {k: {m: round(float(v.mean()), 3) for m, v in r.items()}
                                              for k, r in results.items()}}
    for other in ("random", "stay"):
        for metric in ("survival", "return"):
            mean, lo, hi = paired(results["ppo"][metric], results[other][metric])
            print(f"ppo - {other:6} {metric:8}: {mean:+.2f}  95% CI [{lo:+.2f}, {hi:+.2f}]")
            summary[f"ppo-{other}-{metric}"] = [round(mean, 3), round(lo, 3), round(hi, 3)]
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
