"""Trial configuration: one TOML file of documented defaults plus ``key=value`` overrides.

Keys are dotted paths into the TOML tables (``world.view_range``, ``pf.rho``,
``scenario.capture.view_range_scale``). An override must name an existing key and is
converted to that key's type, so a typo or a wrong value fails loudly instead of running a
sweep with a silently ignored setting. Every trial records the config it ran with and its
hash.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from game.errors import ConfigError

DEFAULTS_PATH = Path(__file__).with_name("defaults.toml")


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(_flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


def _coerce(key: str, text: Any, like: Any) -> Any:
    """Convert an override to the type of the default it replaces."""
    if not isinstance(text, str):
        value = text
    elif isinstance(like, bool):
        lowered = text.strip().lower()
        if lowered not in ("true", "false", "1", "0", "yes", "no"):
            raise ConfigError(f"{key}: expected true or false, got {text!r}")
        value = lowered in ("true", "1", "yes")
    elif isinstance(like, int):
        try:
            value = int(text)
        except ValueError:
            raise ConfigError(f"{key}: expected a whole number, got {text!r}") from None
    elif isinstance(like, float):
        try:
            value = float(text)
        except ValueError:
            raise ConfigError(f"{key}: expected a number, got {text!r}") from None
        if value != value or value in (float("inf"), float("-inf")):
            raise ConfigError(f"{key}: expected a finite number, got {text!r}")
    else:
        value = text
    if isinstance(like, bool) != isinstance(value, bool) or (
        isinstance(like, (int, float)) and not isinstance(value, (int, float))
    ):
        raise ConfigError(f"{key}: expected {type(like).__name__}, got {value!r}")
    if isinstance(like, float) and isinstance(value, int):
        value = float(value)
    return value


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

    @classmethod
    def defaults(cls) -> Config:
        with DEFAULTS_PATH.open("rb") as handle:
            return cls(_flatten(tomllib.load(handle)))

    @classmethod
    def load(cls, overrides: Iterable[str] | Mapping[str, Any] = ()) -> Config:
        """The defaults with ``overrides`` (``"key=value"`` strings or a mapping) applied."""
        return cls.defaults().with_overrides(overrides)

    def with_overrides(self, overrides: Iterable[str] | Mapping[str, Any]) -> Config:
        pairs = list(overrides.items()) if isinstance(overrides, Mapping) else parse_overrides(overrides)
        values = dict(self._values)
        for key, value in pairs:
            if key not in values:
                near = [k for k in values if k.split(".")[-1] == key.split(".")[-1]]
                hint = f" (did you mean {near[0]}?)" if near else ""
                raise ConfigError(f"{key}: unknown config key{hint}")
            values[key] = _coerce(key, value, values[key])
        return Config(values)

    def __getitem__(self, key: str) -> Any:
        return self._values[key]

    def section(self, name: str) -> dict[str, Any]:
        """The keys directly under table ``name`` (not nested tables), prefix stripped."""
        prefix = name + "."
        return {
            k[len(prefix):]: v
            for k, v in self._values.items()
            if k.startswith(prefix) and "." not in k[len(prefix):]
        }

    def as_dict(self) -> dict[str, Any]:
        return dict(self._values)

    def hash(self) -> str:
        """A short stable digest of every value: equal configs, equal hashes, any process."""
        canonical = json.dumps(self._values, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(canonical.encode()).hexdigest()[:16]
