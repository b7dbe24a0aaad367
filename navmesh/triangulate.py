"""Base triangulation of clean rings: constrained Delaunay (GEOS) or ear clipping, and repairs.

The first stage of :meth:`navmesh.mesh.NavMesh.build` (the Recast side: building, not
querying).  Triangles are over the polygon's own vertices; :mod:`navmesh.refine` adds
Steiner points afterwards.  Also the mesh topology every stage shares: the neighbour
across each edge (:func:`edge_neighbors`) and counter-clockwise orientation.
"""

from __future__ import annotations

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import Polygon

__all__ = ["cross2", "edge_neighbors", "orient_ccw", "split_t_junctions", "triangulate_cdt", "ring_vertex_ids", "triangulate_earcut", "vertex_ids", "wall_edges"]


def triangulate_cdt(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Constrained Delaunay triangulation of the rings (GEOS, via shapely)."""
    holes = rings[1:]
    if holes:  # every hole in one call (10^4 holes one by one cost more than the rest here)
        index = np.repeat(np.arange(len(holes)), [len(h) for h in holes])
        poly = shapely.polygons(rings[0], holes=shapely.linearrings(np.concatenate(holes), indices=index))
    else:
        poly = Polygon(rings[0])
    tris = shapely.constrained_delaunay_triangles(poly)
    # a collection of triangles: each one's closed exterior ring, 4 points, in order
    coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3]
    verts = np.unique(np.concatenate(rings), axis=0)
    try:
        triangles = vertex_ids(verts, coords.reshape(-1, 2))
    except KeyError as exc:  # GEOS never adds points; be loud if it ever does
        raise RuntimeError(f"constrained Delaunay output has a vertex not in the input: {exc}") from None
    return verts, triangles.reshape(-1, 3)


def vertex_ids(verts: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Index in ``verts`` (unique rows in ``np.unique`` order) of every point, by exact equality.

    One binary search per point on the rows as complex numbers (numpy orders complex numbers
    by real then imaginary part, the order of ``np.unique(axis=0)``) instead of a Python
    dict per call: the same indices, about 20× faster on 10^5 corners.  Raises ``KeyError``
    naming a point that is not a vertex.
    """
    keys = verts[:, 0] + 1j * verts[:, 1]
    want = points[:, 0] + 1j * points[:, 1]
    idx = np.minimum(np.searchsorted(keys, want), len(keys) - 1)
    miss = np.flatnonzero(keys[idx] != want)
    if miss.size:
        x, y = points[miss[0]]
        raise KeyError((float(x), float(y)))
    return idx.astype(np.int64)


def triangulate_earcut(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Ear-clipping triangulation (mapbox-earcut bridges the holes itself)."""
    flat = np.concatenate(rings)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    idx = mapbox_earcut.triangulate_float64(flat, ends).astype(np.int64).reshape(-1, 3)
    verts, inv = np.unique(flat, axis=0, return_inverse=True)
    return verts, inv.ravel()[idx]


def cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z of the cross product of arrays of 2-D vectors."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def edge_neighbors(triangles: np.ndarray) -> np.ndarray:
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

def orient_ccw(verts: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Counter-clockwise triangles; zero-area ones follow the triangulator's own orientation."""
    p0, p1, p2 = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    area2 = cross2(p1 - p0, p2 - p0)
    if area2.sum() < 0:
        tris, area2 = tris[:, [0, 2, 1]], -area2
    return np.where((area2 < 0)[:, None], tris[:, [0, 2, 1]], tris)


def split_t_junctions(verts: np.ndarray, tris: np.ndarray, walls: set[tuple[int, int]], tol: float) -> np.ndarray:
    """Make the triangulation conforming: split any triangle with a vertex inside one of its edges.

    Ear clipping with collinear polygon vertices can leave a vertex in the middle of a
    diagonal (a T-junction).  Such a diagonal shows up as an edge without a neighbour
    that is not a wall; splitting its triangle at the vertex restores whole-edge sharing.
    """
    for _ in range(len(verts) + 1):
        nbr = edge_neighbors(tris)
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


def wall_edges(verts: np.ndarray, rings: list[np.ndarray]) -> set[tuple[int, int]]:
    """The ring edges as (low, high) vertex-index pairs of ``verts`` (the walls)."""
    ids = ring_vertex_ids(verts, rings)
    nxt = np.concatenate([np.roll(r, -1) for r in ids])
    cur = np.concatenate(ids)
    return set(zip(np.minimum(cur, nxt).tolist(), np.maximum(cur, nxt).tolist()))


def ring_vertex_ids(verts: np.ndarray, rings: list[np.ndarray]) -> list[np.ndarray]:
    """:func:`vertex_ids` of every ring's points (one search for all rings)."""
    ids = vertex_ids(verts, np.concatenate(rings))
    return np.split(ids, np.cumsum([len(r) for r in rings])[:-1])
