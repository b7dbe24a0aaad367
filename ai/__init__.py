"""Guard AI and player policies: composite potential fields, baselines, stimuli.

Imports ``navmesh`` only (SPEC §1). Modes and policies are looked up by name here so the
world, the CLI and the sweep never import a concrete controller class.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib import import_module
from typing import Any

from .view import Event, GuardAI, PlayerPolicy, WorldView

GUARD_MODES: dict[str, str] = {
    "pf": "ai.pf:PotentialFieldGuards",
    "random": "ai.baselines:RandomWalkGuards",
    "fsm": "ai.baselines:FSMGuards",
    "staleness": "ai.baselines:StalenessGuards",
    "cheat": "ai.baselines:CheatGuards",
}

PLAYER_POLICIES: dict[str, str] = {
    "maxmin": "ai.players:MaxMinPlayer",
    "safetygraph": "ai.players:SafetyGraphPlayer",
    "evade": "ai.players:EvadePlayer",
}


def _load(table: dict[str, str], name: str, what: str) -> type:
    if name not in table:
        raise ValueError(f"unknown {what} {name!r} (choose from {', '.join(table)})")
    module, _, attr = table[name].partition(":")
    return getattr(import_module(module), attr)


def make_guard_ai(mode: str, params: Mapping[str, Any] | None = None) -> GuardAI:
    """A fresh guard team controller for ``mode`` (one of :data:`GUARD_MODES`)."""
    return _load(GUARD_MODES, mode, "guard mode")(params)


def make_player_policy(policy: str, params: Mapping[str, Any] | None = None) -> PlayerPolicy:
    """A fresh player policy for ``policy`` (one of :data:`PLAYER_POLICIES`)."""
    return _load(PLAYER_POLICIES, policy, "player policy")(params)


__all__ = [
    "Event", "GuardAI", "PlayerPolicy", "WorldView", "GUARD_MODES", "PLAYER_POLICIES",
    "make_guard_ai", "make_player_policy",
]
