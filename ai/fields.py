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

The precomputation lives beside it: :mod:`ai.field_matrices` (shared per graph), with
:mod:`ai.spreads`, :mod:`ai.kernel` and :mod:`ai.candidates`; searching spreads ahead in a
frame's spare time is :mod:`ai.prefetch`. The names of those modules are re-exported here.

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

from collections.abc import Sequence
from types import ModuleType
from typing import NamedTuple

import numpy as np
from scipy import sparse

from navmesh.graph import NodeGraph

from .candidates import CandidateSets, candidate_sets
from .decay_ahead import DecayAhead
from .field_matrices import FieldMatrices, field_matrices
from .kernel import kernel_matrix
from .params import PFParams
from .spreads import Spreads, read_only
from .view import active_guard_nodes, sighting_node


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


#: "no personal term" for the compiled scores
_NO_TERM = np.zeros(0)


def _field_kernels() -> ModuleType:
    """The compiled decision scores (:mod:`ai.field_kernels`), imported at first use (numba
    costs a second of start-up a program without PF guards need not pay)."""
    from . import field_kernels

    return field_kernels


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
        potential = read_only(composite_potential(self.weights, self.information, self.extra,
                                                   self.confidence, self.connectivity))
        return {"I": self.information, "I_extra": self.extra, "C": self.confidence,
                "N": self.connectivity, "P": potential,
                "K": read_only(self.kernel_matrix @ potential)}


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
        zeros = read_only(np.zeros(n))
        self._information = zeros
        self._confidence = zeros
        self._extra = zeros
        self._confidence_decay = read_only(np.full(n, self.params.rho))
        self._decay_cache: tuple[float, np.ndarray, np.ndarray] | None = None
        #: the next tick's decayed I and C, being computed ahead (:meth:`work_ahead`)
        self._ahead: DecayAhead | None = None
        self._last_dt = 0.0
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
    def spreads(self) -> Spreads:
        """The graph's spreads (rows or balls), e.g. for :class:`ai.prefetch.Prefetch`."""
        return self.matrices.spreads

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
        self._extra = read_only(information_layer(values, self.graph.n))
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
        self._confidence_decay = read_only(values)
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
        rho_dt, decay = p.rho**dt, self._decay_power(dt)
        ahead, self._ahead = self._ahead, None
        if ahead is not None and ahead.matches(dt, self._information, rho_dt,
                                               self._confidence, decay):
            decayed_information, confidence = ahead.result()
        else:
            decayed_information = None
            confidence = self._confidence * decay
        if sighting_node is not None:
            information = -p.I0 * m.info_spread(sighting_node)
            self._set_w_I(p.w_I_max)
        else:
            information = (self._information * rho_dt if decayed_information is None
                           else decayed_information)
            self._set_w_I(max(p.w_I_base, self.w_I - p.weight_decay * dt))
        if self.w_I < self._w_I_floor:
            self._set_w_I(self._w_I_floor)
        guards = np.asarray(guard_nodes, dtype=np.intp)
        if len(guards):
            m.deposit_into(confidence, guards, p.C0)  # C · decay^dt + C0 Σ_g γ_C^d(g, ·)
        if dt > 0:
            self._last_dt = dt
        self._information = read_only(information)
        self._confidence = read_only(confidence)
        self.ticks += 1
        self._version += 1

    def work_ahead(self, deadline: float) -> bool:
        """Compute the next tick's ``I · ρ^dt`` and ``C · decay^dt`` until ``deadline``
        (``time.perf_counter()``), a slice at a time (:class:`~ai.decay_ahead.DecayAhead`),
        for a tick as long as the last; whether work is left. Changes no result: the tick
        uses them only if made from the arrays it would multiply."""
        dt = self._last_dt
        if dt <= 0:
            return False  # no tick yet to take the length from
        rho_dt, decay = self.params.rho**dt, self._decay_power(dt)
        ahead = self._ahead
        if ahead is None or not ahead.matches(dt, self._information, rho_dt,
                                              self._confidence, decay):
            ahead = self._ahead = DecayAhead(dt, self._information, rho_dt,
                                             self._confidence, decay)
        return ahead.run(deadline)

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
        if self.matrices.spreads.tables:
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
        if self.matrices.spreads.tables:  # a dense graph: a handful of floats, no arrays
            choice = self._select_dense(candidates, rng, teammates, recent, personal)
            if choice is not None:
                return choice
        return self._select_arrays(node, candidates, rng, teammates, recent, personal)

    def _select_arrays(
        self,
        node: int,
        candidates: np.ndarray,
        rng: np.random.Generator,
        teammates: Sequence[int] | np.ndarray,
        recent: Sequence[int] | np.ndarray,
        personal: np.ndarray | None,
    ) -> Choice:
        """:meth:`select` on arrays (any graph; large ones read K at the candidates alone)."""
        scores = self.kernel_at(node)
        scale = self.w_C * self.params.teammate_presence * self.params.C0
        if len(teammates) and scale:
            scores = scores + scale * self.matrices.presence(teammates, node)
        revisit = self.revisit_term(candidates, recent)
        if revisit is not None:
            scores = scores + revisit
        if personal is not None:
            scores = scores + personal[candidates]
        # np.minimum.reduce is what ndarray.min calls, without its Python wrapper (~1 us)
        tied = candidates[scores - np.minimum.reduce(scores) < self.params.tie_eps]
        winner = tied[0] if len(tied) == 1 else tied[rng.integers(len(tied))]
        return Choice(int(winner), candidates, scores, tied)

    def _select_dense(
        self,
        candidates: np.ndarray,
        rng: np.random.Generator,
        teammates: Sequence[int] | np.ndarray,
        recent: Sequence[int] | np.ndarray,
        personal: np.ndarray | None,
    ) -> Choice | None:
        """:meth:`select` for a graph with dense tables, compiled (:mod:`ai.field_kernels`):
        each score is the same IEEE operations in the same order as the array path (K, plus
        scale × the teammates' presence summed left to right, plus the revisit term, plus
        the personal term), so the same bits and the same draw; None (use the array path)
        when a score is NaN, where a running minimum and numpy's disagree."""
        p = self.params
        scale = self.w_C * p.teammate_presence * p.C0
        table = self.matrices.presence_table
        assert table is not None  # spreads.tables: the dense table exists
        revisit_scale = self.w_C * p.revisit_penalty * p.C0
        revisit = bool(len(recent)) and bool(revisit_scale)  # revisit_term's condition
        scores, tied, ok = _field_kernels().dense_scores(
            self.kernel(), candidates, table, np.asarray(teammates, dtype=np.intp), scale,
            np.asarray(recent, dtype=np.int64), revisit_scale * 1.0, revisit_scale * 0.0,
            revisit, _NO_TERM if personal is None else personal, p.tie_eps)
        if not ok:
            return None
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
        # per candidate scale × (in recent): the same products as numpy's scale × a bool
        # array (× 1.0 or × 0.0, so a negative scale still gives -0.0), from a set on
        # Python ints: np.isin costs ~25 us on these 4-10 element arrays, a broadcast ~4 us
        found = set(np.asarray(recent).tolist()) if isinstance(recent, np.ndarray) else set(recent)
        hit, miss = scale * 1.0, scale * 0.0
        return np.array([hit if c in found else miss for c in candidates.tolist()],
                        dtype=np.float64)

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
    "information_layer",
    "sighting_node",
]
