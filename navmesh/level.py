"""Level files: reading them, choosing their format, and the level cache (SPEC §8).

A level is one JSON object (``"format": "stealth-level/1"``, :mod:`navmesh.level_format`:
the :class:`Level` it becomes and every check) or a Tiled map (:mod:`navmesh.tiled`, read
into the same structure). This module reads the file, dispatches on its format and keeps
the one per-process level cache; it re-exports the format's names, so
``from navmesh.level import Level, load_level, parse_level`` is the one import of a level.

Every problem with a file is reported as a :class:`LevelError` whose message is one line,
``"<file>: <field>: <problem>"``, so the command line can print it and exit cleanly
(the format's example is :mod:`navmesh.level_format`'s).
"""

from __future__ import annotations

import hashlib
import importlib.resources
import json
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

from navmesh.errors import LevelError
from navmesh.files import FileRefused, read_regular
from navmesh.level_fields import (
    MAX_CELLS,
    MAX_EXTENT,
    MIN_CELL_SIZE,
    MAX_FILE_BYTES,
    MAX_SPOTS,
    ZONE_KINDS,
    _fail,
    _looks_like_name,
    register_zone_kind,
    zone_kinds,
)
from navmesh.level_format import FORMAT, Level, parse_level
from navmesh.tiled_format import is_tiled_json, is_tiled_suffix, is_tiled_xml

__all__ = [
    "FORMAT",
    "MAX_FILE_BYTES",
    "MAX_SPOTS",
    "LEVELS_DIR",
    "MAX_CELLS",
    "ZONE_KINDS",
    "Level",
    "LevelError",
    "MISSIONS_DIR",
    "bundled_level_names",
    "mission_names",
    "cached_level",
    "load_level",
    "parse_level",
    "register_zone_kind",
    "resolve_level_path",
    "zone_kinds",
]


def _bundled_levels_dir() -> Path:
    """``assets/levels`` of a source checkout, else the copy installed as package data.

    The checkout wins so that a worktree on ``PYTHONPATH`` sees its own levels even while an
    editable install of another checkout is on the path; a wheel ships the same folder as
    the data package ``stealthfield_assets`` (pyproject ``package-dir``).
    """
    root = Path(__file__).resolve().parent.parent
    if (root / "pyproject.toml").is_file() and (root / "assets" / "levels").is_dir():
        return root / "assets" / "levels"
    try:
        return Path(str(importlib.resources.files("stealthfield_assets") / "levels"))
    except (ModuleNotFoundError, NotADirectoryError):  # no installed data package to read
        return root / "assets" / "levels"


LEVELS_DIR = _bundled_levels_dir()
"""Folder of the bundled levels (see :func:`_bundled_levels_dir`)."""

MISSIONS_DIR = LEVELS_DIR.parent / "missions"
"""Folder of the bundled missions: collect-and-escape levels for ``stealth play`` (stars
and an exit), named like a bundled level but in no preset or sweep."""


# --------------------------------------------------------------------------- loading


def bundled_level_names() -> list[str]:
    """Names of the levels shipped in ``assets/levels`` (file stems, sorted)."""
    return sorted(p.stem for p in LEVELS_DIR.glob("*.json"))


def mission_names() -> list[str]:
    """Names of the missions shipped in ``assets/missions`` (file stems, sorted)."""
    return sorted(p.stem for p in MISSIONS_DIR.glob("*.json"))


def resolve_level_path(path_or_name: str | Path) -> Path:
    """The file a level argument refers to: an existing file, else a bundled level name.

    A bare name without a folder or ``.json`` suffix (``"miami"``, case-insensitive) that is
    not an existing file is looked up in ``assets/levels``, then ``assets/missions``; an
    unknown bare name raises :class:`LevelError` listing the bundled names. Anything else is returned as a path
    (whether it exists is :func:`load_level`'s business).
    """
    path = Path(path_or_name)
    if path.is_file():
        return path
    text = str(path_or_name)
    if _looks_like_name(text):
        for folder in (LEVELS_DIR, MISSIONS_DIR):
            bundled = folder / f"{text.lower()}.json"
            if bundled.is_file():
                return bundled
        names = ", ".join(bundled_level_names() + mission_names()) or "none"
        raise LevelError(text, "file", f"no such file or bundled level (bundled levels: {names})")
    return path


def load_level(path_or_name: str | Path) -> Level:
    """Load and validate a level from a JSON file, a Tiled map or a bundled level name.

    A ``.tmj`` file, or a JSON file whose ``"type"`` is ``"map"``, is a Tiled map, read by
    :mod:`navmesh.tiled` into the same structure. Errors name the file as the caller gave
    it (a bundled level by its file name).
    """
    content = _read_level_file(path_or_name)
    return _parse_content(content)


def cached_level(path_or_name: str | Path) -> Level:
    """:func:`load_level`, memoised per process on the file's resolved path and content.

    The one level cache of the project: the file is read on every call (levels are a few
    kB) and its SHA-256 compared, so an edited file is parsed again — never a stale level —
    while repeated trials on an unchanged file share one :class:`Level` (and, through
    ``Level.digest``, one node graph).
    """
    return _cached_parse(_read_level_file(path_or_name))


@dataclass(frozen=True)
class _LevelFile:
    """A level file's bytes; equal (and hashed) by resolved path and SHA-256 of the bytes only."""

    resolved: str
    digest: str
    raw: bytes = field(compare=False, repr=False)
    path: Path = field(compare=False)
    source: str = field(compare=False)


def _read_level_file(path_or_name: str | Path) -> _LevelFile:
    path = resolve_level_path(path_or_name)
    source = str(path_or_name) if path == Path(path_or_name) else path.name
    raw = _read_bytes(path, source)
    return _LevelFile(str(path.resolve()), hashlib.sha256(raw).hexdigest(), raw, path, source)


def _parse_content(content: _LevelFile) -> Level:
    tiled = is_tiled_suffix(content.path) or is_tiled_xml(content.raw)
    if not tiled:
        data = _decode_json(content.raw, content.source)
        tiled = is_tiled_json(data)
    if tiled:
        from navmesh.tiled import load_tiled  # lazy: pytiled-parser only when a map is read

        return load_tiled(content.path, content.source, content.digest, content.raw)
    return parse_level(data, content.source, path=content.path, digest=content.digest)


_cached_parse = lru_cache(maxsize=32)(_parse_content)


def _read_bytes(path: Path, src: str) -> bytes:
    """Read a level file (a regular file of at most :data:`MAX_FILE_BYTES`); every failure
    becomes a one-line LevelError."""
    try:
        return read_regular(path, MAX_FILE_BYTES)
    except FileRefused as refused:
        _fail(src, "file", str(refused))
    except FileNotFoundError:
        _fail(src, "file", "no such file")
    except IsADirectoryError:
        _fail(src, "file", "is a directory, not a level file")
    except PermissionError:
        _fail(src, "file", "permission denied")
    except OSError as exc:
        _fail(src, "file", f"cannot read ({exc.strerror or exc})")


def _decode_json(raw: bytes, src: str) -> Any:
    """Decode a level file's bytes; every failure becomes a one-line LevelError."""
    if not raw.strip():
        _fail(src, "file", "is empty")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _fail(src, "file", f"not UTF-8 text (invalid byte at offset {exc.start})")
    try:
        # NaN/Infinity literals decode to floats and are rejected with their field name later.
        return json.loads(text, object_pairs_hook=_no_duplicate_keys)
    except _DuplicateKey as exc:
        _fail(src, exc.key, "duplicate key")
    except json.JSONDecodeError as exc:
        _fail(src, "json", f"not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}")
    except (ValueError, RecursionError) as exc:  # e.g. an integer with too many digits
        _fail(src, "json", f"not valid JSON: {exc}")


class _DuplicateKey(Exception):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    obj: dict[str, Any] = {}
    for key, value in pairs:
        if key in obj:
            raise _DuplicateKey(key)
        obj[key] = value
    return obj
