"""``--config FILE.toml``: a file of config overrides in the dotted-key form of ``[set]``.

``sim``, ``run``, ``play`` and ``tune`` take one (SPEC §10); ``stealth tune`` writes its best
parameters as one (``best.toml``). Both nested tables (``[world] view_range = 6``) and quoted
dotted keys (``"world.view_range" = 6``) are read; every key and value is checked against
the defaults at once, so a bad file fails before anything runs.

>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "c.toml"
>>> write_config_file(path, {"world.view_range": 6.0, "pf.rho": 0.9}, "example")
>>> read_config_file(path)
{'pf.rho': 0.9, 'world.view_range': 6.0}
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from game.config import Config
from game.errors import ConfigError
from navmesh.files import FileRefused, read_regular

MAX_CONFIG_BYTES = 2**20
"""Largest ``--config`` file read (1 MiB; a tuned best.toml is a few hundred bytes)."""

__all__ = ["flatten", "read_config_file", "toml_value", "write_config_file"]


def flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested TOML tables as dotted keys: ``{"pf": {"rho": 0.9}}`` -> ``{"pf.rho": 0.9}``.

    A key given twice (``"pf.rho" = 0.9`` beside ``[pf] rho = 0.8``) is a ConfigError, not
    one value silently dropped; so is an empty table inside (``[metrics] coverage = {}``, or
    a ``[world]`` header with nothing under it), which would set nothing without a word.

    >>> flatten({"pf.rho": 0.9, "pf": {"rho": 0.8}})
    Traceback (most recent call last):
    ...
    game.errors.ConfigError: pf.rho: given twice (as a dotted key and inside a table); keep one
    """
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, Mapping) and not value:
            raise ConfigError(f"{prefix}{key}: an empty table sets nothing; give a value "
                              "(key = value) or remove it")
        inner = flatten(value, f"{prefix}{key}.") if isinstance(value, Mapping) else {
            f"{prefix}{key}": value}
        for name, item in inner.items():
            if name in flat:
                raise ConfigError(f"{name}: given twice (as a dotted key and inside a table); "
                                  "keep one")
            flat[name] = item
    return flat


def read_config_file(path: str | Path) -> dict[str, Any]:
    """The overrides of a ``--config`` file, sorted by key, each value checked and coerced."""
    where = f"--config {path}"
    try:
        data = tomllib.loads(read_regular(path, MAX_CONFIG_BYTES).decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{where}: no such file") from None
    except FileRefused as refused:  # a FIFO, a device, a file too large to be a config
        raise ConfigError(f"{where}: {refused}") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ConfigError(f"{where}: cannot read ({error})") from None
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"{where}: not valid TOML ({error})") from None
    try:
        flat = flatten(data)
        config = Config.load(flat)
    except ConfigError as error:
        raise ConfigError(f"{where}: {error}") from None
    return {key: config[key] for key in sorted(flat)}


def toml_value(value: Any) -> str:
    """A config value as TOML text (booleans, whole numbers, floats, strings)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    return json.dumps(str(value))


def write_config_file(path: str | Path, values: Mapping[str, Any], comment: str = "") -> None:
    """Write ``values`` as a ``--config`` file (quoted dotted keys, one per line)."""
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"{json.dumps(key)} = {toml_value(value)}" for key, value in sorted(values.items())]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
