"""The names of the two experiments (SPEC §7): ``capture`` ends at HP 0, ``fixed`` respawns
the player and always runs the full duration; their numbers are the ``[scenario.NAME]``
tables of ``game/defaults.toml``.

Apart from :mod:`game.world`, which runs them, so the command line can offer the names
without importing the simulation.
"""

from __future__ import annotations

__all__ = ["SCENARIOS"]

#: Every scenario's name, in the order commands list them.
SCENARIOS: tuple[str, ...] = ("capture", "fixed")
