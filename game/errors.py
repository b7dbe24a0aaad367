"""Errors of the ``game`` layer, subclasses of the root :class:`~navmesh.errors.StealthError`.

The front end (``game.front``) raises :class:`FrontError` for a bad command-line value or a
display that cannot open, so it never imports ``headless`` to report a mistake.

>>> issubclass(ConfigError, StealthError) and issubclass(FrontError, StealthError)
True
"""

from __future__ import annotations

from navmesh.errors import StealthError

__all__ = ["ConfigError", "FrontError", "StealthError"]


class ConfigError(StealthError, ValueError):
    """A bad override or config file; the message is one line naming the key."""


class FrontError(StealthError):
    """A user mistake found by the interactive front end (play, replay): one line."""
