"""The node graph both abstractions share (SPEC §2).

A grid level and a navmesh partition both become a :class:`NodeGraph`: node positions in
world coordinates, adjacency (CSR) and edge lengths, with hop (BFS) and metric (Dijkstra)
distance queries. The AI works on this type only and never asks which abstraction it is
running on.

Distances are computed on demand, so memory grows with the level rather than its square:
the graph picks one storage strategy of :mod:`navmesh.distances` when it is built — dense
all-pairs matrices up to 2,048 nodes (every bundled level; :func:`~navmesh.distances.keeps_dense`
decides), per-source
searches with a bounded row cache above — and delegates every query to it. Every answer is
bit-identical whichever strategy a graph holds (tests/test_graph_queries.py checks it).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from .abstractions import ABSTRACTIONS
from .clearance import DEFAULT_AGENT_RADIUS, clearance_for
from .distances import (
    ROW_CACHE_BYTES,
    UNREACHABLE_HOPS,
    Distances,
    RowCache,
    SlicedSearch,
    distances_for,
    keeps_dense,
)

if TYPE_CHECKING:
    from .level import Level
    from .mesh import NavMesh


__all__ = ["ABSTRACTIONS", "ROW_CACHE_BYTES", "UNREACHABLE_HOPS", "Neighbours",
           "NodeGraph", "RowCache", "SlicedSearch", "build_graph", "falloff_depth", "graph_for",
           "hop_ball_pairs"]


def falloff_depth(base: float, tolerance: float = 1e-12) -> int | None:
    """The largest hop count d with ``base ** d ≥ tolerance`` (None when base ≥ 1: no cut-off).

    A field that spreads ``base ** d`` from a source is exactly 0 beyond this depth: the
    dropped terms are below ``tolerance`` (1e-12, far below the 1e-9 tie threshold of every
    argmin), so a search may stop there.

    >>> falloff_depth(0.8), falloff_depth(0.9), falloff_depth(1.0)
    (123, 262, None)
    """
    if base >= 1.0:
        return None
    if base <= 0.0:
        return 0
    depth = int(np.floor(np.log(tolerance) / np.log(base)))
    while base ** (depth + 1) >= tolerance:  # guard the floor against rounding either way
        depth += 1
    while depth > 0 and base**depth < tolerance:
        depth -= 1
    return depth


class Neighbours(Sequence[np.ndarray]):
    """Per-node neighbour lists backed by two CSR arrays (no Python object per node)."""

    def __init__(self, indptr: np.ndarray, indices: np.ndarray) -> None:
        self.indptr, self.indices = indptr, indices
        self.indices.flags.writeable = False

    def __len__(self) -> int:
        return len(self.indptr) - 1

    def __getitem__(self, node):
        if isinstance(node, slice):
            return [self[i] for i in range(*node.indices(len(self)))]
        node = int(node)
        if node < 0:
            node += len(self)
        return self.indices[self.indptr[node] : self.indptr[node + 1]]

    def __iter__(self) -> Iterator[np.ndarray]:
        for node in range(len(self)):
            yield self.indices[self.indptr[node] : self.indptr[node + 1]]

    @classmethod
    def from_lists(cls, lists: Sequence[Sequence[int]] | Sequence[np.ndarray]) -> Neighbours:
        """Pack per-node lists (kept in their given order)."""
        if isinstance(lists, Neighbours):
            return lists
        lengths = np.fromiter((len(nb) for nb in lists), dtype=np.int64, count=len(lists))
        indptr = np.zeros(len(lists) + 1, dtype=np.int64)
        np.cumsum(lengths, out=indptr[1:])
        parts = [np.asarray(nb, dtype=np.int64) for nb in lists]
        indices = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
        return cls(indptr, indices.astype(np.int64, copy=False))


@dataclass(eq=False)
class NodeGraph:
    """Nodes, adjacency and distance queries of one level in one abstraction.

    Build it with :meth:`from_grid` or :meth:`from_mesh`. ``dense`` chooses the storage of
    distances (None: as :func:`~navmesh.distances.keeps_dense` says for its size); it never changes a result.

    >>> import numpy as np
    >>> g = NodeGraph.from_grid(np.array([[True, True, True]]), 1.0)
    >>> g.hops_from(0).tolist(), g.dist_between(0, 2), g.positions[2].tolist()
    ([0, 1, 2], 2.0, [2.5, 0.5])
    """

    kind: str
    positions: np.ndarray
    neighbors: Sequence[np.ndarray]
    mesh: NavMesh | None = None
    cell_size: float = 1.0
    #: grid only: (rows, cols) array mapping a cell to its node index, -1 for blocked cells
    cell_node: np.ndarray | None = None
    #: grid only: (n, 2) array of (row, col) per node
    node_cell: np.ndarray | None = None
    #: dense all-pairs matrices (True), per-source searches (False) or by size (None)
    dense: bool | None = None
    adjacency: csr_matrix = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.neighbors = Neighbours.from_lists(self.neighbors)
        n = len(self.positions)
        nb = self.neighbors
        rows = np.repeat(np.arange(n), np.diff(nb.indptr))
        cols = nb.indices
        lengths = np.linalg.norm(self.positions[rows] - self.positions[cols], axis=1)
        self.adjacency = csr_matrix((lengths, (rows, cols)), shape=(n, n))
        if self.dense is None:
            self.dense = keeps_dense(n)
        self._labels: np.ndarray | None = None
        self._longest: float | None = None
        #: the storage strategy every distance query goes to (chosen here, once)
        self.distances: Distances = distances_for(self.adjacency, lambda: self._neighbour_table,
                                                  bool(self.dense))

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_grid(cls, occupancy: np.ndarray, cell_size: float, dense: bool | None = None,
                  moves: tuple[np.ndarray, np.ndarray] | None = None) -> NodeGraph:
        """Walkable cells as nodes (row-major order), 4-neighbourhood, cell-centre positions.

        ``moves``: (right, down) boolean arrays of the occupancy's shape saying whether the
        move to the cell on the right / below is clear for a body
        (:class:`navmesh.clearance.Clearance`); without it every pair of walkable cells is.
        """
        occupancy = np.asarray(occupancy, dtype=bool)
        node_cell = np.argwhere(occupancy)
        cell_node = np.full(occupancy.shape, -1, dtype=np.int64)
        cell_node[node_cell[:, 0], node_cell[:, 1]] = np.arange(len(node_cell))
        padded = np.pad(cell_node, 1, constant_values=-1)
        r, c = node_cell[:, 0] + 1, node_cell[:, 1] + 1
        # Up, down, left, right: a fixed order so neighbour lists are reproducible.
        around = np.stack(
            [padded[r - 1, c], padded[r + 1, c], padded[r, c - 1], padded[r, c + 1]], axis=1
        )
        if moves is not None:
            right, down = (np.pad(np.asarray(m, dtype=bool), 1) for m in moves)
            clear = np.stack(
                [down[r - 1, c], down[r, c], right[r, c - 1], right[r, c]], axis=1)
            around = np.where(clear, around, -1)
        positions = (node_cell[:, ::-1] + 0.5) * cell_size
        return cls(
            kind="grid",
            positions=positions.astype(np.float64),
            neighbors=_pack(around),
            cell_size=cell_size,
            cell_node=cell_node,
            node_cell=node_cell,
            dense=dense,
        )

    @classmethod
    def from_mesh(cls, mesh: NavMesh, dense: bool | None = None) -> NodeGraph:
        """Triangle centroids as nodes; triangles sharing an edge are neighbours."""
        return cls(
            kind="partition",
            positions=np.asarray(mesh.centroids, dtype=np.float64),
            neighbors=_pack(np.sort(np.asarray(mesh.neighbors), axis=1)),
            mesh=mesh,
            dense=dense,
        )

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        """Number of nodes."""
        return len(self.positions)

    @property
    def degree(self) -> np.ndarray:
        """Number of neighbours of every node."""
        return np.diff(self.adjacency.indptr)

    @property
    def max_degree(self) -> int:
        """κ of the connectivity field: the largest degree in the graph."""
        return int(self.degree.max()) if self.n else 0

    @property
    def mean_edge_length(self) -> float:
        """Mean centre-to-centre distance over all edges."""
        return float(self.adjacency.data.mean()) if self.adjacency.nnz else 0.0

    @property
    def max_edge_length(self) -> float:
        """The longest centre-to-centre edge."""
        return float(self.adjacency.data.max()) if self.adjacency.nnz else 0.0

    # ------------------------------------------------------------------ locating
    def node_at(self, x: float, y: float) -> int:
        """The node whose cell or triangle contains (x, y); the nearest node otherwise."""
        if self.cell_node is not None:
            # math.floor of the same quotient as np.floor, on Python lists: a numpy scalar
            # round trip costs more than the rest of the lookup (an agent per physics step)
            row, col = math.floor(y / self.cell_size), math.floor(x / self.cell_size)
            cells = self._cell_rows
            if 0 <= row < len(cells) and 0 <= col < len(cells[0]) and cells[row][col] >= 0:
                return cells[row][col]
        elif self.mesh is not None:
            tri = self.mesh.locate(x, y)
            if tri >= 0:
                return int(tri)
        return self.nearest_node(x, y)

    @cached_property
    def _cell_rows(self) -> list[list[int]]:
        """``cell_node`` as nested Python lists (grid graphs only), for :meth:`node_at`."""
        return np.asarray(self.cell_node).tolist()

    def node_near(self, x: float, y: float, hint: int) -> int:
        """:meth:`node_at` for a walker last seen on node ``hint`` (usually still there)."""
        if self.mesh is not None and hint >= 0 and self.mesh.triangle_contains(hint, x, y):
            return hint
        return self.node_at(x, y)

    def nearest_node(self, x: float, y: float) -> int:
        """The node whose position is closest to (x, y) in straight-line distance."""
        d2 = np.sum((self.positions - (x, y)) ** 2, axis=1)
        return int(np.argmin(d2))

    # ------------------------------------------------------------------ hop distances
    def hops_from(self, src: int | Sequence[int] | np.ndarray, max_hops: int | None = None) -> np.ndarray:
        """BFS hop distances from ``src`` (an int: (n,); several: (k, n)), int32, read-only.

        :data:`UNREACHABLE_HOPS` where unreachable or farther than ``max_hops``; a bounded
        search on a large graph only visits the ball of radius ``max_hops``.
        """
        if not np.isscalar(src) and np.ndim(src) > 0:
            return self.distances.hops_rows(np.asarray(src, dtype=np.intp), max_hops)
        return self.distances.hops_row(int(np.asarray(src)), max_hops)

    def hop_ball(self, src: int, max_hops: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The nodes within ``max_hops`` of ``src`` (sorted) and their hop distances (int32):
        the finite part of :meth:`hops_from`, without keeping an (n,) row on a large graph."""
        return self.distances.hop_ball(int(src), max_hops)

    def hop_search(self, src: int, max_hops: int | None = None) -> SlicedSearch:
        """:meth:`hop_ball` as a breadth-first search the caller runs a ring at a time
        (:class:`~navmesh.distances.SlicedSearch`), so a caller with a time budget can spread
        one ball over several frames; it finds the same sorted nodes and hops."""
        return self.distances.hop_search(int(src), max_hops)

    @cached_property
    def _neighbour_table(self) -> np.ndarray:
        """(n, max degree) neighbours of every node, padded with the node index n."""
        nb = self.neighbors
        counts = np.diff(nb.indptr)  # type: ignore[attr-defined]
        table = np.full((self.n, max(self.max_degree, 1)), self.n, dtype=np.intp)
        slots = np.arange(table.shape[1]) < counts[:, None]
        table[slots] = nb.indices  # type: ignore[attr-defined]
        return table

    def hops_between(self, a: int | np.ndarray | Sequence[int], b: int | np.ndarray | Sequence[int]) -> np.ndarray | int:
        """Hop distance of each pair (a[i], b[i]) (broadcast like numpy indexing)."""
        found = self.distances.hops_between(a, b)
        return int(found) if found.ndim == 0 else found

    # ------------------------------------------------------------------ metric distances
    def dist_from(self, src: int | Sequence[int] | np.ndarray, limit: float | None = None) -> np.ndarray:
        """Shortest-path distances from ``src`` (an int: (n,); several: (k, n)), read-only.

        ``inf`` where unreachable or (with ``limit``) farther than ``limit``; a limited
        search on a large graph only visits the nodes within it. Row i is the search from
        ``src[i]``: d(a, b) is summed from a, so it may differ from d(b, a) in the last bit.
        """
        if not np.isscalar(src) and np.ndim(src) > 0:
            return self.distances.dist_rows(np.asarray(src, dtype=np.intp), limit)
        return self.distances.dist_row(int(np.asarray(src)), limit)

    def dist_between(self, a: int | np.ndarray | Sequence[int], b: int | np.ndarray | Sequence[int]) -> np.ndarray | float:
        """d(a[i], b[i]) of each pair (broadcast like numpy indexing), searched from a."""
        found = self.distances.dist_between(a, b)
        return float(found) if found.ndim == 0 else found

    def nearest_dist(
        self,
        srcs: Sequence[int] | np.ndarray,
        limit: float | None = None,
        around: int | None = None,
        reach: float = 0.0,
    ) -> np.ndarray:
        """(n,) ``min_s d(s, ·)`` over the sources (one multi-source search on a large graph).

        Equal to ``dist_from(srcs).min(axis=0)`` bit for bit: each node's value is the least
        rounded path sum from any source either way (a search stopped at a limit leaves the
        values inside it unchanged). ``inf`` with no source. With ``around``, only the nodes
        within metric distance ``reach`` of node ``around`` are promised (others may be
        ``inf``). A large graph answers every unlimited call with one search over the whole
        graph per set of sources, cached (measured faster than a search bounded at the
        nearest source, which needs a second search to find that bound).
        """
        del around, reach  # a full row keeps every promise
        nodes = np.asarray(srcs, dtype=np.intp).ravel()
        if not len(nodes):
            return np.full(self.n, np.inf)
        return self.distances.nearest(nodes, limit)

    def nearest_dist_to(self, srcs: Sequence[int] | np.ndarray, target: int) -> float:
        """``min_s d(s, target)``: :meth:`nearest_dist` at one node."""
        nodes = np.asarray(srcs, dtype=np.intp).ravel()
        if not len(nodes):
            return np.inf
        return self.distances.nearest_to(nodes, int(target))

    def nearest_dist_to_rows(self, srcs: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """(k,) :meth:`nearest_dist_to` of many source sets at once: row i of ``srcs``
        (k, g) holds the sources of ``targets[i]``, entries < 0 none (``inf``: no source)."""
        srcs = np.asarray(srcs, dtype=np.intp).reshape(len(targets), -1)
        return self.distances.nearest_to_rows(srcs, np.asarray(targets, dtype=np.intp))

    def components(self) -> np.ndarray:
        """(n,) label of every node's connected piece."""
        if self._labels is None:
            _, self._labels = connected_components(self.adjacency, directed=False)
        return self._labels

    def reachable_from(self, node: int) -> np.ndarray:
        """(n,) bool: the nodes connected to ``node`` (``isfinite(dist_from(node))``)."""
        labels = self.components()
        return labels == labels[int(node)]

    def longest_shortest_path(self) -> float:
        """The longest finite shortest-path distance between two nodes (at least 1e-9; Al Enezi
        & Verbrugge's ``longestShortestPath``, ``staleness.model = "alenezi"``). Exact on a
        graph that keeps its distances dense (read from the matrix); on a larger one the
        double sweep's value (the farthest node from the farthest node of node 0: a lower
        bound, exact on trees), so no all-pairs search runs. Cached.

        >>> NodeGraph.from_grid(np.ones((2, 4), bool), 1.0).longest_shortest_path()
        4.0
        """
        if self._longest is None:
            if self.n == 0:
                found = 0.0
            elif self.dense:
                rows = self.dist_from(np.arange(self.n))
                found = float(rows[np.isfinite(rows)].max())
            else:
                first = self.dist_from(0)
                far = int(np.argmax(np.where(np.isfinite(first), first, -1.0)))
                second = self.dist_from(far)
                found = float(second[np.isfinite(second)].max())
            self._longest = max(found, 1e-9)
        return self._longest

    # ------------------------------------------------------------------ paths
    def shortest_path(self, a: int, b: int) -> list[int]:
        """Nodes of the metric shortest path from a to b, both included."""
        if a == b:
            return [a]
        path = [b]
        pred = self.distances.dist_pred(int(a))[1]
        while path[-1] != a:
            prev = int(pred[path[-1]])
            if prev < 0:
                raise ValueError(f"node {b} is not reachable from node {a}")
            path.append(prev)
        return path[::-1]

    def next_hop(self, a: int, b: int) -> int:
        """The first node after a on the shortest path from a to b (a itself when a == b)."""
        path = self.shortest_path(a, b)
        return path[1] if len(path) > 1 else a

    def step_towards(self, a: int, b: int, horizon: float) -> int:
        """The farthest node on the shortest path a→b within metric distance ``horizon`` of a.

        Always at least one hop (unless a == b), so a walker makes progress; on the grid call
        it with a horizon below two cell sizes to move one cell at a time.
        """
        if a == b:
            return a
        from . import path_kernels  # numba: loaded by the first walker that asks

        dist, pred = self.distances.dist_pred(int(a))
        node = int(path_kernels.step_towards(pred, dist, int(a), int(b), float(horizon)))
        if node < 0:
            raise ValueError(f"node {b} is not reachable from node {a}")
        return node


def _pack(table: np.ndarray) -> Neighbours:
    """Neighbour lists from an (n, k) table padded with negative entries, row order kept."""
    table = np.asarray(table, dtype=np.int64)
    valid = table >= 0
    indptr = np.zeros(len(table) + 1, dtype=np.int64)
    np.cumsum(valid.sum(axis=1), out=indptr[1:])
    return Neighbours(indptr, table[valid])


def hop_ball_pairs(graph: NodeGraph, radius: int, max_pairs: int | None = None,
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every pair (x, y) with ``hops(x, y) ≤ radius``: rows, cols and hops, in row-major order.

    A truncated BFS from every node at once by sparse products: with ``R_k`` the pairs
    within k hops (``R_k = R_{k-1} (I + A)``), ``Σ_{k ≤ K} R_k`` counts ``K + 1 − hops``.
    Memory grows with the ball sizes, not with n²; the search stops once no ball grows (a
    radius past the graph's diameter costs no more than the diameter), and raises
    :class:`BallTooLarge` once more than ``max_pairs`` pairs are within reach.
    """
    from scipy.sparse import identity

    n = graph.n
    step = (graph.adjacency != 0).astype(np.int32) + identity(n, dtype=np.int32, format="csr")
    reach = identity(n, dtype=np.int32, format="csr")
    counts = reach.copy()
    rounds = 0
    while rounds < int(radius):
        grown = reach @ step
        grown.data[:] = 1
        rounds += 1
        if max_pairs is not None and grown.nnz > max_pairs:
            raise BallTooLarge(rounds, grown.nnz)
        if grown.nnz == reach.nnz:  # every ball is its component: more rounds add nothing
            counts = counts + grown
            break
        reach = grown
        counts = counts + reach
    counts = counts.tocsr()
    counts.sum_duplicates()
    counts.sort_indices()
    coo = counts.tocoo()
    hops = (rounds + 1 - coo.data).astype(np.int64)
    return coo.row.astype(np.intp), coo.col.astype(np.intp), hops


class BallTooLarge(ValueError):
    """:func:`hop_ball_pairs` past its ``max_pairs``: ``pairs`` within ``hops`` hops."""

    def __init__(self, hops: int, pairs: int) -> None:
        super().__init__(f"{pairs} node pairs within {hops} hops")
        self.hops, self.pairs = hops, pairs


def build_graph(level: Level, abstraction: str,
                radius: float = DEFAULT_AGENT_RADIUS) -> NodeGraph:
    """Build the node graph of ``level`` in ``abstraction`` ("grid" or "partition").

    On the grid only cells a body of ``radius`` can reach are nodes, joined where the
    move is clear for it (:mod:`navmesh.clearance`); radius 0 is the bare cell grid. The
    partition's navmesh is bounded before it is triangulated
    (:func:`navmesh.sizing.check_mesh_work`: a one-line LevelError past its limits).
    """
    if abstraction == "grid":
        if radius <= 0:
            return NodeGraph.from_grid(level.occupancy, level.cell_size)
        body = clearance_for(level, radius)
        return NodeGraph.from_grid(body.grid_cells, level.cell_size,
                                   moves=(body.right_clear, body.down_clear))
    if abstraction == "partition":
        from .mesh import NavMesh
        from .sizing import check_mesh_work

        check_mesh_work(level)  # refuse before GEOS starts what would not end (issue 24)
        return NodeGraph.from_mesh(NavMesh.build(level.walkable))
    raise ValueError(f"unknown abstraction {abstraction!r} (choose grid or partition)")


@dataclass(frozen=True)
class _GraphKey:
    """A level's content identity and an abstraction; carries (but is not keyed on) the level."""

    digest: str
    abstraction: str
    radius: float
    level: Level = field(compare=False, repr=False)


@lru_cache(maxsize=32)
def _cached_graph(key: _GraphKey) -> NodeGraph:
    return build_graph(key.level, key.abstraction, key.radius)


def graph_for(level: Level, abstraction: str,
              radius: float = DEFAULT_AGENT_RADIUS) -> NodeGraph:
    """The node graph of a level for a body of ``radius`` (``world.agent_radius``), cached
    per process on the level's content (``Level.digest``), abstraction and radius.

    The graph is always built from the level given, so it matches it even when the file
    changed since; levels built in memory (no digest) are not cached.
    """
    if level.digest is not None:
        return _cached_graph(_GraphKey(level.digest, abstraction, float(radius), level))
    return build_graph(level, abstraction, radius)
