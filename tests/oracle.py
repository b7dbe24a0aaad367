"""The visibility-graph oracle: exact Euclidean shortest paths in a polygon with holes.

A test tool, not product: :class:`VisibilityGraph` works on the polygon itself, with no
mesh — a visibility graph over the reflex corners of the walkable area (the only places a
shortest path can bend), all-pairs distances by Floyd–Warshall and numpy-vectorised segment
visibility (about R × E segment tests per query).  The navmesh paths are measured against
it by the tests (``tests/test_paths.py``) and by ``benchmarks/navmesh.py`` (which puts this
folder on ``sys.path`` in ``benchmarks/_paths.py``).  It shares only the ring cleaning
(:func:`navmesh.rings.polygon_rings`) with the product, so the two implementations of
"exact" are independent.

Visibility is *closed*: a segment may touch and run along walls, but may not enter an
obstacle, nor slip through a pinch point where two obstacles touch corner to corner.

>>> from shapely import box
>>> vg = VisibilityGraph(box(0, 0, 10, 10).difference(box(4, 0, 6, 8)))
>>> points, length = vg.shortest_path((1, 1), (9, 1))
>>> points.tolist(), round(length, 6)
([[1.0, 1.0], [4.0, 8.0], [6.0, 8.0], [9.0, 1.0]], 17.231546)
"""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import Polygon

from navmesh.rings import polygon_rings

__all__ = ["VisibilityGraph"]

_TWO_PI = 2.0 * math.pi
_ANGLE_TOL = 1e-9


class VisibilityGraph:
    """Exact shortest paths in a (closed) polygon with holes.

    Attributes: ``reflex`` (R, 2) positions of the reflex corners (one entry per reflex
    sector, so a pinch vertex may appear twice), ``dist`` (R, R) geodesic distances
    between them.
    """

    def __init__(self, polygon: Polygon, *, tol: float | None = None) -> None:
        minx, miny, maxx, maxy = polygon.bounds
        self.tol = tol if tol is not None else 1e-9 * max(1.0, maxx - minx, maxy - miny)
        rings = polygon_rings(polygon, self.tol)
        a = np.concatenate(rings)
        b = np.concatenate([np.roll(r, -1, axis=0) for r in rings])
        p = np.concatenate([np.roll(r, 1, axis=0) for r in rings])
        self._ea, self._eb = a, b
        e = b - a
        self._elen = np.hypot(*e.T)
        self._eunit = e / self._elen[:, None]
        self._build_sectors(a, b, p)
        self._build_graph()

    # ------------------------------------------------------------------ sectors
    def _build_sectors(self, w: np.ndarray, nxt: np.ndarray, prv: np.ndarray) -> None:
        """Walkable angular sectors at every boundary vertex (several at pinch points)."""
        verts, inv = np.unique(w, axis=0, return_inverse=True)
        inv = inv.ravel()
        ang_next = np.arctan2(*(nxt - w)[:, ::-1].T)
        ang_prev = np.arctan2(*(prv - w)[:, ::-1].T)
        sec_vert, sec_start, sec_sweep = [], [], []
        for v in range(len(verts)):
            occ = np.flatnonzero(inv == v)
            for i in occ:
                ccw = (ang_prev[occ] - ang_next[i]) % _TWO_PI
                ccw[ccw <= _ANGLE_TOL] = _TWO_PI  # a prev ray on the next ray closes nothing
                sec_vert.append(v)
                sec_start.append(ang_next[i])
                sec_sweep.append(ccw.min())
        order = np.argsort(np.asarray(sec_vert), kind="stable")
        self._verts = verts
        self._sec_vert = np.asarray(sec_vert)[order]
        self._sec_start = np.asarray(sec_start)[order]
        self._sec_sweep = np.asarray(sec_sweep)[order]
        # first sector of every vertex, for reduceat
        self._vert_first = np.searchsorted(self._sec_vert, np.arange(len(verts)))
        reflex = np.flatnonzero(self._sec_sweep > math.pi + 1e-9)
        self._reflex_sec = reflex
        self.reflex = verts[self._sec_vert[reflex]]

    def _in_sector(self, ang: np.ndarray) -> np.ndarray:
        """(n, S) bool: direction angle ``ang[i]`` lies in closed sector s."""
        rel = (ang[:, None] - self._sec_start[None, :]) % _TWO_PI
        return (rel <= self._sec_sweep[None, :] + _ANGLE_TOL) | (rel >= _TWO_PI - _ANGLE_TOL)

    # --------------------------------------------------------------- visibility
    def visible(
        self,
        p: np.ndarray,
        q: np.ndarray,
        p_sector: np.ndarray | None = None,
        q_sector: np.ndarray | None = None,
    ) -> np.ndarray:
        """For segments ``p[i] → q[i]`` (arrays (n, 2)): does each stay in the closed walkable area?

        ``p`` (and ``q``) must lie in the walkable area.  ``p_sector[i] >= 0`` says ``p[i]``
        is the reflex corner ``self.reflex[p_sector[i]]`` approached from inside that
        sector (matters only at pinch points); -1 means a free point.
        """
        p = np.atleast_2d(np.asarray(p, dtype=np.float64))
        q = np.atleast_2d(np.asarray(q, dtype=np.float64))
        n = max(len(p), len(q))
        p, q = np.broadcast_to(p, (n, 2)), np.broadcast_to(q, (n, 2))
        ps = np.full(n, -1) if p_sector is None else np.broadcast_to(np.asarray(p_sector), (n,))
        qs = np.full(n, -1) if q_sector is None else np.broadcast_to(np.asarray(q_sector), (n,))
        chunk = max(1, 400_000 // max(len(self._ea), len(self._sec_vert)))
        out = np.empty(n, dtype=bool)
        for i in range(0, n, chunk):
            sl = slice(i, i + chunk)
            out[sl] = self._visible_chunk(p[sl], q[sl], ps[sl], qs[sl])
        return out

    def _visible_chunk(self, p: np.ndarray, q: np.ndarray, ps: np.ndarray, qs: np.ndarray) -> np.ndarray:
        tol = self.tol
        d = q - p
        length = np.hypot(*d.T)
        ok = length > tol
        safe_len = np.where(ok, length, 1.0)
        du = d / safe_len[:, None]
        a, b, eu = self._ea, self._eb, self._eunit
        # signed distances of edge ends from the segment's line, and of p, q from the edge's line
        ra = a[None] - p[:, None]
        rb = b[None] - p[:, None]
        sa = du[:, None, 0] * ra[..., 1] - du[:, None, 1] * ra[..., 0]
        sb = du[:, None, 0] * rb[..., 1] - du[:, None, 1] * rb[..., 0]
        sp = eu[None, :, 0] * (-ra[..., 1]) - eu[None, :, 1] * (-ra[..., 0])
        rq = q[:, None] - a[None]
        sq = eu[None, :, 0] * rq[..., 1] - eu[None, :, 1] * rq[..., 0]
        blocked = ((sa > tol) & (sb < -tol) | (sa < -tol) & (sb > tol)) & (
            (sp > tol) & (sq < -tol) | (sp < -tol) & (sq > tol)
        )
        # an end point inside an edge (not at its vertices) must leave into the walkable side
        tp = -(eu[None, :, 0] * ra[..., 0] + eu[None, :, 1] * ra[..., 1])
        tq = eu[None, :, 0] * rq[..., 0] + eu[None, :, 1] * rq[..., 1]
        el = self._elen[None]
        turn = eu[None, :, 0] * du[:, None, 1] - eu[None, :, 1] * du[:, None, 0]
        p_in_edge = (np.abs(sp) <= tol) & (tp > tol) & (tp < el - tol)
        q_in_edge = (np.abs(sq) <= tol) & (tq > tol) & (tq < el - tol)
        blocked |= p_in_edge & (turn < -_ANGLE_TOL)
        blocked |= q_in_edge & (turn > _ANGLE_TOL)
        bad = blocked.any(axis=1)
        # vertices on the segment: the walkable sectors there must let it through
        rw = self._verts[None] - p[:, None]
        dist = du[:, None, 0] * rw[..., 1] - du[:, None, 1] * rw[..., 0]
        along = du[:, None, 0] * rw[..., 0] + du[:, None, 1] * rw[..., 1]
        on = (np.abs(dist) <= tol) & (along >= -tol) & (along <= safe_len[:, None] + tol)
        rows = np.flatnonzero(on.any(axis=1) & ~bad)
        if rows.size:
            ang = np.arctan2(du[rows, 1], du[rows, 0])
            in_d = self._in_sector(ang)
            in_nd = self._in_sector(ang + math.pi)
            first = self._vert_first
            ok_mid = np.logical_or.reduceat(in_d & in_nd, first, axis=1)
            ok_p = np.logical_or.reduceat(in_d, first, axis=1)
            ok_q = np.logical_or.reduceat(in_nd, first, axis=1)
            for j, r in enumerate(rows):  # a named reflex sector at an end point overrides "any"
                if ps[r] >= 0:
                    s = self._reflex_sec[ps[r]]
                    ok_p[j, self._sec_vert[s]] = in_d[j, s]
                if qs[r] >= 0:
                    s = self._reflex_sec[qs[r]]
                    ok_q[j, self._sec_vert[s]] = in_nd[j, s]
            o = on[rows]
            at_p = o & (np.hypot(rw[rows, :, 0], rw[rows, :, 1]) <= tol)
            rwq = self._verts[None] - q[rows, None]
            at_q = o & (np.hypot(rwq[..., 0], rwq[..., 1]) <= tol)
            mid = o & ~at_p & ~at_q
            fail = (mid & ~ok_mid) | (at_p & ~ok_p) | (at_q & ~ok_q)
            bad[rows] |= fail.any(axis=1)
        return ~bad | ~ok

    # -------------------------------------------------------------------- graph
    def _build_graph(self) -> None:
        r = self.reflex
        n = len(r)
        dist = np.full((n, n), np.inf)
        np.fill_diagonal(dist, 0.0)
        if n > 1:
            i, j = np.triu_indices(n, k=1)
            gap = np.hypot(*(r[i] - r[j]).T)
            far = gap > self.tol  # two sectors of one pinch vertex are not connected
            i, j, gap = i[far], j[far], gap[far]
            vis = self.visible(r[i], r[j], i, j)
            dist[i[vis], j[vis]] = gap[vis]
            dist[j[vis], i[vis]] = gap[vis]
        nxt = np.where(np.isfinite(dist), np.arange(n)[None, :], -1)
        for k in range(n):
            via = dist[:, k : k + 1] + dist[k : k + 1, :]
            better = via < dist
            if better.any():
                dist = np.where(better, via, dist)
                nxt = np.where(better, nxt[:, k : k + 1], nxt)
        self.dist = dist
        self._next = nxt

    # ------------------------------------------------------------------- query
    def shortest_path(self, start: tuple[float, float], goal: tuple[float, float]) -> tuple[np.ndarray, float]:
        """Exact shortest path ``(points (k, 2), length)``; both points must be walkable.

        Returns ``(points, inf)`` with just the two points if no path exists.
        """
        s = np.asarray(start, dtype=np.float64)
        g = np.asarray(goal, dtype=np.float64)
        if self.visible(s[None], g[None])[0]:
            return np.array([s, g]), float(np.hypot(*(g - s)))
        n = len(self.reflex)
        if n == 0:
            return np.array([s, g]), math.inf
        idx = np.arange(n)
        ds = np.where(self.visible(np.repeat(s[None], n, 0), self.reflex, None, idx), np.hypot(*(self.reflex - s).T), np.inf)
        dg = np.where(self.visible(np.repeat(g[None], n, 0), self.reflex, None, idx), np.hypot(*(self.reflex - g).T), np.inf)
        total = ds[:, None] + self.dist + dg[None, :]
        a, b = (int(i) for i in np.unravel_index(np.argmin(total), total.shape))
        best = float(total[a, b])
        if not math.isfinite(best):
            return np.array([s, g]), math.inf
        chain: list[int] = [a]
        while chain[-1] != b:
            chain.append(int(self._next[chain[-1], b]))
        pts = np.vstack([s[None], self.reflex[chain], g[None]])
        return pts, best

    def distance(self, start: tuple[float, float], goal: tuple[float, float]) -> float:
        """Length of the shortest path between two walkable points."""
        return self.shortest_path(start, goal)[1]
