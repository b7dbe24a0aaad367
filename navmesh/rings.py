"""Clean polygon rings: the boundary every triangulation and the oracle start from.

Shared by :meth:`navmesh.mesh.NavMesh.build` and the test oracle (``tests/oracle.py``), so
both see exactly the same corners: exterior counter-clockwise, holes clockwise (walkable
side on the left), no repeated points, touching rings sharing their contact vertex, no
straight pass-through vertices.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

__all__ = ["polygon_rings"]


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
    rings = [_drop_repeats(r, tol) for r in rings]
    rings = _insert_touching(rings, tol)
    rings = _drop_straight(rings, tol)
    return rings


def _drop_repeats(ring: np.ndarray, tol: float) -> np.ndarray:
    nxt = np.roll(ring, -1, axis=0)
    keep = np.hypot(*(nxt - ring).T) > tol
    return ring[keep]


def _insert_touching(rings: list[np.ndarray], tol: float) -> list[np.ndarray]:
    """Insert into each edge the vertices of any ring that lie strictly inside it.

    Only the vertices within half an edge (plus the tolerance) of its midpoint can lie on
    it, so a k-d tree gives the candidates: linear in the corners rather than edges ×
    corners (a 1000×1000-cell outline has ~10^5 of each).
    """
    allv = np.concatenate(rings)
    tree = cKDTree(allv)
    out = []
    for ring in rings:
        a, b = ring, np.roll(ring, -1, axis=0)
        e = b - a
        le2 = np.einsum("ij,ij->i", e, e)
        le = np.sqrt(le2)
        near = tree.query_ball_point((a + b) / 2.0, le / 2.0 + 2.0 * tol + 1e-12, return_sorted=True)
        counts = np.fromiter((len(c) for c in near), dtype=np.intp, count=len(near))
        edge = np.repeat(np.arange(len(ring)), counts)
        vert = np.fromiter((v for c in near for v in c), dtype=np.intp, count=int(counts.sum()))
        rel = allv[vert] - a[edge]
        ee = e[edge]
        t = np.einsum("ij,ij->i", rel, ee) / le2[edge]
        dist = np.abs(ee[:, 0] * rel[:, 1] - ee[:, 1] * rel[:, 0]) / le[edge]
        lp = le[edge]
        on = (dist <= tol) & (t * lp > tol) & ((1.0 - t) * lp > tol)
        if not on.any():
            out.append(ring)
            continue
        hits: dict[int, list[int]] = {}
        for k in np.flatnonzero(on):
            hits.setdefault(int(edge[k]), []).append(int(k))
        pts: list[np.ndarray] = []
        for i in range(len(ring)):
            pts.append(ring[i : i + 1])
            if i in hits:
                ks = np.asarray(hits[i])
                pts.append(allv[vert[ks[np.argsort(t[ks])]]])
        out.append(_drop_repeats(np.concatenate(pts), tol))
    return out


def _drop_straight(rings: list[np.ndarray], tol: float) -> list[np.ndarray]:
    """Remove vertices where a ring goes straight on, unless another ring touches there."""
    allv = np.concatenate(rings)
    _, inv, counts = np.unique(allv, axis=0, return_inverse=True, return_counts=True)
    shared = counts[inv.ravel()] > 1
    out, start = [], 0
    for ring in rings:
        n = len(ring)
        sh = shared[start : start + n]
        start += n
        while True:
            prv, nxt = np.roll(ring, 1, axis=0), np.roll(ring, -1, axis=0)
            u, v = ring - prv, nxt - ring
            cr = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
            dot = np.einsum("ij,ij->i", u, v)
            lu, lv = np.hypot(*u.T), np.hypot(*v.T)
            straight = (np.abs(cr) <= tol * np.maximum(lu, lv)) & (dot > 0) & ~sh
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
