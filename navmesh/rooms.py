"""Seeded 12 x 8 rooms that stress a body's geometry: thin walls, pinch points, boxes.

A level a body must get round: 2-4 thin walls (0.05-0.2 thick) anywhere, 1-2 diamonds
touching the outline at a vertex (pinch points), 0-2 boxes (some touching corner to
corner); redrawn until it parses and a body of ``radius`` reaches all of its walkable
area. The bounds tests (tests/test_bounds_geometry.py) and the stand-still probe
(benchmarks/stall_probe.py) run on these.

>>> room = thin_wall_room(0)
>>> room.name, room.rows, room.cols
('random0', 8, 12)
"""

from __future__ import annotations

import numpy as np
import shapely

from .errors import LevelError
from .level import Level, parse_level

__all__ = ["WIDTH", "HEIGHT", "room_level", "thin_wall_room"]

WIDTH, HEIGHT = 12.0, 8.0


def room_level(name: str, obstacles: list, radius: float = 0.3) -> Level | None:
    """The 12 x 8 room with ``obstacles`` and a guard in a free corner, or None when it
    does not parse or a body of ``radius`` cannot reach the whole walkable area."""
    room = shapely.box(0, 0, WIDTH, HEIGHT).difference(
        shapely.union_all([shapely.Polygon(o) for o in obstacles]))
    guard = [0.5, 0.5] if shapely.intersects_xy(room, 0.5, 0.5) else [WIDTH - 0.5, HEIGHT - 0.5]
    try:
        level = parse_level({"format": "stealth-level/1", "name": name,
                             "outline": [[0, 0], [WIDTH, 0], [WIDTH, HEIGHT], [0, HEIGHT]],
                             "obstacles": obstacles, "guards": [guard]})
    except LevelError:
        return None
    body = level.walkable.buffer(-radius, join_style="mitre")  # where a centre fits
    if len([g for g in shapely.get_parts(body) if g.area > 1e-4]) != 1:
        return None
    return level


def thin_wall_room(seed: int, radius: float = 0.3) -> Level:
    """The room of ``seed`` (see the module docstring; the same draws for the same seed)."""
    rng = np.random.default_rng(seed)
    while True:
        obstacles = []
        for _ in range(rng.integers(2, 5)):  # thin walls, 0.05-0.2 thick, anywhere
            x, y = rng.uniform(1, 11), rng.uniform(1, 7)
            t, n = rng.uniform(0.05, 0.2), rng.uniform(1.5, 4)
            if rng.random() < 0.5:
                obstacles.append([[x, y], [x + t, y], [x + t, y + n], [x, y + n]])
            else:
                obstacles.append([[x, y], [x + n, y], [x + n, y + t], [x, y + t]])
        for _ in range(rng.integers(1, 3)):  # diamonds touching the outline at a vertex
            x, h, w = rng.uniform(2, 10), rng.uniform(1, 2.5), rng.uniform(0.3, 0.8)
            top = bool(rng.random() < 0.5)
            y0, s = (0.0, 1) if top else (8.0, -1)
            obstacles.append([[x, y0], [x + w, y0 + s * h], [x, y0 + 2 * s * h],
                              [x - w, y0 + s * h]])
        for _ in range(rng.integers(0, 3)):  # boxes, some touching corner to corner
            x, y, a = rng.uniform(1, 10), rng.uniform(1, 6), rng.uniform(0.5, 1.5)
            obstacles.append([[x, y], [x + a, y], [x + a, y + a], [x, y + a]])
            if rng.random() < 0.5:
                obstacles.append([[x + a, y + a], [x + 2 * a, y + a], [x + 2 * a, y + 2 * a],
                                  [x + a, y + 2 * a]])
        level = room_level(f"random{seed}", obstacles, radius)
        if level is not None:
            return level
