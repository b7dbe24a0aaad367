"""Guard AI and player policies: composite potential fields, baselines, stimuli.

Imports ``navmesh`` only (SPEC §1). Guard modes and player policies are **registered** here
by name — with a display name and the config section their parameters come from — so the
world, the CLI and the sweep never import a concrete controller class, and a new mode is
one :func:`register_guard_mode` call in the module that defines it (or in a test):

>>> from ai.baselines import RandomWalkGuards
>>> register_guard_mode("random2", RandomWalkGuards, display="RandomWalk (copy)")
>>> make_guard_ai("random2").mode, GUARD_MODES["random2"].section
('random', 'random2')
>>> unregister_guard_mode("random2")
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib import import_module
from typing import Any, Generic, TypeVar

from .errors import UnknownNameError
from .view import Event, GuardAI, PlayerPolicy, WorldView

T = TypeVar("T", GuardAI, PlayerPolicy)


@dataclass(frozen=True)
class Registration(Generic[T]):
    """One registered controller: how to build it and how to name it.

    ``factory`` is a class (or any callable taking the params mapping) or a lazy
    ``"module:attr"`` reference, imported the first time the name is built. ``display`` is
    the name tables and figures print; ``section`` the config table its params come from.
    """

    name: str
    factory: Callable[[Mapping[str, Any] | None], T] | str
    display: str
    section: str

    def build(self, params: Mapping[str, Any] | None = None) -> T:
        """A fresh controller with ``params``."""
        factory = self.factory
        if isinstance(factory, str):
            module, _, attr = factory.partition(":")
            factory = getattr(import_module(module), attr)
        return factory(params)


#: Registered guard modes by command-line name (SPEC §9 order).
GUARD_MODES: dict[str, Registration[GuardAI]] = {}
#: Registered player policies by command-line name.
PLAYER_POLICIES: dict[str, Registration[PlayerPolicy]] = {}


def register_guard_mode(name: str, factory: Callable[..., GuardAI] | str, *,
                        display: str | None = None, section: str | None = None) -> None:
    """Register guard mode ``name`` (config section ``section``, default ``name``)."""
    GUARD_MODES[name] = Registration(name, factory, display or name, section or name)


def register_player_policy(name: str, factory: Callable[..., PlayerPolicy] | str, *,
                           display: str | None = None, section: str = "player") -> None:
    """Register player policy ``name`` (its params come from config section ``section``)."""
    PLAYER_POLICIES[name] = Registration(name, factory, display or name, section)


def unregister_guard_mode(name: str) -> None:
    """Remove a guard mode registered by :func:`register_guard_mode` (tests, notebooks)."""
    GUARD_MODES.pop(name, None)


def unregister_player_policy(name: str) -> None:
    """Remove a player policy registered by :func:`register_player_policy`."""
    PLAYER_POLICIES.pop(name, None)


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


register_guard_mode("pf", "ai.pf:PotentialFieldGuards", display="PotentialField")
register_guard_mode("random", "ai.baselines:RandomWalkGuards", display="RandomWalk")
register_guard_mode("fsm", "ai.baselines:FSMGuards", display="FSM")
register_guard_mode("staleness", "ai.baselines:StalenessGuards", display="Staleness")
register_guard_mode("cheat", "ai.baselines:CheatGuards", display="Cheat")
register_player_policy("maxmin", "ai.players:MaxMinPlayer", display="MaxMin")
register_player_policy("safetygraph", "ai.players:SafetyGraphPlayer", display="SafetyGraph")
register_player_policy("evade", "ai.players:EvadePlayer", display="Evade")

__all__ = [
    "Event", "GuardAI", "PlayerPolicy", "Registration", "WorldView", "GUARD_MODES",
    "PLAYER_POLICIES", "guard_mode", "make_guard_ai", "make_player_policy", "player_policy",
    "register_guard_mode", "register_player_policy", "unregister_guard_mode",
    "unregister_player_policy",
]
