"""One environment's match: the world, the agents' controllers, their rewards and frames.

Shared by both environments of :mod:`game.env`. The player and externally controlled
guards are controllers (:class:`ExternalPlayer`, :class:`ExternalGuards`) that answer the
world's decisions with the node the agent's action points to; one :meth:`Match.step` is
one player move.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces

from ai import guard_mode
from ai.pf import PotentialFieldGuards
from ai.view import PlayerPolicy, WorldView
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import cached_level

from ..config import Config
from .observations import OBS_BOUND, Observer
from ..trial import TrialSpec, make_world
from ..world import SCENARIOS, World

__all__ = ["ExternalGuards", "ExternalPlayer", "GRID_ACTIONS", "Match", "Move",
           "PARTITION_ACTIONS", "REWARDS", "SHAPING"]

#: Grid actions (Discrete(5)): stay and the four neighbouring cells (y grows downwards).
GRID_ACTIONS = ("stay", "north", "east", "south", "west")
#: Partition actions (Discrete(9)): stay and eight compass directions.
PARTITION_ACTIONS = ("stay", "north", "northeast", "east", "southeast",
                     "south", "southwest", "west", "northwest")
#: Default reward terms (see docs/api.md, "Rewards"): per second survived, per HP lost, per
#: capture; then shaping by the change of a potential: ``seen`` while a guard sees the
#: player, ``proximity`` for a guard on the player's node, falling linearly to 0 at the
#: guards' view range along the level's paths. A potential's change sums to its last
#: value minus its first over an episode, so shaping never pays a player to die sooner.
#: One per second survived makes the game's part of the return the capture scenario's own
#: score, seconds survived, less 1 per HP and 3 per capture (what the fixed-time scenario,
#: whose clock always runs out, scores); a step is worth about ±0.5 (issue 23).
REWARDS = {"survival": 1.0, "hp": 1.0, "capture": 3.0, "seen": 1.0, "proximity": 3.0}
#: The shaping terms of :data:`REWARDS` (the rest are the game's own score): with these at 0
#: an episode's return is the game's.
SHAPING = ("seen", "proximity")


#: each graph's move table, built once (a read-only array shared by every env on the graph)
_MOVES: weakref.WeakKeyDictionary[NodeGraph, np.ndarray] = weakref.WeakKeyDictionary()


def direction_table(graph: NodeGraph) -> np.ndarray:
    """:func:`_direction_table` of ``graph``, built once per graph (read-only)."""
    moves = _MOVES.get(graph)
    if moves is None:
        moves = _MOVES[graph] = _direction_table(graph)
        moves.flags.writeable = False
    return moves


def _direction_table(graph: NodeGraph) -> np.ndarray:
    """``moves[node, action]``: the node an action leads to from ``node`` (itself if none).

    Grid: the neighbouring cell in that direction. Partition: among the nodes one or two
    hops away, the farthest along the direction within 45° of it (67.5° if none is), so
    an action covers about one grid move's worth of corridor even across small triangles.
    """
    n = graph.n
    pos = graph.positions
    if graph.kind == "grid":
        units = np.array([(0, 0), (0, -1), (1, 0), (0, 1), (-1, 0)], dtype=float)
    else:
        angles = -np.pi / 2 + np.arange(8) * np.pi / 4  # north first, clockwise (y down)
        units = np.vstack([[0.0, 0.0], np.stack([np.cos(angles), np.sin(angles)], axis=1)])
    moves = np.repeat(np.arange(n)[:, None], len(units), axis=1)
    for node in range(n):
        if graph.kind == "grid":
            options = np.asarray(graph.neighbors[node])
        else:
            hops = graph.hops_from(node, max_hops=2)
            options = np.flatnonzero((hops >= 1) & (hops <= 2))
        if not len(options):
            continue
        delta = pos[options] - pos[node]
        length = np.hypot(delta[:, 0], delta[:, 1])
        for a in range(1, len(units)):
            along = delta @ units[a]
            cos = along / np.maximum(length, 1e-12)
            for limit in (math.cos(math.pi / 4) - 1e-9, math.cos(3 * math.pi / 8)):
                ok = cos >= limit
                if ok.any():
                    moves[node, a] = int(options[ok][np.argmax(along[ok])])
                    break
    return moves


#: The largest ``obs_radius``: a window of 513 × 513 cells per channel (about 5 MB a
#: guard's observation); a larger one would only pad a bundled level with zeros.
MAX_OBS_RADIUS = 256
#: The largest reward weight in absolute value: a 60-s return stays far from overflowing
#: (1e308 per second survived made the reward inf).
MAX_REWARD_WEIGHT = 1e6


def _check_rewards(rewards: Any) -> None:
    """Refuse ``rewards`` other than a dict of known terms to finite weights within
    ±:data:`MAX_REWARD_WEIGHT` (a ValueError naming the term), at construction."""
    if rewards is None:
        return
    if not isinstance(rewards, Mapping):
        raise ValueError(f"rewards must be a dict of reward terms to weights, not {rewards!r}")
    unknown = set(rewards) - set(REWARDS)
    if unknown:
        raise ValueError(f"unknown reward terms {sorted(unknown)} (choose from {list(REWARDS)})")
    weights: dict[str, Any] = dict(rewards)
    for term, weight in weights.items():
        if isinstance(weight, bool) or not isinstance(weight, (int, float, np.integer, np.floating)) \
                or not -MAX_REWARD_WEIGHT <= weight <= MAX_REWARD_WEIGHT:  # NaN fails it
            raise ValueError(f"reward weight {term!r} must be a finite number in "
                             f"[-{MAX_REWARD_WEIGHT:g}, {MAX_REWARD_WEIGHT:g}], not {weight!r}")


def _render_size(size: Any) -> tuple[int, int]:
    """``size`` as ``(width, height)`` of positive whole pixels, or a ValueError naming it.

    Refused here, at construction, rather than inside pygame at the first ``render()``.
    """
    try:
        width, height = size
    except (TypeError, ValueError):
        width = height = None
    ok = all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) and 0 < v <= 8192
             for v in (width, height))
    if not ok:
        raise ValueError(f"render_size must be (width, height) in whole pixels in [1, 8192], "
                         f"not {size!r}")
    return int(width), int(height)


class ExternalPlayer(PlayerPolicy):
    """The player as an env agent: each decision goes where the current action points.

    It counts its decisions so the env can tell when the move it asked for has begun.
    """

    policy = "external"

    def __init__(self, moves: np.ndarray) -> None:
        super().__init__()
        self.moves = moves
        self.action = 0
        self.decisions = 0
        self.target = -1

    def reset(self, graph: NodeGraph, rng: np.random.Generator) -> None:
        self.action, self.decisions, self.target = 0, 0, -1

    def decide(self, view: WorldView) -> int:
        self.decisions += 1
        self.target = int(self.moves[view.player_node, self.action])
        return self.target


class ExternalGuards(PotentialFieldGuards):
    """Guards whose moves come from env actions, one per guard.

    It still advances the team's shared potential fields on every AI tick exactly as the
    ``pf`` guards would (sightings, confidence, stimuli hooks), only to show them to the
    guard agents in their observations; the decisions ignore the fields.
    """

    mode = "external"

    def __init__(self, moves: np.ndarray, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(params)
        self.moves = moves
        self.actions = np.zeros(0, dtype=np.int64)

    def reset(self, graph: NodeGraph, rng: np.random.Generator, n_guards: int) -> None:
        super().reset(graph, rng, n_guards)
        self.actions = np.zeros(n_guards, dtype=np.int64)

    def decide(self, i: int, view: WorldView) -> int:
        return int(self.moves[view.guard_nodes[i], self.actions[i]])

    def state_name(self, i: int) -> str:
        return self.mode


class Move:
    """One player move in progress (:meth:`Match.begin_move`): after each physics step of
    the match's world, :meth:`after_step` says whether the move is over — the world's
    trial ended, the player respawned, its target reached (a "stay": held as long as a move
    takes), a second decision began, or :attr:`Match.max_steps` passed — and
    :meth:`result` gives its reward, termination and truncation."""

    def __init__(self, match: Match) -> None:
        self.match = match
        w = match.world
        self.hp0, self.t0, self.caps0 = w.hp, w.t, w.m.captures
        self.hp = self.hp0
        self.steps = 0
        self.staying = False

    def after_step(self, pos: tuple[float, float]) -> bool:
        """The world took one more step and the player stands at ``pos``: is the move over?"""
        match, w = self.match, self.match.world
        k, self.steps = self.steps, self.steps + 1
        if w.done or w.hp > self.hp:  # over, or respawned after a capture (fixed-time)
            return True
        self.hp = w.hp
        player = match.player
        if player.decisions == 1 and k == 0:
            self.staying = player.target == w.player.node and match.at(player.target, pos)
        if player.decisions:
            if self.staying:
                if k + 1 >= match.hold_steps:
                    return True
            elif player.decisions > 1 or match.at(player.target, pos):
                return True
        return self.steps >= match.max_steps

    def result(self) -> tuple[float, bool, bool]:
        """The move's player reward, terminated and truncated (the world read as it is)."""
        match, w = self.match, self.match.world
        captures = w.m.captures - self.caps0
        ends = match.ends_on_capture
        if captures and not ends:  # fixed-time: the player respawned with full HP
            lost = self.hp0 + (captures - 1) * match.hp_max + (match.hp_max - w.hp)
        else:
            lost = self.hp0 - max(0.0, w.hp)
        danger, match._danger = match._danger, match.danger()
        r = match.rewards
        reward = (r["survival"] * (w.t - self.t0) - r["hp"] * lost
                  - r["capture"] * captures + danger - match._danger)
        terminated = bool(w.done and captures and ends)
        truncated = bool(w.done and not terminated)
        return float(reward), terminated, truncated


class Match:
    """One env's world, controllers, observation encoders, rewards and renderer.

    Shared by both environments; ``guard_mode=None`` means the guards are agents.
    """

    def __init__(self, level: str, abstraction: str, scenario: str, guard_mode: str | None,
                 overrides: Mapping[str, Any], obs_radius: int = 2,
                 rewards: Mapping[str, float] | None = None,
                 render_mode: str | None = None,
                 render_size: tuple[int, int] | None = None, batched: bool = False) -> None:
        if abstraction not in ("grid", "partition"):
            raise ValueError(f"unknown abstraction {abstraction!r} (choose grid or partition)")
        if render_mode not in (None, "rgb_array", "human"):
            raise ValueError(f"unknown render_mode {render_mode!r} (choose rgb_array or human)")
        if scenario not in SCENARIOS:
            raise ValueError(f"unknown scenario {scenario!r} (choose from {', '.join(SCENARIOS)})")
        _check_rewards(rewards)
        if isinstance(obs_radius, bool) or not isinstance(obs_radius, (int, np.integer)) \
                or not 0 <= obs_radius <= MAX_OBS_RADIUS:
            raise ValueError(f"obs_radius must be a whole number of cells in [0, {MAX_OBS_RADIUS}], "
                             f"not {obs_radius!r}")
        if render_size is not None:
            render_size = _render_size(render_size)
        self.level = cached_level(level)
        #: worlds for the batch engine (a vector env steps them): walls out of their spaces
        self.batched = bool(batched)
        self.abstraction, self.scenario, self.guard_mode = abstraction, scenario, guard_mode
        self.overrides = dict(overrides)
        self.config = Config.load(self.overrides)
        self.graph = graph_for(self.level, abstraction)
        self.moves = direction_table(self.graph)
        self.n_actions = self.moves.shape[1]
        self.rewards = {**REWARDS, **(rewards or {})}
        self.render_mode, self.render_size = render_mode, render_size
        cfg = self.config
        self.dt = float(cfg["world.physics_step"])
        self.duration = float(cfg["world.duration"])
        self.hp_max = float(cfg["world.player_hp"])
        self.view_range = float(cfg["world.view_range"]) * float(
            cfg[f"scenario.{scenario}.view_range_scale"])
        speed = float(cfg["world.player_speed"]) * float(
            cfg[f"scenario.{scenario}.player_speed_scale"])
        #: physics steps a "stay" lasts: as long as a move along a mean edge takes, at most a
        #: whole step's limit (a player too slow to cross an edge within it, e.g. a speed of
        #: 5e-324, holds that long; the quotient itself may be infinite)
        limit = math.ceil(2 * float(cfg["world.stuck_timeout"]) / self.dt)
        hold = self.graph.mean_edge_length / speed / self.dt - 1e-9
        self.hold_steps = max(1, math.ceil(hold)) if hold < limit else max(1, limit)
        self.max_steps = max(self.hold_steps, limit)
        self.ends_on_capture = bool(cfg[f"scenario.{scenario}.end_on_capture"])
        #: node positions as Python floats (the same values as the graph's rows)
        self._points: list[list[float]] = self.graph.positions.tolist()

        self.seed: int | None = None
        self.world = self._new_world(0)
        self._danger = 0.0
        self.n_guards = len(self.world.guards)
        self.observer = Observer(self.level, self.graph, obs_radius, self.view_range,
                                 self.duration, self.hp_max, self.n_guards, self.moves)
        self._renderer: Any = None

    # ------------------------------------------------------------------ episodes
    def _new_world(self, seed: int) -> World:
        self.player = ExternalPlayer(self.moves)
        if self.guard_mode is None:
            self.guards: ExternalGuards | None = ExternalGuards(self.moves, self.config.section("pf"))
            guard_ai: Any = self.guards
        else:
            self.guards = None
            guard_ai = guard_mode(self.guard_mode).build_for(self.config)
        spec = TrialSpec(level=self.level.name, abstraction=self.abstraction,
                         guards=self.guard_mode or "external", player="external",
                         scenario=self.scenario, seed=seed)
        return make_world(spec, self.config, level=self.level,
                          controllers=(guard_ai, self.player), graph=self.graph,
                          walls_in_space=not self.batched)

    def reset(self, seed: int | None, fallback: np.random.Generator) -> dict[str, Any]:
        """Start the episode of trial seed ``seed`` (or the next one); return its info."""
        if seed is not None:
            self.seed = int(seed)
        elif self.seed is None:
            self.seed = int(fallback.integers(2**31))
        else:
            self.seed += 1
        self.world = self._new_world(self.seed)
        self._danger = self.danger()
        return self.info()

    def danger(self) -> float:
        """The shaping potential now (negated): ``seen`` × seen + ``proximity`` × nearness.

        Nearness falls linearly from 1 (a guard on the player's node) to 0 at the view
        range; blind guards (view range 0) are near only on the player's node (the limit).
        """
        r = self.rewards
        out = r["seen"] * bool(self.world.seen_by)
        if r["proximity"]:
            distance = self.guard_distance()
            if self.view_range > 0:
                out += r["proximity"] * max(0.0, 1.0 - distance / self.view_range)
            elif distance == 0:
                out += r["proximity"]
        return out

    def info(self) -> dict[str, Any]:
        """``seed``, ``t``, ``hp``, ``captures`` and the player's ``action_mask``."""
        w = self.world
        return {"seed": self.seed, "t": round(w.t, 6), "hp": round(w.hp, 6),
                "captures": w.m.captures, "action_mask": self.action_mask()}

    def action_mask(self, node: int | None = None) -> np.ndarray:
        """Which actions move the agent on ``node`` (default: the player's); stay always can.

        An ``int8`` array of 0 and 1, the dtype Gymnasium's ``Discrete.sample(mask=...)`` and
        PettingZoo's API tests require. An action masked out is legal all the same (it
        stays): the mask only tells a masking learner which actions are worth trying.
        """
        row = self.moves[self.world.player.node if node is None else node]
        mask = (row != row[0]).view(np.int8)
        mask[0] = 1
        return mask

    def guard_distance(self) -> float:
        """Path distance from the player's node to the nearest active guard's (inf if none)."""
        w = self.world
        nodes = [g.node for g in w.guards if g.active]
        if not nodes:
            return math.inf
        cached = w.m.cached_distance(w.player.node, nodes)  # the distance metric's, if current
        return self.graph.nearest_dist_to(nodes, w.player.node) if cached is None else cached

    def step(self, player_action: int, guard_actions: np.ndarray | None = None
             ) -> tuple[float, bool, bool]:
        """Play one player move; return (player reward, terminated, truncated)."""
        move = self.begin_move(player_action, guard_actions)
        w = self.world
        while True:
            w.step()
            if move.after_step(w.player.pos):
                return move.result()

    def begin_move(self, player_action: int, guard_actions: np.ndarray | None = None) -> Move:
        """Ask for one player move (:class:`Move` says when it is over and what it earned);
        the world is then stepped by the caller: this match (:meth:`step`) or a vector env
        that steps many worlds at once."""
        if self.world.done:
            raise RuntimeError("step() after the episode ended: call reset()")
        self.player.action, self.player.decisions = int(player_action), 0
        if self.guards is not None and guard_actions is not None:
            self.guards.actions[:] = guard_actions
        return Move(self)

    def at(self, node: int, pos: tuple[float, float]) -> bool:
        """Whether a player standing at ``pos`` is on ``node``'s point (within 1e-3)."""
        px, py = self._points[node]
        return math.hypot(pos[0] - px, pos[1] - py) <= 1e-3

    # ------------------------------------------------------------------ rendering
    def observe_player(self) -> np.ndarray:
        """The player's observation now (layout: docs/api.md, "Observations")."""
        return self.observer.observe_player(self.world, self.world.view())

    def observe_guard(self, view: WorldView, i: int) -> np.ndarray:
        """Guard ``i``'s observation of ``view``: what the team knows plus its fields."""
        return self.observer.observe_guard(self.world, view, i, self.guards)

    def obs_space(self, guard: bool, size: int | None = None) -> spaces.Box:
        """The observation space of the player or a guard (``size``: a padded length)."""
        size = self.observer.obs_size(guard) if size is None else size
        return spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(size,), dtype=np.float32)

    # ------------------------------------------------------------------ rendering
    def render(self) -> np.ndarray | None:
        """Draw the world with the game's renderer: an RGB array, or into a window."""
        if self.render_mode is None:
            return None
        if self._renderer is None:
            # lazy: only rendering imports pygame (game.front); the core never does
            from game.front.frames import FrameRenderer  # noqa: PLC0415
            from game.scene import SceneBuilder  # noqa: PLC0415

            builder = SceneBuilder(self.level, self.graph, view_range=self.view_range,
                                   fov_deg=float(self.config["world.fov_deg"]))
            self._renderer = FrameRenderer(builder, self.render_mode, self.render_size,
                                           title=f"Stealthfield — {self.level.name}")
        return self._renderer.draw(self.world)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


