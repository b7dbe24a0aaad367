"""What the AI sees of the world, and the controller interfaces the world drives.

The world (``game``) builds a :class:`WorldView` whenever a decision or an AI tick is due
and hands it to a :class:`GuardAI` (one object for the whole guard team, since the fields
are shared) or a :class:`PlayerPolicy`. Controllers answer with node indices of the
level's :class:`~navmesh.graph.NodeGraph`; the world turns them into movement. The AI
never touches pymunk and never learns which abstraction it runs on.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from navmesh.graph import NodeGraph


@dataclass(frozen=True)
class Event:
    """Something that happened in the world this AI tick that a mechanic may react to.

    ``kind`` examples: ``"sprint"``, ``"throw_landed"``, ``"decoy_activated"``,
    ``"guard_down"``, ``"guard_on"`` (a guard standing on a decoy or corpse),
    ``"weather"``. ``node`` is where it happened; ``data`` carries anything else.
    """

    kind: str
    node: int = -1
    t: float = 0.0
    data: Mapping[str, Any] = field(default_factory=dict)


@dataclass
class WorldView:
    """A read-only snapshot of the world for the controllers (world units, y down)."""

    t: float
    graph: NodeGraph
    guard_nodes: np.ndarray
    guard_positions: np.ndarray
    guard_headings: np.ndarray
    player_node: int
    player_pos: np.ndarray
    #: indices of the guards that see the player right now
    seen_by: tuple[int, ...] = ()
    #: node where the player was last seen since the previous AI tick, else None
    sighting: int | None = None
    events: tuple[Event, ...] = ()
    #: per-node boolean masks of zones, e.g. ``{"dark": mask, "concealment": mask}``
    zones: Mapping[str, np.ndarray] = field(default_factory=dict)
    #: guards still in play (a guard taken down is inactive)
    guard_active: np.ndarray | None = None
    #: per guard, the nodes it sees at this AI tick (filled only at AI ticks and only for a
    #: mode whose :meth:`GuardAI.wants_guard_sight` is true); None: not computed
    guard_sight: tuple[np.ndarray, ...] | None = None
    #: index of the world's current decision tick (world.decision_interval when decisions
    #: are gated, else the AI tick): a policy that re-plans once per tick compares it
    decision_tick: int = 0

    @property
    def n_guards(self) -> int:
        return len(self.guard_nodes)

    @classmethod
    def at_nodes(
        cls,
        graph: NodeGraph,
        guard_nodes: Sequence[int] | np.ndarray,
        player_node: int,
        *,
        t: float = 0.0,
        active: Sequence[bool] | np.ndarray | None = None,
        **fields: Any,
    ) -> WorldView:
        """A snapshot with every agent standing on a node's centre, headings 0.

        For driving a controller without a world: tests, benchmarks, a designer's notebook.

        >>> import numpy as np
        >>> from navmesh.graph import NodeGraph
        >>> graph = NodeGraph.from_grid(np.ones((1, 4), bool), 1.0)
        >>> WorldView.at_nodes(graph, [0, 1], 3, sighting=3).player_pos.tolist()
        [3.5, 0.5]
        """
        nodes = np.asarray(guard_nodes, dtype=np.int64)
        return cls(
            t=t,
            graph=graph,
            guard_nodes=nodes,
            guard_positions=graph.positions[nodes],
            guard_headings=np.zeros(len(nodes)),
            player_node=int(player_node),
            player_pos=graph.positions[player_node],
            guard_active=np.ones(len(nodes), dtype=bool) if active is None
            else np.asarray(active, dtype=bool),
            **fields,
        )


def move_horizon(graph: NodeGraph, factor: float = 2.5) -> float:
    """How far one decision may reach: one cell on the grid, ``factor`` mean edges on a mesh.

    Baseline controllers with a far goal step along their shortest path by this much, so
    on the grid they move one neighbouring cell per decision (SPEC §6) and on the
    partition they hop a corridor stretch the world walks by funnel path.
    """
    if graph.kind == "grid":
        return graph.cell_size * 1.01
    return factor * graph.mean_edge_length


class GuardAI(ABC):
    """The brain of the whole guard team.

    ``reset`` is called once per trial, ``tick`` once per AI tick (default 1 s) to advance
    shared state (fields, weights, timers), ``decide`` whenever guard ``i`` reaches its
    current target node and needs the next one.
    """

    #: short mode name used on the command line (``pf``, ``random``, ...)
    mode: str = ""

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.params = dict(params or {})

    @abstractmethod
    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        """Start a new trial on ``graph`` with ``n_guards`` guards."""

    def tick(self, view: WorldView, dt: float) -> None:
        """Advance shared state by one AI tick of ``dt`` seconds (no-op by default)."""

    @abstractmethod
    def decide(self, i: int, view: WorldView) -> int:
        """The next target node of guard ``i``."""

    # ---------------------------------------------------------------- capabilities
    # What a mode can do beyond deciding, each with a harmless default (MiniGrid's
    # ``can_overlap``): the world, the stimuli and the front end call these unconditionally.

    def explain(self, i: int) -> dict[str, Any] | None:
        """Why guard ``i`` took its last decision, for modes that can say (else None)."""
        return None

    def state_name(self, i: int) -> str:
        """A short label of guard ``i``'s behaviour state, for traces and the game HUD."""
        return self.mode

    def fields(self) -> dict[str, np.ndarray]:
        """The mode's per-node fields by name (``"I"``, ``"C"``, ``"K"``, ...) for overlays.

        Empty by default: a mode without fields draws no overlay.
        """
        return {}

    def prepare(self, budget: float) -> bool:
        """Spare time of about ``budget`` seconds (the game calls it after each frame): a
        mode may work ahead here, such as cache entries a coming decision will read; never
        anything that changes a result. Returns whether work ahead is left (the game then
        gives more). Nothing by default."""
        return False

    def expect(self, nodes: Sequence[int]) -> None:
        """The guards will soon stand on ``nodes`` (the game's guess: each guard's node and
        target, passed when they change): a mode that works ahead in :meth:`prepare` may put
        what its next tick reads there first. Never changes a result; nothing by default."""

    def fields_later(self) -> tuple[Hashable, Callable[[], dict[str, np.ndarray]]]:
        """:meth:`fields` as they are now, to compute later and on another thread: an
        identity that changes when they change, and the function that computes them (the
        game builds a large level's overlay off the frame). By default they are computed
        now, and the identity is that of the arrays."""
        fields = self.fields()
        return tuple(id(a) for a in fields.values()), lambda: fields

    def set_patrol_routes(self, routes: Sequence[Sequence[int]]) -> None:
        """Receive each guard's patrol route as nodes, in order (an empty route: none), from
        a level that gives routes (a Tiled guard's ``patrol`` property) and places the
        guards (``world.spawns = "level"``); called after :meth:`reset`. Default: ignored
        (modes that choose where to patrol from their fields keep doing so)."""

    def wants_guard_sight(self) -> bool:
        """Whether the mode reads :attr:`WorldView.guard_sight` at its AI ticks (default: no,
        so the world does not compute it)."""
        return False

    def hears_stimuli(self) -> bool:
        """Whether the stimuli's information layer reaches this mode (default: no).

        When false the stimulus set does not even compute the layer for it; a mode that
        returns true receives :meth:`set_extra_information` and
        :meth:`set_information_weight_floor` after every AI tick.
        """
        return False

    def set_extra_information(self, layer: np.ndarray) -> None:
        """Receive the sum of the active stimuli's layers, shape ``(n,)`` (default: ignored)."""

    def set_information_weight_floor(self, floor: float) -> None:
        """Receive the largest information-weight floor the stimuli ask for (default: ignored)."""

    def set_confidence_decay(self, nodes: np.ndarray, rate: float) -> None:
        """Let confidence decay at ``rate`` per second on ``nodes`` (a zone; default: ignored)."""

    def set_guard_information(self, i: int, layer: np.ndarray | None,
                              why: Mapping[str, Any] | None = None) -> None:
        """Receive a field term for guard ``i`` alone, shape ``(n,)`` (``≤ 0`` attracts),
        added to that guard's K at its decisions; ``None`` clears it. ``why`` is a JSON-able
        record of where the term comes from (a coordinated role), for :meth:`explain`.
        Default: ignored."""


@dataclass(frozen=True)
class Action:
    """A player action a scripted policy asks the world for (the keyboard's actions).

    ``kind``: ``"sprint"`` / ``"walk"`` (start / stop sprinting), ``"throw"`` (a decoy
    aimed at ``target``), ``"activate_decoy"``, ``"take_down"``, ``"toggle_rain"``.
    """

    kind: str
    target: tuple[float, float] | None = None


PLAYER_ACTIONS = ("sprint", "walk", "throw", "activate_decoy", "take_down", "toggle_rain")


class PlayerPolicy(ABC):
    """A scripted player: picks the next node whenever the player reaches its target."""

    policy: str = ""

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.params = dict(params or {})

    @abstractmethod
    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        """Start a new trial on ``graph``."""

    @abstractmethod
    def decide(self, view: WorldView) -> int:
        """The player's next target node."""

    def actions(self, view: WorldView) -> Sequence[Action]:
        """Actions to take at this decision (sprint, throw, ...); none by default."""
        return ()


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
