"""Clean polygon rings: the boundary every triangulation and the oracle start from.

Shared by :meth:`navmesh.mesh.NavMesh.build` and the test oracle (``tests/oracle.py``), so
both see exactly the same corners: exterior counter-clockwise, holes clockwise (walkable
side on the left), no repeated points, touching rings sharing their contact vertex, no
straight pass-through vertices.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

__all__ = ["polygon_rings", "ring_neighbours"]


def polygon_rings(polygon: Polygon, tol: float) -> list[np.ndarray]:
    """Clean rings of ``polygon``: exterior first, walkable side on the left of every edge.

    The exterior is counter-clockwise and holes clockwise in the coordinate sense
    (positive signed area = ``cross(b - a, c - a) > 0``).  Repeated points are dropped, a
    vertex of one ring lying on an edge of another (rings touching) is inserted into that
    edge, and straight pass-through vertices used by a single ring are removed.
    """
    if not isinstance(polygon, Polygon):
        raise TypeError(f"expected a shapely Polygon, got {type(polygon).__name__}")
    if polygon.is_empty:
        raise ValueError("polygon is empty")
    if not polygon.is_valid:
        raise ValueError(f"polygon is invalid: {shapely.is_valid_reason(polygon)}")
    if polygon.area <= 0.0:
        raise ValueError("polygon has zero area")
    poly = orient(polygon, sign=1.0)
    rings = [np.asarray(poly.exterior.coords, dtype=np.float64)[:-1, :2]]
    rings += [np.asarray(r.coords, dtype=np.float64)[:-1, :2] for r in poly.interiors]
    rings = _drop_repeats_all(rings, tol)
    rings = _insert_touching(rings, tol)
    rings = _drop_straight(rings, tol)
    return rings


def ring_neighbours(lengths: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Index of the previous and the next point of every point of rings laid end to end.

    What ``np.roll(ring, ±1)`` gives per ring, for all rings at once: a level of 10^4
    holes would otherwise pay numpy's per-call overhead 10^4 times per pass.
    """
    n = np.asarray(lengths, dtype=np.intp)
    start = np.repeat(np.cumsum(n) - n, n)
    pos = np.arange(int(n.sum()), dtype=np.intp) - start
    size = np.repeat(n, n)
    return start + (pos - 1) % size, start + (pos + 1) % size


def _split(values: np.ndarray, lengths: list[int] | np.ndarray) -> list[np.ndarray]:
    return np.split(values, np.cumsum(lengths)[:-1])


def _drop_repeats(ring: np.ndarray, tol: float) -> np.ndarray:
    nxt = np.roll(ring, -1, axis=0)
    keep = np.hypot(*(nxt - ring).T) > tol
    return ring[keep]


def _drop_repeats_all(rings: list[np.ndarray], tol: float) -> list[np.ndarray]:
    """:func:`_drop_repeats` of every ring (the same test, on all rings at once)."""
    lengths = [len(r) for r in rings]
    allv = np.concatenate(rings)
    _, nxt = ring_neighbours(lengths)
    keep = np.hypot(*(allv[nxt] - allv).T) > tol
    kept = [int(k.sum()) for k in _split(keep, lengths)]
    return _split(allv[keep], kept)


def _insert_touching(rings: list[np.ndarray], tol: float) -> list[np.ndarray]:
    """Insert into each edge the vertices of any ring that lie strictly inside it.

    Only the vertices in an edge's bounding box widened by twice the tolerance can lie on
    it, so an R-tree of the vertices gives the candidates: about linear in the corners
    rather than edges × corners (a 1000×1000-cell outline has ~10^5 of each). A box, not
    the ball around the edge's midpoint this once used: a long wall's ball holds most of
    a toothed level's corners (one ring of 2 × 10^5: 9 s), its box only those along it.
    The candidates are taken per edge in vertex order, as the ball's sorted answer was, so
    the rings are the same. All rings' edges are tested at once; only a ring with a hit is
    rebuilt point by point.
    """
    lengths = [len(r) for r in rings]
    allv = np.concatenate(rings)
    _, nxt = ring_neighbours(lengths)
    a, b = allv, allv[nxt]
    e = b - a
    le2 = np.einsum("ij,ij->i", e, e)
    le = np.sqrt(le2)
    pad = 2.0 * tol + 1e-12
    lo, hi = np.minimum(a, b) - pad, np.maximum(a, b) + pad
    tree = shapely.STRtree(shapely.points(allv))
    edge, vert = tree.query(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    order = np.lexsort((vert, edge))
    edge, vert = edge[order].astype(np.intp), vert[order].astype(np.intp)
    rel = allv[vert] - a[edge]
    ee = e[edge]
    t = np.einsum("ij,ij->i", rel, ee) / le2[edge]
    dist = np.abs(ee[:, 0] * rel[:, 1] - ee[:, 1] * rel[:, 0]) / le[edge]
    lp = le[edge]
    on = (dist <= tol) & (t * lp > tol) & ((1.0 - t) * lp > tol)
    hits: dict[int, list[int]] = {}
    for k in np.flatnonzero(on).tolist():
        hits.setdefault(int(edge[k]), []).append(k)
    ring_of = np.repeat(np.arange(len(rings)), lengths)
    touched = set(ring_of[list(hits)].tolist())
    out = []
    start = 0
    for r, ring in enumerate(rings):
        if r in touched:
            pts: list[np.ndarray] = []
            for i in range(len(ring)):
                pts.append(ring[i : i + 1])
                if start + i in hits:
                    ks = np.asarray(hits[start + i])
                    pts.append(allv[vert[ks[np.argsort(t[ks])]]])
            ring = _drop_repeats(np.concatenate(pts), tol)
        out.append(ring)
        start += lengths[r]
    return out


def _straight(ring: np.ndarray, prv: np.ndarray, nxt: np.ndarray, shared: np.ndarray, tol: float) -> np.ndarray:
    """Vertices where the ring goes straight on (not shared with another ring)."""
    u, v = ring - ring[prv], ring[nxt] - ring
    cr = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    dot = np.einsum("ij,ij->i", u, v)
    lu, lv = np.hypot(*u.T), np.hypot(*v.T)
    return (np.abs(cr) <= tol * np.maximum(lu, lv)) & (dot > 0) & ~shared


def _drop_straight(rings: list[np.ndarray], tol: float) -> list[np.ndarray]:
    """Remove vertices where a ring goes straight on, unless another ring touches there.

    The first pass tests every ring at once; a ring with a straight vertex is then thinned
    pass by pass on its own.
    """
    lengths = [len(r) for r in rings]
    allv = np.concatenate(rings)
    _, inv, counts = np.unique(allv, axis=0, return_inverse=True, return_counts=True)
    shared = counts[inv.ravel()] > 1
    prv, nxt = ring_neighbours(lengths)
    first = np.concatenate(([0], np.cumsum(_straight(allv, prv, nxt, shared, tol))))
    ends = np.cumsum(lengths)
    out, start = [], 0
    for ring, n, any_straight in zip(rings, lengths, (first[ends] - first[ends - lengths] > 0).tolist(),
                                     strict=True):
        sh = shared[start : start + n]
        start += n
        while any_straight:
            idx = np.arange(len(ring))
            straight = _straight(ring, np.roll(idx, 1), np.roll(idx, -1), sh, tol)
            if not straight.any() or len(ring) - straight.sum() < 3:
                break
            # drop every other straight vertex per pass so neighbours stay valid references
            idx = np.flatnonzero(straight)
            drop = idx[np.concatenate(([True], np.diff(idx) > 1))]
            keep = np.ones(len(ring), bool)
            keep[drop] = False
            ring, sh = ring[keep], sh[keep]
        out.append(ring)
    return out
