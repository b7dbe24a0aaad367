"""Point location in the refiner's mutable triangulation: walking to a point, its cavity.

A mix-in of :class:`navmesh.refine.Refiner` (split from it to keep modules short): where a
circumcentre lies, which walls it encroaches, and how near it is to a vertex already there.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from navmesh.plane import orient2 as _orient2

__all__ = ["Locating"]


class Locating:
    """Walks and cavities over ``x``, ``y``, ``tri``, ``nbr`` (the refiner's lists)."""

    x: list[float]
    y: list[float]
    tri: list[list[int]]
    nbr: list[list[int]]
    tol: float
    work: int  #: walk steps, cavity triangles and flip tests so far (the refinement's budget)

    _new_vertex: Callable[[float, float], int]  # the refiner's
    _incircle: Callable[[int, int, int, int], float]

    def _walk(self, t: int, px: float, py: float) -> tuple[int, int]:
        """Walk from t towards p: (triangle, -1) containing p, or (triangle, k) blocked by boundary edge k."""
        x, y = self.x, self.y
        a, b, c = self.tri[t]
        ox, oy = (x[a] + x[b] + x[c]) / 3.0, (y[a] + y[b] + y[c]) / 3.0
        eps = self.tol * self.tol
        for _ in range(4 * len(self.tri) + 10):
            self.work += 1
            tri = self.tri[t]
            exit_k = -1
            for k in range(3):
                v1, v2 = tri[(k + 1) % 3], tri[(k + 2) % 3]
                if _orient2(x[v1], y[v1], x[v2], y[v2], px, py) < -eps:
                    o1 = _orient2(ox, oy, px, py, x[v1], y[v1])
                    o2 = _orient2(ox, oy, px, py, x[v2], y[v2])
                    if o1 * o2 <= 0.0:
                        exit_k = k
                        break
                    if exit_k < 0:
                        exit_k = k + 3  # fallback when the walk line grazes a vertex
            if exit_k < 0:
                return t, -1
            exit_k %= 3
            u = self.nbr[t][exit_k]
            if u < 0:
                return t, exit_k
            t = u
        return t, -2

    def _cavity(self, t: int, px: float, py: float) -> tuple[list[tuple[int, int]], float]:
        """Boundary edges of the triangles whose circumcircle holds p (those p may encroach),
        and the distance from p to the nearest of their vertices (p's nearest vertex: the
        cavity's corners become p's neighbours)."""
        x, y = self.x, self.y
        seen, stack, segs = {t}, [t], []
        q = self._new_vertex(px, py)
        try:
            while stack:
                s = stack.pop()
                tri, nb = self.tri[s], self.nbr[s]
                for k in range(3):
                    u = nb[k]
                    if u < 0:
                        segs.append((tri[(k + 1) % 3], tri[(k + 2) % 3]))
                    elif u not in seen:
                        ua, ub, uc = self.tri[u]
                        if self._incircle(ua, ub, uc, q) > 1e-12:
                            seen.add(u)
                            stack.append(u)
        finally:
            self.x.pop()
            self.y.pop()
        out = []
        for b, c in segs:
            if (x[b] - px) * (x[c] - px) + (y[b] - py) * (y[c] - py) < 0.0:
                out.append((b, c))
        self.work += len(seen)
        near2 = min((x[v] - px) ** 2 + (y[v] - py) ** 2 for s in seen for v in self.tri[s])
        return out, math.sqrt(near2)

    def _near_vertex(self, t: int, px: float, py: float, gap: float) -> bool:
        """Whether p lies within ``gap`` of a corner of t or of its neighbours."""
        x, y, tri = self.x, self.y, self.tri
        return any((x[v] - px) ** 2 + (y[v] - py) ** 2 < gap * gap
                   for s in (t, *self.nbr[t]) if s >= 0 for v in tri[s])
