"""``stealth validate``'s body check on a large level, done where the body can be stopped.

The check (:meth:`navmesh.clearance.Clearance.report`) erodes the walkable area by the body
radius r, opens it again and looks at what is lost (passages narrower than 2r) and at the
pieces left. On a polygon with 10^5 holes (a grid of pillars) one GEOS buffer of the whole
area takes minutes. But erosion changes the area only where two walls come closer than 2r
(or an obstacle's own concave part does): an obstacle farther than 2r from every other wall
and convex is eroded around without changing anything. So the obstacles are grouped by
that relation first (an STRtree query, vectorised), and the exact check runs only on each
group's neighbourhood — the outline with the obstacles near it, and each other group of
two or more obstacles (or one concave obstacle) in a box around it. A group away from the
outline can only add pieces by enclosing some of the area.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely
from shapely.geometry import Polygon, box

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

__all__ = ["LOCAL_MIN_HOLES", "exact_parts", "local_parts"]

LOCAL_MIN_HOLES = 100
"""Walkable areas with more holes than this are checked group by group (the bundled levels
have at most 32 and keep the one global check)."""

_AREA_EPS = 1e-4  # navmesh.clearance's: pieces and narrow spots smaller are numerical dust

Parts = tuple[list[tuple[float, float]], list[Polygon]]


def exact_parts(walkable: BaseGeometry, r: float) -> Parts:
    """Narrow-passage points and the eroded area's pieces, by one global computation."""
    eroded = walkable.buffer(-r, join_style="mitre")
    pieces = [g for g in shapely.get_parts(eroded) if isinstance(g, Polygon) and g.area > _AREA_EPS]
    opened = eroded.buffer(r, join_style="mitre")
    lost = walkable.difference(opened)
    narrow = []
    for part in shapely.get_parts(lost):
        if part.area <= _AREA_EPS:
            continue
        thin = part.buffer(-1e-3)
        if thin.is_empty:  # a sliver along a wall, not a passage
            continue
        p = part.representative_point()
        narrow.append((round(float(p.x), 1), round(float(p.y), 1)))
    return narrow, pieces


def local_parts(walkable: Polygon, r: float) -> Parts:
    """:func:`exact_parts` by groups of interacting obstacles (see the module docstring).

    The narrow points are those of the global check; the pieces are the same in number and
    place, a piece's area counting the obstacles of other groups inside it.
    """
    n = shapely.get_num_interior_rings(walkable)
    holes = shapely.polygons(shapely.get_interior_ring(walkable, np.arange(n)))
    reach = 2 * r * (1 + 1e-6) + 1e-9
    tree = shapely.STRtree(holes)
    a, b = tree.query(holes, predicate="dwithin", distance=reach)
    keep = a < b
    a, b = a[keep], b[keep]
    shell_ring = np.asarray(walkable.exterior.coords)
    segments = shapely.linestrings(np.stack([shell_ring[:-1], shell_ring[1:]], axis=1))
    near_shell, _ = shapely.STRtree(segments).query(holes, predicate="dwithin", distance=reach)
    concave = shapely.area(shapely.convex_hull(holes)) - shapely.area(holes) > _AREA_EPS
    # obstacle groups: node n stands for the outline
    src = np.concatenate([a, np.unique(near_shell)])
    dst = np.concatenate([b, np.full(len(np.unique(near_shell)), n)])
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(src.size), (src, dst)), shape=(n + 1, n + 1))
    _, labels = connected_components(graph, directed=False)
    sizes = np.bincount(labels, minlength=labels.max() + 1)
    with_shell = labels[:n] == labels[n]
    narrow, pieces = exact_parts(Polygon(walkable.exterior.coords,
                                         [walkable.interiors[i].coords
                                          for i in np.flatnonzero(with_shell).tolist()]), r)
    group_of = labels[:n]
    checked = ~with_shell & ((sizes[group_of] > 1) | concave)
    members_of: dict[int, list[int]] = {}
    for i in np.flatnonzero(checked).tolist():
        members_of.setdefault(int(group_of[i]), []).append(i)
    for members in members_of.values():
        group_narrow, enclosed = _group_parts(holes[members], r)
        narrow += group_narrow
        pieces += enclosed
    pieces.sort(key=lambda g: -g.area)
    return narrow, pieces


def _group_parts(group: np.ndarray, r: float) -> Parts:
    """The check on one group of obstacles in an open box around it: its narrow points, and
    the pieces it encloses (those not reaching the box's eroded edge)."""
    x0, y0, x1, y1 = shapely.total_bounds(group)
    margin = 3 * r + 1e-6
    frame = box(x0 - margin, y0 - margin, x1 + margin, y1 + margin)
    area = frame.difference(shapely.union_all(group))
    narrow, pieces = exact_parts(area, r)
    edge = frame.buffer(-r, join_style="mitre").exterior
    return narrow, [p for p in pieces if not p.intersects(edge)]
