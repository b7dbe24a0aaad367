"""Per-decision cost of the guard modes and player policies (run by hand).

    PYTHONPATH=. python benchmarks/ai.py [--repeat 2000] [--levels maze miami]

For every bundled level in both abstractions (those that load) plus a synthetic 26×39 grid
with random holes, prints the median time of:

* ``pf tick+decide``: one AI tick of the shared field followed by one guard decision —
  field update, potential, kernel (sparse matrix-vector product) and argmin. The target is
  ≤ 50 µs. In a trial the tick runs once per second and guards decide ~6 times per second,
  so most decisions only pay ``pf decide`` (cached K).
* ``pf decide``: a decision on an unchanged field (K cached since the tick).
* ``fsm``, ``staleness`` decisions (patrol), ``maxmin`` and ``safetygraph`` player decisions.
* ``build``: the one-off per-graph precomputation of the field matrices, in ms.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable

import numpy as np

import _paths  # noqa: E402,F401  (project importable, this folder unshadowed)

from ai import make_guard_ai, make_player_policy  # noqa: E402
from ai.field_matrices import _MATRIX_CACHE  # noqa: E402
from ai.view import WorldView  # noqa: E402
from navmesh.graph import NodeGraph  # noqa: E402


def _view(graph: NodeGraph, guards: np.ndarray, player: int, sighting: int | None) -> WorldView:
    return WorldView.at_nodes(graph, guards, player, sighting=sighting)


def _median_us(call: Callable[[int], object], repeat: int) -> float:
    """Median wall time of ``call(k)`` over ``repeat`` calls, in µs (after a warm-up)."""
    for k in range(min(50, repeat)):
        call(k)
    times = []
    for k in range(repeat):
        start = time.perf_counter_ns()
        call(k)
        times.append(time.perf_counter_ns() - start)
    return statistics.median(times) / 1000.0


def bench_graph(name: str, graph: NodeGraph, repeat: int) -> dict[str, float]:
    """Median µs per decision of every controller on ``graph``."""
    rng = np.random.default_rng(0)
    views = []
    for k in range(repeat):
        guards = rng.choice(graph.n, 3, replace=False)
        player = int(rng.integers(graph.n))
        views.append(_view(graph, guards, player, player if k % 10 == 0 else None))
    result: dict[str, float] = {"nodes": graph.n}

    _MATRIX_CACHE.pop(graph, None)
    pf = make_guard_ai("pf")
    start = time.perf_counter()
    pf.reset(graph, np.random.default_rng(1), 3)
    result["build ms"] = (time.perf_counter() - start) * 1000

    def pf_full(k: int) -> None:
        pf.tick(views[k % repeat], 1.0)
        pf.decide(0, views[k % repeat])

    result["pf tick+decide"] = _median_us(pf_full, repeat)
    result["pf decide"] = _median_us(lambda k: pf.decide(k % 3, views[k % repeat]), repeat)

    for mode in ("fsm", "staleness"):
        guards_ai = make_guard_ai(mode)
        guards_ai.reset(graph, np.random.default_rng(1), 3)
        result[mode] = _median_us(lambda k, g=guards_ai: g.decide(k % 3, views[k % repeat]), repeat)
    for policy in ("maxmin", "safetygraph"):
        player = make_player_policy(policy)
        player.reset(graph, np.random.default_rng(1))
        result[policy] = _median_us(lambda k, p=player: p.decide(views[k % repeat]), repeat)
    return result


def graphs(levels: list[str] | None) -> list[tuple[str, NodeGraph]]:
    """The bundled levels in both abstractions (those that load) and a synthetic grid."""
    found: list[tuple[str, NodeGraph]] = []
    try:
        from navmesh.graph import build_graph
        from navmesh.level import bundled_level_names, load_level
    except ImportError as error:  # the level loader is not there yet
        print(f"(no bundled levels: {error})", file=sys.stderr)
    else:
        for level_name in levels or bundled_level_names():
            try:
                level = load_level(level_name)
            except Exception as error:  # noqa: BLE001 — report and go on
                print(f"(skipping {level_name}: {error})", file=sys.stderr)
                continue
            for abstraction in ("grid", "partition"):
                try:
                    found.append((f"{level_name}/{abstraction}", build_graph(level, abstraction)))
                except Exception as error:  # noqa: BLE001
                    print(f"(skipping {level_name}/{abstraction}: {error})", file=sys.stderr)
    rng = np.random.default_rng(26)
    occupancy = rng.random((26, 39)) > 0.2
    synthetic = NodeGraph.from_grid(occupancy, 1.0)
    # keep the component of the first node so every pair is connected, like a valid level
    keep = synthetic.reachable_from(0)
    cells = synthetic.node_cell[~keep]
    occupancy[cells[:, 0], cells[:, 1]] = False
    found.append(("synthetic 26x39 grid", NodeGraph.from_grid(occupancy, 1.0)))
    return found


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeat", type=int, default=2000, help="timed calls per measurement")
    parser.add_argument("--levels", nargs="*", help="bundled level names (default: all)")
    args = parser.parse_args(argv)
    columns = [
        "nodes",
        "build ms",
        "pf tick+decide",
        "pf decide",
        "fsm",
        "staleness",
        "maxmin",
        "safetygraph",
    ]
    print("median µs per decision (build: ms once per graph)")
    print(f"{'graph':<24}" + "".join(f"{c:>16}" for c in columns))
    for name, graph in graphs(args.levels):
        row = bench_graph(name, graph, args.repeat)
        cells = [f"{row[c]:>16.0f}" if c == "nodes" else f"{row[c]:>16.1f}" for c in columns]
        print(f"{name:<24}" + "".join(cells), flush=True)


if __name__ == "__main__":
    main()
