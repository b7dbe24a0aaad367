"""One headless trial as a pure function of its identity (SPEC §6, §7).

``run_trial(spec) -> row`` is top-level and picklable so a sweep can map it over any
``concurrent.futures`` executor. Every random draw comes from generators seeded from the
trial's identity with ``SeedSequence`` (never ``hash()``, which differs per process), so the
same spec gives bit-identical metrics in any process and any order.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import IO, Any

import numpy as np

from ai import DEFAULT_GUARD_MODE, DEFAULT_PLAYER_POLICY, guard_mode, player_policy
from ai.stimuli import load_stimulus
from ai.view import GuardAI, PlayerPolicy
from navmesh.level import Level, cached_level

from .config import IDENTITY_NEUTRAL, Config
from .schema import scenario_speeds
from .trace import attach_trace
from .world import Generators, World


def _tag(name: str) -> int:
    """A stable 32-bit integer for a name (same in every process, unlike ``hash``)."""
    return zlib.crc32(name.encode("utf-8"))


@dataclass(frozen=True)
class TrialSpec:
    """The identity of a trial; everything about it follows from these fields."""

    level: str
    abstraction: str = "grid"
    guards: str = DEFAULT_GUARD_MODE
    player: str = DEFAULT_PLAYER_POLICY
    scenario: str = "capture"
    seed: int = 0
    overrides: tuple[tuple[str, Any], ...] = ()
    root_seed: int = 0
    #: extra stimuli: ``"path/to/file.py:Name"`` or installed entry-point names (docs/mechanics.md)
    stimuli: tuple[str, ...] = ()
    #: this trial's values of the design's factors (SPEC §10), applied after ``overrides``
    factors: tuple[tuple[str, Any], ...] = ()

    @property
    def settings(self) -> dict[str, Any]:
        """Every config override the trial runs with: the fixed ``[set]`` ones, then its factors."""
        return {**dict(self.overrides), **dict(self.factors)}

    @property
    def key(self) -> str:
        """A unique, human-readable key of this trial (used by the results store).

        A setting that changes how the trial is computed, never its result
        (:data:`game.config.IDENTITY_NEUTRAL`: ``world.engine``), is no part of it, so a
        stored trial resumes and re-runs on either engine.
        """
        overrides, factors = _identity(self.overrides), _identity(self.factors)
        extra = ",".join(f"{k}={v}" for k, v in overrides)
        parts = [self.level, self.abstraction, self.guards, self.player, self.scenario,
                 str(self.seed), str(self.root_seed), extra]
        if self.stimuli:  # only then, so the keys of trials without plugins do not change
            parts.append("stimuli=" + "+".join(self.stimuli))
        if factors:  # likewise: a design without factors keeps today's keys
            parts.append("factors=" + ",".join(f"{k}={v}" for k, v in factors))
        return "/".join(parts)


def _identity(settings: tuple[tuple[str, Any], ...]) -> tuple[tuple[str, Any], ...]:
    """``settings`` without the keys that are no part of a trial's identity."""
    return tuple((k, v) for k, v in settings if k not in IDENTITY_NEUTRAL)


SPAWNS_KEY = "world.spawns"
"""The config key of where guards start (``random`` or ``level``)."""


def placed_spawns(level: Level, overrides: tuple[tuple[str, Any], ...]
                  ) -> tuple[tuple[str, Any], ...]:
    """A single trial's overrides (``stealth sim``, :func:`headless.api.run_one`) with
    ``world.spawns = "level"`` first when the level is a Tiled map that places guards and
    the overrides do not set the key: a designer who drew guards means them to start there
    (with their ``facing`` and ``patrol``). JSON levels and designs (presets) keep the
    configured rule. The setting is part of the trial's key, so a replay starts alike."""
    if level.tiled and level.guards and SPAWNS_KEY not in dict(overrides):
        return ((SPAWNS_KEY, "level"), *overrides)
    return overrides


def trial_rngs(spec: TrialSpec, level_name: str) -> Generators:
    """Generators for spawns, guards and player, derived from the trial's identity.

    The spawn generator depends on (root, level, abstraction, seed) only, so every guard
    mode and player policy of one seed starts from the same positions (common random
    numbers: comparisons between modes are paired), and so does every level of a factor.
    The controllers' generators depend on the whole identity, factor values included (a
    trial without factors draws exactly what it drew before factors existed).
    """
    base = [spec.root_seed, _tag(level_name), _tag(spec.abstraction), spec.seed]
    who = [_tag(spec.guards), _tag(spec.player), _tag(spec.scenario)]
    who += [_tag(f"{k}={v!r}") for k, v in _identity(spec.factors)]
    seqs = [
        np.random.SeedSequence(base + [_tag("spawn")]),
        np.random.SeedSequence(base + who + [_tag("guards")]),
        np.random.SeedSequence(base + who + [_tag("player")]),
    ]
    spawn, guards, player = (np.random.Generator(np.random.PCG64(s)) for s in seqs)
    return spawn, guards, player


def make_world(
    spec: TrialSpec, config: Config | None = None, *, level: Level | None = None,
    controllers: tuple[GuardAI, PlayerPolicy | None] | None = None, **world_kwargs: Any,
) -> World:
    """Build the world of a trial: the one place a :class:`World` is constructed.

    Level and graph are cached per process. ``level`` is the level already loaded (else
    ``spec.level`` is loaded); ``controllers`` are the guard AI and player policy to run
    (an environment's external controllers, the mechanics experiment's players; ``None``
    for no player policy), else the spec's are made. The generators always derive from the
    spec (:func:`trial_rngs`); ``world_kwargs`` go to :class:`World` (``graph``,
    ``interactive``, ``stimuli``).
    """
    if spec.stimuli:  # first: loading a plugin registers the zone kinds its level may use
        world_kwargs.setdefault("stimuli", [load_stimulus(s) for s in spec.stimuli])
    config = config or Config.load(spec.settings)  # and its parameters' config section
    if level is None:
        level = cached_level(spec.level)
    if controllers is None:
        guards = guard_mode(spec.guards)
        controllers = (guards.build_for(config),
                       player_policy(spec.player).build(
                           player_params(config, spec.scenario, spec.player)))
    guard_ai, player = controllers
    return World(
        level,
        spec.abstraction,
        guard_ai,
        player,
        config=config,
        scenario=spec.scenario,
        rngs=trial_rngs(spec, level.name),
        **world_kwargs,
    )


def identity_row(spec: TrialSpec, level_name: str | None = None, *,
                 key: str | None = None) -> dict[str, Any]:
    """The identity part of a trial's row, built from the spec in this one place (a
    trial's row, a failed trial's, a session's; a results store keeps it as it is):
    ``key`` (the spec's, or ``key``), the spec's fields (``stimuli`` and ``factors`` only
    when set), ``level`` the level's name (``level_name``; the spec's level when it is not
    known) and ``level_ref`` the name or path the level was loaded from."""
    return {
        "key": spec.key if key is None else key,
        **{k: v for k, v in asdict(spec).items() if k not in ("overrides", "stimuli", "factors")},
        **({"stimuli": list(spec.stimuli)} if spec.stimuli else {}),
        **({"factors": dict(spec.factors)} if spec.factors else {}),
        "level": spec.level if level_name is None else level_name,
        "level_ref": spec.level,
        "overrides": dict(spec.overrides),
    }


def player_params(config: Config, scenario: str, policy: str | None = None) -> dict[str, Any]:
    """What a player policy needs: its own section (``policy``'s registered one; the
    built-ins' ``[player]`` when not given) plus both speeds in this scenario."""
    section = "player" if policy is None else player_policy(policy).section
    return {**config.section(section), **scenario_speeds(config, scenario)}


def run_trial(
    spec: TrialSpec, trace: IO[str] | None = None, explain: bool = False, *,
    world: World | None = None,
) -> dict[str, Any]:
    """Run one trial to its end and return its row: identity, config hash, metrics, heatmaps,
    and ``engine``, the engine that ran it (here always ``"pymunk"``, the reference; the
    batch engine's rows, :func:`game.batch.run_trials`, say ``"batch"``).

    With ``trace`` every AI tick (and t = 0) is written as one JSON line; with ``explain``
    those lines also carry the first guard's last decision explained (PF only). ``world``
    is the trial's world already built by :func:`make_world` from ``spec`` (``stealth sim``
    builds it from the level and config it loaded and checked, before it opens a trace);
    else it is built here.
    """
    started = time.perf_counter()
    if world is None:
        world = make_world(spec)
    writer = attach_trace(world, trace, explain=explain) if trace is not None else None
    metrics = world.run()
    if writer is not None:
        writer.finish(world)
    return trial_row(spec, world, time.perf_counter() - started, metrics)


def trial_row(spec: TrialSpec, world: World, wall_time: float,
              metrics: dict[str, Any] | None = None, engine: str = "pymunk") -> dict[str, Any]:
    """The row of a trial whose ``world`` has ended (either engine makes it here):
    identity, config hash, metrics (``world.metrics()`` unless given), heatmaps, the
    seconds it took and the engine that ran it."""
    config = world.config
    return {
        **identity_row(spec, world.level.name),
        "config_hash": config.hash(),
        "config": config.as_dict(),
        "metrics": world.metrics() if metrics is None else metrics,
        "visits": world.m.visits.tolist(),
        "attacks": [round(a, 6) for a in world.m.attacks.tolist()],
        "wall_time": wall_time,
        "engine": engine,
    }


def sim_document(row: Mapping[str, Any]) -> dict[str, Any]:
    """The ``stealth sim --json`` shape of SPEC §9 from a trial row."""
    return {
        "level": row["level"],
        "abstraction": row["abstraction"],
        "guards": row["guards"],
        "player": row["player"],
        "scenario": row["scenario"],
        "seed": row["seed"],
        "config_hash": row["config_hash"],
        "config": row["config"],
        **({"stimuli": list(row["stimuli"])} if row.get("stimuli") else {}),
        **({"engine": row["engine"]} if "engine" in row else {}),
        "metrics": row["metrics"],
    }


__all__: Sequence[str] = ["SPAWNS_KEY", "TrialSpec", "identity_row", "placed_spawns",
                          "run_trial", "make_world", "trial_rngs",
                          "trial_row", "sim_document"]
