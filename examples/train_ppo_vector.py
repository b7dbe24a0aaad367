"""Stable-Baselines3 PPO through the vector env (``StealthVectorEnv``, the batch engine).

    pip install 'stealthfield[rl]'
    python examples/train_ppo_vector.py                      # 16 envs, 10^6 steps, miami
    python examples/train_ppo_vector.py --envs 8 --steps 20000 --test-seeds 10

SB3 takes its own ``VecEnv``, with the next episode started in the step that ended the last
(``terminal_observation`` in that step's info). :class:`SB3VecEnv` is that adapter: it
builds ``StealthVectorEnv(autoreset_mode="SameStep")`` — Gymnasium's same-step autoreset,
the last observation in ``info["final_obs"]`` — and hands SB3 its arrays. Training seeds:
sub-env i plays ``train_seed + i``, then ``+ n``, ... (no seed twice). PPO with SB3's
default hyper-parameters, one torch thread; the trained policy, uniformly random actions
and always-stay then play the held-out seeds 0 … N−1 with the unshaped reward, compared
in pairs (``examples/train_ppo.py``'s evaluation).
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnv

from game.env import StealthEnv, StealthVectorEnv
from train_ppo import play  # examples/train_ppo.py: the same held-out play


class SB3VecEnv(VecEnv):
    """``StealthVectorEnv`` as an SB3 ``VecEnv`` (same-step autoreset)."""

    def __init__(self, num_envs: int, **options: Any) -> None:
        self.vec = StealthVectorEnv(num_envs, autoreset_mode="SameStep", **options)
        super().__init__(num_envs, self.vec.single_observation_space,
                         self.vec.single_action_space)
        self._actions = np.zeros(num_envs, dtype=np.int64)

    def reset(self) -> np.ndarray:
        seeds = self._seeds
        seed = None if seeds[0] is None else int(seeds[0])  # SB3's seed(s): s, s + 1, ...
        obs, info = self.vec.reset(seed=seed)
        self.reset_infos = [{k: v[i] for k, v in info.items() if not k.startswith("_")}
                            for i in range(self.num_envs)]
        self._reset_seeds()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions, dtype=np.int64).reshape(self.num_envs)

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, rewards, terminated, truncated, info = self.vec.step(self._actions)
        done = terminated | truncated
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for i in np.flatnonzero(done).tolist():
            infos[i]["terminal_observation"] = info["final_obs"][i]
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, rewards.astype(np.float32), done, infos

    def action_masks(self) -> np.ndarray:
        return self.vec.action_masks()

    def close(self) -> None:
        self.vec.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.vec, attr_name) for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        setattr(self.vec, attr_name, value)

    def env_method(self, method_name: str, *args: Any, indices: Any = None,
                   **kwargs: Any) -> list[Any]:
        return [getattr(self.vec, method_name)(*args, **kwargs) for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--level", default="miami")
    parser.add_argument("--envs", type=int, default=16)
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--test-seeds", type=int, default=50)
    parser.add_argument("--train-seed", type=int, default=1000)
    args = parser.parse_args()

    import torch  # noqa: PLC0415
    from scipy import stats  # noqa: PLC0415
    from stable_baselines3 import PPO  # noqa: PLC0415

    torch.set_num_threads(1)
    venv = SB3VecEnv(args.envs, level=args.level)
    venv.seed(args.train_seed)
    model = PPO("MlpPolicy", venv, seed=args.train_seed, verbose=0)
    start = time.perf_counter()
    model.learn(total_timesteps=args.steps)
    train_s = time.perf_counter() - start

    env = StealthEnv(args.level, rewards={"seen": 0.0, "proximity": 0.0})
    n = env.action_space.n
    players = {"ppo": lambda obs, rng: int(model.predict(obs, deterministic=True)[0]),
               "random": lambda obs, rng: int(rng.integers(n)),
               "stay": lambda obs, rng: 0}
    results = {name: play(env, policy, range(args.test_seeds)) for name, policy in players.items()}
    print(f"{args.level}, grid, capture, PF guards; PPO {model.num_timesteps} steps through "
          f"{args.envs} vector sub-envs ({venv.vec.engine} engine) in {train_s:.0f} s")
    summary: dict[str, Any] = {"steps": model.num_timesteps, "train_seconds": round(train_s, 1),
                               "engine": venv.vec.engine}
    for name, r in results.items():
        print(f"{name:8} survival {r['survival'].mean():6.2f} s  capture rate "
              f"{r['captured'].mean():.2f}  return {r['return'].mean():7.2f}")
    for other in ("random", "stay"):
        d = results["ppo"]["return"] - results[other]["return"]
        ci = stats.bootstrap((d,), np.mean, confidence_level=0.95, random_state=0,
                             method="percentile").confidence_interval
        print(f"ppo - {other:6} return: {d.mean():+.2f}  95% CI [{ci.low:+.2f}, {ci.high:+.2f}]")
        summary[f"ppo-{other}-return"] = [round(float(d.mean()), 3), round(float(ci.low), 3),
                                          round(float(ci.high), 3)]
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
