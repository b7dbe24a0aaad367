"""How much extra work a frame may take, measured at run time from the frame's own cost.

The game does some work only when a frame has time left: the guard AI's work ahead
(:meth:`~ai.view.GuardAI.prepare`), the stripes a new field layer is composed in on a large
level (:mod:`game.front.layers`) and the background results it takes up. How much time is
left depends on the machine: the same frame costs 3 ms on one and 9 ms on a loaded one.
:class:`FrameBudget` watches the fixed part of each frame (events, world step, scene,
drawing, flip: everything but that extra work) and answers from what it saw:

* the frame aims to end by ``share × period`` (half a 60 Hz frame: the rest of the
  period is left to the display server and the rest of the machine);
* the *margin* kept free is the frame's own jitter on this machine (its recent p95 minus
  its median, at least ``min_margin``): a machine whose frames vary gets less;
* :meth:`spare` — the work-ahead of the frame now — is the target minus what the frame
  took so far and the margin, never less than ``floor`` (so work ahead still makes
  progress on a machine too slow for the target, in small slices; twice that while work
  ahead is left over from the last frame) nor more than ``cap``; but nothing in a *spike*,
  a frame past the target on a machine whose typical frame has time to spare (an AI tick:
  the quick frames around it do the work, and the spike does not grow by the floor);
* :meth:`stripes` — how many frames a piece of work of a measured cost is spread over —
  is that cost over the spare a *typical* frame has (the median of recent fixed costs).

Pure (no pygame, no clock): the caller measures and passes seconds in, so tests drive it
with made-up costs.

>>> budget = FrameBudget()
>>> for _ in range(30):
...     budget.observe(0.003)          # a quick machine: 3 ms per frame
>>> round(budget.spare(0.003) * 1000, 2)  # 8.33 target - 3 - 1 margin
4.33
>>> budget.stripes(0.010)             # 10 ms of composing: 3 frames of 4.33 ms
3
>>> budget.spare(0.009)               # a 9-ms spike (an AI tick): nothing ahead in it
0.0
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

__all__ = ["FrameBudget"]


def _quantile(ordered: list[float], q: float) -> float:
    """The q-quantile (0..1, nearest rank) of a sorted non-empty list."""
    return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]


@dataclass
class FrameBudget:
    """The extra-work budget of one frame loop (seconds throughout).

    ``period`` is the frame period (1/60 s), ``share`` the part of it the frame loop aims
    to use, ``window`` how many recent frames the statistics cover.
    """

    period: float = 1.0 / 60.0
    share: float = 0.5
    min_margin: float = 0.001
    floor: float = 0.001
    cap: float = 0.006
    max_stripes: int = 16
    window: int = 120
    _costs: deque[float] = field(default_factory=deque, repr=False)
    _sorted: list[float] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if not (self.period > 0 and 0 < self.share <= 1 and self.window >= 1):
            raise ValueError("FrameBudget: period > 0, 0 < share <= 1 and window >= 1")
        if not 0 <= self.floor <= self.cap:
            raise ValueError("FrameBudget: 0 <= floor <= cap")

    # ------------------------------------------------------------------ measuring
    def observe(self, cost: float) -> None:
        """The fixed part of a frame took ``cost`` seconds (negative values count as 0)."""
        self._costs.append(max(0.0, float(cost)))
        if len(self._costs) > self.window:
            self._costs.popleft()
        self._sorted = None

    def _ordered(self) -> list[float]:
        if self._sorted is None:
            self._sorted = sorted(self._costs)
        return self._sorted

    @property
    def frames(self) -> int:
        """How many frames the statistics cover now."""
        return len(self._costs)

    @property
    def typical(self) -> float:
        """The median fixed cost of the recent frames (0 before the first)."""
        ordered = self._ordered()
        return _quantile(ordered, 0.5) if ordered else 0.0

    @property
    def margin(self) -> float:
        """The time kept free: the frames' jitter (p95 - median), at least ``min_margin``."""
        ordered = self._ordered()
        jitter = _quantile(ordered, 0.95) - _quantile(ordered, 0.5) if ordered else 0.0
        return max(self.min_margin, jitter)

    @property
    def target(self) -> float:
        """When a frame aims to end, counted from its start."""
        return self.share * self.period

    # ------------------------------------------------------------------ answers
    def spare(self, elapsed: float, behind: bool = False) -> float:
        """The work-ahead a frame that has taken ``elapsed`` seconds so far may add;
        ``behind``: the last frame's work ahead was not done, so the floor is doubled
        (the work spreads over more of the frames before it is needed, not into one)."""
        left = self.target - max(0.0, elapsed) - self.margin
        if left < 0 and self.typical + self.margin < self.target:
            return 0.0  # a spike on a machine with time to spare: nothing ahead in it
        return min(self.cap, max(self.floor * (2.0 if behind else 1.0), left))

    def stripes(self, cost: float) -> int:
        """Over how many frames to spread a piece of work of ``cost`` seconds (>= 1)."""
        per_frame = self.spare(self.typical)
        return max(1, min(self.max_stripes, math.ceil(max(0.0, cost) / per_frame)))
