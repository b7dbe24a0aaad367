"""Issue 24, scale of the navmesh build: many-cornered polygons end in one line or a mesh.

A regular polygon of 10^5 corners made ``stealth levels`` end in a ``ValueError`` traceback
deep in the refinement (points inserted at the tolerance's scale near its centre broke the
mesh's neighbour lists), and a 10^5-corner obstacle took minutes in GEOS's constrained
Delaunay. Now the level loader refuses a polygon of more than ``MAX_POLYGON_VERTICES``
points, and the outline and obstacles of more than ``MAX_LEVEL_VERTICES`` together, up
front; the refinement never inserts a point that would make a triangle clockwise, nor one
nearer a vertex than its shortest segment split, and it stops at a work budget. Timings
are in ``benchmarks/hostile_scale.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Polygon

import navmesh.mesh as mesh_module
from headless.cli import main
from navmesh.level_fields import MAX_LEVEL_VERTICES, MAX_POLYGON_VERTICES
from navmesh.mesh import NavMesh
from navmesh.refine import Refiner
from navmesh.triangulate import edge_neighbors

SQUARE = [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]


def _ring(n: int, cx: float, cy: float, r: float) -> list[list[float]]:
    return [[cx + r * math.cos(2 * math.pi * i / n), cy + r * math.sin(2 * math.pi * i / n)] for i in range(n)]


def _write(tmp_path: Path, doc: dict) -> str:
    path = tmp_path / "level.json"
    path.write_text(json.dumps({"format": "stealth-level/1", "name": "many", "cell_size": 10.0,
                                "guards": [[50, 50]], **doc}))
    return str(path)


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("stealth: error: "), err
    return err[0]


@pytest.mark.parametrize("command", ["levels", "validate"])
@pytest.mark.parametrize(("doc", "words"), [
    ({"outline": _ring(MAX_POLYGON_VERTICES + 1, 500, 500, 500)},
     f"outline: polygon of {MAX_POLYGON_VERTICES + 1} points, more than the limit of {MAX_POLYGON_VERTICES}"),
    ({"outline": SQUARE, "obstacles": [[[10, 10], [20, 10], [20, 20]], _ring(MAX_POLYGON_VERTICES + 1, 500, 500, 200)]},
     f"obstacles[1]: polygon of {MAX_POLYGON_VERTICES + 1} points, more than the limit of {MAX_POLYGON_VERTICES}"),
    ({"outline": SQUARE, "obstacles": [_ring(9000, 100 + 200 * (k % 5), 100 + 200 * (k // 5), 50) for k in range(23)]},
     f"obstacles: outline and obstacles have {4 + 23 * 9000} points in all, more than the limit of {MAX_LEVEL_VERTICES}"),
])
def test_too_many_corners_are_refused_up_front(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               command: str, doc: dict, words: str) -> None:
    assert main([command, _write(tmp_path, doc)]) == 2
    assert _one_line(capsys).endswith(words)


def test_a_polygon_at_the_limit_loads(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    hole = _ring(MAX_POLYGON_VERTICES, 500, 500, 200)
    doc = {"outline": SQUARE, "obstacles": [hole + hole[:1]]}  # a closing point is not a corner
    assert main(["validate", _write(tmp_path, doc)]) == 0
    assert ": ok (many, 100x100" in capsys.readouterr().err


def _refiner(points: list[tuple[float, float]], triangles: list[list[int]], ring: list[int]) -> Refiner:
    """A refiner over counter-clockwise ``triangles`` of ``points`` (sorted as ``np.unique``)."""
    verts = np.asarray(points, dtype=np.float64)
    return Refiner(verts, np.asarray(triangles, dtype=np.int64), [verts[ring]], 1e-9)


def test_a_point_that_would_make_a_clockwise_triangle_is_not_inserted() -> None:
    # a sliver (0,0) (1,0) (1,1e-7); p is within the tolerance of its short edge's line but
    # beyond that edge's end: inserted "on the edge", triangle (a, p, c) would be clockwise
    ref = _refiner([(0.0, 0.0), (1.0, 0.0), (1.0, 1e-7)], [[0, 1, 2]], [0, 1, 2])
    before = ([list(t) for t in ref.tri], list(ref.x))
    assert not ref._insert_point(0, 1.0 + 1e-10, 2e-7)
    assert ([list(t) for t in ref.tri], list(ref.x)) == before
    assert ref._insert_point(0, 0.9, 0.5e-7)  # inside: inserted, all counter-clockwise
    x, y = np.asarray(ref.x), np.asarray(ref.y)
    t = np.asarray(ref.tri)
    assert np.all((x[t[:, 1]] - x[t[:, 0]]) * (y[t[:, 2]] - y[t[:, 0]])
                  - (y[t[:, 1]] - y[t[:, 0]]) * (x[t[:, 2]] - x[t[:, 0]]) > 0)


def test_no_point_within_a_thousand_tolerances_of_a_vertex() -> None:
    ref = _refiner([(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)], [[0, 2, 3], [0, 3, 1]], [0, 2, 3, 1])
    assert ref._near_vertex(0, 1.0 - 5e-7, 1.0, 1e3 * ref.tol)  # 5e-7 from (1, 1)
    assert not ref._near_vertex(0, 0.5, 0.4, 1e3 * ref.tol)


def _conforming(mesh: NavMesh) -> None:
    edge_neighbors(mesh.triangles)  # raises on a non-manifold edge or a flipped triangle
    assert np.all(mesh.areas > 0)


def test_the_refinement_stops_at_its_work_budget_with_a_conforming_mesh(monkeypatch: pytest.MonkeyPatch) -> None:
    poly = Polygon(_ring(2000, 500, 500, 500))
    full = NavMesh.build(poly)
    assert not full.refinement_stopped
    _conforming(full)
    monkeypatch.setattr(mesh_module, "MAX_REFINE_WORK", 20_000)
    cut = NavMesh.build(poly)
    assert cut.refinement_stopped and len(cut.triangles) < len(full.triangles)
    _conforming(cut)
    assert math.isclose(float(cut.areas.sum()), float(full.areas.sum()), rel_tol=1e-9)
