"""Navmesh triangulation: conformity, areas, orientation, point location, export.

The polygon strategies here are shared with ``tests/test_paths.py``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely import MultiPolygon, Polygon, box
from shapely.affinity import rotate

from navmesh.mesh import METHODS, NavMesh
from navmesh.query import OutsideError, find_path

LEVELS_DIR = Path(__file__).resolve().parents[1] / "assets" / "levels"
BUNDLED = sorted(p.stem for p in LEVELS_DIR.glob("*.json"))

FAST = settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ------------------------------------------------------------------ strategies
def shortest_edge(polygon: Polygon) -> float:
    """Length of the polygon's shortest exterior edge.

    Random convex hulls can put two vertices 1e-8 apart (angles near 0 and 2π); such
    near-degenerate rings are out of scope for the 1e-9 path agreement the tests check.
    """
    ring = np.asarray(polygon.exterior.coords)
    return float(np.hypot(*np.diff(ring, axis=0).T).min())


@st.composite
def rect_with_holes(draw: st.DrawFn, axis_aligned: bool = False) -> Polygon:
    """A rectangle with up to 7 non-overlapping holes strictly inside (rectangles, rotated, convex)."""
    w = draw(st.floats(6.0, 40.0))
    h = draw(st.floats(6.0, 30.0))
    outline = box(0.0, 0.0, w, h)
    inner = outline.buffer(-0.3, join_style="mitre")
    holes: list[Polygon] = []
    for _ in range(draw(st.integers(0, 7))):
        cx, cy = draw(st.floats(0.5, w - 0.5)), draw(st.floats(0.5, h - 0.5))
        kind = "rect" if axis_aligned else draw(st.sampled_from(["rect", "rotated", "convex"]))
        if kind == "convex":
            k = draw(st.integers(3, 7))
            ang = np.sort(np.asarray(draw(st.lists(st.floats(0.0, 2 * math.pi), min_size=k, max_size=k))))
            r = draw(st.floats(0.4, 3.0))
            hole = Polygon(np.column_stack([cx + r * np.cos(ang), cy + r * np.sin(ang)])).convex_hull
        else:
            hw, hh = draw(st.floats(0.2, 4.0)), draw(st.floats(0.2, 3.0))
            if axis_aligned:  # grid-like coordinates: collinear corners everywhere
                cx, cy, hw, hh = round(cx), round(cy), max(1, round(hw)), max(1, round(hh))
            hole = box(cx - hw / 2, cy - hh / 2, cx + hw / 2, cy + hh / 2)
            if kind == "rotated":
                hole = rotate(hole, draw(st.floats(0.0, 180.0)))
        if (
            isinstance(hole, Polygon)
            and hole.area > 0.05
            and shortest_edge(hole) > 0.01  # near-duplicate vertices: a degenerate input
            and inner.contains(hole)
            and all(hole.distance(o) > 0.25 for o in holes)
        ):
            holes.append(hole)
    return Polygon(outline.exterior.coords, [o.exterior.coords for o in holes])


@st.composite
def star_polygons(draw: st.DrawFn) -> Polygon:
    """A random star-shaped outline around the origin, sometimes with a small rotated hole."""
    k = draw(st.integers(5, 14))
    weights = np.asarray(draw(st.lists(st.floats(1.0, 3.0), min_size=k, max_size=k)))
    ang = draw(st.floats(0.0, 2 * math.pi)) + 2 * math.pi * np.cumsum(weights) / weights.sum()
    r = np.asarray(draw(st.lists(st.floats(3.0, 12.0), min_size=k, max_size=k)))
    outline = Polygon(np.column_stack([r * np.cos(ang), r * np.sin(ang)]))
    if draw(st.booleans()):
        s = draw(st.floats(0.1, 0.4))
        hole = rotate(box(-s, -s / 2, s, s / 2), draw(st.floats(0.0, 90.0)), origin=(0, 0))
        if outline.buffer(-0.2).contains(hole):
            return Polygon(outline.exterior.coords, [hole.exterior.coords])
    return outline


@st.composite
def grid_polygons(draw: st.DrawFn) -> Polygon:
    """Walkable cells of a random occupancy grid (largest piece): collinear runs and pinch points."""
    rows, cols = draw(st.integers(3, 12)), draw(st.integers(3, 14))
    blocked = draw(st.lists(st.integers(0, 3), min_size=rows * cols, max_size=rows * cols))
    cells = [box(c, r, c + 1, r + 1) for i, (r, c) in enumerate(np.ndindex(rows, cols)) if blocked[i] != 0]
    area = shapely.union_all(cells) if cells else Polygon()
    if isinstance(area, MultiPolygon):
        area = max(area.geoms, key=lambda g: g.area)
    if not isinstance(area, Polygon) or area.is_empty:
        return box(0, 0, 1, 1)
    return area


polygons = st.one_of(rect_with_holes(), rect_with_holes(axis_aligned=True), star_polygons(), grid_polygons())


# --------------------------------------------------------------------- checks
def cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def check_mesh(poly: Polygon, mesh: NavMesh) -> None:
    """Areas, orientation, whole-edge neighbours, walls on the boundary, no T-junctions."""
    v, t, nb = mesh.vertices, mesh.triangles, mesh.neighbors
    assert v.dtype == np.float64 and v.shape[1] == 2 and t.shape[1] == 3 and nb.shape == t.shape
    assert math.isclose(mesh.areas.sum(), poly.area, rel_tol=1e-9)
    p0, p1, p2 = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    assert np.all(cross2(p1 - p0, p2 - p0) > 0), "triangles must be counter-clockwise"
    assert np.allclose(mesh.centroids, (p0 + p1 + p2) / 3)
    scale = max(1.0, *np.ptp(v, axis=0))
    # neighbours: symmetric, and across the same two vertex indices (whole edges)
    edge_count: dict[tuple[int, int], int] = {}
    for ti in range(len(t)):
        for k in range(3):
            a, b = int(t[ti, (k + 1) % 3]), int(t[ti, (k + 2) % 3])
            edge_count[(min(a, b), max(a, b))] = edge_count.get((min(a, b), max(a, b)), 0) + 1
            u = int(nb[ti, k])
            if u < 0:
                continue
            back = np.flatnonzero(nb[u] == ti)
            assert back.size == 1
            j = int(back[0])
            assert {int(t[u, (j + 1) % 3]), int(t[u, (j + 2) % 3])} == {a, b}
            assert (int(t[u, (j + 1) % 3]), int(t[u, (j + 2) % 3])) == (b, a), "shared edge runs both ways"
    assert set(edge_count.values()) <= {1, 2}
    # boundary edges are exactly the polygon's walls
    wt, wk = np.nonzero(nb < 0)
    a, b = v[t[wt, (wk + 1) % 3]], v[t[wt, (wk + 2) % 3]]
    assert math.isclose(np.hypot(*(b - a).T).sum(), poly.boundary.length, rel_tol=1e-9)
    mids = (a + b) / 2
    assert np.all(shapely.distance(poly.boundary, shapely.points(mids)) <= 1e-9 * scale)
    it, ik = np.nonzero(nb >= 0)
    ia, ib = v[t[it, (ik + 1) % 3]], v[t[it, (ik + 2) % 3]]
    assert np.all(shapely.contains_xy(poly, *((ia + ib) / 2).T)), "interior edges lie inside"
    # no vertex inside any edge (conforming: no T-junctions)
    ea = v[t[:, [1, 2, 0]].ravel()]
    eb = v[t[:, [2, 0, 1]].ravel()]
    e = eb - ea
    le = np.hypot(*e.T)
    rel = v[None, :, :] - ea[:, None, :]
    along = (rel[..., 0] * e[:, None, 0] + rel[..., 1] * e[:, None, 1]) / le[:, None]
    off = np.abs(rel[..., 1] * e[:, None, 0] - rel[..., 0] * e[:, None, 1]) / le[:, None]
    tj = (off <= 1e-9 * scale) & (along > 1e-9 * scale) & (along < le[:, None] - 1e-9 * scale)
    assert not tj.any(), "a vertex lies inside an edge (T-junction)"


def check_locate(poly: Polygon, mesh: NavMesh, seed: int, n: int = 300) -> None:
    """Each interior point (off edges) is in exactly one triangle, which locate finds; outside -> -1."""
    rng = np.random.default_rng(seed)
    minx, miny, maxx, maxy = poly.bounds
    pts = rng.uniform([minx - 1, miny - 1], [maxx + 1, maxy + 1], size=(n, 2))
    v, t = mesh.vertices, mesh.triangles
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    dists = []
    for p, q in ((b, c), (c, a), (a, b)):
        e = q - p
        le = np.hypot(*e.T)
        dists.append(((pts[:, None, 1] - p[None, :, 1]) * e[None, :, 0] - (pts[:, None, 0] - p[None, :, 0]) * e[None, :, 1]) / le)
    d = np.stack(dists, axis=-1)  # (n, T, 3) signed distance to each edge, > 0 inside
    strictly = np.all(d > 1e-9, axis=-1)
    near_edge = np.any(np.all(d >= -1e-9, axis=-1) & np.any(np.abs(d) <= 1e-9, axis=-1), axis=1)
    located = mesh.locate_many(pts)
    for i, (x, y) in enumerate(pts):
        one = mesh.locate(float(x), float(y))
        assert one == located[i]
        inside = bool(shapely.contains_xy(poly, x, y))
        if near_edge[i]:
            continue
        hits = np.flatnonzero(strictly[i])
        if inside:
            assert hits.size == 1 and one == hits[0]
        elif poly.exterior.distance(shapely.Point(x, y)) > 1e-6 and poly.boundary.distance(shapely.Point(x, y)) > 1e-6:
            assert hits.size == 0 and one == -1
    # points on the walls count as inside
    ring_pts = [poly.exterior.interpolate(f, normalized=True) for f in rng.uniform(0, 1, 20)]
    for ring in poly.interiors:
        ring_pts += [ring.interpolate(f, normalized=True) for f in rng.uniform(0, 1, 5)]
    for p in ring_pts:
        assert mesh.locate(p.x, p.y) >= 0
    assert np.all(mesh.locate_many(np.array([[p.x, p.y] for p in ring_pts])) >= 0)


# ---------------------------------------------------------------------- tests
@FAST
@given(polygons, st.sampled_from(METHODS), st.integers(0, 2**16))
def test_random_polygons_conforming_and_locatable(poly: Polygon, method: str, seed: int) -> None:
    mesh = NavMesh.build(poly, method=method)
    check_mesh(poly, mesh)
    check_locate(poly, mesh, seed)


@settings(max_examples=30, deadline=None)
@given(rect_with_holes(axis_aligned=True), st.sampled_from([20.0, 28.0]), st.sampled_from([None, 2.0, 6.0]))
def test_refinement_meets_angle_and_area(poly: Polygon, min_angle: float, max_area: float | None) -> None:
    """With only right-angle input corners, Ruppert refinement reaches the requested quality."""
    mesh = NavMesh.build(poly, min_angle=min_angle, max_area=max_area)
    check_mesh(poly, mesh)
    v, t = mesh.vertices, mesh.triangles
    angles = []
    for k in range(3):
        p, q, r = v[t[:, k]], v[t[:, (k + 1) % 3]], v[t[:, (k + 2) % 3]]
        u, w = q - p, r - p
        angles.append(np.degrees(np.arctan2(np.abs(cross2(u, w)), np.einsum("ij,ij->i", u, w))))
    assert np.min(angles) >= min_angle - 1e-6
    if max_area is not None:
        assert mesh.areas.max() <= max_area * (1 + 1e-9)


@settings(max_examples=20, deadline=None)
@given(rect_with_holes(), st.sampled_from(["cdt", "earcut"]), st.floats(0.5, 5.0))
def test_refining_other_methods(poly: Polygon, method: str, max_area: float) -> None:
    mesh = NavMesh.build(poly, method=method, max_area=max_area)
    check_mesh(poly, mesh)
    assert mesh.areas.max() <= max_area * (1 + 1e-9)


def test_unrefined_methods_use_only_polygon_vertices() -> None:
    poly = box(0, 0, 20, 10).difference(box(5, 2, 8, 6)).difference(box(12, 3, 15, 9))
    for method in ("cdt", "earcut"):
        mesh = NavMesh.build(poly, method=method)
        assert len(mesh.vertices) == 12  # 4 outline corners + 2 × 4 hole corners
        assert len(mesh) == 12 + 2 * 2 - 2  # T = V + 2H - 2 for V vertices and H holes
        check_mesh(poly, mesh)


def test_pinch_points_and_touching_holes() -> None:
    # two blocked cells touching corner to corner, and a hole touching the outline at a point
    poly = box(0, 0, 6, 6).difference(shapely.union_all([box(1, 1, 2, 2), box(2, 2, 3, 3)]))
    touching = Polygon([(0, 0), (6, 0), (6, 6), (0, 6)], [[(3, 0), (4, 2), (2, 2)]])
    for p in (poly, touching):
        for method in METHODS:
            mesh = NavMesh.build(p, method=method)
            check_mesh(p, mesh)
            check_locate(p, mesh, seed=1)


@pytest.mark.parametrize("name", BUNDLED)
def test_bundled_levels(name: str) -> None:
    from navmesh.level import load_level

    poly = load_level(name).walkable
    for method in METHODS:
        mesh = NavMesh.build(poly, method=method)
        check_mesh(poly, mesh)
        check_locate(poly, mesh, seed=2, n=200)


def test_adjacency_and_shared_edge() -> None:
    poly = box(0, 0, 10, 6).difference(box(3, 2, 6, 4))
    mesh = NavMesh.build(poly)
    adj = mesh.adjacency()
    assert len(adj) == len(mesh)
    for t, row in enumerate(adj):
        assert list(row) == sorted(int(u) for u in mesh.neighbors[t] if u >= 0)
        for u in row:
            edge = mesh.shared_edge(t, int(u))
            back = mesh.shared_edge(int(u), t)
            assert np.array_equal(edge, back[::-1])
            ta, tb = mesh.centroids[t], mesh.centroids[u]
            d = tb - ta
            # walking from t into u, edge[0] is on the right, edge[1] on the left (coordinate sense)
            assert cross2(d, edge[0] - ta) < 0 < cross2(d, edge[1] - ta)
    with pytest.raises(ValueError):
        mesh.shared_edge(0, 0)


def test_outside_error_message() -> None:
    mesh = NavMesh.build(box(0, 0, 4, 4))
    with pytest.raises(OutsideError, match=r"^point \(5\.0, 4\.5\) is outside the walkable area$"):
        find_path(mesh, (5.0, 4.5), (1, 1))
    assert issubclass(OutsideError, ValueError)
    assert mesh.locate(float("nan"), 1.0) == -1
    assert list(mesh.locate_many([[float("nan"), 0.0], [1e9, 1e9], [2.0, 2.0]])[:2]) == [-1, -1]


def test_bad_input() -> None:
    poly = box(0, 0, 4, 4)
    with pytest.raises(ValueError, match="unknown method"):
        NavMesh.build(poly, method="voronoi")
    with pytest.raises(ValueError, match="min_angle"):
        NavMesh.build(poly, min_angle=40)
    with pytest.raises(ValueError, match="max_area"):
        NavMesh.build(poly, max_area=0)
    with pytest.raises(TypeError):
        NavMesh.build(MultiPolygon([box(0, 0, 1, 1), box(2, 2, 3, 3)]))
    with pytest.raises(ValueError, match="invalid"):
        NavMesh.build(Polygon([(0, 0), (2, 2), (2, 0), (0, 2)]))
    with pytest.raises(ValueError):
        NavMesh(np.zeros((3, 2)), np.array([[0, 1, 2]]))


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".glb"])
def test_export_round_trip(tmp_path: Path, suffix: str) -> None:
    trimesh = pytest.importorskip("trimesh")
    mesh = NavMesh.build(box(0, 0, 10, 6).difference(box(3, 2, 6, 4)))
    out = tmp_path / f"mesh{suffix}"
    mesh.export(out)
    loaded = trimesh.load(out, force="mesh")
    assert len(loaded.faces) == len(mesh)
    assert math.isclose(loaded.area, mesh.areas.sum(), rel_tol=1e-6)
    assert np.allclose(loaded.vertices[:, 2], 0.0)
    assert np.all(loaded.face_normals[:, 2] > 0)
    with pytest.raises(ValueError, match="unsupported"):
        mesh.export(tmp_path / "mesh.stl")
