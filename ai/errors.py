"""Errors of the ``ai`` layer, subclasses of the root :class:`~navmesh.errors.StealthError`.

>>> issubclass(UnknownNameError, StealthError)
True
"""

from __future__ import annotations

from navmesh.errors import StealthError

__all__ = ["PluginError", "StealthError", "StimulusError", "UnknownNameError", "WorkBudgetError"]


class UnknownNameError(StealthError, ValueError):
    """A guard mode or player policy name that is not registered; the message lists the names."""


class PluginError(StealthError, ValueError):
    """An installed guard-mode or player-policy entry point that cannot be loaded; the
    message is one line naming it (:mod:`ai.installed`)."""


class StimulusError(StealthError, ValueError):
    """A stimulus plugin that cannot be loaded; the message is one line naming it."""


class WorkBudgetError(StealthError, ValueError):
    """A parameter whose work on this level's graph exceeds the budget (the message names
    the config key), e.g. a smoothing kernel of too many node pairs."""
