"""Allowed values of a tunable: a numeric :class:`Range` or a set of choices (:class:`OneOf`).

Every parameter dataclass (:mod:`ai.params`, :class:`ai.stimuli.StimulusParams`, ...) and
every config key (:mod:`game.schema`) declares its allowed values once with one of these,
so the config check, the parameter check and the documentation read the same declaration.
A bound only describes and judges a value; the caller raises its own error with the text.

>>> UNIT.problem(1.5), UNIT.describe()
('must be in (0, 1]', '(0, 1]')
>>> COUNT.problem(2.5), COUNT.problem(3)
('must be a whole number in [0, inf)', None)
>>> POSITIVE.problem(float("nan"))
'must be a finite number in (0, inf)'
>>> OneOf(("random", "level")).problem("x")
"must be one of 'random', 'level'"
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = [
    "ANY_NUMBER", "Bound", "COUNT", "FLAG", "FRACTION", "NON_NEGATIVE", "OneOf", "POSITIVE",
    "Range", "UNIT",
]


def _number(x: float) -> str:
    """``0.0`` as ``0``, ``inf`` as ``inf``: bounds read like the docs write them."""
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    if isinstance(x, int) or x.is_integer():
        return str(int(x))
    return f"{x:g}"


@dataclass(frozen=True)
class Range:
    """Numbers from ``low`` to ``high``; an open end excludes its limit; ``integer``: whole only.

    NaN and the infinities are never inside a range, whatever its limits.
    """

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    integer: bool = False

    def describe(self) -> str:
        """The interval in the usual notation, e.g. ``(0, 1]``; an infinite end is open."""
        left = "(" if self.low_open or math.isinf(self.low) else "["
        right = ")" if self.high_open or math.isinf(self.high) else "]"
        return f"{left}{_number(self.low)}, {_number(self.high)}{right}"

    def problem(self, value: Any) -> str | None:
        """What is wrong with ``value`` (a phrase such as ``"must be in (0, 1]"``), or None."""
        span = self.describe()
        noun = "a whole number" if self.integer else "a number"
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"must be {noun} in {span}"
        if isinstance(value, float) and not math.isfinite(value):  # an int always is (and
            return f"must be a finite {noun[2:]} in {span}"  # beyond 1e308 cannot be a float)
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        if (self.integer and int(value) != value) or not (above and below):
            return f"must be {noun + ' ' if self.integer else ''}in {span}"
        return None


@dataclass(frozen=True)
class OneOf:
    """One of a few fixed values (the strings of a mode switch; ``False``/``True``)."""

    choices: tuple[Any, ...]

    def describe(self) -> str:
        """The choices, e.g. ``'random', 'level'`` or ``true, false``."""
        return ", ".join(_choice(c) for c in self.choices)

    def problem(self, value: Any) -> str | None:
        """What is wrong with ``value``, or None when it is one of the choices (same type)."""
        for choice in self.choices:
            if type(value) is type(choice) and value == choice:
                return None
        return f"must be one of {self.describe()}"


def _choice(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


Bound = Range | OneOf
"""What a declaration may be: a numeric range or a set of choices."""

UNIT = Range(0.0, 1.0, low_open=True)
"""(0, 1]: a decay or falloff factor (0 would erase everything at once)."""
FRACTION = Range(0.0, 1.0)
"""[0, 1]: a weight or share."""
POSITIVE = Range(0.0, math.inf, low_open=True)
"""(0, inf): speeds, steps, durations, anything divided by."""
NON_NEGATIVE = Range(0.0, math.inf)
"""[0, inf): amplitudes, ranges, times that may be zero."""
COUNT = Range(0, math.inf, integer=True)
"""[0, inf) whole numbers: hops, cells, guards."""
ANY_NUMBER = Range()
"""Any finite number (a margin that may be negative)."""
FLAG = OneOf((True, False))
"""A switch: true or false."""
