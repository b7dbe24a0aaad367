"""The engine a headless command runs its trials on (``world.engine``, SPEC §12).

``pymunk`` is the reference (:func:`game.trial.run_trial`, one world per trial); ``batch``
advances the trials of one level, abstraction, ``[set]`` and factor combination in lockstep
(:func:`game.batch.run_trials`). Asked for explicitly, a trial the batch engine does not
cover (:func:`game.batch.uncovered`) is refused before anything runs or is written, in one
line naming what to use instead (:func:`check_covered`).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from game.config import ENGINE_KEY, Config
from game.trial import TrialSpec

from .errors import UserError

__all__ = ["BATCH", "PYMUNK", "check_covered", "refusal"]

PYMUNK = "pymunk"
BATCH = "batch"


def refusal(what: str) -> UserError:
    """The one-line error for a trial the batch engine does not cover (``what`` names it)."""
    from game.batch import refusal_text

    return UserError(refusal_text(what))


def check_covered(specs: Iterable[TrialSpec]) -> None:
    """Raise :func:`refusal` for the first of ``specs`` the batch engine does not cover.

    Each spec is asked with its own config (its ``[set]`` and factors, the engine batch),
    built once per combination.
    """
    from game.batch import uncovered

    configs: dict[Any, Config] = {}
    for spec in specs:
        key = (spec.overrides, spec.factors)
        config = configs.get(key)
        if config is None:
            config = configs[key] = Config.load({**spec.settings, ENGINE_KEY: BATCH})
        what = uncovered(spec, config)
        if what is None and config["world.attack_needs_awareness"]:  # stealth play's rule
            what = "guards that hurt only a player they noticed (world.attack_needs_awareness)"
        if what is not None:
            raise refusal(what)
