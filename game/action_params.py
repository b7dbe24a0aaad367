"""The tunables of the player's actions (:class:`ActionParams`), declared apart from the
actions themselves (:mod:`game.actions`, which act on a :class:`~game.world.World`): the
config schema reads them without reaching the world.

They are the world's, not the guard AI's, and keep their keys in the ``[stimuli]`` config
section (``stimuli.throw_cooldown`` ...; docs/world.md says why).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from ai.bounds import COUNT, NON_NEGATIVE, POSITIVE
from ai.params import Params

__all__ = ["ActionParams"]


@dataclass(frozen=True)
class ActionParams(Params):
    """Tunables of the player's actions; config keys ``stimuli.<name>`` (see the module)."""

    #: thrown decoy: seconds between throws, landing within this Manhattan radius in cells
    throw_cooldown: float = 10.0
    throw_radius: int = 4
    #: the player activates a level decoy within this distance (world units, line of sight)
    decoy_reach: float = 1.5
    #: take-down: guard centre within this distance of the player's, player outside its cone
    takedown_range: float = 1.0

    bounds = {
        "throw_cooldown": NON_NEGATIVE,
        "throw_radius": COUNT,
        "decoy_reach": NON_NEGATIVE,
        "takedown_range": POSITIVE,
    }

    @classmethod
    def split(cls, section: Mapping[str, Any]) -> tuple[ActionParams, dict[str, Any]]:
        """This object from its keys of a ``[stimuli]`` section, and the other keys.

        >>> params, rest = ActionParams.split({"throw_radius": 2, "noise_decay": 0.5})
        >>> params.throw_radius, rest
        (2, {'noise_decay': 0.5})
        """
        own = {f.name for f in fields(cls)}
        params = cls.from_mapping({k: v for k, v in section.items() if k in own})
        return params, {k: v for k, v in section.items() if k not in own}
