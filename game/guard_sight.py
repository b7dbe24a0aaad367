"""The nodes each guard sees now, for guard modes that patrol by sight (``staleness.model = "view"``).

A node is seen by a guard when a player standing on it would be (:meth:`game.senses.Senses.perceives`):
within the view range scaled by the node's zone, inside the cone, and no wall of the level
between the guard and the node's position. Per guard only the nodes within the view range
are looked at (the grid's window of cells, or a k-d tree of a partition's centroids); the
range and cone tests are vectorised over them, and the line of sight is one vectorised
segment-crossing test against the walls whose bounding box meets the view's square (the
same segments the pymunk space holds). A ray that touches a wall counts as blocked. No
Python loop runs per node: the cost per guard and tick is O(walls) for the box filter plus
O(nodes in range × walls in range) for the crossings, whatever the level's size.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree

from navmesh.graph import NodeGraph

from .agents import Agent
from .senses import RANGE_EPS, Senses

__all__ = ["GuardSight", "nodes_in_square"]

#: per graph (graphs are cached and shared by trials): the k-d tree of a partition's nodes
_TREES: weakref.WeakKeyDictionary[NodeGraph, cKDTree] = weakref.WeakKeyDictionary()


def nodes_in_square(graph: NodeGraph, x: float, y: float, radius: float) -> np.ndarray:
    """Node indices that may lie within ``radius`` of (x, y): a superset (the grid's square
    window of cells; the partition's k-d tree ball with a little slack)."""
    if graph.cell_node is not None:
        size = graph.cell_size
        rows, cols = graph.cell_node.shape
        r0, r1 = max(0, math.floor((y - radius) / size)), min(rows - 1, math.floor((y + radius) / size))
        c0, c1 = max(0, math.floor((x - radius) / size)), min(cols - 1, math.floor((x + radius) / size))
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


class GuardSight:
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
        self.graph, self.cos_half_fov = graph, senses.cos_half_fov
        self.limit = np.asarray(reach, dtype=np.float64) + RANGE_EPS
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
        near = np.sort(nodes_in_square(self.graph, x, y, self.bound))
        if not len(near):
            return near
        points = self.graph.positions[near]
        dx, dy = points[:, 0] - x, points[:, 1] - y
        d2 = dx * dx + dy * dy
        d = np.sqrt(d2)
        keep = (d2 <= self.limit[near] ** 2) & (
            (d <= 1e-9) | (dx * math.cos(heading) + dy * math.sin(heading) >= self.cos_half_fov * d))
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
