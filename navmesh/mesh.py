"""Navigation mesh: conforming triangulation of the walkable polygon, point location, paths.

Conventions
-----------
* World coordinates: x to the right, y downwards (SPEC §8).  Orientation is always
  taken in the *coordinate* sense: a triangle ``(a, b, c)`` is stored with
  ``cross(b - a, c - a) > 0`` ("counter-clockwise" in the maths sense of the raw
  coordinates; on a y-down screen it appears clockwise).
* ``neighbors[t, k]`` is the triangle across the edge opposite vertex ``k`` of ``t``,
  i.e. across ``(triangles[t, k+1], triangles[t, k+2])`` (indices mod 3), or -1 on the
  boundary.  Neighbouring triangles share whole edges (same two vertex indices).

>>> from shapely import box
>>> mesh = NavMesh.build(box(0, 0, 10, 10).difference(box(4, 0, 6, 8)))
>>> mesh.locate(1.0, 1.0) >= 0, mesh.locate(5.0, 5.0)
(True, -1)
>>> path = mesh.find_path((1, 1), (9, 1))
>>> path.points.tolist(), round(path.length, 6)
([[1.0, 1.0], [4.0, 8.0], [6.0, 8.0], [9.0, 1.0]], 17.231546)
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import Polygon

from navmesh.errors import OutsideError
from navmesh.funnel import funnel
from navmesh.visibility import MeshSight, polygon_rings

__all__ = ["DEFAULT_MIN_ANGLE", "MAX_CORNERS", "METHODS", "NavMesh", "NavPath", "OutsideError"]

#: Triangulation methods accepted by :meth:`NavMesh.build`.
METHODS = ("refined", "cdt", "earcut")
#: Minimum angle (degrees) the default ``"refined"`` method asks for.
DEFAULT_MIN_ANGLE = 20.0
#: Above this many wall corners the exact-path tables are not built (A* + funnel instead).
MAX_CORNERS = 1000
_MAX_MIN_ANGLE = 34.0  # Ruppert's refinement is only guaranteed to stop below ~33.8 degrees


@dataclass
class NavPath:
    """A path: ``points`` (k, 2) from start to goal, both included; ``length`` of the polyline."""

    points: np.ndarray
    length: float


# ============================================================================ triangulation
def _triangulate_cdt(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Constrained Delaunay triangulation of the rings (GEOS, via shapely)."""
    poly = Polygon(rings[0], rings[1:])
    tris = shapely.constrained_delaunay_triangles(poly)
    coords = shapely.get_coordinates(shapely.get_exterior_ring(np.asarray(tris.geoms)))
    coords = coords.reshape(-1, 4, 2)[:, :3]
    verts = np.unique(np.concatenate(rings), axis=0)
    lookup = {(float(x), float(y)): i for i, (x, y) in enumerate(verts)}
    try:
        triangles = np.array([[lookup[(float(x), float(y))] for x, y in tri] for tri in coords], dtype=np.int64)
    except KeyError as exc:  # GEOS never adds points; be loud if it ever does
        raise RuntimeError(f"constrained Delaunay output has a vertex not in the input: {exc}") from None
    return verts, triangles.reshape(-1, 3)


def _triangulate_earcut(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Ear-clipping triangulation (mapbox-earcut bridges the holes itself)."""
    flat = np.concatenate(rings)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    idx = mapbox_earcut.triangulate_float64(flat, ends).astype(np.int64).reshape(-1, 3)
    verts, inv = np.unique(flat, axis=0, return_inverse=True)
    return verts, inv.ravel()[idx]


def _orient2(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z of the cross product of arrays of 2-D vectors."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _neighbors(triangles: np.ndarray) -> np.ndarray:
    """Neighbour across the edge opposite each vertex; raises if an edge has > 2 triangles."""
    t = len(triangles)
    a = triangles[:, [1, 2, 0]].ravel()  # edge opposite vertex k = (v[k+1], v[k+2])
    b = triangles[:, [2, 0, 1]].ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * (int(triangles.max()) + 1) + hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    nbr = np.full(3 * t, -1, dtype=np.int64)
    same = np.flatnonzero(ks[1:] == ks[:-1])
    if same.size and np.any(np.diff(same) == 1):
        raise ValueError("non-manifold triangulation: an edge is shared by more than two triangles")
    e1, e2 = order[same], order[same + 1]
    if np.any(a[e1] == a[e2]):
        raise ValueError("inconsistent triangle orientation: a shared edge runs the same way in both")
    nbr[e1] = e2 // 3
    nbr[e2] = e1 // 3
    return nbr.reshape(t, 3)


class _Refiner:
    """Mutable constrained triangulation: Lawson flips and Ruppert-style Steiner refinement.

    Boundary edges (no neighbour) are the constraints and are never flipped.  Every
    insertion splits whole triangles (a point on an edge splits both sides), so the
    result is conforming by construction.
    """

    def __init__(self, verts: np.ndarray, tris: np.ndarray, rings: list[np.ndarray], tol: float) -> None:
        self.x: list[float] = verts[:, 0].tolist()
        self.y: list[float] = verts[:, 1].tolist()
        self.tri: list[list[int]] = tris.tolist()
        self.nbr: list[list[int]] = _neighbors(tris).tolist()
        self.tol = tol
        self.dirty: list[int] = []
        self.n_input = len(verts)
        # input segments and the input angle at every input vertex (for the small-angle rule)
        lookup = {(float(x), float(y)): i for i, (x, y) in enumerate(verts)}
        self.small: set[int] = set()
        for ring in rings:
            ids = [lookup[(float(x), float(y))] for x, y in ring]
            for j, v in enumerate(ids):
                p, n = ids[j - 1], ids[(j + 1) % len(ids)]
                # walkable (interior) angle: counter-clockwise from the next to the previous vertex
                ux, uy = self.x[n] - self.x[v], self.y[n] - self.y[v]
                wx, wy = self.x[p] - self.x[v], self.y[p] - self.y[v]
                ang = math.atan2(ux * wy - uy * wx, ux * wx + uy * wy) % (2.0 * math.pi)
                if ang < math.radians(60.0):
                    self.small.add(v)
        self.on_seg: dict[int, tuple[int, int]] = {}  # Steiner vertex -> input segment end points
        self.bound: dict[tuple[int, int], int] = {}  # directed boundary edge -> triangle
        for t, (tri, nb) in enumerate(zip(self.tri, self.nbr)):
            for k in range(3):
                if nb[k] < 0:
                    self.bound[(tri[(k + 1) % 3], tri[(k + 2) % 3])] = t

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
        u = self.nbr[t][k]
        if u < 0:
            return False
        tri = self.tri[t]
        a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
        d = self.tri[u][self.nbr[u].index(t)]
        if self._incircle(a, b, c, d) <= 1e-12:
            return False
        return self._orient(a, b, d) > 0 and self._orient(a, d, c) > 0

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
        """Lawson flips until every interior edge is locally Delaunay (any triangulation -> CDT)."""
        stack = [(t, k) for t in range(len(self.tri)) for k in range(3)]
        while stack:
            t, k = stack.pop()
            if self._should_flip(t, k):
                u = self._flip(t, k)
                stack += ((t, 0), (t, 2), (u, 0), (u, 1))

    def _legalize_around(self, p: int, tris: list[int]) -> None:
        stack = list(tris)
        while stack:
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
        l0 = math.hypot(x[b] - x[c], y[b] - y[c])
        l1 = math.hypot(x[c] - x[a], y[c] - y[a])
        l2 = math.hypot(x[a] - x[b], y[a] - y[b])
        area2 = _orient2(x[a], y[a], x[b], y[b], x[c], y[c])
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

    def _walk(self, t: int, px: float, py: float) -> tuple[int, int]:
        """Walk from t towards p: (triangle, -1) containing p, or (triangle, k) blocked by boundary edge k."""
        x, y = self.x, self.y
        a, b, c = self.tri[t]
        ox, oy = (x[a] + x[b] + x[c]) / 3.0, (y[a] + y[b] + y[c]) / 3.0
        eps = self.tol * self.tol
        for _ in range(4 * len(self.tri) + 10):
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

    def _cavity_segments(self, t: int, px: float, py: float) -> list[tuple[int, int]]:
        """Boundary edges of the triangles whose circumcircle holds p (those p may encroach)."""
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
        return out

    def refine(self, min_angle: float | None, max_area: float | None, max_steiner: int) -> None:
        """Ruppert's algorithm: split encroached segments, insert circumcentres of bad triangles."""
        sin_min = math.sin(math.radians(min_angle)) if min_angle else 0.0
        area_cap = max_area if max_area else 0.0
        self.legalize_all()
        segq: list[tuple[int, int]] = []
        badq: list[tuple[float, int, tuple[int, ...]]] = []

        def scan(ts: list[int]) -> None:
            for t in dict.fromkeys(ts):
                tri, nb = self.tri[t], self.nbr[t]
                for k in range(3):
                    if nb[k] < 0 and self._encroached(t, k):
                        segq.append((tri[(k + 1) % 3], tri[(k + 2) % 3]))
                q = self._quality(t, sin_min, area_cap)
                if q < 1.0:
                    heapq.heappush(badq, (q, t, tuple(tri)))

        scan(list(range(len(self.tri))))
        self.dirty = []
        budget = max_steiner
        retries: dict[tuple[int, ...], int] = {}
        steps = 0
        while budget > 0 and (segq or badq) and steps < 50 * max_steiner:
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
                enc = self._cavity_segments(s, cx, cy)
            if enc:
                # split the encroached walls instead, then try this triangle again (a few
                # times only: a wall too short to split would otherwise loop for ever)
                segq.extend(enc)
                retries[key] = retries.get(key, 0) + 1
                if retries[key] <= 3:
                    heapq.heappush(badq, (q, t, key))
                continue
            self._insert_point(s, cx, cy)
            budget -= 1
            ts, self.dirty = self.dirty, []
            scan(ts)

    def _insert_point(self, t: int, px: float, py: float) -> None:
        tri = self.tri[t]
        x, y = self.x, self.y
        for k in range(3):
            v1, v2 = tri[(k + 1) % 3], tri[(k + 2) % 3]
            el = math.hypot(x[v2] - x[v1], y[v2] - y[v1])
            if abs(_orient2(x[v1], y[v1], x[v2], y[v2], px, py)) <= self.tol * el:
                self.insert_on_edge(t, k, px, py)
                return
        self.insert_in_triangle(t, px, py)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        return np.column_stack([self.x, self.y]), np.asarray(self.tri, dtype=np.int64)


def _angle(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    """Angle at a between rays a→b and a→c, in [0, π]."""
    ux, uy, vx, vy = bx - ax, by - ay, cx - ax, cy - ay
    return abs(math.atan2(ux * vy - uy * vx, ux * vx + uy * vy))


def _circumcentre(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> tuple[float, float]:
    bx, by, cx, cy = bx - ax, by - ay, cx - ax, cy - ay
    d = 2.0 * (bx * cy - by * cx)
    if d == 0.0:
        return math.nan, math.nan
    b2, c2 = bx * bx + by * by, cx * cx + cy * cy
    return ax + (cy * b2 - by * c2) / d, ay + (bx * c2 - cx * b2) / d


def _orient_ccw(verts: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Counter-clockwise triangles; zero-area ones follow the triangulator's own orientation."""
    p0, p1, p2 = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    area2 = _cross2(p1 - p0, p2 - p0)
    if area2.sum() < 0:
        tris, area2 = tris[:, [0, 2, 1]], -area2
    return np.where((area2 < 0)[:, None], tris[:, [0, 2, 1]], tris)


def _split_t_junctions(verts: np.ndarray, tris: np.ndarray, walls: set[tuple[int, int]], tol: float) -> np.ndarray:
    """Make the triangulation conforming: split any triangle with a vertex inside one of its edges.

    Ear clipping with collinear polygon vertices can leave a vertex in the middle of a
    diagonal (a T-junction).  Such a diagonal shows up as an edge without a neighbour
    that is not a wall; splitting its triangle at the vertex restores whole-edge sharing.
    """
    for _ in range(len(verts) + 1):
        nbr = _neighbors(tris)
        t_idx, k_idx = np.nonzero(nbr < 0)
        a = tris[t_idx, (k_idx + 1) % 3]
        b = tris[t_idx, (k_idx + 2) % 3]
        loose = np.array([(min(p, q), max(p, q)) not in walls for p, q in zip(a.tolist(), b.tolist())], dtype=bool)
        if not loose.any():
            return tris
        t_idx, k_idx, a, b = t_idx[loose], k_idx[loose], a[loose], b[loose]
        cand = np.unique(np.concatenate([a, b]))
        pa, pb, pc = verts[a], verts[b], verts[cand]
        e = pb - pa
        le = np.hypot(*e.T)
        rel = pc[None, :, :] - pa[:, None, :]
        along = (rel[..., 0] * e[:, None, 0] + rel[..., 1] * e[:, None, 1]) / le[:, None]
        off = np.abs(rel[..., 1] * e[:, None, 0] - rel[..., 0] * e[:, None, 1]) / le[:, None]
        hit = (off <= tol) & (along > tol) & (along < le[:, None] - tol)
        rows, cols = np.nonzero(hit)
        if rows.size == 0:
            raise ValueError("triangulation is not conforming: an edge has no neighbour and is not a wall")
        new = tris.tolist()
        done: set[int] = set()
        for r, c in zip(rows.tolist(), cols.tolist()):
            t, k, w = int(t_idx[r]), int(k_idx[r]), int(cand[c])
            if t in done:
                continue
            done.add(t)
            o, p, q = new[t][k], new[t][(k + 1) % 3], new[t][(k + 2) % 3]
            new[t] = [o, p, w]
            new.append([o, w, q])
        tris = np.asarray(new, dtype=np.int64)
    raise RuntimeError("could not remove T-junctions")


def _fix_degenerate(verts: np.ndarray, tris: np.ndarray, tol: float) -> np.ndarray:
    """Remove zero-area triangles by flipping their long edge (earcut can emit them)."""
    tris = _orient_ccw(verts, tris)
    ref = _Refiner.__new__(_Refiner)
    ref.x, ref.y = verts[:, 0].tolist(), verts[:, 1].tolist()
    ref.tri, ref.nbr = tris.tolist(), _neighbors(tris).tolist()
    ref.tol, ref.dirty, ref.bound = tol, [], {}

    def flat(t: int) -> bool:
        a, b, c = ref.tri[t]
        longest = max(math.hypot(ref.x[q] - ref.x[r], ref.y[q] - ref.y[r]) for q, r in ((b, c), (c, a), (a, b)))
        return ref._orient(a, b, c) <= tol * longest

    for _ in range(len(tris) + 1):
        bad = next((t for t in range(len(ref.tri)) if flat(t)), None)
        if bad is None:
            break
        a, b, c = ref.tri[bad]
        # the vertex lying between the other two is opposite the long edge: flip that edge
        lens = [math.hypot(ref.x[q] - ref.x[r], ref.y[q] - ref.y[r]) for q, r in ((b, c), (c, a), (a, b))]
        k = int(np.argmax(lens))
        if ref.nbr[bad][k] < 0:
            raise ValueError("degenerate triangle on the boundary: a vertex lies on a wall")
        ref._flip(bad, k)
    return _orient_ccw(verts, np.asarray(ref.tri, dtype=np.int64))


# ============================================================================== the mesh
class NavMesh:
    """A conforming triangle mesh of the walkable area with point location and paths.

    Build one with :meth:`NavMesh.build`; the constructor takes ready arrays.
    Attributes (numpy, read-only by convention): ``vertices (V, 2) float64``,
    ``triangles (T, 3) int64`` (counter-clockwise in the coordinate sense),
    ``neighbors (T, 3) int64``, ``centroids (T, 2)``, ``areas (T,)``,
    ``boundary_vertex (V,) bool`` (vertex lies on a wall).
    """

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray) -> None:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        t = np.ascontiguousarray(triangles, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 2 or t.ndim != 2 or t.shape[1] != 3 or len(t) == 0:
            raise ValueError("expected vertices (V, 2) and a non-empty triangles (T, 3)")
        if t.min() < 0 or t.max() >= len(v):
            raise ValueError("triangle vertex index out of range")
        p0, p1, p2 = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        area2 = _cross2(p1 - p0, p2 - p0)
        if np.any(area2 == 0.0):
            raise ValueError("degenerate (zero-area) triangle")
        t = np.where((area2 < 0)[:, None], t[:, [0, 2, 1]], t)
        self.vertices = v
        self.triangles = t
        self.neighbors = _neighbors(t)
        self.centroids = (v[t[:, 0]] + v[t[:, 1]] + v[t[:, 2]]) / 3.0
        self.areas = 0.5 * np.abs(area2)
        lo, hi = v.min(axis=0), v.max(axis=0)
        self._tol = 1e-9 * max(1.0, float(np.max(hi - lo)))
        bv = np.zeros(len(v), dtype=bool)
        wt, wk = np.nonzero(self.neighbors < 0)
        bv[t[wt, (wk + 1) % 3]] = True
        bv[t[wt, (wk + 2) % 3]] = True
        self.boundary_vertex = bv
        self._build_locator(lo, hi)
        self._build_tables()
        self._sight: MeshSight | None = None
        self._sight_tried = False  # tables are built on the first exact query

    # ---------------------------------------------------------------- building
    @classmethod
    def build(
        cls,
        polygon: Polygon,
        *,
        max_area: float | None = None,
        min_angle: float | None = None,
        method: str = "refined",
    ) -> NavMesh:
        """Triangulate a shapely polygon (with holes) into a conforming mesh.

        ``method``: ``"refined"`` (default) — constrained Delaunay plus Steiner points until
        every angle is ≥ ``min_angle`` (default 20°) and every area ≤ ``max_area``;
        ``"cdt"`` — GEOS constrained Delaunay, polygon vertices only; ``"earcut"`` —
        mapbox-earcut, polygon vertices only.  Giving ``min_angle`` or ``max_area`` with
        ``"cdt"``/``"earcut"`` refines that triangulation the same way (earcut's is first
        flipped to constrained Delaunay).  ``min_angle`` must be in (0, 34].

        >>> from shapely import box
        >>> len(NavMesh.build(box(0, 0, 4, 3), method="cdt"))
        2
        """
        if method not in METHODS:
            raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
        if min_angle is not None and not 0.0 < min_angle <= _MAX_MIN_ANGLE:
            raise ValueError(f"min_angle must be in (0, {_MAX_MIN_ANGLE}] degrees, got {min_angle}")
        if max_area is not None and not (math.isfinite(max_area) and max_area > 0.0):
            raise ValueError(f"max_area must be a positive number, got {max_area}")
        if not isinstance(polygon, Polygon):
            raise TypeError(f"expected a shapely Polygon, got {type(polygon).__name__}")
        minx, miny, maxx, maxy = polygon.bounds
        tol = 1e-9 * max(1.0, maxx - minx, maxy - miny)
        rings = polygon_rings(polygon, tol)
        if method == "earcut":
            verts, tris = _triangulate_earcut(rings)
        else:
            verts, tris = _triangulate_cdt(rings)
        lookup = {(float(x), float(y)): i for i, (x, y) in enumerate(verts)}
        walls: set[tuple[int, int]] = set()
        for ring in rings:
            ids = [lookup[(float(x), float(y))] for x, y in ring]
            walls.update((min(p, q), max(p, q)) for p, q in zip(ids, ids[1:] + ids[:1]))
        tris = _fix_degenerate(verts, _orient_ccw(verts, tris), tol)
        tris = _split_t_junctions(verts, tris, walls, tol)
        if method == "refined" and min_angle is None:
            min_angle = DEFAULT_MIN_ANGLE
        if min_angle is not None or max_area is not None:
            ref = _Refiner(verts, tris, rings, tol)
            budget = 20 * len(verts) + 2000
            if max_area:
                budget += int(4 * polygon.area / max_area)
            ref.refine(min_angle, max_area, budget)
            verts, tris = ref.arrays()
        return cls(verts, tris)

    def _build_locator(self, lo: np.ndarray, hi: np.ndarray) -> None:
        """Bucket grid over triangle bounding boxes (about one cell per triangle)."""
        t, v = self.triangles, self.vertices
        span = np.maximum(hi - lo, 1e-12)
        cell = math.sqrt(float(span[0] * span[1]) / len(t))
        nx = max(1, min(2048, math.ceil(span[0] / cell)))
        ny = max(1, min(2048, math.ceil(span[1] / cell)))
        scale = np.array([nx / span[0], ny / span[1]])
        self._grid = (float(lo[0]), float(lo[1]), float(scale[0]), float(scale[1]), nx, ny)
        tv = v[t]
        bmin = np.floor((tv.min(axis=1) - lo - self._tol) * scale).astype(np.int64)
        bmax = np.floor((tv.max(axis=1) - lo + self._tol) * scale).astype(np.int64)
        bmin = np.clip(bmin, 0, [nx - 1, ny - 1])
        bmax = np.clip(bmax, 0, [nx - 1, ny - 1])
        cells: list[list[int]] = [[] for _ in range(nx * ny)]
        for i, (x0, y0, x1, y1) in enumerate(np.column_stack([bmin, bmax]).tolist()):
            for cy in range(y0, y1 + 1):
                row = cy * nx
                for cx in range(x0, x1 + 1):
                    cells[row + cx].append(i)
        self._cells = [tuple(c) for c in cells]
        counts = np.array([len(c) for c in cells], dtype=np.int64)
        self._cell_start = np.concatenate(([0], np.cumsum(counts)))
        self._cell_items = np.array([i for c in cells for i in c], dtype=np.int64)
        # edge functions n·p + c >= 0 inside, with unit normals (so tolerances are distances)
        a, b, c = tv[:, 0], tv[:, 1], tv[:, 2]
        eq = []
        for p, q in ((b, c), (c, a), (a, b)):
            e = q - p
            le = np.hypot(*e.T)
            nxv, nyv = -e[:, 1] / le, e[:, 0] / le  # left normal: the inside of a CCW triangle
            eq.append(np.column_stack([nxv, nyv, -(nxv * p[:, 0] + nyv * p[:, 1])]))
        self._edge_eq = np.stack(eq, axis=1)  # (T, 3 edges, 3 coefficients)
        self._edge_py = [tuple(row) for row in self._edge_eq.reshape(len(t), 9).tolist()]

    def _build_tables(self) -> None:
        """Python-level tables for the per-query search (lists beat numpy for scalar access)."""
        v, t, nb = self.vertices, self.triangles, self.neighbors
        self._nb = [tuple(r) for r in nb.tolist()]
        xs, ys = v[:, 0].tolist(), v[:, 1].tolist()
        tl = t.tolist()
        self._tri_list = tl
        # portal across edge k, seen leaving the triangle: right = v[k+1], left = v[k+2]
        self._portal = [
            tuple((xs[tr[(k + 1) % 3]], ys[tr[(k + 1) % 3]], xs[tr[(k + 2) % 3]], ys[tr[(k + 2) % 3]]) for k in range(3))
            for tr in tl
        ]
        self._portal_ids = [tuple((tr[(k + 1) % 3], tr[(k + 2) % 3]) for k in range(3)) for tr in tl]
        self._fans: dict[int, list[int]] | None = None
        self._pinch = self._pinch_points()

    def _pinch_points(self) -> dict[int, list[int]]:
        """Vertices where walls touch (several walkable sectors): one triangle per sector."""
        tl, nb = self._tri_list, self._nb
        parent = list(range(3 * len(tl)))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for t, tri in enumerate(tl):
            for k in range(3):
                u = nb[t][(k + 1) % 3]  # across edge (v[k+2], v[k]): also holds vertex v[k]
                if u >= 0:
                    a, b = find(3 * t + k), find(3 * u + tl[u].index(tri[k]))
                    if a != b:
                        parent[a] = b
        sectors: dict[int, dict[int, int]] = {}
        for t, tri in enumerate(tl):
            for k in range(3):
                sectors.setdefault(tri[k], {}).setdefault(find(3 * t + k), t)
        return {v: list(reps.values()) for v, reps in sectors.items() if len(reps) > 1}

    def _sectors_at(self, t: int, x: float, y: float) -> list[int]:
        """[t], or one triangle per sector if (x, y) is a pinch vertex of t."""
        if self._pinch:
            v = self.vertices
            for w in self._tri_list[t]:
                if w in self._pinch and abs(v[w, 0] - x) <= self._tol and abs(v[w, 1] - y) <= self._tol:
                    return self._pinch[w]
        return [t]

    def _sight_tables(self) -> MeshSight | None:
        """The exact-path tables, built on first use (None when the level has too many corners)."""
        if not self._sight_tried:
            self._sight_tried = True
            try:
                self._sight = MeshSight(self.vertices, self.triangles, self.neighbors, self._tol, max_nodes=MAX_CORNERS)
            except OverflowError:
                self._sight = None
        return self._sight

    # ---------------------------------------------------------------- queries
    def __len__(self) -> int:
        return len(self.triangles)

    def triangle_contains(self, t: int, x: float, y: float) -> bool:
        """Whether triangle ``t`` contains (x, y) (boundary included): a walker's fast path."""
        a0, a1, a2, b0, b1, b2, c0, c1, c2 = self._edge_py[t]
        eps = -self._tol
        return a0 * x + a1 * y + a2 >= eps and b0 * x + b1 * y + b2 >= eps and c0 * x + c1 * y + c2 >= eps

    def locate(self, x: float, y: float) -> int:
        """Index of the triangle containing (x, y), or -1 outside (boundary points are inside).

        A point on an edge shared by two triangles may return either of them.
        """
        x0, y0, sx, sy, nx, ny = self._grid
        fx, fy = (x - x0) * sx, (y - y0) * sy
        if not (-0.5 <= fx <= nx + 0.5 and -0.5 <= fy <= ny + 0.5):  # also rejects NaN
            return -1
        i = min(max(int(fx), 0), nx - 1)
        j = min(max(int(fy), 0), ny - 1)
        eps = -self._tol
        eqs = self._edge_py
        for t in self._cells[j * nx + i]:
            a0, a1, a2, b0, b1, b2, c0, c1, c2 = eqs[t]
            if a0 * x + a1 * y + a2 >= eps and b0 * x + b1 * y + b2 >= eps and c0 * x + c1 * y + c2 >= eps:
                return t
        return -1

    def locate_many(self, points: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`locate` for points (n, 2); -1 where outside."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        x0, y0, sx, sy, nx, ny = self._grid
        with np.errstate(invalid="ignore"):
            fx, fy = (p[:, 0] - x0) * sx, (p[:, 1] - y0) * sy
            near = (fx >= -0.5) & (fx <= nx + 0.5) & (fy >= -0.5) & (fy <= ny + 0.5)
        i = np.clip(np.where(near, fx, 0).astype(np.int64), 0, nx - 1)
        j = np.clip(np.where(near, fy, 0).astype(np.int64), 0, ny - 1)
        cell = j * nx + i
        start = self._cell_start[cell]
        count = np.where(near, self._cell_start[cell + 1] - start, 0)
        out = np.full(len(p), -1, dtype=np.int64)
        todo = np.flatnonzero(count > 0)
        k = 0
        while todo.size:
            cand = self._cell_items[start[todo] + k]
            eq = self._edge_eq[cand]  # (m, 3, 3)
            val = eq[..., 0] * p[todo, 0, None] + eq[..., 1] * p[todo, 1, None] + eq[..., 2]
            hit = np.all(val >= -self._tol, axis=1)
            out[todo[hit]] = cand[hit]
            k += 1
            todo = todo[~hit & (count[todo] > k)]
        return out

    def adjacency(self) -> tuple[np.ndarray, ...]:
        """For each triangle, the indices of its neighbouring triangles (ascending)."""
        return tuple(np.sort(row[row >= 0]) for row in self.neighbors)

    def shared_edge(self, t: int, u: int) -> np.ndarray:
        """The portal between neighbouring triangles t and u, as (2, 2) end points.

        The edge as it runs in t's counter-clockwise order: walking from t into u,
        ``edge[0]`` is on the right and ``edge[1]`` on the left (coordinate sense).
        Raises ``ValueError`` if t and u are not neighbours.
        """
        hits = np.flatnonzero(self.neighbors[t] == u)
        if u < 0 or hits.size == 0:
            raise ValueError(f"triangles {t} and {u} are not neighbours")
        k = int(hits[0])
        tri = self.triangles[t]
        return self.vertices[[tri[(k + 1) % 3], tri[(k + 2) % 3]]].copy()

    # ------------------------------------------------------------------ paths
    def _ends(
        self, start: tuple[float, float], goal: tuple[float, float]
    ) -> tuple[float, float, float, float, list[int], list[int]]:
        """Coordinates and the triangles holding start and goal (one per sector at a pinch)."""
        sx, sy = float(start[0]), float(start[1])
        gx, gy = float(goal[0]), float(goal[1])
        ts = self.locate(sx, sy)
        if ts < 0:
            raise OutsideError(f"point ({sx}, {sy}) is outside the walkable area")
        tg = self.locate(gx, gy)
        if tg < 0:
            raise OutsideError(f"point ({gx}, {gy}) is outside the walkable area")
        return sx, sy, gx, gy, self._sectors_at(ts, sx, sy), self._sectors_at(tg, gx, gy)

    def find_path(self, start: tuple[float, float], goal: tuple[float, float], *, exact: bool = True) -> NavPath:
        """Shortest walkable path from ``start`` to ``goal``, both included.

        ``exact=True`` (default): the corridor is the one the true Euclidean shortest path
        runs through, chosen with the precomputed corner-visibility tables (see
        ``docs/navmesh.md``); the path is the funnel path of that corridor.  ``exact=False``
        (also the fallback on levels with more than ``MAX_CORNERS`` wall corners): A* over
        the triangles with costs through the portal entry points, then the funnel.
        Raises :class:`OutsideError` if either point lies outside the walkable area.
        """
        sx, sy, gx, gy, ts, tg = self._ends(start, goal)
        if ts[0] == tg[0]:
            return _navpath([(sx, sy), (gx, gy)])
        sight = self._sight_tables() if exact else None
        if sight is not None:
            return _navpath(self._exact_points(sight, ts, sx, sy, tg, gx, gy))
        return _navpath(self._astar_path(ts, sx, sy, tg, gx, gy)[0])

    def corridor(self, start: tuple[float, float], goal: tuple[float, float], *, exact: bool = True) -> list[int]:
        """Triangles, from start's to goal's, of the corridor :meth:`find_path` pulls its path through.

        Pulling the funnel (:func:`navmesh.funnel.funnel`) through the portals of this
        corridor gives the :meth:`find_path` path.
        """
        sx, sy, gx, gy, ts, tg = self._ends(start, goal)
        if ts[0] == tg[0]:
            return [ts[0]]
        sight = self._sight_tables() if exact else None
        if sight is not None:
            pts = self._exact_points(sight, ts, sx, sy, tg, gx, gy)
            return sight.corridor_of(ts, pts)
        return self._astar_path(ts, sx, sy, tg, gx, gy)[1]

    def _astar_path(
        self, ts: list[int], sx: float, sy: float, tg: list[int], gx: float, gy: float
    ) -> tuple[list[tuple[float, float]], list[int]]:
        """A* corridor + funnel, searched from both ends when the path bends; the shorter wins.

        Each direction's entry-point costs are biased differently, so the two searches
        rarely pick the same wrong side of an obstacle.
        """
        corridor = self._astar(ts, tg, sx, sy, gx, gy)
        if corridor is None:
            raise ValueError(f"no path from ({sx}, {sy}) to ({gx}, {gy})")
        pts, corridor = self._pull(corridor, sx, sy, gx, gy)
        if len(pts) > 2:
            back = self._astar(tg, ts, gx, gy, sx, sy)
            if back is not None and back[::-1] != corridor:
                pts2, corridor2 = self._pull(back[::-1], sx, sy, gx, gy)
                if _polyline_length(pts2) < _polyline_length(pts):
                    pts, corridor = pts2, corridor2
        return pts, corridor

    def _exact_points(
        self, sight: MeshSight, ts: list[int], sx: float, sy: float, tg: list[int], gx: float, gy: float
    ) -> list[tuple[float, float]]:
        if any(sight.walk(t, sx, sy, gx, gy) >= 0 for t in ts):
            return [(sx, sy), (gx, gy)]
        chain, length = sight.corner_path(ts, sx, sy, tg, gx, gy)
        if not math.isfinite(length):
            raise ValueError(f"no path from ({sx}, {sy}) to ({gx}, {gy})")
        xs, ys = sight.nodes_x, sight.nodes_y
        return _drop_straight_points([(sx, sy)] + [(xs[c], ys[c]) for c in chain] + [(gx, gy)], self._tol)

    def _astar(self, ts: list[int], tg: list[int], sx: float, sy: float, gx: float, gy: float) -> list[int] | None:
        """A* over triangles; the cost runs through the actual entry point on each portal.

        Entering a triangle across portal (a, b) from point p, the entry point is the point
        of the portal minimising |p q| + |q goal| (where the straight line to the goal
        crosses the portal, else towards the goal's mirror image, clamped to the portal),
        so g is the length of a real polyline through the corridor.
        """
        nb, portal = self._nb, self._portal
        n = len(nb)
        hyp = math.hypot
        best = [math.inf] * n
        parent = [-1] * n
        closed = bytearray(n)
        h0 = hyp(gx - sx, gy - sy)
        heap = [(h0, t, sx, sy, 0.0) for t in ts]
        for t in ts:
            best[t] = 0.0
        goals = set(tg)
        pop, push = heapq.heappop, heapq.heappush
        while heap:
            _f, t, px, py, g = pop(heap)
            if closed[t]:
                continue
            if t in goals:
                out = [t]
                while parent[t] >= 0:
                    t = parent[t]
                    out.append(t)
                out.reverse()
                return out
            closed[t] = 1
            nbt, pt = nb[t], portal[t]
            for k in (0, 1, 2):
                u = nbt[k]
                if u < 0 or closed[u]:
                    continue
                ax, ay, bx, by = pt[k]
                ex, ey = bx - ax, by - ay
                ee = ex * ex + ey * ey
                cp = ex * (py - ay) - ey * (px - ax)
                cg = ex * (gy - ay) - ey * (gx - ax)
                if cp * cg > 0.0:  # goal on the near side: aim at its mirror image
                    f = 2.0 * cg / ee
                    hx, hy = gx + f * ey, gy - f * ex
                else:
                    hx, hy = gx, gy
                wx, wy = hx - px, hy - py
                den = wx * ey - wy * ex
                if den != 0.0 and cp != 0.0:
                    lam = (wx * (py - ay) - wy * (px - ax)) / den
                else:
                    lam = ((px - ax) * ex + (py - ay) * ey) / ee
                lam = 0.0 if lam < 0.0 else (min(lam, 1.0))
                qx, qy = ax + lam * ex, ay + lam * ey
                ng = g + hyp(qx - px, qy - py)
                if ng < best[u]:
                    best[u] = ng
                    parent[u] = t
                    push(heap, (ng + hyp(gx - qx, gy - qy), u, qx, qy, ng))
        return None

    def _portals(self, corridor: list[int]) -> tuple[list, list, list, list]:
        nb, portal, pid = self._nb, self._portal, self._portal_ids
        rights, lefts, rid, lid = [], [], [], []
        for t, u in itertools.pairwise(corridor):
            k = nb[t].index(u)
            ax, ay, bx, by = portal[t][k]
            rights.append((ax, ay))
            lefts.append((bx, by))
            r, lft = pid[t][k]
            rid.append(r)
            lid.append(lft)
        return rights, lefts, rid, lid

    def _pull(
        self, corridor: list[int], sx: float, sy: float, gx: float, gy: float
    ) -> tuple[list[tuple[float, float]], list[int]]:
        """Funnel through the corridor; re-route around interior (Steiner) corners.

        A taut path only bends at wall corners.  If the funnel bends at an interior vertex,
        the corridor passes it on the wrong side: swap that stretch for the other half of
        the vertex's triangle fan (same homotopy, strictly shorter) and pull again.
        """
        bv = self.boundary_vertex
        for _ in range(64):
            rights, lefts, rid, lid = self._portals(corridor)
            pts, corners = funnel((sx, sy), (gx, gy), rights, lefts, rid, lid)
            inner = next(((w, i) for w, i in corners if w >= 0 and not bv[w]), None)
            if inner is None:
                break
            corridor = self._reroute(corridor, inner[0], inner[1], rid, lid)
        return pts, corridor

    def _fan(self, w: int) -> list[int]:
        """Triangles around interior vertex w, in counter-clockwise order."""
        if self._fans is None:
            fans: dict[int, list[int]] = {}
            for t, tri in enumerate(self._tri_list):
                for v in tri:
                    fans.setdefault(v, []).append(t)
            self._fans = fans
        around = self._fans[w]
        order = [around[0]]
        while len(order) < len(around):
            t = order[-1]
            k = self._tri_list[t].index(w)
            nxt = self._nb[t][(k + 1) % 3]  # across edge (v[k+2], w): next counter-clockwise
            if nxt < 0 or nxt == order[0]:
                break
            order.append(nxt)
        return order

    def _reroute(self, corridor: list[int], w: int, portal_i: int, rid: list[int], lid: list[int]) -> list[int]:
        """Replace the corridor stretch around interior vertex w by the other side of w's fan."""
        side = rid if rid[portal_i] == w else lid
        i = j = portal_i
        while i > 0 and side[i - 1] == w:
            i -= 1
        while j + 1 < len(side) and side[j + 1] == w:
            j += 1
        first, last = corridor[i], corridor[j + 1]  # portal p joins corridor[p] and corridor[p+1]
        fan = self._fan(w)
        n = len(fan)
        a = fan.index(first)
        step = 1 if fan[(a + 1) % n] == corridor[i + 1] else -1
        arc = [fan[a]]
        pos = a
        while fan[pos] != last:
            pos = (pos - step) % n
            arc.append(fan[pos])
        return _drop_loops(corridor[:i] + arc + corridor[j + 2 :])

    # ----------------------------------------------------------------- export
    def export(self, path: str | Path) -> None:
        """Write the mesh (z = 0) as OBJ, PLY or GLB, chosen by the file suffix (via trimesh)."""
        path = Path(path)
        if path.suffix.lower() not in (".obj", ".ply", ".glb"):
            raise ValueError(f"{path}: unsupported format {path.suffix!r}; use .obj, .ply or .glb")
        import trimesh  # heavy import (~0.6 s): only when exporting

        v3 = np.column_stack([self.vertices, np.zeros(len(self.vertices))])
        trimesh.Trimesh(vertices=v3, faces=self.triangles, process=False).export(path)


def _polyline_length(points: list[tuple[float, float]]) -> float:
    length = 0.0
    for (ax, ay), (bx, by) in itertools.pairwise(points):
        length += math.hypot(bx - ax, by - ay)
    return length


def _navpath(points: list[tuple[float, float]]) -> NavPath:
    return NavPath(np.array(points, dtype=np.float64), _polyline_length(points))


def _drop_straight_points(points: list[tuple[float, float]], tol: float) -> list[tuple[float, float]]:
    """Remove repeated points and inner points where the path goes straight on."""
    out = [points[0]]
    for i in range(1, len(points) - 1):
        (ax, ay), (bx, by), (cx, cy) = out[-1], points[i], points[i + 1]
        ux, uy, vx, vy = bx - ax, by - ay, cx - bx, cy - by
        lu, lv = math.hypot(ux, uy), math.hypot(vx, vy)
        if lu <= tol or lv <= tol:
            continue
        if abs(ux * vy - uy * vx) <= tol * max(lu, lv) and ux * vx + uy * vy > 0.0:
            continue
        out.append(points[i])
    out.append(points[-1])
    return out


def _drop_loops(corridor: list[int]) -> list[int]:
    """Cut out the loop between two visits of the same triangle."""
    seen: dict[int, int] = {}
    out: list[int] = []
    for t in corridor:
        if t in seen:
            del out[seen[t] + 1 :]
            seen = {u: k for k, u in enumerate(out)}
        else:
            seen[t] = len(out)
            out.append(t)
    return out
