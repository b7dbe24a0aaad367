"""Does SB3 PPO with its default hyper-parameters learn ``stealthfield/Stealth-v0``? (run by hand)

    python benchmarks/ppo_learning.py                       # 60k steps, 4 training seeds, 50 held-out
    python benchmarks/ppo_learning.py --steps 2048 --train-seeds 1 --test-seeds 5   # a smoke run
    python benchmarks/ppo_learning.py --env rewards='{"safety": 0}'                 # an env option

For each training seed k = 0 … K−1: ``PPO("MlpPolicy", make_vec_env(ENV_ID, n_envs, seed=S_k),
seed=k)`` with SB3's defaults, ``learn(steps)``, one torch thread; the episodes it trains on
are the trial seeds S_k = 1000 + 100,000·k onwards, never a held-out one. Then the trained
policy (deterministic), uniformly random actions and always-stay (action 0) play the held-out
trial seeds 0 … N−1 (the same seed is the same spawn for all three), each scored by the
game's return: the env's reward with every shaping term set to 0 — seconds survived, less
the HP and the captures lost (docs/api.md, "Rewards"). Printed per training seed: the three
mean returns and the paired differences PPO − random and PPO − stay with their 95 %
percentile-bootstrap intervals (scipy's, ``headless.analysis.stats.bootstrap_ci``, as every
table of the project); then one verdict line. Exit 0 when every training seed beats both
with the interval above 0, 1 when not, 2 for bad arguments. Deterministic: the same
arguments print the same figures (times aside).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

import numpy as np

import _paths  # noqa: F401  (project importable, this folder unshadowed)

#: The training episodes of training seed k start at trial seed TRAIN_SEED_BASE + k × STRIDE.
TRAIN_SEED_BASE = 1000
TRAIN_SEED_STRIDE = 100_000

Policy = Callable[[Any, np.random.Generator], int]


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are one ``ppo_learning: error: ...`` line and exit 2."""

    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"ppo_learning: error: {message}\n")
        raise SystemExit(2)


def _count(low: int) -> Callable[[str], int]:
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, not {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, not {value}")
        return value
    return parse


def _option(text: str) -> tuple[str, Any]:
    """``KEY=VALUE``: VALUE read as JSON when it is JSON, else as a string."""
    key, sep, raw = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, not {text!r}")
    try:
        value = json.loads(raw)
    except ValueError:
        value = raw
    return key, value


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    parser = _Parser(prog="ppo_learning", description=__doc__.split("\n")[0])
    parser.add_argument("--level", default="miami")
    parser.add_argument("--steps", type=_count(1), default=60_000,
                        help="PPO's total_timesteps per training seed (default 60,000)")
    parser.add_argument("--train-seeds", type=_count(1), default=4,
                        help="training seeds 0 … K-1 (default 4)")
    parser.add_argument("--first-train-seed", type=_count(0), default=0)
    parser.add_argument("--test-seeds", type=_count(2), default=50,
                        help="held-out trial seeds 0 … N-1 (default 50)")
    parser.add_argument("--n-envs", type=_count(1), default=1,
                        help="worlds in SB3's vector env (default 1, make_vec_env's)")
    parser.add_argument("--env", type=_option, action="append", default=[], metavar="KEY=VALUE",
                        help="an option of the env (JSON value), for training and held-out play")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON here")
    args = parser.parse_args(argv)
    args.env_kwargs = dict(args.env)
    if args.json and not Path(args.json).resolve().parent.is_dir():
        parser.error(f"argument --json: no folder for {args.json!r}")
    try:  # refuse an env option the env refuses, here, in one line
        _make_env(args.level, args.env_kwargs, game_only=True).close()
    except (ValueError, TypeError, KeyError, OSError) as error:
        parser.error(f"cannot build the env: {error}")
    return args


def _make_env(level: str, kwargs: dict[str, Any], game_only: bool) -> Any:
    from game.env import REWARDS, SHAPING, StealthEnv  # noqa: PLC0415

    kwargs = dict(kwargs)
    if game_only:  # the game's return: every shaping term off, the game's terms as given
        rewards = {**REWARDS, **kwargs.pop("rewards", {})}
        kwargs["rewards"] = {**rewards, **dict.fromkeys(SHAPING, 0.0)}
    return StealthEnv(level, **kwargs)


def play(env: Any, policy: Policy, seeds: Sequence[int]) -> dict[str, np.ndarray]:
    """Return (the game's), survival time and captured flag of ``policy`` on each seed."""
    out: dict[str, list[float]] = {"return": [], "survival": [], "captured": []}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        obs, info = env.reset(seed=seed)
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, info = env.step(policy(obs, rng))
            total += reward
            done = terminated or truncated
        out["return"].append(total)
        out["survival"].append(info["t"])
        out["captured"].append(float(info["captures"] > 0))
    return {k: np.asarray(v) for k, v in out.items()}


def paired(a: np.ndarray, b: np.ndarray, label: str) -> tuple[float, float, float]:
    """Mean of ``a - b`` and its 95 % percentile-bootstrap interval (scipy's)."""
    from headless.analysis.stats import bootstrap_ci  # noqa: PLC0415

    d = a - b
    low, high = bootstrap_ci(d, label)
    return float(d.mean()), low, high


def train(level: str, kwargs: dict[str, Any], steps: int, seed: int, n_envs: int) -> Any:
    """SB3 PPO with its defaults on the env, ``steps`` steps, training seed ``seed``."""
    import game.env  # noqa: F401, PLC0415  (registers the env)
    from stable_baselines3 import PPO  # noqa: PLC0415
    from stable_baselines3.common.env_util import make_vec_env  # noqa: PLC0415

    venv = make_vec_env(game.env.ENV_ID, n_envs=n_envs,
                        seed=TRAIN_SEED_BASE + TRAIN_SEED_STRIDE * seed,
                        env_kwargs={"level": level, **kwargs})
    model = PPO("MlpPolicy", venv, seed=seed, verbose=0)
    model.learn(total_timesteps=steps)
    return model


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        import torch  # noqa: PLC0415
        import stable_baselines3  # noqa: F401, PLC0415
    except ImportError as error:
        sys.stderr.write(f"ppo_learning: error: needs torch and stable-baselines3 "
                         f"({error.name} is missing): pip install 'stealthfield[rl]'\n")
        return 2
    torch.set_num_threads(1)  # the machine is shared; SB3's small MLP gains nothing from more

    env = _make_env(args.level, args.env_kwargs, game_only=True)
    n = int(env.action_space.n)
    seeds = range(args.test_seeds)
    start = time.perf_counter()
    baselines = {"random": play(env, lambda obs, rng: int(rng.integers(n)), seeds),
                 "stay": play(env, lambda obs, rng: 0, seeds)}
    options = " ".join(f"{k}={json.dumps(v)}" for k, v in args.env_kwargs.items()) or "defaults"
    print(f"{args.level}: env {options}; SB3 {stable_baselines3.__version__} PPO defaults, "
          f"{args.steps} steps, {args.n_envs} env(s); held-out seeds 0-{args.test_seeds - 1} "
          f"scored by the game's return")
    for name, r in baselines.items():
        print(f"  {name:6}  return {r['return'].mean():7.2f}  survival {r['survival'].mean():6.2f} s"
              f"  capture rate {r['captured'].mean():.2f}  ({time.perf_counter() - start:.0f} s)")

    figures: dict[str, Any] = {
        "level": args.level, "env": args.env_kwargs, "steps": args.steps, "n_envs": args.n_envs,
        "test_seeds": args.test_seeds,
        "baselines": {k: {m: float(v.mean()) for m, v in r.items()} for k, r in baselines.items()},
        "train_seeds": []}
    passed = 0
    first = args.first_train_seed
    for k in range(first, first + args.train_seeds):
        start = time.perf_counter()
        model = train(args.level, args.env_kwargs, args.steps, k, args.n_envs)
        train_s = time.perf_counter() - start
        start = time.perf_counter()
        ppo = play(env, lambda obs, rng: int(model.predict(obs, deterministic=True)[0]), seeds)
        eval_s = time.perf_counter() - start
        row: dict[str, Any] = {"seed": k, "trained_steps": int(model.num_timesteps),
                               "train_seconds": round(train_s, 1),
                               "ppo": {m: float(v.mean()) for m, v in ppo.items()}}
        ok = True
        parts = []
        for other in ("random", "stay"):
            mean, low, high = paired(ppo["return"], baselines[other]["return"],
                                     f"ppo_learning/{args.level}/{k}/{other}")
            row[f"ppo-{other}"] = [mean, low, high]
            ok = ok and low > 0
            parts.append(f"PPO - {other} {mean:+.2f} [{low:+.2f}, {high:+.2f}]")
        row["beats_both"] = ok
        passed += ok
        figures["train_seeds"].append(row)
        print(f"seed {k}: PPO return {ppo['return'].mean():7.2f}  survival "
              f"{ppo['survival'].mean():6.2f} s  capture rate {ppo['captured'].mean():.2f};  "
              f"{';  '.join(parts)}  {'beats both' if ok else 'DOES NOT beat both'}  "
              f"({model.num_timesteps} steps in {train_s:.0f} s, play {eval_s:.0f} s)",
              flush=True)
    verdict = passed == args.train_seeds
    print(f"verdict: {'PASS' if verdict else 'FAIL'}: PPO beats random and always-stay with the "
          f"95 % CI above 0 on {passed} of {args.train_seeds} training seeds")
    figures["passed"] = passed
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump(figures, out, indent=1)
    return 0 if verdict else 1


if __name__ == "__main__":
    raise SystemExit(main())
