"""The nodes the guards see: now, per guard (:class:`GuardSight`), and so far, by any guard
(:class:`ViewCover`, ``metrics.coverage = "seen"``, SPEC §11).

A node is seen by a guard when a player standing on it would be
(:meth:`game.senses.Senses.perceives`): within the view range scaled by the node's zone,
inside the cone, and no wall of the level between the guard and the node's position. Per
guard only the nodes within the view range are looked at (:func:`nodes_within`: the grid's
window of cells, or a partition's nodes bucketed in square cells) and each is tested in a
compiled loop (numba) that repeats :meth:`~game.senses.Senses.perceives`' float operations
in its order, so both engines get the same bits.

The line of sight is where the two differ, each as its reader needs it:

* :class:`GuardSight` (for guard modes that patrol by sight, ``staleness.model = "view"``)
  tests every node in view with a segment-crossing test against the walls near the ray
  (the same segments the pymunk space holds); a ray that touches a wall counts as blocked.
* :class:`ViewCover` only needs the nodes not seen yet. Most of those are occluded, tick
  after tick: the wall that last blocked a node's ray is kept, and a line it still crosses
  plainly (no end of either segment within rounding of the other) is blocked without a
  ray; every other line is the query the player's sight uses
  (:meth:`game.senses.Senses.clear_line`, pymunk's segment query, here in its bit-exact
  port :func:`game.exact.blocking_wall`), so the metric is that rule exactly.

  Its work is deferred: an AI tick only notes the active guards' positions and headings,
  worked through in tick order when :attr:`ViewCover.seen` is read (the trial's metrics) or
  when :data:`PENDING_TICKS` of them wait. The walls never move, so the answer is the same
  bits as working each tick at once; an env episode nobody scores by coverage never pays.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable, Sequence

import numpy as np
import pymunk
from numba import njit

from navmesh.graph import NodeGraph

from . import exact
from .agents import Agent
from .exact import blocking_wall, cell_range, wall_grid
from .senses import RANGE_EPS, Senses

__all__ = ["PENDING_TICKS", "GuardSight", "ViewCover", "nodes_within"]

exact.forget_stale_cache(__file__)

#: AI ticks noted before the cover is brought up to date (bounds the notes' memory)
PENDING_TICKS = 256

#: a side test within this share of |ray|·|wall| of zero is left to the full query (rounding)
_TOLERANCE = 1e-9

#: a partition's nodes are looked up within the view range plus this (a superset)
_SLACK = 1e-6


class _NodeIndex:
    """A graph's nodes by place, as arrays the compiled loops read: the grid's own cells, or
    a partition's node positions bucketed in square cells of side ``cell`` (CSR lists).
    Built once per graph and cell side, shared by every trial (graphs are cached)."""

    def __init__(self, graph: NodeGraph, cell: float) -> None:
        self.positions = np.ascontiguousarray(graph.positions, dtype=np.float64)
        if graph.cell_node is not None:
            self.is_grid = True
            self.cell_node = np.ascontiguousarray(graph.cell_node, dtype=np.int64)
            self.size = float(graph.cell_size)
            self.start = np.zeros(1, dtype=np.int64)
            self.items = np.zeros(0, dtype=np.int64)
            self.geom = np.zeros(5)
            return
        self.is_grid, self.size = False, 0.0
        self.cell_node = np.zeros((0, 0), dtype=np.int64)
        pts = self.positions
        if not len(pts):
            pts = np.zeros((1, 2))
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        # at most a few cells per node, however small the view range
        cell = max(float(cell), math.sqrt(float(np.prod(hi - lo + 1.0)) / (4 * len(pts) + 64)),
                   1e-3)
        ncx, ncy = (int(k) for k in np.floor((hi - lo) / cell) + 1)
        cx = np.floor((self.positions[:, 0] - lo[0]) / cell).astype(np.int64)
        cy = np.floor((self.positions[:, 1] - lo[1]) / cell).astype(np.int64)
        flat = cy * ncx + cx
        self.items = np.ascontiguousarray(np.argsort(flat, kind="stable"), dtype=np.int64)
        self.start = np.zeros(ncx * ncy + 1, dtype=np.int64)
        np.cumsum(np.bincount(flat, minlength=ncx * ncy), out=self.start[1:])
        self.geom = np.array([lo[0], lo[1], cell, ncx, ncy], dtype=np.float64)

    @property
    def arrays(self) -> tuple[bool, np.ndarray, float, np.ndarray, np.ndarray, np.ndarray,
                              np.ndarray]:
        """What :func:`_near` takes."""
        return (self.is_grid, self.positions, self.size, self.cell_node, self.start,
                self.items, self.geom)


#: per graph (graphs are cached and shared by trials): its node index per cell side
_INDEXES: weakref.WeakKeyDictionary[NodeGraph, dict[float, _NodeIndex]] = (
    weakref.WeakKeyDictionary())


def _node_index(graph: NodeGraph, cell: float) -> _NodeIndex:
    per_cell = _INDEXES.setdefault(graph, {})
    index = per_cell.get(cell)
    if index is None:
        index = per_cell[cell] = _NodeIndex(graph, cell)
    return index


def nodes_within(graph: NodeGraph, x: float, y: float, radius: float) -> np.ndarray:
    """Indices of nodes whose position may lie within ``radius`` of (x, y): a superset
    (the grid's square window of cells; a partition's buckets under the disc's box)."""
    buf = np.empty(graph.n, dtype=np.int64)
    count = _near(*_node_index(graph, max(radius, 1.0)).arrays, float(x), float(y),
                  float(radius), buf)
    return buf[:count]


@njit(cache=True, error_model="numpy")
def _near(is_grid, positions, size, cell_node, start, items, geom, x, y, radius, out):
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
def _sight(gx, gy, gcos, gsin, active, bound, limit, cos_half_fov, is_grid, positions, size,
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
        n = _near(is_grid, positions, size, cell_node, start, items, geom, x, y, bound, buf)
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
def _cover(seen, blocker, gx, gy, gcos, gsin, bound, limit, cos_half_fov, is_grid, positions,
           size, cell_node, start, items, geom, segs, wall_start, wall_items, wall_geom):
    """Mark the nodes each noted guard (in tick order) perceives; a node's blocking wall is
    kept, and a line it still plainly crosses is blocked without the full query."""
    buf = np.empty(positions.shape[0], dtype=np.int64)
    for g in range(gx.shape[0]):
        x = gx[g]
        y = gy[g]
        n = _near(is_grid, positions, size, cell_node, start, items, geom, x, y, bound, buf)
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


class _NodeView:
    """What both readers share: the graph, the cone and, per node, the guards' view range
    for a player standing there (``reach``: the scenario's range × the node's zone scale)."""

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray,
                 walls: np.ndarray) -> None:
        self.graph, self.senses, self.cos_half_fov = graph, senses, float(senses.cos_half_fov)
        self.reach = np.asarray(reach, dtype=np.float64)
        self.limit = np.ascontiguousarray(self.reach + RANGE_EPS)
        self.walls = wall_grid(walls)


class GuardSight(_NodeView):
    """Which nodes each guard sees now (:meth:`seen`).

    ``reach``: per node, the guards' view range for a player standing there (the scenario's
    range × the node's zone scale); ``walls``: the level's wall segments, shape (m, 2, 2).

    >>> import pymunk
    >>> graph = NodeGraph.from_grid(np.ones((1, 5), bool), 1.0)
    >>> walls = np.array([[[3.0, 0.0], [3.0, 1.0]]])      # a wall across the corridor at x = 3
    >>> sight = GuardSight(graph, Senses(pymunk.Space(), 90.0), np.full(5, 8.0), walls)
    >>> sight.seen_by((0.5, 0.5), 0.0).tolist()          # facing +x: cells 0..2, not past the wall
    [0, 1, 2]
    """

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray,
                 walls: np.ndarray) -> None:
        super().__init__(graph, senses, reach, walls)
        self.bound = float(self.limit.max()) if len(self.limit) else 0.0
        self.index = _node_index(graph, max(self.bound, 1.0))

    def seen(self, guards: Sequence[Agent]) -> tuple[np.ndarray, ...]:
        """Per guard, the sorted node indices it sees now (empty for a guard out of play)."""
        return self._seen([g.pos for g in guards], [g.heading for g in guards],
                          [g.active for g in guards])

    def seen_by(self, pos: tuple[float, float], heading: float) -> np.ndarray:
        """The sorted node indices seen from ``pos`` looking along ``heading`` (radians)."""
        return self._seen([pos], [heading], [True])[0]

    def _seen(self, pos: list[tuple[float, float]], headings: list[float],
              active: list[bool]) -> tuple[np.ndarray, ...]:
        xy = np.array(pos, dtype=np.float64).reshape(-1, 2)
        # math's cos and sin, as Senses.perceives takes them (numpy's may differ in a bit)
        cos = np.array([math.cos(h) for h in headings])
        sin = np.array([math.sin(h) for h in headings])
        counts, nodes = _sight(np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1]),
                               cos, sin, np.array(active, dtype=np.bool_), self.bound,
                               self.limit, self.cos_half_fov, *self.index.arrays,
                               *self.walls.arrays)
        return tuple(np.split(nodes, np.cumsum(counts)[:-1]))


class ViewCover(_NodeView):
    """Which nodes any guard's view has covered so far (:attr:`seen`, one bool per node).

    ``reach`` is the guards' view range per node (the scenario's range × the node's zone
    scale, as for the player standing there); the walls are the pymunk space's segments.
    """

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray) -> None:
        walls = [(*shape.a, *shape.b) for shape in senses.space.shapes
                 if isinstance(shape, pymunk.Segment)]
        super().__init__(graph, senses, reach, np.array(walls, dtype=np.float64).reshape(-1, 4))
        self.bound = float(self.reach.max()) if len(self.reach) else 0.0
        self.index = _node_index(graph, max(self.bound, 1.0))
        self._seen = np.zeros(graph.n, dtype=bool)
        self._blocker = np.full(graph.n, -1, dtype=np.int64)
        #: per noted AI tick: the active guards' (x, y, cos, sin), not yet worked through
        self._pending: list[tuple[float, float, float, float]] = []
        self._ticks = 0

    @property
    def seen(self) -> np.ndarray:
        """Per node: inside an active guard's view at some AI tick so far."""
        self._catch_up()
        return self._seen

    @property
    def blocker(self) -> np.ndarray:
        """Per node: a wall (a row of the wall grid's ``segs``) that blocked its last ray, or
        -1."""
        self._catch_up()
        return self._blocker

    def observe(self, guards: Iterable[Agent]) -> None:
        """Note what the active guards see now (one AI tick): their positions and headings,
        worked through in order when :attr:`seen` is next read."""
        # math's cos and sin, as Senses.perceives takes them (numpy's may differ in a bit)
        self._pending.extend((g.pos[0], g.pos[1], math.cos(g.heading), math.sin(g.heading))
                             for g in guards if g.active)
        self._ticks += 1
        if self._ticks >= PENDING_TICKS:
            self._catch_up()

    def _catch_up(self) -> None:
        pending, self._pending, self._ticks = self._pending, [], 0
        if not pending:
            return
        gx, gy, gcos, gsin = (np.ascontiguousarray(col) for col in
                              np.array(pending, dtype=np.float64).T)
        _cover(self._seen, self._blocker, gx, gy, gcos, gsin, self.bound, self.limit,
               self.cos_half_fov, *self.index.arrays, *self.walls.arrays)

    def share(self) -> float:
        """The share of nodes seen so far (0 on an empty graph)."""
        seen = self.seen
        return float(seen.mean()) if len(seen) else 0.0
