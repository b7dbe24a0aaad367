"""The project's error hierarchy, at the bottom of the import order (Gymnasium's ``error``).

Every error a user can cause — a broken level file, a point outside the walkable area, an
unknown guard mode, a bad override, an unreadable preset — is a :class:`StealthError`. Its
message is one line, and the ``stealth`` command prints it as ``stealth: error: ...`` with
exit code 2. Each layer declares its own subclasses in its own ``errors`` module
(``ai.errors``, ``game.errors``, ``headless.errors``), so code raises an error without
importing the layer above it. Programming errors stay ordinary Python exceptions and keep
their tracebacks.

>>> issubclass(LevelError, StealthError) and issubclass(LevelError, ValueError)
True
>>> str(LevelError("a.json", "guards", "missing required key"))
'a.json: guards: missing required key'
"""

from __future__ import annotations

__all__ = ["LevelError", "LevelWarning", "OutsideError", "StealthError", "UserError"]


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


class StealthError(Exception):
    """Root of every Stealthfield error: a user's mistake, reported as one line (exit 2)."""


class UserError(StealthError):
    """A problem with what the user asked for that no more specific class names."""


class LevelError(StealthError, ValueError):
    """A level file is missing, unreadable or invalid.

    ``str(error)`` is one line, ``"<file>: <field>: <problem>"``; the three parts are also
    available as ``source``, ``field`` and ``problem``. The exception pickles (it is raised
    inside worker processes too).
    """

    def __init__(self, source: str, field: str, problem: str) -> None:
        super().__init__(source, field, problem)
        self.source = _one_line(source)
        self.field = _one_line(field)
        self.problem = _one_line(problem)

    def __str__(self) -> str:
        return f"{self.source}: {self.field}: {self.problem}"


class LevelWarning(UserWarning):
    """A level loads, but probably not as its author meant (a Tiled map without walls or
    guards, an object class Stealthfield does not know): issued with :func:`warnings.warn`,
    one line ``"<file>: <field>: <problem>"``, which the ``stealth`` command prints as
    ``stealth: warning: ...``.

    >>> str(LevelWarning("m.tmx", "map", "no walls"))
    'm.tmx: map: no walls'
    """

    def __init__(self, source: str, field: str, problem: str) -> None:
        super().__init__(source, field, problem)
        self.source = _one_line(source)
        self.field = _one_line(field)
        self.problem = _one_line(problem)

    def __str__(self) -> str:
        return f"{self.source}: {self.field}: {self.problem}"


class OutsideError(StealthError, ValueError):
    """A query point lies outside the walkable area."""
