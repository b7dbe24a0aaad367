"""Large levels: a generated 300×300 building runs a full trial; graph storage never
changes a trial (the same trials with every graph forced to per-source searches)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import navmesh.distances as distances_module
import navmesh.graph as graph_module
import navmesh.sizing as sizing
from game.trial import TrialSpec, run_trial
from navmesh.buildings import building_level, building_occupancy
from navmesh.graph import build_graph
from navmesh.level import parse_level


def test_generated_buildings_are_valid_levels_of_rooms() -> None:
    grid = parse_level(building_level(60, 80, seed=2, form="grid"))
    outline = parse_level(building_level(60, 80, seed=2, form="polygon"))
    assert grid.occupancy.shape == (60, 80)
    assert outline.walkable.area == pytest.approx(grid.walkable.area)
    occupancy = building_occupancy(60, 80, seed=2)
    assert 0.5 < occupancy.mean() < 0.95  # walls and furniture, not an open field
    assert np.array_equal(occupancy, building_occupancy(60, 80, seed=2))


def test_a_300x300_building_runs_a_full_trial(tmp_path: Path) -> None:
    path = tmp_path / "building.json"
    path.write_text(json.dumps(building_level(300, 300, seed=0)))
    graph = build_graph(parse_level(json.loads(path.read_text())), "grid")
    assert graph.n > 50_000 and not graph.dense
    row = run_trial(TrialSpec(level=str(path), guards="pf", player="maxmin"))
    assert row["level"] == "building-300x300-0"
    assert row["metrics"]["coverage"] > 0 and row["metrics"]["avg_guard_player_dist"] > 0


@pytest.mark.parametrize("guards,player", [("pf", "maxmin"), ("cheat", "safetygraph"),
                                           ("staleness", "maxmin"), ("fsm", "safetygraph")])
def test_trials_do_not_depend_on_the_graph_storage(
    guards: str, player: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    specs = [TrialSpec(level=name, abstraction=ab, guards=guards, player=player, seed=1)
             for name, ab in (("maze", "grid"), ("tlou", "partition"))]
    dense = [run_trial(spec) for spec in specs]
    monkeypatch.setattr(distances_module, "DENSE_MAX_NODES", 0)
    graph_module._cached_graph.cache_clear()
    try:
        searched = [run_trial(spec) for spec in specs]
    finally:
        monkeypatch.undo()
        graph_module._cached_graph.cache_clear()
    for a, b in zip(dense, searched, strict=True):
        a.pop("wall_time"), b.pop("wall_time")
        assert a == b


def test_a_level_too_big_for_the_machine_is_refused_in_one_line(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from navmesh.errors import LevelError
    from navmesh.level import load_level

    level = load_level("maze")
    sizing.check_fits(level, "maze")  # fits
    monkeypatch.setattr(sizing, "available_bytes", lambda: 2**20)
    with pytest.raises(LevelError) as error:
        sizing.check_fits(level, "maze")
    message = str(error.value)
    assert message.startswith("maze: size: 20x20 cells, about ") and "nodes: needs about" in message
    assert "\n" not in message and "GB available" in message


def test_a_building_of_40x50_cells_is_generated() -> None:
    """Regression: a last block narrower than a room put a wall index past the border."""
    level = parse_level(building_level(40, 50, seed=4))
    assert level.occupancy.shape == (40, 50)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rows=st.integers(3, 90), cols=st.integers(3, 90), seed=st.integers(0, 10**6),
       form=st.sampled_from(["grid", "polygon"]))
def test_every_building_size_is_a_valid_level(rows: int, cols: int, seed: int, form: str) -> None:
    level = parse_level(building_level(rows, cols, seed, form=form))
    occupancy = building_occupancy(rows, cols, seed)
    if form == "grid":
        assert level.occupancy.shape == (rows, cols)
    # an outline's grid ends at its last walkable cell (the border wall is outside it)
    r, c = level.occupancy.shape
    assert np.array_equal(level.occupancy, occupancy[:r, :c]) and not occupancy[r:].any()
    assert not occupancy[:, c:].any()


@pytest.mark.parametrize("rows,cols", [(2, 10), (10, 2), (0, 0)])
def test_a_building_too_small_for_its_walls_is_refused(rows: int, cols: int) -> None:
    with pytest.raises(ValueError, match="at least 3x3"):
        building_level(rows, cols)


# ---------------------------------------------------------------------- the navmesh's bound
def _pillars(tmp_path: Path, side: int) -> Path:
    """A grid-form level of side × side cells with a one-cell pillar at every odd (row, col)
    inside the border: ((side - 2) / 2)^2 square holes (benchmarks/hostile_scale.py's form)."""
    grid = ["".join("#" if y % 2 and x % 2 and 0 < y < side - 1 and 0 < x < side - 1 else "."
                    for x in range(side)) for y in range(side)]
    path = tmp_path / f"pillars{side}.json"
    path.write_text(json.dumps({"format": "stealth-level/1", "name": f"pillars{side}",
                                "grid": grid, "guards": [[0.5, 0.5]]}))
    return path


def _error_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("stealth: error: "), err
    return err[0]


def test_a_grid_of_pillars_past_the_navmesh_bound_is_refused_before_triangulating(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 24: 400 × 400 cells, 39,601 holes (``levels`` took 48 s, the 1000 × 1000 grid
    never returned): every command that builds the partition mesh gives the same line, and
    GEOS is never started."""
    from headless.cli import main
    from navmesh.mesh import NavMesh

    path = _pillars(tmp_path, 400)
    holes, corners = 199 * 199, 4 * 199 * 199 + 4
    assert holes * corners > sizing.MAX_MESH_HOLE_WORK and corners <= sizing.MAX_MESH_CORNERS

    def no_build(*args: object, **kwargs: object) -> None:
        raise AssertionError("the navmesh was built past its bound")

    monkeypatch.setattr(NavMesh, "build", no_build)
    expected = (f"stealth: error: pillars400.json: walkable area: {holes} holes x {corners} corners"
                f" = {holes * corners:.3g} for the partition navmesh, more than the limit of "
                f"{sizing.MAX_MESH_HOLE_WORK:.3g} (its triangulation time grows with holes x "
                "corners; the grid abstraction has no such limit)")
    for argv in (["levels", str(path)], ["levels", "maze", str(path)],
                 ["path", str(path), "--from", "0.5,0.5", "--to", "3.5,3.5"],
                 ["sim", str(path), "--abstraction", "partition"]):
        assert main(argv) == 2, argv
        assert _error_line(capsys) == expected, argv
    # validate accepts it (the grid runs it) and says the partition will not
    assert main(["validate", str(path)]) == 0
    err = capsys.readouterr().err
    assert "pillars400.json: warning: the partition abstraction refuses this level: 39601 holes" in err
    assert ": ok (pillars400, 400x400" in err


def test_the_navmesh_corner_bound_is_shared_by_every_partition_graph(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The corner limit (the 1000 × 1000 pillars: 996,008 corners) is checked by every build
    of a partition graph, shown here with the limit lowered below a small level's corners."""
    from navmesh.errors import LevelError
    from navmesh.level import load_level

    level = load_level(_pillars(tmp_path, 20))  # 81 holes, 328 corners
    assert sizing.walkable_size(level.walkable) == (81, 328)
    monkeypatch.setattr(sizing, "MAX_MESH_CORNERS", 327)
    with pytest.raises(LevelError) as error:
        build_graph(level, "partition")
    assert str(error.value) == ("pillars20.json: walkable area: 328 corners (81 holes) for the "
                                "partition navmesh, more than the limit of 327 (the grid "
                                "abstraction has no such limit)")
    assert build_graph(level, "grid").n == 20 * 20 - 81  # the grid has no such bound


def test_levels_below_the_navmesh_bound_still_get_their_mesh(tmp_path: Path) -> None:
    """The bundled levels, a 300 × 300 building and 100 × 100 pillars are far below it."""
    from headless.commands.levels import level_stats
    from navmesh.level import bundled_level_names, load_level

    for name in bundled_level_names():
        sizing.check_mesh_work(load_level(name))
    building = parse_level(building_level(300, 300, seed=0))
    holes, corners = sizing.walkable_size(building.walkable)
    assert holes * corners < sizing.MAX_MESH_HOLE_WORK / 100
    level = load_level(_pillars(tmp_path, 100))
    sizing.check_mesh_work(level)
    stats = level_stats(level)
    assert stats["triangles"] > 2 * 49 * 49 and stats["walkable"] == 100 * 100 - 49 * 49


def test_the_levels_table_keeps_wide_values_apart(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                                   ) -> None:
    """Areas of 10^4 and more and 7-digit counts ran together (``0.067829690.0348``): every
    column is as wide as its widest value, with space between."""
    from headless.cli import main
    from headless.commands.levels import levels_table

    rows = [{"name": "round", "triangles": 1234567, "min_area": 0.0678, "max_area": 29690.0348,
             "avg_area": 123456.7891, "rows": 1000, "cols": 1000, "walkable": 1000000,
             "blocked": 0},
            {"name": "a-much-longer-name", "triangles": 5, "min_area": 0.5, "max_area": 1.0,
             "avg_area": 0.75, "rows": 3, "cols": 4, "walkable": 9, "blocked": 3}]
    lines = levels_table(rows)
    assert lines[1].split() == ["round", "1234567", "0.0678", "29690.0348", "123456.7891",
                                "1000", "1000", "1000000", "(100%)", "0", "(0%)"]
    assert lines[2].split() == ["a-much-longer-name", "5", "0.5000", "1.0000", "0.7500", "3", "4",
                                "9", "(75%)", "3", "(25%)"]
    assert len({len(line) for line in lines}) == 1  # right-aligned columns end together
    for column in ("tris", "min area", "max area", "avg area", "rows", "cols", "walkable"):
        end = lines[0].index(column) + len(column)
        assert all(line[end] == " " for line in lines), column  # a space after every column
    # through the command: a 1000 × 1000 open grid of 10-unit cells (areas of 5 × 10^7)
    path = tmp_path / "open.json"
    path.write_text(json.dumps({"format": "stealth-level/1", "name": "open", "cell_size": 10.0,
                                "grid": ["." * 1000] * 1000, "guards": [[5, 5]]}))
    assert main(["levels", str(path)]) == 0
    header, row = capsys.readouterr().out.splitlines()
    values = row.split()
    assert values[0] == "open" and values[-4:] == ["1000000", "(100%)", "0", "(0%)"]
    assert all(float(v) >= 10**4 for v in values[2:5]) and len(header) == len(row)


def test_a_toothed_outline_around_pillars_is_refused_for_the_partitions_path_area(
    tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    """Within the navmesh's bounds (its mesh: 20 s) but a partition trial's eroded path area
    took minutes in GEOS's buffer (every hole tested against a 1.7 × 10^5-corner outline)."""
    from headless.cli import main

    cols, top, k = 640, 530, 86
    occupancy = np.ones((top + 2 * k + 6, cols), dtype=bool)
    for y in range(1, top - 3, 4):  # walls from the left border, teeth on every other cell
        occupancy[y, : cols - 2] = False
        occupancy[y + 1, : cols - 2 : 2] = False
    occupancy[top + 1 : top + 1 + 2 * k : 2, 1 : 1 + 2 * k : 2] = False  # k × k pillars
    path = tmp_path / "toothed.json"
    path.write_text(json.dumps({"format": "stealth-level/1", "name": "toothed", "guards": [[0.5, 0.5]],
                                "grid": ["".join(".#"[not c] for c in row) for row in occupancy]}))
    assert main(["sim", str(path), "--abstraction", "partition"]) == 2
    line = _error_line(capsys)
    holes, corners = k * k, 198284
    assert holes * corners <= sizing.MAX_MESH_HOLE_WORK and corners <= sizing.MAX_MESH_CORNERS
    assert line.startswith(f"stealth: error: toothed.json: walkable area: {holes} holes x ")
    assert "outline corners" in line and f"limit of {sizing.MAX_PATH_HOLE_WORK:.3g}" in line
