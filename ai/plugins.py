"""Plugin stimuli: loading ``FILE.py:NAME`` or an installed entry point, registering zone kinds."""

from __future__ import annotations

import importlib.util
import sys
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from navmesh.level import register_zone_kind

from .errors import StimulusError
from .installed import load_entry_point, plugin_code
from .stimulus import Measure, Stimulus, register_stimulus

#: importlib.metadata entry-point group under which installed packages register stimuli
ENTRY_POINT_GROUP = "stealthfield.stimuli"

StimulusFactory = Callable[[], Stimulus]


def _load_file(path: Path) -> Any:
    resolved = path.resolve()
    name = f"stealthfield_stimulus_{zlib.crc32(str(resolved).encode()):08x}"
    mtime = resolved.stat().st_mtime_ns
    cached = sys.modules.get(name)
    if cached is not None and getattr(cached, "__stealthfield_mtime__", None) == mtime:
        return cached
    spec = importlib.util.spec_from_file_location(name, resolved)
    if spec is None or spec.loader is None:
        raise StimulusError(f"{path}: not a Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        with plugin_code(f"{path}: cannot load", StimulusError):  # the user's file: one line
            spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    module.__stealthfield_mtime__ = mtime  # type: ignore[attr-defined]
    return module


def _entry_point(name: str) -> Any:
    from importlib.metadata import entry_points

    found = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == name]
    if not found:
        known = sorted(ep.name for ep in entry_points(group=ENTRY_POINT_GROUP))
        hint = f" (installed: {', '.join(known)})" if known else " (none installed)"
        raise StimulusError(
            f"{name}: expected FILE.py:NAME or the name of an installed "
            f"{ENTRY_POINT_GROUP} entry point{hint}"
        )
    return load_entry_point(found[0], StimulusError)


def load_stimulus(spec: str) -> StimulusFactory:
    """The factory of a plugin stimulus: ``"path/to/file.py:Name"`` or an entry-point name.

    ``Name`` must be a :class:`Stimulus` subclass that can be created with no arguments, or
    a function of no arguments returning a :class:`Stimulus`; installed packages register
    either under the ``stealthfield.stimuli`` entry-point group. The factory is called once
    here to check it, the zone kinds it declares (:attr:`Stimulus.zone_kinds`) are
    registered, so load plugins **before** the levels that use their zones, and its class
    is registered (:func:`~ai.stimulus.register_stimulus`), so load them before the config
    that sets their :attr:`~Stimulus.parameters`. Raises
    :class:`StimulusError` (one line) otherwise.
    """
    text = str(spec).strip()
    path_text, sep, attr = text.rpartition(":")
    if sep and path_text and (path_text.endswith(".py") or "/" in path_text or "\\" in path_text):
        path = Path(path_text)
        if not attr.isidentifier():
            raise StimulusError(f"{text}: {attr!r} is not a Python name")
        if not path.is_file():
            what = "not a regular file" if path.exists() else "no such file"  # a FIFO, a folder
            raise StimulusError(f"{text}: {what} {path_text}")
        module = _load_file(path)
        if not hasattr(module, attr):
            raise StimulusError(f"{text}: {path_text} defines no {attr!r}")
        obj = getattr(module, attr)
    elif sep:
        raise StimulusError(f"{text}: expected FILE.py:NAME")
    else:
        obj = _entry_point(text)
    if isinstance(obj, type) and not issubclass(obj, Stimulus):
        raise StimulusError(f"{text}: {obj.__name__} is not a subclass of ai.stimuli.Stimulus")
    if not callable(obj):
        raise StimulusError(f"{text}: not a Stimulus subclass or a factory function")
    try:
        probe = obj()
    except (Exception, SystemExit) as error:
        raise StimulusError(
            f"{text}: cannot be created with no arguments: {type(error).__name__}: {error}"
        ) from None
    if not isinstance(probe, Stimulus):
        raise StimulusError(f"{text}: returned {type(probe).__name__}, not a Stimulus")
    _register_zone_kinds(text, probe)
    if not isinstance(probe.measure, Measure):
        raise StimulusError(f"{text}: measure must be an ai.stimuli.Measure, "
                            f"got {type(probe.measure).__name__}")
    try:
        register_stimulus(type(probe))  # its names, and its parameters' config section
    except StimulusError as error:
        raise StimulusError(f"{text}: {error}") from None
    return obj


def _register_zone_kinds(text: str, probe: Stimulus) -> None:
    """Let levels use the zone kinds ``probe`` declares (before any level is parsed)."""
    kinds = probe.zone_kinds
    if not isinstance(kinds, tuple) or not all(isinstance(k, str) for k in kinds):
        raise StimulusError(f"{text}: zone_kinds must be a tuple of strings, got {kinds!r}")
    for kind in kinds:
        try:
            register_zone_kind(kind)
        except ValueError as error:
            raise StimulusError(f"{text}: zone_kinds: {error}") from None
