"""The candidate sets of the PF guards (SPEC §3.5): per node, where a guard there may go."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from navmesh.graph import NodeGraph


class CandidateSets(Sequence[np.ndarray]):
    """Per node, the nodes a guard there may choose next (SPEC §3.5), found on first use.

    Grid: the 4-neighbours. Partition: the frontier of a metric search (Dijkstra) from the
    node at ``R = r_edge_factor × mean edge length`` — every node v with ``dist(s, v) ≥ R``
    reached over a shortest-path edge (u, v) whose start is still inside, ``dist(s, u) < R``;
    the adjacent nodes when that frontier is empty (the whole reachable graph lies within R).
    The search stops just past R (the frontier is at most one edge beyond it).
    """

    def __init__(self, graph: NodeGraph, r_edge_factor: float) -> None:
        self.graph = graph
        self.r_edge = r_edge_factor * graph.mean_edge_length
        self._found: dict[int, np.ndarray] = {}

    def __len__(self) -> int:
        return self.graph.n

    def __getitem__(self, node):
        s = int(node)
        found = self._found.get(s)
        if found is None:
            found = self._frontier(s)
            found.flags.writeable = False
            self._found[s] = found
        return found

    def _frontier(self, s: int) -> np.ndarray:
        graph, r_edge = self.graph, self.r_edge
        neighbours = np.asarray(graph.neighbors[s], dtype=np.intp)
        if graph.kind == "grid" or r_edge <= 0:
            return neighbours
        limit = (r_edge + graph.max_edge_length) * (1 + 1e-8) + 1e-8
        dist = graph.dist_from(s, limit=limit)
        adjacency = graph.adjacency
        inside = np.flatnonzero(dist < r_edge)
        lo, hi = adjacency.indptr[inside], adjacency.indptr[inside + 1]
        counts = hi - lo
        u = np.repeat(inside, counts)
        edges = np.repeat(lo - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
        v, w = adjacency.indices[edges], adjacency.data[edges]
        du, dv = dist[u], dist[v]
        tol = 1e-9 * (1.0 + np.abs(dv))
        with np.errstate(invalid="ignore"):
            frontier = (dv >= r_edge) & (np.abs(du + w - dv) <= tol)
        found = np.unique(v[frontier]).astype(np.intp)
        return found if len(found) else neighbours


def candidate_sets(graph: NodeGraph, r_edge_factor: float) -> tuple[np.ndarray, ...]:
    """Every node's candidate set (:class:`CandidateSets`), e.g. for tests and plots."""
    sets = CandidateSets(graph, r_edge_factor)
    return tuple(sets[s] for s in range(graph.n))


__all__ = ["CandidateSets", "candidate_sets"]
