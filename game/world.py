"""The simulated world: pymunk bodies, vision cones, attack ranges, scenarios and metrics.

One :class:`World` is one trial in progress. It owns the physics space, the agents and the
metric counters, asks the controllers (``ai``) for target nodes, walks agents there (the
neighbouring cell centre on the grid, the funnel path on the partition) and never imports
pygame: the front end and the headless runner both drive it through :meth:`World.step`.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pymunk
import shapely

from ai import GuardAI, PlayerPolicy, WorldView
from ai.stimuli import (
    StimulusFactory,
    StimulusParams,
    StimulusSet,
    apply_zones,
    zone_view_scale,
    zones_from_config,
)
from ai.view import PLAYER_ACTIONS, Action, Event
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import Level

from .config import Config

WALL_CATEGORY = 0b01
AGENT_CATEGORY = 0b10
#: Agents collide with walls only: guards blocking each other in one-cell corridors would
#: deadlock, and the paper's agents pass through each other too.
AGENT_FILTER = pymunk.ShapeFilter(categories=AGENT_CATEGORY, mask=WALL_CATEGORY)
WALL_QUERY = pymunk.ShapeFilter(mask=WALL_CATEGORY)

SCENARIOS = ("capture", "fixed")
ARRIVE_EPS = 1e-3
#: Ranges are compared with this slack so a distance of exactly the range counts as inside
#: whatever the last bit of the float sum of positions.
RANGE_EPS = 1e-9


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
        return not self.waypoints


class Refused(str):
    """Why a player action did not happen: a message that is false in a boolean test.

    ``if world.throw_decoy(x, y): ...`` reads naturally, and the front end shows the text.
    """

    def __bool__(self) -> bool:
        return False


@dataclass
class Metrics:
    """Counters of one trial (SPEC §7); :meth:`World.metrics` turns them into the JSON row."""

    captures: int = 0
    capture_time: float | None = None
    first_detect_time: float | None = None
    backtracks: int = 0
    dist_sum: float = 0.0
    dist_samples: int = 0
    covered: np.ndarray | None = None
    visits: np.ndarray | None = None
    attacks: np.ndarray | None = None


class World:
    """One trial of one level, abstraction, guard team, player policy, scenario and seed.

    >>> world = World(load_level("maze"), "grid", make_guard_ai("cheat"),  # doctest: +SKIP
    ...               make_player_policy("evade"), config=Config.defaults(), seed=1)
    >>> while not world.done: world.step()  # doctest: +SKIP
    """

    def __init__(
        self,
        level: Level,
        abstraction: str,
        guard_ai: GuardAI,
        player_policy: PlayerPolicy | None,
        *,
        config: Config,
        scenario: str = "capture",
        seed: int = 0,
        rngs: tuple[np.random.Generator, np.random.Generator, np.random.Generator] | None = None,
        interactive: bool = False,
        graph: NodeGraph | None = None,
        stimuli: Sequence[StimulusFactory] = (),
    ) -> None:
        if scenario not in SCENARIOS:
            raise ValueError(f"unknown scenario {scenario!r} (choose capture or fixed)")
        self.level, self.abstraction, self.scenario = level, abstraction, scenario
        self.config = config
        self.graph = graph if graph is not None else graph_for(level, abstraction)
        self.guard_ai, self.player_policy = guard_ai, player_policy
        spawn_rng, guard_rng, player_rng = rngs or default_rngs(seed)
        self.spawn_rng = spawn_rng

        w = config.section("world")
        s = config.section(f"scenario.{scenario}")
        self.dt = float(w["physics_step_interactive"] if interactive else w["physics_step"])
        self.steps_per_tick = max(1, round(float(w["ai_tick"]) / self.dt))
        self.total_steps = round(float(w["duration"]) / self.dt)
        self.end_on_capture = bool(s["end_on_capture"])
        self.view_range = float(w["view_range"]) * float(s["view_range_scale"])
        self.cos_half_fov = math.cos(math.radians(float(w["fov_deg"])) / 2)
        self.attack_range = float(w["attack_range"])
        self.attack_los = bool(w["attack_needs_line_of_sight"])
        self.radius = float(w["agent_radius"])
        self.hp_max = float(w["player_hp"])
        self.stuck_timeout = float(w["stuck_timeout"])
        self.sprint_factor = float(w["sprint_factor"])
        # Zones (SPEC §5) say what they do to confidence decay and view range (ai.stimuli.Zone).
        self.zone_rules = zones_from_config(config.section("zones"))
        concealment = self.zone_rules.get("concealment")
        self.concealment_view_scale = concealment.view_scale if concealment else 1.0
        self.stimulus_params = StimulusParams.from_mapping(config.section("stimuli"))
        # HP is tracked in integer guard-steps of damage so it never drifts with float sums.
        self.damage_steps = 0
        self.lethal_steps = round(self.hp_max / self.dt)

        self.zones = self._zone_masks()
        self.view_scale_at = zone_view_scale(self.zone_rules, self.zones, self.graph.n)
        self._watched: frozenset[int] = frozenset()
        self.space = self._build_space()
        self.step_index = 0
        self.done = False
        self.events: list[Event] = []
        self.tick_events: list[Event] = []
        self.sighting: int | None = None
        self.seen_by: tuple[int, ...] = ()
        self.sprinting = False
        self._sprinted = False
        self.player_input: tuple[float, float] | None = None
        self.on_tick: Callable[[World], None] | None = None

        n = self.graph.n
        self.m = Metrics(
            covered=np.zeros(n, dtype=bool),
            visits=np.zeros(n, dtype=np.int64),
            attacks=np.zeros(n, dtype=np.float64),
        )

        guard_speed = float(w["guard_speed"])
        player_speed = float(w["player_speed"]) * float(s["player_speed_scale"])
        spawn_nodes = self._guard_spawn_nodes(int(w["guards"]), str(w["spawns"]))
        self.guards = [self._make_agent(node, guard_speed) for node in spawn_nodes]
        for guard in self.guards:
            guard.heading = float(spawn_rng.uniform(-math.pi, math.pi))
        self.player = self._make_agent(self.start_node(), player_speed)
        self.player_speed = player_speed

        self.guard_ai.reset(self.graph, guard_rng, len(self.guards))
        if self.player_policy is not None:
            self.player_policy.reset(self.graph, player_rng)
        for guard in self.guards:
            self._enter_node(guard, guard.node, count_visit=True)
            guard.history.append(guard.node)

        # Stimuli (ai.stimuli): world events become field layers for the guard AI's hooks.
        apply_zones(self.guard_ai, self.zone_rules, self.zones)
        self.stimuli = StimulusSet(
            self.graph, self.stimulus_params, guard_ai=self.guard_ai,
            rng=spawn_rng.spawn(1)[0], zones=self.zones,
        )
        self.decoy_points = [(float(x), float(y)) for x, y in level.decoys]
        self.decoy_nodes = [self.graph.node_at(x, y) for x, y in self.decoy_points]
        self._next_throw = 0.0
        self._raining = False
        if self.stimulus_params.raining:
            self._set_rain(True, immediately=True)
        for factory in stimuli:
            self.stimuli.add(factory())
        self.stimuli.refresh()
        self._watched = self.stimuli.marked_nodes()

        self.attackers = 0
        self._dist_key: tuple[int, ...] = ()
        self._dist_now: float | None = None
        self._sense()

    # ------------------------------------------------------------------ construction
    def _zone_masks(self) -> dict[str, np.ndarray]:
        masks = {}
        x, y = self.graph.positions[:, 0], self.graph.positions[:, 1]
        for kind, polygons in self.level.zones.items():
            mask = np.zeros(self.graph.n, dtype=bool)
            for polygon in polygons:
                mask |= shapely.intersects_xy(polygon, x, y)
            masks[kind] = mask
        return masks

    def _build_space(self) -> pymunk.Space:
        space = pymunk.Space()
        space.gravity = (0.0, 0.0)
        for (ax, ay), (bx, by) in self.level.walls:
            wall = pymunk.Segment(space.static_body, (ax, ay), (bx, by), 0.0)
            wall.filter = pymunk.ShapeFilter(categories=WALL_CATEGORY)
            wall.friction = 0.0
            wall.elasticity = 0.0
            space.add(wall)
        return space

    def _make_agent(self, node: int, speed: float) -> Agent:
        body = pymunk.Body(1.0, float("inf"))
        shape = pymunk.Circle(body, self.radius)
        shape.filter = AGENT_FILTER
        shape.friction = 0.0
        shape.elasticity = 0.0
        self.space.add(body, shape)
        agent = Agent(body=body, speed=speed, node=node, target=node)
        agent.place(tuple(float(v) for v in self.graph.positions[node]))
        return agent

    def _guard_spawn_nodes(self, count: int, spawns: str) -> list[int]:
        if spawns == "level":
            return [self.graph.node_at(x, y) for x, y in self.level.guards]
        if spawns != "random":
            raise ValueError(f"world.spawns: expected 'random' or 'level', got {spawns!r}")
        count = min(count, self.graph.n - 1)
        return [int(v) for v in self.spawn_rng.choice(self.graph.n, size=count, replace=False)]

    def start_node(self) -> int:
        """SPEC §7: the node farthest (min shortest path) from every guard, out of their sight.

        Nodes any active guard could see now are excluded unless that leaves none; ties are
        broken with the trial's spawn generator.
        """
        active = [g for g in self.guards if g.active]
        if not active:
            return int(self.spawn_rng.integers(self.graph.n))
        nodes = np.array([g.node for g in active])
        score = self.graph.dist[nodes].min(axis=0)
        visible = np.zeros(self.graph.n, dtype=bool)
        for guard in active:
            visible |= self._visible_nodes(guard)
        if not visible.all():
            score = np.where(visible, -np.inf, score)
        best = np.flatnonzero(score >= score.max() - 1e-9)
        return int(best[self.spawn_rng.integers(len(best))])

    def _visible_nodes(self, guard: Agent) -> np.ndarray:
        gx, gy = guard.pos
        delta = self.graph.positions - (gx, gy)
        dist = np.hypot(delta[:, 0], delta[:, 1])
        hx, hy = math.cos(guard.heading), math.sin(guard.heading)
        in_cone = (dist <= self.view_range) & (
            delta @ (hx, hy) >= self.cos_half_fov * dist - 1e-12
        )
        for node in np.flatnonzero(in_cone):
            if not self._clear_line((gx, gy), tuple(self.graph.positions[node])):
                in_cone[node] = False
        return in_cone

    # ------------------------------------------------------------------ queries
    def _clear_line(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        return self.space.segment_query_first(a, b, 0.0, WALL_QUERY) is None

    def sees(self, guard: Agent, target: tuple[float, float]) -> bool:
        """Vision: within range (scaled by concealment), inside the cone, line of sight clear."""
        if not guard.active:
            return False
        gx, gy = guard.pos
        dx, dy = target[0] - gx, target[1] - gy
        d2 = dx * dx + dy * dy
        reach = self.view_range * self._zone_view_factor() + RANGE_EPS
        if d2 > reach * reach:
            return False
        d = math.sqrt(d2)
        if d > 1e-9 and dx * math.cos(guard.heading) + dy * math.sin(guard.heading) < (
            self.cos_half_fov * d
        ):
            return False
        return self._clear_line((gx, gy), target)

    def _zone_view_factor(self) -> float:
        """Factor on the view range from the zones the player stands in (concealment 0.7)."""
        return float(self.view_scale_at[self.player.node])

    @property
    def hp(self) -> float:
        return self.hp_max - self.damage_steps * self.dt

    @property
    def t(self) -> float:
        return self.step_index * self.dt

    def view(self) -> WorldView:
        """The snapshot the controllers read."""
        return WorldView(
            t=self.t,
            graph=self.graph,
            guard_nodes=np.array([g.node for g in self.guards], dtype=np.int64),
            guard_positions=np.array([g.pos for g in self.guards], dtype=np.float64),
            guard_headings=np.array([g.heading for g in self.guards], dtype=np.float64),
            player_node=self.player.node,
            player_pos=np.array(self.player.pos),
            seen_by=self.seen_by,
            sighting=self.sighting,
            events=tuple(self.tick_events),
            zones=self.zones,
            guard_active=np.array([g.active for g in self.guards], dtype=bool),
        )

    # ------------------------------------------------------------------ movement
    def _plan(self, agent: Agent, target: int) -> None:
        """Waypoints from the agent's position to ``target``'s node position."""
        goal = tuple(self.graph.positions[target])
        agent.target, agent.since_target = target, 0.0
        if self.graph.mesh is None or target == agent.node:
            agent.waypoints = deque([goal])
            return
        if self.graph.kind == "grid":
            path = self.graph.shortest_path(agent.node, target)
            agent.waypoints = deque(tuple(self.graph.positions[v]) for v in path[1:])
            return
        points = self.graph.mesh.find_path(agent.pos, goal).points
        agent.waypoints = deque(self._clear_corners(points))

    def _clear_corners(self, points: np.ndarray) -> list[tuple[float, float]]:
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

    def _drive(self, agent: Agent, speed: float) -> None:
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

    def _advance_waypoints(self, agent: Agent, moved: float, expected: float) -> None:
        """Pop reached waypoints; a stalled agent close enough to one counts as arrived."""
        while agent.waypoints:
            x, y = agent.pos
            wx, wy = agent.waypoints[0]
            d = math.hypot(wx - x, wy - y)
            stalled = moved < 0.25 * expected
            if d <= ARRIVE_EPS or (stalled and d <= self.radius + 0.05):
                agent.waypoints.popleft()
                if not agent.waypoints:
                    self._arrive(agent)
                continue
            break

    def _arrive(self, agent: Agent) -> None:
        """A guard reached its target: count a backtrack if it is among its last 5 nodes."""
        if agent is self.player or agent.target == agent.history[-1]:
            return  # the player is not scored; staying put is not a move
        if agent.target in agent.history:
            self.m.backtracks += 1
        agent.history.append(agent.target)

    def _enter_node(self, agent: Agent, node: int, count_visit: bool) -> None:
        agent.node = node
        if count_visit and agent is not self.player:
            self.m.visits[node] += 1
            self.m.covered[node] = True
            if node in self._watched and agent.active:
                guard = next(i for i, g in enumerate(self.guards) if g is agent)
                self.events.append(Event("guard_on", node, self.t, {"guard": guard}))

    # ------------------------------------------------------------------ the step
    def step(self) -> None:
        """Advance the world by one physics step (decisions, motion, senses, AI tick)."""
        if self.done:
            return
        view = None
        for i, guard in enumerate(self.guards):
            if guard.active and guard.needs_decision:
                view = view or self.view()
                self._plan(guard, int(self.guard_ai.decide(i, view)))
        if self.player_input is None and self.player_policy is not None and self.player.needs_decision:
            view = view or self.view()
            self._plan(self.player, int(self.player_policy.decide(view)))
            for action in self.player_policy.actions(view):
                self.perform(action)

        for guard in self.guards:
            self._drive(guard, guard.speed)
        player_speed = self.player_speed * (self.sprint_factor if self.sprinting else 1.0)
        if self.player_input is not None:
            vx, vy = self.player_input
            self.player.set_velocity((vx * player_speed, vy * player_speed))
            if vx or vy:
                self.player.heading = math.atan2(vy, vx)
        else:
            self._drive(self.player, player_speed)

        before = [a.pos for a in self.guards] + [self.player.pos]
        sprint = self.sprinting
        self.space.step(self.dt)
        self.step_index += 1
        if self.attackers:
            # Guards in range at the start of the step hurt over the whole step, so a
            # player in range from t0 on dies at exactly t0 + HP (per guard).
            self.damage_steps += self.attackers
            self.m.attacks[self.player.node] += self.attackers * self.dt
            if self.damage_steps >= self.lethal_steps:
                self._captured()
                if not self.done:  # respawned: a teleport, not a walk (no footsteps, no stall)
                    before[-1] = self.player.pos

        agents = self.guards + [self.player]
        for agent, (bx, by), speed in zip(
            agents, before, [g.speed for g in self.guards] + [player_speed]
        ):
            agent.sync()
            x, y = agent.pos
            moved = math.hypot(x - bx, y - by)
            agent.on_track = abs(moved - speed * self.dt) < 1e-9
            agent.since_target += self.dt
            self._advance_waypoints(agent, moved, speed * self.dt)
            node = self.graph.node_near(x, y, agent.node)
            if node != agent.node:
                self._enter_node(agent, node, count_visit=True)
            if agent.waypoints and agent.since_target > self.stuck_timeout:
                agent.waypoints.clear()  # re-plan from where it stands
        if sprint and self.player.pos != before[-1]:
            self._sprinted = True  # footsteps: the player moved while sprinting this tick

        self._sense()
        if self.step_index % self.steps_per_tick == 0:
            self._ai_tick()
        if self.step_index >= self.total_steps:
            self.done = True

    def _sense(self) -> None:
        """Vision, attack damage, distance and detection metrics for the current positions."""
        ppos = self.player.pos
        self.seen_by = tuple(i for i, g in enumerate(self.guards) if self.sees(g, ppos))
        if self.seen_by:
            self.sighting = self.player.node
            if self.m.first_detect_time is None:
                self.m.first_detect_time = self.t

        self.attackers = sum(1 for g in self.guards if g.active and self._in_attack_range(g))
        if self.step_index > 0:
            nodes = (self.player.node, *(g.node for g in self.guards if g.active))
            if nodes != self._dist_key:  # nodes change a few times a second, steps 20 times
                self._dist_key = nodes
                self._dist_now = (
                    float(self.graph.dist[list(nodes[1:]), nodes[0]].min()) if nodes[1:] else None
                )
            if self._dist_now is not None:
                self.m.dist_sum += self._dist_now
                self.m.dist_samples += 1

    def _in_attack_range(self, guard: Agent) -> bool:
        gx, gy = guard.pos
        px, py = self.player.pos
        if math.hypot(gx - px, gy - py) > self.attack_range + RANGE_EPS:
            return False
        return not self.attack_los or self._clear_line((gx, gy), (px, py))

    def _captured(self) -> None:
        self.m.captures += 1
        if self.m.capture_time is None:
            self.m.capture_time = self.t
        self.events.append(Event("capture", self.player.node, self.t))
        if self.end_on_capture:
            self.done = True
            return
        # Fixed-time scenario: respawn at a fresh start position with full HP.
        self.damage_steps = 0
        node = self.start_node()
        self.player.place(tuple(float(v) for v in self.graph.positions[node]))
        self.player.node = node
        self.player.waypoints.clear()
        self.events.append(Event("respawn", node, self.t))

    def _ai_tick(self) -> None:
        dt = self.steps_per_tick * self.dt
        if self._sprinted:
            self.events.append(Event("sprint", self.player.node, self.t))
            self._sprinted = False
        self.tick_events = self.events
        view = self.view()
        self.stimuli.tick(view, dt)  # before the guard AI's tick, so FSM reacts to new layers
        self.guard_ai.tick(view, dt)
        self._watched = self.stimuli.marked_nodes()
        self.events = []
        self.sighting = None
        if self.on_tick is not None:
            self.on_tick(self)

    # ------------------------------------------------------------------ player actions
    # SPEC §5 mechanics the player triggers. Each returns True when it happened, else a
    # :class:`Refused` message (false in a boolean test). An action raises an event; the
    # stimulus it makes enters the fields at the next AI tick, like everything in the fields.

    def emit(self, kind: str, node: int = -1, **data: Any) -> Event:
        """Raise a world event now (scripted scenarios, tests); stimuli see it at the next tick."""
        event = Event(kind, int(node), self.t, data)
        self.events.append(event)
        return event

    def _cell(self, x: float, y: float) -> tuple[int, int]:
        cs = self.level.cell_size
        return math.floor(y / cs), math.floor(x / cs)

    def _node_containing(self, x: float, y: float) -> int:
        """The node whose walkable cell or triangle contains (x, y); -1 in a wall or outside."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return -1
        graph = self.graph
        if graph.cell_node is not None:
            row, col = math.floor(y / graph.cell_size), math.floor(x / graph.cell_size)
            rows, cols = graph.cell_node.shape
            return int(graph.cell_node[row, col]) if 0 <= row < rows and 0 <= col < cols else -1
        if graph.mesh is not None:
            return int(graph.mesh.locate(x, y))
        return graph.node_at(x, y) if self.level.contains(x, y) else -1

    def landing_node(self, x: float, y: float) -> int:
        """Where a decoy thrown at (x, y) lands (SPEC §5: within the Manhattan throw radius).

        The node containing the point if it is walkable and its cell lies within
        ``throw_radius`` cells (Manhattan) of the player's cell; otherwise the point is
        clamped to the nearest node (straight line) whose position is within that radius.
        """
        radius = self.stimulus_params.throw_radius
        prow, pcol = self._cell(*self.player.pos)
        node = self._node_containing(float(x), float(y))
        if node >= 0:
            row, col = self._cell(float(x), float(y))
            if abs(row - prow) + abs(col - pcol) <= radius:
                return node
        cs = self.level.cell_size
        cells = np.floor(self.graph.positions / cs).astype(np.int64)
        near = np.abs(cells[:, 1] - prow) + np.abs(cells[:, 0] - pcol) <= radius
        options = np.flatnonzero(near)
        if not len(options):
            return self.player.node
        if not (math.isfinite(x) and math.isfinite(y)):
            x, y = self.player.pos
        d2 = np.sum((self.graph.positions[options] - (x, y)) ** 2, axis=1)
        return int(options[np.argmin(d2)])

    def perform(self, action: Action) -> bool | str:
        """Carry out a scripted player's :class:`~ai.view.Action` (what the keys do in play)."""
        if action.kind in ("sprint", "walk"):
            self.sprinting = action.kind == "sprint"
            return True
        if action.kind == "throw":
            if action.target is None:
                raise ValueError("a throw action needs a target (x, y)")
            return self.throw_decoy(*action.target)
        if action.kind in ("activate_decoy", "take_down", "toggle_rain"):
            return getattr(self, action.kind)()
        raise ValueError(f"unknown player action {action.kind!r} (choose from "
                         f"{', '.join(PLAYER_ACTIONS)})")

    def throw_decoy(self, x: float, y: float) -> bool | Refused:
        """Throw a decoy towards (x, y): a noise impulse where it lands; 10 s cooldown."""
        if self.done:
            return Refused("the trial is over")
        if self.t < self._next_throw - 1e-9:
            return Refused(f"cooldown, {self._next_throw - self.t:.1f} s left")
        node = self.landing_node(float(x), float(y))
        lx, ly = (float(v) for v in self.graph.positions[node])
        self._next_throw = self.t + self.stimulus_params.throw_cooldown
        self.emit("throw_landed", node, x=lx, y=ly, target=[float(x), float(y)])
        return True

    def _decoy_on(self, k: int) -> bool:
        pending = any(e.kind == "decoy_activated" and e.data.get("decoy") == k for e in self.events)
        return pending or any(getattr(s, "decoy", None) == k for s in self.stimuli.active)

    def activate_decoy(self) -> bool | Refused:
        """Switch on the nearest level decoy within ``decoy_reach`` (line of sight) of the player.

        It draws the guards until they have stood on it for ``decoy_disarm_time``; then it
        can be switched on again.
        """
        if self.done:
            return Refused("the trial is over")
        reach = self.stimulus_params.decoy_reach + RANGE_EPS
        px, py = self.player.pos
        options = sorted(
            (math.hypot(x - px, y - py), k) for k, (x, y) in enumerate(self.decoy_points)
            if math.hypot(x - px, y - py) <= reach and self._clear_line((px, py), (x, y))
        )
        if not options:
            return Refused("no decoy within reach")
        free = [k for _, k in options if not self._decoy_on(k)]
        if not free:
            return Refused("the decoy is already on")
        self.emit("decoy_activated", self.decoy_nodes[free[0]], decoy=free[0])
        return True

    def take_down(self) -> bool | Refused:
        """Take down the nearest guard within ``takedown_range`` whose view cone the player is
        outside of (from behind or the side), with no wall between; its body becomes a corpse."""
        if self.done:
            return Refused("the trial is over")
        reach = self.stimulus_params.takedown_range + RANGE_EPS
        px, py = self.player.pos
        best: tuple[float, int] | None = None
        for i, guard in enumerate(self.guards):
            if not guard.active:
                continue
            gx, gy = guard.pos
            dx, dy = px - gx, py - gy
            d = math.hypot(dx, dy)
            if d > reach:
                continue
            facing = dx * math.cos(guard.heading) + dy * math.sin(guard.heading)
            if d > 1e-9 and facing >= self.cos_half_fov * d:
                continue  # the player is inside this guard's view cone
            if not self._clear_line((gx, gy), (px, py)):
                continue
            if best is None or d < best[0]:
                best = (d, i)
        if best is None:
            return Refused("no guard within reach from behind")
        self.down_guard(best[1])
        return True

    def down_guard(self, i: int) -> None:
        """Take guard ``i`` out of play; its body stays where it is (raises ``"guard_down"``).

        The player's :meth:`take_down` checks range and cone first; scripts may call this
        directly.
        """
        guard = self.guards[i]
        if not guard.active:
            raise ValueError(f"guard {i} is already down")
        guard.active = False
        guard.waypoints.clear()
        guard.set_velocity((0.0, 0.0))
        self.emit("guard_down", guard.node, guard=int(i))

    @property
    def raining(self) -> bool:
        """Whether it rains (noises made while it rains are quieter, SPEC §5)."""
        return self._raining

    def _set_rain(self, on: bool, immediately: bool = False) -> None:
        self._raining = bool(on)
        event = Event("weather", -1, self.t, {"rain": bool(on)})
        if immediately:
            self.stimuli.handle(event)
        else:
            self.events.append(event)

    def toggle_rain(self) -> str:
        """Start or stop the rain; returns ``"on"`` or ``"off"``."""
        self._set_rain(not self._raining)
        return "on" if self._raining else "off"

    def stimulus_points(self) -> np.ndarray:
        """Positions ``(k, 2)`` of the active decoys, corpses and landed throws, for drawing."""
        nodes = [s.node for s in self.stimuli.markers()]
        return self.graph.positions[nodes].reshape(-1, 2)

    # ------------------------------------------------------------------ results
    def run(self) -> dict[str, Any]:
        """Step until the trial ends; return its metrics."""
        while not self.done:
            self.step()
        return self.metrics()

    def metrics(self) -> dict[str, Any]:
        """SPEC §9 metrics of the trial so far (times in seconds, None where nothing happened)."""
        m = self.m
        return {
            "captured": m.captures > 0,
            "capture_time": _round(m.capture_time),
            "captures": m.captures,
            "coverage": float(m.covered.mean()) if self.graph.n else 0.0,
            "avg_guard_player_dist": m.dist_sum / m.dist_samples if m.dist_samples else None,
            "first_detect_time": _round(m.first_detect_time),
            "backtracks": m.backtracks,
        }

    def trace_record(self) -> dict[str, Any]:
        """One trace line (SPEC §9): time, agents, who sees the player, HP, events."""
        return {
            "t": _round(self.t),
            "player": {
                "pos": [round(v, 4) for v in self.player.pos],
                "hp": round(self.hp, 4),
                "node": self.player.node,
            },
            "guards": [
                {
                    "pos": [round(v, 4) for v in g.pos],
                    "heading": round(g.heading, 4),
                    "sees_player": i in self.seen_by,
                    "node": g.node,
                    "target": g.target,
                    "state": self.guard_ai.state_name(i),
                    "active": g.active,
                }
                for i, g in enumerate(self.guards)
            ],
            "events": [
                {"kind": e.kind, "node": e.node, "t": _round(e.t), **dict(e.data)}
                for e in self.tick_events
            ],
            **({"stimuli": [s.describe() for s in self.stimuli.active]} if self.stimuli else {}),
        }


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def default_rngs(seed: int) -> tuple[np.random.Generator, ...]:
    """Three independent generators (spawns, guards, player) from one integer seed."""
    children = np.random.SeedSequence(seed).spawn(3)
    return tuple(np.random.Generator(np.random.PCG64(c)) for c in children)
