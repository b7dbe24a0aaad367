"""What defines a ``stealth play`` game (:class:`PlaySettings`), apart from the window playing it."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from ai import DEFAULT_GUARD_MODE

__all__ = ["PlaySettings", "SessionSink"]

#: What ``--record`` hands the command line for every finished session: the row and trace.
SessionSink = Callable[[dict[str, Any], Sequence[str]], None]


@dataclass(frozen=True)
class PlaySettings:
    """Everything that defines a game; the world is rebuilt from it on restart."""

    level: str
    guards: str = DEFAULT_GUARD_MODE
    abstraction: str = "grid"
    scenario: str = "capture"
    seed: int = 0
    overrides: tuple[str, ...] = ()
    autopilot: str | None = None
    overlay: str = "none"
    show_mesh: bool = False
    show_plans: bool = False
    #: plugin stimuli, ``"FILE.py:NAME"`` or entry-point names (``--stimulus``)
    stimuli: tuple[str, ...] = ()
    #: keep every game as a trial row (``stealth play --record DIR``)
    record: bool = False
    #: ask the post-game questionnaire (``--questions``, with ``--record``)
    questions: bool = False
    #: the levels N (next level) cycles through
    playlist: tuple[str, ...] = ()
