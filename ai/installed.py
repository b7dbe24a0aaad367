"""Installed plugins: packages that register guard modes and player policies through
``importlib.metadata`` entry points, imported once per process.

A package declares, in its ``pyproject.toml``::

    [project.entry-points."stealthfield.guard_modes"]
    patrol = "mypkg.patrol"            # a module whose import registers the mode
    # or "mypkg.patrol:register"       # a function of no arguments that registers it

The registry (:data:`ai.GUARD_MODES`, :data:`ai.PLAYER_POLICIES`) calls
:func:`load_installed` before its first read, so every process — ``stealth``, a sweep's
worker, a notebook — sees the installed modes without importing them by hand. The stimuli's
entry points (``stealthfield.stimuli``, :mod:`ai.plugins`) share :func:`load_entry_point`.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, redirect_stdout
from types import ModuleType
from typing import TYPE_CHECKING, Any

from .errors import PluginError, StealthError

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

#: entry-point groups whose entries register guard modes and player policies when loaded
GROUPS = ("stealthfield.guard_modes", "stealthfield.player_policies")

_loaded = False


@contextmanager
def plugin_code(what: str, error: type[StealthError] = PluginError) -> Iterator[None]:
    """Run a plugin's code (its import, its registering function): what it prints goes to
    stderr, so ``--json`` keeps stdout one JSON document; whatever it raises — ``sys.exit()``
    and other ``BaseException`` subclasses too — is ``error``, one line starting with
    ``what``. Only ``KeyboardInterrupt`` passes, as a Ctrl-C during the import is one."""
    try:
        with redirect_stdout(sys.stderr):
            yield
    except KeyboardInterrupt:
        raise
    except StealthError as failure:  # a registration refused: its own line
        raise error(f"{what}: {failure}") from None
    except SystemExit as exit_:  # the command must not end silently
        raise error(f"{what}: it called sys.exit({exit_.code!r})") from None
    except BaseException as failure:
        raise error(f"{what}: {type(failure).__name__}: {failure}") from None


def load_entry_point(ep: EntryPoint, error: type[StealthError] = PluginError) -> Any:
    """The object ``ep`` names; ``error`` (one line naming the entry point) if importing it
    fails, whatever the package raises (:func:`plugin_code`)."""
    with plugin_code(f"{ep.name}: cannot load entry point {ep.value!r} ({ep.group})", error):
        return ep.load()


def load_installed(tables: Mapping[str, Mapping[str, object]]) -> None:
    """Import every installed ``stealthfield.guard_modes`` / ``stealthfield.player_policies``
    entry point, once per process (later calls return at once, also after a failure, which
    raises :class:`~ai.errors.PluginError` the first time). No package installed: nothing.
    An entry point that registers a name already held (by another package, or by this
    process before the registry's first read) is a ``PluginError``: which one won would
    depend on the order the packages are found in. ``tables`` are the registrations by
    kind (``"guard mode"``: :data:`ai.GUARD_MODES`'s), read before and after each entry
    point."""
    global _loaded
    if _loaded:
        return
    _loaded = True  # first: the plugins' own registrations read the registry
    from importlib.metadata import entry_points

    for group in GROUPS:
        for ep in entry_points(group=group):
            held = _held(tables)
            obj = load_entry_point(ep)
            if not isinstance(obj, ModuleType):  # a module registered its modes on import
                if not callable(obj) or isinstance(obj, type):
                    raise PluginError(f"{ep.name}: entry point {ep.value!r} ({group}) names "
                                      "neither a module nor a function that registers")
                with plugin_code(f"{ep.name}: entry point {ep.value!r} ({group}) failed"):
                    obj()
            now = _held(tables)
            taken = [name for name, reg in held.items() if now.get(name) != reg]  # the same: fine
            if taken:
                kind, name = taken[0]
                raise PluginError(f"{ep.name}: entry point {ep.value!r} ({group}) registers "
                                  f"{kind} {name!r} again, which another package or this "
                                  "process registered first; one of them must use another name")


def _held(tables: Mapping[str, Mapping[str, object]]) -> dict[tuple[str, str], object]:
    """Every registration held now, by kind and name."""
    return {(kind, name): reg for kind, table in tables.items() for name, reg in table.items()}
