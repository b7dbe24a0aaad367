"""Memory over many trials in one process (issue 24): ``headless.api.run_one`` in a loop.

Prints the resident set size (``/proc/self/statm``) after the first ``--warmup`` trials and
every ``--every`` trials after, and the growth after the warm-up in per cent (the issue's
acceptance: under 20 % over 2,000 trials). ``--trace`` adds tracemalloc's top allocation
sites grown since the warm-up, to find what keeps growing.

Run: ``python benchmarks/memory.py`` (2,000 trials of 20 s on maze, several minutes);
``--trials 400 --duration 5`` for a short look.
"""

from __future__ import annotations

import argparse
import gc
import os
import time

import _paths  # noqa: F401  (project importable, this folder unshadowed)


def rss_mb() -> float:
    with open("/proc/self/statm", encoding="ascii") as statm:
        return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=2000)
    parser.add_argument("--warmup", type=int, default=100)
    parser.add_argument("--every", type=int, default=200)
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--level", default="maze")
    parser.add_argument("--trace", action="store_true")
    parser.add_argument("--vary", action="store_true",
                        help="a different pf.kernel_lambda per trial (as a tuner does)")
    args = parser.parse_args()

    from headless.api import run_one

    combos = [(a, g) for a in ("grid", "partition") for g in ("pf", "random", "fsm")]
    start = time.perf_counter()
    base = None
    snapshot = None
    for i in range(args.trials):
        abstraction, guards = combos[i % len(combos)]
        overrides = {"world.duration": args.duration}
        if args.vary:
            overrides["pf.kernel_lambda"] = 0.5 + (i % 997) / 2000
        run_one(args.level, abstraction=abstraction, guards=guards, seed=i, overrides=overrides)
        done = i + 1
        if done == args.warmup:
            gc.collect()
            base = rss_mb()
            print(f"{done:6d} trials  {base:8.1f} MB  (baseline)", flush=True)
            if args.trace:
                import tracemalloc

                tracemalloc.start(8)
                snapshot = tracemalloc.take_snapshot()
        elif base is not None and (done % args.every == 0 or done == args.trials):
            gc.collect()
            now = rss_mb()
            print(f"{done:6d} trials  {now:8.1f} MB  {100 * (now - base) / base:+6.1f} %  "
                  f"({time.perf_counter() - start:.0f} s)", flush=True)
    if snapshot is not None:
        import tracemalloc

        for stat in tracemalloc.take_snapshot().compare_to(snapshot, "traceback")[:8]:
            print(stat)
            for line in stat.traceback.format()[-6:]:
                print("   ", line)


if __name__ == "__main__":
    main()
