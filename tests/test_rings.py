"""polygon_rings' touching-vertex insertion (k-d tree candidates) against an all-pairs check."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon

from navmesh.buildings import building_level
from navmesh.level import parse_level
from navmesh.rings import _insert_touching


def _all_pairs_on_edge(rings: list[np.ndarray], tol: float) -> list[set[tuple[float, float]]]:
    """Per ring, the corners of any ring strictly inside one of its edges (every pair tested)."""
    allv = np.concatenate(rings)
    found = []
    for ring in rings:
        hits: set[tuple[float, float]] = set()
        for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
            e = b - a
            length = float(np.hypot(*e))
            rel = allv - a
            t = rel @ e / (length * length)
            dist = np.abs(e[0] * rel[:, 1] - e[1] * rel[:, 0]) / length
            on = (dist <= tol) & (t * length > tol) & ((1 - t) * length > tol)
            hits |= {(float(x), float(y)) for x, y in allv[on]}
        found.append(hits)
    return found


@pytest.mark.parametrize("polygon,touches", [
    (Polygon([(0, 0), (6, 0), (6, 6), (0, 6)], [[(3, 0), (4, 2), (2, 2)]]), True),
    (parse_level(building_level(40, 60, seed=1, form="polygon")).walkable, False),
])
def test_touching_corners_are_inserted_exactly_where_an_all_pairs_test_finds_them(
    polygon: Polygon, touches: bool
) -> None:
    rings = [np.asarray(polygon.exterior.coords)[:-1]]
    rings += [np.asarray(r.coords)[:-1] for r in polygon.interiors]
    out = _insert_touching(rings, 1e-9)
    for before, after, hits in zip(rings, out, _all_pairs_on_edge(rings, 1e-9), strict=True):
        added = {tuple(p) for p in after.tolist()} - {tuple(p) for p in before.tolist()}
        assert added == hits - {tuple(p) for p in before.tolist()}
        assert len(after) >= len(before)
    assert any(len(a) > len(b) for a, b in zip(out, rings, strict=True)) == touches
