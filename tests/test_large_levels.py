"""Large levels: a generated 300×300 building runs a full trial; graph storage never
changes a trial (the same trials with every graph forced to per-source searches)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

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
    monkeypatch.setattr(graph_module, "DENSE_MAX_NODES", 0)
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
