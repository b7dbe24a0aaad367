"""Potential-field guards (mode ``pf``): the paper's method (SPEC §3).

The whole team shares one :class:`~ai.fields.CompositeField`. ``tick`` advances it once per
AI tick; ``decide`` takes the argmin of the kernel-smoothed potential over the guard's
candidate set; ``explain`` says why, in plain JSON-able types.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from navmesh.graph import NodeGraph

from .fields import (
    Choice,
    CompositeField,
    active_guard_nodes,
    composite_potential,
    information_layer,
    sighting_node,
)
from .params import PFParams
from .prefetch import Prefetch
from .view import GuardAI, WorldView


@dataclass(frozen=True)
class _Decision:
    """A decision and references to the (immutable) field arrays it was taken on."""

    t: float
    node: int
    choice: Choice
    information: np.ndarray
    extra: np.ndarray
    confidence: np.ndarray
    weights: tuple[float, float, float]
    teammates: np.ndarray
    recent: tuple[int, ...]
    personal: np.ndarray | None = None
    role: dict[str, Any] | None = None


class PotentialFieldGuards(GuardAI):
    """Guards that descend the team's shared composite potential field (paper §Methods).

    >>> import numpy as np
    >>> from navmesh.graph import NodeGraph
    >>> from ai.view import WorldView
    >>> graph = NodeGraph.from_grid(np.ones((1, 5), bool), 1.0)
    >>> guards = PotentialFieldGuards()
    >>> guards.reset(graph, np.random.default_rng(0), 1)
    >>> view = WorldView(t=0.0, graph=graph, guard_nodes=np.array([2]),
    ...                  guard_positions=graph.positions[[2]], guard_headings=np.zeros(1),
    ...                  player_node=4, player_pos=graph.positions[4], sighting=4)
    >>> guards.tick(view, 1.0)
    >>> guards.decide(0, view), guards.explain(0)["winner"]
    (3, 3)
    """

    mode = "pf"

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.config = PFParams.from_mapping(self.params)

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        """A fresh field on ``graph``; the graph's matrices are reused from the cache."""
        self.graph, self.rng, self.n_guards = graph, rng, n_guards
        self.field = CompositeField(graph, self.config)
        #: the balls this team will read soon, searched in the frames' spare time
        self.prefetch = Prefetch(self.field.spreads)
        self._last: list[_Decision | None] = [None] * n_guards
        #: explain(i)'s answer for the decision it was made from (same dict until the next)
        self._explained: dict[int, tuple[_Decision, dict[str, Any]]] = {}
        #: each guard's last 5 decided nodes (the window the backtrack metric uses)
        self._recent: list[deque[int]] = [deque(maxlen=5) for _ in range(n_guards)]
        #: per guard, its own field term and why (coordinated roles), else None
        self._personal: list[tuple[np.ndarray, dict[str, Any]] | None] = [None] * n_guards

    def tick(self, view: WorldView, dt: float) -> None:
        """Decay and refresh I and C, adapt the weights (eqs. 1–3, 8)."""
        self.field.tick(dt, active_guard_nodes(view), sighting_node(view))

    def decide(self, i: int, view: WorldView) -> int:
        """argmin K over guard ``i``'s candidates (eq. 7).

        Before the trial's first AI tick the field is ticked once with ``dt = 0`` from this
        view, so the first decisions already see the guards' own confidence deposits.
        """
        field = self.field
        if field.ticks == 0:
            field.tick(0.0, active_guard_nodes(view), sighting_node(view))
        node = int(view.guard_nodes[i])
        teammates = _teammate_nodes(view, i)
        recent = self._recent[i]
        if not recent or recent[-1] != node:
            recent.append(node)
        own = self._personal[i] if 0 <= i < len(self._personal) else None
        personal = None if own is None else own[0]
        choice = field.select(node, self.rng, teammates, recent, personal)
        self.prefetch.expect(choice.winner)  # the guard's next node: its deposit ahead
        seen = sighting_node(view)
        if seen is not None:  # the next tick spreads information from here (if still seen)
            self.prefetch.expect(seen, "I")
        self._last[i] = _Decision(
            t=float(view.t),
            node=node,
            choice=choice,
            information=field.information,
            extra=field.extra_information,
            confidence=field.confidence,
            weights=field.weights,
            teammates=teammates,
            recent=tuple(recent),
            personal=personal,
            role=None if own is None else own[1],
        )
        return choice.winner

    # ------------------------------------------------------------------ stimuli hook
    @property
    def extra_information(self) -> np.ndarray:
        """The field's I_extra layer (see :attr:`CompositeField.extra_information`)."""
        return self.field.extra_information

    @extra_information.setter
    def extra_information(self, values: np.ndarray) -> None:
        self.field.extra_information = values

    @property
    def information_weight_floor(self) -> float:
        """Lower bound on w_I asked for by stimuli (see :attr:`CompositeField.information_weight_floor`)."""
        return self.field.information_weight_floor

    @information_weight_floor.setter
    def information_weight_floor(self, value: float | None) -> None:
        self.field.information_weight_floor = value

    def hears_stimuli(self) -> bool:
        """PF guards read the stimuli's layer and weight floor."""
        return True

    def set_extra_information(self, layer: np.ndarray) -> None:
        self.extra_information = layer

    def set_information_weight_floor(self, floor: float) -> None:
        self.information_weight_floor = floor

    def set_confidence_decay(self, nodes: np.ndarray, rate: float) -> None:
        """Zones hook: confidence decay ``rate`` per second in ``nodes`` (indices or a mask)."""
        self.field.set_confidence_decay(nodes, rate)

    def set_guard_information(self, i: int, layer: np.ndarray | None,
                              why: Mapping[str, Any] | None = None) -> None:
        """Roles hook: guard ``i``'s own term, added to its K at its next decisions."""
        if 0 <= i < len(self._personal):
            self._personal[i] = None if layer is None else (
                information_layer(layer, self.graph.n), dict(why or {}))

    # ------------------------------------------------------------------ explainability
    def explain(self, i: int) -> dict[str, Any] | None:
        """Guard ``i``'s last decision: candidates with I, I_extra, C, C_live, N, P, K, winner.

        Plain Python types only (JSON-able); None before the guard's first decision. For
        every candidate ``P = w_I·(I + I_extra) + w_C·(C + C_live) + w_N·N`` (C_live: the
        teammates' presence at their current nodes), ``K`` is the kernel average of that P
        over the candidate's hop ball plus ``revisit`` (eq. 10: ``w_C·revisit_penalty·C0``
        when the candidate is among the guard's last 5 nodes, listed in ``recent``), and
        the winner has the least K.
        """
        record = self._last[i] if 0 <= i < len(self._last) else None
        if record is None:
            return None
        cached = self._explained.get(i)
        if cached is not None and cached[0] is record:  # a pure function of the decision:
            return cached[1]  # the game asks every frame, the decision changes about 1/s
        w_I, w_C, w_N = record.weights  # noqa: N806 — the paper's symbols
        at = np.asarray(record.choice.candidates, dtype=np.intp)
        connectivity = self.field.connectivity[at]
        live = self.field.teammate_confidence_at(record.teammates, at)
        # P as the field computed it for this decision, at the candidates only (eq. 5)
        potential = composite_potential(record.weights, record.information[at],
                                        record.extra[at], record.confidence[at], connectivity)
        revisit_unit = w_C * self.config.revisit_penalty * self.config.C0
        candidates = [
            {
                "node": int(c),
                "I": float(record.information[c]),
                "I_extra": float(record.extra[c]),
                "C": float(record.confidence[c]),
                "C_live": float(live[j]),
                "N": float(connectivity[j]),
                "P": float(potential[j] + w_C * live[j]),
                "revisit": float(revisit_unit if int(c) in record.recent else 0.0),
                "K": float(record.choice.scores[j]),
            }
            for j, c in enumerate(record.choice.candidates)
        ]
        if record.personal is not None:
            for entry, c in zip(candidates, record.choice.candidates, strict=True):
                entry["role_term"] = float(record.personal[c])
        role = {"role": record.role} if record.role is not None else {}
        answer = {
            **role,
            "mode": self.mode,
            "guard": int(i),
            "t": record.t,
            "node": record.node,
            "teammates": [int(g) for g in record.teammates],
            "recent": [int(v) for v in record.recent],
            "weights": {"w_I": w_I, "w_C": w_C, "w_N": w_N},
            "candidates": candidates,
            "winner": record.choice.winner,
            "tied": [int(c) for c in record.choice.tied],
            "tie_broken": bool(len(record.choice.tied) > 1),
        }
        self._explained[i] = (record, answer)
        return answer

    def fields(self) -> dict[str, np.ndarray]:
        """Current I, I_extra, C, N, P, K arrays (read-only), for the game overlay."""
        return self.field.fields()

    def prepare(self, budget: float) -> bool:
        """Work ahead for about ``budget`` s: the next tick's decayed fields
        (:meth:`CompositeField.work_ahead`), then the guards' next nodes' spreads
        (:meth:`Prefetch.run`)."""
        deadline = time.perf_counter() + budget
        fields_left = self.field.work_ahead(deadline)
        return self.prefetch.run(max(0.0, deadline - time.perf_counter())) or fields_left

    def expect(self, nodes: Sequence[int]) -> None:
        """The confidence balls of ``nodes`` first in the work-ahead queue: the next tick
        deposits from the guards' nodes, and every decision reads its teammates' balls."""
        for node in nodes:
            self.prefetch.expect(int(node), urgent=True)

    def fields_later(self) -> tuple[Hashable, Callable[[], dict[str, np.ndarray]]]:
        """The field's state now (:meth:`CompositeField.snapshot`): nothing computed until called."""
        snapshot = self.field.snapshot()
        return snapshot.identity, snapshot.__call__

    def state_name(self, i: int) -> str:
        """``alert`` while a recent detection keeps w_I above its base, else ``patrol``."""
        return "alert" if self.field.w_I > self.config.w_I_base + 1e-12 else "patrol"


def _teammate_nodes(view: WorldView, i: int) -> np.ndarray:
    """Current nodes of the active guards other than ``i``."""
    active = view.guard_active
    others = [k for k in range(len(view.guard_nodes))
              if k != i and (active is None or active[k])]
    return np.asarray(view.guard_nodes, dtype=np.intp)[np.array(others, dtype=np.intp)]


__all__ = ["PotentialFieldGuards"]
