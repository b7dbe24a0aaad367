"""Level files (SPEC §8): the bundled levels, rasterisation, and every kind of bad input."""

from __future__ import annotations

import json
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from scipy import ndimage

from navmesh.level import (
    LEVELS_DIR,
    Level,
    LevelError,
    bundled_level_names,
    load_level,
    parse_level,
    resolve_level_path,
)

# Paper Table 1: rows, cols, walkable cells, blocked cells.
TABLE_1 = {
    "arkham": (28, 26, 548, 180),
    "dishonored": (26, 39, 726, 288),
    "miami": (26, 21, 377, 169),
    "maze": (20, 20, 206, 194),
    "tlou": (14, 30, 255, 165),
}


def grid_level(**overrides: Any) -> dict[str, Any]:
    """A small valid grid level (4 x 3), with keys replaced or removed (value ``None``)."""
    data: dict[str, Any] = {
        "format": "stealth-level/1",
        "name": "tiny",
        "grid": ["....", ".#..", "...."],
        "guards": [[0.5, 0.5]],
    }
    data.update(overrides)
    return {k: v for k, v in data.items() if v is not None}


def polygon_level(**overrides: Any) -> dict[str, Any]:
    """A small valid polygon level (6 x 4 outline, no obstacles), keys replaced or removed."""
    return grid_level(**{"grid": None, "outline": rect(0, 0, 6, 4), **overrides})


def rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


# --------------------------------------------------------------------------- bundled levels


def test_bundled_level_names() -> None:
    assert bundled_level_names() == sorted(TABLE_1)


@pytest.mark.parametrize("name", sorted(TABLE_1))
def test_bundled_level_matches_table_1(name: str) -> None:
    level = load_level(name)
    rows, cols, walkable, blocked = TABLE_1[name]
    assert (level.rows, level.cols) == (rows, cols)
    assert int(level.occupancy.sum()) == walkable
    assert int((~level.occupancy).sum()) == blocked
    assert level.name == name
    assert level.path == LEVELS_DIR / f"{name}.json"
    assert level.cell_size == 1.0
    assert level.walkable.is_valid
    assert level.walkable.area == pytest.approx(walkable)  # grid levels: exactly the cells


@pytest.mark.parametrize("name", sorted(TABLE_1))
def test_bundled_level_spawns_and_zones(name: str) -> None:
    level = load_level(name)
    assert len(level.guards) == 3
    assert len(level.decoys) >= 1
    for x, y in level.guards + level.decoys:
        assert level.contains(x, y)
        row, col = level.cell_of(x, y)
        assert level.occupancy[row, col]
        assert level.cell_center(row, col) == (x, y)  # spawns sit at cell centres
    assert len(set(level.guards)) == 3
    for kind in ("dark", "concealment"):
        assert len(level.zones[kind]) >= 1
        for zone in level.zones[kind]:
            # mostly over walkable ground, not a wall
            assert zone.intersection(level.walkable).area >= 0.5 * zone.area


@pytest.mark.parametrize("name", sorted(TABLE_1))
def test_bundled_level_is_one_piece_without_diagonal_pinches(name: str) -> None:
    occ = load_level(name).occupancy
    _, pieces = ndimage.label(occ)
    assert pieces == 1
    a, b, c, d = occ[:-1, :-1], occ[:-1, 1:], occ[1:, :-1], occ[1:, 1:]
    pinches = (a & d & ~b & ~c) | (b & c & ~a & ~d)  # cells touching only at a corner
    assert not pinches.any(), np.argwhere(pinches).tolist()


def test_load_by_name_path_and_str_agree() -> None:
    by_name = load_level("Miami")  # bundled names are case-insensitive
    by_path = load_level(LEVELS_DIR / "miami.json")
    by_str = load_level(str(LEVELS_DIR / "miami.json"))
    for level in (by_path, by_str):
        assert np.array_equal(level.occupancy, by_name.occupancy)
        assert level.walkable.equals(by_name.walkable)
    assert resolve_level_path("maze") == LEVELS_DIR / "maze.json"


def test_unknown_bundled_name() -> None:
    with pytest.raises(LevelError) as info:
        load_level("atlantis")
    message = str(info.value)
    assert message.startswith("atlantis: file: ")
    assert "maze" in message  # lists the bundled levels


# --------------------------------------------------------------------------- geometry


def test_polygon_level_rasterises_by_cell_centres() -> None:
    obstacles = [
        rect(0, 0, 2, 1),  # touches the outline (a notch)
        rect(3, 1, 4, 3),  # these two touch each other along x = 4 ...
        rect(4, 2, 5, 3),  # ... and form one hole together
        [[5, 0], [6, 0], [6, 1]],  # cell (0, 5)'s centre lies on its edge: blocked
        [[5.2, 4], [6, 4], [6, 3.2]],  # chips cell (3, 5) but misses its centre
    ]
    level = parse_level(polygon_level(obstacles=obstacles, guards=[[1.5, 2.5]]))
    rows = ("##...#", "...#..", "...##.", "......")
    expected = np.array([[c != "#" for c in row] for row in rows])
    assert (level.rows, level.cols) == (4, 6)
    assert np.array_equal(level.occupancy, expected)
    assert level.walkable.area == pytest.approx(24 - 2 - 2 - 1 - 0.5 - 0.32)
    assert len(level.walkable.interiors) == 1
    assert level.walkable.exterior.is_ccw
    assert level.zones == {"dark": (), "concealment": ()}
    assert level.decoys == ()


def test_polygon_level_rows_cols_round_up() -> None:
    level = parse_level(polygon_level(outline=[[0, 0], [4.2, 0], [4.2, 2.5], [0, 2.5]]))
    assert (level.rows, level.cols) == (3, 5)
    assert not level.occupancy[:, 4].any()  # centres at x = 4.5 lie outside the outline
    assert not level.occupancy[2].any()


def test_grid_level_geometry_and_cell_size() -> None:
    level = parse_level(grid_level(cell_size=0.5, guards=[[0.25, 0.25]]))
    assert (level.rows, level.cols) == (3, 4)
    assert level.walkable.area == pytest.approx(11 * 0.25)
    assert level.walkable.bounds == (0.0, 0.0, 2.0, 1.5)
    assert len(level.walkable.interiors) == 1  # the '#' cell
    assert level.cell_of(1.2, 0.3) == (0, 2)
    assert level.cell_center(0, 2) == (1.25, 0.25)


def test_contains_cell_of_cell_center() -> None:
    level = parse_level(polygon_level(obstacles=[rect(0, 0, 2, 1)], guards=[[3, 3]]))
    assert not level.contains(0.5, 0.5)  # inside the obstacle
    assert level.contains(2.0, 0.5)  # on the obstacle's edge: the boundary counts as inside
    assert level.contains(0.0, 4.0)  # outline corner
    assert level.contains(1.0, 2.0)
    assert not level.contains(6.5, 1.0)
    assert level.cell_of(2.2, 0.7) == (0, 2)
    assert level.cell_of(0.0, 0.0) == (0, 0)
    assert level.cell_of(6.0, 4.0) == (3, 5)  # the far edges belong to the last cell
    assert level.cell_center(1, 2) == (2.5, 1.5)
    with pytest.raises(ValueError):
        level.cell_of(-0.1, 1.0)
    with pytest.raises(ValueError):
        level.cell_of(1.0, 4.01)


def test_in_memory_levels_accept_tuples_and_numpy_numbers() -> None:
    level = parse_level(
        grid_level(grid=("....", "....", "...."), guards=[(np.float64(0.5), np.int64(1))])
    )
    assert level.guards == ((0.5, 1.0),)
    assert all(type(v) is float for v in level.guards[0])


def test_walls_are_boundary_segments() -> None:
    level = parse_level(grid_level(grid=["...", ".#.", "..."]))
    walls = level.walls
    assert walls.shape == (8, 2, 2)  # 4 exterior sides + 4 sides of the hole
    lengths = np.linalg.norm(walls[:, 1] - walls[:, 0], axis=1)
    assert lengths.sum() == pytest.approx(12 + 4)
    assert not walls.flags.writeable
    assert level.walls is walls  # computed once


def test_level_is_immutable_and_picklable() -> None:
    level = load_level("tlou")
    assert not level.occupancy.flags.writeable
    with pytest.raises(AttributeError):
        level.name = "other"  # type: ignore[misc]
    copy = pickle.loads(pickle.dumps(level))
    assert np.array_equal(copy.occupancy, level.occupancy)
    assert copy.walkable.equals(level.walkable)
    assert isinstance(copy, Level)


def test_grid_polygon_equals_union_of_cells() -> None:
    """The traced grid polygon is valid and equals the union of its cells, pinches included."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        shape = rng.integers(1, 12, size=2)
        labels, count = ndimage.label(rng.random(shape) < rng.uniform(0.3, 0.9))
        if count == 0:
            continue
        occ = labels == np.argmax(np.bincount(labels.ravel())[1:]) + 1
        rows = ["".join("." if v else "#" for v in row) for row in occ]
        r, c = np.nonzero(occ)
        level = parse_level(grid_level(grid=rows, guards=[[c[0] + 0.5, r[0] + 0.5]]))
        union = shapely.unary_union(shapely.box(c, r, c + 1, r + 1))
        assert level.walkable.is_valid, shapely.is_valid_reason(level.walkable)
        assert level.walkable.symmetric_difference(union).area == pytest.approx(0.0, abs=1e-9)
        assert level.walkable.exterior.is_ccw


# --------------------------------------------------------------------------- bad input

# (id, file content: dict -> JSON, str/bytes -> raw, field named, words in the problem)
BAD_LEVELS: list[tuple[str, Any, str, str]] = [
    ("empty file", "", "file", "empty"),
    ("blank file", "  \n\t", "file", "empty"),
    ("not utf-8", b"\xff\xfe{}", "file", "UTF-8"),
    ("not json", '{"format": "stealth-level/1",', "json", "not valid JSON"),
    ("top-level array", "[1, 2]", "top-level", "JSON object"),
    ("unknown key", grid_level(walls=[]), "walls", "unknown key"),
    ("duplicate key", '{"name": "a", "name": "b"}', "name", "duplicate key"),
    ("missing format", grid_level(format=None), "format", "missing required key"),
    ("missing name", grid_level(name=None), "name", "missing required key"),
    ("missing guards", grid_level(guards=None), "guards", "missing required key"),
    ("wrong format", grid_level(format="stealth-level/2"), "format", "stealth-level/1"),
    ("name not a string", grid_level(name=3), "name", "expected a non-empty string"),
    ("string for number", grid_level(cell_size="1"), "cell_size", "expected a number"),
    ("boolean for number", grid_level(cell_size=True), "cell_size", "got a boolean"),
    ("cell size zero", grid_level(cell_size=0), "cell_size", "must be in [0.001, 1e+06]"),
    ("cell size negative", grid_level(cell_size=-1.5), "cell_size", "must be in [0.001, 1e+06]"),
    ("point of 3 numbers", grid_level(guards=[[1, 2, 3]]), "guards[0]", "expected a point"),
    ("guards not a list", grid_level(guards={"x": 1}), "guards", "expected an array"),
    ("string coordinate", grid_level(guards=[["1", 2]]), "guards[0][0]", "expected a number"),
    ("both geometries", grid_level(outline=rect(0, 0, 4, 3)), "outline/grid", "both"),
    ("no geometry", grid_level(grid=None), "outline/grid", "no geometry"),
    ("obstacles with grid", grid_level(obstacles=[]), "obstacles", "only allowed with"),
    ("ragged grid", grid_level(grid=["....", "...", "...."]), "grid[1]", "row has 3 cells"),
    ("empty grid", grid_level(grid=[]), "grid", "empty"),
    ("empty grid row", grid_level(grid=[""]), "grid[0]", "empty"),
    ("grid row not a string", grid_level(grid=["..", 7]), "grid[1]", "expected a string"),
    ("grid not a list", grid_level(grid="...."), "grid", "expected an array"),
    ("grid too large", grid_level(grid=["." * 1001] * 1000), "grid", "exceeds the limit"),
    (
        "outline too large",
        polygon_level(outline=rect(0, 0, 1e6, 1e6)),
        "outline",
        "exceeds the limit",
    ),
    (
        "two distinct points",
        polygon_level(outline=[[0, 0], [4, 0], [0, 0]]),
        "outline",
        "3 distinct",
    ),
    ("zero area", polygon_level(outline=[[0, 0], [2, 0], [4, 0]]), "outline", "zero area"),
    (
        "self-intersecting",
        polygon_level(outline=[[0, 0], [4, 3], [4, 0], [0, 3]]),
        "outline",
        "Self-intersection",
    ),
    (
        "self-intersecting obstacle",
        polygon_level(obstacles=[[[1, 1], [3, 2], [3, 1], [1, 2]]]),
        "obstacles[0]",
        "not simple",
    ),
    ("negative outline", polygon_level(outline=rect(-1, 0, 4, 3)), "outline", "negative"),
    (
        "obstacle outside",
        polygon_level(obstacles=[rect(7, 0, 8, 1)]),
        "obstacles[0]",
        "entirely outside",
    ),
    ("nan literal", '{"format": "stealth-level/1", "name": "t", "grid": ["."], '
     '"guards": [[NaN, 0.5]]}', "guards[0][0]", "non-finite"),
    ("infinity literal", '{"format": "stealth-level/1", "name": "t", "grid": ["."], '
     '"guards": [[0.5, -Infinity]]}', "guards[0][1]", "non-finite"),
    ("overflowing float", '{"format": "stealth-level/1", "name": "t", "grid": ["."], '
     '"cell_size": 1e999, "guards": [[0.5, 0.5]]}', "cell_size", "non-finite"),
    (
        "disconnected grid",
        grid_level(grid=["..#..", "..#.."]),
        "grid",
        "2 disconnected groups",
    ),
    ("diagonal-only grid", grid_level(grid=[".#", "#."]), "grid", "disconnected"),
    (
        "disconnected polygon",
        polygon_level(obstacles=[rect(2, -1, 3, 5)]),
        "obstacles",
        "2 disconnected pieces",
    ),
    (
        "passage narrower than a cell",
        polygon_level(obstacles=[rect(1.8, 0, 3.2, 1.9), rect(1.8, 2.1, 3.2, 4)]),
        "obstacles",
        "disconnected groups",
    ),
    ("nothing walkable", polygon_level(obstacles=[rect(-1, -1, 7, 5)]), "obstacles", "nothing"),
    ("no walkable cell (grid)", grid_level(grid=["##", "##"]), "grid", "no walkable cell"),
    (
        "no walkable cell (polygon)",
        polygon_level(outline=[[0, 0], [0.4, 0], [0, 0.4]], guards=[[0.1, 0.1]]),
        "outline",
        "no walkable cell",
    ),
    ("guard in wall", grid_level(guards=[[0.5, 0.5], [1.5, 1.5]]), "guards[1]", "inside a wall"),
    ("guard outside", grid_level(guards=[[4.5, 0.5]]), "guards[0]", "outside the level"),
    (
        "guard outside outline",
        polygon_level(outline=[[0, 0], [6, 0], [0, 4]], guards=[[5, 3]]),
        "guards[0]",
        "outside the level",
    ),
    (
        "guard in obstacle",
        polygon_level(obstacles=[rect(1, 1, 2, 2)], guards=[[1.5, 1.2]]),
        "guards[0]",
        "inside a wall",
    ),
    (
        "guard in a blocked cell",
        polygon_level(obstacles=[rect(1, 0, 1.6, 1)], guards=[[1.8, 0.5]]),
        "guards[0]",
        "not walkable",
    ),
    ("no guards", grid_level(guards=[]), "guards", "at least one"),
    ("decoy in wall", grid_level(decoys=[[1.5, 1.5]]), "decoys[0]", "inside a wall"),
    ("decoy outside", grid_level(decoys=[[0.5, -1]]), "decoys[0]", "outside the level"),
    ("zones not an object", grid_level(zones=[]), "zones", "expected an object"),
    ("unknown zone kind", grid_level(zones={"fog": []}), "zones.fog", "unknown zone kind"),
    (
        "bad zone polygon",
        grid_level(zones={"dark": [[[0, 0], [1, 1], [2, 2]]]}),
        "zones.dark[0]",
        "zero area",
    ),
    (
        "zone off the level",
        grid_level(zones={"concealment": [rect(10, 10, 11, 11)]}),
        "zones.concealment[0]",
        "does not overlap",
    ),
]


@pytest.mark.parametrize(
    ("content", "field", "words"), [case[1:] for case in BAD_LEVELS], ids=[c[0] for c in BAD_LEVELS]
)
def test_bad_level_file(tmp_path: Path, content: Any, field: str, words: str) -> None:
    path = tmp_path / "bad.json"
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content)
    else:
        path.write_text(json.dumps(content))
    assert_level_error(path, field, words)


def test_missing_file(tmp_path: Path) -> None:
    assert_level_error(tmp_path / "nowhere.json", "file", "no such file")


def test_directory_instead_of_file(tmp_path: Path) -> None:
    folder = tmp_path / "level.json"
    folder.mkdir()
    assert_level_error(folder, "file", "directory")


def test_parse_level_names_its_source() -> None:
    with pytest.raises(LevelError) as info:
        parse_level(grid_level(guards=[]), "inline test")
    assert str(info.value) == "inline test: guards: needs at least one point"


def test_level_error_is_a_picklable_value_error() -> None:
    error = LevelError("maze.json", "guards[1]", "point (3.5, 4.5) is inside a wall")
    assert isinstance(error, ValueError)
    assert str(error) == "maze.json: guards[1]: point (3.5, 4.5) is inside a wall"
    copy = pickle.loads(pickle.dumps(error))
    assert (copy.source, copy.field, copy.problem) == (error.source, error.field, error.problem)
    assert str(LevelError("a\nb", "f", "two\nlines")) == "a b: f: two lines"


def assert_level_error(path: Path, field: str, words: str) -> None:
    """Loading ``path`` fails with one line ``<path>: <field>: <problem containing words>``."""
    with pytest.raises(LevelError) as info:
        load_level(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {field}: "), message
    assert words in info.value.problem, message
    assert info.value.field == field


def test_validate_a_level_of_many_holes_one_near_its_outline(tmp_path, capsys):
    """More than LOCAL_MIN_HOLES obstacles, one of them closer to the outline than a body:
    the body check's local path indexed the holes with numpy integers, which shapely
    refuses (a TypeError traceback from ``stealth validate``; found loading a Tiled map
    whose walled-off pockets issue 41 now blocks)."""
    from headless.cli import main

    pillars = [[[x + 0.4, y + 0.4], [x + 0.6, y + 0.4], [x + 0.6, y + 0.6], [x + 0.4, y + 0.6]]
               for x in range(2, 14, 1) for y in range(2, 14, 1)]
    near = [[0.3, 5.0], [0.5, 5.0], [0.5, 5.5], [0.3, 5.5]]  # 0.3 from the outline
    level = {"format": "stealth-level/1", "name": "holes",
             "outline": [[0, 0], [16, 0], [16, 16], [0, 16]],
             "obstacles": [*pillars, near], "guards": [[1.5, 1.5]]}
    path = tmp_path / "holes.json"
    path.write_text(json.dumps(level))
    assert main(["validate", str(path)]) == 0
    assert "ok (holes" in capsys.readouterr().err
