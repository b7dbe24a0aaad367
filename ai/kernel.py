"""The smoothing kernel of eq. 6 and the kernel cache: its rows at a node's candidates."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse

from navmesh.distances import RowCache
from navmesh.graph import NodeGraph, hop_ball_pairs


def kernel_matrix(graph: NodeGraph, lam: float, radius: int) -> sparse.csr_matrix:
    """Row-normalised smoothing kernel ``λ^d / Σ λ^d`` over the hop ball of ``radius``."""
    rows, cols, hops = hop_ball_pairs(graph, radius)
    weights = lam ** hops.astype(np.float64)
    n = graph.n
    totals = np.bincount(rows, weights=weights, minlength=n)
    return sparse.csr_matrix((weights / totals[rows], (rows, cols)), shape=(n, n))


def kernel_block(kernel: sparse.csr_matrix, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kernel rows ``rows`` as (c, w) column indices and weights: each row's nonzeros in
    CSR order, then zero weights (at column 0) up to the widest."""
    start = kernel.indptr[rows]
    counts = kernel.indptr[rows + 1] - start
    width = max(int(counts.max(initial=0)), 1)
    filled = np.arange(width) < counts[:, None]
    at = (start[:, None] + np.arange(width))[filled]  # row after row, in CSR order
    cols = np.zeros(filled.shape, dtype=np.intp)
    weights = np.zeros(filled.shape)
    cols[filled] = kernel.indices[at]
    weights[filled] = kernel.data[at]
    return cols, weights


class KernelRows:
    """Per node, :func:`kernel_block` of its candidates, kept in a shared :class:`RowCache`."""

    def __init__(self, cache: RowCache) -> None:
        self._rows = cache

    def get(self, node: int, make: Callable[[], tuple[np.ndarray, np.ndarray]],
            ) -> tuple[np.ndarray, np.ndarray]:
        """The block of ``node``, made by ``make`` on first use."""
        cols, weights = self._rows.get(("K", int(node)), make)
        return cols, weights


__all__ = ["KernelRows", "kernel_block", "kernel_matrix"]
