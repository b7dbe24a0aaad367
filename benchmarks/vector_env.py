"""Env steps per second of the vector env against one env, random actions (run by hand).

    taskset -c 0 python benchmarks/vector_env.py [--num-envs 256] [--level miami]
        [--abstraction grid] [--guards pf] [--seconds 20] [--engine auto]

Both measured in this process, one after the other: ``StealthEnv`` stepped alone (the
reference rate), then ``StealthVectorEnv`` with ``--num-envs`` sub-envs (each vector step
is ``num_envs`` env steps: one player move in every sub-env). Printed: each rate, in env
steps per wall second and per CPU second, and their ratio. Targets (issue 43), one core:
≥ 50,000 env steps/s at 256 envs and ≥ 30× the single env.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from game.env import StealthEnv, StealthVectorEnv


def single_rate(options: dict, seconds: float) -> tuple[float, float]:
    """(env steps per wall second, per CPU second) of one env, random actions."""
    env = StealthEnv(**options)
    env.action_space.seed(0)
    env.reset(seed=0)
    steps = 0
    cpu, start = time.process_time(), time.perf_counter()
    while time.perf_counter() - start < seconds:
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        steps += 1
        if terminated or truncated:
            env.reset()
    return steps / (time.perf_counter() - start), steps / (time.process_time() - cpu)


def vector_rate(options: dict, num_envs: int, seconds: float) -> tuple[float, float, str, float]:
    """(env steps per wall second, per CPU second, engine, set-up seconds) of the vector
    env, random actions (autoreset plays on)."""
    built = time.perf_counter()
    env = StealthVectorEnv(num_envs, **options)
    env.reset(seed=0)
    setup = time.perf_counter() - built
    rng = np.random.default_rng(0)
    n_actions = int(env.single_action_space.n)
    steps = 0
    cpu, start = time.process_time(), time.perf_counter()
    while time.perf_counter() - start < seconds:
        env.step(rng.integers(0, n_actions, num_envs))
        steps += num_envs
    return (steps / (time.perf_counter() - start), steps / (time.process_time() - cpu),
            env.engine, setup)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--num-envs", type=int, default=256)
    parser.add_argument("--level", default="miami")
    parser.add_argument("--abstraction", default="grid", choices=("grid", "partition"))
    parser.add_argument("--guards", default="pf")
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--engine", default="auto", choices=("auto", "batch", "pymunk"))
    args = parser.parse_args()
    options = {"level": args.level, "abstraction": args.abstraction, "guards": args.guards,
               "world__engine": args.engine}
    one_wall, one_cpu = single_rate({k: v for k, v in options.items() if k != "world__engine"},
                                    args.seconds)
    print(f"one env           {one_wall:10,.0f} steps/s  ({one_cpu:,.0f} per CPU s)")
    vec_wall, vec_cpu, engine, setup = vector_rate(options, args.num_envs, args.seconds)
    print(f"{args.num_envs} envs ({engine:6}) {vec_wall:10,.0f} steps/s  ({vec_cpu:,.0f} per CPU s;"
          f" set-up {setup:.1f} s)")
    print(f"ratio {vec_wall / one_wall:.2f}x (per CPU s {vec_cpu / one_cpu:.2f}x); targets: "
          f">= 50,000 steps/s and >= 30x")


if __name__ == "__main__":
    main()
