"""The batch engine (SPEC §12, ``world.engine = "batch"``): trials of one level and
abstraction advanced in lockstep, their bodies and senses in arrays.

Each trial of a batch is a :class:`~game.world.World` built by :func:`game.trial.make_world`
(so spawns, controllers, stimuli and counters are the reference's own), but it is never
stepped by pymunk. Per physics step the compiled kernels (:mod:`game.batch.kernels`) drive,
move, settle and sense every body of every live trial at once; whatever they flag — a
decision, a new waypoint, an arrival, a node entered, damage, a sighting, the AI tick — is
handed to that trial's world, whose phase methods (:meth:`World.decide`,
:meth:`World.settle_agent`, :meth:`World.hurt`, :meth:`World.detect`, :meth:`World.end_step`)
are the rules the reference runs. Before a world's rule runs, the arrays are written into
its agents (:meth:`Batch.pull`); after, read back (:meth:`Batch.push`). A trial's result
does not depend on its batch: no value crosses trials, and each keeps its own generators.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from ai.view import PlayerPolicy
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import cached_level

from ..agents import Agent, add_walls
from ..config import Config
from ..team import SECTIONS
from ..trial import TrialSpec, make_world, trial_row
from ..world import World
from . import kernels
from ..exact import WallGrid

#: trials advanced together at most (memory grows linearly with it)
MAX_BATCH = 256
#: the largest graph the batch engine takes (its per-level tables are built per batch)
MAX_NODES = 200_000
#: a seeing mask holds one bit per guard
MAX_GUARDS = 62


def refusal_text(what: str) -> str:
    """The one line refusing a trial the batch engine does not cover (``what`` names it)."""
    return f'world.engine = "batch" does not cover {what}; use world.engine = "pymunk"'


def uncovered(spec: TrialSpec, config: Config) -> str | None:
    """None when the batch engine runs ``spec`` as the reference does, else what of it the
    engine does not cover (a phrase for :func:`refusal_text`)."""
    if spec.stimuli:
        return "plugin stimuli (" + ", ".join(spec.stimuli) + ")"
    for section in SECTIONS:
        if config[f"{section}.enabled"]:
            return f"the team switch [{section}] enabled"
    if config["stimuli.raining"]:
        return "rain (stimuli.raining)"
    if config["world.attack_needs_awareness"]:  # stealth play's rule: its kernel counts range
        return "guards that hurt only a player they noticed (world.attack_needs_awareness)"
    if int(config["world.guards"]) > MAX_GUARDS:
        return f"more than {MAX_GUARDS} guards"
    nodes = graph_for(cached_level(spec.level), spec.abstraction,
                      float(config["world.agent_radius"])).n  # cached: the trials build it too
    if nodes > MAX_NODES:
        return f"graphs of more than {MAX_NODES} nodes ({spec.level}: {nodes})"
    return None


def run_trials(specs: Sequence[TrialSpec]) -> list[dict[str, Any]]:
    """Run ``specs`` (one level, abstraction and config; at most :data:`MAX_BATCH`) in
    lockstep; their rows, in order, as :func:`game.trial.run_trial` makes them."""
    rows: list[dict[str, Any]] = []
    for start in range(0, len(specs), MAX_BATCH):
        rows.extend(Batch(specs[start:start + MAX_BATCH]).run())
    return rows


class Batch:
    """Trials sharing level, abstraction and config, stepped together."""

    def __init__(self, specs: Sequence[TrialSpec], worlds: Sequence[World] | None = None) -> None:
        """The trials ``specs``, their worlds built here, or ``worlds`` built by the caller
        (a vector env's: made with ``walls_in_space=False``, one level, graph and config)."""
        if not specs:
            raise ValueError("a batch needs at least one trial")
        self.started = time.perf_counter()
        self.specs = list(specs)
        first = specs[0]
        level = cached_level(first.level)
        if worlds is None:
            shared = (first.level, first.abstraction, first.settings, first.stimuli)
            for spec in specs:
                if (spec.level, spec.abstraction, spec.settings, spec.stimuli) != shared:
                    raise ValueError("a batch's trials share level, abstraction, settings and "
                                     f"stimuli: {spec.key} differs from {first.key}")
            config = Config.load({**first.settings, "world.engine": "batch"})  # rows say so
            problem = uncovered(first, config)
            if problem is not None:
                raise ValueError(refusal_text(problem))
            # one config for all: the trials share their settings (Config is read-only);
            # their spaces hold the bodies alone: the walls are added when a trial first
            # takes a step in pymunk's hands (most never do; the walls cost a third of a world)
            worlds = [make_world(spec, config, level=level, walls_in_space=False)
                      for spec in specs]
        elif len(worlds) != len(specs) or not all(w.senses.compiled_lines for w in worlds):
            raise ValueError("a batch takes one world per trial, built with walls_in_space=False")
        self.worlds = list(worlds)
        self.level = level
        self.space_walls = np.zeros(len(specs), dtype=np.bool_)
        w0 = self.worlds[0]
        self.graph: NodeGraph = w0.graph
        self.dt, self.radius = w0.dt, w0.radius
        self.steps_per_tick, self.steps_per_decision = w0.steps_per_tick, w0.steps_per_decision
        self.total_steps, self.stuck_timeout = w0.total_steps, w0.stuck_timeout
        self.attack_range, self.attack_los = w0.attack_range, w0.attack_los
        self.cos_half_fov = w0.senses.cos_half_fov
        self.view_scale_at = np.ascontiguousarray(w0.view_scale_at, dtype=np.float64)
        self.walls = WallGrid.build(level.walls)
        if self.graph.cell_node is not None:
            self.cell_node = np.ascontiguousarray(self.graph.cell_node, dtype=np.int64)
            self.tri_eqs, self.tri_tol = np.zeros((0, 9)), 0.0
            self.locate_geom = np.zeros(6)
            self.locate_start = np.zeros(1, dtype=np.int64)
            self.locate_items = np.zeros(0, dtype=np.int64)
        else:
            mesh = self.graph.mesh
            assert mesh is not None
            self.cell_node = kernels.empty_cells()
            self.tri_eqs = np.ascontiguousarray(np.asarray(mesh._edge_py, dtype=np.float64))
            self.tri_tol = float(mesh.tol)
            self.locate_geom = np.array(mesh._grid, dtype=np.float64)
            self.locate_start = np.ascontiguousarray(mesh._cell_start, dtype=np.int64)
            self.locate_items = np.ascontiguousarray(mesh._cell_items, dtype=np.int64)
        self._arrays()

    # ------------------------------------------------------------------ state
    def _arrays(self) -> None:
        n_trials = len(self.worlds)
        n_agents = len(self.worlds[0].guards) + 1
        shape = (n_trials, n_agents)
        self.pos = np.zeros(shape + (2,))
        self.vel = np.zeros(shape + (2,))
        self.cmd = np.zeros(shape + (2,))
        self.wp = np.zeros(shape + (2,))
        self.has_wp = np.zeros(shape, dtype=np.bool_)
        self.n_wp = np.zeros(shape, dtype=np.int64)  # waypoints left (the deque's length)
        self.kind = np.zeros(shape, dtype=np.int8)  # what kernels.settle made of the step
        self.new_node = np.zeros(shape, dtype=np.int64)
        self.cruise_ok = np.zeros(shape, dtype=np.bool_)
        self.cruise_speed = np.zeros(shape)
        self.cruise_rem = np.zeros(shape)
        self.on_track = np.zeros(shape, dtype=np.bool_)
        self.since = np.zeros(shape)
        self.node = np.zeros(shape, dtype=np.int64)
        self.active = np.zeros(shape, dtype=np.bool_)
        self.speed = np.zeros(shape)
        self.heading = np.zeros(shape)
        self.live = np.zeros(n_trials, dtype=np.bool_)
        self.view_range = np.zeros(n_trials)
        self.key = np.full(shape, -2, dtype=np.int64)  # the nodes of the last distance sample
        self.dist_now = np.zeros(n_trials)
        self.has_dist = np.zeros(n_trials, dtype=np.bool_)
        self.dist_sum = np.zeros(n_trials)
        self.dist_n = np.zeros(n_trials, dtype=np.int64)
        self.euc_sum = np.zeros(n_trials)
        self.euc_n = np.zeros(n_trials, dtype=np.int64)
        self.seeing = np.zeros(n_trials, dtype=np.int64)
        self.seen = np.zeros(n_trials, dtype=np.int64)
        self.attackers = np.zeros(n_trials, dtype=np.int64)
        self.key_changed = np.zeros(n_trials, dtype=np.bool_)
        self.touch = np.zeros(n_trials, dtype=np.bool_)
        self.held = np.zeros(n_trials, dtype=np.int64)  # steps left in pymunk's hands
        self.ended = np.zeros(n_trials, dtype=np.bool_)  # done: not stepped after this step
        self.sprinting = np.zeros(n_trials, dtype=np.bool_)
        self.has_policy = np.zeros(n_trials, dtype=np.bool_)
        # a player policy with actions of its own (take-downs, throws) may change any agent
        self.acting = np.zeros(n_trials, dtype=np.bool_)
        #: each trial's own clock: physics steps it has taken (World.step_index)
        self.clock = np.zeros(n_trials, dtype=np.int64)
        for b in range(n_trials):
            self._start(b)

    def _start(self, b: int) -> None:
        """Trial ``b``'s entries, from its world as built (a new trial)."""
        world = self.worlds[b]
        if len(world.guards) + 1 != self.pos.shape[1]:
            raise ValueError("a batch's trials have one number of guards")
        self.live[b] = not world.done
        self.ended[b] = world.done
        self.view_range[b] = world.view_range
        self.key[b] = -2
        self.dist_now[b] = self.dist_sum[b] = self.euc_sum[b] = 0.0
        self.dist_n[b] = self.euc_n[b] = self.held[b] = 0
        self.has_dist[b] = self.key_changed[b] = self.touch[b] = self.space_walls[b] = False
        self.seeing[b] = 0
        self.attackers[b] = world.attackers
        policy = world.player_policy
        self.has_policy[b] = policy is not None
        self.acting[b] = policy is not None and type(policy).actions is not PlayerPolicy.actions
        self.clock[b] = world.step_index
        self.cmd[b] = np.nan  # every velocity differs: push reads them all
        self.push(b)

    def replace(self, b: int, spec: TrialSpec, world: World) -> None:
        """Trial ``b`` becomes ``spec``'s new ``world`` (a vector env's reset of one env)."""
        if not world.senses.compiled_lines:
            raise ValueError("a batch takes worlds built with walls_in_space=False")
        self.specs[b], self.worlds[b] = spec, world
        self._start(b)

    def agents(self, b: int) -> list[Agent]:
        """Trial ``b``'s agents in array order: the guards, then the player."""
        world = self.worlds[b]
        return [*world.guards, world.player]

    def pull(self, b: int, only: int | None = None) -> None:
        """Write the arrays into trial ``b``'s world (one agent: ``only``)."""
        world = self.worlds[b]
        world.step_index = int(self.clock[b])
        world.attackers = int(self.attackers[b])
        agents = self.agents(b)
        pos, on_track, since = self.pos[b].tolist(), self.on_track[b], self.since[b]
        for a in (range(len(agents)) if only is None else (only,)):
            agent = agents[a]
            agent.pos = (pos[a][0], pos[a][1])
            agent.on_track = bool(on_track[a])
            agent.since_target = float(since[a])
            agent.cruise = ((agent.waypoints[0], float(self.cruise_speed[b, a]),
                             float(self.cruise_rem[b, a])) if self.cruise_ok[b, a] else None)
            if agent.velocity != (self.cmd[b, a, 0], self.cmd[b, a, 1]):
                agent.velocity = (float(self.cmd[b, a, 0]), float(self.cmd[b, a, 1]))
            agent.heading = float(self.heading[b, a])

    def pull_view(self, b: int) -> None:
        """Write what a :class:`~ai.view.WorldView` and a plan read (clock, positions,
        headings) into trial ``b``'s world; nothing it would write back."""
        world = self.worlds[b]
        world.step_index = int(self.clock[b])
        world.attackers = int(self.attackers[b])
        heading = self.heading[b].tolist()
        for agent, (x, y), h in zip(self.agents(b), self.pos[b].tolist(), heading):
            agent.pos = (x, y)
            agent.heading = h

    def _decide(self, b: int, askers: list[int]) -> None:
        """:meth:`World.decide` in trial ``b``, whose agents ``askers`` have no plan: only
        they change (a policy's actions may change any agent: then all are read back)."""
        world = self.worlds[b]
        if self.acting[b]:
            self.pull(b)
            world.decide()
            self.push(b)
            return
        for a in askers:  # a plan starts where the agent stands
            self.pull(b, a)
        p = self.pos.shape[1] - 1
        world.decide(world.view_of(self.node[b, :p].copy(), self.pos[b, :p].copy(),
                                   self.heading[b, :p].copy(), self.active[b, :p].copy(),
                                   int(self.node[b, p]), self.pos[b, p].copy()))
        agents = self.agents(b)
        for a in askers:  # a plan sets the target, the waypoints and the clock alone
            self._push_walk(b, a, agents[a])

    def push(self, b: int, only: int | None = None) -> None:
        """Read trial ``b``'s world back into the arrays (one agent: ``only``)."""
        world = self.worlds[b]
        agents = self.agents(b)
        last = len(agents) - 1
        for a in (range(len(agents)) if only is None else (only,)):
            agent = agents[a]
            self.pos[b, a, 0], self.pos[b, a, 1] = agent.pos
            if agent.velocity != (self.cmd[b, a, 0], self.cmd[b, a, 1]):  # set_velocity wrote
                self.cmd[b, a, 0], self.cmd[b, a, 1] = agent.velocity
                self.vel[b, a, 0], self.vel[b, a, 1] = agent.velocity
            self._push_walk(b, a, agent)
            self.on_track[b, a] = agent.on_track
            self.node[b, a] = agent.node
            self.active[b, a] = agent.active
            self.heading[b, a] = agent.heading
            self.speed[b, a] = world.player_step_speed() if a == last else agent.speed
        self.seen[b] = _bits(world.seen_by)
        self.sprinting[b] = world.sprinting

    def _push_walk(self, b: int, a: int, agent: Agent) -> None:
        """Read agent ``a``'s walk back: waypoints, cruise and the time since its target."""
        waypoints = agent.waypoints
        self.has_wp[b, a] = bool(waypoints)
        self.n_wp[b, a] = len(waypoints)
        if waypoints:
            self.wp[b, a, 0], self.wp[b, a, 1] = waypoints[0]
        cruise = agent.cruise
        ok = cruise is not None and bool(waypoints) and cruise[0] is waypoints[0]
        self.cruise_ok[b, a] = ok
        if ok:
            assert cruise is not None
            self.cruise_speed[b, a], self.cruise_rem[b, a] = cruise[1], cruise[2]
        self.since[b, a] = agent.since_target

    # ------------------------------------------------------------------ one step
    def step(self, advance: np.ndarray | None = None) -> None:
        """One physics step of every live trial (of those ``advance`` marks, when given: a
        vector env holds a trial whose move has ended while the others finish theirs):
        :meth:`World.step`'s phases in its order, each trial on its own clock."""
        live = self.live.copy() if advance is None else self.live & advance
        dt, clock = self.dt, self.clock
        due = live & (clock % self.steps_per_decision == 0)  # World.decide's askers
        if due.any():
            idle = ~self.has_wp
            idle[:, :-1] &= self.active[:, :-1]
            idle[:, -1] &= self.has_policy
            for b in np.flatnonzero(due & idle.any(axis=1)).tolist():
                self._decide(b, np.flatnonzero(idle[b]).tolist())
        kernels.drive(live, self.active, self.has_wp, self.wp, self.pos, self.cruise_ok,
                      self.cruise_speed, self.cruise_rem, self.on_track, self.speed, self.cmd,
                      self.vel, self.heading, dt)
        before = self.pos.copy()
        speeds = self.speed.copy()
        kernels.move(live, self.pos, self.vel, dt)
        w = self.walls
        kernels.touching(live, self.pos, self.radius, w.segs, w.cell_start, w.cell_items,
                         w.geom, self.touch)
        # pymunk's solver answers a contact with a velocity and a bias it applies over the
        # next steps (cpBody's v_bias, its arbiters kept 3 steps): such a trial takes this
        # step and the next three in its own space
        self.held[self.touch] = 4  # (touch is False for a trial not stepped)
        held = live & (self.held > 0)
        if held.any():
            self._pymunk_step(np.flatnonzero(held), before)
            self.held[held] -= 1
        clock[live] += 1
        for b in np.flatnonzero(live & (self.attackers > 0)).tolist():
            self._hurt(b, before)
        kernels.settle(live, self.pos, before, self.has_wp, self.n_wp, self.wp, self.cruise_ok,
                       speeds, dt, self.since, self.on_track, self.node, self.stuck_timeout,
                       self.radius, self.cell_node, self.graph.cell_size, self.tri_eqs,
                       self.tri_tol, self.locate_geom, self.locate_start, self.locate_items,
                       self.kind, self.new_node)
        events = live[:, None] & (self.kind != kernels.QUIET)
        for b, a, kind in zip(*np.nonzero(events), self.kind[events].tolist()):
            self._settle(int(b), int(a), kind, before, speeds)
        for b in np.flatnonzero(live & self.sprinting).tolist():  # footsteps: the world's rule
            self.pull(b)
            self.worlds[b].moved((float(before[b, -1, 0]), float(before[b, -1, 1])), True)
        self._sense(live)
        tick = live & (clock % self.steps_per_tick == 0)
        for b in np.flatnonzero(tick).tolist():
            # the tick reads where the agents are and changes none of them (the rules
            # that would: team switches, plugin stimuli, are not covered)
            self.pull_view(b)
            self.worlds[b].end_step()
            self.ended[b] = self.worlds[b].done
        over = live & ~tick & (clock >= self.total_steps)  # World.end_step's other rule
        for b in np.flatnonzero(over).tolist():
            self.worlds[b].done = True
        self.ended[over] = True
        self.live[self.ended] = False

    def _settle(self, b: int, a: int, kind: int, before: np.ndarray, speeds: np.ndarray) -> None:
        """What :func:`kernels.settle` flagged for agent ``a`` of trial ``b``: a node entered
        or the target reached run the world's rule alone (the kernel committed the rest);
        anything else is :meth:`World.settle_agent` on the agent's whole state."""
        world = self.worlds[b]
        world.step_index = int(self.clock[b])
        agent = self.agents(b)[a]
        if kind == kernels.ENTERED:
            world.enter_node(agent, int(self.new_node[b, a]), a)
            self.node[b, a] = agent.node
        elif kind == kernels.ARRIVED:
            agent.waypoints.popleft()
            world.arrived(a, agent)
            self.node[b, a] = agent.node
        else:
            self.pull(b, a)
            world.settle_agent(a, agent, (float(before[b, a, 0]), float(before[b, a, 1])),
                               float(speeds[b, a]))
            self.push(b, a)

    def _hurt(self, b: int, before: np.ndarray) -> None:
        """Damage in trial ``b`` as :meth:`World.hurt` deals it, where the reference deals
        it: after pymunk moved the bodies but before the world read them (every agent's
        ``pos`` still the step's start); the player's body holds where it moved to, unless
        a respawn places it elsewhere."""
        world = self.worlds[b]
        attackers = int(self.attackers[b])
        if not world.health.lethal(attackers):  # damage alone: no agent moves, none is read
            world.step_index, world.attackers = int(self.clock[b]), attackers
            world.hurt((0.0, 0.0))
            return
        self.pull(b)
        agents = self.agents(b)
        for a, agent in enumerate(agents):
            agent.pos = (float(before[b, a, 0]), float(before[b, a, 1]))
        player = world.player
        player.body.position = (float(self.pos[b, -1, 0]), float(self.pos[b, -1, 1]))
        before[b, -1] = world.hurt(player.pos)
        self.ended[b] = world.done  # a capture that ends the trial: after this step
        placed = player.body.position
        self.pos[b, -1] = (placed.x, placed.y)
        for a, agent in enumerate(agents):
            agent.pos = (float(self.pos[b, a, 0]), float(self.pos[b, a, 1]))
        self.push(b)

    def _sense(self, live: np.ndarray) -> None:
        w = self.walls
        kernels.sense(live, self.pos, self.heading, self.active, self.node, self.view_range,
                      self.view_scale_at, self.attack_range, self.attack_los, self.cos_half_fov,
                      w.segs, w.cell_start, w.cell_items, w.geom, self.key, self.dist_now,
                      self.has_dist, self.dist_sum, self.dist_n, self.euc_sum, self.euc_n,
                      self.seeing, self.attackers, self.key_changed)
        for b in np.flatnonzero(live & ((self.seeing != 0) | (self.seen != 0))).tolist():
            world = self.worlds[b]
            world.step_index = int(self.clock[b])
            world.detect(_guards(int(self.seeing[b])))
            self.seen[b] = _bits(world.seen_by)
        changed = np.flatnonzero(live & self.key_changed)
        if len(changed):
            self._new_distances(changed)

    def _new_distances(self, trials: np.ndarray) -> None:
        """The path distance of the trials whose nodes changed, asked of the graph as
        ``Counters.sample_distance`` asks it (the active guards' nearest to the player),
        and this step's sample."""
        p = self.node.shape[1] - 1
        active = self.active[trials, :p]
        guards = np.where(active, self.node[trials, :p], -1)
        self.key[trials, :p] = guards
        self.key[trials, p] = self.node[trials, p]
        found = self.graph.nearest_dist_to_rows(guards, self.node[trials, p])
        has = active.any(axis=1)
        self.has_dist[trials] = has
        sampled = trials[has]
        self.dist_now[sampled] = found[has]
        self.dist_sum[sampled] += found[has]
        self.dist_n[sampled] += 1

    def _pymunk_step(self, trials: np.ndarray, before: np.ndarray) -> None:
        """Trials with a body at a wall take this step in their own pymunk space, whose
        solver is the reference's (the kernels move bodies only where nothing touches)."""
        for b in trials.tolist():
            world = self.worlds[b]
            if not self.space_walls[b]:
                add_walls(world.space, self.level)
                self.space_walls[b] = True
            agents = self.agents(b)
            for a, agent in enumerate(agents):
                agent.body.position = (float(before[b, a, 0]), float(before[b, a, 1]))
                agent.body.velocity = (float(self.vel[b, a, 0]), float(self.vel[b, a, 1]))
            world.space.step(self.dt)
            for a, agent in enumerate(agents):
                p, v = agent.body.position, agent.body.velocity
                self.pos[b, a] = (p.x, p.y)
                self.vel[b, a] = (v.x, v.y)


    # ------------------------------------------------------------------ the whole run
    def run(self) -> list[dict[str, Any]]:
        """Step until every trial has ended; their rows."""
        while self.live.any():
            self.step()
        wall = (time.perf_counter() - self.started) / len(self.worlds)
        rows = []
        for b, (spec, world) in enumerate(zip(self.specs, self.worlds, strict=True)):
            self.pull(b)
            m = world.m
            m.dist_sum, m.dist_samples = float(self.dist_sum[b]), int(self.dist_n[b])
            m.euclid_sum, m.euclid_samples = float(self.euc_sum[b]), int(self.euc_n[b])
            rows.append(trial_row(spec, world, wall, engine="batch"))
        return rows


def _bits(guards: Sequence[int]) -> int:
    bits = 0
    for g in guards:
        bits |= 1 << int(g)
    return bits


def _guards(bits: int) -> tuple[int, ...]:
    if bits < len(_SMALL_MASKS):
        return _SMALL_MASKS[bits]
    return tuple(g for g in range(bits.bit_length()) if bits >> g & 1)


#: the guards of every mask of up to 8 guards, in order (a sighting is looked up, not decoded)
_SMALL_MASKS = [tuple(g for g in range(8) if bits >> g & 1) for bits in range(256)]


__all__ = ["Batch", "MAX_BATCH", "refusal_text", "run_trials", "uncovered"]
