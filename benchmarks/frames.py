"""Frame times of the game window on a paper level per overlay, and on large building
levels through the camera (run by hand).

    SDL_VIDEODRIVER=dummy PYTHONPATH=. python benchmarks/frames.py [--level dishonored]
        [--frames 1200] [--warmup 60] [--abstraction grid partition] [--no-extras]
        [--overlays none K] [--building 1000x1000] [--game-building 48x64]

Without ``SDL_VIDEODRIVER`` set it opens a real window (e.g. under ``xvfb-run`` or with
``DISPLAY`` pointing at an Xvfb server).

``--game-building RxC``: the whole game (world, AI, scene, drawing) on a generated
building level (:func:`navmesh.buildings.building_level`) with the camera zoomed in and
following the MaxMin autopilot, the minimap on. ``--building RxC``: the front end alone on
a building of R×C cells (10^6 with 1000x1000) — a level too large for the simulation's
all-pairs distance tables — with 12 guards walking around the player, their cones cast
against the level's walls every frame (the scene builder's wall buckets), the camera
following the player and the minimap: what a frame costs besides ``world.step()``.

Each frame is what ``stealth play`` does once per frame in lockstep: events, one physics
step (``world.step()``, 1/60 s, with the AI's decisions and its 1-s tick), the scene
(cones ray-cast against the walls, plans, field layer) and the pygame drawing, plus the
display flip. Guards are ``pf`` (the only mode with fields), the player is the MaxMin
autopilot, and by default the navmesh/grid lines and the guards' plans are shown too, so
this is the busiest picture the game draws. The first ``--warmup`` frames (world
construction caches, first composition of the background) are not counted.

Target (issue): median ≤ 8 ms and p99 ≤ 16.7 ms on the busiest overlay.
"""

from __future__ import annotations

import argparse
import os
import statistics

import _paths  # noqa: E402,F401  (project importable, this folder unshadowed)

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from navmesh.buildings import building_level
from game.front.play import PlayGame, PlaySettings
from game.front.render import Renderer, init_pygame, pygame
from game.scene import OVERLAYS, GuardDrawing, PlayerDrawing, Scene, SceneBuilder
from navmesh.level import parse_level

MEDIAN_TARGET_MS = 8.0
P99_TARGET_MS = 16.7


def percentile(values: list[float], q: float) -> float:
    """The q-th percentile (nearest rank) of ``values``."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, round(q / 100 * len(ordered)) - 1))]


def measure(level: str, abstraction: str, overlay: str, frames: int, warmup: int,
            extras: bool) -> list[float]:
    """Frame times in milliseconds after ``warmup`` frames."""
    game = PlayGame(
        PlaySettings(level, guards="pf", abstraction=abstraction, autopilot="maxmin",
                     overlay=overlay, show_mesh=extras, show_plans=extras),
        lockstep=True,
    )
    try:
        game.run(warmup)
        return [t * 1000 for t in game.run(frames)]
    finally:
        game.close()


def _size(text: str) -> tuple[int, int]:
    rows, _, cols = text.partition("x")
    return int(rows), int(cols)


def measure_game_building(rows: int, cols: int, frames: int, warmup: int) -> list[float]:
    """The whole game on a generated building, camera zoomed in on the autopilot."""
    path = Path(tempfile.mkdtemp()) / "building.json"
    path.write_text(json.dumps(building_level(rows, cols, guards=8)))
    game = PlayGame(PlaySettings(str(path), guards="pf", autopilot="maxmin", overlay="K",
                                 show_plans=True), lockstep=True, size=(1280, 860))
    game.camera.zoom = 24.0
    try:
        game.run(warmup)
        return [t * 1000 for t in game.run(frames)]
    finally:
        game.close()


class _GridOnly:
    """What :class:`SceneBuilder` reads of a grid graph, without the all-pairs tables."""

    kind = "grid"
    mesh = None

    def __init__(self, occupancy: np.ndarray, cell: float) -> None:
        self.cell_node = np.full(occupancy.shape, -1, dtype=np.int64)
        free = np.argwhere(occupancy)
        self.cell_node[occupancy] = np.arange(len(free))
        self.positions = (free[:, ::-1] + 0.5) * cell


def measure_front_building(rows: int, cols: int, frames: int, warmup: int) -> tuple[list[float], int]:
    """The front end alone on a building of rows × cols cells (see the module docstring)."""
    level = parse_level(building_level(rows, cols, guards=12))
    graph = _GridOnly(level.occupancy, level.cell_size)
    builder = SceneBuilder(level, graph, view_range=8.0, fov_deg=90.0)  # type: ignore[arg-type]
    init_pygame()
    screen = pygame.display.set_mode((1280, 860))
    renderer = Renderer(builder.static, screen.get_size())
    renderer.camera.zoom = 24.0
    free = graph.positions
    rng = np.random.default_rng(0)
    # The player walks a straight line across the building (through walls: it is only a
    # camera path); guards circle around it at 3-9 units.
    start, end = np.array([2.0, 2.0]), np.array([cols - 2.0, rows - 2.0])
    offsets = rng.uniform(3, 9, 12), rng.uniform(0, 2 * math.pi, 12)
    times: list[float] = []
    total = warmup + frames
    for k in range(total):
        t0 = time.perf_counter()
        pygame.event.pump()
        p = start + (end - start) * (k / total) * 0.05  # 5 % of the diagonal: ~50 cells
        guards = []
        for i in range(12):
            a = offsets[1][i] + k * 0.01
            pos = (float(p[0] + offsets[0][i] * math.cos(a)), float(p[1] + offsets[0][i] * math.sin(a)))
            heading = a + math.pi / 2
            guards.append(GuardDrawing(pos=pos, heading=heading, active=True, sees_player=False,
                                       state="patrol", cone=builder.cone(pos, heading, 8.0)))
        scene = Scene(static=builder.static, t=k / 60, duration=60.0, guards=tuple(guards),
                      player=PlayerDrawing(pos=(float(p[0]), float(p[1])), heading=0.0, hp=3, hp_max=3))
        renderer.camera.follow(scene.player.pos)
        renderer.refresh_view()
        renderer.draw(screen, scene)
        pygame.display.flip()
        times.append(time.perf_counter() - t0)
    del free
    return [t * 1000 for t in times[warmup:]], len(level.walls)


def _line(name: str, times: list[float]) -> tuple[float, float]:
    median, p99 = statistics.median(times), percentile(times, 99)
    ok = median <= MEDIAN_TARGET_MS and p99 <= P99_TARGET_MS
    print(f"{name}: median {median:.2f} ms, p99 {p99:.2f} ms, max {max(times):.2f} ms "
          f"-> {'OK' if ok else 'OVER TARGET'}", flush=True)
    return median, p99


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="dishonored")
    parser.add_argument("--frames", type=int, default=1200, help="measured frames (60 = 1 s of game)")
    parser.add_argument("--warmup", type=int, default=60)
    parser.add_argument("--abstraction", nargs="+", default=["grid", "partition"])
    parser.add_argument("--no-extras", dest="extras", action="store_false",
                        help="without the mesh lines and the guards' plans")
    parser.add_argument("--overlays", nargs="+", default=list(OVERLAYS), help="overlays measured")
    parser.add_argument("--building", type=_size, default=None, metavar="RxC",
                        help="also the front end alone on an RxC building (e.g. 1000x1000)")
    parser.add_argument("--game-building", type=_size, default=None, metavar="RxC",
                        help="also the whole game on an RxC building through the camera")
    parser.add_argument("--skip-level", action="store_true", help="only the building runs")
    args = parser.parse_args()
    driver = os.environ.get("SDL_VIDEODRIVER") or f"x11 {os.environ.get('DISPLAY', '')}"
    if args.game_building:
        r, c = args.game_building
        _line(f"game on building {r}x{c} (camera, K overlay, plans)",
              measure_game_building(r, c, args.frames, args.warmup))
    if args.building:
        r, c = args.building
        times, walls = measure_front_building(r, c, args.frames, args.warmup)
        _line(f"front end on building {r}x{c} = {r * c} cells, {walls} wall segments "
              f"(camera, 12 cones, minimap)", times)
    if args.skip_level:
        return

    print(f"level {args.level}, {args.frames} frames after {args.warmup} warm-up frames, "
          f"pf guards, maxmin autopilot, mesh+plans {'on' if args.extras else 'off'}, "
          f"driver {driver}, load average {os.getloadavg()[0]:.2f}")
    print(f"{'abstraction':<12}{'overlay':<9}{'median ms':>10}{'p99 ms':>9}{'max ms':>9}")
    worst: tuple[float, float, str] | None = None
    for abstraction in args.abstraction:
        for overlay in args.overlays:
            times = measure(args.level, abstraction, overlay, args.frames, args.warmup, args.extras)
            median, p99 = statistics.median(times), percentile(times, 99)
            print(f"{abstraction:<12}{overlay:<9}{median:>10.2f}{p99:>9.2f}{max(times):>9.2f}",
                  flush=True)
            if worst is None or (p99, median) > (worst[1], worst[0]):
                worst = (median, p99, f"{abstraction}/{overlay}")
    assert worst is not None
    median, p99, name = worst
    ok = median <= MEDIAN_TARGET_MS and p99 <= P99_TARGET_MS
    print(f"busiest ({name}): median {median:.2f} ms (target ≤ {MEDIAN_TARGET_MS}), "
          f"p99 {p99:.2f} ms (target ≤ {P99_TARGET_MS}) -> {'OK' if ok else 'OVER TARGET'}")


if __name__ == "__main__":
    main()
