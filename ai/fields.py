"""The composite potential field of the guard team (paper §Methods; SPEC §3).

Everything that depends only on the graph and the parameters — the spreads ``γ_I^d`` and
``γ_C^d`` per source node, the row-normalised kernel matrix, the connectivity field and the
candidate sets — is computed once per :class:`~navmesh.graph.NodeGraph` and cached, because
thousands of trials reuse one graph; nothing is n × n, so large levels fit. A tick and a
decision are then a handful of numpy vector operations and one sparse matrix-vector
product; there is no per-node Python loop (SPEC §3.8). On a graph too large for dense
tables a spread is kept as its ball (the nodes it reaches and their values) and a decision
reads K at its candidates alone (:meth:`CompositeField.kernel_at`), summed in the order
scipy's product sums it: the same bits, without a product over every node per tick.

State arrays are never modified in place: every tick makes new arrays and marks them
read-only, so references handed out by :meth:`CompositeField.fields` or kept for
``explain()`` stay valid snapshots.

>>> import numpy as np
>>> from navmesh.graph import NodeGraph
>>> field = CompositeField(NodeGraph.from_grid(np.ones((1, 5), bool), 1.0))
>>> field.tick(1.0, guard_nodes=[4], sighting_node=0)
>>> field.information.round(4).tolist()
[-5.0, -4.5, -4.05, -3.645, -3.2805]
>>> field.choose(2, np.random.default_rng(0))  # towards the sighting, away from the guard
1
"""

from __future__ import annotations

import time
import weakref
from collections import OrderedDict, deque
from collections.abc import Generator, Sequence
from functools import cached_property
from typing import NamedTuple

import numpy as np
from scipy import sparse

from navmesh.graph import (
    BallTooLarge,
    NodeGraph,
    RowCache,
    falloff_depth,
    finish_search,
    hop_ball_pairs,
)

from .errors import WorkBudgetError
from .params import PFParams
from .view import WorldView

# ---------------------------------------------------------------------------- precomputation


#: Spreads ``γ^d`` are cut to 0 where ``γ^d`` drops below this (far below the 1e-9 tie
#: threshold of every argmin); on the bundled levels no spread reaches that depth.
SPREAD_TOLERANCE = 1e-12

#: Node pairs the smoothing kernel may hold (the work budget, docs/config.md): the default
#: radius 3 on a 10^6-cell grid holds about 2.5 × 10^7
MAX_KERNEL_PAIRS = 50_000_000

#: Bytes of per-source spread rows and kernel blocks one :class:`FieldMatrices` keeps.
SPREAD_CACHE_BYTES = 128 * 2**20


class FieldMatrices:
    """What never changes for one graph and one parameter set; shared by every trial on it.

    Nothing here is n × n on a large graph: the spreads ``γ^d(s, ·)`` are computed per
    source node by a BFS cut at :data:`SPREAD_TOLERANCE` and cached (guards and sightings sit
    on few nodes), the kernel is a sparse radius-δ matrix and the candidate sets are found per
    node on first use. Only a graph small enough to be dense keeps its presence table.
    """

    def __init__(self, graph: NodeGraph, params: PFParams) -> None:
        self.graph = graph
        self.gamma_I, self.gamma_C = params.gamma_I, params.gamma_C
        self.depth_I = falloff_depth(params.gamma_I, SPREAD_TOLERANCE)
        self.depth_C = falloff_depth(params.gamma_C, SPREAD_TOLERANCE)
        #: (n, n) CSR, ``K[x, y] = λ^d(x,y) / Σ_{d(x,z) ≤ δ} λ^d(x,z)`` for ``d(x, y) ≤ δ``, else 0
        self.kernel = kernel_matrix(graph, params.kernel_lambda, params.kernel_radius)
        degree = np.asarray(graph.degree, dtype=np.float64)
        #: (n,) ``κ − degree`` with κ the graph's maximum degree
        self.connectivity = _read_only(graph.max_degree - degree)
        #: partition candidate horizon in world units (``r_edge_factor × mean edge length``)
        self.r_edge = params.r_edge_factor * graph.mean_edge_length
        #: per node, the nodes a guard standing there may choose (SPEC §3.5)
        self.candidates = CandidateSets(graph, params.r_edge_factor)
        self._rows = RowCache(SPREAD_CACHE_BYTES)
        #: large graph: the balls that will soon be read, as (field, node) — guards' next
        #: nodes ("C"), the player's node while seen ("I") — and the one being searched
        #: ahead (:meth:`warm`)
        self._ahead: deque[tuple[str, int]] = deque()
        self._warming: tuple[str, int, Generator[None, None, tuple[np.ndarray, np.ndarray]]] | None = None
        if not graph.dense:
            graph.hop_ball(0, 0)  # the searches' neighbour table, built now rather than mid-game

    def anticipate(self, node: int, which: str = "C") -> None:
        """``node``'s ball of field ``which`` ("C": a guard heads there, "I": the player is
        seen there) will be needed soon: on a large graph, queue it for :meth:`warm`."""
        if not self.graph.dense:
            self._ahead.append((which, int(node)))

    def warm(self, budget: float) -> None:
        """Search the queued balls not yet kept for about ``budget`` seconds, a ring at a
        time, at least one (a search left unfinished goes on at the next call): work the game
        does in a frame's spare time, so the next tick and decisions find the balls. Values
        never depend on it."""
        deadline = time.perf_counter() + budget
        first = True  # at least one ring per call, whatever the budget
        while first or time.perf_counter() < deadline:
            first = False
            if self._warming is None:
                while self._ahead and ("ball", *self._ahead[0]) in self._rows:
                    self._ahead.popleft()
                if not self._ahead:
                    return
                which, node = self._ahead.popleft()
                depth = self._gamma_depth(which)[1]
                self._warming = (which, node, self.graph.hop_ball_search(node, depth))
            which, node, search = self._warming
            try:
                next(search)
            except StopIteration as done:
                self._warming = None
                inside, hops = done.value
                self._rows.get(("ball", which, node),
                               lambda: self._ball_values(which, inside, hops))

    def _spread(self, which: str, node: int) -> np.ndarray:
        """(n,) ``γ ** d(node, ·)``, read-only: a cached row on a dense graph, else made
        from the cached ball (:meth:`_ball`)."""
        if self.graph.dense:
            return self._rows.get((which, node), lambda: (self._spread_row(which, node),))[0]
        return _read_only(self._row_of(*self._ball(which, node)))

    def _row_of(self, inside: np.ndarray, values: np.ndarray) -> np.ndarray:
        row = np.zeros(self.graph.n)
        row[inside] = values
        return row

    def _ball(self, which: str, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The nonzeros of :meth:`_spread` as (sorted nodes, values), cached: on a large
        graph a spread reaches a few thousand nodes, so rows of n floats would fill the cache
        with zeros (and a sum of them would add zeros)."""
        def make() -> tuple[np.ndarray, np.ndarray]:
            warming = self._warming
            if warming is not None and warming[:2] == (which, node):
                self._warming = None  # being searched ahead: finish that search
                return self._ball_values(which, *finish_search(warming[2]))
            return self._search_ball(which, node)

        inside, values = self._rows.get(("ball", which, node), make)
        return inside, values

    def _ball_values(self, which: str, inside: np.ndarray, hops: np.ndarray,
                     ) -> tuple[np.ndarray, np.ndarray]:
        return inside, self._gamma_depth(which)[0] ** hops.astype(np.float64)

    def _gamma_depth(self, which: str) -> tuple[float, int | None]:
        return (self.gamma_I, self.depth_I) if which == "I" else (self.gamma_C, self.depth_C)

    def _search_ball(self, which: str, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The ball of :meth:`_ball`, searched now (uncached)."""
        return self._ball_values(which, *self.graph.hop_ball(node, self._gamma_depth(which)[1]))

    def _spread_row(self, which: str, node: int) -> np.ndarray:
        """(n,) ``γ ** d(node, ·)`` cut at the field's depth (uncached)."""
        return self._row_of(*self._search_ball(which, node))

    def info_spread(self, node: int) -> np.ndarray:
        """(n,) ``γ_I ** d(node, ·)``: the information spread of a sighting at ``node`` (read-only)."""
        return self._spread("I", int(node))

    def conf_spread(self, node: int) -> np.ndarray:
        """(n,) ``γ_C ** d(node, ·)``: one guard's confidence deposit from ``node`` (read-only)."""
        return self._spread("C", int(node))

    def conf_spread_at(self, node: int, at: np.ndarray) -> np.ndarray:
        """``conf_spread(node)[at]`` (any shape of ``at``), without making the (n,) row on a
        large graph: the values are looked up in the node's ball."""
        if self.graph.dense:
            return self.conf_spread(node)[at]
        inside, values = self._ball("C", int(node))
        slot = np.minimum(np.searchsorted(inside, at), len(inside) - 1)
        return np.where(inside[slot] == at, values[slot], 0.0)

    def deposit(self, nodes: Sequence[int] | np.ndarray) -> np.ndarray:
        """(n,) ``Σ_g γ_C ** d(g, ·)`` over ``nodes``, summed in their order (zeros if none).

        A large graph adds each ball into zeros: outside a ball its row is 0, and x + 0 = x,
        so the sums are bit for bit those of the (n,) rows.
        """
        nodes = np.asarray(nodes, dtype=np.intp)
        if not len(nodes):
            return np.zeros(self.graph.n)
        if not self.graph.dense:
            total = np.zeros(self.graph.n)
            for g in nodes:
                inside, values = self._ball("C", int(g))
                total[inside] += values
            return total
        total = self.conf_spread(int(nodes[0])).copy()
        for g in nodes[1:]:
            total += self.conf_spread(int(g))
        return total

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
            picked = table[np.ix_(self.candidates[node], np.asarray(teammates, dtype=np.intp))]
            return np.ascontiguousarray(picked.T).sum(axis=0)
        cols, weights = self.kernel_rows(node)
        smoothed = np.empty((len(teammates), len(cols)))  # (t, c): one row per teammate
        for k, t in enumerate(teammates):
            smoothed[k] = (self.conf_spread_at(int(t), cols) * weights).cumsum(axis=1)[:, -1]
        return smoothed.sum(axis=0)

    @cached_property
    def presence_table(self) -> np.ndarray | None:
        """(n, n) ``Kmat @ γ_C^d(·, t)`` for a graph small enough to be dense (``graph.dense``:
        at most DENSE_MAX_NODES nodes, 32 MB at most), else None.

        scipy's CSR × dense product sums each entry in the same sequence as
        :meth:`presence`'s per-row ``cumsum`` (``0 + w0·x0 + w1·x1 + …``), so either way
        gives the same bits (tests/test_hot_paths.py); the table makes a decision's
        presence term one lookup, as round 1's dense matrices did.
        """
        if not self.graph.dense:
            return None
        spreads = np.stack([self._spread_row("C", t) for t in range(self.graph.n)], axis=1)
        table = np.asarray(self.kernel @ spreads)
        table.flags.writeable = False
        return table

    def kernel_rows(self, node: int) -> tuple[np.ndarray, np.ndarray]:
        """The kernel rows of ``node``'s candidates as (c, w) column indices and weights:
        each row's nonzeros in CSR order, then zero weights (at column 0) up to the widest."""
        def make() -> tuple[np.ndarray, np.ndarray]:
            kernel, rows = self.kernel, self.candidates[node]
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

        cols, weights = self._rows.get(("K", int(node)), make)
        return cols, weights


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
        float(params.kernel_radius),
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


def _read_only(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


# ---------------------------------------------------------------------------- reading a view


def active_guard_nodes(view: WorldView) -> np.ndarray:
    """Nodes of the guards still in play (a guard taken down deposits no confidence)."""
    nodes = np.asarray(view.guard_nodes, dtype=np.intp)
    if view.guard_active is None:
        return nodes
    return nodes[np.asarray(view.guard_active, dtype=bool)]


def sighting_node(view: WorldView) -> int | None:
    """The player's node if a guard sees it now, else ``view.sighting`` (None: not seen)."""
    if view.seen_by:
        return int(view.player_node)
    return None if view.sighting is None else int(view.sighting)


# ---------------------------------------------------------------------------- the field


def composite_potential(
    weights: tuple[float, float, float],
    information: np.ndarray,
    extra: np.ndarray,
    confidence: np.ndarray,
    connectivity: np.ndarray,
) -> np.ndarray:
    """Eq. 5, ``P = w_I (I + I_extra) + w_C C + w_N N``, elementwise: the whole field or any
    gathered part of it gives the same bits at the same nodes."""
    w_I, w_C, w_N = weights  # noqa: N806 — the paper's symbols
    return w_I * (information + extra) + w_C * confidence + w_N * connectivity


def information_layer(values: np.ndarray | Sequence[float], n: int) -> np.ndarray:
    """A copy of ``values`` as a float (n,) array: what the ``extra_information`` hooks take."""
    layer = np.array(values, dtype=np.float64)
    if layer.shape != (n,):
        raise ValueError(f"extra_information must have shape ({n},), got {layer.shape}")
    return layer


class Choice(NamedTuple):
    """One argmin decision: the winner, the candidates with their K, and the tied ones."""

    winner: int
    candidates: np.ndarray
    scores: np.ndarray
    tied: np.ndarray


class FieldSnapshot(NamedTuple):
    """A field's state at one moment; calling it computes that moment's :meth:`CompositeField.fields`
    (the same P and K bits), touching nothing of the live field."""

    weights: tuple[float, float, float]
    information: np.ndarray
    extra: np.ndarray
    confidence: np.ndarray
    connectivity: np.ndarray
    kernel_matrix: sparse.csr_matrix

    @property
    def identity(self) -> tuple[int, int, int, tuple[float, float, float]]:
        """Changes whenever the fields do (the state arrays are replaced, never modified)."""
        return id(self.information), id(self.extra), id(self.confidence), self.weights

    def __call__(self) -> dict[str, np.ndarray]:
        potential = _read_only(composite_potential(self.weights, self.information, self.extra,
                                                   self.confidence, self.connectivity))
        return {"I": self.information, "I_extra": self.extra, "C": self.confidence,
                "N": self.connectivity, "P": potential,
                "K": _read_only(self.kernel_matrix @ potential)}


class CompositeField:
    """Shared I, C, N fields, adaptive weights, composite potential P and kernel K.

    Equation numbers as in docs/ai.md (the paper's Methods order): ``I ≤ 0`` attractive
    information (eqs. 1–2), ``C ≥ 0`` repulsive confidence (eq. 3), ``N = κ − degree``
    (eq. 4), ``P = w_I (I + I_extra) + w_C C + w_N N`` (eq. 5), ``K = Kmat @ P`` (eq. 6), a
    guard moves to ``argmin K`` over its candidates (eq. 7), weights per eq. 8.
    ``I_extra`` (:attr:`extra_information`) and :attr:`confidence_decay` are the hooks for
    stimuli and zones; ``select(..., teammates)`` adds the teammate-presence term.
    """

    def __init__(self, graph: NodeGraph, params: PFParams | None = None) -> None:
        self.graph = graph
        self.params = params or PFParams()
        self.matrices = field_matrices(graph, self.params)
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Empty fields, patrol weights, the global decay everywhere."""
        n = self.graph.n
        zeros = _read_only(np.zeros(n))
        self._information = zeros
        self._confidence = zeros
        self._extra = zeros
        self._confidence_decay = _read_only(np.full(n, self.params.rho))
        self._decay_cache: tuple[float, np.ndarray, np.ndarray] | None = None
        self._w_I_floor = 0.0
        self._set_w_I(self.params.w_I_base)
        self.ticks = 0
        self._version = 0
        self._cached_version = -1
        self._potential = zeros
        self._kernel = zeros

    @property
    def information(self) -> np.ndarray:
        """I (n,), ≤ 0: the sighting field, decayed by ρ per second (read-only array)."""
        return self._information

    @property
    def confidence(self) -> np.ndarray:
        """C (n,), ≥ 0: where guards have recently been (read-only array)."""
        return self._confidence

    @property
    def connectivity(self) -> np.ndarray:
        """N (n,) = κ − degree, static (read-only array)."""
        return self.matrices.connectivity

    @property
    def extra_information(self) -> np.ndarray:
        """I_extra (n,): temporary information layers of stimuli, added to I inside P.

        The stimulus module owns it: it assigns the sum of its active layers (≤ 0 for
        attractive stimuli) after each tick, e.g. ``field.extra_information = layers``.
        Zeros by default. The returned array is read-only; assign a new one to change it.
        """
        return self._extra

    @extra_information.setter
    def extra_information(self, values: np.ndarray) -> None:
        self._extra = _read_only(information_layer(values, self.graph.n))
        self._version += 1

    @property
    def confidence_decay(self) -> np.ndarray:
        """Per-node temporal decay of C per second: ρ everywhere unless overridden (read-only)."""
        return self._confidence_decay

    @confidence_decay.setter
    def confidence_decay(self, values: np.ndarray) -> None:
        values = np.array(np.broadcast_to(values, (self.graph.n,)), dtype=np.float64)
        if np.any(values <= 0) or np.any(values > 1):
            raise ValueError("confidence_decay values must be in (0, 1]")
        self._confidence_decay = _read_only(values)
        self._decay_cache = None

    def set_confidence_decay(self, nodes: np.ndarray | Sequence[int], rate: float) -> None:
        """Override the confidence decay of ``nodes`` (indices or a mask), e.g. dark cells 0.80."""
        values = self._confidence_decay.copy()
        values[np.asarray(nodes)] = rate
        self.confidence_decay = values

    @property
    def information_weight_floor(self) -> float:
        """A lower bound on w_I asked for by stimuli (0 = none; e.g. an alarm puts guards on alert).

        While it is above w_I, w_I is raised to it at once and eq. 8 never takes w_I below it;
        when it is lowered, w_I decays from where it is at δ_w per second as after a sighting.
        """
        return self._w_I_floor

    @information_weight_floor.setter
    def information_weight_floor(self, value: float | None) -> None:
        floor = 0.0 if value is None else float(value)
        if not 0.0 <= floor <= 1.0:
            raise ValueError(f"information_weight_floor must be in [0, 1], got {value!r}")
        self._w_I_floor = floor
        if self.w_I < floor:
            self._set_w_I(floor)
            self._version += 1

    @property
    def weights(self) -> tuple[float, float, float]:
        """(w_I, w_C, w_N), summing to 1."""
        return self.w_I, self.w_C, self.w_N

    def _set_w_I(self, w_I: float) -> None:  # noqa: N802, N803 — the paper's symbol
        p = self.params
        self.w_I = float(w_I)
        rest = 1.0 - self.w_I
        self.w_C = rest * p.w_C_patrol / (p.w_C_patrol + p.w_N_patrol)
        self.w_N = rest * p.w_N_patrol / (p.w_C_patrol + p.w_N_patrol)

    # ------------------------------------------------------------------ the AI tick
    def tick(
        self, dt: float, guard_nodes: Sequence[int] | np.ndarray, sighting_node: int | None
    ) -> None:
        """Advance the fields and weights by one AI tick of ``dt`` seconds (eqs. 1–3, 8).

        ``guard_nodes`` are the active guards' nodes; ``sighting_node`` the player's node if
        any guard saw the player since the last tick, else None.
        """
        if dt < 0:
            raise ValueError(f"dt must be >= 0, got {dt}")
        p, m = self.params, self.matrices
        if sighting_node is not None:
            information = -p.I0 * m.info_spread(sighting_node)
            self._set_w_I(p.w_I_max)
        else:
            information = self._information * (p.rho**dt)
            self._set_w_I(max(p.w_I_base, self.w_I - p.weight_decay * dt))
        if self.w_I < self._w_I_floor:
            self._set_w_I(self._w_I_floor)
        confidence = self._confidence * self._decay_power(dt)
        guards = np.asarray(guard_nodes, dtype=np.intp)
        if len(guards):
            confidence = confidence + p.C0 * m.deposit(guards)
        self._information = _read_only(information)
        self._confidence = _read_only(confidence)
        self.ticks += 1
        self._version += 1

    def _decay_power(self, dt: float) -> np.ndarray:
        """``confidence_decay ** dt``, cached for the last dt (ticks are usually all 1 s)."""
        cache = self._decay_cache
        if cache is None or cache[0] != dt or cache[1] is not self._confidence_decay:
            cache = (dt, self._confidence_decay, self._confidence_decay**dt)
            self._decay_cache = cache
        return cache[2]

    # ------------------------------------------------------------------ potential and kernel
    def _refresh(self) -> None:
        if self._cached_version != self._version:
            fields = self.snapshot()()
            self._potential, self._kernel = fields["P"], fields["K"]
            self._cached_version = self._version

    def potential_at(self, at: np.ndarray | slice) -> np.ndarray:
        """``potential()[at]``, computed at ``at`` alone (the same operations, so the same bits)."""
        return composite_potential(self.weights, self._information[at], self._extra[at],
                                   self._confidence[at], self.matrices.connectivity[at])

    def kernel_at(self, node: int) -> np.ndarray:
        """``kernel()[candidates(node)]``. A large graph computes just these entries: each
        candidate's kernel row summed left to right as scipy's CSR product sums it
        (``0 + w0·P0 + w1·P1 + …``, :meth:`FieldMatrices.presence`), so an AI tick does not
        pay for a product over every node that a decision reads a few entries of."""
        if self.graph.dense:
            return self.kernel()[self.matrices.candidates[node]]
        cols, weights = self.matrices.kernel_rows(node)
        return (self.potential_at(cols) * weights).cumsum(axis=1)[:, -1]

    def potential(self) -> np.ndarray:
        """P (n,) = w_I (I + I_extra) + w_C C + w_N N (eq. 5); cached until the state changes."""
        self._refresh()
        return self._potential

    def kernel(self) -> np.ndarray:
        """K (n,) = kernel-smoothed P (eq. 6); cached until the state changes."""
        self._refresh()
        return self._kernel

    def candidates(self, node: int) -> np.ndarray:
        """The nodes a guard at ``node`` may choose (SPEC §3.5)."""
        return self.matrices.candidates[node]

    def select(
        self,
        node: int,
        rng: np.random.Generator,
        teammates: Sequence[int] | np.ndarray = (),
        recent: Sequence[int] | np.ndarray = (),
        personal: np.ndarray | None = None,
    ) -> Choice:
        """argmin K over the candidates of ``node`` (eq. 7); ties within tie_eps drawn with ``rng``.

        ``teammates`` are the other active guards' current nodes: their presence term
        ``w_C · teammate_presence · C0 · (Kmat @ γ_C^d(g, ·))`` is added to K (docs/ai.md).
        ``recent`` are the deciding guard's last visited nodes: a candidate among them gets
        ``w_C · revisit_penalty · C0`` added (eq. 10, unsmoothed, docs/ai.md).
        ``personal`` is the deciding guard's own field term (a coordinated role, docs/ai.md
        "Beyond the paper"), added unsmoothed at the candidates; None: the paper.
        """
        candidates = self.matrices.candidates[node]
        if len(candidates) == 0:
            empty = np.zeros(0, dtype=np.intp)
            return Choice(int(node), empty, np.zeros(0), empty)
        scores = self.kernel_at(node)
        scale = self.w_C * self.params.teammate_presence * self.params.C0
        if len(teammates) and scale:
            scores = scores + scale * self.matrices.presence(teammates, node)
        revisit = self.revisit_term(candidates, recent)
        if revisit is not None:
            scores = scores + revisit
        if personal is not None:
            scores = scores + personal[candidates]
        tied = candidates[scores - scores.min() < self.params.tie_eps]
        winner = tied[0] if len(tied) == 1 else tied[rng.integers(len(tied))]
        return Choice(int(winner), candidates, scores, tied)

    def choose(
        self,
        node: int,
        rng: np.random.Generator,
        teammates: Sequence[int] | np.ndarray = (),
        recent: Sequence[int] | np.ndarray = (),
    ) -> int:
        """The next node of a guard at ``node``: :meth:`select`'s winner."""
        return self.select(node, rng, teammates, recent).winner

    def revisit_term(
        self, candidates: np.ndarray, recent: Sequence[int] | np.ndarray
    ) -> np.ndarray | None:
        """Eq. 10: ``w_C · revisit_penalty · C0`` on candidates among ``recent`` (else None)."""
        scale = self.w_C * self.params.revisit_penalty * self.params.C0
        if not len(recent) or not scale:
            return None
        # a broadcast compare: np.isin costs ~25 us on these 4-10 element arrays
        recent_nodes = np.fromiter(recent, dtype=np.intp, count=len(recent))
        return scale * (candidates[:, None] == recent_nodes).any(axis=1)

    def teammate_confidence(self, teammates: Sequence[int] | np.ndarray) -> np.ndarray:
        """C_live (n,): teammates' deposit at their current nodes × teammate_presence."""
        live = np.zeros(self.graph.n)
        if len(teammates):
            live = self.matrices.deposit(teammates)
        return self.params.teammate_presence * self.params.C0 * live

    def teammate_confidence_at(self, teammates: Sequence[int] | np.ndarray,
                               at: np.ndarray) -> np.ndarray:
        """``teammate_confidence(teammates)[at]``, from the teammates' balls alone."""
        return self.params.teammate_presence * self.params.C0 * self.matrices.deposit_at(teammates, at)

    def snapshot(self) -> FieldSnapshot:
        """The state now, to compute :meth:`fields` from later (on any thread): references to
        the immutable arrays and the weights, nothing computed yet."""
        return FieldSnapshot(self.weights, self._information, self._extra, self._confidence,
                             self.matrices.connectivity, self.matrices.kernel)

    def fields(self) -> dict[str, np.ndarray]:
        """Current I, I_extra, C, N, P, K (read-only arrays), e.g. for the game overlay."""
        self._refresh()
        return {
            "I": self._information,
            "I_extra": self._extra,
            "C": self._confidence,
            "N": self.matrices.connectivity,
            "P": self._potential,
            "K": self._kernel,
        }


__all__ = [
    "CompositeField",
    "CandidateSets",
    "FieldSnapshot",
    "Choice",
    "FieldMatrices",
    "field_matrices",
    "kernel_matrix",
    "composite_potential",
    "candidate_sets",
    "active_guard_nodes",
    "sighting_node",
]
