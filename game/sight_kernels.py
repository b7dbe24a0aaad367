"""The compiled loops of :mod:`game.guard_sight` (numba): the nodes near a guard, the view
test in :meth:`game.senses.Senses.perceives`' float operations and order, and the two line
tests — the segment crossing of :class:`~game.guard_sight.GuardSight` and pymunk's query
(:func:`game.exact.blocking_wall`) for :class:`~game.guard_sight.ViewCover`. Imported at
first use, so a world that never reads the guards' sight never loads numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import exact
from .exact import blocking_wall, cell_range, clear_line

__all__ = ["cover", "near", "sight", "visible"]

exact.forget_stale_cache(__file__)

#: a side test within this share of |ray|·|wall| of zero is left to the full query (rounding)
_TOLERANCE = 1e-9


@njit(cache=True, error_model="numpy")
def near(is_grid, positions, size, cell_node, start, items, geom, x, y, radius, out):
    """Write the nodes that may lie within ``radius`` of (x, y) into ``out``; their count.
    The grid's window is :func:`math.floor` of the same quotients the reference took."""
    n = 0
    if is_grid:
        rows, cols = cell_node.shape
        r0 = max(0, math.floor((y - radius) / size))
        r1 = min(rows - 1, math.floor((y + radius) / size))
        c0 = max(0, math.floor((x - radius) / size))
        c1 = min(cols - 1, math.floor((x + radius) / size))
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                k = cell_node[r, c]
                if k >= 0:
                    out[n] = k
                    n += 1
        return n
    reach = radius + 1e-6
    i0, i1 = cell_range(x - reach, x + reach, geom[0], geom[2], int(geom[3]))
    j0, j1 = cell_range(y - reach, y + reach, geom[1], geom[2], int(geom[4]))
    ncx = int(geom[3])
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            c = j * ncx + i
            for k in range(start[c], start[c + 1]):
                out[n] = items[k]
                n += 1
    return n


@njit(cache=True, error_model="numpy", inline="always")
def _in_view(px, py, x, y, cos, sin, limit, cos_half_fov):
    """:meth:`Senses.perceives` without the line: (px, py) within ``limit`` of (x, y) and
    inside the cone facing (cos, sin); the operations of :meth:`Senses.perceives`."""
    dx = px - x
    dy = py - y
    d2 = dx * dx + dy * dy
    if not d2 <= limit * limit:
        return False
    d = math.sqrt(d2)
    return d <= 1e-9 or dx * cos + dy * sin >= cos_half_fov * d


@njit(cache=True, error_model="numpy")
def sight(gx, gy, gcos, gsin, active, bound, limit, cos_half_fov, is_grid, positions, size,
           cell_node, start, items, geom, segs, wall_start, wall_items, wall_geom):
    """Per guard, the sorted nodes in view with no wall crossing or touching the ray: their
    counts and the nodes one guard after another."""
    n_guards = gx.shape[0]
    counts = np.zeros(n_guards, dtype=np.int64)
    buf = np.empty(positions.shape[0], dtype=np.int64)
    out = np.empty(1024, dtype=np.int64)
    total = 0
    wx0 = wall_geom[0]
    wy0 = wall_geom[1]
    wcell = wall_geom[2]
    wncx = int(wall_geom[3])
    wncy = int(wall_geom[4])
    for g in range(n_guards):
        if not active[g]:
            continue
        x = gx[g]
        y = gy[g]
        n = near(is_grid, positions, size, cell_node, start, items, geom, x, y, bound, buf)
        if total + n > out.shape[0]:
            grown = np.empty(max(2 * out.shape[0], total + n), dtype=np.int64)
            grown[:total] = out[:total]
            out = grown
        first = total
        for m in range(n):
            k = buf[m]
            px = positions[k, 0]
            py = positions[k, 1]
            if not _in_view(px, py, x, y, gcos[g], gsin[g], limit[k], cos_half_fov):
                continue
            if segs.shape[0] > 0 and _crossed(px - x, py - y, x, y, segs, wall_start,
                                              wall_items, wx0, wy0, wcell, wncx, wncy):
                continue
            out[total] = k
            total += 1
        out[first:total].sort()
        counts[g] = total - first
    return counts, out[:total]


@njit(cache=True, error_model="numpy", inline="always")
def _crossed(dx, dy, x, y, segs, wall_start, wall_items, x0, y0, cell, ncx, ncy):
    """Some wall meets the ray from (x, y) along (dx, dy) (crosses it, touches it, or lies
    along it over a shared stretch). The walls from the guard's position, as the segment
    test of the first engines took them: the same operations in the same order."""
    lox = x if dx >= 0 else x + dx
    hix = x + dx if dx >= 0 else x
    loy = y if dy >= 0 else y + dy
    hiy = y + dy if dy >= 0 else y
    if hix < x0 or hiy < y0 or lox > x0 + ncx * cell or loy > y0 + ncy * cell:
        return False
    i0, i1 = cell_range(lox, hix, x0, cell, ncx)
    j0, j1 = cell_range(loy, hiy, y0, cell, ncy)
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            c = j * ncx + i
            for q in range(wall_start[c], wall_start[c + 1]):
                w = wall_items[q]
                ax = segs[w, 0] - x
                ay = segs[w, 1] - y
                bx = segs[w, 2] - x
                by = segs[w, 3] - y
                wx = bx - ax
                wy = by - ay
                s_a = dx * ay - dy * ax
                s_b = dx * by - dy * bx
                s_o = wx * -ay - wy * -ax
                s_p = wx * (dy - ay) - wy * (dx - ax)
                if s_a == 0 and s_b == 0:  # collinear: an overlap along the ray
                    length2 = dx * dx + dy * dy
                    if length2 == 0:
                        continue  # the guard's own position: nothing between
                    ta = (ax * dx + ay * dy) / length2
                    tb = (bx * dx + by * dy) / length2
                    if max(ta, tb) >= 0 and min(ta, tb) <= 1:
                        return True
                elif s_a * s_b <= 0 and s_o * s_p <= 0:
                    return True
    return False


@njit(cache=True, error_model="numpy")
def cover(seen, blocker, gx, gy, gcos, gsin, bound, limit, cos_half_fov, is_grid, positions,
           size, cell_node, start, items, geom, segs, wall_start, wall_items, wall_geom):
    """Mark the nodes each noted guard (in tick order) perceives; a node's blocking wall is
    kept, and a line it still plainly crosses is blocked without the full query."""
    buf = np.empty(positions.shape[0], dtype=np.int64)
    for g in range(gx.shape[0]):
        x = gx[g]
        y = gy[g]
        n = near(is_grid, positions, size, cell_node, start, items, geom, x, y, bound, buf)
        for m in range(n):
            k = buf[m]
            if seen[k]:
                continue
            px = positions[k, 0]
            py = positions[k, 1]
            if not _in_view(px, py, x, y, gcos[g], gsin[g], limit[k], cos_half_fov):
                continue
            w = blocker[k]
            if w >= 0:
                ax = segs[w, 0]
                ay = segs[w, 1]
                bx = segs[w, 2]
                by = segs[w, 3]
                rx = px - x
                ry = py - y
                wx = bx - ax
                wy = by - ay
                s_o = wx * (y - ay) - wy * (x - ax)   # the ray's ends against the wall's line
                s_p = wx * (py - ay) - wy * (px - ax)
                s_a = rx * (ay - y) - ry * (ax - x)   # the wall's ends against the ray's line
                s_b = rx * (by - y) - ry * (bx - x)
                tol = _TOLERANCE * math.sqrt(rx * rx + ry * ry) * math.sqrt(wx * wx + wy * wy)
                if (s_o * s_p < 0 and s_a * s_b < 0 and min(abs(s_o), abs(s_p)) > tol
                        and min(abs(s_a), abs(s_b)) > tol):
                    continue  # still plainly behind that wall
            w = blocking_wall(segs, wall_start, wall_items, wall_geom, x, y, px, py)
            if w < 0:
                seen[k] = True
            else:
                blocker[k] = w


@njit(cache=True, error_model="numpy")
def visible(x, y, cos, sin, points, reach, cos_half_fov, segs, wall_start, wall_items,
            wall_geom):
    """:meth:`game.senses.Senses.visible_points`: per point, within ``reach`` (with
    ``RANGE_EPS``) of (x, y), inside the cone facing (cos, sin) and a clear line to it —
    :meth:`~game.senses.Senses.perceives`' operations in its order."""
    out = np.zeros(points.shape[0], dtype=np.bool_)
    limit = reach + 1e-9
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        if _in_view(px, py, x, y, cos, sin, limit, cos_half_fov):
            out[k] = clear_line(segs, wall_start, wall_items, wall_geom, x, y, px, py)
    return out
