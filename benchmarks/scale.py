"""Scale benchmark: generated building levels from 10^3 to 10^6 cells (issue 13).

For every size and form (grid / polygon) it writes the level (navmesh/buildings.py), then
runs each trial in its own subprocess and reads that process's peak RSS (``ru_maxrss``):
graph build time, one 60-s trial's wall time, peak RSS; PF vs MaxMin at every size, every
guard mode and player policy at ``--all-modes-at``; and the same figures on a bundled level
for the ratio. Run: ``python benchmarks/scale.py --sizes 1e3 1e4 1e5 [--abstractions grid]``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, resource, sys, time
from navmesh.level import load_level
from navmesh.graph import build_graph
from game.trial import TrialSpec, run_trial
path, abstraction, guards, player = sys.argv[1:5]
t = time.perf_counter()
graph = build_graph(load_level(path), abstraction)
build = time.perf_counter() - t
t = time.perf_counter()
run_trial(TrialSpec(level=path, abstraction=abstraction, guards=guards, player=player))
trial = time.perf_counter() - t
print(json.dumps({"nodes": graph.n, "build_s": build, "trial_s": trial,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

MODES = ("pf", "random", "cheat", "fsm", "staleness")
POLICIES = ("maxmin", "safetygraph")


def measure(path: str, abstraction: str, guards: str, player: str, timeout: float) -> dict:
    """One trial in a fresh interpreter; its figures, or the reason it did not finish."""
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, path, abstraction, guards, player],
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:g} s"}
    if done.returncode:
        return {"error": (done.stderr.strip().splitlines() or ["?"])[-1][:120]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    from navmesh.buildings import building_level

    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e3, 1e4, 1e5, 1e6])
    parser.add_argument("--forms", nargs="+", default=["grid", "polygon"])
    parser.add_argument("--abstractions", nargs="+", default=["grid", "partition"])
    parser.add_argument("--all-modes-at", type=float, default=1e5)
    parser.add_argument("--timeout", type=float, default=600.0)
    args = parser.parse_args()
    out = Path(tempfile.mkdtemp(prefix="scale-"))
    rows = []
    reference = {ab: measure("tlou", ab, "pf", "maxmin", args.timeout) for ab in args.abstractions}
    for ab, ref in reference.items():
        rows.append(("tlou (paper)", "file", ab, "pf", "maxmin", ref))
    for cells in args.sizes:
        side = int(round(cells**0.5))
        for form in args.forms:
            path = out / f"building-{side}-{form}.json"
            path.write_text(json.dumps(building_level(side, side, seed=0, form=form)))
            pairs = [("pf", "maxmin")]
            if abs(cells - args.all_modes_at) < 1:
                pairs = [(m, p) for m in MODES for p in POLICIES]
            for ab in args.abstractions:
                for guards, player in pairs:
                    result = measure(str(path), ab, guards, player, args.timeout)
                    rows.append((f"{side}x{side}", form, ab, guards, player, result))
                    print(_line(rows[-1], reference), flush=True)
    print("\n| level | form | abstraction | guards | player | nodes | build s | trial s | peak MB | trial × paper |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(_line(row, reference))


def _line(row: tuple, reference: dict) -> str:
    name, form, ab, guards, player, r = row
    if "error" in r:
        return f"| {name} | {form} | {ab} | {guards} | {player} | — | — | {r['error']} | — | — |"
    ref = reference.get(ab, {}).get("trial_s")
    ratio = f"{r['trial_s'] / ref:.1f}" if ref else "—"
    return (f"| {name} | {form} | {ab} | {guards} | {player} | {r['nodes']} | {r['build_s']:.2f} "
            f"| {r['trial_s']:.2f} | {r['peak_mb']:.0f} | {ratio} |")


if __name__ == "__main__":
    main()
