"""Presets: experiment designs in TOML, validated completely before anything runs.

A **preset** is a TOML file (``headless/presets/NAME.toml`` or the user's own) naming the
levels, abstractions, guard modes, player policies, scenarios and seeds of a full factorial
design, an optional ``root_seed``, an optional ``[set]`` table of config overrides, an
optional ``[factors]`` table (a config key → the list of values the design crosses, SPEC
§10) and a one-line ``description``. :func:`load_preset` turns one into a :class:`Preset` whose
:meth:`Preset.specs` lists every trial in the sweep's order; every mistake is a one-line
:class:`~headless.errors.PresetError` naming the file and field.

>>> [name for name, _ in bundled_presets()][:2]
['paper', 'paper-calibrated']
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from game.config import ENGINE_KEY
from game.config_file import flatten
from game.trial import TrialSpec
from navmesh.files import FileRefused, read_regular

from .errors import PresetError

__all__ = [
    "MAX_PRESET_BYTES", "MAX_TRIALS", "PRESETS_DIR", "Preset", "bundled_preset_names",
    "bundled_presets", "check_setting", "load_preset", "parse_preset",
]

PRESETS_DIR = Path(__file__).resolve().parent / "presets"
"""Folder of the bundled presets."""

MAX_TRIALS = 1_000_000
"""Most trials one design may have (100 x the paper preset; about 8 h on 2 cores)."""

MAX_PRESET_BYTES = 2**20
"""Largest preset file read (1 MiB)."""

_LIST_FIELDS = ("levels", "abstractions", "guards", "players", "scenarios")
_ALLOWED_KEYS = (*_LIST_FIELDS, "seeds", "root_seed", "set", "factors", "stimuli", "description")


@dataclass(frozen=True)
class Preset:
    """A validated experiment design (see the module docstring and docs/experiments.md)."""

    name: str
    source: str
    text: str
    levels: tuple[str, ...]
    level_names: tuple[str, ...]
    abstractions: tuple[str, ...]
    guards: tuple[str, ...]
    players: tuple[str, ...]
    scenarios: tuple[str, ...]
    seeds: tuple[int, ...]
    root_seed: int = 0
    overrides: tuple[tuple[str, Any], ...] = ()
    description: str = ""
    config_hash: str = ""
    #: every config value the sweep's trials run with (defaults + the preset's [set])
    config: Mapping[str, Any] = field(default_factory=dict)
    #: plugin stimuli of every trial (``stimuli = ["file.py:Name"]``; paths made absolute)
    stimuli: tuple[str, ...] = ()
    #: ``(key, levels)`` of every factor, sorted by key (the design crosses all of them)
    factors: tuple[tuple[str, tuple[Any, ...]], ...] = ()
    #: ``world.engine`` the sweep runs the trials on (SPEC §12); no part of the design, the
    #: overrides, the trials' keys or the config hash: the engines give equal results
    engine: str = "auto"

    @property
    def n_trials(self) -> int:
        """Number of trials of the full design."""
        n = len(self.seeds)
        for name in _LIST_FIELDS:
            n *= len(getattr(self, name))
        for _, levels in self.factors:
            n *= len(levels)
        return n

    def factor_points(self) -> list[tuple[tuple[str, Any], ...]]:
        """Every combination of factor levels (one empty combination without factors)."""
        points: list[tuple[tuple[str, Any], ...]] = [()]
        for key, levels in self.factors:
            points = [(*point, (key, value)) for point in points for value in levels]
        return points

    def specs(self) -> list[TrialSpec]:
        """Every trial of the design, in the sweep's deterministic order (seeds outermost,
        factor levels innermost)."""
        points = self.factor_points()
        return [
            TrialSpec(level=level, abstraction=abstraction, guards=guards, player=player,
                      scenario=scenario, seed=seed, overrides=self.overrides,
                      root_seed=self.root_seed, stimuli=self.stimuli, factors=point)
            for seed in self.seeds
            for level in self.levels
            for abstraction in self.abstractions
            for guards in self.guards
            for player in self.players
            for scenario in self.scenarios
            for point in points
        ]

    def with_seeds(self, count: int) -> Preset:
        """The same design with seeds ``0 … count-1`` (``stealth run --seeds N``)."""
        if count < 1:
            raise PresetError(f"--seeds: must be at least 1, got {count}")
        if count * (self.n_trials // len(self.seeds)) > MAX_TRIALS:
            raise PresetError(f"--seeds {count}: the design would have more than "
                              f"{MAX_TRIALS} trials")
        return replace(self, seeds=tuple(range(count)))

    def design(self) -> dict[str, Any]:
        """The design as JSON-able data (stored in the results' ``meta`` table)."""
        return {
            "levels": list(self.levels),
            "level_names": list(self.level_names),
            "abstractions": list(self.abstractions),
            "guards": list(self.guards),
            "players": list(self.players),
            "scenarios": list(self.scenarios),
            "seeds": list(self.seeds),
            "root_seed": self.root_seed,
            "set": {k: v for k, v in self.overrides},
            # each only when there are any, so the designs of existing stores stay equal
            **({"stimuli": list(self.stimuli)} if self.stimuli else {}),
            **({"factors": {k: list(v) for k, v in self.factors}} if self.factors else {}),
        }


def bundled_preset_names() -> list[str]:
    """Names of the presets shipped in ``headless/presets`` (sorted)."""
    return sorted(p.stem for p in PRESETS_DIR.glob("*.toml"))


def _preset_path(name_or_path: str) -> tuple[Path, str]:
    """The file a ``--preset`` argument means and how to name it in messages."""
    path = Path(name_or_path)
    if path.is_file():
        return path, str(name_or_path)
    bare = "/" not in name_or_path and "\\" not in name_or_path and not name_or_path.endswith(
        ".toml")
    if bare:
        bundled = PRESETS_DIR / f"{name_or_path}.toml"
        if bundled.is_file():
            return bundled, f"presets/{bundled.name}"
        names = ", ".join(bundled_preset_names()) or "none"
        raise PresetError(f"--preset {name_or_path}: no such file or bundled preset "
                        f"(bundled presets: {names})")
    if path.is_dir():
        raise PresetError(f"{name_or_path}: is a directory, not a preset file")
    if path.exists():  # a FIFO, a device: load_preset's read refuses it with one line
        return path, str(name_or_path)
    raise PresetError(f"{name_or_path}: no such preset file")


def load_preset(name_or_path: str, extra: Mapping[str, Any] | None = None) -> Preset:
    """Load and fully validate a bundled preset (by name) or a preset file (by path).

    Every problem raises :class:`~headless.errors.PresetError` with one line naming the file and
    the field: unknown keys, modes, policies, abstractions or scenarios, levels that do not
    load, empty lists or no seeds, bad ``[set]`` overrides or factors. ``extra`` overrides
    (a ``--config`` file's) are applied after the preset's ``[set]``.
    """
    path, src = _preset_path(name_or_path)
    try:
        text = read_regular(path, MAX_PRESET_BYTES).decode("utf-8")
    except FileRefused as refused:
        raise PresetError(f"{src}: file: {refused}") from None
    except (OSError, UnicodeDecodeError) as error:
        raise PresetError(f"{src}: file: cannot read ({error})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise PresetError(f"{src}: toml: not valid TOML ({error})") from None
    return parse_preset(data, src, name=path.stem, text=text, base=path.resolve().parent,
                        extra=extra)


def _fail(src: str, field: str, problem: str) -> PresetError:
    return PresetError(f"{src}: {field}: {' '.join(problem.splitlines())}")


def check_setting(key: str, value: Any) -> Any:
    """A config value as the trials will run with it, or :class:`~game.errors.ConfigError`.

    The one check every ``[set]`` value, factor level and ``stealth tune`` search bound goes
    through: the key must exist and the value lie in its declared range
    (:func:`game.config.check_value`, through ``Config.load``).
    """
    from game.config import Config

    return Config.load({key: value})[key]


def _factors(data: Mapping[str, Any], src: str, fixed: Mapping[str, Any],
             ) -> tuple[tuple[str, tuple[Any, ...]], ...]:
    """The ``[factors]`` table: each dotted config key → a non-empty list of distinct values."""
    from game.errors import ConfigError

    table = data.get("factors", {})
    if not isinstance(table, Mapping):
        raise _fail(src, "factors", "expected a table: config key = [values]")
    try:
        flat = flatten(table)
    except ConfigError as error:
        raise _fail(src, "factors", str(error)) from None
    factors = []
    for key, values in sorted(flat.items()):
        where = f"factors.{key}"
        if key in fixed:
            raise _fail(src, where, "is also in [set]: a key is either fixed or a factor")
        if not isinstance(values, list) or not values:
            raise _fail(src, where, f"expected a non-empty list of values, got {values!r}")
        levels = []
        for value in values:
            try:
                levels.append(check_setting(key, value))
            except ConfigError as error:
                raise _fail(src, where, str(error)) from None
        if len(set(map(repr, levels))) != len(levels):
            raise _fail(src, where, "a value is listed twice")
        factors.append((key, tuple(levels)))
    return tuple(factors)


def _names(data: Mapping[str, Any], key: str, src: str, allowed: Sequence[str] | None) -> list[str]:
    """A non-empty list of distinct strings, each in ``allowed`` when given."""
    if key not in data:
        raise _fail(src, key, "missing required key")
    value = data[key]
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(src, key, f"expected a list of names, got {value!r}")
    if not value:
        raise _fail(src, key, "empty list: the design would have no trials")
    seen = set()
    for v in value:
        if allowed is not None and v not in allowed:
            raise _fail(src, key, f"unknown value {v!r} (choose from {', '.join(allowed)})")
        if v in seen:
            raise _fail(src, key, f"{v!r} is listed twice")
        seen.add(v)
    return list(value)


def _seeds(data: Mapping[str, Any], src: str) -> tuple[int, ...]:
    from game.schema import SEED

    if "seeds" not in data:
        raise _fail(src, "seeds", "missing required key (a count, or a list of seeds)")
    value = data["seeds"]
    if isinstance(value, int) and not isinstance(value, bool):
        if value <= 0:
            raise _fail(src, "seeds", f"must be at least 1, got {value}: the design would "
                                      "have no trials")
        if value > MAX_TRIALS:
            raise _fail(src, "seeds", f"{value} seeds: more than the limit of {MAX_TRIALS} "
                                      "trials of a design")
        return tuple(range(value))
    if isinstance(value, list):
        if not value:
            raise _fail(src, "seeds", "empty list: the design would have no trials")
        for seed in value:
            if isinstance(seed, bool) or not isinstance(seed, int) or SEED.problem(seed):
                raise _fail(src, "seeds", f"{seed!r}: a seed {SEED.problem(seed)}")
        if len(set(value)) != len(value):
            raise _fail(src, "seeds", "a seed is listed twice")
        return tuple(value)
    raise _fail(src, "seeds", f"expected a count or a list of seeds, got {value!r}")


def _level_ref(name: str, base: Path | None) -> str:
    """A bundled name stays a name; a path is made absolute (relative to the preset file)."""
    bare = "/" not in name and "\\" not in name and not name.lower().endswith((".json", ".tmj"))
    if bare:
        return name
    path = Path(name).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    return str(path.resolve())


def _stimuli(data: Mapping[str, Any], src: str, base: Path | None) -> tuple[str, ...]:
    """The ``stimuli`` list, each plugin loaded now (which registers its zone kinds);
    a ``FILE.py:NAME`` path is made absolute, relative to the preset file."""
    from ai.errors import StimulusError
    from ai.stimuli import load_stimulus

    value = data.get("stimuli", [])
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(src, "stimuli", f"expected a list of FILE.py:NAME or entry-point names, "
                                    f"got {value!r}")
    refs = []
    for text in value:
        path_text, sep, attr = text.rpartition(":")
        ref = text
        if sep and path_text.endswith(".py"):
            path = Path(path_text).expanduser()
            if not path.is_absolute() and base is not None:
                path = base / path
            ref = f"{path.resolve()}:{attr}"
        try:
            load_stimulus(ref)
        except StimulusError as error:
            raise _fail(src, "stimuli", str(error)) from None
        if ref in refs:
            raise _fail(src, "stimuli", f"{text!r} is listed twice")
        refs.append(ref)
    return tuple(refs)


def parse_preset(
    data: Mapping[str, Any],
    src: str = "<preset>",
    *,
    name: str = "preset",
    text: str = "",
    base: Path | None = None,
    extra: Mapping[str, Any] | None = None,
) -> Preset:
    """Validate decoded preset data (see :func:`load_preset`); relative level paths are
    resolved against ``base`` (the preset file's folder); ``extra`` overrides the ``[set]``."""
    from ai import GUARD_MODES, PLAYER_POLICIES, guard_mode, player_policy
    from game.budget import check_design_steps
    from game.config import IDENTITY_NEUTRAL, Config
    from game.errors import ConfigError
    from game.schema import SEED, check_level
    from game.scenarios import SCENARIOS
    from navmesh.errors import LevelError
    from navmesh.graph import ABSTRACTIONS, graph_for
    from navmesh.level import load_level

    for key in data:
        if key not in _ALLOWED_KEYS:
            raise _fail(src, str(key), f"unknown key (allowed keys: {', '.join(_ALLOWED_KEYS)})")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise _fail(src, "description", "expected a string")
    abstractions = _names(data, "abstractions", src, ABSTRACTIONS)
    guards = _names(data, "guards", src, list(GUARD_MODES))
    players = _names(data, "players", src, list(PLAYER_POLICIES))
    scenarios = _names(data, "scenarios", src, SCENARIOS)
    seeds = _seeds(data, src)
    levels_raw = data.get("levels")
    n_levels = len(levels_raw) if isinstance(levels_raw, list) else 1
    n_trials = len(seeds) * n_levels * math.prod(
        len(x) for x in (abstractions, guards, players, scenarios))
    if n_trials > MAX_TRIALS:
        raise _fail(src, "seeds", f"the design has {n_trials} trials, more than the limit of "
                                  f"{MAX_TRIALS}; use fewer seeds or split it into presets")
    root_seed = data.get("root_seed", 0)
    if isinstance(root_seed, bool) or not isinstance(root_seed, int) or SEED.problem(root_seed):
        raise _fail(src, "root_seed", f"{root_seed!r}: {SEED.problem(root_seed)}")

    # before the [set] and the levels, which may use their parameters and zone kinds
    stimuli = _stimuli(data, src, base)
    overrides_table = data.get("set", {})
    if not isinstance(overrides_table, Mapping):
        raise _fail(src, "set", "expected a table of config overrides (dotted keys)")
    try:
        flat = {**flatten(overrides_table), **(extra or {})}
        config = Config.load(flat)
    except ConfigError as error:
        raise _fail(src, "set", str(error)) from None
    # The values as the config coerced them (10 -> 10.0 for a float key), so equal settings
    # written differently give equal trial keys. The engine is how, not what: it stays out
    # of the trials' overrides and the design, so a store resumes on either engine.
    overrides = tuple((key, config[key]) for key in sorted(flat) if key not in IDENTITY_NEUTRAL)
    factors = _factors(data, src, flat)
    engine = str(config[ENGINE_KEY])
    for key, levels in factors:
        if key == ENGINE_KEY:
            if len(levels) > 1:
                raise _fail(src, f"factors.{key}", "the engines give equal results trial for "
                            "trial, so a factor over them would run every trial twice under "
                            "one key; name one engine (in [set])")
            engine = str(levels[0])
    factors = tuple((key, levels) for key, levels in factors if key not in IDENTITY_NEUTRAL)
    if engine != config[ENGINE_KEY]:
        config = config.with_overrides({ENGINE_KEY: engine})
    n_trials *= math.prod(len(levels) for _, levels in factors)
    if n_trials > MAX_TRIALS:
        raise _fail(src, "factors", f"the design has {n_trials} trials, more than the limit of "
                                    f"{MAX_TRIALS}; use fewer factor levels or seeds")
    try:
        check_design_steps(n_trials // math.prod(len(levels) for _, levels in factors),
                           config.as_dict(), factors)
    except ConfigError as error:
        raise _fail(src, "factors" if factors else "set", str(error)) from None

    for mode in guards:
        try:
            guard_mode(mode).build_for(config)
        except Exception as error:  # a mode that is listed but cannot be built
            raise _fail(src, "guards", f"{mode}: cannot be loaded "
                                       f"({type(error).__name__}: {error})") from None
    for policy in players:
        try:
            player_policy(policy).build_for(config)
        except Exception as error:
            raise _fail(src, "players", f"{policy}: cannot be loaded "
                                        f"({type(error).__name__}: {error})") from None

    level_names = _names(data, "levels", src, None)
    refs: list[str] = []
    names: list[str] = []
    for level_name in level_names:
        ref = _level_ref(level_name, base)
        try:
            level = load_level(ref)
        except LevelError as error:
            raise _fail(src, "levels", str(error)) from None
        if level.name in names:
            raise _fail(src, "levels", f"two levels are named {level.name!r}")
        try:
            check_level(config, level)
        except (ConfigError, LevelError) as error:
            raise _fail(src, "set", str(error)) from None
        for abstraction in abstractions:
            try:
                graph_for(level, abstraction)
            except LevelError as error:  # e.g. a navmesh past its bound: the level's own line
                raise _fail(src, "levels", str(error)) from None
            except Exception as error:
                raise _fail(src, "abstractions", f"{abstraction}: cannot build the graph of "
                            f"level {level.name!r} ({type(error).__name__}: {error})") from None
        refs.append(ref)
        names.append(level.name)

    return Preset(
        name=name, source=src, text=text, levels=tuple(refs), level_names=tuple(names),
        abstractions=tuple(abstractions), guards=tuple(guards), players=tuple(players),
        scenarios=tuple(scenarios), seeds=seeds, root_seed=root_seed, overrides=overrides,
        description=description, config_hash=config.hash(), config=config.as_dict(),
        stimuli=stimuli,
        factors=factors, engine=engine,
    )


def bundled_presets() -> list[tuple[str, str]]:
    """``(name, description)`` of every bundled preset, sorted by name (for ``stealth presets``).

    Only the description is read: listing does not validate or load the levels.
    """
    listed = []
    for name in bundled_preset_names():
        try:
            data = tomllib.loads((PRESETS_DIR / f"{name}.toml").read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            data = {}
        description = data.get("description", "")
        listed.append((name, description if isinstance(description, str) else ""))
    return listed
