"""The nodes the guards' views have covered: ``metrics.coverage = "seen"`` (SPEC §11).

A node counts as seen when, at some AI tick, an active guard perceives its position by the
world's one vision rule (:meth:`game.senses.Senses.perceives`: within the view range scaled
by the node's zone, inside the cone, a clear line), i.e. a player standing there would
have been seen. Per guard and tick only the nodes within the view range are looked at
(the grid's cell window or a k-d tree of the partition's centroids), the range and cone
tests are vectorised over them, and only the unseen ones that pass need a line of sight.
Most of those are occluded, tick after tick: the wall that last blocked a node's ray is
kept, and a line it still crosses plainly (no end of either segment within rounding of the
other) is blocked without a ray; every other line is the pymunk query the player's sight
uses (:meth:`game.senses.Senses.clear_line`).

The work is deferred: an AI tick only notes the active guards' positions and headings, and
the notes are worked through, in tick order, when :attr:`ViewCover.seen` is read (the trial's
metrics) or when :data:`PENDING_TICKS` of them wait. The walls never move, so the answer is
the same bits as working each tick at once; an env episode that nobody scores by coverage
never pays for it.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable

import numpy as np
import pymunk
from scipy.spatial import cKDTree

from navmesh.graph import NodeGraph

from .agents import WALL_QUERY, Agent
from .senses import RANGE_EPS, Senses

__all__ = ["PENDING_TICKS", "ViewCover", "nodes_within"]

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


class ViewCover:
    """Which nodes any guard's view has covered so far (:attr:`seen`, one bool per node).

    ``reach`` is the guards' view range per node (the scenario's range × the node's zone
    scale, as for the player standing there).
    """

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray) -> None:
        self.graph, self.senses = graph, senses
        self.reach = np.asarray(reach, dtype=np.float64)
        self.limit = self.reach + RANGE_EPS
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
        points = self.graph.positions[near]
        dx, dy = points[:, 0] - gx, points[:, 1] - gy
        d2 = dx * dx + dy * dy
        d = np.sqrt(d2)
        # Senses.perceives, vectorised: range (with the zone), then the cone
        keep = (d2 <= self.limit[near] ** 2) & (
            (d <= 1e-9) | (dx * cos + dy * sin >= self.senses.cos_half_fov * d))
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
