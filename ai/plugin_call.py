"""Calls into stimulus code, checked: a plugin that raises or answers nonsense is one line.

A stimulus may come from any file (``--stimulus FILE.py:NAME``) or installed package, so the
:class:`~ai.stimuli.StimulusSet` calls every stimulus method through :func:`call`: whatever
the method raises becomes a :class:`~ai.errors.StimulusError` naming the stimulus, its class
and the method (the original exception is chained, so ``stealth --debug`` shows where), and
what it returns is checked where the caller depends on it (:func:`checked_layer`,
:func:`checked_number`). Built-in stimuli go through the same path; the values are never
changed, so trials stay bit-identical.

>>> class Broken:
...     name = "broken"
...     def inject(self, ctx):
...         raise KeyError("x")
>>> call(Broken(), Broken().inject, None)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ai.errors.StimulusError: stimulus 'broken' (Broken...): inject() raised KeyError: 'x'
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any, Protocol, TypeVar

import numpy as np

from .errors import StimulusError

__all__ = ["Plugin", "call", "checked_layer", "checked_number", "describe", "is_done"]

T = TypeVar("T")


class Plugin(Protocol):
    """What the checked calls read of plugin code's object (a :class:`~ai.stimulus.Stimulus`
    or whatever a plugin hands over): the name errors give it, and ``done``, whose value
    :func:`is_done` checks rather than trusts."""

    @property
    def name(self) -> str: ...

    @property
    def done(self) -> object: ...


def describe(stimulus: Plugin) -> str:
    """``stimulus 'NAME' (module.Class)``: how errors name a stimulus."""
    kind = type(stimulus)
    try:
        where = f" in {inspect.getfile(kind)}"
    except (TypeError, OSError):  # defined at the prompt or in C: no file to name
        where = ""
    return f"stimulus {str(stimulus.name)!r} ({kind.__qualname__}{where})"


def call(stimulus: Plugin, method: Callable[..., T], *args: Any) -> T:
    """``method(*args)`` (a bound method of ``stimulus``); an exception becomes a StimulusError."""
    try:
        return method(*args)
    except StimulusError:
        raise
    except Exception as error:
        text = " ".join(f"{type(error).__name__}: {error}".split())
        raise StimulusError(f"{describe(stimulus)}: {method.__name__}() raised {text}") from error


def is_done(stimulus: Plugin) -> bool:
    """``stimulus.done`` (an attribute or a property), checked: a property that raises, or
    a value that is not a bool (a ``done`` written as a plain method), is a StimulusError."""
    try:
        value = stimulus.done
    except StimulusError:
        raise
    except Exception as error:
        text = " ".join(f"{type(error).__name__}: {error}".split())
        raise StimulusError(f"{describe(stimulus)}: done raised {text}") from error
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    hint = " (a method: make it a @property or an attribute)" if callable(value) else ""
    raise StimulusError(f"{describe(stimulus)}: done must be a bool, got "
                        f"{type(value).__name__}{hint}")


def checked_layer(stimulus: Plugin, values: Any, n: int) -> np.ndarray | None:
    """``inject()``'s answer as a float array of shape ``(n,)`` with finite values, or None."""
    if values is None:
        return None
    try:
        layer = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise StimulusError(f"{describe(stimulus)}: inject() returned "
                            f"{type(values).__name__}, not an array of numbers ({error})") from None
    if layer.shape != (n,):
        raise StimulusError(f"{describe(stimulus)}: inject() must return shape ({n},), "
                            f"got {layer.shape}")
    bad = int(np.count_nonzero(~np.isfinite(layer)))
    if bad:
        raise StimulusError(f"{describe(stimulus)}: inject() returned NaN or infinite values "
                            f"at {bad} of {n} nodes")
    return layer


def checked_number(stimulus: Plugin, what: str, value: Any, low: float, high: float) -> float:
    """A number a stimulus answers with (a weight floor, a sound's amplitude), in [low, high]."""
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    number = float(value) if ok else float("nan")
    if not low <= number <= high:  # also false for NaN
        raise StimulusError(f"{describe(stimulus)}: {what} must be a number in "
                            f"[{low:g}, {high:g}], got {value!r}")
    return number
