"""Navmesh path quality and query time, against the exact oracle and pynavmesh (run by hand).

    python benchmarks/navmesh.py [--pairs 500] [--levels maze miami] [--no-methods]

For every bundled level (plus a synthetic 28×39 level with 10 holes), on the default mesh
and the same random point pairs:

* ``exact``  — :func:`navmesh.query.find_path` (default): corridor of the true shortest path.
* ``astar``  — ``find_path(..., exact=False)``: A* with portal entry-point costs + funnel.
* ``pynavmesh`` — the pure-Python ``pynavmesh`` package on the SAME triangles (passed
  clockwise in its XZ plane, which it needs) with its own A* + funnel.

Each: path length ÷ Euclidean shortest path (``tests/oracle.py``, the test oracle)
as mean / p95 / max, and the median query time.  A second table compares the
triangulation methods (A*-only quality is what depends on the mesh).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import _paths  # noqa: F401  (project importable, this folder unshadowed)
import numpy as np
import shapely
from shapely import Polygon, box
from shapely.affinity import rotate

from navmesh.mesh import METHODS, NavMesh
from navmesh.query import find_path
from oracle import VisibilityGraph


def synthetic_level(seed: int = 7) -> Polygon:
    """A 28×39 room with 10 rotated/axis-aligned obstacles (like MEASURED.md's test level)."""
    rng = np.random.default_rng(seed)
    holes: list[Polygon] = []
    while len(holes) < 10:
        c = rng.uniform([2, 2], [37, 26])
        h = box(*(c - rng.uniform(0.5, 3.0, 2)), *(c + rng.uniform(0.5, 3.0, 2)))
        if rng.random() < 0.4:
            h = rotate(h, rng.uniform(0, 90))
        if box(0.5, 0.5, 38.5, 27.5).contains(h) and all(h.distance(o) > 0.5 for o in holes):
            holes.append(h)
    return Polygon(box(0, 0, 39, 28).exterior.coords, [h.exterior.coords for h in holes])


def levels(names: list[str] | None) -> list[tuple[str, Polygon]]:
    out = []
    try:
        from navmesh.level import bundled_level_names, load_level

        for name in names or bundled_level_names():
            if name != "synthetic":
                out.append((name, load_level(name).walkable))
    except ImportError:  # no level loader yet
        pass
    if not names or "synthetic" in names:
        out.append(("synthetic", synthetic_level()))
    return out


def sample_pairs(poly: Polygon, n: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    minx, miny, maxx, maxy = poly.bounds
    pts = np.zeros((0, 2))
    while len(pts) < 2 * n:
        p = rng.uniform([minx, miny], [maxx, maxy], size=(8 * n, 2))
        pts = np.vstack([pts, p[shapely.contains_xy(poly, p[:, 0], p[:, 1])]])
    return pts[: 2 * n].reshape(n, 2, 2)


def timed(fn: Callable[[np.ndarray, np.ndarray], float], pairs: np.ndarray) -> tuple[np.ndarray, float]:
    """Lengths and the median time per call (µs); every pair is run once to warm up."""
    for s, g in pairs[:20]:
        fn(s, g)
    lengths, times = [], []
    for s, g in pairs:
        t0 = time.perf_counter()
        length = fn(s, g)
        times.append(time.perf_counter() - t0)
        lengths.append(length)
    return np.asarray(lengths), statistics.median(times) * 1e6


def pynavmesh_search(mesh: NavMesh) -> Callable[[np.ndarray, np.ndarray], float] | None:
    """pynavmesh on our triangles: XZ plane (z = our y), triangles passed clockwise there."""
    try:
        from pathfinder.navmesh import Navmesh
    except ImportError:
        return None
    verts = [(float(x), 0.0, float(y)) for x, y in mesh.vertices]
    nm = Navmesh(verts, mesh.triangles[:, ::-1].tolist())

    def search(s: np.ndarray, g: np.ndarray) -> float:
        path = nm.search_path((float(s[0]), 0.0, float(s[1])), (float(g[0]), 0.0, float(g[1])))
        if not path:
            return float("nan")
        p = np.asarray(path)[:, [0, 2]]
        return float(np.hypot(*np.diff(p, axis=0).T).sum())

    return search


def pynavmesh_paths_ok(mesh: NavMesh, poly: Polygon, pairs: np.ndarray) -> tuple[int, int]:
    """(paths that start/end at the query points and stay inside, paths checked)."""
    from pathfinder.navmesh import Navmesh

    nm = Navmesh([(float(x), 0.0, float(y)) for x, y in mesh.vertices], mesh.triangles[:, ::-1].tolist())
    area = poly.buffer(1e-6)
    ok = 0
    for s, g in pairs:
        path = nm.search_path((float(s[0]), 0.0, float(s[1])), (float(g[0]), 0.0, float(g[1])))
        if not path:
            continue
        p = np.asarray(path)[:, [0, 2]]
        if np.allclose(p[0], s) and np.allclose(p[-1], g) and area.covers(shapely.LineString(p)):
            ok += 1
    return ok, len(pairs)


def stats(r: np.ndarray) -> str:
    r = r[np.isfinite(r)]
    return f"{r.mean():.4f} / {np.percentile(r, 95):.4f} / {r.max():.4f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pairs", type=int, default=500, help="random point pairs per level")
    ap.add_argument("--levels", nargs="*", help="bundled level names (and/or 'synthetic')")
    ap.add_argument("--no-methods", action="store_true", help="skip the triangulation comparison")
    args = ap.parse_args()

    warm = NavMesh.build(box(0, 0, 4, 4).difference(box(1, 1, 3, 3)))
    find_path(warm, (0.5, 0.5), (3.5, 3.5))  # first tables build imports scipy: keep it out of the timings
    rows, speedups = [], []
    method_rows: dict[str, list] = {m: [] for m in METHODS}
    for name, poly in levels(args.levels):
        pairs = sample_pairs(poly, args.pairs)
        oracle = VisibilityGraph(poly)
        t0 = time.perf_counter()
        best = np.array([oracle.distance(s, g) for s, g in pairs])
        oracle_us = (time.perf_counter() - t0) / len(pairs) * 1e6
        t0 = time.perf_counter()
        mesh = NavMesh.build(poly)
        build_ms = (time.perf_counter() - t0) * 1e3
        t0 = time.perf_counter()
        find_path(mesh, pairs[0, 0], pairs[0, 1])  # builds the exact-path tables
        tables_ms = (time.perf_counter() - t0) * 1e3
        loc = [mesh.locate(float(x), float(y)) for x, y in pairs.reshape(-1, 2)]
        t0 = time.perf_counter()
        for x, y in pairs.reshape(-1, 2).tolist():
            mesh.locate(x, y)
        locate_us = (time.perf_counter() - t0) / (2 * len(pairs)) * 1e6
        assert min(loc) >= 0
        ex, ex_us = timed(lambda s, g, mesh=mesh: find_path(mesh, s, g).length, pairs)
        sa, sa_us = timed(lambda s, g, mesh=mesh: find_path(mesh, s, g, exact=False).length, pairs)
        row = [name, len(mesh), build_ms, tables_ms, locate_us, stats(ex / best), ex_us, stats(sa / best), sa_us]
        pyn = pynavmesh_search(mesh)
        if pyn is not None:
            pl, p_us = timed(pyn, pairs)
            ok, n = pynavmesh_paths_ok(mesh, poly, pairs[:100])
            fails = int(np.sum(~np.isfinite(pl)))
            row += [stats(pl / best), p_us, f"{ok}/{n}", fails]
            speedups.append((ex_us / p_us, sa_us / p_us))
        rows.append(row + [oracle_us])
        if not args.no_methods:
            for method in METHODS:
                t0 = time.perf_counter()
                m = NavMesh.build(poly, method=method)
                bms = (time.perf_counter() - t0) * 1e3
                ls, us = timed(lambda s, g, m=m: find_path(m, s, g, exact=False).length, pairs)
                le, use = timed(lambda s, g, m=m: find_path(m, s, g).length, pairs)
                method_rows[method].append((name, len(m), bms, ls / best, us, le / best, use))

    print(f"\n## Default mesh ({NavMesh.build.__kwdefaults__['method']}), {args.pairs} random pairs per level")
    print("length ÷ optimal as mean / p95 / max; times are medians per query\n")
    head = "| level | tris | build ms | tables ms | locate µs | exact ratio | exact µs | A* ratio | A* µs |"
    if speedups:
        head += " pynavmesh ratio | pynavmesh µs | pynavmesh paths ok | no path |"
    print(head + " oracle µs |")
    print("|" + "---|" * (head.count("|") - 1 + 1))
    for r in rows:
        cells = [r[0], str(r[1]), f"{r[2]:.1f}", f"{r[3]:.1f}", f"{r[4]:.1f}", r[5], f"{r[6]:.0f}", r[7], f"{r[8]:.0f}"]
        if speedups:
            cells += [r[9], f"{r[10]:.0f}", r[11], str(r[12])]
        cells.append(f"{r[-1]:.0f}")
        print("| " + " | ".join(cells) + " |")
    if speedups:
        e = statistics.median(s[0] for s in speedups)
        a = statistics.median(s[1] for s in speedups)
        print(f"\nmedian query time ÷ pynavmesh's (median over levels): exact {e:.2f}, A* {a:.2f}")

    if not args.no_methods:
        print("\n## Triangulation methods (all levels pooled)\n")
        print("| method | triangles per level | build ms | A*-only ratio | A* µs | exact ratio | exact µs |")
        print("|---|---|---|---|---|---|---|")
        for method, entries in method_rows.items():
            tris = ", ".join(f"{n}:{t}" for n, t, *_ in entries)
            bms = statistics.median(e[2] for e in entries)
            ra = np.concatenate([e[3] for e in entries])
            re = np.concatenate([e[5] for e in entries])
            print(
                f"| {method} | {tris} | {bms:.1f} | {stats(ra)} | {statistics.median(e[4] for e in entries):.0f} "
                f"| {stats(re)} | {statistics.median(e[6] for e in entries):.0f} |"
            )


if __name__ == "__main__":
    main()
