"""Errors of the ``headless`` layer, subclasses of the root :class:`~navmesh.errors.StealthError`.

:class:`UserError` (re-exported from :mod:`navmesh.errors`) is the generic one-line mistake
the commands raise; :class:`PresetError` names a preset file and field; :class:`SweepError`
is a results directory, store, lock or scheduler that a sweep cannot use.

>>> issubclass(PresetError, UserError) and issubclass(SweepError, StealthError)
True
"""

from __future__ import annotations

from navmesh.errors import StealthError, UserError

__all__ = ["PresetError", "StealthError", "SweepError", "UsageError", "UserError"]


class PresetError(UserError):
    """A preset that is missing or invalid: ``"<file>: <field>: <problem>"`` on one line."""


class SweepError(UserError):
    """A results directory, store, lock or cluster a sweep cannot use."""


class UsageError(UserError):
    """A command line argparse rejects (unknown option, bad choice, missing argument)."""
