"""The config's keys, their defaults' one source and their allowed values, declared once each.

A section that feeds a parameter dataclass has that class's fields as keys, its field
defaults as defaults and its ``bounds`` (:mod:`ai.bounds`) as allowed values
(:func:`parameter_sections`): each registered guard mode and player policy brings its own
(``ai.register_guard_mode(..., params=, section=)``: ``[pf]`` is
:class:`~ai.params.PFParams`, ``[fsm]`` / ``[staleness]`` the FSM classes, ``[player]``
:class:`~ai.params.PlayerParams`), so does each loaded plugin stimulus that declares
``parameters`` (``[its section]``), and the world's are ``[stimuli]``
(:class:`~ai.stimuli.StimulusParams` plus :class:`~game.action_params.ActionParams`) and the four
switchable team rules. The keys no dataclass holds — ``[world]``, ``[scenario.*]``,
``[zones]`` (:class:`~ai.stimuli.Zone` per zone kind), ``[metrics]`` and the team rules'
``enabled`` switches — have their defaults in ``game/defaults.toml`` and their bounds here.
:func:`game.config.check_value` checks a value against :func:`bound_of` its key;
:func:`check_sections` builds the dataclasses (their cross-key rules, e.g.
``w_I_max >= w_I_base``) and :func:`check_level` what depends on the level.
``docs/config.md`` is :func:`markdown_table` (a test keeps it current).

>>> bound_of("pf.rho").describe(), bound_of("world.fov_deg").describe()
('(0, 1]', '[0, 360]')
>>> bound_of("zones.dark_confidence_decay") is bound_of("zones.concealment_confidence_decay")
True
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any, Protocol

from ai import registrations
from ai.bounds import COUNT, FLAG, NON_NEGATIVE, POSITIVE, Bound, OneOf, Range
from ai.alert import AlertParams
from ai.awareness import AwarenessParams
from ai.params import PlayerParams, Params
from ai.radio import RadioParams
from ai.roles import RoleParams
from ai.stimuli import STIMULUS_TYPES, StimulusParams, Zone, zones_from_config
from navmesh.clearance import check_body
from navmesh.level import ZONE_KINDS

from .action_params import ActionParams
from .budget import check_trial_steps
from .errors import ConfigError
from .metrics import BACKTRACK_RULES, COVERAGE_RULES, DISTANCE_RULES, PARTITION_COVERAGE_RULES

if TYPE_CHECKING:
    from navmesh.level import Level

__all__ = [
    "ENGINES", "RESPAWN_RULES", "SEED", "SPAWN_RULES", "bound_of", "check_level", "check_sections",
    "markdown_table", "parameter_defaults", "parameter_sections", "registered_params",
    "scenario_speeds",
]

SPAWN_RULES = ("random", "level")
"""``world.spawns``: guard start nodes drawn per seed, or the level's spawn points."""

RESPAWN_RULES = ("farthest", "random", "stay")
"""``world.respawn``: where the fixed-time scenario puts a captured player (game.spawns):
the start rule's farthest hidden node, a hidden node drawn uniformly, or where it stands
(``stay``: HP restored, no teleport; the paper's trial runs "regardless of the player's
health status")."""

ENGINES = ("auto", "pymunk", "batch")
"""``world.engine`` (SPEC §12): what advances a headless trial. ``pymunk``: the reference,
one :class:`~game.world.World` per trial; ``batch``: the trials of one level and abstraction
advanced in lockstep over arrays (:mod:`game.batch`); ``auto`` (the default): a sweep or a
study runs on ``batch`` the trials it covers and on ``pymunk`` the rest, one trial alone
(``stealth sim``, ``play``, the envs) on ``pymunk``. All give the same rows trial for trial,
so the engine is no part of a trial's identity (``game.config.IDENTITY_NEUTRAL``)."""

SEED = Range(0, 2**63 - 1, integer=True)
"""A trial's ``seed`` and a preset's ``root_seed``: whole numbers that fit the store's
64-bit integer column (``numpy.random.SeedSequence`` refuses negative ones)."""

#: seconds between decision ticks, 0 = on arrival; longer than 10 s is no decision rule
#: of the paper's (1 s) and would leave agents standing most of a 60 s trial
DECISION_INTERVAL = Range(0.0, 10.0)

#: SPEC §6: the physics step is at most 1/20 s (faster bodies would tunnel through walls)
_PHYSICS_STEP = Range(0.0, 0.05, low_open=True)

WORLD: Mapping[str, Bound] = {
    "guards": COUNT,
    "spawns": OneOf(SPAWN_RULES),
    "respawn": OneOf(RESPAWN_RULES),
    "player_hp": POSITIVE,
    "ai_tick": POSITIVE,
    # 0 = decide on arrival (SPEC §6); > 0 = the paper's grid decision tick (game.world)
    "grid_decision_interval": NON_NEGATIVE,
    # both abstractions; > 0 wins over grid_decision_interval (game.world.decision_interval)
    "decision_interval": DECISION_INTERVAL,
    "physics_step": _PHYSICS_STEP,
    "physics_step_interactive": _PHYSICS_STEP,
    "duration": POSITIVE,
    # the scripted players read both speeds too: their declaration is the one
    "guard_speed": PlayerParams.bounds["guard_speed"],
    "player_speed": PlayerParams.bounds["player_speed"],
    "sprint_factor": POSITIVE,
    "sneak_factor": POSITIVE,
    # and below half the level's cell size: check_level
    "agent_radius": POSITIVE,
    "view_range": NON_NEGATIVE,
    "fov_deg": Range(0.0, 360.0),
    "attack_range": NON_NEGATIVE,
    "attack_needs_line_of_sight": FLAG,
    # the game's rule (stealth play's [play.world]); off: the paper's l. 206
    "attack_needs_awareness": FLAG,
    "attack_memory": NON_NEGATIVE,
    "stuck_timeout": POSITIVE,
    "engine": OneOf(ENGINES),
}
"""``[world]``: the keys the world reads itself."""

SCENARIO: Mapping[str, Bound] = {
    "player_speed_scale": POSITIVE,
    "view_range_scale": NON_NEGATIVE,
    "end_on_capture": FLAG,
}
"""``[scenario.<name>]``: the same keys for every scenario."""

# ---- [metrics] (SPEC §11): which definition the keyed metrics take (game.metrics); they
# change what is measured, never what happens
METRICS: Mapping[str, Bound] = {
    "coverage": OneOf(COVERAGE_RULES),
    # SPEC §12: the partition's own reading ("same": metrics.coverage on both)
    "partition_coverage": OneOf(PARTITION_COVERAGE_RULES),
    "backtracks": OneOf(BACKTRACK_RULES),
    "distance": OneOf(DISTANCE_RULES),
}
"""``[metrics]``: the definition of coverage, backtracks and distance."""

#: the switchable rules beyond the paper: config section -> parameter class; each section
#: also has an ``enabled`` switch (game.team)
_TEAM_RULES: Mapping[str, Any] = {"awareness": AwarenessParams, "alert": AlertParams,
                                  "radio": RadioParams, "roles": RoleParams}

#: the world's parameter classes, by the section that holds their keys
_WORLD_PARAMS: Mapping[str, tuple[type[Params], ...]] = {
    "stimuli": (StimulusParams, ActionParams), **{k: (v,) for k, v in _TEAM_RULES.items()}}

#: the sections no parameter class holds (defaults in game/defaults.toml, bounds above)
_FILE_SECTIONS: Mapping[str, Mapping[str, Bound]] = {
    "world": WORLD,
    "zones": {f"{kind}_{name}": bound for kind in ZONE_KINDS for name, bound in Zone.bounds.items()},
    "metrics": METRICS,
}

_Registered = tuple[tuple[str, str, type[Params]], ...]


def registered_params() -> _Registered:
    """``(section, name, params class)`` of every registration that has parameters: the
    guard modes' and player policies', then the loaded plugin stimuli's
    (:attr:`ai.stimuli.Stimulus.parameters`)."""
    return (*((r.section, r.name, cls) for r in registrations()
              if (cls := r.parameters()) is not None),
            *((s.section, s.name, cls) for s in STIMULUS_TYPES.values()
              if (cls := s.parameters) is not None))


@functools.cache
def _sections(registered: _Registered) -> dict[str, tuple[type[Params], ...]]:
    sections: dict[str, tuple[type[Params], ...]] = {}
    for section, name, cls in registered:
        if section in _FILE_SECTIONS or section in _WORLD_PARAMS or section.startswith("scenario"):
            raise ConfigError(f"{name}: config section [{section}] is the world's; register "
                              "its parameters under a section of their own")
        sections.setdefault(section, (cls,))  # one class a section: ai checks at registration
    return {**sections, **_WORLD_PARAMS}


def parameter_sections() -> Mapping[str, tuple[type[Params], ...]]:
    """Config section -> the parameter dataclasses whose fields are its keys: the registered
    guard modes' and player policies' (registration order), then the world's.

    >>> [c.__name__ for c in parameter_sections()["stimuli"]], parameter_sections()["pf"]
    (['StimulusParams', 'ActionParams'], (<class 'ai.params.PFParams'>,))
    """
    return _sections(registered_params())


def parameter_defaults(section: str) -> dict[str, Any]:
    """The defaults of ``section``'s keys, from its parameter classes (the one source);
    empty for a section no parameter class holds.

    >>> parameter_defaults("pf")["rho"], "guard_speed" in parameter_defaults("player")
    (0.95, False)
    """
    classes = parameter_sections().get(section, ())
    return {k: v for cls in classes for k, v in cls.config_defaults().items()}


@functools.cache
def _tables(registered: _Registered) -> dict[str, Mapping[str, Bound]]:
    tables: dict[str, Mapping[str, Bound]] = dict(_FILE_SECTIONS)
    for section, classes in _sections(registered).items():
        table: dict[str, Bound] = {"enabled": FLAG} if section in _TEAM_RULES else {}
        for cls in classes:
            table.update({k: cls.bounds[k] for k in cls.config_defaults()})
        tables[section] = table
    return tables


def bound_of(key: str) -> Bound:
    """The declared allowed values of config key ``key``; KeyError when none is declared."""
    section, _, name = key.rpartition(".")
    tables = _tables(registered_params())
    table = SCENARIO if section.startswith("scenario.") else tables.get(section, {})
    if name not in table:
        raise KeyError(f"{key}: no bound declared in game.schema")
    return table[name]


def scenario_speeds(values: Any, scenario: str) -> dict[str, float]:
    """The speeds a player policy's parameters take from ``[world]`` in ``scenario``
    (``PlayerParams.from_world``); ``values`` is a config or its flat mapping."""
    return {"guard_speed": values["world.guard_speed"],
            "player_speed": (values["world.player_speed"]
                             * values[f"scenario.{scenario}.player_speed_scale"])}


def _section(values: Mapping[str, Any], name: str) -> dict[str, Any]:
    prefix = name + "."
    return {k[len(prefix):]: v for k, v in values.items()
            if k.startswith(prefix) and "." not in k[len(prefix):]}


def check_sections(values: Mapping[str, Any]) -> None:
    """Build every section's parameter dataclass from ``values`` (flat dotted keys), so the
    rules between keys hold before anything runs; a violation raises :class:`ConfigError`.

    ``values`` are already in range key by key (:func:`game.config.check_value`).
    """
    scenarios = sorted({k.split(".")[1] for k in values if k.startswith("scenario.")})
    builds: list[tuple[str, Any, dict[str, Any]]] = []
    for section, classes in parameter_sections().items():
        given = _section(values, section)
        for cls in classes:
            own = {k: given[k] for k in cls.config_defaults() if k in given}
            if not cls.from_world:
                builds.append((section, cls, own))
            builds += [(f"{section} (scenario {scenario})", cls,
                        {**own, **scenario_speeds(values, scenario)})
                       for scenario in (scenarios if cls.from_world else ())]
    for where, cls, params in builds:
        try:
            cls.from_mapping(params)
        except ValueError as error:
            raise ConfigError(f"{where}: {error}") from None
    try:
        zones_from_config(_section(values, "zones"))
    except ValueError as error:
        raise ConfigError(f"zones: {error}") from None
    check_trial_steps(values)  # the work budget (game.budget)


class Settings(Protocol):
    """Config values read by dotted key (a :class:`game.config.Config`, which is built on
    this module: the schema never names it)."""

    def __getitem__(self, key: str) -> Any: ...


def check_level(config: Settings, level: Level) -> None:
    """What a level bounds: an agent's body must pass a one-cell corridor, so
    ``world.agent_radius`` must be below half the level's cell size (both abstractions:
    the level is drawn on that grid). Raises :class:`ConfigError`; a level whose walkable
    area that body cannot cross raises :class:`~navmesh.errors.LevelError`, the same check
    as ``stealth validate`` (:func:`navmesh.clearance.check_body`).
    """
    radius = float(config["world.agent_radius"])
    half = level.cell_size / 2
    if not radius < half:
        raise ConfigError(
            f"world.agent_radius = {radius:g}: must be below half the cell size of level "
            f"{level.name!r} ({half:g}), or an agent cannot pass a one-cell corridor")
    check_body(level, radius)  # and reach the whole walkable area: validate's check too


def _toml(value: Any) -> str:
    """A default as a config file writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return f'"{value}"' if isinstance(value, str) else repr(value)


def markdown_table(defaults: Mapping[str, Any]) -> str:
    """Every key of ``defaults`` with its default and its allowed values, as a Markdown
    table (``docs/config.md``: with the defaults' one source in code, the doc lists them)."""
    lines = ["| key | default | allowed values |", "|---|---|---|"]
    for key, default in defaults.items():
        bound = bound_of(key)
        if isinstance(bound, Range):
            text = ("whole number in " if bound.integer else "") + bound.describe()
        else:
            text = "one of " + bound.describe()
        if key == "world.agent_radius":
            text += ", and below half the level's cell size"
        lines.append(f"| `{key}` | `{_toml(default)}` | {text} |")
    return "\n".join(lines) + "\n"
