"""Scale of the body-clearance check on hostile levels (issue 24, class 4).

Writes the levels of the issue into a temporary folder — a 1000 × 1000 grid of pillars
(250,000 holes), an outline of 10^5 vertices, a 10^5-vertex obstacle, and 10^5 outline
vertices with 10^4 obstacles (the last three refused by the loader's limit of 10^4 points a
polygon), and the same at that limit (10^4-point outline, obstacle, outline + 10^4 boxes);
grids of pillars of 200, 280 and 400 cells a side and a toothed outline of 1.7 × 10^5
corners above 86 × 86 or 33 × 33 pillars (around the partition's bounds,
``navmesh.sizing.check_mesh_work``) — and times ``stealth validate`` (and, with
``--levels``, ``stealth levels``; with ``--partition``, ``stealth sim --abstraction
partition``) on each in a subprocess with a timeout. Acceptance: validate on the pillars
within 20 s, the others within 30 s or one error line.

Run: ``python benchmarks/hostile_scale.py`` (about a minute); ``--levels`` adds
``stealth levels`` (the partition's triangulation), ``--partition`` a partition trial.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import _paths

ENV = {**os.environ, "PYTHONPATH": str(_paths.ROOT)}


def pillars(side: int) -> list[str]:
    """side × side cells, a one-cell pillar at every odd (row, col) inside the border."""
    return ["".join("#" if y % 2 and x % 2 and 0 < y < side - 1 and 0 < x < side - 1 else "."
                    for x in range(side)) for y in range(side)]


def toothed(k: int, cols: int = 640, top: int = 530) -> list[str]:
    """Walls from the left border every 4 rows, a tooth on every other cell below each (one
    outline ring of ~1.7 × 10^5 corners), above k × k one-cell pillars."""
    rows = top + 2 * k + 6
    blocked = [[False] * cols for _ in range(rows)]
    for y in range(1, top - 3, 4):
        for x in range(cols - 2):
            blocked[y][x] = True
            blocked[y + 1][x] = blocked[y + 1][x] or x % 2 == 0
    for y in range(top + 1, top + 1 + 2 * k, 2):
        for x in range(1, 1 + 2 * k, 2):
            blocked[y][x] = True
    return ["".join("#" if b else "." for b in row) for row in blocked]


def levels(folder: Path) -> dict[str, Path]:
    n, r = 100_000, 500.0
    ring = [[r + r * math.cos(2 * math.pi * i / n), r + r * math.sin(2 * math.pi * i / n)]
            for i in range(n)]
    side = 1000
    grid = ["".join("#" if y % 2 and x % 2 and 0 < y < side - 1 and 0 < x < side - 1 else "."
                    for x in range(side)) for y in range(side)]
    hole = [[500 + 200 * math.cos(2 * math.pi * i / n), 500 + 200 * math.sin(2 * math.pi * i / n)]
            for i in range(n)]
    boxes = [[[x, y], [x + 2, y], [x + 2, y + 2], [x, y + 2]]
             for x in range(200, 800, 6) for y in range(200, 800, 6)][:10_000]
    m = 10_000  # MAX_POLYGON_VERTICES: the largest polygons a level may have
    ring4 = [[r + r * math.cos(2 * math.pi * i / m), r + r * math.sin(2 * math.pi * i / m)] for i in range(m)]
    hole4 = [[500 + 200 * math.cos(2 * math.pi * i / m), 500 + 200 * math.sin(2 * math.pi * i / m)]
             for i in range(m)]
    docs = {
        "pillars1000": {"grid": grid, "guards": [[0.5, 0.5]]},
        **{f"pillars{n}": {"grid": pillars(n), "guards": [[0.5, 0.5]]} for n in (200, 280, 400)},
        **{f"toothed_pillars{k}": {"grid": toothed(k), "guards": [[0.5, 0.5]]} for k in (33, 86)},
        "outline1e5": {"cell_size": 10.0, "outline": ring, "guards": [[500, 500]]},
        "obstacle1e5": {"cell_size": 10.0, "outline": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]],
                        "obstacles": [hole], "guards": [[50, 50]]},
        "outline1e5_obstacles1e4": {"cell_size": 2.0, "outline": ring, "obstacles": boxes,
                                    "guards": [[500, 150]]},
        "outline1e4": {"cell_size": 10.0, "outline": ring4, "guards": [[500, 500]]},
        "obstacle1e4": {"cell_size": 10.0, "outline": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]],
                        "obstacles": [hole4], "guards": [[50, 50]]},
        "outline1e4_obstacles1e4": {"cell_size": 2.0, "outline": ring4, "obstacles": boxes,
                                    "guards": [[500, 150]]},
    }
    paths = {}
    for name, doc in docs.items():
        path = folder / f"{name}.json"
        path.write_text(json.dumps({"format": "stealth-level/1", "name": name, **doc}))
        paths[name] = path
    return paths


def timed(args: list[str], timeout: float) -> tuple[float, str]:
    start = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, "-m", "headless.cli", *args], env=ENV,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return time.perf_counter() - start, f"timeout after {timeout:g} s"
    last = (done.stderr.strip().splitlines() or [""])[-1]
    return time.perf_counter() - start, f"exit {done.returncode}: {last[:120]}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", action="store_true", help="time `stealth levels` too")
    parser.add_argument("--partition", action="store_true",
                        help="time `stealth sim --abstraction partition` too")
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    commands = [["validate"]] + [["levels"]] * args.levels
    commands += [["sim", "--abstraction", "partition"]] * args.partition
    with tempfile.TemporaryDirectory() as folder:
        for name, path in levels(Path(folder)).items():
            for command in commands:
                seconds, outcome = timed([*command, str(path)], args.timeout)
                print(f"{command[0]:9s} {name:26s} {seconds:7.1f} s  {outcome}", flush=True)


if __name__ == "__main__":
    main()
