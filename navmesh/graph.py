"""The node graph both abstractions share (SPEC §2).

A grid level and a navmesh partition both become a :class:`NodeGraph`: node positions in
world coordinates, adjacency, edge lengths, the BFS hop-distance matrix and the metric
shortest-path matrix. The AI works on this type only and never asks which abstraction it
is running on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Literal

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path

from .clearance import DEFAULT_AGENT_RADIUS, clearance_for

if TYPE_CHECKING:
    from .level import Level
    from .mesh import NavMesh

Abstraction = Literal["grid", "partition"]
ABSTRACTIONS: tuple[str, ...] = ("grid", "partition")

#: Hop distance used for node pairs that are not connected (never happens on a valid level).
UNREACHABLE_HOPS = np.iinfo(np.int32).max // 4


@dataclass(eq=False)
class NodeGraph:
    """Nodes, adjacency and all-pairs distances of one level in one abstraction.

    Build it with :meth:`from_grid` or :meth:`from_mesh`; the matrices are computed once.

    >>> import numpy as np
    >>> g = NodeGraph.from_grid(np.array([[True, True, True]]), 1.0)
    >>> g.hops[0].tolist(), g.positions[2].tolist()
    ([0, 1, 2], [2.5, 0.5])
    """

    kind: str
    positions: np.ndarray
    neighbors: tuple[np.ndarray, ...]
    mesh: NavMesh | None = None
    cell_size: float = 1.0
    #: grid only: (rows, cols) array mapping a cell to its node index, -1 for blocked cells
    cell_node: np.ndarray | None = None
    #: grid only: (n, 2) array of (row, col) per node
    node_cell: np.ndarray | None = None
    adjacency: csr_matrix = field(init=False, repr=False)
    hops: np.ndarray = field(init=False, repr=False)
    dist: np.ndarray = field(init=False, repr=False)
    _pred: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = len(self.positions)
        rows = np.repeat(np.arange(n), [len(nb) for nb in self.neighbors])
        cols = np.concatenate(self.neighbors) if n else np.zeros(0, dtype=np.int64)
        lengths = np.linalg.norm(self.positions[rows] - self.positions[cols], axis=1)
        self.adjacency = csr_matrix((lengths, (rows, cols)), shape=(n, n))
        hop_matrix = shortest_path(self.adjacency, method="D", unweighted=True)
        hop_matrix[~np.isfinite(hop_matrix)] = UNREACHABLE_HOPS
        self.hops = hop_matrix.astype(np.int32)
        self.dist, self._pred = shortest_path(
            self.adjacency, method="D", directed=False, return_predecessors=True
        )

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_grid(cls, occupancy: np.ndarray, cell_size: float,
                  moves: tuple[np.ndarray, np.ndarray] | None = None) -> NodeGraph:
        """Walkable cells as nodes (row-major order), 4-neighbourhood, cell-centre positions.

        ``moves``: (right, down) boolean arrays of the occupancy's shape saying whether the
        move to the cell on the right / below is clear for a body
        (:class:`navmesh.clearance.Clearance`); without it every pair of walkable cells is.
        """
        occupancy = np.asarray(occupancy, dtype=bool)
        rows, cols = occupancy.shape
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
        neighbors = tuple(row[row >= 0] for row in around)
        positions = (node_cell[:, ::-1] + 0.5) * cell_size
        return cls(
            kind="grid",
            positions=positions.astype(np.float64),
            neighbors=neighbors,
            cell_size=cell_size,
            cell_node=cell_node,
            node_cell=node_cell,
        )

    @classmethod
    def from_mesh(cls, mesh: NavMesh) -> NodeGraph:
        """Triangle centroids as nodes; triangles sharing an edge are neighbours."""
        neighbors = tuple(np.sort(row[row >= 0]) for row in np.asarray(mesh.neighbors))
        return cls(
            kind="partition",
            positions=np.asarray(mesh.centroids, dtype=np.float64),
            neighbors=neighbors,
            mesh=mesh,
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

    # ------------------------------------------------------------------ queries
    def node_at(self, x: float, y: float) -> int:
        """The node whose cell or triangle contains (x, y); the nearest node otherwise."""
        if self.cell_node is not None:
            row, col = int(np.floor(y / self.cell_size)), int(np.floor(x / self.cell_size))
            rows, cols = self.cell_node.shape
            if 0 <= row < rows and 0 <= col < cols and self.cell_node[row, col] >= 0:
                return int(self.cell_node[row, col])
        elif self.mesh is not None:
            tri = self.mesh.locate(x, y)
            if tri >= 0:
                return int(tri)
        return self.nearest_node(x, y)

    def node_near(self, x: float, y: float, hint: int) -> int:
        """:meth:`node_at` for a walker last seen on node ``hint`` (usually still there)."""
        if self.mesh is not None and hint >= 0 and self.mesh.triangle_contains(hint, x, y):
            return hint
        return self.node_at(x, y)

    def nearest_node(self, x: float, y: float) -> int:
        """The node whose position is closest to (x, y) in straight-line distance."""
        d2 = np.sum((self.positions - (x, y)) ** 2, axis=1)
        return int(np.argmin(d2))

    def shortest_path(self, a: int, b: int) -> list[int]:
        """Nodes of the metric shortest path from a to b, both included."""
        if a == b:
            return [a]
        path = [b]
        pred = self._pred[a]
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
        path = self.shortest_path(a, b)
        if len(path) == 1:
            return a
        along = self.dist[a, path]
        within = np.nonzero(along <= horizon + 1e-9)[0]
        return path[max(1, int(within[-1]))]


def build_graph(level: Level, abstraction: str,
                radius: float = DEFAULT_AGENT_RADIUS) -> NodeGraph:
    """Build the node graph of ``level`` in ``abstraction`` ("grid" or "partition").

    On the grid only cells a body of ``radius`` can reach are nodes, joined where the
    move is clear for it (:mod:`navmesh.clearance`); radius 0 is the bare cell grid.
    """
    if abstraction == "grid":
        if radius <= 0:
            return NodeGraph.from_grid(level.occupancy, level.cell_size)
        body = clearance_for(level, radius)
        return NodeGraph.from_grid(body.grid_cells, level.cell_size,
                                   moves=(body.right_clear, body.down_clear))
    if abstraction == "partition":
        from .mesh import NavMesh

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
