"""How a node graph answers distance queries: one interface, two storage strategies.

:class:`DenseDistances` computes the all-pairs hop and metric matrices once (cheapest on a
small graph); :class:`SearchedDistances` answers each query with a search from the source —
metric distances by :func:`scipy.sparse.csgraph.dijkstra`, hop counts by a breadth-first
search ring by ring — keeping the last rows in a cache bounded in bytes. A graph picks one
when it is built (:class:`~navmesh.graph.NodeGraph`, by its size) and delegates every query
to it; no caller asks which it got. Metric queries run the same per-source search on the
same CSR matrix either way and hop counts are exact integers, so every answer is
bit-identical whichever strategy a graph holds (tests/test_graph_queries.py).

A hop ball can also be searched in slices (:class:`SlicedSearch`, after Detour's sliced
``findPath``: start, ``update`` with the caller's budget of rings, ``finish``), so a caller
with a frame budget can spread one search over several frames.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Generator, Hashable
from typing import Any

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra, shortest_path

#: Hop distance used for node pairs that are not connected (or beyond a search's max_hops).
UNREACHABLE_HOPS = np.iinfo(np.int32).max // 4

#: Graphs with at most this many nodes keep dense all-pairs matrices (20 bytes × n²:
#: 84 MB at the limit); larger ones search per source. Results are the same either way.
#: Compared in one place only: :func:`keeps_dense`.
DENSE_MAX_NODES = 2048

#: Bytes of per-source distance rows a searched graph keeps (least recently used go first).
ROW_CACHE_BYTES = 256 * 2**20


class RowCache:
    """Least-recently-used per-key arrays, bounded by their total bytes."""

    def __init__(self, max_bytes: int) -> None:
        self.max_bytes, self.bytes = max_bytes, 0
        self._rows: OrderedDict[Hashable, tuple[np.ndarray, ...]] = OrderedDict()

    def __contains__(self, key: Hashable) -> bool:
        return key in self._rows

    def get(self, key: Hashable, make: Callable[[], tuple[np.ndarray, ...]]) -> tuple[np.ndarray, ...]:
        rows = self._rows.get(key)
        if rows is not None:
            self._rows.move_to_end(key)
            return rows
        rows = make()
        for row in rows:
            if isinstance(row, np.ndarray):
                row.flags.writeable = False
        size = sum(_nbytes(row) for row in rows)
        while self._rows and self.bytes + size > self.max_bytes:
            _, old = self._rows.popitem(last=False)
            self.bytes -= sum(_nbytes(row) for row in old)
        if size <= self.max_bytes:
            self._rows[key] = rows
            self.bytes += size
        return rows


def _nbytes(value: object) -> int:
    """Bytes of an array or of a sparse matrix's three arrays."""
    if isinstance(value, np.ndarray):
        return value.nbytes
    return sum(getattr(value, part).nbytes for part in ("data", "indices", "indptr"))


def _as_hops(found: np.ndarray) -> np.ndarray:
    """A float hop array from a search as int32, :data:`UNREACHABLE_HOPS` where infinite."""
    out = np.full(found.shape, UNREACHABLE_HOPS, dtype=np.int32)
    finite = np.isfinite(found)
    out[finite] = found[finite]
    return out


def _read_only(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


def _rings(table: np.ndarray, src: int, max_hops: int | None,
           ) -> Generator[None, None, tuple[np.ndarray, np.ndarray]]:
    """A breadth-first search from ``src`` that pauses (yields) after each ring and returns
    the sorted nodes within ``max_hops`` and their hops (int32). A ring is one gather from
    the padded neighbour table (``table``: (n, max degree), padded with n) and a few vector
    operations, without the (n,) setup of a scipy search."""
    n = len(table)
    visited = np.zeros(n + 1, dtype=bool)
    visited[n] = True  # the padding's node: never entered
    slot = np.empty(n + 1, dtype=np.intp)  # dedup without sorting: last write wins
    hop = np.empty(n + 1, dtype=np.int32)
    ring = np.array([int(src)], dtype=np.intp)
    visited[ring] = True
    hop[ring] = 0
    rings = 1
    depth = n if max_hops is None else int(max_hops)
    while len(ring) and rings <= depth:
        reached = table[ring].ravel()
        reached = reached[~visited[reached]]
        order = np.arange(len(reached))
        slot[reached] = order
        ring = reached[slot[reached] == order]
        visited[ring] = True
        hop[ring] = rings
        rings += 1
        yield
    nodes = np.flatnonzero(visited[:n])
    return nodes, hop[nodes]


class SlicedSearch:
    """A hop ball searched a ring at a time: :meth:`update` with a budget of rings, then
    :meth:`finish` (which completes what is left). The result is the same sorted nodes and
    hop counts however the search was sliced.

    >>> table = np.array([[1, 3], [0, 2], [1, 3]])  # a path 0-1-2, padded with n = 3
    >>> search = SlicedSearch(table, 0, None)
    >>> search.update(1), search.done
    (False, False)
    >>> [a.tolist() for a in search.finish()]
    [[0, 1, 2], [0, 1, 2]]
    """

    def __init__(self, table: np.ndarray, src: int, max_hops: int | None) -> None:
        self.src, self.max_hops = int(src), max_hops
        self._rings = _rings(table, self.src, max_hops)
        self._result: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def done(self) -> bool:
        """Whether the search has found its whole ball."""
        return self._result is not None

    def update(self, max_rings: int = 1) -> bool:
        """Search at most ``max_rings`` more rings (at least one step); True once done."""
        for _ in range(max(int(max_rings), 1)):
            if self._result is not None:
                break
            try:
                next(self._rings)
            except StopIteration as finished:
                self._result = finished.value
        return self._result is not None

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """The ball: (sorted nodes, int32 hops), searching what is left first."""
        while not self.update(1 << 30):
            pass
        assert self._result is not None
        return self._result


class Distances:
    """The queries every storage strategy answers, in the same bits.

    ``adjacency`` is the graph's symmetric CSR matrix of edge lengths, ``table`` a function
    giving its padded (n, max degree) neighbour table (built on first use).
    """

    #: whether the all-pairs matrices are kept (what :attr:`NodeGraph.dense` reports)
    dense: bool = False

    def __init__(self, adjacency: csr_matrix, table: Callable[[], np.ndarray]) -> None:
        self.adjacency, self._table = adjacency, table
        self.n = adjacency.shape[0]

    # hop counts
    def hops_row(self, s: int, max_hops: int | None) -> np.ndarray:
        """(n,) int32 hops from ``s``, :data:`UNREACHABLE_HOPS` beyond ``max_hops`` (read-only)."""
        raise NotImplementedError

    def hops_rows(self, nodes: np.ndarray, max_hops: int | None) -> np.ndarray:
        """(k, n): :meth:`hops_row` of every node of ``nodes``."""
        if not len(nodes):
            return np.zeros((0, self.n), dtype=np.int32)
        return np.stack([self.hops_row(int(s), max_hops) for s in nodes])

    def hop_ball(self, s: int, max_hops: int | None) -> tuple[np.ndarray, np.ndarray]:
        """The nodes within ``max_hops`` of ``s`` (sorted) and their int32 hops."""
        return SlicedSearch(self._table(), s, max_hops).finish()

    def hop_search(self, s: int, max_hops: int | None) -> SlicedSearch:
        """:meth:`hop_ball` as a search the caller runs in slices."""
        return SlicedSearch(self._table(), s, max_hops)

    def hops_between(self, a: Any, b: Any) -> np.ndarray:
        """Hop distance of each pair (a[i], b[i]) (broadcast like numpy indexing)."""
        return self._pairwise(a, b, lambda s: self.hops_row(s, None), np.int32)

    # metric distances
    def dist_pred(self, s: int) -> tuple[np.ndarray, np.ndarray]:
        """(n,) distances from ``s`` and the shortest-path predecessors (read-only)."""
        raise NotImplementedError

    def dist_row(self, s: int, limit: float | None) -> np.ndarray:
        """(n,) distances from ``s``, ``inf`` beyond ``limit`` (read-only)."""
        raise NotImplementedError

    def dist_rows(self, nodes: np.ndarray, limit: float | None) -> np.ndarray:
        """(k, n): :meth:`dist_row` of every node of ``nodes``."""
        if not len(nodes):
            return np.zeros((0, self.n))
        return np.stack([self.dist_row(int(s), limit) for s in nodes])

    def dist_between(self, a: Any, b: Any) -> np.ndarray:
        """d(a[i], b[i]) of each pair, searched from a."""
        return self._pairwise(a, b, lambda s: self.dist_row(s, None), np.float64)

    def nearest(self, nodes: np.ndarray, limit: float | None) -> np.ndarray:
        """(n,) ``min_s d(s, ·)`` over the (non-empty) ``nodes``, ``inf`` beyond ``limit``."""
        raise NotImplementedError

    def nearest_to(self, nodes: np.ndarray, target: int) -> float:
        """``min_s d(s, target)`` over the (non-empty) ``nodes``."""
        return float(self.nearest(nodes, None)[target])

    def nearest_to_rows(self, srcs: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """(k,) :meth:`nearest_to` of each row: ``min_j d(srcs[i, j], targets[i])`` over
        the row's sources (entries < 0 are none; ``inf`` for a row without any)."""
        out = np.full(len(targets), np.inf)
        for i, (row, target) in enumerate(zip(srcs.tolist(), targets.tolist(), strict=True)):
            nodes = np.array([s for s in row if s >= 0], dtype=np.intp)
            if len(nodes):
                out[i] = self.nearest_to(nodes, int(target))
        return out

    def _pairwise(self, a: Any, b: Any, row: Callable[[int], np.ndarray], dtype: type) -> np.ndarray:
        """Each pair's value from one per-source row per source."""
        a_arr, b_arr = np.broadcast_arrays(np.asarray(a, dtype=np.intp), np.asarray(b, dtype=np.intp))
        out: np.ndarray = np.empty(a_arr.shape, dtype=dtype)
        for s in np.unique(a_arr):
            mask = a_arr == s
            out[mask] = row(int(s))[b_arr[mask]]
        return out


class DenseDistances(Distances):
    """All-pairs hop and metric matrices (and predecessors), computed once: 20 bytes × n²."""

    dense = True

    def __init__(self, adjacency: csr_matrix, table: Callable[[], np.ndarray]) -> None:
        super().__init__(adjacency, table)
        self._hops = _as_hops(shortest_path(adjacency, method="D", unweighted=True))
        self._dist, self._pred = shortest_path(adjacency, method="D", directed=False,
                                               return_predecessors=True)

    def hops_row(self, s: int, max_hops: int | None) -> np.ndarray:
        row = self._hops[s]
        if max_hops is None:
            return row
        return _read_only(np.where(row <= max_hops, row, UNREACHABLE_HOPS).astype(np.int32))

    def hops_rows(self, nodes: np.ndarray, max_hops: int | None) -> np.ndarray:
        if max_hops is None:
            return self._hops[nodes]
        return super().hops_rows(nodes, max_hops)

    def hop_ball(self, s: int, max_hops: int | None) -> tuple[np.ndarray, np.ndarray]:
        row = self._hops[s]
        inside = np.flatnonzero(row < UNREACHABLE_HOPS if max_hops is None else row <= max_hops)
        return inside, row[inside]

    def hops_between(self, a: Any, b: Any) -> np.ndarray:
        return np.asarray(self._hops[a, b])

    def dist_pred(self, s: int) -> tuple[np.ndarray, np.ndarray]:
        return self._dist[s], self._pred[s]

    def dist_row(self, s: int, limit: float | None) -> np.ndarray:
        row = self._dist[s]
        if limit is None:
            return row
        return _read_only(np.where(row <= limit, row, np.inf))

    def dist_rows(self, nodes: np.ndarray, limit: float | None) -> np.ndarray:
        if limit is None:
            return self._dist[nodes]
        return super().dist_rows(nodes, limit)

    def dist_between(self, a: Any, b: Any) -> np.ndarray:
        return np.asarray(self._dist[a, b])

    def nearest(self, nodes: np.ndarray, limit: float | None) -> np.ndarray:
        found = self._dist[nodes].min(axis=0)
        if limit is not None:
            found = np.where(found <= limit, found, np.inf)
        return found

    def nearest_to(self, nodes: np.ndarray, target: int) -> float:
        return float(self._dist[nodes, target].min())

    def nearest_to_rows(self, srcs: np.ndarray, targets: np.ndarray) -> np.ndarray:
        found = self._dist[np.maximum(srcs, 0), np.asarray(targets)[:, None]]
        return np.where(srcs >= 0, found, np.inf).min(axis=1, initial=np.inf)


class SearchedDistances(Distances):
    """A search per source, the last rows kept in a :class:`RowCache` of
    :data:`ROW_CACHE_BYTES`: memory grows with the level, not its square."""

    def __init__(self, adjacency: csr_matrix, table: Callable[[], np.ndarray]) -> None:
        super().__init__(adjacency, table)
        self._rows = RowCache(ROW_CACHE_BYTES)

    def hops_row(self, s: int, max_hops: int | None) -> np.ndarray:
        def make() -> tuple[np.ndarray]:
            inside, hops = self.hop_ball(s, max_hops)
            row = np.full(self.n, UNREACHABLE_HOPS, dtype=np.int32)
            row[inside] = hops
            return (row,)

        (row,) = self._rows.get(("hops", s, max_hops), make)
        return row

    def dist_pred(self, s: int) -> tuple[np.ndarray, np.ndarray]:
        dist, pred = self._rows.get(
            ("dist", s),
            # symmetric adjacency: the directed search relaxes the same edges in the same
            # order as the undirected one (same rows, same predecessors), without scipy
            # transposing the matrix on every call
            lambda: tuple(dijkstra(self.adjacency, indices=s, return_predecessors=True)),
        )
        return dist, pred

    def dist_row(self, s: int, limit: float | None) -> np.ndarray:
        if limit is None:
            return self.dist_pred(s)[0]
        out = dijkstra(self.adjacency, indices=s, limit=float(limit))  # symmetric: no transpose
        return _read_only(out)

    def nearest(self, nodes: np.ndarray, limit: float | None) -> np.ndarray:
        """One multi-source search per set of sources, cached: guards change nodes less often
        than the callers ask (each physics step, each player move), so the row is shared by
        the distance metric and the players until a guard moves."""
        if len(nodes) == 1 and limit is None:
            return self.dist_row(int(nodes[0]), None)
        key = ("nearest", tuple(sorted(set(nodes.tolist()))), limit)
        # symmetric adjacency: the directed search gives the undirected distances
        (row,) = self._rows.get(key, lambda: (dijkstra(
            self.adjacency, indices=nodes, min_only=True,
            limit=np.inf if limit is None else float(limit)),))
        return row


def keeps_dense(nodes: int) -> bool:
    """Whether a graph of ``nodes`` nodes keeps dense all-pairs matrices: the one test of
    :data:`DENSE_MAX_NODES`, asked by the graph choosing its strategy
    (:class:`navmesh.graph.NodeGraph`) and by the memory estimate made before a level is built
    (:func:`navmesh.sizing.estimate_bytes`).

    >>> keeps_dense(2048), keeps_dense(2049)
    (True, False)
    """
    return nodes <= DENSE_MAX_NODES


def distances_for(adjacency: csr_matrix, table: Callable[[], np.ndarray], dense: bool) -> Distances:
    """The storage strategy of a graph: the one place the choice is made."""
    return (DenseDistances if dense else SearchedDistances)(adjacency, table)
