"""The simulated world: one trial in progress, advanced by :meth:`World.step` (decisions,
motion in :mod:`game.agents`, damage in :mod:`game.health`, senses in :mod:`game.senses`, the
AI tick); player actions in :mod:`game.actions`, metrics in :mod:`game.metrics`; traces are
written by :mod:`game.trace`, which reads the world (the world never imports it). Never imports pygame: the front end and the headless runner share it."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ai import GuardAI, PlayerPolicy, WorldView
from ai.stimuli import StimulusFactory, StimulusParams, StimulusSet, apply_zones
from ai.view import Event
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import Level

from .action_params import ActionParams
from .actions import PlayerActions, Refused
from .agents import Agent, Locomotion, bodies_space, build_space
from .config import Config
from .guard_sight import GuardSight, ViewCover
from .health import Health
from .metrics import Counters, world_metrics
from .scenarios import SCENARIOS
from .schema import check_level
from .senses import RANGE_EPS, Senses
from .spawns import guard_spawn_nodes, level_start_node, respawn_node, start_node
from .team import TeamRules
from .zones import ZoneMap

Generators = tuple[np.random.Generator, np.random.Generator, np.random.Generator]
__all__ = ["Agent", "RANGE_EPS", "Refused", "SCENARIOS", "World", "decision_interval",
           "default_rngs"]


class World(PlayerActions):
    """One trial of one level, abstraction, guard team, player policy, scenario and seed
    (``game.trial.make_world(TrialSpec(...))`` builds one; ``world.run()`` plays it out)."""

    def __init__(
        self, level: Level, abstraction: str, guard_ai: GuardAI,
        player_policy: PlayerPolicy | None, *, config: Config, scenario: str = "capture",
        seed: int = 0,
        rngs: Generators | None = None,
        interactive: bool = False, graph: NodeGraph | None = None,
        stimuli: Sequence[StimulusFactory] = (), walls_in_space: bool = True,
    ) -> None:
        if scenario not in SCENARIOS:
            raise ValueError(f"unknown scenario {scenario!r} (choose capture or fixed)")
        self.level, self.abstraction, self.scenario = level, abstraction, scenario
        check_level(config, level)  # a body too wide for the level's corridors: one line
        self.config = config
        self.graph: NodeGraph = graph if graph is not None else graph_for(
            level, abstraction, float(config["world.agent_radius"]))
        self.guard_ai, self.player_policy = guard_ai, player_policy
        spawn_rng, guard_rng, player_rng = rngs or default_rngs(seed)
        self.spawn_rng = spawn_rng

        w = config.section("world")
        s = config.section(f"scenario.{scenario}")
        self.dt = float(w["physics_step_interactive"] if interactive else w["physics_step"])
        self.steps_per_tick = max(1, round(float(w["ai_tick"]) / self.dt))
        # The paper's decision tick: > 0 gates decisions to every this many steps (an arrived
        # agent waits on its target until then, a walking one walks on); 0: on arrival.
        interval = decision_interval(w, grid=self.graph.mesh is None)
        self.steps_per_decision = max(1, round(interval / self.dt)) if interval > 0 else 1
        # the clock of policies that re-plan once per tick (SafetyGraph "paper"): the decision
        # tick when decisions are gated, else the AI tick (WorldView.decision_tick)
        self.steps_per_plan = self.steps_per_decision if interval > 0 else self.steps_per_tick
        self.respawn = str(w["respawn"])
        self.total_steps = round(float(w["duration"]) / self.dt)
        self.end_on_capture = bool(s["end_on_capture"])
        self.view_range = float(w["view_range"]) * float(s["view_range_scale"])
        self.attack_range = float(w["attack_range"])
        self.attack_los = bool(w["attack_needs_line_of_sight"])
        # The game's rule (stealth play): a guard hurts only a player it detects now or did
        # within attack_memory s; None: the paper's (l. 206), every guard in range hurts.
        self.attack_memory: float | None = (float(w["attack_memory"])
                                            if w["attack_needs_awareness"] else None)
        self.radius = float(w["agent_radius"])
        self.hp_max = float(w["player_hp"])
        self.stuck_timeout = float(w["stuck_timeout"])
        self.sprint_factor = float(w["sprint_factor"])
        self.sneak_factor = float(w["sneak_factor"])
        # Zones (SPEC §5) say what they do to confidence decay and view range (game.zones).
        zone_map = ZoneMap.build(level, self.graph, config)
        self.zone_rules, self.zones, self.view_scale_at = (
            zone_map.rules, zone_map.masks, zone_map.view_scale)
        concealment = self.zone_rules.get("concealment")
        self.concealment_view_scale = concealment.view_scale if concealment else 1.0
        self.action_params, stimulus_section = ActionParams.split(config.section("stimuli"))
        self.stimulus_params = StimulusParams.from_mapping(stimulus_section)
        self.health = Health(self.hp_max, self.dt)

        self._watched: frozenset[int] = frozenset()
        # walls_in_space=False (the batch engine, which steps a space only when a body
        # touches a wall): the space holds the bodies alone until add_walls, and lines of
        # sight use the compiled port of pymunk's query over the level's walls
        self.space = build_space(level) if walls_in_space else bodies_space()
        self.senses = Senses(self.space, float(w["fov_deg"]), level.walls,
                             compiled_lines=not walls_in_space)
        self.locomotion = Locomotion(self.space, self.graph, level, self.radius, self.dt)
        self.step_index = 0
        self.done = False
        self.events: list[Event] = []
        self.tick_events: list[Event] = []
        self.sighting: int | None = None
        self.seen_by: tuple[int, ...] = ()
        self.sprinting = False
        #: the slow walk (stealth play): speed x sneak_factor, the "sneak" gait
        self.sneaking = False
        self._sprinted = False
        self.player_moved = False
        self.player_input: tuple[float, float] | None = None
        self.on_tick: Callable[[World], None] | None = None
        self.m: Counters = Counters.for_nodes(self.graph.n)
        # metrics.coverage = "seen": a node is seen as a player standing on it would be
        self.m.view_cover = ViewCover(self.graph, self.senses,
                                      self.view_range * self.view_scale_at, level.walls)

        guard_speed = self.guard_speed = float(w["guard_speed"])
        player_speed = float(w["player_speed"]) * float(s["player_speed_scale"])
        spawn_nodes = guard_spawn_nodes(self.graph, level, spawn_rng, int(w["guards"]),
                                        str(w["spawns"]))
        self.guards = [self.locomotion.make_agent(node, guard_speed) for node in spawn_nodes]
        for guard in self.guards:
            guard.heading = float(spawn_rng.uniform(-math.pi, math.pi))
        placed = str(w["spawns"]) == "level" and bool(level.guards)
        if placed:  # a Tiled guard's facing (the draw above is kept: the same stream)
            for guard, facing in zip(self.guards, level.facing):
                if facing is not None:
                    guard.heading = facing
        first = level_start_node(self.graph, level, str(w["spawns"]))
        self.player = self.locomotion.make_agent(
            self.start_node() if first is None else first, player_speed)
        self.player_speed = player_speed

        self.guard_ai.reset(self.graph, guard_rng, len(self.guards))
        if placed and level.patrols:
            self.guard_ai.set_patrol_routes(
                [[self.graph.node_at(x, y) for x, y in route] for route in level.patrols])
        if self.player_policy is not None:
            self.player_policy.reset(self.graph, player_rng)
        for i, guard in enumerate(self.guards):
            self.enter_node(guard, guard.node, i)
            guard.history.append(guard.node)

        # Stimuli (ai.stimuli): world events become field layers for the guard AI's hooks.
        apply_zones(self.guard_ai, self.zone_rules, self.zones)
        self.stimuli = StimulusSet(self.graph, self.stimulus_params, guard_ai=self.guard_ai,
                                   rng=spawn_rng.spawn(1)[0], zones=self.zones,
                                   config=config.as_dict())
        self.init_actions(level, raining=self.stimulus_params.raining)
        for factory in stimuli:
            self.stimuli.add(factory())
        # Beyond the paper (game.team): graded perception, alert phases, radio, roles.
        self.team = TeamRules.build(config, len(self.guards), self.stimuli)
        # What each guard sees, for a mode that patrols by sight (staleness.model = "view")
        self.guard_sight = (GuardSight(self.graph, self.senses, self.view_range * self.view_scale_at,
                                       level.walls) if self.guard_ai.wants_guard_sight() else None)
        self.stimuli.refresh()
        self._watched = self.stimuli.marked_nodes()

        self.attackers = 0
        self._last_seen = [-math.inf] * len(self.guards)  # when each guard last detected
        self._sense()

    def start_node(self) -> int:
        """SPEC §7: the node farthest from every guard, out of their sight (game.spawns)."""
        return start_node(self.graph, self.guards, self.senses, self.view_range, self.spawn_rng)

    def place_player(self, node: int, *, forget_detection: bool = False) -> None:
        """Teleport the player onto ``node`` (a respawn; scripted set-ups such as
        ``stealth mechanics``); ``forget_detection`` clears the first-detection time."""
        self.player.place(self.locomotion.stand_point(node))
        self.player.node = node
        self.player.waypoints.clear()
        if forget_detection:
            self.m.first_detect_time = None

    def sees(self, guard: Agent, target: tuple[float, float], reach: float | None = None) -> bool:
        """Vision: within range (scaled by the player's zone), inside the cone, clear line.
        ``reach``: that range when the caller has it already (:meth:`view_reach`)."""
        if reach is None:
            reach = self.view_reach()
        return guard.active and self.senses.perceives(guard.pos, guard.heading, target, reach)

    def view_reach(self) -> float:
        """The guards' view range now: the scenario's, scaled by the player's zone."""
        return self.view_range * float(self.view_scale_at[self.player.node])

    @property
    def hp(self) -> float:
        """The player's HP now."""
        return self.health.hp

    @property
    def t(self) -> float:
        """Seconds since the start of the trial."""
        return self.step_index * self.dt

    def view(self) -> WorldView:
        """The snapshot the controllers read."""
        guards = self.guards
        return self.view_of(
            np.array([g.node for g in guards], dtype=np.int64),
            np.array([g.pos for g in guards], dtype=np.float64),
            np.array([g.heading for g in guards], dtype=np.float64),
            np.array([g.active for g in guards], dtype=bool),
            self.player.node, np.array(self.player.pos))

    def view_of(self, guard_nodes: np.ndarray, guard_positions: np.ndarray,
                guard_headings: np.ndarray, guard_active: np.ndarray, player_node: int,
                player_pos: np.ndarray) -> WorldView:
        """:meth:`view` with the agents' state given (the batch engine has it in arrays):
        the rest of the snapshot is the world's."""
        return WorldView(
            t=self.t, graph=self.graph, guard_nodes=guard_nodes, guard_positions=guard_positions,
            guard_headings=guard_headings, player_node=player_node, player_pos=player_pos,
            seen_by=self.seen_by, sighting=self.sighting, events=tuple(self.tick_events),
            zones=self.zones, guard_active=guard_active,
            decision_tick=self.step_index // self.steps_per_plan,
        )

    def step(self) -> None:
        """Advance the world by one physics step (decisions, motion, senses, AI tick).

        The phases are methods of their own so the batch engine (:mod:`game.batch`), which
        moves and senses many trials at once over arrays, calls the same rules for the
        events (decisions, arrivals, damage, sightings, ticks) of each of its trials.
        """
        if self.done:
            return
        if self.step_index % self.steps_per_decision == 0:  # always, unless gated
            self.decide()
        player_speed = self.drive()
        agents = [*self.guards, self.player]
        before = [a.pos for a in agents]
        sprint = self.sprinting
        self.space.step(self.dt)
        self.step_index += 1
        before[-1] = self.hurt(before[-1])
        for i, (agent, speed) in enumerate(zip(agents, self.speeds(player_speed), strict=True)):
            agent.sync()
            self.settle_agent(i, agent, before[i], speed)
        self.moved(before[-1], sprint)
        self._sense()
        self.end_step()

    def decide(self, view: WorldView | None = None) -> None:
        """A decision tick: every active guard and the player without a plan decide
        (reading ``view``, or the world's :meth:`view` made when first needed)."""
        walk = self.locomotion
        for i, guard in enumerate(self.guards):
            if guard.active and guard.needs_decision:
                view = view or self.view()
                walk.plan(guard, int(self.guard_ai.decide(i, view)))
        if (self.player_input is None and self.player_policy is not None
                and self.player.needs_decision):
            view = view or self.view()
            walk.plan(self.player, int(self.player_policy.decide(view)))
            for action in self.player_policy.actions(view):
                self.perform(action)

    def drive(self) -> float:
        """Set every body's velocity for the coming step; returns the player's speed."""
        walk = self.locomotion
        for guard in self.guards:
            walk.drive(guard, guard.speed)
        player_speed = self.player_step_speed()
        if self.player_input is not None:
            vx, vy = self.player_input
            self.player.set_velocity((vx * player_speed, vy * player_speed))
            if vx or vy:
                self.player.heading = math.atan2(vy, vx)
        else:
            walk.drive(self.player, player_speed)
        return player_speed

    def player_step_speed(self) -> float:
        """The player's speed this step (sprinting, walking slowly or neither)."""
        if self.sprinting:
            return self.player_speed * self.sprint_factor
        return self.player_speed * (self.sneak_factor if self.sneaking else 1.0)

    def speeds(self, player_speed: float) -> list[float]:
        """The speed each agent walks at this step: the guards', then the player's."""
        return [g.speed for g in self.guards] + [player_speed]

    def hurt(self, before: tuple[float, float]) -> tuple[float, float]:
        """Damage from the guards in range at the start of the step; returns where the
        player's step counts from (``before``, or the respawn point: a teleport, not a walk,
        so no footsteps and no stall)."""
        if self.attackers:
            # Guards in range at the start of the step hurt over the whole step, so a
            # player in range from t0 on dies at exactly t0 + HP (per guard).
            self.m.attacks[self.player.node] += self.attackers * self.dt
            if self.health.hurt(self.attackers):
                self._captured()
                if not self.done:
                    return self.player.pos
        return before

    def moved(self, before: tuple[float, float], sprint: bool) -> None:
        """Whether the player moved this step (footsteps while sprinting)."""
        self.player_moved = self.player.pos != before
        if sprint and self.player_moved:
            self._sprinted = True  # footsteps: the player moved while sprinting this tick

    def end_step(self) -> None:
        """The AI tick when one is due; the end of the trial when its time is up."""
        if self.step_index % self.steps_per_tick == 0:
            self._ai_tick()
        if self.step_index >= self.total_steps:
            self.done = True

    def stop(self) -> None:
        """End the trial now (a script that has seen what it waited for)."""
        self.done = True

    def settle_agent(self, index: int, agent: Agent, before: tuple[float, float],
                     speed: float) -> None:
        """After a physics step, agent number ``index`` (the guards, then the player; its
        position read): stop it if it arrived and enter the node it stands on (the player's
        arrivals are not scored).

        An agent that has reached its target stands on it, and keeps its node until it moves.
        That is not always the node under its centre: on the partition a body stops on the
        target's stand point, which lies in a neighbouring triangle when the target's centroid
        is within a body radius of a wall (the slivers by a thin wall's end). Read from the
        centre, the controller never saw it arrive and sent it there again, for ever (issue 24).
        """
        if self.locomotion.settle(agent, before, speed, self.stuck_timeout):
            self.arrived(index, agent)
            return
        if agent.pos == before:
            return
        node = self.graph.node_near(agent.pos[0], agent.pos[1], agent.node)
        if node != agent.node:
            self.enter_node(agent, node, index)

    def arrived(self, index: int, agent: Agent) -> None:
        """Agent number ``index`` has just reached its target (its last waypoint): a guard's
        arrival is scored, and the agent stands on the target from now on."""
        if agent is not self.player:
            self.m.count_arrival(agent.history, agent.target)
        if agent.target != agent.node:
            self.enter_node(agent, agent.target, index)

    def enter_node(self, agent: Agent, node: int, index: int) -> None:
        """``agent`` (guard number ``index``, or the player) now stands on ``node``."""
        agent.node = node
        if agent is not self.player:
            self.m.count_visit(node, index)
            if node in self._watched and agent.active:
                self.events.append(Event("guard_on", node, self.t, {"guard": index}))

    def _sense(self) -> None:
        """Vision, attack damage, distance and detection metrics for the current positions."""
        ppos = self.player.pos
        reach = self.view_reach()  # once per step, not once per guard
        seeing, in_range, nodes, positions = _guard_senses(
            self.guards, self.senses, ppos, reach, self.attack_range, self.attack_los)
        self.detect(seeing)
        self.attackers = len(in_range) if self.attack_memory is None else self._aware(in_range)
        if self.step_index > 0:
            self.m.sample_distance(self.graph, self.player.node, nodes)
            self.m.sample_euclidean(ppos, positions)

    def detect(self, seeing: Sequence[int]) -> None:
        """The guards ``seeing`` the player now become the team's detections (``seen_by``,
        the sighting, the first detection time)."""
        self.seen_by = self.team.detect(self, tuple(seeing))
        if self.seen_by:
            self.sighting = self.player.node
            if self.m.first_detect_time is None:
                self.m.first_detect_time = self.t

    def _aware(self, in_range: Sequence[int]) -> int:
        """How many of the guards ``in_range`` detect the player now or did within
        ``world.attack_memory`` s (``world.attack_needs_awareness``)."""
        for i in self.seen_by:
            self._last_seen[i] = self.t
        memory = self.attack_memory or 0.0
        return sum(1 for i in in_range if self.t - self._last_seen[i] <= memory)

    def _captured(self) -> None:
        self.m.count_capture(self.t)
        self.events.append(Event("capture", self.player.node, self.t))
        if self.end_on_capture:
            self.done = True
            return
        # Fixed-time: full HP again, at a fresh start (world.respawn) or, with "stay", where the
        # player stands; guards still in range deplete the full HP again from the next step.
        self.health.heal()
        node = respawn_node(self.respawn, self.graph, self.guards, self.senses,
                            self.view_range, self.spawn_rng, here=self.player.node)
        if self.respawn != "stay":
            self.place_player(node)
        self.events.append(Event("respawn", node, self.t))

    def _ai_tick(self) -> None:
        dt = self.steps_per_tick * self.dt
        if self._sprinted:
            self.events.append(Event("sprint", self.player.node, self.t))
            self._sprinted = False
        self.team.before_tick(self)
        self.tick_events = self.events
        view = self.view()
        self.m.observe_view(self.guards)
        self.stimuli.tick(view, dt)  # before the guard AI's tick, so FSM reacts to new layers
        self.team.after_stimuli(self)
        if self.guard_sight is not None:
            view.guard_sight = self.guard_sight.seen(self.guards)
        self.guard_ai.tick(view, dt)
        self._watched = self.stimuli.marked_nodes()
        self.events = []
        self.sighting = None
        if self.on_tick is not None:
            self.on_tick(self)

    def emit(self, kind: str, node: int = -1, **data: Any) -> Event:
        """Raise a world event now (scripted scenarios, tests); stimuli see it at the next tick."""
        event = Event(kind, int(node), self.t, data)
        self.events.append(event)
        return event

    def run(self) -> dict[str, Any]:
        """Step until the trial ends; return its metrics."""
        while not self.done:
            self.step()
        return self.metrics()

    def metrics(self) -> dict[str, Any]:
        """Every registered metric (:mod:`game.metrics`) of the trial so far (SPEC §9)."""
        return world_metrics(self)


def _guard_senses(guards: list[Agent], senses: Senses, ppos: tuple[float, float], reach: float,
                  attack_range: float, attack_los: bool
                  ) -> tuple[list[int], list[int], list[int], list[tuple[float, float]]]:
    """One pass over the active guards: which see the player (:meth:`World.sees`), which
    are in attack range, and their nodes and positions (the distance metrics' samples)."""
    perceives = senses.perceives
    seeing: list[int] = []
    attackers: list[int] = []
    nodes: list[int] = []
    positions: list[tuple[float, float]] = []
    for i, g in enumerate(guards):
        if not g.active:
            continue
        if perceives(g.pos, g.heading, ppos, reach):
            seeing.append(i)
        if perceives(g.pos, None, ppos, attack_range, line_of_sight=attack_los):
            attackers.append(i)
        nodes.append(g.node)
        positions.append(g.pos)
    return seeing, attackers, nodes, positions


def decision_interval(world: Mapping[str, Any], *, grid: bool) -> float:
    """Seconds between decision ticks under the ``[world]`` section ``world``, 0 = decide on
    arrival: ``decision_interval`` when > 0 (both abstractions), else on the grid
    ``grid_decision_interval`` (the older, grid-only key), else 0."""
    interval = float(world["decision_interval"])
    if interval > 0:
        return interval
    return float(world["grid_decision_interval"]) if grid else 0.0


def default_rngs(seed: int) -> Generators:
    """Three independent generators (spawns, guards, player) from one integer seed."""
    children = np.random.SeedSequence(seed).spawn(3)
    spawn, guards, player = (np.random.Generator(np.random.PCG64(c)) for c in children)
    return spawn, guards, player
