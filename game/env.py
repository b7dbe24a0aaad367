"""Reinforcement-learning environments over the simulated world (SPEC §10, docs/api.md).

* :func:`parallel_env` — a PettingZoo ``ParallelEnv``: the player and every guard are agents
  (``"player"``, ``"guard_0"``, ``"guard_1"``, ...).
* :class:`StealthEnv` — a Gymnasium ``Env``: the agent is the player, the guards run one of
  the project's guard AIs (``pf``, ``fsm``, ...). Registered as ``"stealthfield/Stealth-v0"``
  when this module is imported.

Both drive the ordinary :class:`~game.world.World` through its public API: the player and
externally controlled guards are controllers (:class:`ExternalPlayer`,
:class:`ExternalGuards`) that answer the world's decisions with the node the agent's
action points to. **One env step is one player move**: the player walks to the node its
action chose and the step ends when it arrives ("stay" holds for as long as one move
takes), the trial ends, or the player is captured. Guards decide whenever they reach their
node, as in every trial. Seeding is through ``reset(seed=s)`` only: episode ``s`` uses the
generators of trial seed ``s`` (:func:`game.trial.trial_rngs`), so guard spawns, headings
and the player's start are those of every headless trial with that level, abstraction and
seed; the following seedless resets play seeds ``s + 1``, ``s + 2``, ...

Only rendering imports pygame (``game.front``), inside :meth:`_Match.render`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString

try:
    import gymnasium
    from gymnasium import spaces
    from pettingzoo import ParallelEnv
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError(
        f"game.env needs gymnasium and pettingzoo ({error.name} is missing): "
        "pip install 'stealthfield[rl]'"
    ) from error

from ai import make_guard_ai
from ai.pf import PotentialFieldGuards
from ai.view import PlayerPolicy, WorldView
from navmesh.graph import NodeGraph, graph_for
from navmesh.level import cached_level

from .config import Config
from .trial import TrialSpec, trial_rngs
from .world import World

ENV_ID = "stealthfield/Stealth-v0"
#: Grid actions (Discrete(5)): stay and the four neighbouring cells (y grows downwards).
GRID_ACTIONS = ("stay", "north", "east", "south", "west")
#: Partition actions (Discrete(9)): stay and eight compass directions.
PARTITION_ACTIONS = ("stay", "north", "northeast", "east", "southeast",
                     "south", "southwest", "west", "northwest")
#: Every observation entry lies in [-OBS_BOUND, OBS_BOUND] (most in [-1, 1]).
OBS_BOUND = 10.0
#: Names of the window channels of a player's / a guard's observation.
PLAYER_CHANNELS = ("walkable", "player", "guards")
GUARD_CHANNELS = ("walkable", "player", "guards", "information", "confidence")
PLAYER_FEATURES = ("x", "y", "cos_heading", "sin_heading", "hp", "time", "detected")
GUARD_FEATURES = ("x", "y", "cos_heading", "sin_heading", "player_hp", "time", "sees_player")
OTHER_GUARD = ("known", "dx", "dy", "cos_heading", "sin_heading")
PLAYER_AS_SEEN = ("known", "dx", "dy")
#: Default reward terms (see docs/api.md, "Rewards").
REWARDS = {"survival": 0.1, "hp": 1.0, "capture": 10.0}
#: Keyword options of the environments; every other keyword is a config override.
_OPTIONS = ("render_mode", "obs_radius", "rewards", "render_size", "overrides")


# ---------------------------------------------------------------------------- controllers


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
            hops = graph.hops[node]
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


# ---------------------------------------------------------------------------- the match


def _active(view: WorldView) -> np.ndarray:
    """Which guards are in play (all of them when the view does not say)."""
    if view.guard_active is None:
        return np.ones(len(view.guard_nodes), dtype=bool)
    return view.guard_active


def _split_options(level: str, abstraction: str, scenario: str, kwargs: dict[str, Any]
                   ) -> tuple[dict[str, Any], dict[str, Any]]:
    """Env options and config overrides (``world__guards=2`` means ``world.guards=2``)."""
    options = {k: kwargs.pop(k) for k in _OPTIONS if k in kwargs}
    overrides = dict(options.pop("overrides", None) or {})
    for key, value in kwargs.items():
        overrides[key.replace("__", ".")] = value
    return options, overrides


class _Match:
    """One env's world, controllers, observation encoders, rewards and renderer.

    Shared by both environments; ``guard_mode=None`` means the guards are agents.
    """

    def __init__(self, level: str, abstraction: str, scenario: str, guard_mode: str | None,
                 overrides: Mapping[str, Any], obs_radius: int = 4,
                 rewards: Mapping[str, float] | None = None,
                 render_mode: str | None = None,
                 render_size: tuple[int, int] | None = None) -> None:
        if abstraction not in ("grid", "partition"):
            raise ValueError(f"unknown abstraction {abstraction!r} (choose grid or partition)")
        if render_mode not in (None, "rgb_array", "human"):
            raise ValueError(f"unknown render_mode {render_mode!r} (choose rgb_array or human)")
        unknown = set(rewards or {}) - set(REWARDS)
        if unknown:
            raise ValueError(f"unknown reward terms {sorted(unknown)} (choose from {list(REWARDS)})")
        self.level = cached_level(level)
        self.abstraction, self.scenario, self.guard_mode = abstraction, scenario, guard_mode
        self.overrides = dict(overrides)
        self.config = Config.load(self.overrides)
        self.graph = graph_for(self.level, abstraction)
        self.moves = _direction_table(self.graph)
        self.n_actions = self.moves.shape[1]
        self.radius = int(obs_radius)
        if self.radius < 0:
            raise ValueError("obs_radius must be >= 0")
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
        #: physics steps a "stay" lasts: as long as a move along a mean edge takes
        self.hold_steps = max(1, math.ceil(self.graph.mean_edge_length / speed / self.dt - 1e-9))
        self.max_steps = max(self.hold_steps, math.ceil(2 * float(cfg["world.stuck_timeout"]) / self.dt))

        rows, cols = self.level.rows, self.level.cols
        cs = self.level.cell_size
        self.cell_size = cs
        self.width, self.height = cols * cs, rows * cs
        self.diagonal = math.hypot(self.width, self.height)
        r = self.radius
        self.occupancy = np.pad(self.level.occupancy.astype(np.float32), r)
        if self.graph.cell_node is not None:
            cell_node = np.asarray(self.graph.cell_node)
        else:
            cell_node = np.full((rows, cols), -1, dtype=np.int64)
            for row, col in zip(*np.nonzero(self.level.occupancy), strict=True):
                cell_node[row, col] = self.graph.node_at((col + 0.5) * cs, (row + 0.5) * cs)
        self.cell_node = np.pad(cell_node, r, constant_values=-1)
        self.walkable = self.level.walkable
        shapely.prepare(self.walkable)

        self.seed: int | None = None
        self.world = self._new_world(0)
        self.n_guards = len(self.world.guards)
        self._renderer: Any = None

    # ------------------------------------------------------------------ episodes
    def _new_world(self, seed: int) -> World:
        self.player = ExternalPlayer(self.moves)
        if self.guard_mode is None:
            self.guards: ExternalGuards | None = ExternalGuards(self.moves, self.config.section("pf"))
            guard_ai: Any = self.guards
        else:
            self.guards = None
            guard_ai = make_guard_ai(self.guard_mode, self.config.section(self.guard_mode))
        spec = TrialSpec(level=self.level.name, abstraction=self.abstraction,
                         guards=self.guard_mode or "external", player="external",
                         scenario=self.scenario, seed=seed)
        return World(self.level, self.abstraction, guard_ai, self.player, config=self.config,
                     scenario=self.scenario, rngs=trial_rngs(spec, self.level.name),
                     graph=self.graph)

    def reset(self, seed: int | None, fallback: np.random.Generator) -> dict[str, Any]:
        """Start the episode of trial seed ``seed`` (or the next one); return its info."""
        if seed is not None:
            self.seed = int(seed)
        elif self.seed is None:
            self.seed = int(fallback.integers(2**31))
        else:
            self.seed += 1
        self.world = self._new_world(self.seed)
        return self.info()

    def info(self) -> dict[str, Any]:
        w = self.world
        return {"seed": self.seed, "t": round(w.t, 6), "hp": round(w.hp, 6),
                "captures": w.metrics()["captures"]}

    def step(self, player_action: int, guard_actions: np.ndarray | None = None
             ) -> tuple[float, bool, bool]:
        """Play one player move; return (player reward, terminated, truncated)."""
        w = self.world
        if w.done:
            raise RuntimeError("step() after the episode ended: call reset()")
        self.player.action, self.player.decisions = int(player_action), 0
        if self.guards is not None and guard_actions is not None:
            self.guards.actions[:] = guard_actions
        hp0, t0, caps0 = w.hp, w.t, w.metrics()["captures"]
        staying = False
        hp = hp0
        for k in range(self.max_steps):
            w.step()
            if w.done or w.hp > hp:  # over, or respawned after a capture (fixed-time)
                break
            hp = w.hp
            if self.player.decisions == 1 and k == 0:
                staying = self.player.target == w.player.node and self._at(self.player.target)
            if self.player.decisions:
                if staying:
                    if k + 1 >= self.hold_steps:
                        break
                elif self.player.decisions > 1 or self._at(self.player.target):
                    break
        captures = w.metrics()["captures"] - caps0
        ends = bool(self.config[f"scenario.{self.scenario}.end_on_capture"])
        if captures and not ends:  # fixed-time: the player respawned with full HP
            lost = hp0 + (captures - 1) * self.hp_max + (self.hp_max - w.hp)
        else:
            lost = hp0 - max(0.0, w.hp)
        reward = (self.rewards["survival"] * (w.t - t0) - self.rewards["hp"] * lost
                  - self.rewards["capture"] * captures)
        terminated = bool(w.done and captures and ends)
        truncated = bool(w.done and not terminated)
        return float(reward), terminated, truncated

    def _at(self, node: int) -> bool:
        x, y = self.world.player.pos
        px, py = self.graph.positions[node]
        return math.hypot(x - px, y - py) <= 1e-3

    # ------------------------------------------------------------------ observations
    def _cell(self, pos: Any) -> tuple[int, int]:
        return (min(max(int(pos[1] // self.cell_size), 0), self.level.rows - 1),
                min(max(int(pos[0] // self.cell_size), 0), self.level.cols - 1))

    def _window(self, centre: Any, channels: int) -> tuple[np.ndarray, int, int]:
        r = self.radius
        row, col = self._cell(centre)
        win = np.zeros((channels, 2 * r + 1, 2 * r + 1), dtype=np.float32)
        win[0] = self.occupancy[row:row + 2 * r + 1, col:col + 2 * r + 1]
        return win, row, col

    def _mark(self, win: np.ndarray, channel: int, row: int, col: int, pos: Any) -> None:
        r = self.radius
        pr, pc = self._cell(pos)
        if abs(pr - row) <= r and abs(pc - col) <= r:
            win[channel, pr - row + r, pc - col + r] += 1.0

    def player_sees(self, view: WorldView, j: int) -> bool:
        """The player perceives guard ``j`` within view range with a clear line (no cone)."""
        a, b = view.player_pos, view.guard_positions[j]
        if not _active(view)[j] or math.dist(a, b) > self.view_range:
            return False
        return math.dist(a, b) < 1e-9 or bool(self.walkable.covers(LineString([a, b])))

    def _self_features(self, pos: Any, heading: float, view: WorldView) -> list[float]:
        return [pos[0] / self.width, pos[1] / self.height, math.cos(heading), math.sin(heading),
                self.world.hp / self.hp_max, min(1.0, view.t / self.duration)]

    def _guard_features(self, view: WorldView, origin: Any, known: list[bool]) -> list[float]:
        out: list[float] = []
        for j in range(self.n_guards):
            if known[j]:
                d = (view.guard_positions[j] - origin) / self.diagonal
                h = view.guard_headings[j]
                out += [1.0, d[0], d[1], math.cos(h), math.sin(h)]
            else:
                out += [0.0] * len(OTHER_GUARD)
        return out

    def observe_player(self, view: WorldView) -> np.ndarray:
        """The player's observation (layout: docs/api.md, "Observations")."""
        pos = view.player_pos
        win, row, col = self._window(pos, len(PLAYER_CHANNELS))
        self._mark(win, 1, row, col, pos)
        known = [self.player_sees(view, j) for j in range(self.n_guards)]
        for j in range(self.n_guards):
            if known[j]:
                self._mark(win, 2, row, col, view.guard_positions[j])
        heading = self.world.player.heading
        vec = self._self_features(pos, heading, view) + [float(bool(view.seen_by))]
        vec += self._guard_features(view, pos, known)
        return self._pack(win, vec)

    def observe_guard(self, view: WorldView, i: int) -> np.ndarray:
        """Guard ``i``'s observation: what the team knows plus the team's fields."""
        pos = view.guard_positions[i]
        win, row, col = self._window(pos, len(GUARD_CHANNELS))
        team_sees = bool(view.seen_by)
        if team_sees:
            self._mark(win, 1, row, col, view.player_pos)
        for j in range(self.n_guards):
            if _active(view)[j]:
                self._mark(win, 2, row, col, view.guard_positions[j])
        if self.guards is not None:
            fields = self.guards.fields()
            r = self.radius
            nodes = self.cell_node[row:row + 2 * r + 1, col:col + 2 * r + 1]
            inside = nodes >= 0
            info = np.asarray(fields["I"]) + np.asarray(fields["I_extra"])
            c_scale = self.guards.config.C0 / max(1e-9, 1.0 - self.guards.config.rho)
            win[3][inside] = info[nodes[inside]] / self.guards.config.I0
            win[4][inside] = np.asarray(fields["C"])[nodes[inside]] / c_scale
        vec = self._self_features(pos, float(view.guard_headings[i]), view)
        vec += [float(i in view.seen_by)]
        vec += self._guard_features(view, pos, [bool(a) for a in _active(view)])
        d = (view.player_pos - pos) / self.diagonal
        vec += [1.0, d[0], d[1]] if team_sees else [0.0, 0.0, 0.0]
        return self._pack(win, vec)

    @staticmethod
    def _pack(win: np.ndarray, vec: list[float]) -> np.ndarray:
        out = np.concatenate([win.ravel(), np.asarray(vec, dtype=np.float32)])
        return np.clip(out, -OBS_BOUND, OBS_BOUND).astype(np.float32)

    def obs_size(self, guard: bool) -> int:
        side = (2 * self.radius + 1) ** 2
        if guard:
            return (len(GUARD_CHANNELS) * side + len(GUARD_FEATURES)
                    + len(OTHER_GUARD) * self.n_guards + len(PLAYER_AS_SEEN))
        return len(PLAYER_CHANNELS) * side + len(PLAYER_FEATURES) + len(OTHER_GUARD) * self.n_guards

    def obs_space(self, guard: bool) -> spaces.Box:
        return spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(self.obs_size(guard),), dtype=np.float32)

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


# ---------------------------------------------------------------------------- PettingZoo


class StealthParallelEnv(ParallelEnv):
    """Player and guards as PettingZoo agents in one trial (see :func:`parallel_env`)."""

    metadata = {"name": "stealthfield_v0", "render_modes": ["rgb_array", "human"],
                "render_fps": 4, "is_parallelizable": True}

    def __init__(self, level: str = "miami", abstraction: str = "grid",
                 scenario: str = "capture", **config: Any) -> None:
        options, overrides = _split_options(level, abstraction, scenario, config)
        self.match = _Match(level, abstraction, scenario, None, overrides, **options)
        self.render_mode = self.match.render_mode
        self.possible_agents = ["player"] + [f"guard_{i}" for i in range(self.match.n_guards)]
        self.agents: list[str] = []
        self._obs_spaces = {a: self.match.obs_space(a != "player") for a in self.possible_agents}
        self._act_spaces = {a: spaces.Discrete(self.match.n_actions) for a in self.possible_agents}
        self._fallback = np.random.default_rng()

    def observation_space(self, agent: str) -> spaces.Box:
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> spaces.Discrete:
        return self._act_spaces[agent]

    def _observe(self) -> dict[str, np.ndarray]:
        view = self.match.world.view()
        obs = {"player": self.match.observe_player(view)}
        for i in range(self.match.n_guards):
            obs[f"guard_{i}"] = self.match.observe_guard(view, i)
        return obs

    def reset(self, seed: int | None = None, options: dict | None = None
              ) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
        info = self.match.reset(seed, self._fallback)
        self.agents = list(self.possible_agents)
        return self._observe(), {a: dict(info) for a in self.agents}

    def step(self, actions: Mapping[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """Missing actions mean "stay"; guard rewards are the negated player reward."""
        if not self.agents:
            raise RuntimeError("step() after the episode ended: call reset()")
        guard_actions = np.array([int(actions.get(f"guard_{i}", 0))
                                  for i in range(self.match.n_guards)], dtype=np.int64)
        reward, terminated, truncated = self.match.step(int(actions.get("player", 0)), guard_actions)
        obs = self._observe()
        rewards = {a: (reward if a == "player" else -reward) for a in self.agents}
        terms = dict.fromkeys(self.agents, terminated)
        truncs = dict.fromkeys(self.agents, truncated)
        info = self.match.info()
        infos = {a: dict(info) for a in self.agents}
        if terminated or truncated:
            self.agents = []
        if self.render_mode == "human":
            self.match.render()
        return obs, rewards, terms, truncs, infos

    def render(self) -> np.ndarray | None:
        return self.match.render()

    def close(self) -> None:
        self.match.close()


def parallel_env(level: str = "miami", abstraction: str = "grid", scenario: str = "capture",
                 **config: Any) -> StealthParallelEnv:
    """A PettingZoo ``ParallelEnv`` of one level: agents ``"player"``, ``"guard_0"``, ...

    Options: ``render_mode`` (``"rgb_array"`` or ``"human"``), ``render_size`` ``(w, h)``,
    ``obs_radius`` (half side of the observation window, default 4 cells), ``rewards``
    (override :data:`REWARDS` terms), ``overrides`` (``{"world.guards": 2, ...}``); any
    other keyword is a config override with ``__`` for ``.`` (``world__guards=2``).

    >>> env = parallel_env("maze", world__guards=2)
    >>> env.possible_agents
    ['player', 'guard_0', 'guard_1']
    """
    return StealthParallelEnv(level, abstraction, scenario, **config)


# ---------------------------------------------------------------------------- Gymnasium


class StealthEnv(gymnasium.Env):
    """The player against AI guards (``guards``: pf, random, fsm, staleness, cheat).

    Same observations, actions, step and rewards as the ``"player"`` agent of
    :func:`parallel_env`; options as there.

    >>> env = StealthEnv("maze", guards="pf")
    >>> obs, info = env.reset(seed=3)
    >>> obs.shape == env.observation_space.shape, info["seed"]
    (True, 3)
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 4}

    def __init__(self, level: str = "miami", guards: str = "pf", abstraction: str = "grid",
                 scenario: str = "capture", **config: Any) -> None:
        options, overrides = _split_options(level, abstraction, scenario, config)
        self.match = _Match(level, abstraction, scenario, guards, overrides, **options)
        self.render_mode = self.match.render_mode
        self.observation_space = self.match.obs_space(False)
        self.action_space = spaces.Discrete(self.match.n_actions)

    def reset(self, *, seed: int | None = None, options: dict | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        info = self.match.reset(seed, self.np_random)
        return self.match.observe_player(self.match.world.view()), info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        reward, terminated, truncated = self.match.step(int(action))
        obs = self.match.observe_player(self.match.world.view())
        if self.render_mode == "human":
            self.match.render()
        return obs, reward, terminated, truncated, self.match.info()

    def render(self) -> np.ndarray | None:
        return self.match.render()

    def close(self) -> None:
        self.match.close()


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="game.env:StealthEnv")

__all__ = ["parallel_env", "StealthParallelEnv", "StealthEnv", "ExternalPlayer",
           "ExternalGuards", "ENV_ID", "GRID_ACTIONS", "PARTITION_ACTIONS", "REWARDS"]
