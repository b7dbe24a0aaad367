"""Navmesh paths against the exact visibility-graph oracle (``tests/oracle.py``).

Quality criteria (issue): path length ÷ Euclidean shortest path over random point pairs,
mean ≤ 1.01 and max ≤ 1.05.  The default (exact) search must in fact match the oracle to
1e-9; the A*-only search (``exact=False``) must meet the criteria over the bundled and a
fixed set of generated levels.  Every path starts and ends at the query points and stays
in the walkable area.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely import LineString, Polygon, box

from navmesh.funnel import funnel
from navmesh.mesh import METHODS, NavMesh
from navmesh.query import NavPath, OutsideError, corridor, find_path
from oracle import VisibilityGraph

try:  # the polygon strategies live next door
    from tests.test_mesh import BUNDLED, grid_polygons, polygons, rect_with_holes
except ImportError:  # pragma: no cover - rootdir-less runs
    from test_mesh import BUNDLED, grid_polygons, polygons, rect_with_holes

LEVELS_DIR = Path(__file__).resolve().parents[1] / "assets" / "levels"


def sample_points(poly: Polygon, n: int, rng: np.random.Generator) -> np.ndarray:
    """n uniform random points of the polygon."""
    minx, miny, maxx, maxy = poly.bounds
    out = np.zeros((0, 2))
    while len(out) < n:
        p = rng.uniform([minx, miny], [maxx, maxy], size=(4 * n, 2))
        out = np.vstack([out, p[shapely.contains_xy(poly, p[:, 0], p[:, 1])]])
    return out[:n]


def check_path(poly: Polygon, path: NavPath, start: np.ndarray, goal: np.ndarray) -> None:
    """Endpoints, containment and the reported length."""
    pts = path.points
    assert pts.shape[1] == 2 and len(pts) >= 2
    assert tuple(pts[0]) == (float(start[0]), float(start[1]))
    assert tuple(pts[-1]) == (float(goal[0]), float(goal[1]))
    assert math.isclose(path.length, float(np.hypot(*np.diff(pts, axis=0).T).sum()), rel_tol=1e-12, abs_tol=1e-12)
    if len(pts) > 1 and path.length > 0:
        assert poly.buffer(1e-7).covers(LineString(pts)), "path leaves the walkable area"


def ratios(poly: Polygon, mesh: NavMesh, oracle: VisibilityGraph, pairs: np.ndarray, *, exact: bool) -> np.ndarray:
    out = []
    for s, g in pairs:
        path = find_path(mesh, s, g, exact=exact)
        check_path(poly, path, s, g)
        best = oracle.distance(s, g)
        out.append(path.length / best if best > 1e-12 else 1.0)
    r = np.asarray(out)
    assert r.min() >= 1.0 - 1e-9, "shorter than the Euclidean shortest path: a path cuts through a wall"
    return r


def in_triangle(mesh: NavMesh, t: int, p: np.ndarray, tol: float = 1e-9) -> bool:
    a, b, c = mesh.vertices[mesh.triangles[t]]
    for u, v in ((a, b), (b, c), (c, a)):
        e, w = v - u, p - u
        if e[0] * w[1] - e[1] * w[0] < -tol * float(np.hypot(*e)):
            return False
    return True


def random_pairs(poly: Polygon, n: int, seed: int) -> np.ndarray:
    return sample_points(poly, 2 * n, np.random.default_rng(seed)).reshape(n, 2, 2)


# ---------------------------------------------------------------- the oracle
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rect_with_holes(), st.integers(0, 2**16))
def test_oracle_visibility_matches_shapely(poly: Polygon, seed: int) -> None:
    """The vectorised segment test agrees with shapely's covers on generic segments."""
    vg = VisibilityGraph(poly)
    pts = random_pairs(poly, 150, seed)
    got = vg.visible(pts[:, 0], pts[:, 1])
    want = shapely.covers(poly, shapely.linestrings(pts))
    assert np.array_equal(got, want)


def test_oracle_knows_pinches_and_corners() -> None:
    pinch = box(0, 0, 6, 6).difference(shapely.union_all([box(1, 1, 2, 2), box(2, 2, 3, 3)]))
    vg = VisibilityGraph(pinch)
    # through the pinch point (2, 2): blocked; grazing a corner: allowed
    assert list(vg.visible([[0.5, 3.5], [0.5, 0.5]], [[3.5, 0.5], [2.5, 0.5]])) == [False, True]
    assert list(vg.visible([[0.5, 2.0]], [[5.0, 2.0]])) == [False]  # along both walls through the pinch
    _, length = vg.shortest_path((1.5, 2.5), (2.5, 1.5))
    assert math.isclose(length, 2 + math.sqrt(2))


# ------------------------------------------------------------- exact search
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygons, st.sampled_from(METHODS), st.integers(0, 2**16))
def test_generated_levels_exact(poly: Polygon, method: str, seed: int) -> None:
    mesh = NavMesh.build(poly, method=method)
    r = ratios(poly, mesh, VisibilityGraph(poly), random_pairs(poly, 30, seed), exact=True)
    assert r.max() <= 1.0 + 1e-9
    assert r.mean() <= 1.01 and r.max() <= 1.05


@pytest.mark.parametrize("name", BUNDLED)
def test_bundled_levels_exact(name: str) -> None:
    from navmesh.level import load_level

    level = load_level(name)
    poly = level.walkable
    mesh = NavMesh.build(poly)
    oracle = VisibilityGraph(poly)
    spots = np.array(list(level.guards) + list(level.decoys) + [tuple(c) for c in mesh.centroids[::7]])
    spot_pairs = np.stack(np.broadcast_arrays(spots[:, None], spots[None, :]), axis=2).reshape(-1, 2, 2)
    pairs = np.concatenate([random_pairs(poly, 150, seed=len(name)), spot_pairs[:: max(1, len(spot_pairs) // 100)]])
    r = ratios(poly, mesh, oracle, pairs, exact=True)
    assert r.max() <= 1.0 + 1e-9


# ----------------------------------------------------------- A* + funnel only
def _astar_levels() -> list[tuple[str, Polygon]]:
    from shapely.affinity import rotate

    rng = np.random.default_rng(2024)
    levels = []
    for i in range(4):  # rooms with rotated obstacles
        holes: list[Polygon] = []
        while len(holes) < 8:
            c = rng.uniform([2, 2], [28, 20])
            h = rotate(box(*(c - rng.uniform(0.3, 2.0, 2)), *(c + rng.uniform(0.3, 2.0, 2))), rng.uniform(0, 90))
            if box(0.5, 0.5, 29.5, 21.5).contains(h) and all(h.distance(o) > 0.4 for o in holes):
                holes.append(h)
        levels.append((f"rooms{i}", Polygon(box(0, 0, 30, 22).exterior.coords, [h.exterior.coords for h in holes])))
    if LEVELS_DIR.is_dir():
        from navmesh.level import load_level

        levels += [(name, load_level(name).walkable) for name in BUNDLED]
    return levels


def test_astar_search_meets_the_targets() -> None:
    """exact=False: A* with entry-point costs from both ends + funnel, over 150 pairs per level."""
    allr = []
    for name, poly in _astar_levels():
        mesh = NavMesh.build(poly)
        r = ratios(poly, mesh, VisibilityGraph(poly), random_pairs(poly, 150, seed=7), exact=False)
        assert r.max() <= 1.15, name
        allr.append(r)
    r = np.concatenate(allr)
    assert r.mean() <= 1.01 and r.max() <= 1.05, (r.mean(), r.max())


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygons, st.sampled_from(["refined", "cdt"]), st.integers(0, 2**16))
def test_generated_levels_astar(poly: Polygon, method: str, seed: int) -> None:
    """exact=False on well-shaped meshes. Not earcut: its slivers mislead A* (max 1.31 on
    the bundled levels, docs/navmesh.md); earcut meshes are covered in exact mode."""
    mesh = NavMesh.build(poly, method=method)
    r = ratios(poly, mesh, VisibilityGraph(poly), random_pairs(poly, 30, seed), exact=False)
    assert r.mean() <= 1.03 and r.max() <= 1.15


# ------------------------------------------------------------- path contract
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygons, st.booleans(), st.integers(0, 2**16))
def test_corridor_funnel_gives_the_path(poly: Polygon, exact: bool, seed: int) -> None:
    """Pulling the funnel through corridor() reproduces find_path()."""
    mesh = NavMesh.build(poly)
    for s, g in random_pairs(poly, 20, seed):
        path = find_path(mesh, s, g, exact=exact)
        route = corridor(mesh, s, g, exact=exact)
        steps = list(itertools.pairwise(route))
        assert all(u in mesh.neighbors[t] for t, u in steps), "corridor not edge-connected"
        assert in_triangle(mesh, route[0], s) and in_triangle(mesh, route[-1], g)
        rights = [tuple(mesh.shared_edge(t, u)[0]) for t, u in steps]
        lefts = [tuple(mesh.shared_edge(t, u)[1]) for t, u in steps]
        pts, _ = funnel(tuple(s), tuple(g), rights, lefts)
        length = float(np.hypot(*np.diff(np.array(pts), axis=0).T).sum())
        assert math.isclose(length, path.length, rel_tol=1e-9, abs_tol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.one_of(rect_with_holes(axis_aligned=True), grid_polygons()), st.integers(0, 2**16))
def test_queries_on_walls_and_corners(poly: Polygon, seed: int) -> None:
    """Start or goal exactly on a wall or a wall corner (grid coordinates: many collinear corners)."""
    mesh = NavMesh.build(poly)
    oracle = VisibilityGraph(poly)
    rng = np.random.default_rng(seed)
    corners = np.asarray(poly.exterior.coords)[:-1]
    for ring in poly.interiors:
        corners = np.vstack([corners, np.asarray(ring.coords)[:-1]])
    walls = [poly.boundary.interpolate(f, normalized=True) for f in rng.uniform(0, 1, 10)]
    ends = np.vstack([corners[rng.integers(0, len(corners), 10)], [[p.x, p.y] for p in walls], sample_points(poly, 10, rng)])
    pairs = np.stack([ends[rng.permutation(len(ends))], ends], axis=1)
    for exact in (True, False):
        r = ratios(poly, mesh, oracle, pairs, exact=exact)
        if exact:
            assert r.max() <= 1.0 + 1e-9


def test_grid_coordinates_through_corners() -> None:
    """Cell-centre queries whose straight lines pass exactly through wall corners."""
    grid = ["......", ".#..#.", "..#...", "...#..", "......"]
    cells = [box(c, r, c + 1, r + 1) for r, row in enumerate(grid) for c, ch in enumerate(row) if ch == "."]
    poly = shapely.union_all(cells)
    assert isinstance(poly, Polygon)
    mesh = NavMesh.build(poly)
    oracle = VisibilityGraph(poly)
    centres = np.array([(c + 0.5, r + 0.5) for r, row in enumerate(grid) for c, ch in enumerate(row) if ch == "."])
    corners = np.array([(c, r) for r in range(6) for c in range(7)], dtype=float)
    corners = corners[shapely.covers(poly, shapely.points(corners))]
    ends = np.vstack([centres, corners])
    pairs = np.stack(np.broadcast_arrays(ends[:, None], ends[None, :]), axis=2).reshape(-1, 2, 2)
    r = ratios(poly, mesh, oracle, pairs, exact=True)
    assert r.max() <= 1.0 + 1e-9
    # the two diagonal blocks at (2, 2) and (3, 3) touch at (3, 3): no squeezing through
    path = find_path(mesh, (2.5, 3.5), (3.5, 2.5))
    assert path.length > math.sqrt(2) + 0.5


def test_same_triangle_and_same_point() -> None:
    mesh = NavMesh.build(box(0, 0, 4, 3), method="cdt")
    path = find_path(mesh, (0.5, 0.5), (0.7, 0.4))
    assert path.points.tolist() == [[0.5, 0.5], [0.7, 0.4]]
    assert math.isclose(path.length, math.hypot(0.2, 0.1))
    path = find_path(mesh, (1.0, 1.0), (1.0, 1.0))
    assert path.length == 0.0 and len(path.points) == 2


@pytest.mark.parametrize("exact", [True, False])
def test_outside_points_raise(exact: bool) -> None:
    poly = box(0, 0, 10, 10).difference(box(4, 0, 6, 8))
    mesh = NavMesh.build(poly)
    with pytest.raises(OutsideError, match=r"^point \(5\.0, 4\.0\) is outside the walkable area$"):
        find_path(mesh, (5.0, 4.0), (1.0, 1.0), exact=exact)
    with pytest.raises(OutsideError, match=r"^point \(11\.0, 1\.0\) is outside the walkable area$"):
        find_path(mesh, (1.0, 1.0), (11.0, 1.0), exact=exact)
    with pytest.raises(OutsideError):
        corridor(mesh, (1.0, 1.0), (-3.0, 1.0), exact=exact)


def test_path_around_a_wall() -> None:
    poly = box(0, 0, 10, 10).difference(box(4, 0, 6, 8))
    for method in METHODS:
        mesh = NavMesh.build(poly, method=method)
        for exact in (True, False):
            path = find_path(mesh, (1, 1), (9, 1), exact=exact)
            assert path.points.tolist() == [[1, 1], [4, 8], [6, 8], [9, 1]]
            assert math.isclose(path.length, 2 * math.hypot(3, 7) + 2)
