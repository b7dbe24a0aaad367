"""The batch engine against the pymunk engine on the paper's trials (run by hand).

    python benchmarks/batch.py [--seeds 3] [--levels maze miami] [--check 40]

Runs every paper trial of the given levels and seeds (both abstractions, the five guard
modes, both players, both scenarios) on the batch engine, one batch per level ×
abstraction (at most 256 trials each), and the same trials on the pymunk engine, in this
process, one after the other. Prints CPU seconds and trials per CPU second of each, their
ratio, the batch engine's peak memory (RSS high-water mark, MB), and how many trials of
the first ``--check`` per batch were equal in every metric and heatmap. Numba compiles
its kernels (or loads them from its cache) before the clock starts.
Targets (issue 40): ratio ≥ 10 (stage 2); peak memory ≤ 2 GB at B = 256.
"""

from __future__ import annotations

import argparse
import resource
import time

import _paths  # noqa: F401  (project importable, this folder unshadowed)
from game.batch import run_trials
from game.trial import run_trial
from headless.presets import load_preset


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--levels", nargs="*", default=None)
    parser.add_argument("--check", type=int, default=1000,
                        help="compare at most this many trials per batch with the reference")
    args = parser.parse_args()
    specs = list(load_preset("paper").with_seeds(args.seeds).specs())
    groups: dict[tuple[str, str], list] = {}
    for spec in specs:
        if args.levels is None or spec.level in args.levels:
            groups.setdefault((spec.level, spec.abstraction), []).append(spec)
    run_trials(next(iter(groups.values()))[:1])  # compile or load the kernels
    batch_cpu = reference_cpu = 0.0
    trials = equal = compared = 0
    for (level, abstraction), group in groups.items():
        for start in range(0, len(group), 256):
            part = group[start:start + 256]
            clock = time.process_time()
            rows = run_trials(part)
            spent = time.process_time() - clock
            batch_cpu += spent
            checked = part[:args.check]
            clock = time.process_time()
            refs = [run_trial(s) for s in checked]
            ref_spent = time.process_time() - clock
            reference_cpu += ref_spent * len(part) / max(1, len(checked))
            same = sum((r["metrics"], r["visits"], r["attacks"]) ==
                       (f["metrics"], f["visits"], f["attacks"]) for r, f in zip(rows, refs))
            trials, equal, compared = trials + len(part), equal + same, compared + len(checked)
            print(f"{level:11s} {abstraction:9s} B={len(part):3d}  batch {spent:6.1f} s  "
                  f"pymunk {ref_spent * len(part) / max(1, len(checked)):6.1f} s  "
                  f"equal {same}/{len(checked)}", flush=True)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\n{trials} trials: batch {trials / batch_cpu:.2f} trials per CPU s, pymunk "
          f"{trials / reference_cpu:.2f}; ratio {reference_cpu / batch_cpu:.2f}x; "
          f"equal {equal} of {compared} compared; peak RSS {peak:.0f} MB")


if __name__ == "__main__":
    main()
