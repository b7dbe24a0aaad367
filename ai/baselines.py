"""The paper's baseline guards (SPEC §4): RandomWalk, Cheat, FSM and Staleness.

FSM and Staleness share one state machine (:class:`ScriptedGuards`) and differ only in how
a patrolling guard picks its next target. State changes and timers advance in ``tick`` (once
per AI tick); ``decide`` only turns the current state into the next node, stepping along
the shortest path by :func:`~ai.view.move_horizon` (one cell on the grid).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from navmesh.graph import NodeGraph

from .fields import active_guard_nodes, information_layer, sighting_node
from .params import FSMParams, StalenessParams
from .view import GuardAI, WorldView, move_horizon

PATROL, INVESTIGATE, CHASE, RETURN = "patrol", "investigate", "chase", "return"

#: tolerance of timer comparisons, so 0.1-s ticks summed ten times still make 1 s
_TIME_EPS = 1e-9


class RandomWalkGuards(GuardAI):
    """Each guard moves to a uniformly random neighbouring node at every decision."""

    mode = "random"

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        self.graph, self.rng = graph, rng

    def decide(self, i: int, view: WorldView) -> int:
        node = int(view.guard_nodes[i])
        options = self.graph.neighbors[node]
        if len(options) == 0:
            return node
        return int(options[self.rng.integers(len(options))])


class CheatGuards(GuardAI):
    """Every guard follows the shortest path to the player's true position (an upper bound)."""

    mode = "cheat"

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        self.graph = graph
        self.horizon = move_horizon(graph, float(self.params.get("r_edge_factor", 2.5)))

    def decide(self, i: int, view: WorldView) -> int:
        return self.graph.step_towards(int(view.guard_nodes[i]), view.player_node, self.horizon)


@dataclass
class GuardState:
    """One scripted guard's state and timers (seconds)."""

    state: str = PATROL
    time_in_state: float = 0.0
    #: patrol target (kept across Investigate/Chase/Return so Patrol resumes it)
    target: int | None = None
    #: where the guard left its patrol; Return walks back here
    route_node: int | None = None
    #: Investigate: the last known position being searched
    spot: int | None = None
    #: Investigate: the guard has reached the spot
    arrived: bool = False
    #: Investigate: seconds searched, counted from the first AI tick at or after arrival
    search_time: float | None = None
    #: Chase: seconds since any guard last saw the player
    unseen: float = 0.0
    #: Return after Chase hit chase_max: the guard ignores the player until back on patrol
    gave_up: bool = False


class ScriptedGuards(GuardAI):
    """Patrol → Investigate → Chase → Return → Patrol (paper Table 2; SPEC §4).

    Rules, evaluated per guard at every AI tick (``tick``):

    * **Chase** starts when *this* guard sees the player (from Patrol, Investigate, or a
      Return that did not follow a give-up). The chaser heads for the team's last known
      player node, updated whenever *any* guard sees the player (shared radio). It ends after
      ``t_lose_sight`` with no sighting by any guard (a sighting between two ticks
      counts), or after ``chase_max`` in Chase; then **Return**. A guard that sees the
      player when it decides switches to Chase at once; all other changes happen in
      ``tick``.
    * **Investigate** starts on information of strength ≥ ``info_threshold``: a sighting by
      any guard since the last tick (strength ``sighting_information``) or a stimulus layer
      whose magnitude at the guard's node, ``|extra_information[node]|``, reaches the
      threshold (the guard then investigates the layer's strongest node). The guard walks
      to the spot, then searches around it (random steps within one hop) for
      ``t_investigate`` seconds counted from its arrival; then **Return**.
    * **Return** walks back to where the guard left its patrol, for at most ``return_max``
      seconds (or until it is there); then **Patrol** resumes the old target.
    """

    mode = ""
    config_type: ClassVar[type[FSMParams]] = FSMParams

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.config = self.config_type.from_mapping(self.params)

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        self.graph, self.rng, self.n_guards = graph, rng, n_guards
        self.horizon = move_horizon(graph, self.config.r_edge_factor)
        self.guards = [GuardState() for _ in range(n_guards)]
        self.last_known: int | None = None
        self._extra = np.zeros(graph.n)
        self._routes: dict[int, list[int]] = {}
        self._route_at: dict[int, int] = {}

    def set_patrol_routes(self, routes: Sequence[Sequence[int]]) -> None:
        """A guard with a route patrols it in order, round and round (from its first point),
        instead of choosing its patrol targets; chase, investigate and return are unchanged,
        and Patrol resumes the route where it left it."""
        self._routes = {i: [int(v) for v in route] for i, route in enumerate(routes)
                        if len(route) and i < self.n_guards}
        self._route_at = {i: -1 for i in self._routes}

    def _route_target(self, i: int, node: int) -> int:
        """The next node of guard ``i``'s route that is not ``node``."""
        route = self._routes[i]
        for _ in range(len(route)):
            self._route_at[i] = (self._route_at[i] + 1) % len(route)
            if route[self._route_at[i]] != node:
                break
        return route[self._route_at[i]]

    # ------------------------------------------------------------------ stimuli hook
    @property
    def extra_information(self) -> np.ndarray:
        """Stimulus information layers (n,), ≤ 0 for attractive stimuli; zeros by default.

        Same hook as the PF guards': the stimulus module assigns the sum of its layers. A
        guard whose node has ``|layer| ≥ info_threshold`` investigates the layer's minimum.
        """
        return self._extra

    @extra_information.setter
    def extra_information(self, values: np.ndarray) -> None:
        self._extra = information_layer(values, self.graph.n)

    def hears_stimuli(self) -> bool:
        """Scripted guards investigate strong stimulus layers (no weight floor: no weights)."""
        return True

    def set_extra_information(self, layer: np.ndarray) -> None:
        self.extra_information = layer

    # ------------------------------------------------------------------ timers and states
    def tick(self, view: WorldView, dt: float) -> None:
        """Advance every guard's timers and switch states (see the class docstring)."""
        c = self.config
        seen_by = set(view.seen_by)
        sighting = sighting_node(view)
        if sighting is not None:
            self.last_known = sighting
        stimulus_source = (
            int(np.argmin(self._extra)) if self._extra.size and self._extra.min() < 0 else None
        )
        heard = self._sighting_heard(sighting, view.guard_nodes)
        active = view.guard_active
        for i, gs in enumerate(self.guards):
            if active is not None and not active[i]:
                continue
            node = int(view.guard_nodes[i])
            gs.time_in_state += dt
            if gs.state == CHASE:
                gs.unseen = 0.0 if sighting is not None else gs.unseen + dt
                if gs.unseen >= c.t_lose_sight - _TIME_EPS:
                    self._enter(gs, RETURN, node)
                elif gs.time_in_state >= c.chase_max - _TIME_EPS:
                    self._enter(gs, RETURN, node)
                    gs.gave_up = True
                continue
            deaf = gs.state == RETURN and gs.gave_up
            if i in seen_by and not deaf:
                self._enter(gs, CHASE, node)
                continue
            info_node = None
            if sighting is not None and heard[i]:
                info_node = sighting
            elif stimulus_source is not None and -self._extra[node] >= c.info_threshold:
                info_node = stimulus_source
            if info_node is not None and not deaf:
                if gs.state != INVESTIGATE or gs.spot != info_node:
                    self._enter(gs, INVESTIGATE, node)
                    gs.spot = info_node
                # fresh information restarts the search (and the walk, unless already there)
                gs.arrived, gs.search_time = node == info_node, None
            if gs.state == INVESTIGATE:
                gs.arrived = gs.arrived or node == gs.spot
                if gs.arrived:
                    gs.search_time = 0.0 if gs.search_time is None else gs.search_time + dt
                    if gs.search_time >= c.t_investigate - _TIME_EPS:
                        self._enter(gs, RETURN, node)
            elif gs.state == RETURN and (
                gs.time_in_state >= c.return_max - _TIME_EPS or node == gs.route_node
            ):
                self._enter(gs, PATROL, node)

    def _sighting_heard(self, sighting: int | None, guard_nodes: np.ndarray) -> np.ndarray:
        """Per guard: whether the sighting's information reaches ``info_threshold`` for it.

        ``team``: everyone, when ``sighting_information`` does. ``local``: a guard whose node
        is within the hops where ``sighting_information × information_falloff^hops`` does
        (one breadth-first search bounded at that depth, from the sighting node).
        """
        c = self.config
        n = len(guard_nodes)
        if sighting is None or c.sighting_information < c.info_threshold:
            return np.zeros(n, dtype=bool)
        if c.investigate == "team":
            return np.ones(n, dtype=bool)
        inside, _ = self.graph.hop_ball(sighting, _information_depth(
            c.sighting_information, c.information_falloff, c.info_threshold))
        at = np.searchsorted(inside, guard_nodes)
        return (at < len(inside)) & (inside[np.minimum(at, len(inside) - 1)] == guard_nodes)

    @staticmethod
    def _enter(gs: GuardState, state: str, node: int) -> None:
        if (gs.state == PATROL and state != PATROL) or gs.route_node is None:
            gs.route_node = node  # where the guard leaves its patrol
        gs.state, gs.time_in_state = state, 0.0
        gs.unseen, gs.gave_up = 0.0, False
        gs.spot, gs.arrived, gs.search_time = None, False, None

    # ------------------------------------------------------------------ movement
    def decide(self, i: int, view: WorldView) -> int:
        """The next node for guard ``i``'s current state, one move horizon along its path."""
        gs = self.guards[i]
        node = int(view.guard_nodes[i])
        if view.seen_by:
            self.last_known = int(view.player_node)
        self._visit(node)
        if i in view.seen_by and gs.state != CHASE and not (gs.state == RETURN and gs.gave_up):
            self._enter(gs, CHASE, node)  # seeing the player needs no timer: chase at once
        if gs.state == CHASE:
            goal = self.last_known if self.last_known is not None else node
        elif gs.state == INVESTIGATE and gs.spot is not None:
            gs.arrived = gs.arrived or node == gs.spot
            goal = self._look_around(gs.spot, node) if gs.arrived else gs.spot
        elif gs.state == RETURN and gs.route_node is not None and node != gs.route_node:
            goal = gs.route_node
        else:
            if gs.target is None or node == gs.target:
                gs.target = (self._route_target(i, node) if i in self._routes
                             else self._patrol_target(i, node))
            goal = gs.target
        return self.graph.step_towards(node, goal, self.horizon)

    def _look_around(self, spot: int, node: int) -> int:
        """A random node within one hop of the investigated spot, other than where the guard is."""
        around = np.append(self.graph.neighbors[spot], spot)
        around = around[around != node]
        return int(around[self.rng.integers(len(around))]) if len(around) else node

    def _taken_targets(self, i: int) -> list[int]:
        return [g.target for j, g in enumerate(self.guards) if j != i and g.target is not None]

    def _visit(self, node: int) -> None:
        """Hook: a guard stands on ``node`` (Staleness resets it)."""

    def _patrol_target(self, i: int, node: int) -> int:
        raise NotImplementedError

    def state_name(self, i: int) -> str:
        """patrol / investigate / chase / return."""
        return self.guards[i].state


class FSMGuards(ScriptedGuards):
    """FSM baseline: patrols random reachable targets (uniform, never another guard's)."""

    mode = "fsm"
    config_type = FSMParams

    def _patrol_target(self, i: int, node: int) -> int:
        allowed = self.graph.reachable_from(node)
        allowed[node] = False
        allowed[self._taken_targets(i)] = False
        options = np.flatnonzero(allowed)
        return int(options[self.rng.integers(len(options))]) if len(options) else node


class StalenessGuards(ScriptedGuards):
    """Staleness baseline: patrols to where the team has not looked (``model``) for longest.

    Staleness grows by ``increment`` per second of AI tick (``increment × dt``) everywhere
    and is reset to 0 on every active guard's node at each tick and on a guard's node
    whenever it decides (so cells a guard walks through between ticks count). Then:

    * ``model = "node"`` (the rule before SPEC §11): the target is the stalest reachable
      node that no other guard is heading for; ties are drawn with the trial's generator.
      Every node no guard stood on is equally stale, so this is close to the FSM's patrol.
    * ``model = "view"`` (Al Enezi & Verbrugge 2020; docs/ai.md): staleness is also reset on
      every node a guard sees at the tick (``view.guard_sight``, computed by the world). The
      target maximises ``staleness − distance_weight × path distance`` over the reachable
      nodes farther than ``spread_radius`` from every other guard's target (ties drawn with
      the generator), and a target that any guard sees is done: the guard picks the next
      at its next decision.
    * ``model = "alenezi"`` (SPEC §12): Al Enezi & Verbrugge's grid patroller as their
      simulator's code scores it (wralenezi/Stealth-Simulator,
      ``Assets/Resources/Scripts/NPCs/NPCBehaviors/Guards/Patroler/Gridbased/``
      ``GridPatroler.cs`` and ``GridPatrolerDecisionMaker.cs``). Staleness is reset as in
      ``view``; a target maximises ``staleness_weight × s̃ + distance_weight × (1 − d/L) +
      separation_weight × d_sep/L``, where ``s̃ = (s − min s) / (max s − min s)`` is the
      staleness normalised over all nodes (their ``CalculateHeatValues``; 0 when all are
      equal), ``d`` the path distance from the guard, ``d_sep`` the path distance to the
      nearest other active guard (1·L when there is none or it is unreachable), ``L`` the
      graph's longest shortest path
      (:meth:`~navmesh.graph.NodeGraph.longest_shortest_path`). A node within 1 world unit of
      another guard's target is taken (their ``IsGoalTaken``: squared distance ≤ 1).
      The target is kept until the guard reaches it (their guard asks for a new goal only
      when it is not busy): no target is dropped for being seen. Ties (within 1e-9) are
      drawn with the generator (their loop keeps the first node of its list).
    """

    mode = "staleness"
    config_type = StalenessParams

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        super().reset(graph, rng, n_guards)
        self.staleness = np.zeros(graph.n)
        model = self.config.model  # type: ignore[attr-defined]
        self.by_view = model in ("view", "alenezi")
        #: view: a target in sight is done; alenezi keeps it until the guard is there
        self.drops_seen = model == "view"
        self._guard_nodes: np.ndarray | None = None
        self._guard_active: np.ndarray | None = None

    def wants_guard_sight(self) -> bool:
        """The view and alenezi models reset staleness on what the guards see."""
        return self.config.model in ("view", "alenezi")  # type: ignore[attr-defined]

    def decide(self, i: int, view: WorldView) -> int:
        """The FSM's decision; alenezi's patrol target reads where the other guards are."""
        self._guard_nodes, self._guard_active = view.guard_nodes, view.guard_active
        return super().decide(i, view)

    def tick(self, view: WorldView, dt: float) -> None:
        """Staleness grows by ``increment × dt`` and resets under (view: in sight of) the
        guards; then the FSM tick."""
        self.staleness += self.config.increment * dt  # type: ignore[attr-defined]
        self.staleness[active_guard_nodes(view)] = 0.0
        if self.by_view and view.guard_sight is not None:
            sights = [s for s in view.guard_sight if len(s)]
            if sights:
                self.staleness[np.concatenate(sights)] = 0.0
            for gs in self.guards if self.drops_seen else ():  # a target in sight has been
                if gs.target is not None and self.staleness[gs.target] == 0.0:  # looked at
                    gs.target = None
        super().tick(view, dt)

    def _visit(self, node: int) -> None:
        self.staleness[node] = 0.0

    def _patrol_target(self, i: int, node: int) -> int:
        taken = self._taken_targets(i)
        if self.config.model == "alenezi":  # type: ignore[attr-defined]
            return self._alenezi_target(i, node, taken)
        if not self.by_view:
            values = np.where(self.graph.reachable_from(node), self.staleness, -np.inf)
        else:
            c = self.config
            distance = self.graph.dist_from(node)  # the row the step along the path reads too
            values = np.where(np.isfinite(distance),
                              self.staleness - c.distance_weight * distance,  # type: ignore[attr-defined]
                              -np.inf)
            values = self._spread(values, taken, c.spread_radius)  # type: ignore[attr-defined]
        values[node] = -np.inf
        values[taken] = -np.inf
        best = values.max()
        if not np.isfinite(best):
            return node
        stalest = np.flatnonzero(values >= best - 1e-9)
        return int(stalest[self.rng.integers(len(stalest))])

    def alenezi_scores(self, i: int, node: int) -> np.ndarray:
        """Per node, guard ``i``'s alenezi score from ``node`` (see the class; ``-inf`` where
        unreachable). Their ``GetWeightedSumFittestTarget`` term by term."""
        c = self.config
        graph = self.graph
        s = self.staleness
        lo, hi = float(s.min()), float(s.max())
        stale = (s - lo) / (hi - lo) if hi > lo else np.zeros(graph.n)
        longest = graph.longest_shortest_path()
        distance = graph.dist_from(node)
        others = [int(v) for j, v in enumerate(self._guard_nodes if self._guard_nodes is not None
                                               else ())
                  if j != i and (self._guard_active is None or self._guard_active[j])]
        separation = np.ones(graph.n)
        if others:
            nearest = graph.nearest_dist(others) / longest
            separation = np.where(np.isfinite(nearest), nearest, 1.0)
        score = (c.staleness_weight * stale  # type: ignore[attr-defined]
                 + c.distance_weight * (1.0 - distance / longest)  # type: ignore[attr-defined]
                 + c.separation_weight * separation)  # type: ignore[attr-defined]
        return np.where(np.isfinite(distance), score, -np.inf)

    def _alenezi_target(self, i: int, node: int, taken: list[int]) -> int:
        values = self.alenezi_scores(i, node)
        values[node] = -np.inf
        if taken:  # IsGoalTaken: within 1 unit (squared distance <= 1) of another's goal
            pos = self.graph.positions
            for t in taken:
                d = pos - pos[t]
                values[d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] <= ALENEZI_TAKEN_RADIUS ** 2] = -np.inf
        best = values.max()
        if not np.isfinite(best):
            return node
        fittest = np.flatnonzero(values >= best - 1e-9)
        return int(fittest[self.rng.integers(len(fittest))])

    def _spread(self, values: np.ndarray, taken: list[int], radius: float) -> np.ndarray:
        """``values`` with the nodes within ``radius`` of another guard's target ruled out,
        unless that rules out everything (a small level, many guards)."""
        if not taken or radius <= 0:
            return values
        pos = self.graph.positions
        near = np.zeros(self.graph.n, dtype=bool)
        for t in taken:
            d = pos - pos[t]
            near |= d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] <= radius * radius
        spread = np.where(near, -np.inf, values)
        return spread if np.isfinite(spread).any() else values


#: ``staleness.model = "alenezi"``: a goal this close (world units) to another guard's goal is
#: taken (GridPatrolerDecisionMaker.IsGoalTaken: ``minSqrMagThreshold = 1``)
ALENEZI_TAKEN_RADIUS = 1.0

def _information_depth(strength: float, falloff: float, threshold: float) -> int | None:
    """The largest hop count d with ``strength × falloff^d ≥ threshold`` (None: any depth).

    >>> _information_depth(5.0, 0.9, 1.0), _information_depth(5.0, 0.5, 5.0), _information_depth(5.0, 1.0, 1.0)
    (15, 0, None)
    """
    if threshold <= 0 or falloff >= 1.0:
        return None
    if falloff <= 0.0:
        return 0
    depth = max(0, int(np.floor(np.log(threshold / strength) / np.log(falloff))))
    while strength * falloff ** (depth + 1) >= threshold:  # the floor may round either way
        depth += 1
    while depth > 0 and strength * falloff**depth < threshold:
        depth -= 1
    return depth


__all__ = [
    "RandomWalkGuards",
    "CheatGuards",
    "FSMGuards",
    "StalenessGuards",
    "ScriptedGuards",
    "GuardState",
]
