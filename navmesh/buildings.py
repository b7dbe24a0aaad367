"""Generated building-like levels of any size, for scale tests and benchmarks.

A floor plan of rooms on a jittered lattice: one-cell walls, corridors between blocks of
rooms, a door from every room to the next one and a door to every corridor it touches, and
furniture (boxes and shelves) inside rooms that never blocks a door. The result is a level
in the JSON format (:data:`navmesh.level.FORMAT`), in grid form or as an outline with
obstacle polygons, so :func:`navmesh.level.parse_level` validates it like a file.

>>> data = building_level(40, 60, seed=1)
>>> len(data["grid"]), len(data["grid"][0]), len(data["guards"])
(40, 60, 4)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import ndimage

from .level import FORMAT


def building_occupancy(rows: int, cols: int, seed: int = 0) -> np.ndarray:
    """(rows, cols) bool, True = walkable: rooms, corridors, doors and furniture, one piece.

    Any size from 3 × 3 (one walkable cell inside the border wall); smaller raises ValueError.
    """
    if rows < 3 or cols < 3:
        raise ValueError(f"a building needs at least 3x3 cells (a wall all round), got {rows}x{cols}")
    rng = np.random.default_rng(seed)
    walk = np.zeros((rows, cols), dtype=bool)
    walk[1:-1, 1:-1] = True
    # corridors run between blocks of rooms; walls cut each block into rooms
    block = 24
    corridor = np.zeros((rows, cols), dtype=bool)
    corridor[[r for r in range(block, rows - 2, block)], :] = True
    corridor[:, [c for c in range(block, cols - 2, block)]] = True
    corridor = ndimage.binary_dilation(corridor, iterations=1) & walk
    wall = np.zeros((rows, cols), dtype=bool)
    for r0 in range(0, rows, block):
        for c0 in range(0, cols, block):
            r1, c1 = min(r0 + block, rows - 1), min(c0 + block, cols - 1)
            # one wall around the block, then split it into 2-3 rooms each way
            # a last block narrower than a room puts its near wall on (or past) the border:
            # clamped onto the border column/row, which ``walk`` then removes
            wall[r0 + 2 : r1 - 1, [min(max(c0 + 2, 1), cols - 1), max(c1 - 2, 1)]] = True
            wall[[min(max(r0 + 2, 1), rows - 1), max(r1 - 2, 1)], c0 + 2 : c1 - 1] = True
            cuts_r = sorted(rng.choice(np.arange(r0 + 7, max(r0 + 8, r1 - 6)), size=1))
            cuts_c = sorted(rng.choice(np.arange(c0 + 7, max(c0 + 8, c1 - 6)), size=1))
            for r in cuts_r:
                if r < r1 - 3:
                    wall[r, c0 + 2 : c1 - 1] = True
            for c in cuts_c:
                if c < c1 - 3:
                    wall[r0 + 2 : r1 - 1, c] = True
    wall &= walk & ~corridor
    # doors: knock a 2-cell gap into every wall segment between two open regions
    open_ = walk & ~wall
    labels, count = ndimage.label(open_)
    doors = np.zeros_like(wall)
    wr, wc = np.nonzero(wall)
    vertical = (
        (wc > 0) & (wc < cols - 1)
        & open_[wr, np.clip(wc - 1, 0, cols - 1)] & open_[wr, np.clip(wc + 1, 0, cols - 1)]
    )
    horizontal = (
        (wr > 0) & (wr < rows - 1)
        & open_[np.clip(wr - 1, 0, rows - 1), wc] & open_[np.clip(wr + 1, 0, rows - 1), wc]
    )
    left = np.where(vertical, labels[wr, np.clip(wc - 1, 0, cols - 1)], 0)
    right = np.where(vertical, labels[wr, np.clip(wc + 1, 0, cols - 1)], 0)
    up = np.where(horizontal, labels[np.clip(wr - 1, 0, rows - 1), wc], 0)
    down = np.where(horizontal, labels[np.clip(wr + 1, 0, rows - 1), wc], 0)
    a = np.where(vertical, np.minimum(left, right), np.minimum(up, down))
    b = np.where(vertical, np.maximum(left, right), np.maximum(up, down))
    candidates = np.flatnonzero((a > 0) & (a != b))
    order = rng.permutation(candidates)
    seen: set[tuple[int, int]] = set()
    for k in order.tolist():
        pair = (int(a[k]), int(b[k]))
        if pair in seen:
            continue
        seen.add(pair)
        r, c = int(wr[k]), int(wc[k])
        if vertical[k]:
            doors[r : r + 2, c] = True
        else:
            doors[r, c : c + 2] = True
    wall &= ~doors
    walk &= ~wall
    # furniture: boxes inside rooms, kept off the cells next to walls and doors
    interior = ndimage.binary_erosion(walk & ~corridor, iterations=2)
    spots = np.argwhere(interior)
    if len(spots):
        picks = spots[rng.choice(len(spots), size=max(1, len(spots) // 90), replace=False)]
        for r, c in picks.tolist():
            h, w = int(rng.integers(1, 3)), int(rng.integers(1, 4))
            box = np.zeros_like(walk)
            box[r : r + h, c : c + w] = True
            if (box & ~interior).any():
                continue
            walk &= ~box
    # keep the largest 4-connected piece (furniture may close a pocket)
    labels, count = ndimage.label(walk)
    if count > 1:
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        walk = labels == int(np.argmax(sizes))
    return walk


def building_level(
    rows: int, cols: int, seed: int = 0, *, form: str = "grid", guards: int = 4, name: str | None = None
) -> dict[str, Any]:
    """A building of ``rows × cols`` one-metre cells as level JSON data (``form``: grid / polygon).

    Guards stand on walkable cells spread over the plan (farthest-point picks from a sample).
    """
    walk = building_occupancy(rows, cols, seed)
    rng = np.random.default_rng(seed + 1)
    cells = np.argwhere(walk)
    sample = cells[rng.choice(len(cells), size=min(len(cells), 4000), replace=False)]
    chosen = [sample[0]]
    for _ in range(guards - 1):
        gap = np.min([np.abs(sample - c).sum(axis=1) for c in chosen], axis=0)
        chosen.append(sample[int(np.argmax(gap))])
    spots = [[float(c) + 0.5, float(r) + 0.5] for r, c in chosen]
    data: dict[str, Any] = {
        "format": FORMAT,
        "name": name or f"building-{rows}x{cols}-{seed}",
        "cell_size": 1.0,
        "guards": spots,
    }
    if form == "grid":
        data["grid"] = ["".join(".#"[int(not v)] for v in row) for row in walk]
    elif form == "polygon":
        from .grid_geometry import cells_polygon

        polygon = cells_polygon(walk, 1.0)
        data["outline"] = [list(p) for p in polygon.exterior.coords[:-1]]
        data["obstacles"] = [[list(p) for p in ring.coords[:-1]] for ring in polygon.interiors]
    else:
        raise ValueError(f"unknown form {form!r} (choose grid or polygon)")
    return data


__all__ = ["building_occupancy", "building_level"]
