"""Issue 24 class 4: the body-clearance check scales with the level.

``stealth validate`` erodes the walkable area by the body radius; on a polygon of 10^5
holes one global GEOS buffer took minutes. Obstacles that cannot interact (farther than 2r
from every other wall, convex) are left out and the exact check runs per group
(:mod:`navmesh.body_report`); these tests pin that the grouped check says what the global
one says. The timings (``validate`` on a 1000 × 1000 grid of pillars, outlines and
obstacles of 10^5 vertices) are in ``benchmarks/hostile_scale.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon, box

import navmesh.body_report as body_report
from headless.cli import main
from navmesh.body_report import exact_parts, local_parts
from navmesh.clearance import Clearance
from navmesh.level import bundled_level_names, load_level, parse_level

RADIUS = 0.3


def _crowded(seed: int) -> Polygon:
    """150 boxes, some closer than a body, a ring of four enclosing a pocket, a U-shaped
    obstacle with a narrow inside and one box near the outline."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for i in range(12):
        for j in range(12):
            x, y = 2 + i * 4 + rng.uniform(-0.8, 0.8), 2 + j * 4 + rng.uniform(-0.8, 0.8)
            w, h = rng.uniform(0.5, 2.5, 2)
            obstacles.append(box(x, y, x + w, y + h))
    obstacles += [box(60, 10, 66, 10.5), box(60, 15.5, 66, 16), box(60, 10.7, 60.5, 15.3),
                  box(65.5, 10.7, 66, 15.3)]
    obstacles.append(Polygon([(60, 30), (64, 30), (64, 34), (63.8, 34), (63.8, 30.2),
                              (60.2, 30.2), (60.2, 34), (60, 34)]))
    obstacles.append(box(51.0, 3, 53, 5))
    walkable = box(0, 0, 70, 52).difference(shapely.union_all(obstacles))
    assert isinstance(walkable, Polygon) and len(walkable.interiors) > 100
    return walkable


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_grouped_check_says_what_the_global_one_says(seed):
    walkable = _crowded(seed)
    narrow, pieces = exact_parts(walkable, RADIUS)
    local_narrow, local_pieces = local_parts(walkable, RADIUS)
    assert sorted(set(local_narrow)) == sorted(set(narrow)) and narrow
    assert len(local_pieces) == len(pieces) == 2  # the main area and the ring's pocket
    pocket = box(60.5, 10.5, 65.5, 15.5)
    assert sum(pocket.contains(p) for p in local_pieces) == 1


@pytest.mark.parametrize("name", bundled_level_names())
def test_the_grouped_check_agrees_on_the_bundled_levels(name):
    walkable = load_level(name).walkable
    narrow, pieces = exact_parts(walkable, RADIUS)
    local_narrow, local_pieces = local_parts(walkable, RADIUS)
    assert sorted(set(local_narrow)) == sorted(set(narrow))
    assert len(local_pieces) == len(pieces)


def _pillars(n: int) -> dict:
    grid = ["".join("#" if r % 2 and c % 2 and 0 < r < n - 1 and 0 < c < n - 1 else "."
                    for c in range(n)) for r in range(n)]
    return {"format": "stealth-level/1", "name": "pillars", "grid": grid, "guards": [[0.5, 0.5]]}


def test_a_grid_of_pillars_is_checked_by_groups_and_is_fine(monkeypatch):
    level = parse_level(_pillars(60))
    assert len(level.walkable.interiors) > body_report.LOCAL_MIN_HOLES
    calls = []
    monkeypatch.setattr(body_report, "exact_parts",
                        lambda w, r: calls.append(len(w.interiors)) or exact_parts(w, r))
    body = Clearance(level, RADIUS)
    report = body.report()
    assert report.connected and report.narrow == ()
    assert calls == [0]  # only the outline: no pillar is within a body of another wall
    assert "right_clear" not in body.__dict__  # validate builds no grid moves


def test_validate_on_a_grid_of_pillars_is_ok(tmp_path, capsys):
    import json

    path = tmp_path / "pillars.json"
    path.write_text(json.dumps(_pillars(120)))
    assert main(["validate", str(path)]) == 0
    assert "ok (pillars, 120x120" in capsys.readouterr().err
