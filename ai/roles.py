"""Coordinated roles inside the shared field (the paper's future work; docs/ai.md).

At every AI tick with a detection (``view.seen_by`` or ``view.sighting``) the team is
split into roles, kept for ``hold_time`` seconds after the last detection:

* **chaser** — the active guard nearest (hops) to the sighting: no term of its own, it
  descends the shared field's information gradient as in the paper;
* **interceptors** — sent to the player's likely *escape nodes*, predicted from the graph
  alone: nodes ``escape_min_hops..escape_max_hops`` hops from the sighting with the largest
  *lead* ``min_g hops(g, v) − hops(s, v)`` (how much sooner the player could be there than
  any guard), spread at least ``escape_min_hops`` apart; never the player's true position;
* **holders** — sent to chokepoints of the bounded neighbourhood ``hops(s, ·) ≤
  choke_radius``: a node u at ring distance d *dominates* a node w farther out when u is
  the only node of its ring on a shortest path s → w; the nodes dominating most (an
  articulation-like measure on shortest paths) are the chokepoints.

Targets go to guards greedily (each target in turn to the free guard nearest to it; ties
drawn with the trial's seeded generator), so an assignment is a function of the seed.
A role is a field term for its guard alone, ``−amplitude · falloff^hops(target, ·)``,
handed over by :meth:`~ai.stimuli.Stimulus.guard_layers` (the guard AI's
``set_guard_information``), and ``explain`` reports it.

>>> import numpy as np
>>> from navmesh.graph import NodeGraph
>>> from ai.stimuli import StimulusSet
>>> from ai.view import WorldView
>>> graph = NodeGraph.from_grid(np.ones((1, 12), bool), 1.0)
>>> roles = Roles(RoleParams(interceptors=1, holders=0))
>>> stimuli = StimulusSet(graph)
>>> _ = stimuli.add(roles)
>>> stimuli.tick(WorldView.at_nodes(graph, [0, 1], 4, t=1.0, sighting=4), 1.0)
>>> [(a.guard, a.role, a.target) for a in roles.assignment]  # the far side: 3 hops ahead
[(1, 'chaser', 4), (0, 'interceptor', 7)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from navmesh.graph import UNREACHABLE_HOPS, NodeGraph

from .bounds import COUNT, NON_NEGATIVE, UNIT, Range
from .params import Params
from .stimuli import FieldContext, Stimulus
from .view import WorldView


@dataclass(frozen=True)
class RoleParams(Params):
    """The ``[roles]`` config section (``enabled`` is the world's switch)."""

    #: how many guards intercept and how many hold chokepoints (the rest chase)
    interceptors: int = 1
    holders: int = 1
    #: escape nodes lie this many hops from the sighting
    escape_min_hops: int = 3
    escape_max_hops: int = 8
    #: the neighbourhood (hops from the sighting) in which chokepoints are looked for
    choke_radius: int = 8
    #: a role's term: −amplitude · falloff^hops(target, ·)
    amplitude: float = 6.0
    falloff: float = 0.9
    #: seconds after the last detection the roles are kept
    hold_time: float = 10.0

    bounds = {
        "interceptors": COUNT, "holders": COUNT,
        "escape_min_hops": Range(1, math.inf, integer=True), "escape_max_hops": Range(1, math.inf, integer=True),
        "choke_radius": Range(2, math.inf, integer=True), "amplitude": NON_NEGATIVE,
        "falloff": UNIT, "hold_time": NON_NEGATIVE,
    }


@dataclass(frozen=True)
class Assignment:
    """One guard's role: what, where to, and why (JSON-able in :meth:`why`)."""

    guard: int
    role: str
    target: int
    reason: str

    def why(self, sighting: int, t: float) -> dict[str, Any]:
        return {"role": self.role, "target": self.target, "sighting": sighting,
                "assigned_at": round(t, 6), "reason": self.reason}


#: hop distances indexable like a matrix: a dense array, or rows on demand (:class:`_HopRows`)
HopTable = Any


class _HopRows:
    """Hop distances indexed like a matrix (``hops[s]``, ``hops[nodes]``, ``hops[s, cols]``),
    each row computed on demand by :meth:`NodeGraph.hops_from` (no all-pairs matrix)."""

    def __init__(self, graph: NodeGraph) -> None:
        self.graph = graph

    def __getitem__(self, key: Any) -> Any:
        if isinstance(key, tuple):
            row, cols = key
            return self.graph.hops_from(int(row))[cols]
        return self.graph.hops_from(key)


def escape_nodes(hops: HopTable, sighting: int, guards: np.ndarray, k: int,
                 min_hops: int, max_hops: int) -> list[tuple[int, int]]:
    """Up to ``k`` (node, lead) escape nodes of a player last seen at ``sighting``.

    Candidates are ``min_hops..max_hops`` hops away; best lead first (then nearer to the
    sighting, then lower index), each at least ``min_hops`` from those already chosen.
    """
    if k <= 0 or not len(guards):
        return []
    from_s = hops[sighting]
    ring = np.flatnonzero((from_s >= min_hops) & (from_s <= max_hops))
    if not len(ring):
        return []
    lead = hops[guards][:, ring].min(axis=0).astype(np.int64) - from_s[ring]
    order = np.lexsort((ring, from_s[ring], -lead))
    chosen: list[tuple[int, int]] = []
    for idx in order:
        v = int(ring[idx])
        if all(hops[v, c] >= min_hops for c, _ in chosen):
            chosen.append((v, int(lead[idx])))
            if len(chosen) == k:
                break
    return chosen


def chokepoints(hops: HopTable, sighting: int, k: int, radius: int,
                exclude: set[int] | frozenset[int] = frozenset()) -> list[tuple[int, int]]:
    """Up to ``k`` (node, dominated) chokepoints within ``radius`` hops of ``sighting``.

    For each ring distance d in ``2..radius−1``, a ring node u dominates w (``d <
    hops(s, w) ≤ radius``) when u is the only ring-d node on a shortest path s → w; most
    dominated first (then nearer, then lower index), nodes in ``exclude`` skipped.

    >>> from navmesh.graph import NodeGraph
    >>> corridor = NodeGraph.from_grid(np.ones((1, 8), bool), 1.0)
    >>> chokepoints(corridor.hops_from(np.arange(corridor.n)), 0, 1, 6)   # in a corridor the nearest ring node cuts most
    [(2, 4)]
    """
    if k <= 0:
        return []
    from_s = hops[sighting]
    scored: list[tuple[int, int, int]] = []
    for d in range(2, radius):
        ring = np.flatnonzero(from_s == d)
        beyond = np.flatnonzero((from_s > d) & (from_s <= radius))
        if not len(ring) or not len(beyond):
            continue
        on_path = (hops[ring][:, beyond] + d) == from_s[beyond][None, :]
        unique = on_path.sum(axis=0) == 1
        counts = (on_path & unique[None, :]).sum(axis=1)
        scored.extend((-int(c), d, int(u)) for u, c in zip(ring, counts, strict=True) if c > 0)
    scored.sort()
    out: list[tuple[int, int]] = []
    for neg, _, u in scored:
        if u in exclude or any(hops[u, c] < 2 for c, _ in out):
            continue
        out.append((u, -neg))
        if len(out) == k:
            break
    return out


class Roles(Stimulus):
    """The team's role assignment as a stimulus: one field term per guard with a target."""

    name = "roles"

    def __init__(self, params: RoleParams | None = None) -> None:
        self.params = params or RoleParams()
        self.assignment: tuple[Assignment, ...] = ()
        self.sighting = -1
        self.assigned_at = 0.0
        self.last_detection: float | None = None
        self.rng: np.random.Generator = np.random.default_rng(0)
        self.graph: NodeGraph | None = None
        self._layers: dict[int, np.ndarray] = {}

    def start(self, ctx: FieldContext) -> None:
        self.rng, self.graph = ctx.rng, ctx.graph

    def on_tick(self, view: WorldView, dt: float) -> None:
        t = float(view.t)
        if view.seen_by or view.sighting is not None:
            node = int(view.player_node) if view.seen_by else int(view.sighting or 0)
            self.last_detection = t
            self.assign(view, node)
        elif self.last_detection is not None and t - self.last_detection > self.params.hold_time + 1e-9:
            self.assignment, self._layers, self.last_detection = (), {}, None

    def assign(self, view: WorldView, sighting: int) -> tuple[Assignment, ...]:
        """Roles for a detection at ``sighting`` (see the module docstring)."""
        p, graph = self.params, view.graph
        hops = _HopRows(graph)
        active = (np.ones(view.n_guards, bool) if view.guard_active is None
                  else np.asarray(view.guard_active, bool))
        guards = [int(i) for i in np.flatnonzero(active)]
        if not guards:
            self.assignment, self._layers = (), {}
            return ()
        nodes = np.asarray(view.guard_nodes, dtype=np.intp)
        free = list(guards)
        chaser = self._nearest(hops, nodes, free, sighting)
        free.remove(chaser)
        out = [Assignment(chaser, "chaser", sighting, "nearest guard to the sighting")]
        escapes = escape_nodes(hops, sighting, nodes[guards], min(p.interceptors, len(free)),
                               p.escape_min_hops, p.escape_max_hops)
        targets = [("interceptor", v, f"escape node {int(hops[sighting, v])} hops from the "
                    f"sighting, {lead} hops ahead of every guard") for v, lead in escapes]
        holds = chokepoints(hops, sighting, min(p.holders, len(free) - len(targets)),
                            p.choke_radius, {v for v, _ in escapes} | {sighting})
        targets += [("holder", u, f"chokepoint {int(hops[sighting, u])} hops from the "
                     f"sighting, sole shortest way to {n} nodes") for u, n in holds]
        for role, target, reason in targets:
            if not free:
                break
            guard = self._nearest(hops, nodes, free, target)
            free.remove(guard)
            out.append(Assignment(guard, role, int(target), reason))
        out += [Assignment(g, "chaser", sighting, "no role left: chases") for g in free]
        self.assignment, self.sighting, self.assigned_at = tuple(out), sighting, float(view.t)
        self._layers = {a.guard: self._pull(hops[a.target]) for a in out if a.role != "chaser"}
        return self.assignment

    def _pull(self, row: np.ndarray) -> np.ndarray:
        """A role's term from its target's hop row: −amplitude · falloff^hops (0 unreachable)."""
        p = self.params
        return -p.amplitude * np.where(row < UNREACHABLE_HOPS, p.falloff ** row.astype(np.float64), 0.0)

    def _nearest(self, hops: HopTable, nodes: np.ndarray, free: list[int], target: int) -> int:
        """The free guard nearest in hops to ``target``; ties drawn with the seeded generator."""
        d = hops[target, nodes[free]]
        tied = [g for g, dist in zip(free, d, strict=True) if dist == d.min()]
        return tied[0] if len(tied) == 1 else tied[int(self.rng.integers(len(tied)))]

    def role_of(self, guard: int) -> str:
        """Guard ``guard``'s role now (``""``: none)."""
        return next((a.role for a in self.assignment if a.guard == guard), "")

    def guard_layers(self, ctx: FieldContext) -> dict[int, tuple[np.ndarray, dict[str, Any]]]:
        by_guard = {a.guard: a for a in self.assignment}
        return {g: (layer, by_guard[g].why(self.sighting, self.assigned_at))
                for g, layer in self._layers.items()}

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": -1, "sighting": self.sighting,
                "roles": [{"guard": a.guard, "role": a.role, "target": a.target}
                          for a in self.assignment]}


__all__ = ["Assignment", "RoleParams", "Roles", "chokepoints", "escape_nodes"]
