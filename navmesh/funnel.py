"""String pulling: the taut path through a corridor of portals (the "simple stupid funnel").

A corridor is a sequence of portals, each a segment crossed by the path, given by its
*right* and *left* end point as seen walking along the corridor, in the coordinate sense
(left = the side where ``cross(direction, p - apex) > 0``; with y pointing down on a
screen that is the visual right — only the consistency matters).

>>> pts, corners = funnel((0.0, 0.0), (4.0, 0.0), [(2.0, 1.0)], [(2.0, 3.0)], [7], [8])
>>> pts
[(0.0, 0.0), (2.0, 1.0), (4.0, 0.0)]
>>> corners
[(7, 0)]
"""

from __future__ import annotations

__all__ = ["funnel"]

Point = tuple[float, float]


def funnel(
    start: Point,
    goal: Point,
    rights: list[Point],
    lefts: list[Point],
    right_ids: list[int] | None = None,
    left_ids: list[int] | None = None,
    eps: float = 1e-12,
) -> tuple[list[Point], list[tuple[int, int]]]:
    """Shortest path from ``start`` to ``goal`` through the portals ``(rights[i], lefts[i])``.

    Returns ``(points, corners)``: the path including both end points, and for every
    inner corner ``(vertex id, portal index)`` taken from ``right_ids`` / ``left_ids``
    (-1 where not given).  The path is exact for the corridor: each corner is a portal
    end point where the path wraps around it.
    """
    n = len(rights)
    # portal list: start, the corridor portals, goal (degenerate portals at both ends)
    rx = [start[0]] + [p[0] for p in rights] + [goal[0]]
    ry = [start[1]] + [p[1] for p in rights] + [goal[1]]
    lx = [start[0]] + [p[0] for p in lefts] + [goal[0]]
    ly = [start[1]] + [p[1] for p in lefts] + [goal[1]]
    rid = [-1] + (list(right_ids) if right_ids is not None else [-1] * n) + [-1]
    lid = [-1] + (list(left_ids) if left_ids is not None else [-1] * n) + [-1]
    m = n + 2

    ax, ay = start
    plx, ply, prx, pry = ax, ay, ax, ay
    apex_i = left_i = right_i = 0
    points: list[Point] = [(ax, ay)]
    corners: list[tuple[int, int]] = []
    i = 1
    while i < m:
        nrx, nry, nlx, nly = rx[i], ry[i], lx[i], ly[i]
        # --- try to move the right side inward
        # cross(right - apex, new_right - apex) >= 0: new right is left of (or on) the right ray
        if (prx - ax) * (nry - ay) - (pry - ay) * (nrx - ax) >= -eps:
            same = abs(prx - ax) <= eps and abs(pry - ay) <= eps
            # new right strictly right of the left ray: funnel still open
            if same or (plx - ax) * (nry - ay) - (ply - ay) * (nrx - ax) < -eps:
                prx, pry, right_i = nrx, nry, i
            else:
                # right crosses over left: the left point becomes a corner
                ax, ay = plx, ply
                points.append((ax, ay))
                corners.append((lid[left_i], left_i - 1))
                apex_i = left_i
                plx, ply, prx, pry = ax, ay, ax, ay
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        # --- try to move the left side inward
        if (plx - ax) * (nly - ay) - (ply - ay) * (nlx - ax) <= eps:
            same = abs(plx - ax) <= eps and abs(ply - ay) <= eps
            if same or (prx - ax) * (nly - ay) - (pry - ay) * (nlx - ax) > eps:
                plx, ply, left_i = nlx, nly, i
            else:
                ax, ay = prx, pry
                points.append((ax, ay))
                corners.append((rid[right_i], right_i - 1))
                apex_i = right_i
                plx, ply, prx, pry = ax, ay, ax, ay
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        i += 1
    gx, gy = goal
    if len(points) > 1 and abs(points[-1][0] - gx) <= eps and abs(points[-1][1] - gy) <= eps:
        points[-1] = (gx, gy)  # a last corner on the goal: end exactly at the goal
        corners.pop()
    else:
        points.append((gx, gy))
    return points, corners
