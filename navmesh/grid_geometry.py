"""Grid geometry: the walkable polygon traced exactly along the boundary of a cell grid."""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

__all__ = ["cells_polygon"]


# Boundary-edge directions in world coordinates (x right, y down): east, south, west, north.
_STEPS = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]])


def cells_polygon(occupancy: np.ndarray, cell_size: float) -> Polygon:
    """Union of the walkable cells as one polygon, traced in linear time.

    Precondition: the walkable cells are one non-empty 4-connected group (checked first).
    Every cell side between a walkable and a blocked cell is a directed boundary edge with
    the walkable cell on its right (on screen); each edge's successor is the next edge at
    its end vertex, preferring a left turn so that where two blocked cells touch diagonally
    each ring hugs its own blocked side: every ring is then simple and the polygon valid
    (a hole may touch the exterior or another hole at one vertex). ``shapely.unary_union``
    of the cells gives the same polygon but slows down badly with many holes.
    """
    rows, cols = occupancy.shape
    padded = np.pad(occupancy, 1)
    cell = padded[1:-1, 1:-1]
    sides = (  # (edge mask, direction, start vertex offset (dx, dy) from the cell's corner)
        (cell & ~padded[:-2, 1:-1], 0, (0, 0)),  # top side, eastwards
        (cell & ~padded[1:-1, 2:], 1, (1, 0)),  # right side, southwards
        (cell & ~padded[2:, 1:-1], 2, (1, 1)),  # bottom side, westwards
        (cell & ~padded[1:-1, :-2], 3, (0, 1)),  # left side, northwards
    )
    parts = [(np.nonzero(mask), d, off) for mask, d, off in sides]
    x = np.concatenate([c + dx for (_, c), _, (dx, _) in parts])
    y = np.concatenate([r + dy for (r, _), _, (_, dy) in parts])
    direction = np.concatenate([np.full(r.size, d) for (r, _), d, _ in parts])
    count = x.size

    edge_at = np.full((rows + 1, cols + 1, 4), -1, dtype=np.int64)  # (y, x, dir) -> edge
    edge_at[y, x, direction] = np.arange(count)
    end_x, end_y = x + _STEPS[direction, 0], y + _STEPS[direction, 1]
    successor = np.full(count, -1, dtype=np.int64)
    for turn in (1, 0, 3):  # right turn, straight on, left turn: later ones take priority
        candidate = edge_at[end_y, end_x, (direction + turn) % 4]
        successor = np.where(candidate >= 0, candidate, successor)

    # Follow the successor permutation around each ring. Edge 0 is the top side of the
    # first walkable cell in row-major order, so ring 0 is the exterior.
    nxt = successor.tolist()
    seen = bytearray(count)
    order: list[int] = []
    ring_starts: list[int] = []
    for first in range(count):
        if seen[first]:
            continue
        ring_starts.append(len(order))
        edge = first
        while not seen[edge]:
            seen[edge] = 1
            order.append(edge)
            edge = nxt[edge]
    ring_of = np.zeros(count, dtype=np.int64)
    ring_of[ring_starts[1:]] = 1
    ring_of = np.cumsum(ring_of)
    previous = np.arange(count) - 1  # position of the previous edge in the same ring
    previous[ring_starts] = np.append(ring_starts[1:], count) - 1
    ordered = np.asarray(order)
    turning = direction[ordered] != direction[ordered][previous]  # drop collinear vertices
    corners = ordered[turning]
    coords = np.column_stack([x[corners], y[corners]]) * cell_size
    rings = shapely.linearrings(coords, indices=ring_of[turning])
    return shapely.polygons(rings[0], holes=rings[1:])
