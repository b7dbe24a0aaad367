"""How long a sweep will take, printed before it starts (``stealth run``).

Per-trial wall times were measured on the bundled levels with the ``quick`` preset
(1,000 trials, default config, 2 workers on a 2-vCPU machine shared with other work:
``stealth run --preset quick`` then the mean ``wall_time`` per level × abstraction ×
scenario of its store). A trial of another level costs the mean of the table; a trial
runs ``world.duration`` seconds of game time, so the cost scales with it. The estimate is
the sum over the trials still to run divided by the workers, plus the pool's start; the
progress bar's ETA then takes over with the real rate. A trial on the batch engine costs
:data:`BATCH_COST` of its pymunk time.

>>> round(estimate_seconds([("maze", "grid", "capture")] * 200, 2, 60.0), 1)
9.3
>>> duration_text(75), duration_text(4000)
('1 min 15 s', '1 h 6 min')
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["BATCH_COST", "MEASURED_DURATION", "POOL_START", "TRIAL_SECONDS", "duration_text",
           "estimate_seconds"]

MEASURED_DURATION = 60.0
"""``world.duration`` (game seconds) of the measured trials: the default."""

POOL_START = 1.0
"""Seconds to start the worker processes (imports), measured: about 1 s."""

TRIAL_SECONDS: dict[tuple[str, str, str], float] = {
    ("arkham", "grid", "capture"): 0.113, ("arkham", "grid", "fixed"): 0.117,
    ("arkham", "partition", "capture"): 0.093, ("arkham", "partition", "fixed"): 0.089,
    ("dishonored", "grid", "capture"): 0.100, ("dishonored", "grid", "fixed"): 0.102,
    ("dishonored", "partition", "capture"): 0.083, ("dishonored", "partition", "fixed"): 0.089,
    ("maze", "grid", "capture"): 0.083, ("maze", "grid", "fixed"): 0.096,
    ("maze", "partition", "capture"): 0.081, ("maze", "partition", "fixed"): 0.101,
    ("miami", "grid", "capture"): 0.086, ("miami", "grid", "fixed"): 0.088,
    ("miami", "partition", "capture"): 0.067, ("miami", "partition", "fixed"): 0.073,
    ("tlou", "grid", "capture"): 0.081, ("tlou", "grid", "fixed"): 0.089,
    ("tlou", "partition", "capture"): 0.079, ("tlou", "partition", "fixed"): 0.079,
}
"""Mean wall time (s) of one trial per (level, abstraction, scenario), measured as above."""

BATCH_COST = 0.7
"""A trial's time on the batch engine over its time on the pymunk engine: ``stealth run
--preset quick`` with ``--set world.engine=auto`` against ``=pymunk``, 2 workers, quiet
(46.3 s / 66.4 s on 2026-12-07; ``python benchmarks/batch.py --seeds 3``'s CPU-time ratio
is 1.71, the sweep's start and smaller batches cost the rest)."""

_MEAN = sum(TRIAL_SECONDS.values()) / len(TRIAL_SECONDS)


def estimate_seconds(trials: Iterable[tuple[str, str, str]], workers: int,
                     duration: float, batch: Iterable[tuple[str, str, str]] = ()) -> float:
    """Expected wall time of running ``trials`` on the pymunk engine and ``batch`` on the
    batch engine — (level name, abstraction, scenario) each — on ``workers`` processes with
    ``world.duration = duration``."""
    total = (sum(TRIAL_SECONDS.get(trial, _MEAN) for trial in trials)
             + BATCH_COST * sum(TRIAL_SECONDS.get(trial, _MEAN) for trial in batch))
    return POOL_START + total * (duration / MEASURED_DURATION) / max(1, workers)


def duration_text(seconds: float) -> str:
    """``"45 s"``, ``"1 min 15 s"``, ``"1 h 6 min"``."""
    seconds = max(0, round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60} min"
