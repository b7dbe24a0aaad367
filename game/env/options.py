"""What the environments of :mod:`game.env` take: their options beside the config
overrides, and an action checked against its space."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces

#: Keyword options of the environments; every other keyword is a config override.
OPTIONS = ("render_mode", "obs_radius", "rewards", "render_size", "overrides")


def check_action(space: spaces.Discrete, action: Any, who: str = "the agent") -> int:
    """``action`` as an int, or a ValueError naming it when it is not in ``space``.

    ``Discrete.contains`` refuses floats, strings and out-of-range integers (numpy's
    ``-1`` included), so ``step(1.7)`` cannot silently become action 1; booleans (Python's
    or numpy's, which ``contains`` takes) are refused here, so ``step(True)`` is not 1.
    """
    kind = type(action)
    if kind is int or kind is np.int64:  # the usual cases, without contains()'s dtype checks
        start = int(space.start)
        if start <= action < start + int(space.n):
            return int(action)
    ok = False
    if not isinstance(action, (bool, np.bool_)) and getattr(action, "dtype", None) != np.bool_:
        try:
            ok = space.contains(action)
        except (TypeError, ValueError):
            ok = False
    if not ok:
        raise ValueError(f"invalid action {action!r} for {who}: expected an integer in "
                         f"[0, {space.n - 1}] ({space})")
    return int(action)


def split_options(level: str, abstraction: str, scenario: str, kwargs: dict[str, Any]
                  ) -> tuple[dict[str, Any], dict[str, Any]]:
    """Env options and config overrides (``world__guards=2`` means ``world.guards=2``)."""
    options = {k: kwargs.pop(k) for k in OPTIONS if k in kwargs}
    given = options.pop("overrides", None)
    if given is not None and not isinstance(given, Mapping):
        raise ValueError(f"overrides must be a dict of config keys, not {given!r}")
    overrides = dict(given or {})
    for key, value in kwargs.items():
        overrides[key.replace("__", ".")] = value
    return options, overrides


__all__ = ["OPTIONS", "check_action", "split_options"]
