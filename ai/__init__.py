"""Guard AI and player policies: composite potential fields, baselines, stimuli.

Imports ``navmesh`` only (SPEC §1). Guard modes and player policies are **registered** here
by name, and a registration carries everything the rest of the house needs: how to build
the controller, its parameter dataclass and the config section those parameters live in
(the config's keys and defaults, ``game.schema``), its display and short names (Table 3,
figures, robustness), and its place (the number keys of ``stealth play``). The world, the
CLI, the sweep and the reports never import a concrete controller class or write a mode's
name again, so a new mode is one :func:`register_guard_mode` call in the module that
defines it (or in a test). Installed packages register theirs through the entry points
of :mod:`ai.installed`, imported at the registry's first read, so every process sees them:

>>> from ai.baselines import RandomWalkGuards
>>> register_guard_mode("random2", RandomWalkGuards, display="RandomWalk (copy)", short="R2")
>>> make_guard_ai("random2").mode, GUARD_MODES["random2"].section, GUARD_MODES["random2"].short
('random', 'random2', 'R2')
>>> unregister_guard_mode("random2")
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, MutableMapping
from dataclasses import dataclass
from functools import cached_property
from importlib import import_module
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from .errors import PluginError, UnknownNameError
from .view import Event, GuardAI, PlayerPolicy, WorldView

if TYPE_CHECKING:
    from .params import Params

T = TypeVar("T", GuardAI, PlayerPolicy)


def _resolve(ref: Any, name: str = "") -> Any:
    """``ref`` itself, or the object a lazy ``"module:attr"`` reference names; a reference
    that names nothing is a :class:`~ai.errors.PluginError` naming registration ``name``."""
    if isinstance(ref, str):
        module, _, attr = ref.partition(":")
        try:
            return getattr(import_module(module), attr)
        except (ImportError, AttributeError) as error:
            raise PluginError(f"{name}: cannot import {ref!r} "
                              f"({type(error).__name__}: {error})") from None
    return ref


@dataclass(frozen=True)
class Registration(Generic[T]):
    """One registered controller: how to build it, what it is tuned by, how it is named.

    ``factory`` is a class (or any callable taking the params mapping) or a lazy
    ``"module:attr"`` reference, imported the first time the name is built. ``params`` is
    its parameter dataclass (an :class:`ai.params.Params`, or a ``"module:attr"``
    reference; ``None``: it takes none): its fields are the config keys of ``section``,
    their defaults the config's defaults, its ``bounds`` their allowed values. ``display``
    is the name tables and figures print, ``short`` the figures' tick label and ``abbrev``
    the name in dense text (the robustness verdicts; default ``short``).
    """

    name: str
    factory: Callable[[Mapping[str, Any] | None], T] | str
    display: str
    section: str
    short: str
    abbrev: str
    params: type[Params] | str | None = None

    def build(self, params: Mapping[str, Any] | None = None) -> T:
        """A fresh controller with ``params``; :class:`~ai.errors.PluginError` if the factory
        returns no guard team controller or player policy."""
        factory: Callable[[Mapping[str, Any] | None], T] = _resolve(self.factory, self.name)
        made = factory(params)
        if not isinstance(made, (GuardAI, PlayerPolicy)):
            raise PluginError(f"{self.name}: its factory returned {type(made).__name__}, not "
                              "an ai.GuardAI or ai.PlayerPolicy")
        return made

    def build_for(self, config: Any) -> T:
        """A fresh controller with its section's values of ``config`` (anything with a
        ``section(name)`` mapping, e.g. a :class:`game.config.Config`)."""
        return self.build(config.section(self.section))

    def parameters(self) -> type[Params] | None:
        """The parameter dataclass (imported on first use), or None."""
        return self._parameters

    @cached_property
    def _parameters(self) -> type[Params] | None:
        return _resolve(self.params, self.name) if self.params is not None else None


class Registry(MutableMapping[str, Registration[T]]):
    """Registrations by command-line name, in registration order. Its first read imports
    the installed plugins (:func:`ai.installed.load_installed`: the
    ``stealthfield.guard_modes`` and ``stealthfield.player_policies`` entry points), so
    the CLI, the config, a sweep's workers and play all see an installed mode; writing
    (registering) imports nothing."""

    def __init__(self, what: str) -> None:
        self._entries: dict[str, Registration[T]] = {}
        self._what = what
        self._built_in: frozenset[str] = frozenset()

    def seal(self) -> None:
        """Fix the names registered so far as the built-in ones: no later registration (an
        installed package, a notebook) may replace them, because that would change what
        ``--guards pf`` and the ``paper`` preset run without a word."""
        self._built_in = frozenset(self._entries)

    def __getitem__(self, name: str) -> Registration[T]:
        _load_installed()
        return self._entries[name]

    def __iter__(self) -> Iterator[str]:
        _load_installed()
        return iter(list(self._entries))

    def __len__(self) -> int:
        _load_installed()
        return len(self._entries)

    def __setitem__(self, name: str, registration: Registration[T]) -> None:
        if name in self._built_in:
            raise ValueError(f"{name}: a built-in {self._what}; register yours under a name "
                             "of its own")
        self._entries[name] = registration

    def __delitem__(self, name: str) -> None:
        if name in self._built_in:
            raise ValueError(f"{name}: a built-in {self._what} stays registered")
        del self._entries[name]

    def held(self) -> dict[str, Registration[T]]:
        """The registrations made so far, without importing the installed plugins (what a
        registration is checked against, and what :func:`ai.installed.load_installed`
        compares before and after each entry point)."""
        return self._entries

    def discard(self, name: str) -> None:
        """Remove ``name`` if it is registered and not a built-in (tests, notebooks)."""
        if name not in self._built_in:
            self._entries.pop(name, None)


def _load_installed() -> None:
    from .installed import load_installed

    load_installed({"guard mode": GUARD_MODES.held(), "player policy": PLAYER_POLICIES.held()})


def registrations() -> list[Registration[Any]]:
    """Every registration: the guard modes', then the player policies'."""
    return [*GUARD_MODES.values(), *PLAYER_POLICIES.values()]


#: The guard mode and player policy a trial, ``stealth play`` and the environments take when
#: none is named (the paper's method against its first scripted player).
DEFAULT_GUARD_MODE = "pf"
DEFAULT_PLAYER_POLICY = "maxmin"

#: Registered guard modes by command-line name (SPEC §9 order: the order of play's keys).
GUARD_MODES: Registry[GuardAI] = Registry("guard mode")
#: Registered player policies by command-line name.
PLAYER_POLICIES: Registry[PlayerPolicy] = Registry("player policy")


def _registration(name: str, factory: Any, display: str | None, short: str | None,
                  abbrev: str | None, section: str,
                  params: type[Params] | str | None) -> Registration[Any]:
    """A registration with its names filled in. Refuses (``ValueError`` naming the argument)
    a name or section that is no word and a display, short or abbreviated name that is no
    short line (:mod:`navmesh.names`), a factory that is neither callable nor a
    ``"module:attr"`` reference, parameters that are no checked parameter class
    (:meth:`ai.params.Params.declaration_problem`) nor such a reference, and a section that
    another registration fills with another parameter class (one section, one set of keys).
    """
    _check_declaration(name, factory, display, short, abbrev, section, params)
    held_now: list[Registration[Any]] = [*GUARD_MODES.held().values(),
                                         *PLAYER_POLICIES.held().values()]  # loads nothing
    for other in held_now:
        held = other.parameters() if other.params is not None else None
        if (other.name != name and other.section == section and held is not None
                and params is not None and other.params != params
                and held is not _resolve(params, name)):
            raise ValueError(f"{name}: config section [{section}] already holds the parameters "
                             f"of {other.name!r} ({held.__name__})")
    display = display or name.title()
    short = short or display
    return Registration(name, factory, display, section, short, abbrev or short, params)


def _check_declaration(name: Any, factory: Any, display: Any, short: Any, abbrev: Any,
                       section: Any, params: Any) -> None:
    from navmesh.names import label_problem, name_problem

    problem = name_problem(name)
    if problem is not None:
        raise ValueError(f"name {problem}")
    for what, value, check in (("section", section, name_problem),
                               ("display", display, label_problem),
                               ("short", short, label_problem), ("abbrev", abbrev, label_problem)):
        problem = None if value is None else check(value)
        if problem is not None:
            raise ValueError(f"{name}: {what} {problem}")
    if not (callable(factory) or _is_reference(factory)):
        raise ValueError(f"{name}: factory must be callable or a 'module:attr' reference, "
                         f"got {factory!r:.80}")
    if params is not None and not _is_reference(params):
        from .params import Params

        problem = Params.declaration_problem(params)
        if problem is not None:
            raise ValueError(f"{name}: params {problem}")


def _is_reference(ref: Any) -> bool:
    """Whether ``ref`` is a lazy ``"module:attr"`` reference (resolved on first use)."""
    if not isinstance(ref, str):
        return False
    module, sep, attr = ref.partition(":")
    return bool(sep) and attr.isidentifier() and all(p.isidentifier() for p in module.split("."))


def register_guard_mode(name: str, factory: Callable[..., GuardAI] | str, *,
                        display: str | None = None, short: str | None = None,
                        abbrev: str | None = None, section: str | None = None,
                        params: type[Params] | str | None = None) -> None:
    """Register guard mode ``name``: its parameters ``params`` in config section ``section``
    (default ``name``), its names (display default ``name.title()``, short default the
    display name). A mode registered later comes later (play's next number key).
    """
    GUARD_MODES[name] = _registration(name, factory, display, short, abbrev, section or name,
                                      params)


def register_player_policy(name: str, factory: Callable[..., PlayerPolicy] | str, *,
                           display: str | None = None, short: str | None = None,
                           section: str = "player",
                           params: type[Params] | str | None = None) -> None:
    """Register player policy ``name`` (its parameters ``params`` in config section ``section``)."""
    PLAYER_POLICIES[name] = _registration(name, factory, display, short, None, section, params)


def unregister_guard_mode(name: str) -> None:
    """Remove a guard mode registered by :func:`register_guard_mode` (tests, notebooks); a
    built-in one stays."""
    GUARD_MODES.discard(name)


def unregister_player_policy(name: str) -> None:
    """Remove a player policy registered by :func:`register_player_policy`; a built-in one
    stays."""
    PLAYER_POLICIES.discard(name)


class Names(Mapping[str, str]):
    """One name of every registration in ``table`` (``"display"``, ``"short"``, ``"abbrev"``),
    read live, so a mode registered later has its names in every report.

    >>> Names(GUARD_MODES, "display")["pf"], "nobody" in Names(GUARD_MODES, "short")
    ('PotentialField', False)
    """

    def __init__(self, table: Mapping[str, Registration[Any]], attr: str) -> None:
        self._table, self._attr = table, attr

    def __getitem__(self, name: str) -> str:
        return str(getattr(self._table[name], self._attr))

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._table))

    def __len__(self) -> int:
        return len(self._table)


def _lookup(table: Mapping[str, Registration[T]], name: str, what: str) -> Registration[T]:
    try:
        return table[name]
    except KeyError:
        raise UnknownNameError(f"unknown {what} {name!r} (choose from {', '.join(table)})") \
            from None


def guard_mode(mode: str) -> Registration[GuardAI]:
    """The registration of ``mode``; :class:`~ai.errors.UnknownNameError` if there is none."""
    return _lookup(GUARD_MODES, mode, "guard mode")


def player_policy(policy: str) -> Registration[PlayerPolicy]:
    """The registration of ``policy``; :class:`~ai.errors.UnknownNameError` if there is none."""
    return _lookup(PLAYER_POLICIES, policy, "player policy")


def make_guard_ai(mode: str, params: Mapping[str, Any] | None = None) -> GuardAI:
    """A fresh guard team controller for ``mode`` (one of :data:`GUARD_MODES`)."""
    return guard_mode(mode).build(params)


def make_player_policy(policy: str, params: Mapping[str, Any] | None = None) -> PlayerPolicy:
    """A fresh player policy for ``policy`` (one of :data:`PLAYER_POLICIES`)."""
    return player_policy(policy).build(params)


register_guard_mode("pf", "ai.pf:PotentialFieldGuards", display="PotentialField", short="PF",
                    params="ai.params:PFParams")
register_guard_mode("random", "ai.baselines:RandomWalkGuards", display="RandomWalk", short="RW")
register_guard_mode("fsm", "ai.baselines:FSMGuards", display="FSM", params="ai.params:FSMParams")
register_guard_mode("staleness", "ai.baselines:StalenessGuards", display="Staleness", short="S",
                    abbrev="Stal", params="ai.params:StalenessParams")
register_guard_mode("cheat", "ai.baselines:CheatGuards", display="Cheat", short="C",
                    abbrev="Cheat")
register_player_policy("maxmin", "ai.players:MaxMinPlayer", display="MaxMin", short="MM",
                       params="ai.params:PlayerParams")
register_player_policy("safetygraph", "ai.players:SafetyGraphPlayer", display="SafetyGraph",
                       short="SG", params="ai.params:PlayerParams")
register_player_policy("evade", "ai.players:EvadePlayer", display="Evade", short="EV")
GUARD_MODES.seal()  # the names above are the built-in ones: nothing replaces them
PLAYER_POLICIES.seal()

__all__ = [
    "DEFAULT_GUARD_MODE", "DEFAULT_PLAYER_POLICY", "Event", "GuardAI", "Names", "PlayerPolicy",
    "Registration", "Registry", "WorldView", "GUARD_MODES", "PLAYER_POLICIES", "guard_mode",
    "make_guard_ai", "make_player_policy", "player_policy", "register_guard_mode",
    "register_player_policy", "registrations", "unregister_guard_mode",
    "unregister_player_policy",
]
