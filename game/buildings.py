"""Building-like test levels of any size: a grid of rooms joined by doors (benchmarks,
screenshots of the camera on a large level).

>>> level = building_level(24, 36, room=12)
>>> level["grid"][0][:5], len(level["grid"]), len(level["grid"][0])
('#####', 24, 36)
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["building_level"]


def building_level(rows: int, cols: int, *, room: int = 12, door: int = 3, seed: int = 0,
                   guards: int = 6) -> dict[str, Any]:
    """A ``stealth-level/1`` document: ``rows × cols`` cells, rooms of ``room`` cells with
    one-cell walls, a ``door``-wide gap in every inner wall (at a seeded place), a pillar in
    some rooms, ``guards`` guard spawns and the player start in the first room."""
    rng = np.random.default_rng(seed)
    grid = np.zeros((rows, cols), dtype=bool)  # True = wall
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = True
    # Inner walls every ``room`` cells, none that would leave a strip narrower than a door.
    wall_rows = list(range(room, rows - door - 2, room))
    wall_cols = list(range(room, cols - door - 2, room))
    for r in wall_rows:
        grid[r, :] = True
    for c in wall_cols:
        grid[:, c] = True
    row_starts = [0] + wall_rows
    col_starts = [0] + wall_cols
    for r in row_starts:  # doors through the vertical walls, per room row
        for c in wall_cols:
            lo, hi = r + 1, min(r + room, rows - 1) if r != row_starts[-1] else rows - 1
            if hi - lo >= door:
                d = int(rng.integers(lo, hi - door + 1))
                grid[d:d + door, c] = False
    for c in col_starts:  # doors through the horizontal walls
        for r in wall_rows:
            lo, hi = c + 1, min(c + room, cols - 1) if c != col_starts[-1] else cols - 1
            if hi - lo >= door:
                d = int(rng.integers(lo, hi - door + 1))
                grid[r, d:d + door] = False
    for r in row_starts:  # pillars in some rooms
        for c in col_starts:
            if room >= 8 and rng.random() < 0.4:
                pr, pc = r + room // 2 - 1, c + room // 2 - 1
                grid[pr:pr + 2, pc:pc + 2] = True
    free = np.argwhere(~grid)
    picks = free[rng.choice(len(free), size=min(guards, len(free) - 1), replace=False)]
    return {
        "format": "stealth-level/1", "name": f"building{rows}x{cols}", "cell_size": 1.0,
        "grid": ["".join("#" if w else "." for w in row) for row in grid],
        "guards": [[float(c) + 0.5, float(r) + 0.5] for r, c in picks],
        "player": [1.5, 1.5],
    }
