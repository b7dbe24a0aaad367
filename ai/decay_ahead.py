"""The next AI tick's decayed fields, computed ahead in a frame's spare time.

A tick starts from ``I · ρ^dt`` and ``C · decay^dt`` (eqs. 1 and 3), two products over
every node that depend only on the fields as they are now. On a 10^6-cell level they are
most of a tick's cost, all in one frame; the game computes them ahead instead, a slice at
a time, in the spare time of the frames before the tick (:meth:`DecayAhead.run`). An
elementwise product gives the same bits whatever the slicing, so the tick reads them
(:meth:`DecayAhead.result`) only when they were made from the very arrays and factors it
would multiply, and otherwise multiplies as before.
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["DecayAhead"]


class DecayAhead:
    """``information · rho_dt`` and ``confidence · decay_power``, filled a slice at a time."""

    #: elements per slice: a few hundred microseconds of work
    SLICE = 1 << 16

    def __init__(self, dt: float, information: np.ndarray, rho_dt: float,
                 confidence: np.ndarray, decay_power: np.ndarray) -> None:
        self.dt, self.rho_dt = dt, rho_dt
        self._sources = (information, confidence, decay_power)
        self.information = np.empty_like(information)
        self.confidence = np.empty_like(confidence)
        self.done = 0  # nodes [0, done) are filled

    def run(self, deadline: float) -> bool:
        """Fill slices until ``deadline`` (``time.perf_counter()``); whether work is left."""
        information, confidence, decay_power = self._sources
        n = len(self.information)
        while self.done < n and time.perf_counter() < deadline:
            a, b = self.done, min(n, self.done + self.SLICE)
            np.multiply(information[a:b], self.rho_dt, out=self.information[a:b])
            np.multiply(confidence[a:b], decay_power[a:b], out=self.confidence[a:b])
            self.done = b
        return self.done < n

    def matches(self, dt: float, information: np.ndarray, rho_dt: float,
                confidence: np.ndarray, decay_power: np.ndarray) -> bool:
        """Whether these are the products a tick of ``dt`` would make from these arrays."""
        sources = (information, confidence, decay_power)
        return dt == self.dt and rho_dt == self.rho_dt and all(
            mine is theirs for mine, theirs in zip(self._sources, sources, strict=True))

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        """The two products, finishing any slices left (the caller's to modify)."""
        self.run(float("inf"))
        return self.information, self.confidence
