"""Scale benchmark: generated building levels from 10^3 to 10^6 cells (issue 13).

For every size and form (grid / polygon) it writes the level (navmesh/buildings.py), then
runs each trial in its own subprocess and reads that process's peak RSS (``ru_maxrss``):
graph build time, one 60-s trial's wall time, peak RSS; PF vs MaxMin at every size, every
guard mode and player policy at ``--all-modes-at``; and the same figures on a bundled level
for the ratio; and ``stealth levels`` on each level file. CPU seconds are reported beside
wall seconds because on a shared machine the wall time mostly measures the other jobs.
Run: ``python benchmarks/scale.py --sizes 1e3 1e4 1e5 [--abstractions grid] [--jobs 2]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import _paths  # noqa: F401  (project importable, this folder unshadowed)

#: children import this checkout, not whatever the editable install points at
ENV = {**os.environ, "PYTHONPATH": str(_paths.ROOT)}

CHILD = r"""
import json, resource, sys, time
from navmesh.level import load_level
from navmesh.graph import build_graph
from game.trial import TrialSpec, run_trial
path, abstraction, guards, player = sys.argv[1:5]
t, c = time.perf_counter(), time.process_time()
graph = build_graph(load_level(path), abstraction)
build, build_cpu = time.perf_counter() - t, time.process_time() - c
t, c = time.perf_counter(), time.process_time()
run_trial(TrialSpec(level=path, abstraction=abstraction, guards=guards, player=player))
trial, cpu = time.perf_counter() - t, time.process_time() - c
print(json.dumps({"nodes": graph.n, "build_s": build, "build_cpu_s": build_cpu, "trial_s": trial, "cpu_s": cpu,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

MODES = ("pf", "random", "cheat", "fsm", "staleness")
POLICIES = ("maxmin", "safetygraph")


def measure(path: str, abstraction: str, guards: str, player: str, timeout: float) -> dict:
    """One trial in a fresh interpreter; its figures, or the reason it did not finish."""
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, path, abstraction, guards, player],
                              capture_output=True, text=True, timeout=timeout, env=ENV)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:g} s"}
    if done.returncode:
        return {"error": (done.stderr.strip().splitlines() or ["?"])[-1][:120]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def levels_time(path: str, timeout: float) -> str:
    """Wall and CPU seconds of ``stealth levels`` on one level file (a fresh interpreter)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, "-m", "headless.cli", "levels", path],
                              capture_output=True, text=True, timeout=timeout, env=ENV)
    except subprocess.TimeoutExpired:
        return f"timeout after {timeout:g} s"
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    if done.returncode:
        return (done.stderr.strip().splitlines() or ["?"])[-1][:120]
    return f"{wall:.1f} s wall, {cpu:.1f} s CPU"


def main() -> None:
    from navmesh.buildings import building_level

    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e3, 1e4, 1e5, 1e6])
    parser.add_argument("--forms", nargs="+", default=["grid", "polygon"])
    parser.add_argument("--abstractions", nargs="+", default=["grid", "partition"])
    parser.add_argument("--all-modes-at", type=float, default=1e5)
    parser.add_argument("--all-modes-forms", nargs="+", default=["grid"],
                        help="forms whose level at --all-modes-at runs every mode/policy")
    parser.add_argument("--timeout", type=float, default=600.0)
    parser.add_argument("--jobs", type=int, default=1, help="trials run side by side")
    args = parser.parse_args()
    out = Path(tempfile.mkdtemp(prefix="scale-"))
    jobs: list[tuple[str, str, str, str, str, str]] = [
        ("tlou (paper)", "file", "tlou", ab, "pf", "maxmin") for ab in args.abstractions
    ]
    for cells in args.sizes:
        side = int(round(cells**0.5))
        for form in args.forms:
            path = out / f"building-{side}-{form}.json"
            t = time.perf_counter()
            path.write_text(json.dumps(building_level(side, side, seed=0, form=form)))
            made = time.perf_counter() - t
            print(f"{side}x{side} {form}: generated in {made:.1f} s; stealth levels: "
                  f"{levels_time(str(path), args.timeout)}", flush=True)
            pairs = [("pf", "maxmin")]
            if abs(cells - args.all_modes_at) < 1 and form in args.all_modes_forms:
                pairs = [(m, p) for m in MODES for p in POLICIES]
            for ab in args.abstractions:
                for guards, player in pairs:
                    jobs.append((f"{side}x{side}", form, str(path), ab, guards, player))
    def run(job: tuple[str, str, str, str, str, str]) -> dict:
        result = measure(job[2], job[3], job[4], job[5], args.timeout)
        print(_line((job[0], job[1], job[3], job[4], job[5], result), {}), flush=True)
        return result

    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        results = list(pool.map(run, jobs))
    reference = {j[3]: r for j, r in zip(jobs, results) if j[1] == "file"}
    rows = [(j[0], j[1], j[3], j[4], j[5], r) for j, r in zip(jobs, results)]
    print("\n| level | form | abstraction | guards | player | nodes | build s (CPU) | trial s (wall) "
          "| trial s (CPU) | peak MB | CPU × paper |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(_line(row, reference))


def _line(row: tuple, reference: dict) -> str:
    name, form, ab, guards, player, r = row
    if "error" in r:
        return f"| {name} | {form} | {ab} | {guards} | {player} | — | — | {r['error']} | — | — | — |"
    ref = reference.get(ab, {}).get("cpu_s")
    ratio = f"{r['cpu_s'] / ref:.1f}" if ref else "—"
    return (f"| {name} | {form} | {ab} | {guards} | {player} | {r['nodes']} | {r['build_cpu_s']:.2f} "
            f"| {r['trial_s']:.2f} | {r['cpu_s']:.2f} | {r['peak_mb']:.0f} | {ratio} |")


if __name__ == "__main__":
    main()
