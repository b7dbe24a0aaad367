"""Trial configuration: documented defaults plus ``key=value`` overrides.

Every default is written once: a key of a parameter dataclass (a registered guard mode's
or player policy's, the stimuli's, the team rules') has its field default
(:func:`game.schema.parameter_defaults`); the keys no dataclass holds — ``[world]``,
``[scenario.*]``, ``[zones]``, ``[metrics]``, the ``enabled`` switches — are in
``game/defaults.toml``, whose empty tables say where a section's parameters come from and
so where its keys stand in the config.

Keys are dotted paths into the TOML tables (``world.view_range``, ``pf.rho``,
``scenario.capture.view_range_scale``). An override must name an existing key, is
converted to that key's type and must lie in the key's declared bound (``game.schema``,
listed in docs/config.md): :func:`check_value` is the one check of every ``--set``, preset
``[set]`` and config value, so a typo or a wrong value fails loudly before anything runs
instead of running a sweep with a silently ignored or crashing setting. Every trial records the config it ran with and its
hash.
"""

from __future__ import annotations

import functools
import hashlib
import json
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ai.bounds import FLAG, Bound, Range
from game.errors import ConfigError

from .schema import (bound_of, check_sections, parameter_defaults, parameter_sections,
                     registered_params)

DEFAULTS_PATH = Path(__file__).with_name("defaults.toml")

#: keys that change what is measured, never what happens (SPEC §11): out of
#: :meth:`Config.hash` while at their default
HASH_NEUTRAL_PREFIX = "metrics."

#: keys that choose how a trial is computed, never what it gives (SPEC §12: the engines give
#: equal results trial for trial): out of :meth:`Config.hash` at any value and out of
#: :attr:`game.trial.TrialSpec.key`, so a stored trial resumes or re-runs on either engine
ENGINE_KEY = "world.engine"
IDENTITY_NEUTRAL: frozenset[str] = frozenset({ENGINE_KEY})

#: keys added after stores were written whose default is the older behaviour: out of
#: :meth:`Config.hash` while at their default, so those stores keep their hash and resume
NEUTRAL_AT_DEFAULT: frozenset[str] = frozenset({"world.attack_needs_awareness",
                                                "world.attack_memory", "world.sneak_factor",
                                                "awareness.gait_sneak",
                                                # SPEC §12's readings (their keys read only
                                                # under staleness.model = "alenezi" /
                                                # player.safetygraph_goal = "local")
                                                "staleness.staleness_weight",
                                                "staleness.separation_weight",
                                                "player.safetygraph_hops"})

#: the table of ``stealth play``'s own defaults (:func:`play_defaults`), no section of keys
PLAY_TABLE = "play"


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(_flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


@functools.cache
def _file_tables() -> dict[str, Any]:
    with DEFAULTS_PATH.open("rb") as handle:
        return tomllib.load(handle)


@functools.cache
def _defaults(registered: Any) -> dict[str, Any]:
    """The file's values with every parameter section's defaults at its table's place
    (sections the file does not name, a registered mode's, at the end)."""
    tables = {k: v for k, v in _file_tables().items() if k != PLAY_TABLE}
    values: dict[str, Any] = {}
    for name in [*tables, *(s for s in parameter_sections() if s not in tables)]:
        table = tables.get(name, {})
        values.update(_flatten(table, name + "."))
        values.update({f"{name}.{k}": v for k, v in parameter_defaults(name).items()})
    return values


def _default_values() -> dict[str, Any]:
    """Every config key's default (read-only: shared), for the guard modes and player
    policies registered now."""
    return _defaults(registered_params())


def play_defaults() -> dict[str, Any]:
    """``stealth play``'s own defaults: the ``[play.X]`` tables of defaults.toml as the
    ``X.*`` keys they set (checked like any override), applied before the player's ``--set``.

    >>> play_defaults()["world.attack_needs_awareness"], Config.defaults()["world.attack_needs_awareness"]
    (True, False)
    """
    table = _file_tables().get(PLAY_TABLE, {})
    return {key: check_value(key, value) for key, value in _flatten(table).items()}


_WORDS = {"true": True, "1": True, "yes": True, "false": False, "0": False, "no": False}


def _parse(key: str, text: str, bound: Bound) -> Any:
    """A ``--set`` string as the type its key declares (a number, a whole number, a switch:
    true / false, and the shell's yes / no and 1 / 0, which the message names too)."""
    if isinstance(bound, Range):
        try:
            return int(text) if bound.integer else float(text)
        except ValueError:
            what = "a whole number" if bound.integer else "a number"
            raise ConfigError(f"{key}: expected {what} in {bound.describe()}, got {text!r}") from None
    if bound == FLAG:
        word = text.strip().lower()
        if word not in _WORDS:
            raise ConfigError(f"{key}: expected true or false (or yes / no, 1 / 0), got {text!r}")
        return _WORDS[word]
    return text


def check_value(key: str, value: Any) -> Any:
    """``value`` as config key ``key`` holds it, or a one-line :class:`ConfigError`.

    The key must exist; a string (``--set``) is parsed as the key's type; the value must lie
    in the key's declared bound (:func:`game.schema.bound_of`): NaN, infinities, a value out
    of range, a fraction for a whole-number key all fail, naming the key, the value and the
    allowed values. Float keys give floats (``6`` -> ``6.0``), whole-number keys ints.

    >>> check_value("world.view_range", "6"), check_value("world.guards", 2.0)
    (6.0, 2)
    >>> check_value("pf.rho", 1.5)
    Traceback (most recent call last):
    ...
    game.errors.ConfigError: pf.rho = 1.5: must be in (0, 1]
    """
    defaults = _default_values()
    if key not in defaults:
        near = [k for k in defaults if k.split(".")[-1] == key.split(".")[-1]]
        hint = f" (did you mean {near[0]}?)" if near else ""
        raise ConfigError(f"{key}: unknown config key{hint}")
    bound = bound_of(key)
    if isinstance(value, str):
        value = _parse(key, value, bound)
    problem = bound.problem(value)
    if problem is not None:
        raise ConfigError(f"{key} = {_show(value)}: {problem}")
    if isinstance(bound, Range):
        return int(value) if bound.integer else float(value)
    return value


def _show(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, str) else str(value)


def parse_overrides(items: Iterable[str]) -> list[tuple[str, str]]:
    """``["world.view_range=6", ...]`` as ``[("world.view_range", "6"), ...]`` (unchecked)."""
    pairs = []
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise ConfigError(f"--set {item!r}: expected key=value")
        pairs.append((key.strip(), value.strip()))
    return pairs


class Config:
    """An immutable flat mapping of dotted keys to values.

    >>> cfg = Config.load(["world.view_range=6"])
    >>> cfg["world.view_range"], cfg.section("pf")["rho"]
    (6.0, 0.95)
    """

    def __init__(self, values: Mapping[str, Any]) -> None:
        self._values = dict(values)
        #: section name -> its keys (the mapping is immutable, so each is found once)
        self._sections: dict[str, dict[str, Any]] = {}

    @classmethod
    def defaults(cls) -> Config:
        return cls(_default_values())

    @classmethod
    def for_play(cls, overrides: Iterable[str] | Mapping[str, Any] = ()) -> Config:
        """The config of a ``stealth play`` game: :func:`play_defaults`, then ``overrides``."""
        return cls.load(play_defaults()).with_overrides(overrides)

    @classmethod
    def load(cls, overrides: Iterable[str] | Mapping[str, Any] = ()) -> Config:
        """The defaults with ``overrides`` (``"key=value"`` strings or a mapping) applied."""
        return cls.defaults().with_overrides(overrides)

    def with_overrides(self, overrides: Iterable[str] | Mapping[str, Any]) -> Config:
        pairs = list(overrides.items()) if isinstance(overrides, Mapping) else parse_overrides(overrides)
        values = dict(self._values)
        for key, value in pairs:
            values[key] = check_value(key, value)
        check_sections(values)
        return Config(values)

    def __getitem__(self, key: str) -> Any:
        return self._values[key]

    def section(self, name: str) -> dict[str, Any]:
        """The keys directly under table ``name`` (not nested tables), prefix stripped."""
        found = self._sections.get(name)
        if found is None:
            prefix = name + "."
            found = self._sections[name] = {
                k[len(prefix):]: v
                for k, v in self._values.items()
                if k.startswith(prefix) and "." not in k[len(prefix):]
            }
        return dict(found)  # the caller's own copy

    def as_dict(self) -> dict[str, Any]:
        return dict(self._values)

    def hash(self) -> str:
        """A short stable digest of every value: equal configs, equal hashes, any process.

        A ``[metrics]`` key (what is measured, never what happens) at its default is left
        out, so a store written before the section existed keeps its hash and resumes (so is
        a :data:`NEUTRAL_AT_DEFAULT` key at its default); an
        :data:`IDENTITY_NEUTRAL` key (``world.engine``: how, not what) is left out at any
        value, so the same design has one hash on either engine.
        """
        defaults = _default_values()
        values = {k: v for k, v in self._values.items()
                  if k not in IDENTITY_NEUTRAL
                  and not ((k.startswith(HASH_NEUTRAL_PREFIX) or k in NEUTRAL_AT_DEFAULT)
                           and defaults.get(k) == v)}
        canonical = json.dumps(values, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(canonical.encode()).hexdigest()[:16]
