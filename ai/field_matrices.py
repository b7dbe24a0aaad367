"""What never changes for one graph and one parameter set: shared by every trial on it.

:class:`FieldMatrices` holds the spreads (:mod:`ai.spreads`, rows or balls by the graph's
storage), the kernel (:mod:`ai.kernel`), the connectivity field, the candidate sets
(:mod:`ai.candidates`) and, on a graph that keeps whole tables, the presence table;
:func:`field_matrices` caches it per graph (held weakly) and parameter set.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict
from collections.abc import Sequence
from functools import cached_property

import numpy as np

from navmesh.distances import RowCache
from navmesh.graph import NodeGraph

from .candidates import CandidateSets
from .kernel import KernelRows, kernel_block, kernel_matrix
from .params import PFParams
from .spreads import SPREAD_TOLERANCE, Spreads, read_only, spreads_for

#: Bytes of per-source spread rows and kernel blocks one :class:`FieldMatrices` keeps.
SPREAD_CACHE_BYTES = 128 * 2**20


class FieldMatrices:
    """What never changes for one graph and one parameter set; shared by every trial on it.

    Nothing here is n × n on a large graph: the spreads ``γ^d(s, ·)`` are computed per
    source node by a BFS cut at :data:`~ai.spreads.SPREAD_TOLERANCE` and cached (guards and
    sightings sit on few nodes), the kernel is a sparse radius-δ matrix and the candidate
    sets are found per node on first use. Only a graph whose spreads are rows keeps its
    presence table.
    """

    def __init__(self, graph: NodeGraph, params: PFParams) -> None:
        self.graph = graph
        #: (n, n) CSR, ``K[x, y] = λ^d(x,y) / Σ_{d(x,z) ≤ δ} λ^d(x,z)`` for ``d(x, y) ≤ δ``, else 0
        self.kernel = kernel_matrix(graph, params.kernel_lambda, params.kernel_radius)
        degree = np.asarray(graph.degree, dtype=np.float64)
        #: (n,) ``κ − degree`` with κ the graph's maximum degree
        self.connectivity = read_only(graph.max_degree - degree)
        #: partition candidate horizon in world units (``r_edge_factor × mean edge length``)
        self.r_edge = params.r_edge_factor * graph.mean_edge_length
        #: per node, the nodes a guard standing there may choose (SPEC §3.5)
        self.candidates = CandidateSets(graph, params.r_edge_factor)
        self._rows = RowCache(SPREAD_CACHE_BYTES)
        #: the spreads of both fields, rows or balls as the graph's storage suits
        self.spreads: Spreads = spreads_for(graph, params, self._rows)
        self._kernel_rows = KernelRows(self._rows)

    def info_spread(self, node: int) -> np.ndarray:
        """(n,) ``γ_I ** d(node, ·)``: the information spread of a sighting at ``node`` (read-only)."""
        return self.spreads.row("I", int(node))

    def conf_spread(self, node: int) -> np.ndarray:
        """(n,) ``γ_C ** d(node, ·)``: one guard's confidence deposit from ``node`` (read-only)."""
        return self.spreads.row("C", int(node))

    def conf_spread_at(self, node: int, at: np.ndarray) -> np.ndarray:
        """``conf_spread(node)[at]`` (any shape of ``at``), without making the (n,) row on a
        large graph: the values are looked up in the node's ball."""
        return self.spreads.at("C", int(node), at)

    def _spread_row(self, which: str, node: int) -> np.ndarray:
        """(n,) ``γ ** d(node, ·)`` cut at the field's depth (uncached)."""
        return self.spreads.row_now(which, node)

    def deposit(self, nodes: Sequence[int] | np.ndarray) -> np.ndarray:
        """(n,) ``Σ_g γ_C ** d(g, ·)`` over ``nodes``, summed in their order (zeros if none).

        A large graph adds each ball into zeros: outside a ball its row is 0, and x + 0 = x,
        so the sums are bit for bit those of the (n,) rows.
        """
        nodes = np.asarray(nodes, dtype=np.intp)
        if not len(nodes):
            return np.zeros(self.graph.n)
        return self.spreads.deposit(nodes)

    def deposit_into(self, target: np.ndarray, nodes: np.ndarray, scale: float) -> None:
        """``target += scale * deposit(nodes)`` in place, bit for bit ``target + scale *
        deposit(nodes)`` (the tick adds into the decayed C it has just made)."""
        self.spreads.deposit_into(target, np.asarray(nodes, dtype=np.intp), scale)

    def deposit_at(self, nodes: Sequence[int] | np.ndarray, at: np.ndarray) -> np.ndarray:
        """``deposit(nodes)[at]``, summed in the same order, from the balls alone."""
        nodes = np.asarray(nodes, dtype=np.intp)
        total = np.zeros(np.shape(at))
        for g in nodes:
            total = total + self.conf_spread_at(int(g), at)
        return total

    def presence(self, teammates: Sequence[int] | np.ndarray, node: int) -> np.ndarray:
        """(c,) ``Σ_t (Kmat @ γ_C^d(t, ·))`` at the candidates of ``node``, over ``teammates``.

        Each kernel row is gathered from :meth:`kernel_rows` and summed left to right by
        ``cumsum``, exactly the sequence of scipy's CSR product (``0 + w0·x0 + w1·x1 + …``),
        without its ~90 µs of overhead per call; teammates are then summed as before.
        """
        table = self.presence_table
        if table is not None:
            # (t, c) = table[c, t] transposed, gathered directly (C-contiguous, as the copy
            # of np.ix_'s (c, t) transpose was): the same rows summed in the same order
            tm = np.asarray(teammates, dtype=np.intp)
            return table[self.candidates[node][None, :], tm[:, None]].sum(axis=0)
        cols, weights = self.kernel_rows(node)
        smoothed = np.empty((len(teammates), len(cols)))  # (t, c): one row per teammate
        for k, t in enumerate(teammates):
            smoothed[k] = (self.conf_spread_at(int(t), cols) * weights).cumsum(axis=1)[:, -1]
        return smoothed.sum(axis=0)

    @cached_property
    def presence_table(self) -> np.ndarray | None:
        """(n, n) ``Kmat @ γ_C^d(·, t)`` when the spreads keep whole tables (a dense graph:
        at most DENSE_MAX_NODES nodes, 32 MB at most), else None.

        scipy's CSR × dense product sums each entry in the same sequence as
        :meth:`presence`'s per-row ``cumsum`` (``0 + w0·x0 + w1·x1 + …``), so either way
        gives the same bits (tests/test_hot_paths.py); the table makes a decision's
        presence term one lookup, as round 1's dense matrices did.
        """
        if not self.spreads.tables:
            return None
        spreads = np.stack([self._spread_row("C", t) for t in range(self.graph.n)], axis=1)
        table = np.asarray(self.kernel @ spreads)
        table.flags.writeable = False
        return table

    def kernel_rows(self, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The kernel rows of ``node``'s candidates as (c, w) column indices and weights:
        each row's nonzeros in CSR order, then zero weights (at column 0) up to the widest."""
        return self._kernel_rows.get(node, lambda: kernel_block(self.kernel, self.candidates[node]))


_MATRIX_CACHE: weakref.WeakKeyDictionary[NodeGraph, OrderedDict[tuple[float, ...], FieldMatrices]] = (
    weakref.WeakKeyDictionary()
)

#: Parameter sets whose matrices one graph keeps (least recently used dropped first): a
#: design or a tuner that varies ``pf.gamma_*``, ``kernel_*`` or ``r_edge_factor`` per trial
#: would otherwise keep every set's kernel and row caches for the life of the process
MATRICES_PER_GRAPH = 4


def field_matrices(graph: NodeGraph, params: PFParams) -> FieldMatrices:
    """The precomputed matrices of ``graph`` for ``params``, built on first use and cached.

    The cache holds the graph weakly, so a graph that is no longer used frees its matrices,
    and at most :data:`MATRICES_PER_GRAPH` parameter sets per graph.
    """
    key = (
        params.gamma_I,
        params.gamma_C,
        params.kernel_lambda,
        params.kernel_radius,  # not float(): a whole number beyond 1e308 is in range
        params.r_edge_factor,
    )
    per_graph = _MATRIX_CACHE.setdefault(graph, OrderedDict())
    matrices = per_graph.get(key)
    if matrices is None:
        matrices = FieldMatrices(graph, params)
        per_graph[key] = matrices
        while len(per_graph) > MATRICES_PER_GRAPH:
            per_graph.popitem(last=False)
    else:
        per_graph.move_to_end(key)
    return matrices


__all__ = ["MATRICES_PER_GRAPH", "SPREAD_CACHE_BYTES", "SPREAD_TOLERANCE", "FieldMatrices", "field_matrices"]
