"""sb3-contrib MaskablePPO on ``stealthfield/Stealth-v0`` with the env's own action masks.

    pip install 'stealthfield[rl]'                  # gymnasium, sb3-contrib, ...
    python examples/train_maskable_ppo.py           # miami, grid, capture, PF guards; 10k steps
    python examples/train_maskable_ppo.py --steps 60000 --level maze

``MaskablePPO("MlpPolicy", make_vec_env(ENV_ID, n_envs=2))`` on the environment's default
options with sb3-contrib's default hyper-parameters, one torch thread: no masker of ours,
MaskablePPO reads ``action_masks()`` through the Monitor wrappers and the vector env. Every
env, in training and in evaluation, sits in a :class:`MaskAudit`, which only counts the
actions taken that the mask had ruled out (and the steps at which the mask ruled any out,
so a zero is not vacuous); the script fails if the count is not zero.

Then, as ``examples/train_ppo.py`` (whose ``play`` and ``paired`` it uses): the trained
policy (deterministic, masked), uniformly random actions, random among the open actions
and always-stay play the held-out seeds 0 … N−1, scored with the game's reward alone and
by survival time, paired per seed with a 95 % t interval. Prints a JSON summary last.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import gymnasium
import numpy as np

import game.env  # noqa: F401  (registers the environment)
from game.env import ENV_ID, StealthEnv
from train_ppo import Policy, paired, play  # beside this file


class MaskAudit(gymnasium.Wrapper):
    """Counts the steps whose action the env's mask had ruled out: a check, not a masker.

    ``restricted`` counts the steps at which the mask ruled out at least one action.
    """

    def __init__(self, env: gymnasium.Env) -> None:
        super().__init__(env)
        self.steps = self.restricted = self.masked = 0

    def step(self, action: Any) -> Any:
        mask = self.env.unwrapped.action_masks()  # type: ignore[attr-defined]
        self.steps += 1
        self.restricted += int(not mask.all())
        self.masked += int(not mask[int(action)])
        return self.env.step(action)


def audits(envs: list[MaskAudit]) -> dict[str, int]:
    """The counts of ``envs`` added up."""
    return {k: sum(getattr(e, k) for e in envs) for k in ("steps", "restricted", "masked")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--level", default="miami")
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--test-seeds", type=int, default=50)
    parser.add_argument("--train-seed", type=int, default=1000)
    args = parser.parse_args()

    import torch  # noqa: PLC0415
    from sb3_contrib import MaskablePPO  # noqa: PLC0415
    from stable_baselines3.common.env_util import make_vec_env  # noqa: PLC0415

    torch.set_num_threads(1)  # the machine is shared; SB3's MLP gains nothing from more
    train_envs: list[MaskAudit] = []

    def audited(env: gymnasium.Env) -> MaskAudit:
        train_envs.append(MaskAudit(env))
        return train_envs[-1]

    venv = make_vec_env(ENV_ID, n_envs=2, seed=args.train_seed, wrapper_class=audited,
                        env_kwargs={"level": args.level})
    model = MaskablePPO("MlpPolicy", venv, seed=args.train_seed, verbose=0)
    start = time.perf_counter()
    model.learn(total_timesteps=args.steps)
    train_s = time.perf_counter() - start
    trained = audits(train_envs)

    # the unshaped reward: the one that scores the game (shaping only guides learning)
    env = MaskAudit(StealthEnv(args.level, rewards={"seen": 0.0, "proximity": 0.0}))
    n = int(env.action_space.n)  # type: ignore[attr-defined]
    seeds = range(args.test_seeds)

    def masks() -> np.ndarray:
        return env.unwrapped.action_masks()  # type: ignore[attr-defined,no-any-return]

    players: dict[str, Policy] = {
        "masked": lambda obs, rng: int(model.predict(obs, action_masks=masks(),
                                                     deterministic=True)[0]),
        "random": lambda obs, rng: int(rng.integers(n)),
        "open": lambda obs, rng: int(rng.choice(np.flatnonzero(masks()))),
        "stay": lambda obs, rng: 0,
    }
    start = time.perf_counter()
    results, evaluated = {}, {}
    for name, policy in players.items():
        env.steps = env.restricted = env.masked = 0
        results[name] = play(env, policy, seeds)  # type: ignore[arg-type]
        evaluated[name] = audits([env])
    eval_s = time.perf_counter() - start

    print(f"{args.level}, grid, capture, PF guards; MaskablePPO {model.num_timesteps} steps "
          f"in {train_s:.0f} s; held-out seeds 0-{args.test_seeds - 1} ({eval_s:.0f} s)")
    print(f"training: {trained['masked']} masked actions taken in {trained['steps']} steps "
          f"({trained['restricted']} with an action masked out)")
    print(f"{'player':8} {'survival s':>10} {'capture rate':>12} {'return':>8} "
          f"{'masked taken':>12}")
    for name, r in results.items():
        print(f"{name:8} {r['survival'].mean():10.2f} {r['captured'].mean():12.2f} "
              f"{r['return'].mean():8.2f} {evaluated[name]['masked']:12d}")
    summary: dict[str, object] = {
        "level": args.level, "steps": model.num_timesteps, "train_seconds": round(train_s, 1),
        "eval_seconds": round(eval_s, 1), "training_audit": trained, "eval_audit": evaluated,
        "players": {k: {m: round(float(v.mean()), 3) for m, v in r.items()}
                    for k, r in results.items()}}
    for other in ("random", "open", "stay"):
        for metric in ("survival", "return"):
            mean, lo, hi = paired(results["masked"][metric], results[other][metric])
            print(f"masked - {other:6} {metric:8}: {mean:+.2f}  95% CI [{lo:+.2f}, {hi:+.2f}]")
            summary[f"masked-{other}-{metric}"] = [round(mean, 3), round(lo, 3), round(hi, 3)]
    print(json.dumps(summary))
    if trained["masked"] or evaluated["masked"]["masked"]:
        raise SystemExit("MaskablePPO took an action its mask had ruled out")


if __name__ == "__main__":
    main()
