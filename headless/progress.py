"""A dependency-free progress bar for sweeps, written to a stream (stderr).

>>> import io
>>> bar = Progress(4, io.StringIO(), interval=0.0)
>>> bar.update(2); bar.line().split()[1:3]
['2/4', '50%']
"""

from __future__ import annotations

import math
import sys
import time
from typing import IO

__all__ = ["Progress"]


def _duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "--:--"
    seconds = round(seconds)
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m:02d}:{s:02d}"


class Progress:
    """A dependency-free progress bar on a stream (stderr).

    On a terminal it redraws one line with ``\\r``; otherwise (a log file, CI) it prints a
    plain line at most every ``interval`` seconds.
    """

    def __init__(self, total: int, stream: IO[str] | None = None, *, enabled: bool = True,
                 interval: float = 5.0, unit: str = "trials") -> None:
        self.total = total
        self.unit = unit
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.tty = self.stream.isatty()
        self.interval = 0.1 if self.tty else interval
        self.started = time.monotonic()
        self.last = -math.inf
        self.done = 0
        self.failed = 0

    def line(self) -> str:
        """The current progress text, e.g. ``[#####.....] 50/100 50% 12.3 trials/s ETA 00:04``."""
        elapsed = time.monotonic() - self.started
        rate = self.done / elapsed if elapsed > 0 else 0.0
        eta = (self.total - self.done) / rate if rate > 0 else math.inf
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(frac * 24) + "." * (24 - int(frac * 24))
        failed = f" {self.failed} failed" if self.failed else ""
        return (f"[{bar}] {self.done}/{self.total} {100 * frac:3.0f}% "
                f"{rate:5.1f} {self.unit}/s ETA {_duration(eta)}{failed}")

    def update(self, done: int, failed: int = 0, *, force: bool = False) -> None:
        """Record ``done`` (and ``failed``) more trials and redraw if it is time to."""
        self.done += done
        self.failed += failed
        now = time.monotonic()
        if not self.enabled or (not force and now - self.last < self.interval):
            return
        self.last = now
        if self.tty:
            self.stream.write("\r" + self.line() + "\x1b[K")
        else:
            self.stream.write(self.line() + "\n")
        self.stream.flush()

    def close(self) -> None:
        """Draw the final state (and end the redrawn line on a terminal)."""
        if self.enabled:
            self.update(0, force=True)
            if self.tty:
                self.stream.write("\n")
                self.stream.flush()
