"""The nodes the guards' views have covered: ``metrics.coverage = "seen"`` (SPEC §11).

A node counts as seen when, at some AI tick, an active guard perceives its position by the
world's one vision rule (:meth:`game.senses.Senses.perceives`: within the view range scaled
by the node's zone, inside the cone, a clear line), i.e. a player standing there would
have been seen. Per guard and tick only the nodes within the view range are looked at
(the grid's cell window or a k-d tree of the partition's centroids), the range and cone
tests are vectorised over them, and only the unseen ones that pass get a ray (the one
pymunk query the player's sight uses), so a trial casts a ray per newly seen node plus one
per occluded node of each cone and tick (about 1,700 rays, 10-20 ms, in a 60-s trial on
the bundled levels).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable

import numpy as np
from scipy.spatial import cKDTree

from navmesh.graph import NodeGraph

from .agents import Agent
from .senses import RANGE_EPS, Senses

__all__ = ["ViewCover", "nodes_within"]

#: per graph (graphs are cached and shared by trials): the k-d tree of a partition's nodes
_TREES: weakref.WeakKeyDictionary[NodeGraph, cKDTree] = weakref.WeakKeyDictionary()


def nodes_within(graph: NodeGraph, x: float, y: float, radius: float) -> np.ndarray:
    """Indices of nodes whose position may lie within ``radius`` of (x, y): a superset
    (the grid's square window of cells; the partition's k-d tree ball with slack)."""
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
        self.seen = np.zeros(graph.n, dtype=bool)

    def observe(self, guards: Iterable[Agent]) -> None:
        """Mark every node an active guard perceives now (one AI tick)."""
        positions, seen, clear = self.graph.positions, self.seen, self.senses.clear_line
        cos_half = self.senses.cos_half_fov
        for guard in guards:
            if not guard.active:
                continue
            x, y = guard.pos
            near = nodes_within(self.graph, x, y, self.bound)
            near = near[~seen[near]]
            if not len(near):
                continue
            dx, dy = positions[near, 0] - x, positions[near, 1] - y
            d2 = dx * dx + dy * dy
            d = np.sqrt(d2)
            # Senses.perceives, vectorised: range (with the zone), then the cone
            keep = (d2 <= self.limit[near] ** 2) & (
                (d <= 1e-9) | (dx * math.cos(guard.heading) + dy * math.sin(guard.heading)
                               >= cos_half * d))
            near = near[keep]
            for k, point in zip(near.tolist(), positions[near].tolist()):
                if clear((x, y), (point[0], point[1])):
                    seen[k] = True

    def share(self) -> float:
        """The share of nodes seen so far (0 on an empty graph)."""
        return float(self.seen.mean()) if len(self.seen) else 0.0
