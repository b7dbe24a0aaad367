"""Ruppert refinement: a mutable constrained triangulation with Lawson flips and Steiner points.

The second stage of :meth:`navmesh.mesh.NavMesh.build`: the base triangulation of
:mod:`navmesh.triangulate` is flipped to constrained Delaunay, then refined until every
angle reaches the minimum angle and every area the maximum area (see ``docs/navmesh.md``).
:func:`navmesh.degenerate.fix_degenerate` uses the same flips to remove the zero-area
triangles earcut emits.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from navmesh.plane import angle_at as _angle
from navmesh.plane import circumcentre as _circumcentre
from navmesh.plane import orient2 as _orient2
from navmesh.predicates import flip_candidates, quality_candidates, small_angle_candidates
from navmesh.refine_locate import Locating
from navmesh.rings import ring_neighbours
from navmesh.triangulate import edge_neighbors, vertex_ids

__all__ = ["Refiner"]


_NEXT, _PREV = (1, 2, 0), (2, 0, 1)  # (k + 1) % 3 and (k + 2) % 3


class Refiner(Locating):
    """Mutable constrained triangulation: Lawson flips and Ruppert-style Steiner refinement.

    Boundary edges (no neighbour) are the constraints and are never flipped.  Every
    insertion splits whole triangles (a point on an edge splits both sides), so the
    result is conforming by construction.
    """

    def __init__(self, verts: np.ndarray, tris: np.ndarray, rings: list[np.ndarray], tol: float) -> None:
        self.x: list[float] = verts[:, 0].tolist()
        self.y: list[float] = verts[:, 1].tolist()
        nbr = edge_neighbors(tris)
        self.tri: list[list[int]] = tris.tolist()
        self.nbr: list[list[int]] = nbr.tolist()
        self.tol = tol
        self.dirty: list[int] = []
        self.n_input = len(verts)
        self.work = 0
        # input segments and the input angle at every input vertex (for the small-angle rule);
        # numpy picks the vertices that may be below 60 degrees, the scalar test decides
        self.small: set[int] = set()
        limit = math.radians(60.0)
        allv = np.concatenate(rings)
        prv, nxt = ring_neighbours([len(r) for r in rings])
        maybe = np.flatnonzero(small_angle_candidates(allv[:, 0], allv[:, 1], prv, nxt, limit))
        ids = vertex_ids(verts, allv)
        for v, p, n in zip(ids[maybe].tolist(), ids[prv[maybe]].tolist(), ids[nxt[maybe]].tolist()):
            # walkable (interior) angle: counter-clockwise from the next to the previous vertex
            ux, uy = self.x[n] - self.x[v], self.y[n] - self.y[v]
            wx, wy = self.x[p] - self.x[v], self.y[p] - self.y[v]
            ang = math.atan2(ux * wy - uy * wx, ux * wx + uy * wy) % (2.0 * math.pi)
            if ang < limit:
                self.small.add(v)
        self.on_seg: dict[int, tuple[int, int]] = {}  # Steiner vertex -> input segment end points
        bt, bk = np.nonzero(nbr < 0)
        ends = zip(tris[bt, (bk + 1) % 3].tolist(), tris[bt, (bk + 2) % 3].tolist())
        self.bound: dict[tuple[int, int], int] = dict(zip(ends, bt.tolist()))  # directed boundary edge -> triangle

    # -------------------------------------------------------------- primitives
    def _orient(self, a: int, b: int, c: int) -> float:
        x, y = self.x, self.y
        return _orient2(x[a], y[a], x[b], y[b], x[c], y[c])

    def _incircle(self, a: int, b: int, c: int, d: int) -> float:
        """Positive when d lies inside the circumcircle of the counter-clockwise (a, b, c)."""
        x, y = self.x, self.y
        adx, ady = x[a] - x[d], y[a] - y[d]
        bdx, bdy = x[b] - x[d], y[b] - y[d]
        cdx, cdy = x[c] - x[d], y[c] - y[d]
        ad, bd, cd = adx * adx + ady * ady, bdx * bdx + bdy * bdy, cdx * cdx + cdy * cdy
        det = adx * (bdy * cd - bd * cdy) - ady * (bdx * cd - bd * cdx) + ad * (bdx * cdy - bdy * cdx)
        scale = max(ad, bd, cd)
        return det / (scale * scale) if scale > 0 else 0.0

    def _replace_nbr(self, t: int, old: int, new: int) -> None:
        if t >= 0:
            nb = self.nbr[t]
            nb[nb.index(old)] = new

    def _should_flip(self, t: int, k: int) -> bool:
        """Whether edge k of t is not locally Delaunay and its quad is convex (so it flips).

        :meth:`_incircle` and :meth:`_orient` written out (the hottest test of the
        refinement): the same operations in the same order.
        """
        u = self.nbr[t][k]
        if u < 0:
            return False
        tri = self.tri[t]
        a, b, c = tri[k], tri[_NEXT[k]], tri[_PREV[k]]
        d = self.tri[u][self.nbr[u].index(t)]
        x, y = self.x, self.y
        xa, ya, xd, yd = x[a], y[a], x[d], y[d]
        adx, ady = xa - xd, ya - yd
        bdx, bdy = x[b] - xd, y[b] - yd
        cdx, cdy = x[c] - xd, y[c] - yd
        ad, bd, cd = adx * adx + ady * ady, bdx * bdx + bdy * bdy, cdx * cdx + cdy * cdy
        scale = max(ad, bd, cd)
        if not scale > 0:
            return False
        det = adx * (bdy * cd - bd * cdy) - ady * (bdx * cd - bd * cdx) + ad * (bdx * cdy - bdy * cdx)
        if det / (scale * scale) <= 1e-12:
            return False
        return ((x[b] - xa) * (yd - ya) - (y[b] - ya) * (xd - xa) > 0
                and (xd - xa) * (y[c] - ya) - (yd - ya) * (x[c] - xa) > 0)

    def _flip(self, t: int, k: int) -> int:
        """Flip the edge opposite vertex k of t; afterwards both t and u start with that vertex."""
        tri, nb = self.tri[t], self.nbr[t]
        a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
        u, n_b, n_c = nb[k], nb[(k + 1) % 3], nb[(k + 2) % 3]
        j = self.nbr[u].index(t)
        utri, unb = self.tri[u], self.nbr[u]
        d = utri[j]
        n_uc, n_ub = unb[(j + 1) % 3], unb[(j + 2) % 3]
        self.tri[t] = [a, b, d]
        self.nbr[t] = [n_uc, u, n_c]
        self.tri[u] = [a, d, c]
        self.nbr[u] = [n_ub, n_b, t]
        self._replace_nbr(n_uc, u, t)
        self._replace_nbr(n_b, t, u)
        if n_uc < 0:
            self.bound[(b, d)] = t
        if n_b < 0:
            self.bound[(c, a)] = u
        self.dirty += (t, u)
        return u

    def legalize_all(self) -> None:
        """Lawson flips until every interior edge is locally Delaunay (any triangulation -> CDT).

        Every edge (t, k) is tested from the last to the first, each flip's four outer
        edges first.  An edge whose two triangles no flip has touched yet keeps the result
        numpy found for it up front (:func:`flip_candidates`), so only candidates and
        touched triangles are tested one by one: the same flips in the same order.
        """
        n = len(self.tri)
        maybe = flip_candidates(np.asarray(self.x), np.asarray(self.y), np.asarray(self.tri, dtype=np.int64),
                                np.asarray(self.nbr, dtype=np.int64), 1e-12).tolist()
        touched = bytearray(n)
        stack: list[tuple[int, int]] = []
        t_next = n - 1  # the untested initial items are (t, k) for t <= t_next, k <= k_next
        k_next = 2
        while True:
            if stack:
                t, k = stack.pop()
            else:
                while t_next >= 0 and not touched[t_next] and not any(maybe[t_next][: k_next + 1]):
                    t_next, k_next = t_next - 1, 2
                if t_next < 0:
                    return
                t, k = t_next, k_next
                t_next, k_next = (t_next, k_next - 1) if k_next else (t_next - 1, 2)
                if not touched[t] and not maybe[t][k]:
                    continue
            if self._should_flip(t, k):
                u = self._flip(t, k)
                for s in (t, u, *self.nbr[t], *self.nbr[u]):
                    if s >= 0:
                        touched[s] = 1
                stack += ((t, 0), (t, 2), (u, 0), (u, 1))

    def _legalize_around(self, p: int, tris: list[int]) -> None:
        stack = list(tris)
        while stack:
            self.work += 1
            t = stack.pop()
            k = self.tri[t].index(p)
            if self._should_flip(t, k):
                u = self._flip(t, k)
                stack += (t, u)

    def _new_vertex(self, px: float, py: float) -> int:
        self.x.append(px)
        self.y.append(py)
        return len(self.x) - 1

    def insert_in_triangle(self, t: int, px: float, py: float) -> int:
        p = self._new_vertex(px, py)
        a, b, c = self.tri[t]
        na, nb, nc = self.nbr[t]
        t1, t2 = len(self.tri), len(self.tri) + 1
        self.tri[t] = [a, b, p]
        self.nbr[t] = [t1, t2, nc]
        self.tri.append([b, c, p])
        self.nbr.append([t2, t, na])
        self.tri.append([c, a, p])
        self.nbr.append([t, t1, nb])
        self._replace_nbr(na, t, t1)
        self._replace_nbr(nb, t, t2)
        if na < 0:
            self.bound[(b, c)] = t1
        if nb < 0:
            self.bound[(c, a)] = t2
        self.dirty += (t, t1, t2)
        self._legalize_around(p, [t, t1, t2])
        return p

    def insert_on_edge(self, t: int, k: int, px: float, py: float) -> int:
        """Insert a point on the edge opposite vertex k of t (splitting both sides)."""
        p = self._new_vertex(px, py)
        tri, nbt = self.tri[t], self.nbr[t]
        a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
        u, n_b, n_c = nbt[k], nbt[(k + 1) % 3], nbt[(k + 2) % 3]
        t1 = len(self.tri)
        if u < 0:
            self.tri[t] = [a, b, p]
            self.nbr[t] = [-1, t1, n_c]
            self.tri.append([a, p, c])
            self.nbr.append([-1, n_b, t])
            self._replace_nbr(n_b, t, t1)
            if n_b < 0:
                self.bound[(c, a)] = t1
            self.bound.pop((b, c), None)
            self.bound[(b, p)] = t
            self.bound[(p, c)] = t1
            self.dirty += (t, t1)
            self._legalize_around(p, [t, t1])
            return p
        j = self.nbr[u].index(t)
        utri, unb = self.tri[u], self.nbr[u]
        d = utri[j]
        n_uc, n_ub = unb[(j + 1) % 3], unb[(j + 2) % 3]
        u1 = t1 + 1
        self.tri[t] = [a, b, p]
        self.nbr[t] = [u1, t1, n_c]
        self.tri.append([a, p, c])
        self.nbr.append([u, n_b, t])
        self.tri[u] = [d, c, p]
        self.nbr[u] = [t1, u1, n_ub]
        self.tri.append([d, p, b])
        self.nbr.append([t, n_uc, u])
        self._replace_nbr(n_b, t, t1)
        self._replace_nbr(n_uc, u, u1)
        if n_b < 0:
            self.bound[(c, a)] = t1
        if n_uc < 0:
            self.bound[(b, d)] = u1
        self.dirty += (t, t1, u, u1)
        self._legalize_around(p, [t, t1, u, u1])
        return p

    # -------------------------------------------------------------- refinement
    def _split_segment(self, b: int, c: int) -> bool:
        """Split the boundary edge b→c (midpoint, or a power-of-two shell near a small angle)."""
        t = self.bound.get((b, c))
        if t is None:
            return False
        x, y = self.x, self.y
        length = math.hypot(x[c] - x[b], y[c] - y[b])
        if length < 1e3 * self.tol:
            return False
        frac = 0.5
        # next to a small input angle, split on concentric shells (powers of two) around
        # the apex so the refinement of the two segments meeting there cannot ping-pong
        if b in self.small:
            frac = 2.0 ** round(math.log2(length / 2.0)) / length
        elif c in self.small:
            frac = 1.0 - 2.0 ** round(math.log2(length / 2.0)) / length
        px, py = x[b] + frac * (x[c] - x[b]), y[b] + frac * (y[c] - y[b])
        k = next(k for k in range(3) if self.tri[t][k] not in (b, c))
        seg = self.on_seg.get(b) or self.on_seg.get(c) or (b, c)
        p = self.insert_on_edge(t, k, px, py)
        self.on_seg[p] = seg
        return True

    def _encroached(self, t: int, k: int) -> bool:
        """Boundary edge opposite vertex k of t lies under an obtuse apex (diametral circle)."""
        tri = self.tri[t]
        a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
        x, y = self.x, self.y
        return (x[b] - x[a]) * (x[c] - x[a]) + (y[b] - y[a]) * (y[c] - y[a]) < 0.0

    def _quality(self, t: int, sin_min: float, max_area: float) -> float:
        """< 1 when the triangle is bad (too small an angle or too large)."""
        a, b, c = self.tri[t]
        x, y = self.x, self.y
        xa, ya, xb, yb, xc, yc = x[a], y[a], x[b], y[b], x[c], y[c]
        hypot = math.hypot
        l0 = hypot(xb - xc, yb - yc)
        l1 = hypot(xc - xa, yc - ya)
        l2 = hypot(xa - xb, ya - yb)
        area2 = (xb - xa) * (yc - ya) - (yb - ya) * (xc - xa)  # _orient2 written out
        lmin = min(l0, l1, l2)
        prod = l0 * l1 * l2 / lmin if lmin > 0 else math.inf
        q = (area2 / prod) / sin_min if sin_min > 0 and prod > 0 else math.inf
        if max_area > 0:
            q = min(q, max_area / (0.5 * area2))
        return q

    def _area(self, t: int) -> float:
        a, b, c = self.tri[t]
        return 0.5 * self._orient(a, b, c)

    def _unfixable(self, t: int) -> bool:
        """A small angle squeezed between two input segments at a small input angle."""
        tri, nb = self.tri[t], self.nbr[t]
        x, y = self.x, self.y
        best, kmin = math.inf, 0
        for k in range(3):
            a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            ang = _angle(x[a], y[a], x[b], y[b], x[c], y[c])
            if ang < best:
                best, kmin = ang, k
        v = tri[kmin]
        if nb[(kmin + 1) % 3] < 0 and nb[(kmin + 2) % 3] < 0:
            return True
        if v in self.small:
            others = [tri[(kmin + 1) % 3], tri[(kmin + 2) % 3]]
            return all(o < self.n_input or v in self.on_seg.get(o, ()) for o in others)
        return False

    def refine(self, min_angle: float | None, max_area: float | None, max_steiner: int,
               max_work: int | None = None) -> bool:
        """Ruppert's algorithm: split encroached segments, insert circumcentres of bad triangles.

        At most ``max_steiner`` Steiner points and about ``max_work`` steps (walk steps,
        cavity triangles, flip tests: :attr:`work`; an insertion can cost as many as the
        mesh has triangles).  True when nothing is left to do; False when a budget stopped
        it with bad triangles left (the mesh is conforming all the same).
        """
        sin_min = math.sin(math.radians(min_angle)) if min_angle else 0.0
        area_cap = max_area if max_area else 0.0
        self.legalize_all()
        segq: list[tuple[int, int]] = []
        badq: list[tuple[float, int, tuple[int, ...]]] = []

        def scan(ts: list[int]) -> None:
            for t in dict.fromkeys(ts):
                tri, nb = self.tri[t], self.nbr[t]
                if nb[0] < 0 or nb[1] < 0 or nb[2] < 0:
                    for k in range(3):
                        if nb[k] < 0 and self._encroached(t, k):
                            segq.append((tri[(k + 1) % 3], tri[(k + 2) % 3]))
                q = self._quality(t, sin_min, area_cap)
                if q < 1.0:
                    heapq.heappush(badq, (q, t, tuple(tri)))

        self._scan_all(segq, badq, sin_min, area_cap)
        self.dirty = []
        budget = max_steiner
        retries: dict[tuple[int, ...], int] = {}
        steps = 0
        work_cap = max_work if max_work is not None else math.inf
        while budget > 0 and (segq or badq) and steps < 50 * max_steiner and self.work < work_cap:
            steps += 1
            if segq:
                b, c = segq.pop()
                if self._split_segment(b, c):
                    budget -= 1
                    ts, self.dirty = self.dirty, []
                    scan(ts)
                continue
            q, t, key = heapq.heappop(badq)
            if tuple(self.tri[t]) != key:
                continue
            if not (area_cap and self._area(t) > area_cap) and self._unfixable(t):
                continue
            a, b, c = key
            cx, cy = _circumcentre(self.x[a], self.y[a], self.x[b], self.y[b], self.x[c], self.y[c])
            if not (math.isfinite(cx) and math.isfinite(cy)):
                continue
            s, k = self._walk(t, cx, cy)
            if k == -2:
                continue
            if k >= 0:  # circumcentre beyond a wall: that wall segment is encroached
                tri = self.tri[s]
                enc = [(tri[(k + 1) % 3], tri[(k + 2) % 3])]
            else:
                # no point nearer a vertex than the shortest segment split (1000 tolerances):
                # the circumcentres of a regular polygon's slivers all meet at its centre, up
                # to rounding, and triangles that small defeat the tolerance tests.  The
                # triangle's own corners first (cheap), then the cavity's (p's nearest vertex)
                if self._near_vertex(s, cx, cy, 1e3 * self.tol):
                    continue
                enc, gap = self._cavity(s, cx, cy)
                if gap < 1e3 * self.tol:
                    continue
            if enc:
                # split the encroached walls instead, then try this triangle again (a few
                # times only: a wall too short to split would otherwise loop for ever)
                segq.extend(enc)
                retries[key] = retries.get(key, 0) + 1
                if retries[key] <= 3:
                    heapq.heappush(badq, (q, t, key))
                continue
            if not self._insert_point(s, cx, cy):
                continue
            budget -= 1
            ts, self.dirty = self.dirty, []
            scan(ts)
        return not segq and not any(tuple(self.tri[t]) == key for _, t, key in badq)

    def _scan_all(self, segq: list[tuple[int, int]], badq: list[tuple[float, int, tuple[int, ...]]],
                  sin_min: float, area_cap: float) -> None:
        """The refinement's first scan of every triangle: what ``scan`` does on them all, with
        numpy narrowing the scalar quality test to the triangles that may be bad."""
        x, y = np.asarray(self.x), np.asarray(self.y)
        tri, nbr = np.asarray(self.tri, dtype=np.int64), np.asarray(self.nbr, dtype=np.int64)
        bt, bk = np.nonzero(nbr < 0)
        a, b, c = tri[bt, bk], tri[bt, (bk + 1) % 3], tri[bt, (bk + 2) % 3]
        enc = (x[b] - x[a]) * (x[c] - x[a]) + (y[b] - y[a]) * (y[c] - y[a]) < 0.0  # _encroached
        maybe_bad = quality_candidates(x, y, tri, sin_min, area_cap)
        # scan's order: triangle by triangle, its encroached edges (k ascending), then its quality
        bad = np.flatnonzero(maybe_bad)
        tri_of = np.concatenate([bt[enc], bad])
        order = np.argsort(tri_of, kind="stable")
        seg_of = np.concatenate([np.column_stack([b[enc], c[enc]]), np.full((len(bad), 2), -1)])[order]
        for t, (seg_b, seg_c) in zip(tri_of[order].tolist(), seg_of.tolist()):
            if seg_b >= 0:
                segq.append((seg_b, seg_c))
                continue
            q = self._quality(t, sin_min, area_cap)
            if q < 1.0:
                heapq.heappush(badq, (q, t, tuple(self.tri[t])))

    def _insert_point(self, t: int, px: float, py: float) -> bool:
        """Insert p into t (or onto the edge of t it lies on); False, inserting nothing,
        when a triangle it would make is not counter-clockwise by :func:`_orient2` (p
        beyond an edge by the rounding of a sliver: the flips' tests would stop agreeing
        and the mesh could stop being a manifold)."""
        tri = self.tri[t]
        x, y = self.x, self.y
        for k in range(3):
            a, v1, v2 = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            el = math.hypot(x[v2] - x[v1], y[v2] - y[v1])
            if abs(_orient2(x[v1], y[v1], x[v2], y[v2], px, py)) <= self.tol * el:
                u = self.nbr[t][k]
                sides = [(a, v1), (v2, a)]
                if u >= 0:
                    d = self.tri[u][self.nbr[u].index(t)]
                    sides += [(d, v2), (v1, d)]
                if not all(_orient2(x[i], y[i], x[j], y[j], px, py) > 0.0 for i, j in sides):
                    return False
                self.insert_on_edge(t, k, px, py)
                return True
        a, b, c = tri
        if not all(_orient2(x[i], y[i], x[j], y[j], px, py) > 0.0 for i, j in ((a, b), (b, c), (c, a))):
            return False
        self.insert_in_triangle(t, px, py)
        return True

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        return np.column_stack([self.x, self.y]), np.asarray(self.tri, dtype=np.int64)

