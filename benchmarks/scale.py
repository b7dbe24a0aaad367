"""Scale benchmark: generated building levels from 10^3 to 10^6 cells (issue 13).

For every size and form (grid / polygon) it writes the level (navmesh/buildings.py), then
runs each trial in its own subprocess and reads that process's peak RSS (``ru_maxrss``):
graph build time, one 60-s trial's wall and CPU time, peak RSS; PF vs MaxMin at every
size, every guard mode and player policy at ``--all-modes-at``; the same figures on a
bundled level for the ratio; ``stealth levels`` on each level file; and the per-trial
growth from the smallest to the largest size. CPU seconds are reported beside wall seconds
because on a shared machine the wall time mostly measures the other jobs.

The child builds the graph through the per-process cache the trial uses (``cached_level``
+ ``graph_for``), so the trial does not build it again: *build* is the graph, *trial* the
60-s run (which builds the body's path mesh on the partition), *total* both.

Run: ``python benchmarks/scale.py`` (all sizes, about 15 min on a quiet machine) and
``--write docs/scale.md`` to put the tables between the ``<!-- scale:begin -->`` /
``<!-- scale:end -->`` markers there; ``--sizes 1e3 1e4`` for a short run.
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
from navmesh.level import cached_level
from navmesh.graph import graph_for
from game.trial import TrialSpec, run_trial
path, abstraction, guards, player = sys.argv[1:5]
t, c = time.perf_counter(), time.process_time()
graph = graph_for(cached_level(path), abstraction)  # the cache run_trial then hits
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


def levels_time(path: str, timeout: float) -> dict:
    """Wall and CPU seconds of ``stealth levels`` on one level file (a fresh interpreter)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, "-m", "headless.cli", "levels", path],
                              capture_output=True, text=True, timeout=timeout, env=ENV)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:g} s"}
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    if done.returncode:
        return {"error": (done.stderr.strip().splitlines() or ["?"])[-1][:120]}
    return {"wall_s": wall, "cpu_s": cpu}


Job = tuple[str, str, str, str, str, str]  # name, form, path, abstraction, guards, player


def main() -> None:
    from navmesh.buildings import building_level

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e3, 1e4, 1e5, 1e6])
    parser.add_argument("--forms", nargs="+", default=["grid", "polygon"])
    parser.add_argument("--abstractions", nargs="+", default=["grid", "partition"])
    parser.add_argument("--all-modes-at", type=float, default=1e5)
    parser.add_argument("--all-modes-forms", nargs="+", default=["grid"],
                        help="forms whose level at --all-modes-at runs every mode/policy")
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--jobs", type=int, default=1, help="trials run side by side")
    parser.add_argument("--write", metavar="MD", help="replace the tables between the scale markers of MD")
    args = parser.parse_args()
    out = Path(tempfile.mkdtemp(prefix="scale-"))
    jobs: list[Job] = [("tlou (paper)", "file", "tlou", ab, "pf", "maxmin") for ab in args.abstractions]
    levels: list[tuple[str, str, dict]] = []
    for cells in args.sizes:
        side = int(round(cells**0.5))
        for form in args.forms:
            path = out / f"building-{side}-{form}.json"
            path.write_text(json.dumps(building_level(side, side, seed=0, form=form)))
            timing = levels_time(str(path), args.timeout)
            levels.append((f"{side}x{side}", form, timing))
            print(f"{side}x{side} {form}: stealth levels {_seconds(timing)}", flush=True)
            pairs = [("pf", "maxmin")]
            if abs(cells - args.all_modes_at) < 1 and form in args.all_modes_forms:
                pairs = [(m, p) for m in MODES for p in POLICIES]
            for ab in args.abstractions:
                for guards, player in pairs:
                    jobs.append((f"{side}x{side}", form, str(path), ab, guards, player))

    def run(job: Job) -> dict:
        result = measure(job[2], job[3], job[4], job[5], args.timeout)
        print(_line(job, result, {}), flush=True)
        return result

    with ThreadPoolExecutor(max(1, args.jobs)) as pool:
        results = list(pool.map(run, jobs))
    text = report(jobs, results, levels)
    print("\n" + text)
    if args.write:
        write_between_markers(Path(args.write), text)
        print(f"wrote the tables into {args.write}")


def report(jobs: list[Job], results: list[dict], levels: list[tuple[str, str, dict]]) -> str:
    """The markdown of docs/scale.md's benchmark section: trials, ``stealth levels``, growth."""
    load = os.getloadavg()[0]
    lines = [f"Measured {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {os.cpu_count()} cores, "
             f"load average {load:.1f} at the end (`python benchmarks/scale.py`).", "",
             "| level | form | abstraction | guards | player | nodes | build s (CPU) | trial s (wall) "
             "| trial s (CPU) | total s (wall) | peak MB | CPU × paper |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    reference = {j[3]: r for j, r in zip(jobs, results) if j[1] == "file"}
    lines += [_line(j, r, reference) for j, r in zip(jobs, results)]
    lines += ["", "`stealth levels` on each level file (the partition mesh of Table 1; wall / CPU seconds):", "",
              "| level | form | stealth levels |", "|---|---|---|"]
    lines += [f"| {name} | {form} | {_seconds(t)} |" for name, form, t in levels]
    growth = _growth(jobs, results)
    if growth:
        lines += ["", "Per-trial CPU time, PF vs MaxMin, from the smallest to the largest level "
                  "(×cells → ×time; linear or better when ×time ≤ ×cells):", "",
                  "| form | abstraction | cells | trial s (CPU) | × cells | × time |", "|---|---|---|---|---|---|"]
        lines += growth
    return "\n".join(lines)


def _growth(jobs: list[Job], results: list[dict]) -> list[str]:
    rows = []
    for form in dict.fromkeys(j[1] for j in jobs if j[1] != "file"):
        for ab in dict.fromkeys(j[3] for j in jobs):
            runs = [(int(j[0].split("x")[0]) ** 2, r) for j, r in zip(jobs, results)
                    if j[1] == form and j[3] == ab and j[4:] == ("pf", "maxmin") and "error" not in r]
            runs = [(c, r) for c, r in runs if c >= 5000]  # from 10^4: the smallest are start-up
            if len(runs) < 2:
                continue
            base_cells, base = runs[0]
            for cells, r in runs:
                rows.append(f"| {form} | {ab} | {cells} | {r['cpu_s']:.2f} | {cells / base_cells:.0f} "
                            f"| {r['cpu_s'] / base['cpu_s']:.1f} |")
    return rows


def write_between_markers(path: Path, text: str) -> None:
    """Replace what stands between ``<!-- scale:begin -->`` and ``<!-- scale:end -->`` in ``path``."""
    from headless.analysis.markers import replace_marked

    begin, end = "<!-- scale:begin -->", "<!-- scale:end -->"
    if not replace_marked(path, begin, end, text + "\n"):
        raise SystemExit(f"scale.py: error: {path} has no {begin} ... {end} markers")


def _seconds(t: dict) -> str:
    return t["error"] if "error" in t else f"{t['wall_s']:.1f} / {t['cpu_s']:.1f}"


def _line(job: Job, r: dict, reference: dict) -> str:
    name, form, _, ab, guards, player = job
    if "error" in r:
        return f"| {name} | {form} | {ab} | {guards} | {player} | — | — | {r['error']} | — | — | — | — |"
    ref = reference.get(ab, {}).get("cpu_s")
    ratio = f"{r['cpu_s'] / ref:.1f}" if ref else "—"
    return (f"| {name} | {form} | {ab} | {guards} | {player} | {r['nodes']} | {r['build_cpu_s']:.2f} "
            f"| {r['trial_s']:.2f} | {r['cpu_s']:.2f} | {r['build_s'] + r['trial_s']:.2f} | {r['peak_mb']:.0f} "
            f"| {ratio} |")


if __name__ == "__main__":
    main()
