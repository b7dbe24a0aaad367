"""The mesh build is bit-identical to the one the paper's results were made with.

``tests/mesh_digests.json`` holds the SHA-256 of every bundled level's meshes (partition,
body path mesh and the other build options) and of small generated buildings, as the
build before its numpy first passes produced them (``benchmarks/mesh_digest.py``; its
``--large`` run covers the 10^5- and 10^6-cell buildings). Same triangles in the same
order keep the paper preset's partition rows byte-identical.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from shapely import box

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import mesh_digest  # noqa: E402

from navmesh.mesh import NavMesh  # noqa: E402

SAVED = json.loads((ROOT / "tests" / "mesh_digests.json").read_text())


@pytest.mark.parametrize("name,level,variants", mesh_digest.cases(large=False), ids=lambda v: v if isinstance(v, str) else "")
def test_every_mesh_is_bit_identical_to_the_saved_digest(name: str, level: object, variants: bool) -> None:
    assert mesh_digest.level_digests(level, variants) == SAVED[name]


def _locator_cells(mesh: NavMesh) -> list[list[int]]:
    """The locator's buckets as the per-triangle loop it replaced built them."""
    _, _, sx, sy, nx, ny = mesh._grid
    lo = mesh.vertices.min(axis=0)
    tv = mesh.vertices[mesh.triangles]
    scale = np.array([sx, sy])
    bmin = np.clip(np.floor((tv.min(axis=1) - lo - mesh.tol) * scale).astype(np.int64), 0, [nx - 1, ny - 1])
    bmax = np.clip(np.floor((tv.max(axis=1) - lo + mesh.tol) * scale).astype(np.int64), 0, [nx - 1, ny - 1])
    cells: list[list[int]] = [[] for _ in range(nx * ny)]
    for i, (x0, y0, x1, y1) in enumerate(np.column_stack([bmin, bmax]).tolist()):
        for cy in range(y0, y1 + 1):
            for cx in range(x0, x1 + 1):
                cells[cy * nx + cx].append(i)
    return cells


@pytest.mark.parametrize("polygon", [
    box(0, 0, 10, 10).difference(box(4, 0, 6, 8)),
    box(0, 0, 30, 7).difference(box(3, 2, 4, 5)).difference(box(10, 1, 20, 3)),
])
def test_the_locator_buckets_hold_the_triangles_in_index_order(polygon: object) -> None:
    mesh = NavMesh.build(polygon, max_area=0.5)
    expected = _locator_cells(mesh)
    assert [list(c) for c in mesh._cells] == expected
    assert mesh._cell_items.tolist() == [t for c in expected for t in c]
    rng = np.random.default_rng(0)
    points = rng.uniform(0, 30, size=(400, 2))
    assert mesh.locate_many(points).tolist() == [mesh.locate(x, y) for x, y in points]
