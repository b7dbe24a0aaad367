"""Removing the zero-area triangles earcut emits, by Lawson flips of their long edge (before refinement)."""

from __future__ import annotations

import heapq
import math

import numpy as np

from navmesh.predicates import degenerate_candidates
from navmesh.refine import Refiner
from navmesh.triangulate import edge_neighbors, orient_ccw

__all__ = ["fix_degenerate"]


def fix_degenerate(verts: np.ndarray, tris: np.ndarray, tol: float) -> np.ndarray:
    """Remove zero-area triangles by flipping their long edge (earcut can emit them)."""
    tris = orient_ccw(verts, tris)
    ref = Refiner.__new__(Refiner)
    ref.x, ref.y = verts[:, 0].tolist(), verts[:, 1].tolist()
    ref.tri, ref.nbr = tris.tolist(), edge_neighbors(tris).tolist()
    ref.tol, ref.dirty, ref.bound = tol, [], {}

    def flat(t: int) -> bool:
        a, b, c = ref.tri[t]
        longest = max(math.hypot(ref.x[q] - ref.x[r], ref.y[q] - ref.y[r]) for q, r in ((b, c), (c, a), (a, b)))
        return ref._orient(a, b, c) <= tol * longest

    # the first flat triangle each time: numpy lists those that may be flat, a heap keeps
    # them and the triangles each flip changes in index order, the scalar test decides
    x, y = np.asarray(ref.x), np.asarray(ref.y)
    maybe = np.flatnonzero(degenerate_candidates(x, y, tris, tol)).tolist()
    heapq.heapify(maybe)
    for _ in range(len(tris) + 1):
        while maybe and not flat(maybe[0]):
            heapq.heappop(maybe)
        if not maybe:
            break
        bad = maybe[0]
        a, b, c = ref.tri[bad]
        # the vertex lying between the other two is opposite the long edge: flip that edge
        lens = [math.hypot(ref.x[q] - ref.x[r], ref.y[q] - ref.y[r]) for q, r in ((b, c), (c, a), (a, b))]
        k = int(np.argmax(lens))
        if ref.nbr[bad][k] < 0:
            raise ValueError("degenerate triangle on the boundary: a vertex lies on a wall")
        heapq.heappush(maybe, ref._flip(bad, k))
    return orient_ccw(verts, np.asarray(ref.tri, dtype=np.int64))
