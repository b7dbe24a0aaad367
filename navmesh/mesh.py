"""Navigation mesh: the triangle arrays of the walkable area, point location and export.

The mesh is plain arrays plus a bucket-grid locator.  Building it (:meth:`NavMesh.build`)
runs the pipeline of :mod:`navmesh.rings` → :mod:`navmesh.triangulate` →
:mod:`navmesh.refine`.  Path queries are another object, made from a built mesh
(:func:`navmesh.query.path_query`, as Detour's ``dtNavMeshQuery`` is made from a
``dtNavMesh``): this module imports nothing of :mod:`navmesh.query`.

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
"""

from __future__ import annotations

import gc
import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from shapely.geometry import Polygon

from navmesh.degenerate import fix_degenerate
from navmesh.refine import Refiner
from navmesh.rings import polygon_rings
from navmesh.triangulate import (
    cross2,
    edge_neighbors,
    orient_ccw,
    split_t_junctions,
    triangulate_cdt,
    triangulate_earcut,
    wall_edges,
)

__all__ = ["DEFAULT_MIN_ANGLE", "MAX_REFINE_WORK", "MAX_STEINER", "METHODS", "NavMesh"]

#: Triangulation methods accepted by :meth:`NavMesh.build`.
METHODS = ("refined", "cdt", "earcut")
#: Minimum angle (degrees) the default ``"refined"`` method asks for.
DEFAULT_MIN_ANGLE = 20.0
#: The refinement's budgets (``docs/navmesh.md``): at most this many Steiner points and
#: :attr:`~navmesh.refine.Refiner.work` steps (walk steps, cavity triangles, flip tests),
#: about 10 s.  A 1000×1000-cell building needs 9 × 10^4 points and 7 × 10^5 steps; a
#: regular polygon of 10^5 corners (all its slivers' circumcentres at its centre) would
#: need millions of points, each insertion visiting thousands of triangles.
MAX_STEINER = 100_000
MAX_REFINE_WORK = 1_500_000
_MAX_MIN_ANGLE = 34.0  # Ruppert's refinement is only guaranteed to stop below ~33.8 degrees


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while a mesh is built, back on (if it was) after.

    The build makes no reference cycles, but the refinement's 10^5 small lists and tuples
    set off collector passes that each walk every live object: ~1 s of a 10^6-cell build.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


class NavMesh:
    """A conforming triangle mesh of the walkable area with point location.

    Build one with :meth:`NavMesh.build`; the constructor takes ready arrays.
    Attributes (numpy, read-only by convention): ``vertices (V, 2) float64``,
    ``triangles (T, 3) int64`` (counter-clockwise in the coordinate sense),
    ``neighbors (T, 3) int64``, ``centroids (T, 2)``, ``areas (T,)``,
    ``boundary_vertex (V,) bool`` (vertex lies on a wall); ``tol``, the distance
    tolerance (1e-9 × the extent).
    """

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray) -> None:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        t = np.ascontiguousarray(triangles, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 2 or t.ndim != 2 or t.shape[1] != 3 or len(t) == 0:
            raise ValueError("expected vertices (V, 2) and a non-empty triangles (T, 3)")
        if t.min() < 0 or t.max() >= len(v):
            raise ValueError("triangle vertex index out of range")
        p0, p1, p2 = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        area2 = cross2(p1 - p0, p2 - p0)
        if np.any(area2 == 0.0):
            raise ValueError("degenerate (zero-area) triangle")
        t = np.where((area2 < 0)[:, None], t[:, [0, 2, 1]], t)
        self.vertices = v
        self.triangles = t
        self.neighbors = edge_neighbors(t)
        self.centroids = (v[t[:, 0]] + v[t[:, 1]] + v[t[:, 2]]) / 3.0
        self.areas = 0.5 * np.abs(area2)
        lo, hi = v.min(axis=0), v.max(axis=0)
        self.tol = 1e-9 * max(1.0, float(np.max(hi - lo)))
        bv = np.zeros(len(v), dtype=bool)
        wt, wk = np.nonzero(self.neighbors < 0)
        bv[t[wt, (wk + 1) % 3]] = True
        bv[t[wt, (wk + 2) % 3]] = True
        self.boundary_vertex = bv
        #: True when the refinement's budget (:data:`MAX_STEINER`) stopped it with triangles
        #: below ``min_angle`` (or above ``max_area``) left: a conforming mesh all the same
        self.refinement_stopped = False
        #: objects built from this mesh and kept while it lives, by their type (the path
        #: query of :func:`navmesh.query.path_query`); the mesh itself never reads them
        self.derived: dict[type, object] = {}
        self._build_locator(lo, hi)

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
        with _collector_paused():
            return cls._build(polygon, max_area=max_area, min_angle=min_angle, method=method)

    @classmethod
    def _build(cls, polygon: Polygon, *, max_area: float | None, min_angle: float | None, method: str) -> NavMesh:
        minx, miny, maxx, maxy = polygon.bounds
        tol = 1e-9 * max(1.0, maxx - minx, maxy - miny)
        rings = polygon_rings(polygon, tol)
        if method == "earcut":
            verts, tris = triangulate_earcut(rings)
        else:
            verts, tris = triangulate_cdt(rings)
        walls = wall_edges(verts, rings)
        tris = fix_degenerate(verts, orient_ccw(verts, tris), tol)
        tris = split_t_junctions(verts, tris, walls, tol)
        if method == "refined" and min_angle is None:
            min_angle = DEFAULT_MIN_ANGLE
        if min_angle is not None or max_area is not None:
            ref = Refiner(verts, tris, rings, tol)
            budget = 20 * len(verts) + 2000
            if max_area:
                budget += int(4 * polygon.area / max_area)
            finished = ref.refine(min_angle, max_area, min(budget, MAX_STEINER), MAX_REFINE_WORK)
            verts, tris = ref.arrays()
            mesh = cls(verts, tris)
            mesh.refinement_stopped = not finished
            return mesh
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
        bmin = np.floor((tv.min(axis=1) - lo - self.tol) * scale).astype(np.int64)
        bmax = np.floor((tv.max(axis=1) - lo + self.tol) * scale).astype(np.int64)
        bmin = np.clip(bmin, 0, [nx - 1, ny - 1])
        bmax = np.clip(bmax, 0, [nx - 1, ny - 1])
        # every (cell, triangle) pair of the bounding boxes, triangles ascending within a cell
        # (a stable sort of the pairs listed triangle by triangle, cells row by row)
        wx, wy = bmax[:, 0] - bmin[:, 0] + 1, bmax[:, 1] - bmin[:, 1] + 1
        per = wx * wy
        tri_of = np.repeat(np.arange(len(t), dtype=np.int64), per)
        k = np.arange(len(tri_of), dtype=np.int64) - np.repeat(np.cumsum(per) - per, per)
        cell_of = (bmin[tri_of, 1] + k // wx[tri_of]) * nx + bmin[tri_of, 0] + k % wx[tri_of]
        order = np.argsort(cell_of, kind="stable")
        self._cell_items = tri_of[order]
        counts = np.bincount(cell_of, minlength=nx * ny)
        self._cell_start = np.concatenate(([0], np.cumsum(counts)))
        items, bounds = self._cell_items.tolist(), self._cell_start.tolist()
        self._cells = [items[a:b] for a, b in zip(bounds[:-1], bounds[1:])]
        # edge functions n·p + c >= 0 inside, with unit normals (so tolerances are distances)
        a, b, c = tv[:, 0], tv[:, 1], tv[:, 2]
        eq = []
        for p, q in ((b, c), (c, a), (a, b)):
            e = q - p
            le = np.hypot(*e.T)
            nxv, nyv = -e[:, 1] / le, e[:, 0] / le  # left normal: the inside of a CCW triangle
            eq.append(np.column_stack([nxv, nyv, -(nxv * p[:, 0] + nyv * p[:, 1])]))
        self._edge_eq = np.stack(eq, axis=1)  # (T, 3 edges, 3 coefficients)
        self._edge_py = self._edge_eq.reshape(len(t), 9).tolist()

    # ---------------------------------------------------------------- queries
    def __len__(self) -> int:
        return len(self.triangles)

    def triangle_contains(self, t: int, x: float, y: float) -> bool:
        """Whether triangle ``t`` contains (x, y) (boundary included): a walker's fast path."""
        a0, a1, a2, b0, b1, b2, c0, c1, c2 = self._edge_py[t]
        eps = -self.tol
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
        eps = -self.tol
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
            hit = np.all(val >= -self.tol, axis=1)
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

    # ----------------------------------------------------------------- export
    def export(self, path: str | Path) -> None:
        """Write the mesh (z = 0) as OBJ, PLY or GLB, chosen by the file suffix (via trimesh)."""
        path = Path(path)
        if path.suffix.lower() not in (".obj", ".ply", ".glb"):
            raise ValueError(f"{path}: unsupported format {path.suffix!r}; use .obj, .ply or .glb")
        import trimesh  # heavy import (~0.6 s): only when exporting

        v3 = np.column_stack([self.vertices, np.zeros(len(self.vertices))])
        trimesh.Trimesh(vertices=v3, faces=self.triangles, process=False).export(path)

