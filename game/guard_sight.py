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

from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np
import pymunk

from navmesh.graph import NodeGraph

from .agents import Agent
from .senses import RANGE_EPS, Senses

if TYPE_CHECKING:
    from .exact import WallGrid

__all__ = ["PENDING_TICKS", "GuardSight", "ViewCover", "nodes_within"]

#: AI ticks noted before the cover is brought up to date (bounds the notes' memory)
PENDING_TICKS = 256



def _compiled() -> ModuleType:
    """The compiled loops (:mod:`game.sight_kernels`), imported at their first use: numba
    costs a second of start-up that a world which never reads the sight need not pay."""
    from . import sight_kernels

    return sight_kernels


class _NodeIndex:
    """A graph's nodes by place, as arrays the compiled loops read: the grid's own cells, or
    a partition's node positions bucketed in square cells (CSR lists) about two node
    spacings wide. Built once per graph, shared by every trial (graphs are cached)."""

    def __init__(self, graph: NodeGraph) -> None:
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
        # about four nodes a cell, whatever the view range (a window spans more cells)
        cell = max(2.0 * math.sqrt(float(np.prod(hi - lo + 1.0)) / len(pts)), 1e-3)
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
        """What :func:`game.sight_kernels.near` takes."""
        return (self.is_grid, self.positions, self.size, self.cell_node, self.start,
                self.items, self.geom)


#: per graph (graphs are cached and shared by trials): its node index
_INDEXES: weakref.WeakKeyDictionary[NodeGraph, _NodeIndex] = weakref.WeakKeyDictionary()


def _node_index(graph: NodeGraph) -> _NodeIndex:
    index = _INDEXES.get(graph)
    if index is None:
        index = _INDEXES[graph] = _NodeIndex(graph)
    return index


def nodes_within(graph: NodeGraph, x: float, y: float, radius: float) -> np.ndarray:
    """Indices of nodes whose position may lie within ``radius`` of (x, y): a superset
    (the grid's square window of cells; a partition's buckets under the disc's box)."""
    buf = np.empty(graph.n, dtype=np.int64)
    count = _compiled().near(*_node_index(graph).arrays, float(x), float(y),
                             float(radius), buf)
    return buf[:count]


class _NodeView:
    """What both readers share: the graph, the cone and, per node, the guards' view range
    for a player standing there (``reach``: the scenario's range × the node's zone scale)."""

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray,
                 walls: np.ndarray) -> None:
        self.graph, self.senses, self.cos_half_fov = graph, senses, float(senses.cos_half_fov)
        self.reach = np.asarray(reach, dtype=np.float64)
        self.limit = np.ascontiguousarray(self.reach + RANGE_EPS)
        self._wall_ends = np.asarray(walls, dtype=np.float64).reshape(-1, 4)
        self._walls: WallGrid | None = None

    @property
    def walls(self) -> WallGrid:
        """The level's walls bucketed for the compiled line tests (shared per wall set)."""
        if self._walls is None:
            from .exact import wall_grid

            self._walls = wall_grid(self._wall_ends)
        return self._walls


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
        self.index = _node_index(graph)

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
        counts, nodes = _compiled().sight(np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1]),
                               cos, sin, np.array(active, dtype=np.bool_), self.bound,
                               self.limit, self.cos_half_fov, *self.index.arrays,
                               *self.walls.arrays)
        return tuple(np.split(nodes, np.cumsum(counts)[:-1]))


class ViewCover(_NodeView):
    """Which nodes any guard's view has covered so far (:attr:`seen`, one bool per node).

    ``reach`` is the guards' view range per node (the scenario's range × the node's zone
    scale, as for the player standing there); ``walls`` the level's wall segments, by
    default the pymunk space's.
    """

    def __init__(self, graph: NodeGraph, senses: Senses, reach: np.ndarray,
                 walls: np.ndarray | None = None) -> None:
        if walls is None:  # the space's segments (the level's walls: game.agents.build_space)
            walls = np.array([(*shape.a, *shape.b) for shape in senses.space.shapes
                              if isinstance(shape, pymunk.Segment)], dtype=np.float64)
        super().__init__(graph, senses, reach, walls)
        self.bound = float(self.reach.max()) if len(self.reach) else 0.0
        self.index = _node_index(graph)
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
        _compiled().cover(self._seen, self._blocker, gx, gy, gcos, gsin, self.bound, self.limit,
               self.cos_half_fov, *self.index.arrays, *self.walls.arrays)

    def fresh(self) -> ViewCover:
        """A cover of the same graph, sight and walls that has seen nothing yet (one per
        guard: ``metrics.coverage = "seen_per_guard"``)."""
        cover = ViewCover(self.graph, self.senses, self.reach, self._wall_ends)
        cover._walls = self._walls
        return cover

    def share(self) -> float:
        """The share of nodes seen so far (0 on an empty graph)."""
        seen = self.seen
        return float(seen.mean()) if len(seen) else 0.0
