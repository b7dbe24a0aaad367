"""Sweep throughput benchmark (run by hand; not part of the test suite).

Runs a preset (default ``quick``: the paper's full design with 5 seeds, so its trial mix
is the paper's) into a temporary results directory with N workers and prints the wall
time, trials per second, the mean time of one trial and the projected time of the
``paper`` preset (10,000 trials) at that rate.

    PYTHONPATH=. python benchmarks/sweep.py                       # quick, all CPUs
    PYTHONPATH=. python benchmarks/sweep.py --workers 1 --seeds 1 # 1 seed of quick, in-process
    PYTHONPATH=. python benchmarks/sweep.py --preset paper        # the real thing
    PYTHONPATH=. python benchmarks/sweep.py --profile 20          # 20 trials under cProfile
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import io
import os
import pstats
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

import _paths  # noqa: E402,F401  (project importable, this folder unshadowed)

from headless.sweep import Preset, load_preset, run_batch, run_sweep


def _minutes(seconds: float) -> str:
    return f"{seconds:.0f} s ({seconds / 60:.1f} min)"


def _spread(preset: Preset, count: int) -> list:
    """``count`` trials spread evenly over the design (every guard mode, level, ...)."""
    specs = preset.specs()
    step = max(1, len(specs) // count)
    return specs[::step][:count]


def profile(preset: Preset, count: int, top: int, use_pyinstrument: bool) -> None:
    """Run ``count`` trials in this process under a profiler and print the top entries."""
    specs = _spread(preset, count)
    run_batch(specs[:1])  # warm the level and graph caches: profile trials, not set-up
    if use_pyinstrument:
        from pyinstrument import Profiler

        profiler = Profiler()
        profiler.start()
        run_batch(specs)
        profiler.stop()
        print(profiler.output_text(unicode=False, color=False))
        return
    prof = cProfile.Profile()
    started = time.perf_counter()
    prof.runcall(run_batch, specs)
    elapsed = time.perf_counter() - started
    print(f"{len(specs)} trials in {elapsed:.2f} s under cProfile "
          f"({1000 * elapsed / len(specs):.1f} ms per trial, profiler overhead included)")
    stream = io.StringIO()
    pstats.Stats(prof, stream=stream).sort_stats("cumulative").print_stats(top)
    stream.write("\n--- by own time ---\n")
    pstats.Stats(prof, stream=stream).sort_stats("tottime").print_stats(top)
    print(stream.getvalue())


def bench(preset: Preset, workers: int, keep: Path | None) -> None:
    """Run the preset with ``workers`` and print the figures."""
    paper = load_preset("paper")
    with tempfile.TemporaryDirectory(prefix="stealth-bench-") as tmp:
        out = keep or Path(tmp) / "results"
        started = time.perf_counter()
        result = run_sweep(preset, out, workers=workers, progress=True)
        wall = time.perf_counter() - started
        db = sqlite3.connect(out / "results.sqlite")
        per_trial = db.execute("SELECT AVG(wall_time), COUNT(*) FROM trials "
                               "WHERE error IS NULL").fetchone()
        by_mode = db.execute("SELECT abstraction, guards, AVG(wall_time) * 1000, COUNT(*) "
                             "FROM trials WHERE error IS NULL GROUP BY abstraction, guards "
                             "ORDER BY abstraction, guards").fetchall()
        db.close()
    ran = result.finished + result.failed
    rate = ran / wall if wall > 0 else float("nan")
    print()
    print(f"preset {preset.name}: {ran} trials ({result.failed} failed, {result.skipped} "
          f"skipped) with {workers} worker{'s' * (workers != 1)} on {os.cpu_count()} CPUs")
    print(f"wall time            {wall:.2f} s (including pool start-up)")
    print(f"throughput           {rate:.1f} trials/s")
    if per_trial[0] is not None:
        print(f"one trial (in-worker) {1000 * per_trial[0]:.1f} ms mean")
        print(f"parallel efficiency  {per_trial[0] * rate / workers:.2f} "
              "(trial time x throughput / workers)")
    print(f"projected paper      {_minutes(paper.n_trials / rate)} for {paper.n_trials} trials "
          f"at this rate" + ("" if set(preset.guards) == set(paper.guards)
                             and set(preset.levels) == set(paper.levels)
                             else " (this preset's trial mix differs from the paper's)"))
    print("\nmean trial time by abstraction and guard mode (ms):")
    for abstraction, guards, ms, n in by_mode:
        print(f"  {abstraction:<10}{guards:<11}{ms:7.1f}  ({n} trials)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="quick", help="preset name or TOML file")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--seeds", type=int, default=None,
                        help="use only the first N seeds of the preset (same trial mix)")
    parser.add_argument("--keep", type=Path, default=None,
                        help="write the results here instead of a temporary directory")
    parser.add_argument("--profile", type=int, nargs="?", const=20, default=None, metavar="N",
                        help="profile N trials in-process instead of benchmarking (default 20)")
    parser.add_argument("--pyinstrument", action="store_true",
                        help="with --profile: use pyinstrument instead of cProfile")
    parser.add_argument("--top", type=int, default=25, help="profile entries to print")
    args = parser.parse_args(argv)

    preset = load_preset(args.preset)
    if args.seeds:
        preset = dataclasses.replace(preset, seeds=preset.seeds[: args.seeds])
    if args.profile:
        profile(preset, args.profile, args.top, args.pyinstrument)
    else:
        bench(preset, args.workers, args.keep)
    return 0


if __name__ == "__main__":
    sys.exit(main())
