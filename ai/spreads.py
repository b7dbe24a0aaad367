"""The spreads ``γ^d(s, ·)`` of the information and confidence fields, per source node.

Two implementations behind one interface, chosen once per graph by :func:`spreads_for`
(the one place ``ai/`` reads the graph's storage): :class:`DenseSpreads` keeps (n,) rows,
cheapest on a small graph; :class:`BallSpreads` keeps each spread as its ball (the nodes it
reaches and their values), since on a large graph a spread reaches a few thousand nodes
and rows of n floats would fill the cache with zeros. Every value is the same bits either
way: outside a ball a row is 0, and x + 0 = x.
"""

from __future__ import annotations

import numpy as np

from navmesh.distances import RowCache, SlicedSearch
from navmesh.graph import NodeGraph, falloff_depth

from .params import PFParams

#: Spreads ``γ^d`` are cut to 0 where ``γ^d`` drops below this (far below the 1e-9 tie
#: threshold of every argmin); on the bundled levels no spread reaches that depth.
SPREAD_TOLERANCE = 1e-12


def read_only(array: np.ndarray) -> np.ndarray:
    """``array``, marked read-only (the fields hand out snapshots, never modified)."""
    array.flags.writeable = False
    return array


class Spreads:
    """``γ_I^d`` ("I") and ``γ_C^d`` ("C") from any node, cut at :data:`SPREAD_TOLERANCE`.

    ``cache`` holds what is kept (shared with the kernel blocks of the same matrices).
    """

    #: whether whole-graph tables (the presence table, K over every node) are worth making
    tables: bool = False

    def __init__(self, graph: NodeGraph, params: PFParams, cache: RowCache) -> None:
        self.graph, self._rows = graph, cache
        self.gamma_I, self.gamma_C = params.gamma_I, params.gamma_C
        self.depth_I = falloff_depth(params.gamma_I, SPREAD_TOLERANCE)
        self.depth_C = falloff_depth(params.gamma_C, SPREAD_TOLERANCE)

    def gamma_depth(self, which: str) -> tuple[float, int | None]:
        """(γ, cut-off depth) of field ``which``."""
        return (self.gamma_I, self.depth_I) if which == "I" else (self.gamma_C, self.depth_C)

    def ball_values(self, which: str, inside: np.ndarray, hops: np.ndarray,
                    ) -> tuple[np.ndarray, np.ndarray]:
        """A hop ball as (nodes, ``γ ** hops``)."""
        return inside, self.gamma_depth(which)[0] ** hops.astype(np.float64)

    def search_ball(self, which: str, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The nonzeros of the spread of ``which`` from ``node``, searched now (uncached)."""
        return self.ball_values(which, *self.graph.hop_ball(node, self.gamma_depth(which)[1]))

    def row_of(self, inside: np.ndarray, values: np.ndarray) -> np.ndarray:
        """An (n,) row, zero outside the ball."""
        row = np.zeros(self.graph.n)
        row[inside] = values
        return row

    def row_now(self, which: str, node: int) -> np.ndarray:
        """(n,) ``γ ** d(node, ·)`` cut at the field's depth (uncached)."""
        return self.row_of(*self.search_ball(which, node))

    # the interface
    def row(self, which: str, node: int) -> np.ndarray:
        """(n,) ``γ ** d(node, ·)``, read-only."""
        raise NotImplementedError

    def at(self, which: str, node: int, at: np.ndarray) -> np.ndarray:
        """``row(which, node)[at]`` (any shape of ``at``)."""
        raise NotImplementedError

    def deposit(self, nodes: np.ndarray) -> np.ndarray:
        """(n,) ``Σ_g γ_C ** d(g, ·)`` over the (non-empty) ``nodes``, summed in their order."""
        raise NotImplementedError

    def deposit_into(self, target: np.ndarray, nodes: np.ndarray, scale: float) -> None:
        """``target += scale * deposit(nodes)`` in place, the same bits as ``target + scale *
        deposit(nodes)`` without two of its three (n,) temporaries (measured on a 10^6-cell
        level: a sparse sum over the balls' nodes alone costs more than these dense passes)."""
        total = self.deposit(nodes)  # a new row, ours to scale
        np.multiply(total, scale, out=total)
        np.add(target, total, out=target)

    # searching ahead (:mod:`ai.prefetch`); a strategy that keeps rows needs none
    def wanted(self, which: str, node: int) -> bool:
        """Whether the ball of ``which`` at ``node`` would be searched when first read."""
        return False

    def begin(self, which: str, node: int) -> SlicedSearch:
        """Start searching that ball ahead; a read of it meanwhile finishes the search."""
        raise NotImplementedError

    def keep(self, which: str, node: int, search: SlicedSearch) -> None:
        """Keep the ball a search begun by :meth:`begin` found."""


class DenseSpreads(Spreads):
    """Cached (n,) rows: every bundled level."""

    tables = True

    def row(self, which: str, node: int) -> np.ndarray:
        return self._rows.get((which, node), lambda: (self.row_now(which, node),))[0]

    def at(self, which: str, node: int, at: np.ndarray) -> np.ndarray:
        return self.row(which, node)[at]

    def deposit(self, nodes: np.ndarray) -> np.ndarray:
        total = self.row("C", int(nodes[0])).copy()
        for g in nodes[1:]:
            total += self.row("C", int(g))
        return total


class BallSpreads(Spreads):
    """Cached balls (sorted nodes, values); rows made from them when asked for."""

    def __init__(self, graph: NodeGraph, params: PFParams, cache: RowCache) -> None:
        super().__init__(graph, params, cache)
        #: the ball being searched ahead, as (field, node, search)
        self._pending: tuple[str, int, SlicedSearch] | None = None
        graph.hop_ball(0, 0)  # the searches' neighbour table, built now rather than mid-game

    def ball(self, which: str, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The nonzeros of :meth:`row` as (sorted nodes, values), cached."""
        def make() -> tuple[np.ndarray, np.ndarray]:
            pending = self._pending
            if pending is not None and pending[:2] == (which, node):
                self._pending = None  # being searched ahead: finish that search
                return self.ball_values(which, *pending[2].finish())
            return self.search_ball(which, node)

        inside, values = self._rows.get(("ball", which, node), make)
        return inside, values

    def row(self, which: str, node: int) -> np.ndarray:
        return read_only(self.row_of(*self.ball(which, node)))

    def at(self, which: str, node: int, at: np.ndarray) -> np.ndarray:
        inside, values = self.ball(which, int(node))
        slot = np.minimum(np.searchsorted(inside, at), len(inside) - 1)
        return np.where(inside[slot] == at, values[slot], 0.0)

    def deposit(self, nodes: np.ndarray) -> np.ndarray:
        total = np.zeros(self.graph.n)
        for g in nodes:
            inside, values = self.ball("C", int(g))
            total[inside] += values
        return total

    def wanted(self, which: str, node: int) -> bool:
        return ("ball", which, node) not in self._rows

    def begin(self, which: str, node: int) -> SlicedSearch:
        search = self.graph.hop_search(node, self.gamma_depth(which)[1])
        self._pending = (which, node, search)
        return search

    def keep(self, which: str, node: int, search: SlicedSearch) -> None:
        pending = self._pending
        if pending is None or pending[2] is not search:
            return  # a read finished it first and kept its ball
        self._pending = None
        inside, hops = search.finish()
        self._rows.get(("ball", which, node), lambda: self.ball_values(which, inside, hops))


def spreads_for(graph: NodeGraph, params: PFParams, cache: RowCache) -> Spreads:
    """The spreads of ``graph``: rows on a graph that keeps dense distances, balls on one
    that searches (the one place the AI reads the graph's storage)."""
    return (DenseSpreads if graph.dense else BallSpreads)(graph, params, cache)

