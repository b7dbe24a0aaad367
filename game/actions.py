"""The player's actions (SPEC §5): sprint, walk, throw, activate_decoy, take_down, toggle_rain.

Each action is a function ``(world, action) -> True | Refused`` in :data:`ACTIONS`, the one
dispatch table behind :meth:`game.world.World.perform` (a scripted player's
:class:`~ai.view.Action`) and the world's named methods (what the keys do in play). An
action raises an event; the stimulus it makes enters the fields at the next AI tick.

The tunables of these actions are the world's, not the guard AI's; they are declared below
the world, in :mod:`game.action_params`, so the config schema reads them without reaching
the world (docs/world.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ai.view import PLAYER_ACTIONS, Action, Event
from navmesh.level import Level

if TYPE_CHECKING:
    from .world import World


class Refused(str):
    """Why a player action did not happen: a message that is false in a boolean test.

    ``if world.throw_decoy(x, y): ...`` reads naturally, and the front end shows the text.

    >>> bool(Refused("cooldown")), str(Refused("cooldown"))
    (False, 'cooldown')
    """

    def __bool__(self) -> bool:
        return False


Outcome = bool | Refused


def _cell(world: World, x: float, y: float) -> tuple[int, int]:
    cs = world.level.cell_size
    return math.floor(y / cs), math.floor(x / cs)


def node_containing(world: World, x: float, y: float) -> int:
    """The node whose walkable cell or triangle contains (x, y); -1 in a wall or outside."""
    if not (math.isfinite(x) and math.isfinite(y)):
        return -1
    graph = world.graph
    if graph.cell_node is not None:
        row, col = math.floor(y / graph.cell_size), math.floor(x / graph.cell_size)
        rows, cols = graph.cell_node.shape
        return int(graph.cell_node[row, col]) if 0 <= row < rows and 0 <= col < cols else -1
    if graph.mesh is not None:
        return int(graph.mesh.locate(x, y))
    return graph.node_at(x, y) if world.level.contains(x, y) else -1


def landing_node(world: World, x: float, y: float) -> int:
    """Where a decoy thrown at (x, y) lands (SPEC §5: within the Manhattan throw radius).

    The node containing the point if it is walkable and its cell lies within
    ``throw_radius`` cells (Manhattan) of the player's cell; otherwise the point is
    clamped to the nearest node (straight line) whose position is within that radius.
    """
    radius = world.action_params.throw_radius
    prow, pcol = _cell(world, *world.player.pos)
    node = node_containing(world, float(x), float(y))
    if node >= 0:
        row, col = _cell(world, float(x), float(y))
        if abs(row - prow) + abs(col - pcol) <= radius:
            return node
    cs = world.level.cell_size
    cells = np.floor(world.graph.positions / cs).astype(np.int64)
    near = np.abs(cells[:, 1] - prow) + np.abs(cells[:, 0] - pcol) <= radius
    options = np.flatnonzero(near)
    if not len(options):
        return world.player.node
    if not (math.isfinite(x) and math.isfinite(y)):
        x, y = world.player.pos
    d2 = np.sum((world.graph.positions[options] - (x, y)) ** 2, axis=1)
    return int(options[np.argmin(d2)])


def sprint(world: World, action: Action) -> Outcome:
    """Start (``sprint``) or stop (``walk``) sprinting."""
    world.sprinting = action.kind == "sprint"
    return True


def throw(world: World, action: Action) -> Outcome:
    """Throw a decoy towards ``action.target``: a noise impulse where it lands; cooldown."""
    if action.target is None:
        raise ValueError("a throw action needs a target (x, y)")
    if world.done:
        return Refused("the trial is over")
    if world.t < world.next_throw - 1e-9:
        return Refused(f"cooldown, {world.next_throw - world.t:.1f} s left")
    x, y = (float(v) for v in action.target)
    node = landing_node(world, x, y)
    lx, ly = (float(v) for v in world.graph.positions[node])
    world.next_throw = world.t + world.action_params.throw_cooldown
    world.emit("throw_landed", node, x=lx, y=ly, target=[x, y])
    return True


def _decoy_on(world: World, k: int) -> bool:
    pending = any(e.kind == "decoy_activated" and e.data.get("decoy") == k for e in world.events)
    return pending or any(s.decoy == k for s in world.stimuli.active)


def activate_decoy(world: World, action: Action) -> Outcome:
    """Switch on the nearest level decoy within ``decoy_reach`` (line of sight) of the player.

    It draws the guards until they have stood on it for ``decoy_disarm_time``; then it can
    be switched on again.
    """
    if world.done:
        return Refused("the trial is over")
    reach = world.action_params.decoy_reach
    ppos = world.player.pos
    options = sorted(
        (math.hypot(x - ppos[0], y - ppos[1]), k) for k, (x, y) in enumerate(world.decoy_points)
        if world.senses.perceives(ppos, None, (x, y), reach)
    )
    if not options:
        return Refused("no decoy within reach")
    free = [k for _, k in options if not _decoy_on(world, k)]
    if not free:
        return Refused("the decoy is already on")
    world.emit("decoy_activated", world.decoy_nodes[free[0]], decoy=free[0])
    return True


def take_down(world: World, action: Action) -> Outcome:
    """Take down the nearest guard within ``takedown_range`` whose view cone the player is
    outside of (from behind or the side), with no wall between; its body becomes a corpse."""
    if world.done:
        return Refused("the trial is over")
    reach = world.action_params.takedown_range
    ppos = world.player.pos
    best: tuple[float, int] | None = None
    for i, guard in enumerate(world.guards):
        if not guard.active:
            continue
        d = math.hypot(ppos[0] - guard.pos[0], ppos[1] - guard.pos[1])
        if d > 1e-9 and world.senses.in_cone(guard.pos, guard.heading, ppos):
            continue  # the player is inside this guard's view cone
        if not world.senses.perceives(guard.pos, None, ppos, reach):
            continue
        if best is None or d < best[0]:
            best = (d, i)
    if best is None:
        return Refused("no guard within reach from behind")
    world.down_guard(best[1])
    return True


def toggle_rain(world: World, action: Action) -> str:
    """Start or stop the rain; returns ``"on"`` or ``"off"``."""
    world.set_rain(not world.raining)
    return "on" if world.raining else "off"


ACTIONS: dict[str, Callable[[World, Action], Any]] = {
    "sprint": sprint,
    "walk": sprint,
    "throw": throw,
    "activate_decoy": activate_decoy,
    "take_down": take_down,
    "toggle_rain": toggle_rain,
}
assert tuple(ACTIONS) == PLAYER_ACTIONS, "every player action of ai.view needs a handler"


def perform(world: World, action: Action) -> Any:
    """Carry out ``action`` in ``world`` through :data:`ACTIONS`."""
    handler = ACTIONS.get(action.kind)
    if handler is None:
        raise ValueError(f"unknown player action {action.kind!r} (choose from "
                         f"{', '.join(PLAYER_ACTIONS)})")
    return handler(world, action)


class PlayerActions:
    """The world's action methods (a base class of :class:`game.world.World`, so its API
    stays where scripts and the front end look for it). Each returns True when it
    happened, else a :class:`Refused` message."""

    #: set by :meth:`init_actions`
    decoy_points: list[tuple[float, float]]
    decoy_nodes: list[int]
    next_throw: float
    rain_on: bool

    def _world(self) -> World:
        return cast("World", self)

    def init_actions(self, level: Level, *, raining: bool) -> None:
        """The actions' state at the start of a trial: level decoys, throw cooldown, weather."""
        world = self._world()
        world.decoy_points = [(float(x), float(y)) for x, y in level.decoys]
        world.decoy_nodes = [world.graph.node_at(x, y) for x, y in world.decoy_points]
        world.next_throw = 0.0  # earliest time of the next throw (cooldown)
        world.rain_on = False  # read it as ``raining``
        if raining:
            self.set_rain(True, immediately=True)

    def perform(self, action: Action) -> bool | str:
        """Carry out a scripted player's :class:`~ai.view.Action` (:data:`ACTIONS`)."""
        return perform(self._world(), action)

    def landing_node(self, x: float, y: float) -> int:
        """Where a decoy thrown at (x, y) lands (:func:`landing_node`)."""
        return landing_node(self._world(), x, y)

    def throw_decoy(self, x: float, y: float) -> Outcome:
        """Throw a decoy towards (x, y): a noise impulse where it lands; 10 s cooldown."""
        return throw(self._world(), Action("throw", (x, y)))

    def activate_decoy(self) -> Outcome:
        """Switch on the nearest level decoy within ``decoy_reach`` (line of sight)."""
        return activate_decoy(self._world(), Action("activate_decoy"))

    def take_down(self) -> Outcome:
        """Take down the nearest guard within ``takedown_range`` from behind or the side."""
        return take_down(self._world(), Action("take_down"))

    def toggle_rain(self) -> str:
        """Start or stop the rain; returns ``"on"`` or ``"off"``."""
        return toggle_rain(self._world(), Action("toggle_rain"))

    def down_guard(self, i: int) -> None:
        """Take guard ``i`` out of play; its body stays where it is (raises ``"guard_down"``).

        The player's :meth:`take_down` checks range and cone first; scripts may call this
        directly.
        """
        world = self._world()
        guard = world.guards[i]
        if not guard.active:
            raise ValueError(f"guard {i} is already down")
        guard.active = False
        guard.waypoints.clear()
        guard.set_velocity((0.0, 0.0))
        world.emit("guard_down", guard.node, guard=int(i))

    @property
    def raining(self) -> bool:
        """Whether it rains (noises made while it rains are quieter, SPEC §5)."""
        return self._world().rain_on

    def set_rain(self, on: bool, immediately: bool = False) -> None:
        """Start or stop the rain (``immediately``: the stimuli hear it now, not next tick)."""
        world = self._world()
        world.rain_on = bool(on)
        event = Event("weather", -1, world.t, {"rain": bool(on)})
        if immediately:
            world.stimuli.handle(event)
        else:
            world.events.append(event)

    def stimulus_points(self) -> np.ndarray:
        """Positions ``(k, 2)`` of the active decoys, corpses and landed throws, for drawing."""
        world = self._world()
        nodes = [s.node for s in world.stimuli.markers()]
        return world.graph.positions[nodes].reshape(-1, 2)

__all__ = ["ACTIONS", "PlayerActions", "Refused", "landing_node", "node_containing", "perform"]
