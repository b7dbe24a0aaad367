"""Issue 24: look for guards that stand still without their controller choosing to.

    python benchmarks/stall_probe.py [--levels 40] [--seeds 2] [--kinds random,wall]
        [--modes pf,fsm,staleness,cheat,random] [--abstraction partition]
        [--duration 60] [--jobs 2] [--min 3.0] [--show 20]

Runs fixed-time trials (MaxMin player, default config plus ``world.duration``) on seeded
generated levels and reports every guard stand-still longer than ``--min`` seconds that
its controller did not choose: the body's position is exactly unchanged from one physics
step to the next while it does not stand on its target with no waypoints left (the rule of
tests/test_bounds_geometry.py). A "creep" is the looser figure: the body stays within
0.02 units of where the stand began (a body pushed against a wall jitters). A "restless"
stand is still too, but its controller re-decides at every step: each target's stand
point is where the body already is (nodes a body cannot enter, sharing one stand point),
so every decision counts as arrived at once.

Level kinds (both 12 x 8 rooms, regenerated until a body of the agent radius reaches the
whole walkable area):

* ``random``: :func:`navmesh.rooms.thin_wall_room` (the rooms of tests/test_bounds_geometry.py) — 2-4 thin walls 0.05-0.2 thick,
  1-2 diamonds touching the outline at a vertex (pinch points), 0-2 boxes;
* ``wall``: one thin wall (0.05-0.2 thick) from an outline edge most of the way across,
  so routes between the two sides must turn around its free end.

Prints one line per stand (level, mode, seed, guard, start time, length, position, node,
target, waypoints, whether the plan was a re-plan), one per restless stand, and the
longest of each figure per level kind and mode. Determinism: a level is a pure function of (kind, index), a trial of its seed.
"""

from __future__ import annotations

import argparse
import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np
import shapely

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from ai import make_guard_ai, make_player_policy
from game.config import Config
from game.trial import player_params
from game.world import World
from navmesh.level import Level
from navmesh.rooms import HEIGHT as H, WIDTH as W, room_level, thin_wall_room

RADIUS = 0.3
CREEP = 0.02


def wall_level(index: int) -> Level:
    """One thin wall from an outline edge, its free end 1-2.5 units from the far edge."""
    rng = np.random.default_rng([24, index])
    while True:
        t = float(rng.uniform(0.05, 0.2))
        vertical = bool(rng.random() < 0.6)
        span = H if vertical else W
        gap = float(rng.uniform(1.0, 2.5))
        at = float(rng.uniform(2.0, (W if vertical else H) - 2.0))
        from_low = bool(rng.random() < 0.5)
        lo, hi = (0.0, span - gap) if from_low else (gap, span)
        if vertical:
            wall = [[at, lo], [at + t, lo], [at + t, hi], [at, hi]]
        else:
            wall = [[lo, at], [hi, at], [hi, at + t], [lo, at + t]]
        level = room_level(f"wall{index}", [wall], RADIUS)
        if level is not None:
            return level


KINDS = {"random": thin_wall_room, "wall": wall_level}


@dataclass(frozen=True)
class Job:
    kind: str
    index: int
    abstraction: str
    mode: str
    seed: int
    duration: float
    minimum: float


def run(job: Job) -> tuple[Job, list[dict], list[dict], dict[str, float]]:
    """Every unwanted stand and every restless stand of one trial longer than
    ``job.minimum``, and the trial's longest figures: ``stand`` (unwanted, exact),
    ``creep`` (unwanted, within :data:`CREEP`) and ``restless`` (exactly still while the
    controller's target changed at least once, each target reached at once: the
    controller hops between nodes a body cannot tell apart)."""
    level = KINDS[job.kind](job.index)
    config = Config.load({"world.duration": job.duration})
    world = World(level, job.abstraction, make_guard_ai(job.mode, config.section(job.mode)),
                  make_player_policy("maxmin", player_params(config, "fixed")),
                  config=config, scenario="fixed", seed=job.seed)
    guards, walk, graph, dt = world.guards, world.locomotion, world.graph, world.dt
    n = len(guards)
    still, creep, quiet = [0.0] * n, [0.0] * n, [0.0] * n
    targets: list[set[int]] = [set() for _ in range(n)]
    anchor = [g.pos for g in guards]
    last = [g.pos for g in guards]
    start: list[dict | None] = [None] * n
    found: list[dict] = []
    hops: list[dict] = []
    where = [g.pos for g in guards]
    worst = {"stand": 0.0, "creep": 0.0, "restless": 0.0}

    def off(node: int) -> bool:
        """Whether a body sent to ``node`` stops outside its triangle (partition only)."""
        return graph.mesh is not None and not graph.mesh.triangle_contains(
            node, *walk.stand_point(node))

    def close(k: int) -> None:
        if start[k] is not None and still[k] > job.minimum:
            found.append({**start[k], "length": still[k]})  # type: ignore[dict-item]

    def close_hop(k: int) -> None:
        if len(targets[k]) > 1 and quiet[k] > job.minimum:
            hops.append({"guard": k, "t": world.t - quiet[k], "length": quiet[k],
                         "pos": where[k], "targets": sorted(targets[k])})

    while not world.done:
        world.step()
        for k, g in enumerate(guards):
            chose = g.target == g.node and not g.waypoints  # the controller's wish
            if g.pos == last[k] and not chose:
                if still[k] == 0.0:
                    start[k] = {"guard": k, "t": world.t - dt, "pos": g.pos, "node": g.node,
                                "target": g.target, "waypoints": list(g.waypoints),
                                "replanned": g.replanned, "off": off(g.target)}
                still[k] += dt
            else:
                close(k)
                still[k], start[k] = 0.0, None
            if not chose and math.dist(g.pos, anchor[k]) < CREEP:
                creep[k] += dt
            else:
                creep[k], anchor[k] = 0.0, g.pos
            if g.pos == last[k]:
                quiet[k] += dt
                targets[k].add(g.target)
            else:
                close_hop(k)
                quiet[k], targets[k], where[k] = 0.0, {g.target}, g.pos
            worst["stand"] = max(worst["stand"], still[k])
            worst["creep"] = max(worst["creep"], creep[k])
            if len(targets[k]) > 1:
                worst["restless"] = max(worst["restless"], quiet[k])
            last[k] = g.pos
    for k in range(n):
        close(k)
        close_hop(k)
    return job, found, hops, worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=40, help="levels per kind")
    parser.add_argument("--first", type=int, default=0, help="first level index")
    parser.add_argument("--seeds", type=int, default=2, help="trial seeds per level and mode")
    parser.add_argument("--kinds", default="random,wall")
    parser.add_argument("--modes", default="pf,fsm,staleness,cheat,random")
    parser.add_argument("--abstraction", default="partition")
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--min", type=float, default=3.0, dest="minimum")
    parser.add_argument("--show", type=int, default=30, help="stands listed (longest first)")
    args = parser.parse_args()
    jobs = [Job(kind, i, args.abstraction, mode, seed, args.duration, args.minimum)
            for kind in args.kinds.split(",") for i in range(args.first, args.first + args.levels)
            for mode in args.modes.split(",") for seed in range(args.seeds)]
    began = time.perf_counter()
    stands: list[tuple[Job, dict]] = []
    restless: list[tuple[Job, dict]] = []
    worst: dict[tuple[str, str], dict[str, float]] = {}
    with ProcessPoolExecutor(args.jobs) as pool:
        for job, found, hops, figures in pool.map(run, jobs, chunksize=2):
            stands += [(job, f) for f in found]
            restless += [(job, h) for h in hops]
            row = worst.setdefault((job.kind, job.mode), dict.fromkeys(figures, 0.0))
            for name, value in figures.items():
                row[name] = max(row[name], value)
    stands.sort(key=lambda s: -s[1]["length"])
    print(f"{len(jobs)} trials ({args.abstraction}, {args.duration:g} s) in "
          f"{time.perf_counter() - began:.0f} s; {len(stands)} stands > {args.minimum:g} s")
    for job, f in stands[:args.show]:
        wps = ", ".join(f"({x:.3f}, {y:.3f})" for x, y in f["waypoints"][:3])
        print(f"  {job.kind}{job.index} {job.mode} seed {job.seed} guard {f['guard']}: {f['length']:.2f} s from "
              f"t={f['t']:.2f} at ({f['pos'][0]:.3f}, {f['pos'][1]:.3f}) node {f['node']} "
              f"target {f['target']}{' (stands off it)' if f['off'] else ''} waypoints [{wps}]"
              f"{' replanned' if f['replanned'] else ''}")
    planned = sum(1 for _, f in stands if f["waypoints"])
    offs = sum(1 for _, f in stands if f["off"])
    print(f"stands with waypoints left: {planned}; whose target's stand point lies outside "
          f"the target's triangle: {offs}")
    restless.sort(key=lambda s: -s[1]["length"])
    print(f"restless stands > {args.minimum:g} s (still, the controller re-deciding): "
          f"{len(restless)}")
    for job, h in restless[:args.show]:
        print(f"  {job.kind}{job.index} {job.mode} seed {job.seed} guard {h['guard']}: "
              f"{h['length']:.2f} s from t={h['t']:.2f} at ({h['pos'][0]:.3f}, "
              f"{h['pos'][1]:.3f}), targets {h['targets'][:8]}"
              f"{' ...' if len(h['targets']) > 8 else ''}")
    print("longest per level kind and mode (s):\n  kind   mode       stand  creep restless")
    for (kind, mode), row in sorted(worst.items()):
        print(f"  {kind:6s} {mode:9s} {row['stand']:6.2f} {row['creep']:6.2f} "
              f"{row['restless']:6.2f}")


if __name__ == "__main__":
    main()
