"""The player's vector env: many episodes of :class:`game.env.StealthEnv` stepped at once.

``gymnasium.make_vec("stealthfield/Stealth-v0", num_envs=n,
vectorization_mode="vector_entry_point", **options)`` builds :class:`StealthVectorEnv`. Its
sub-envs are the single env's matches (:class:`game.env.match.Match`: the same world,
observations and rewards); their worlds advance together on the batch engine
(:mod:`game.batch`, SPEC §12) — each on its own clock: one vector step is one player move
in every sub-env, the batch stepping the worlds whose move has not ended yet until none
is left. Where the batch engine does not cover the config (``world.engine = "pymunk"``, or
``"auto"`` and a rule it does not cover), each world takes its own steps: the same moves.

Gymnasium's conventions: ``metadata["autoreset_mode"]`` is ``NEXT_STEP`` (the step after
an episode ends resets that sub-env, ignores its action, and returns its first observation
with reward 0); ``reset(seed=s)`` seeds sub-env i with ``s + i``, its later episodes
``s + i + n``, ``s + i + 2n``, ... (no seed is played by two sub-envs);
``reset(options={"reset_mask": m})`` resets only the sub-envs ``m`` marks; ``info`` holds
each sub-env's ``seed``, ``t``, ``hp``, ``captures`` and ``action_mask`` stacked, each with
its ``_``-prefixed mask.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space, create_empty_array

from ai import DEFAULT_GUARD_MODE

from ..batch import Batch, refusal_text, uncovered
from ..config import ENGINE_KEY
from ..trial import TrialSpec
from .match import Match, Move
from .options import check_action, split_options
from .wrappers import OBSERVATIONS, player_layout

__all__ = ["MAX_NUM_ENVS", "StealthVectorEnv"]


def _row(obs: Any, i: int) -> Any:
    """Sub-env ``i``'s observation (a copy) out of a batch of them."""
    if isinstance(obs, dict):
        return {key: value[i].copy() for key, value in obs.items()}
    return obs[i].copy()

#: The most sub-envs one :class:`StealthVectorEnv` holds (10^9 ran out of memory after
#: 38 s); more belong in several processes.
MAX_NUM_ENVS = 1024


class StealthVectorEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` player episodes stepped together (see the module); options as
    :class:`game.env.StealthEnv`'s, ``max_episode_steps`` as ``TimeLimit``'s (``None`` or
    ``-1``: no limit but the env's own clock). ``engine`` says which engine steps them.

    >>> vec = StealthVectorEnv(3, level="maze", world__duration=5.0)
    >>> obs, info = vec.reset(seed=7)
    >>> obs.shape[0], info["seed"].tolist(), vec.engine
    (3, [7, 8, 9], 'batch')
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None,
                 level: str = "miami", guards: str = DEFAULT_GUARD_MODE,
                 abstraction: str = "grid", scenario: str = "capture",
                 observation: str = "flat",
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 **config: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) \
                or not 1 <= num_envs <= MAX_NUM_ENVS:
            raise ValueError(f"num_envs must be a whole number in [1, {MAX_NUM_ENVS}], "
                             f"not {num_envs!r}")
        limit = max_episode_steps
        if limit is not None and (isinstance(limit, bool) or not isinstance(limit, (int, np.integer))
                                  or not (limit == -1 or limit >= 1)):
            raise ValueError(f"max_episode_steps must be a whole number >= 1 (or -1 or None: "
                             f"no limit), not {limit!r}")
        modes = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)
        mode = next((m for m in modes if autoreset_mode in (m, m.value)), None)
        if mode is None:
            raise ValueError(f"autoreset_mode must be {' or '.join(m.value for m in modes)}, "
                             f"not {autoreset_mode!r}")
        #: this env's own copy: NEXT_STEP (the class's) or SAME_STEP
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        if observation not in OBSERVATIONS:
            raise ValueError(f"unknown observation {observation!r} "
                             f"(choose from {', '.join(OBSERVATIONS)})")
        options, overrides = split_options(level, abstraction, scenario, dict(config))
        if options.get("render_mode") is not None:
            raise ValueError("the vector env does not render: use StealthEnv(render_mode=...)")
        first = Match(level, abstraction, scenario, guards, overrides, **options)
        self._level = level  # as given (a bundled name or a path): the trials' level
        self.engine = self._engine(first, level, guards)
        batched = self.engine == "batch"
        self.matches = [Match(level, abstraction, scenario, guards, overrides, batched=batched,
                              **options) for _ in range(int(num_envs))]
        self.num_envs = int(num_envs)
        self.limit = None if limit is None or limit == -1 else int(limit)
        self.observation = observation
        self._layout = player_layout(first.observer)
        self.single_observation_space = self._layout.space(observation)
        self._actions = spaces.Discrete(first.n_actions)
        self.single_action_space = self._actions
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._obs: Any = create_empty_array(self.single_observation_space, self.num_envs)
        self._seeds = np.zeros(self.num_envs, dtype=np.int64)
        self._elapsed = np.zeros(self.num_envs, dtype=np.int64)
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)
        self._started = np.zeros(self.num_envs, dtype=np.bool_)
        self._fallback: np.random.Generator | None = None
        self.batch: Batch | None = None

    @staticmethod
    def _engine(match: Match, level: str, guards: str) -> str:
        """``"batch"`` or ``"pymunk"``: the config's ``world.engine`` (``auto``: batch where
        it covers the config), refused in one line where ``batch`` is asked and not covered."""
        asked = str(match.config[ENGINE_KEY])
        if asked == "pymunk":
            return "pymunk"
        spec = TrialSpec(level=level, abstraction=match.abstraction, guards=guards,
                         player="external", scenario=match.scenario, seed=0)
        problem = uncovered(spec, match.config)
        if problem is None:
            return "batch"
        if asked == "batch":
            raise ValueError(refusal_text(problem))
        return "pymunk"

    # ------------------------------------------------------------------ episodes
    def reset(self, *, seed: int | list[int] | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Start every sub-env's episode (those ``options["reset_mask"]`` marks): sub-env i
        plays seed ``seed + i`` (a list: its own seed; None: drawn once, then + i)."""
        n = self.num_envs
        mask = np.ones(n, dtype=np.bool_)
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.shape != (n,) or mask.dtype != np.bool_:
                raise ValueError(f"reset_mask must be a bool array of shape ({n},), not {mask!r}")
        if seed is None:
            if self._fallback is None:
                self._fallback = np.random.default_rng()
            seeds = int(self._fallback.integers(2**31)) + np.arange(n)
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = int(seed) + np.arange(n)
        else:
            seeds = np.asarray(seed)
            if seeds.shape != (n,) or not np.issubdtype(seeds.dtype, np.integer):
                raise ValueError(f"seed must be an int or a list of {n} ints, not {seed!r}")
        if not self._started.all() and not mask.all():
            raise ValueError("the first reset resets every sub-env (reset_mask all True)")
        infos: dict[str, Any] = {}
        for i in np.flatnonzero(mask).tolist():
            infos = self._add_info(infos, self._reset_one(i, int(seeds[i])), i)
        if self.batch is None and self.engine == "batch":
            specs = [self._spec(m) for m in self.matches]
            self.batch = Batch(specs, [m.world for m in self.matches])
        self._autoreset[mask] = False
        return self._observations(), infos

    def _spec(self, match: Match) -> TrialSpec:
        return TrialSpec(level=self._level, abstraction=match.abstraction,
                         guards=match.guard_mode or "external", player="external",
                         scenario=match.scenario, seed=int(match.seed or 0))

    def _reset_one(self, i: int, seed: int) -> dict[str, Any]:
        """Sub-env ``i`` starts the episode of trial seed ``seed``; its info."""
        match = self.matches[i]
        info = match.reset(seed, np.random.default_rng(seed))
        self._seeds[i], self._elapsed[i], self._started[i] = seed, 0, True
        if self.batch is not None:
            self.batch.replace(i, self._spec(match), match.world)
        self._observe(i)
        return info

    # ------------------------------------------------------------------ steps
    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One player move in every sub-env (a sub-env whose episode ended at the last step
        resets instead: reward 0, its first observation)."""
        if not self._started.all():
            raise RuntimeError("step() before reset()")
        n = self.num_envs
        chosen = np.asarray(actions)
        if chosen.shape != (n,):
            raise ValueError(f"actions must have shape ({n},), not {chosen.shape}")
        rewards = np.zeros(n)
        terminated = np.zeros(n, dtype=np.bool_)
        truncated = np.zeros(n, dtype=np.bool_)
        infos: dict[str, Any] = {}
        moves: dict[int, Move] = {}
        for i in range(n):
            if self._autoreset[i]:
                infos = self._add_info(infos, self._reset_one(i, int(self._seeds[i]) + n), i)
            else:
                action = check_action(self._actions, chosen[i].item(), f"sub-env {i}")
                moves[i] = self.matches[i].begin_move(action)
        self._play(moves)
        for i, move in moves.items():
            if self.batch is not None:
                self.batch.pull(i)  # the world as its arrays left it: clock, bodies
            reward, terminated[i], truncated[i] = move.result()
            rewards[i] = reward
            self._elapsed[i] += 1
            if self.limit is not None and self._elapsed[i] >= self.limit:
                truncated[i] = True  # TimeLimit's rule: cut at the limit, ended or not
            self._observe(i)
            infos = self._add_info(infos, self.matches[i].info(), i)
        ended = terminated | truncated
        if self.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP and ended.any():
            # Gymnasium's SAME_STEP: the next episode starts now; the last observation and
            # info of the ended one in info["final_obs"] / info["final_info"]
            final = {i: (_row(self._obs, i), {k: v[i] for k, v in infos.items()
                                               if not k.startswith("_") and infos["_" + k][i]})
                     for i in np.flatnonzero(ended).tolist()}
            for i, (last_obs, last_info) in final.items():
                infos = self._add_info(infos, self._reset_one(i, int(self._seeds[i]) + n), i)
                infos = self._add_info(infos, {"final_obs": last_obs, "final_info": last_info}, i)
        else:
            self._autoreset = ended
        return self._observations(), rewards, terminated, truncated, infos

    def _play(self, moves: dict[int, Move]) -> None:
        """Step the worlds of ``moves`` until each move is over."""
        if self.batch is None:  # the reference: each world steps on its own
            for i, move in moves.items():
                world = self.matches[i].world
                while True:
                    world.step()
                    if move.after_step(world.player.pos):
                        break
            return
        batch = self.batch
        going = np.zeros(self.num_envs, dtype=np.bool_)
        going[list(moves)] = True
        while going.any():
            batch.step(going)
            players = batch.pos[:, -1].tolist()
            for i in np.flatnonzero(going).tolist():
                x, y = players[i]
                if moves[i].after_step((x, y)):
                    going[i] = False

    # ------------------------------------------------------------------ observations
    def _observe(self, i: int) -> None:
        """Write sub-env ``i``'s observation into the batch of observations."""
        match = self.matches[i]
        one = self._layout.convert(match.observe_player(), self.observation)
        if isinstance(self._obs, dict):
            for key, value in one.items():
                self._obs[key][i] = value
        else:
            self._obs[i] = one

    def _observations(self) -> Any:
        """A copy of the observations (the caller may keep them across steps)."""
        if isinstance(self._obs, dict):
            return {key: value.copy() for key, value in self._obs.items()}
        return self._obs.copy()

    def action_masks(self) -> np.ndarray:
        """(num_envs, actions): each sub-env's action mask now (``MaskablePPO`` reads it)."""
        return np.stack([m.action_mask() for m in self.matches])

    def close_extras(self, **kwargs: Any) -> None:
        for match in self.matches:
            match.close()

