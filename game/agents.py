"""Agents and their locomotion: circle bodies walking to a target node along waypoints.

The world asks a controller for a target node; :class:`Locomotion` turns it into waypoints
(the neighbouring cell centre on the grid, whose moves are clear for the body; on the
partition the funnel path through the walkable area eroded by the body radius, see
:mod:`navmesh.clearance`), sets each body's velocity towards the next waypoint so it lands
on it exactly, and pops the waypoints the body reached. A body stuck on a plan re-plans
once from where it stands along the eroded area before its controller is asked again.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pymunk

from navmesh.clearance import clearance_for
from navmesh.graph import NodeGraph
from navmesh.level import Level
from navmesh.query import find_path

WALL_CATEGORY = 0b01
AGENT_CATEGORY = 0b10
#: Agents collide with walls only: guards blocking each other in one-cell corridors would
#: deadlock, and the paper's agents pass through each other too.
AGENT_FILTER = pymunk.ShapeFilter(categories=AGENT_CATEGORY, mask=WALL_CATEGORY)
WALL_QUERY = pymunk.ShapeFilter(mask=WALL_CATEGORY)
WALL_SHAPES = pymunk.ShapeFilter(categories=WALL_CATEGORY)
ARRIVE_EPS = 1e-3


@dataclass
class Agent:
    """A circle body walking towards a target node along a list of waypoints."""

    body: pymunk.Body
    speed: float
    node: int
    target: int
    heading: float = 0.0
    waypoints: deque[tuple[float, float]] = field(default_factory=deque)
    since_target: float = 0.0
    active: bool = True
    history: deque[int] = field(default_factory=lambda: deque(maxlen=5))
    #: position cached once per physics step (reading pymunk's Vec2d costs ~1 µs a time)
    pos: tuple[float, float] = (0.0, 0.0)
    velocity: tuple[float, float] = (0.0, 0.0)
    #: (waypoint, speed, distance left after this step) while cruising a straight stretch
    cruise: tuple[tuple[float, float], float, float] | None = None
    #: whether the last physics step moved the body exactly as commanded (no wall contact)
    on_track: bool = False
    #: whether the current plan is already a re-plan after being stuck (Locomotion.settle)
    replanned: bool = False

    def sync(self) -> None:
        """Read the body's position after a physics step."""
        p = self.body.position
        self.pos = (p.x, p.y)

    def place(self, xy: tuple[float, float]) -> None:
        """Teleport the body (spawn, respawn) and stop it."""
        self.body.position = xy
        self.cruise = None
        self.set_velocity((0.0, 0.0))
        self.pos = (float(xy[0]), float(xy[1]))

    def set_velocity(self, v: tuple[float, float]) -> None:
        """Set the body's velocity, skipping the (slow) write when it is unchanged."""
        if v != self.velocity:
            self.body.velocity = v
            self.velocity = v

    @property
    def needs_decision(self) -> bool:
        """Whether it has reached its target (no waypoints left)."""
        return not self.waypoints


def build_space(level: Level) -> pymunk.Space:
    """A gravity-free pymunk space with the level's walls as frictionless static segments.

    A shape's friction and elasticity start at 0 (chipmunk's cpShapeInit), so they are not
    set again, and the walls are added in one call in the same order: pymunk's attribute
    writes cost ~5 µs each, and an env builds a space every episode.
    """
    space = bodies_space()
    add_walls(space, level)
    return space


def bodies_space() -> pymunk.Space:
    """A gravity-free pymunk space without walls (:func:`add_walls` adds them)."""
    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    return space


def add_walls(space: pymunk.Space, level: Level) -> None:
    """Add the level's walls to ``space`` (:func:`build_space`'s; the batch engine's
    spaces get them when first stepped)."""
    walls = []
    for (ax, ay), (bx, by) in level.walls:
        wall = pymunk.Segment(space.static_body, (ax, ay), (bx, by), 0.0)
        wall.filter = WALL_SHAPES
        walls.append(wall)
    space.add(*walls)


def max_agent_speed(config: Any) -> float:
    """The fastest any agent can walk under ``config`` (world units per second).

    The player sprinting in the fastest scenario, or a guard. ``config`` is a
    :class:`game.config.Config` (anything indexable by dotted key).
    """
    scales = [float(v) for k, v in config.as_dict().items()
              if k.startswith("scenario.") and k.endswith(".player_speed_scale")]
    player = float(config["world.player_speed"]) * max(scales or [1.0])
    return max(float(config["world.guard_speed"]), player * float(config["world.sprint_factor"]))


class Locomotion:
    """Plans, drives and advances agents of one world (graph, level, radius, physics step)."""

    def __init__(self, space: pymunk.Space, graph: NodeGraph, level: Level, radius: float,
                 dt: float) -> None:
        self.space, self.graph, self.level = space, graph, level
        self.radius, self.dt = radius, dt
        self.body = clearance_for(level, radius)
        #: node -> its position as Python floats, filled on first use (a numpy row read
        #: and two float() calls cost more than the rest of a cached plan)
        self._points: dict[int, tuple[float, float]] = {}

    def make_agent(self, node: int, speed: float) -> Agent:
        """A body of the agent radius in the space, standing on ``node``'s position."""
        body = pymunk.Body(1.0, float("inf"))
        shape = pymunk.Circle(body, self.radius)
        shape.filter = AGENT_FILTER
        shape.friction = 0.0
        shape.elasticity = 0.0
        self.space.add(body, shape)
        agent = Agent(body=body, speed=speed, node=node, target=node)
        agent.place(self.stand_point(node))
        return agent

    def node_point(self, node: int) -> tuple[float, float]:
        """A node's position as a new tuple of floats (waypoints are told apart by identity)."""
        point = self._points.get(node)
        if point is None:
            x, y = self.graph.positions[node]
            point = self._points[node] = (float(x), float(y))
        return (point[0], point[1])

    def stand_point(self, node: int) -> tuple[float, float]:
        """Where a body stands on ``node``: its position, or on the partition the nearest
        point a body's centre may occupy (a triangle's centroid can lie by a wall)."""
        if self.graph.mesh is None:
            return self.node_point(node)
        return self.body.snap(*self.node_point(node))

    def plan(self, agent: Agent, target: int) -> None:
        """Waypoints from the agent's position to ``target``'s node position."""
        goal = self.node_point(target)
        agent.target, agent.since_target, agent.replanned = target, 0.0, False
        if self.graph.mesh is None:
            agent.waypoints = deque(self._grid_start(agent) + [goal])
            return
        path = self.body.path(agent.pos, goal)
        if path:
            agent.waypoints = deque(path)
            return
        # No body-wide way (the ends lie in pieces of the eroded area a body cannot join):
        # the centre-line funnel path, corners moved off the walls.
        if target == agent.node:
            agent.waypoints = deque([goal])
            return
        points = find_path(self.graph.mesh, agent.pos, goal).points
        agent.waypoints = deque(self.clear_corners(points))

    def _grid_start(self, agent: Agent) -> list[tuple[float, float]]:
        """On the grid: [] when the body stands on its cell's centre (moves between centres
        are clear), else the body-wide way back to that centre first."""
        centre = self.node_point(agent.node)
        x, y = agent.pos
        if abs(x - centre[0]) < 1e-6 and abs(y - centre[1]) < 1e-6:
            return []
        if self.body.clear_move(agent.pos, centre):
            return [centre]
        return self.body.path(agent.pos, centre)[:-1] + [centre]

    def replan(self, agent: Agent) -> None:
        """A different way to the same target for a stuck agent: from where it stands, back
        onto the body-wide network (grid: via its cell centre along the eroded area, then the
        graph path; partition: the eroded-area path from its current position)."""
        agent.since_target, agent.replanned, agent.cruise = 0.0, True, None
        goal = self.node_point(agent.target)
        if self.graph.mesh is None:
            start = self._grid_start(agent)
            path = self.graph.shortest_path(agent.node, agent.target)
            agent.waypoints = deque(start + [self.node_point(v) for v in path[1:]] or [goal])
            return
        agent.waypoints = deque(self.body.path(agent.pos, goal) or [goal])

    def clear_corners(self, points: np.ndarray) -> list[tuple[float, float]]:
        """Move the funnel path's corner points one agent radius off the wall corner.

        The funnel's interior points are wall vertices, which a body of radius r can never
        reach; shifting each away from the corner along its bisector keeps the turn tight
        without grinding the body along the wall.
        """
        out = []
        for k in range(1, len(points) - 1):
            p = points[k]
            u = points[k - 1] - p
            v = points[k + 1] - p
            nu, nv = np.linalg.norm(u), np.linalg.norm(v)
            if nu < 1e-9 or nv < 1e-9:
                continue
            bisector = u / nu + v / nv
            norm = np.linalg.norm(bisector)
            if norm < 1e-6:
                out.append((float(p[0]), float(p[1])))
                continue
            shifted = p - bisector / norm * (self.radius + 0.02)
            if self.level.contains(float(shifted[0]), float(shifted[1])):
                p = shifted
            out.append((float(p[0]), float(p[1])))
        out.append((float(points[-1][0]), float(points[-1][1])))
        return out

    def drive(self, agent: Agent, speed: float) -> None:
        """Set the body's velocity towards its next waypoint, landing on it exactly.

        On a straight stretch the velocity stays what it was while the body moved exactly
        as commanded (``agent.cruise``), so most steps do no arithmetic here at all.
        """
        if not agent.active or not agent.waypoints:
            agent.cruise = None
            agent.set_velocity((0.0, 0.0))
            return
        waypoint = agent.waypoints[0]
        step = speed * self.dt
        cruise = agent.cruise
        if (cruise is not None and cruise[0] is waypoint and cruise[1] == speed
                and agent.on_track and cruise[2] > step):
            agent.cruise = (waypoint, speed, cruise[2] - step)
            return
        x, y = agent.pos
        dx, dy = waypoint[0] - x, waypoint[1] - y
        d = math.hypot(dx, dy)
        if d < 1e-12:
            agent.cruise = None
            agent.set_velocity((0.0, 0.0))
            return
        if d <= step:
            agent.cruise = None
            agent.set_velocity((dx / self.dt, dy / self.dt))
        else:
            agent.cruise = (waypoint, speed, d - step)
            agent.set_velocity((dx / d * speed, dy / d * speed))
        agent.heading = math.atan2(dy, dx)

    def settle(self, agent: Agent, before: tuple[float, float], speed: float,
               stuck_timeout: float) -> bool:
        """After a physics step (``agent.pos`` read from the body, or set by the batch
        engine): pop reached waypoints, and re-plan an agent
        stuck for ``stuck_timeout`` s (:meth:`replan`; stuck again, its plan is cleared and
        its controller decides anew). True when the agent has just reached its target."""
        x, y = agent.pos
        moved = math.hypot(x - before[0], y - before[1])
        agent.on_track = abs(moved - speed * self.dt) < 1e-9
        agent.since_target += self.dt
        arrived = self.advance(agent, moved, speed * self.dt)
        if agent.waypoints and agent.since_target > stuck_timeout:
            if agent.replanned:
                agent.waypoints.clear()
            else:
                self.replan(agent)
        return arrived

    def advance(self, agent: Agent, moved: float, expected: float) -> bool:
        """Pop reached waypoints (a stalled agent close enough to one counts as arrived);
        True when the agent has just reached its target."""
        while agent.waypoints:
            x, y = agent.pos
            wx, wy = agent.waypoints[0]
            d = math.hypot(wx - x, wy - y)
            stalled = moved < 0.25 * expected
            if d <= ARRIVE_EPS or (stalled and d <= self.radius + 0.05):
                agent.waypoints.popleft()
                if not agent.waypoints:
                    return True
                continue
            break
        return False


__all__ = ["AGENT_FILTER", "Agent", "Locomotion", "WALL_QUERY", "add_walls", "bodies_space",
           "build_space", "max_agent_speed"]
