"""Env steps per second of ``StealthEnv`` with random actions (run by hand).

    python benchmarks/env.py [--level miami] [--abstraction grid] [--seconds 10] [--profile]

One env step is one player move (9 physics steps on the grid in the capture scenario).
Printed beside it, measured in the same run: the reference of the plain headless world of
the same level (``game.trial.make_world``, PF guards, the ``evade`` player) in physics
steps per second, and what that makes in moves per second at the env's physics steps per
move, so the env's own share of the time is visible on any machine. ``--profile`` prints
cProfile's top entries of the env run. Target (issue 23): ≥ 2,000 env steps/s, miami grid.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from game.env import StealthEnv
from game.trial import TrialSpec, make_world


def env_rate(level: str, abstraction: str, seconds: float) -> tuple[float, float, float]:
    """(env steps/s, physics steps per env step, env steps per CPU second) of random
    actions for ``seconds``; the CPU rate counts this process's time alone, so it says
    less about what else runs on the machine."""
    env = StealthEnv(level, abstraction=abstraction)
    env.action_space.seed(0)
    env.reset(seed=0)
    steps = physics = 0
    cpu = time.process_time()
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        before = env.match.world.step_index
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        physics += env.match.world.step_index - before
        steps += 1
        if terminated or truncated:
            env.reset()
    wall = time.perf_counter() - start
    return steps / wall, physics / max(1, steps), steps / max(1e-9, time.process_time() - cpu)


def world_rate(level: str, abstraction: str, seconds: float) -> float:
    """Physics steps/s of the headless world itself (PF guards, evade player)."""
    steps, seed = 0, 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        world = make_world(TrialSpec(level, abstraction, "pf", "evade", "capture", seed))
        while not world.done and time.perf_counter() - start < seconds:
            world.step()
            steps += 1
        seed += 1
    return steps / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="miami")
    parser.add_argument("--abstraction", default="grid")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    env_rate(args.level, args.abstraction, 0.5)  # warm caches (level, graph, imports)
    if args.profile:
        profiler = cProfile.Profile()
        profiler.enable()
    rate, per_step, cpu_rate = env_rate(args.level, args.abstraction, args.seconds)
    if args.profile:
        profiler.disable()
        pstats.Stats(profiler).sort_stats("cumulative").print_stats(25)
    reference = world_rate(args.level, args.abstraction, args.seconds)
    print(f"{args.level} {args.abstraction}: env {rate:,.0f} steps/s "
          f"({per_step:.1f} physics steps each; {cpu_rate:,.0f} per CPU second)")
    print(f"reference: headless world {reference:,.0f} physics steps/s "
          f"= {reference / per_step:,.0f} moves/s; env / reference {rate * per_step / reference:.2f}")


if __name__ == "__main__":
    main()
