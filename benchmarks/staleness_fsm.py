"""Staleness − FSM on paired trials (run by hand; issue 21's acceptance figure).

    python benchmarks/staleness_fsm.py [--seeds 10] [--set staleness.model=node ...]

Fixed-time grid trials against MaxMin on miami and maze, seeds 0..N-1, defaults plus the
``--set`` overrides (given to the Staleness trials only). The FSM and Staleness trials of a
seed share their spawns (common random numbers), so each (level, seed) is one pair. Prints
the mean paired difference of coverage and first-detection time with its 95 % t-interval
(first detection twice: over the pairs where both detected, and with "never" = the trial's
duration).
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy import stats

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from game.config import Config
from game.trial import TrialSpec, run_trial

LEVELS = ("miami", "maze")


def interval(d: np.ndarray) -> str:
    """Mean and 95 % t-interval of the paired differences ``d``."""
    if len(d) < 2:
        return f"n={len(d)}"
    m = float(d.mean())
    h = float(stats.t.ppf(0.975, len(d) - 1) * d.std(ddof=1) / math.sqrt(len(d)))
    return f"n={len(d)}  mean {m:+.4f}  95% CI [{m - h:+.4f}, {m + h:+.4f}]"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    config = Config.load(args.set)  # checks the overrides; typed values for the trials
    overrides = tuple((kv.split("=", 1)[0], config[kv.split("=", 1)[0]]) for kv in args.set)
    duration = float(config["world.duration"])
    rows = {}
    for level in LEVELS:
        for seed in range(args.seeds):
            for guards in ("fsm", "staleness"):
                spec = TrialSpec(level=level, guards=guards, player="maxmin", scenario="fixed",
                                 seed=seed, overrides=overrides if guards == "staleness" else ())
                rows[level, seed, guards] = run_trial(spec)["metrics"]
    pairs = [(level, seed) for level in LEVELS for seed in range(args.seeds)]
    cover = np.array([rows[p + ("staleness",)]["coverage"] - rows[p + ("fsm",)]["coverage"]
                      for p in pairs])
    first = [(rows[p + ("staleness",)]["first_detect_time"], rows[p + ("fsm",)]["first_detect_time"])
             for p in pairs]
    both = np.array([a - b for a, b in first if a is not None and b is not None])
    never = np.array([(duration if a is None else a) - (duration if b is None else b) for a, b in first])
    print("coverage                      ", interval(cover))
    print("first detection (both)        ", interval(both))
    print(f"first detection (never = {duration:g} s)", interval(never))
    for guards in ("fsm", "staleness"):
        found = sum(rows[p + (guards,)]["first_detect_time"] is not None for p in pairs)
        mean = np.mean([rows[p + (guards,)]["coverage"] for p in pairs])
        print(f"{guards}: coverage {mean:.3f}, detected in {found} of {len(pairs)}")


if __name__ == "__main__":
    main()
