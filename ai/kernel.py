"""The smoothing kernel of eq. 6 and the kernel cache: its rows at a node's candidates."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse

from navmesh.distances import RowCache
from navmesh.graph import BallTooLarge, NodeGraph, hop_ball_pairs

from .errors import WorkBudgetError

#: Node pairs the smoothing kernel may hold (the work budget, docs/config.md): the default
#: radius 3 on a 10^6-cell grid holds about 2.5 × 10^7
MAX_KERNEL_PAIRS = 50_000_000


def kernel_matrix(graph: NodeGraph, lam: float, radius: int) -> sparse.csr_matrix:
    """Row-normalised smoothing kernel ``λ^d / Σ λ^d`` over the hop ball of ``radius``.

    Part of the work budget (:mod:`game.budget`): a kernel of more than
    :data:`MAX_KERNEL_PAIRS` node pairs is refused with a :class:`WorkBudgetError` naming
    ``pf.kernel_radius``; a radius past the graph's diameter costs the diameter.
    """
    try:
        rows, cols, hops = hop_ball_pairs(graph, radius, MAX_KERNEL_PAIRS)
    except BallTooLarge as too_large:
        raise WorkBudgetError(
            f"pf.kernel_radius = {radius}: the smoothing kernel of this {graph.n}-node "
            f"{graph.kind} graph would hold more than {too_large.pairs} node pairs "
            f"(within {too_large.hops} hops), more than the limit of {MAX_KERNEL_PAIRS}"
        ) from None
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


__all__ = ["MAX_KERNEL_PAIRS", "KernelRows", "kernel_block", "kernel_matrix"]
