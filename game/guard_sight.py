"""The nodes the guards see: now, per guard (:class:`GuardSight`), and so far, by any guard
(:class:`ViewCover`, ``metrics.coverage = "seen"``, SPEC §11).

A node is seen by a guard when a player standing on it would be
(:meth:`game.senses.Senses.perceives`): within the view range scaled by the node's zone,
inside the cone, and no wall of the level between the guard and the node's position. Per guard only the nodes within the view range
are looked at (:func:`nodes_within`: the grid's window of cells, or a k-d tree of a
partition's centroids) and the range and cone tests are vectorised over them
(:meth:`_NodeView.in_view`, one code for both). No Python loop runs per node for those.

The line of sight is where the two differ, each as its reader needs it:

* :class:`GuardSight` (for guard modes that patrol by sight, ``staleness.model = "view"``)
  tests every node in view: one vectorised segment-crossing test against the walls whose
  bounding box meets the view's square (the same segments the pymunk space holds); a ray
  that touches a wall counts as blocked. Per guard and tick: O(walls) for the box filter
  plus O(nodes in range × walls in range) for the crossings, whatever the level's size.
* :class:`ViewCover` only needs the nodes not seen yet. Most of those are occluded, tick
  after tick: the wall that last blocked a node's ray is kept, and a line it still crosses
  plainly (no end of either segment within rounding of the other) is blocked without a
  ray; every other line is the pymunk query the player's sight uses
  (:meth:`game.senses.Senses.clear_line`), so the metric is that rule exactly.

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
from scipy.spatial import cKDTree

from navmesh.graph import NodeGraph

from .agents import WALL_QUERY, Agent
from .senses import RANGE_EPS, Senses

__all__ = ["PENDING_TICKS", "GuardSight", "ViewCover", "nodes_within"]

#: AI ticks noted before the cover is brought up to date (bounds the notes' memory)
PENDING_TICKS = 256

#: a side test within this share of |ray|·|wall| of zero is left to pymunk (rounding)
_TOLERANCE = 1e-9

#: per graph (graphs are cached and shared by trials): the k-d tree of a partition's nodes
_TREES: weakref.WeakKeyDictionary[NodeGraph, cKDTree] = weakref.WeakKeyDictionary()


def nodes_within(graph: NodeGraph, x: float, y: float, radius: float) -> np.ndarray:
    """Indices of nodes whose position may lie within ``radius`` of (x, y): a superset
    (the grid's square window of cells; the partition's k-d tree ball with slack)."""
    if graph.cell_node is not None:
        size = graph.cell_size
        rows, cols = graph.cell_node.shape
        r0 = max(0, math.floor((y - radius) / size))
        r1 = min(rows - 1, math.floor((y + radius) / size))
        c0 = max(0, math.floor((x - radius) / size))
        c1 = min(cols - 1, math.floor((x + radius) / size))
        if r0 > r1 or c0 > c1:
            return np.zeros(0, dtype=np.int64)
        window = graph.cell_node[r0:r1 + 1, c0:c1 + 1].ravel()
        return window[window >= 0]
    tree = _TREES.get(graph)
    if tree is None:
        tree = _TREES[graph] = cKDTree(graph.positions)
    return np.asarray(tree.query_ball_point((x, y), radius + 1e-6), dtype=np.int64)


def _cross(ux: np.ndarray, uy: np.ndarray, vx: np.ndarray, vy: np.ndarray) -> np.ndarray:
    return ux * vy - uy * vx


class _NodeView:
    """What both readers share: the graph, the cone and, per node, the guards' view range
    for a player standing there (``reach``: the scenario's range × the node's zone scale)."""

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray) -> None:
        self.graph, self.senses, self.cos_half_fov = graph, senses, senses.cos_half_fov
        self.reach = np.asarray(reach, dtype=np.float64)
        self.limit = self.reach + RANGE_EPS

    def in_view(self, near: np.ndarray, x: float | np.ndarray, y: float | np.ndarray,
                cos: float | np.ndarray, sin: float | np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`Senses.perceives` without the line, vectorised over the nodes ``near`` seen
        from (x, y) facing (cos, sin) (one value, or one per node): ``(keep, points, dx, dy)``,
        ``keep`` true for the nodes in range (with their zone) and inside the cone."""
        points = self.graph.positions[near]
        dx, dy = points[:, 0] - x, points[:, 1] - y
        d2 = dx * dx + dy * dy
        d = np.sqrt(d2)
        keep = (d2 <= self.limit[near] ** 2) & (
            (d <= 1e-9) | (dx * cos + dy * sin >= self.cos_half_fov * d))
        return keep, points, dx, dy


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
        super().__init__(graph, senses, reach)
        self.bound = float(self.limit.max()) if len(self.limit) else 0.0
        seg = np.asarray(walls, dtype=np.float64).reshape(-1, 4)
        self.ax, self.ay, self.bx, self.by = (np.ascontiguousarray(seg[:, k]) for k in range(4))
        self.lo_x, self.hi_x = np.minimum(self.ax, self.bx), np.maximum(self.ax, self.bx)
        self.lo_y, self.hi_y = np.minimum(self.ay, self.by), np.maximum(self.ay, self.by)

    def seen(self, guards: Sequence[Agent]) -> tuple[np.ndarray, ...]:
        """Per guard, the sorted node indices it sees now (empty for a guard out of play)."""
        return tuple(self.seen_by(g.pos, g.heading) if g.active else np.zeros(0, dtype=np.int64)
                     for g in guards)

    def seen_by(self, pos: tuple[float, float], heading: float) -> np.ndarray:
        """The sorted node indices seen from ``pos`` looking along ``heading`` (radians)."""
        x, y = float(pos[0]), float(pos[1])
        near = np.sort(nodes_within(self.graph, x, y, self.bound))
        if not len(near):
            return near
        keep, _, dx, dy = self.in_view(near, x, y, math.cos(heading), math.sin(heading))
        near, dx, dy = near[keep], dx[keep], dy[keep]
        if not len(near):
            return near
        return near[self._clear(x, y, dx, dy)]

    def _clear(self, x: float, y: float, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """Per ray from (x, y) along (dx, dy): no wall crosses or touches it."""
        b = self.bound
        walls = np.flatnonzero((self.hi_x >= x - b) & (self.lo_x <= x + b)
                               & (self.hi_y >= y - b) & (self.lo_y <= y + b))
        if not len(walls):
            return np.ones(len(dx), dtype=bool)
        ax, ay = self.ax[walls][None, :] - x, self.ay[walls][None, :] - y   # walls from the guard
        bx, by = self.bx[walls][None, :] - x, self.by[walls][None, :] - y
        px, py = dx[:, None], dy[:, None]
        wx, wy = bx - ax, by - ay
        # the wall's ends on either side of (or on) the ray, and the ray's ends of the wall
        s_a, s_b = _cross(px, py, ax, ay), _cross(px, py, bx, by)
        s_o = _cross(wx, wy, -ax, -ay)
        s_p = _cross(wx, wy, px - ax, py - ay)
        meets = (s_a * s_b <= 0) & (s_o * s_p <= 0)
        # collinear ray and wall: they meet only if their extents overlap along the ray
        flat = (s_a == 0) & (s_b == 0)
        if flat.any():
            length2 = px * px + py * py
            point = length2 == 0  # the guard's own position: nothing between
            length2 = np.where(point, 1.0, length2)
            ta, tb = (ax * px + ay * py) / length2, (bx * px + by * py) / length2
            overlap = (np.maximum(ta, tb) >= 0) & (np.minimum(ta, tb) <= 1) & ~point
            meets = np.where(flat, overlap, meets)
        return ~meets.any(axis=1)


class ViewCover(_NodeView):
    """Which nodes any guard's view has covered so far (:attr:`seen`, one bool per node).

    ``reach`` is the guards' view range per node (the scenario's range × the node's zone
    scale, as for the player standing there).
    """

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray) -> None:
        super().__init__(graph, senses, reach)
        self.bound = float(self.reach.max()) if len(self.reach) else 0.0
        self._seen = np.zeros(graph.n, dtype=bool)
        self._blocker = np.full(graph.n, -1, dtype=np.int32)
        #: per noted AI tick: the active guards' (x, y, heading), not yet worked through
        self._pending: list[list[tuple[float, float, float]]] = []
        walls = [shape for shape in senses.space.shapes if isinstance(shape, pymunk.Segment)]
        self._wall_index: dict[pymunk.Shape, int] = {shape: i for i, shape in enumerate(walls)}
        ends = [(*shape.a, *shape.b) for shape in walls]
        self._walls = np.array(ends, dtype=np.float64).reshape(-1, 4)

    @property
    def seen(self) -> np.ndarray:
        """Per node: inside an active guard's view at some AI tick so far."""
        self._catch_up()
        return self._seen

    @property
    def blocker(self) -> np.ndarray:
        """Per node: the wall (index into ``_walls``) that blocked its last ray, or -1."""
        self._catch_up()
        return self._blocker

    def observe(self, guards: Iterable[Agent]) -> None:
        """Note what the active guards see now (one AI tick): their positions and headings,
        worked through in order when :attr:`seen` is next read."""
        self._pending.append([(g.pos[0], g.pos[1], g.heading) for g in guards if g.active])
        if len(self._pending) >= PENDING_TICKS:
            self._catch_up()

    def _catch_up(self) -> None:
        pending, self._pending = self._pending, []
        for active in pending:
            self._observe(active)

    def _observe(self, active: list[tuple[float, float, float]]) -> None:
        """Mark every node one tick's active guards (x, y, heading) perceive; the guards'
        nodes in range are tested together, one array per test."""
        parts = [nodes_within(self.graph, x, y, self.bound) for x, y, _ in active]
        if not parts:
            return
        near = np.concatenate(parts)
        owner = np.repeat(np.arange(len(active)), [len(p) for p in parts])
        unseen = ~self._seen[near]
        near, owner = near[unseen], owner[unseen]
        if not len(near):
            return
        pos = np.array([(x, y) for x, y, _ in active], dtype=np.float64)
        # math's cos and sin, as Senses.perceives takes them (numpy's may differ in a bit)
        cos = np.array([math.cos(h) for _, _, h in active])[owner]
        sin = np.array([math.sin(h) for _, _, h in active])[owner]
        gx, gy = pos[owner, 0], pos[owner, 1]
        keep, points, _, _ = self.in_view(near, gx, gy, cos, sin)
        keep[keep] = ~self._still_blocked(gx[keep], gy[keep], points[keep], near[keep])
        query, seen, blocker = self.senses.space.segment_query_first, self._seen, self._blocker
        for k, (px, py), (x, y) in zip(near[keep].tolist(), points[keep].tolist(),
                                       pos[owner[keep]].tolist()):
            hit = query((x, y), (px, py), 0.0, WALL_QUERY)
            if hit is None:
                seen[k] = True
            else:
                blocker[k] = self._wall_index.get(hit.shape, -1)

    def _still_blocked(self, x: np.ndarray, y: np.ndarray, points: np.ndarray,
                       nodes: np.ndarray) -> np.ndarray:
        """Per line from (x, y) to a node's point: the wall that last blocked the node's ray
        plainly crosses it — both ends of each segment strictly on either side of the
        other, beyond rounding — so the ray would hit a wall too."""
        wall = self._blocker[nodes]
        out = np.zeros(len(nodes), dtype=bool)
        known = np.flatnonzero(wall >= 0)
        if not len(known):
            return out
        ax, ay, bx, by = self._walls[wall[known]].T
        x, y = x[known], y[known]
        px, py = points[known, 0], points[known, 1]
        rx, ry, wx, wy = px - x, py - y, bx - ax, by - ay
        s_o = wx * (y - ay) - wy * (x - ax)      # the ray's ends against the wall's line
        s_p = wx * (py - ay) - wy * (px - ax)
        s_a = rx * (ay - y) - ry * (ax - x)      # the wall's ends against the ray's line
        s_b = rx * (by - y) - ry * (bx - x)
        tol = _TOLERANCE * np.hypot(rx, ry) * np.hypot(wx, wy)
        out[known] = ((s_o * s_p < 0) & (s_a * s_b < 0) & (np.minimum(
            np.minimum(np.abs(s_o), np.abs(s_p)), np.minimum(np.abs(s_a), np.abs(s_b))) > tol))
        return out

    def share(self) -> float:
        """The share of nodes seen so far (0 on an empty graph)."""
        seen = self.seen
        return float(seen.mean()) if len(seen) else 0.0
