"""Reinforcement-learning environments over the simulated world (SPEC §10, docs/api.md).

* :func:`parallel_env` — a PettingZoo ``ParallelEnv``: the player and every guard are agents
  (``"player_0"``, ``"guard_0"``, ``"guard_1"``, ...; the old name ``"player"`` is still
  read, with a DeprecationWarning, until 0.3); :func:`env` / :func:`raw_env` — the same as
  PettingZoo's AEC env (agents act in turn).
* :class:`StealthEnv` — a Gymnasium ``Env``: the agent is the player, the guards run one of
  the project's guard AIs (``pf``, ``fsm``, ...). Registered as ``"stealthfield/Stealth-v0"``
  when this module is imported.
* :class:`StealthVectorEnv` (:mod:`game.env.vector`) — ``gymnasium.make_vec`` of that id: many
  player episodes stepped together on the batch engine.

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

Only rendering imports pygame (``game.front``), inside :meth:`game.env.match.Match.render`.
Observations: :mod:`game.env.observations`; the match (world, controllers, rewards):
:mod:`game.env.match`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
    from pettingzoo import AECEnv, ParallelEnv
    from pettingzoo.utils.conversions import parallel_to_aec_wrapper
    from pettingzoo.utils.wrappers import OrderEnforcingWrapper
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError(
        f"game.env needs gymnasium and pettingzoo ({error.name} is missing): "
        "pip install 'stealthfield[rl]'"
    ) from error

from ai import DEFAULT_GUARD_MODE

from .match import (  # re-exported: the env API names them
    GRID_ACTIONS,
    PARTITION_ACTIONS,
    REWARDS,
    SHAPING,
    ExternalGuards,
    ExternalPlayer,
    Match,
)
from .observations import (  # re-exported: the layout's names (docs/api.md)
    GUARD_CHANNELS,
    GUARD_FEATURES,
    MOVE_FEATURES,
    OTHER_GUARD,
    PLAYER_AS_SEEN,
    PLAYER_CHANNELS,
    PLAYER_FEATURES,
    PLAYER_GUARD,
    STATE_FEATURES,
    STATE_GUARD,
)
from .observations import OBS_BOUND
from .options import check_action, split_options
from .vector import MAX_NUM_ENVS, StealthVectorEnv
from .wrappers import OBSERVATIONS, FlatObsWrapper, ImgObsWrapper, player_layout

ENV_ID = "stealthfield/Stealth-v0"


# ---------------------------------------------------------------------------- PettingZoo

#: The player's agent name, in PettingZoo's ``<kind>_<index>`` style.
PLAYER = "player_0"
#: The player's name until issue 41; still accepted, with a DeprecationWarning, until 0.3.
OLD_PLAYER = "player"


def _old_name_warning(stacklevel: int) -> None:
    warnings.warn(f"the agent name {OLD_PLAYER!r} is deprecated and will be removed in 0.3: "
                  f"use {PLAYER!r}", DeprecationWarning, stacklevel=stacklevel + 1)


def agent_name(agent: Any, stacklevel: int = 2) -> Any:
    """``agent`` with the deprecated ``"player"`` read as ``"player_0"`` (and a warning)."""
    if agent == OLD_PLAYER:
        _old_name_warning(stacklevel + 1)
        return PLAYER
    return agent


class AgentDict(dict[str, Any]):
    """A dict keyed by agent names in which ``d["player"]`` still finds ``d["player_0"]``.

    Only lookup by the old name is forwarded (with a DeprecationWarning); keys, iteration,
    ``in`` and ``get`` see the new names alone, so PettingZoo's checks see no extra agent.
    """

    def __missing__(self, key: str) -> Any:
        if key == OLD_PLAYER and PLAYER in self:
            _old_name_warning(2)
            return self[PLAYER]
        raise KeyError(key)


class StealthParallelEnv(ParallelEnv):
    """Player and guards as PettingZoo agents in one trial (see :func:`parallel_env`)."""

    metadata = {"name": "stealthfield_v0", "render_modes": ["rgb_array", "human"],
                "render_fps": 4, "is_parallelizable": True}

    def __init__(self, level: str = "miami", abstraction: str = "grid",
                 scenario: str = "capture", pad_observations: bool = True,
                 **config: Any) -> None:
        if not isinstance(pad_observations, (bool, np.bool_)):
            raise ValueError(f"pad_observations must be True or False, not {pad_observations!r}")
        options, overrides = split_options(level, abstraction, scenario, config)
        self.match = Match(level, abstraction, scenario, None, overrides, **options)
        self.render_mode = self.match.render_mode
        self.possible_agents = [PLAYER] + [f"guard_{i}" for i in range(self.match.n_guards)]
        self.agents: list[str] = []
        sizes = {a: self.match.observer.obs_size(a != PLAYER) for a in self.possible_agents}
        #: every agent's observation length: the largest one when padding (the default)
        self._sizes = dict.fromkeys(sizes, max(sizes.values())) if pad_observations else sizes
        self._obs_spaces = {a: self.match.obs_space(a != PLAYER, self._sizes[a])
                            for a in self.possible_agents}
        self._act_spaces = {a: spaces.Discrete(self.match.n_actions) for a in self.possible_agents}
        #: the global state's space (:meth:`state`): everyone's true position and status
        self.state_space = spaces.Box(-OBS_BOUND, OBS_BOUND,
                                      shape=(self.match.observer.state_size(),), dtype=np.float32)
        #: where the first seedless reset's seed comes from; made at the first reset, not
        #: here, so that copies of a new env (SuperSuit's vector wrappers pickle one per
        #: copy, then SB3 resets them seedless) draw seeds of their own: copies of one
        #: generator all drew the same seed and played the same episodes
        self._fallback: np.random.Generator | None = None

    def observation_space(self, agent: str) -> spaces.Box:
        return self._obs_spaces[agent_name(agent)]

    def action_space(self, agent: str) -> spaces.Discrete:
        return self._act_spaces[agent_name(agent)]

    def state(self) -> np.ndarray:
        """The global state now (layout: docs/api.md, "State"): what a centralised critic
        reads, the true positions of everyone whatever each agent perceives."""
        return self.match.observer.state(self.match.world, self.match.world.view())

    def _observe(self) -> AgentDict:
        view = self.match.world.view()
        obs = AgentDict({PLAYER: self.match.observe_player()})
        for i in range(self.match.n_guards):
            obs[f"guard_{i}"] = self.match.observe_guard(view, i)
        for agent, o in obs.items():
            if len(o) < self._sizes[agent]:  # padded mode: zeros after the agent's own layout
                obs[agent] = np.concatenate([o, np.zeros(self._sizes[agent] - len(o), np.float32)])
        return obs

    def _infos(self) -> AgentDict:
        info = self.match.info()
        infos = {PLAYER: info}
        for i, guard in enumerate(self.match.world.guards):
            infos[f"guard_{i}"] = {**info, "action_mask": self.match.action_mask(guard.node)}
        return AgentDict({a: infos[a] for a in self.agents})

    def action_masks(self, agent: str) -> np.ndarray:
        """``agent``'s action mask now (as its ``info["action_mask"]``)."""
        agent = agent_name(agent)
        if agent == PLAYER:
            return self.match.action_mask()
        return self.match.action_mask(self.match.world.guards[self._guard_index(agent)].node)

    def _guard_index(self, agent: str) -> int:
        if agent not in self.possible_agents or agent == PLAYER:
            raise ValueError(f"unknown agent {agent!r} (agents: {self.possible_agents})")
        return self.possible_agents.index(agent) - 1

    def reset(self, seed: int | None = None, options: dict | None = None
              ) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
        if self._fallback is None:  # made at the first reset (OS entropy): see __init__
            self._fallback = np.random.default_rng()
        self.match.reset(seed, self._fallback)
        self.agents = list(self.possible_agents)
        return self._observe(), self._infos()

    def step(self, actions: Mapping[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """Missing actions mean "stay"; guard rewards are the negated player reward.

        An unknown agent or an action outside the agent's space is a ValueError naming it;
        the deprecated name ``"player"`` is read as ``"player_0"`` (twice is an error).
        """
        if not self.agents:
            raise RuntimeError("step() after the episode ended: call reset()")
        unknown = [a for a in actions if a not in self.agents and a != OLD_PLAYER]
        if unknown:
            raise ValueError(f"unknown agent(s) {unknown} (agents: {self.agents})")
        if OLD_PLAYER in actions:
            if PLAYER in actions:
                raise ValueError(f"actions for both {OLD_PLAYER!r} and {PLAYER!r}: "
                                 f"they are one agent (use {PLAYER!r})")
            _old_name_warning(2)
            actions = {PLAYER if a == OLD_PLAYER else a: act for a, act in actions.items()}
        chosen = {a: check_action(self._act_spaces[a], act, repr(a)) for a, act in actions.items()}
        guard_actions = np.array([chosen.get(f"guard_{i}", 0)
                                  for i in range(self.match.n_guards)], dtype=np.int64)
        reward, terminated, truncated = self.match.step(chosen.get(PLAYER, 0), guard_actions)
        obs = self._observe()
        rewards = AgentDict({a: (reward if a == PLAYER else -reward) for a in self.agents})
        terms = AgentDict(dict.fromkeys(self.agents, terminated))
        truncs = AgentDict(dict.fromkeys(self.agents, truncated))
        infos = self._infos()
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
                 pad_observations: bool = True, **config: Any) -> StealthParallelEnv:
    """A PettingZoo ``ParallelEnv`` of one level: agents ``"player_0"``, ``"guard_0"``, ...

    Every agent's observation has the same length (the guards', the longest; the player's
    is padded with zeros) so that SuperSuit's vector wrappers take the env as it is;
    ``pad_observations=False`` gives each agent its own length.

    Options: ``render_mode`` (``"rgb_array"`` or ``"human"``), ``render_size`` ``(w, h)``,
    ``obs_radius`` (half side of the observation window, default 2 cells), ``rewards``
    (override :data:`REWARDS` terms), ``overrides`` (``{"world.guards": 2, ...}``); any
    other keyword is a config override with ``__`` for ``.`` (``world__guards=2``).

    >>> env = parallel_env("maze", world__guards=2)
    >>> env.possible_agents
    ['player_0', 'guard_0', 'guard_1']
    """
    return StealthParallelEnv(level, abstraction, scenario, pad_observations, **config)


def raw_env(level: str = "miami", abstraction: str = "grid", scenario: str = "capture",
            pad_observations: bool = True, **config: Any) -> AECEnv:
    """The PettingZoo AEC env of :func:`parallel_env` without wrappers: agents act in turn
    (``player_0``, ``guard_0``, ...) and the world plays the move once the last has acted.

    >>> aec = raw_env("maze", world__guards=2)
    >>> aec.reset(seed=0); aec.agent_selection
    'player_0'
    """
    return parallel_to_aec_wrapper(parallel_env(level, abstraction, scenario, pad_observations,
                                                **config))


def env(level: str = "miami", abstraction: str = "grid", scenario: str = "capture",
        pad_observations: bool = True, **config: Any) -> AECEnv:
    """:func:`raw_env` with PettingZoo's ``OrderEnforcingWrapper`` (what its ``env()`` gives)."""
    return OrderEnforcingWrapper(raw_env(level, abstraction, scenario, pad_observations,
                                         **config))


# ---------------------------------------------------------------------------- Gymnasium


class StealthEnv(gymnasium.Env):
    """The player against AI guards (``guards``: pf, random, fsm, staleness, cheat).

    Same observations, actions, step and rewards as the ``"player_0"`` agent of
    :func:`parallel_env`; options as there, and ``observation``: ``"flat"`` (the default),
    ``"dict"`` or ``"image"`` (:mod:`game.env.wrappers`).

    >>> env = StealthEnv("maze", guards="pf")
    >>> obs, info = env.reset(seed=3)
    >>> obs.shape == env.observation_space.shape, info["seed"]
    (True, 3)
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 4}

    def __init__(self, level: str = "miami", guards: str = DEFAULT_GUARD_MODE,
                 abstraction: str = "grid", scenario: str = "capture",
                 observation: str = "flat", **config: Any) -> None:
        if observation not in OBSERVATIONS:
            raise ValueError(f"unknown observation {observation!r} "
                             f"(choose from {', '.join(OBSERVATIONS)})")
        options, overrides = split_options(level, abstraction, scenario, config)
        self.match = Match(level, abstraction, scenario, guards, overrides, **options)
        self.render_mode = self.match.render_mode
        #: ``"flat"``, ``"dict"`` or ``"image"`` (game.env.wrappers)
        self.observation = observation
        self._layout = player_layout(self.match.observer)
        self.observation_space = self._layout.space(observation)
        self._actions = spaces.Discrete(self.match.n_actions)
        self.action_space = self._actions

    def _observe(self) -> Any:
        return self._layout.convert(self.match.observe_player(), self.observation)

    def reset(self, *, seed: int | None = None, options: dict | None = None
              ) -> tuple[Any, dict[str, Any]]:
        super().reset(seed=seed)
        info = self.match.reset(seed, self.np_random)
        return self._observe(), info

    def action_masks(self) -> np.ndarray:
        """Which actions move the player now (sb3-contrib's ``MaskablePPO`` reads this)."""
        return self.match.action_mask()

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """One player move; an action outside ``action_space`` is a ValueError naming it."""
        action = check_action(self._actions, action, "the player")
        reward, terminated, truncated = self.match.step(action)
        obs = self._observe()
        if self.render_mode == "human":
            self.match.render()
        return obs, reward, terminated, truncated, self.match.info()

    def render(self) -> np.ndarray | None:
        return self.match.render()

    def close(self) -> None:
        self.match.close()


#: ``spec.max_episode_steps`` of the registered env: the default episode (60 s) in physics
#: steps (1/20 s). An env step lasts at least one physics step, so the ``TimeLimit`` wrapper
#: ``gymnasium.make`` adds never ends a default episode before the env's own clock does; a
#: longer ``world.duration`` needs ``max_episode_steps=`` (or ``-1``: no wrapper) of its own.
MAX_EPISODE_STEPS = 1200

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="game.env:StealthEnv",
                       vector_entry_point="game.env:StealthVectorEnv",
                       max_episode_steps=MAX_EPISODE_STEPS)

__all__ = ["ENV_ID", "GRID_ACTIONS", "GUARD_CHANNELS", "GUARD_FEATURES", "MAX_EPISODE_STEPS",
           "MOVE_FEATURES", "OLD_PLAYER", "OTHER_GUARD", "PARTITION_ACTIONS", "PLAYER",
           "PLAYER_AS_SEEN", "PLAYER_CHANNELS", "PLAYER_FEATURES", "PLAYER_GUARD", "REWARDS",
           "SHAPING", "OBSERVATIONS", "STATE_FEATURES", "STATE_GUARD", "AgentDict", "FlatObsWrapper",
           "ImgObsWrapper", "ExternalGuards", "ExternalPlayer",
           "StealthEnv", "StealthParallelEnv", "StealthVectorEnv", "agent_name", "check_action",
           "env", "parallel_env", "raw_env"]
