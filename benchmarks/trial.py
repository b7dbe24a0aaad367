"""Wall time of one 60-s trial, per bundled level and abstraction (run by hand).

    python benchmarks/trial.py [--guards cheat] [--player evade] [--seeds 7] [--profile]

Prints the median over seeds for every level × abstraction, and the same for a bare
pymunk + numpy skeleton of the loop (3 guards and a player walking between random points
of the same walls at the same physics step, line of sight cast for every guard every
step) measured in the same run, so the ratio is comparable across machines.
Target (issue 3): ≤ 60 ms per trial with Cheat guards on a 2-core machine.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
import pymunk

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from game.config import Config
from game.trial import TrialSpec, run_trial
from navmesh.graph import graph_for
from navmesh.level import bundled_level_names, cached_level


def skeleton_trial(level_name: str, seed: int, dt: float = 0.05, duration: float = 60.0) -> float:
    """The bare loop the issue compares against: pymunk bodies + numpy, no AI, no metrics."""
    level = cached_level(level_name)
    graph = graph_for(level, "grid")
    rng = np.random.default_rng(seed)
    started = time.perf_counter()
    space = pymunk.Space()
    for (ax, ay), (bx, by) in level.walls:
        space.add(pymunk.Segment(space.static_body, (ax, ay), (bx, by), 0.0))
    bodies = []
    for node in rng.choice(graph.n, 4, replace=False):
        body = pymunk.Body(1.0, float("inf"))
        body.position = tuple(graph.positions[node])
        shape = pymunk.Circle(body, 0.3)
        shape.filter = pymunk.ShapeFilter(categories=2, mask=1)
        space.add(body, shape)
        bodies.append(body)
    targets = [graph.positions[rng.integers(graph.n)] for _ in bodies]
    query = pymunk.ShapeFilter(mask=1)
    for _ in range(round(duration / dt)):
        positions = [b.position for b in bodies]
        for k, (body, pos) in enumerate(zip(bodies, positions)):
            dx, dy = targets[k][0] - pos.x, targets[k][1] - pos.y
            d = math.hypot(dx, dy)
            if d < 0.1:
                targets[k] = graph.positions[rng.integers(graph.n)]
                continue
            body.velocity = (dx / d * 2.0, dy / d * 2.0)
        space.step(dt)
        player = bodies[-1].position
        for body in bodies[:-1]:
            space.segment_query_first(body.position, player, 0.0, query)
        graph.nearest_dist_to([graph.node_at(b.position.x, b.position.y) for b in bodies[:-1]],
                              graph.node_at(player.x, player.y))
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--guards", default="cheat")
    parser.add_argument("--player", default="evade")
    parser.add_argument("--scenario", default="fixed", help="fixed always runs the full 60 s")
    parser.add_argument("--seeds", type=int, default=7)
    parser.add_argument("--profile", action="store_true", help="cProfile one level's trials")
    args = parser.parse_args()

    print(f"guards={args.guards} player={args.player} scenario={args.scenario} "
          f"physics step={Config.defaults()['world.physics_step']} s, median of {args.seeds} seeds")
    print(f"{'level':<12}{'abstraction':<12}{'trial ms':>10}{'skeleton ms':>13}{'ratio':>8}")
    all_times = []
    for name in bundled_level_names():
        skeleton_trial(name, 0)  # warm the level and graph caches
        skeleton = statistics.median(skeleton_trial(name, s) for s in range(args.seeds))
        for abstraction in ("grid", "partition"):
            spec = lambda s: TrialSpec(name, abstraction, args.guards, args.player,  # noqa: E731
                                       args.scenario, s)
            run_trial(spec(10_000))  # warm-up: graph and field caches
            times = []
            for seed in range(args.seeds):
                started = time.perf_counter()
                run_trial(spec(seed))
                times.append(time.perf_counter() - started)
            median = statistics.median(times)
            all_times.append(median)
            print(f"{name:<12}{abstraction:<12}{median * 1e3:>10.1f}{skeleton * 1e3:>13.1f}"
                  f"{median / skeleton:>8.2f}")
    print(f"median over levels and abstractions: {statistics.median(all_times) * 1e3:.1f} ms "
          f"(target <= 60 ms)")

    if args.profile:
        import cProfile
        import pstats

        profile = cProfile.Profile()
        profile.enable()
        for seed in range(args.seeds):
            run_trial(TrialSpec("dishonored", "partition", args.guards, args.player,
                                args.scenario, seed))
        profile.disable()
        pstats.Stats(profile).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
