"""Issue 24 class 5: absurd cell sizes and coordinates end in one line, in every command.

A cell size of 1e200 (or coordinates of that size) used to pass the level check and then
break the geometry in ``sim``, ``path`` and ``play`` (GEOS and numpy tracebacks): double
precision cannot hold a 0.3-unit body beside 1e200. The level check bounds the cell size
to [MIN_CELL_SIZE, MAX_EXTENT] and every coordinate to ±MAX_EXTENT world units, once, for
every command and for Tiled maps too.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from headless.cli import main
from navmesh.errors import LevelError
from navmesh.level import MAX_EXTENT, MIN_CELL_SIZE, load_level, parse_level

ROOT = Path(__file__).resolve().parent.parent
MAZE = json.loads((ROOT / "assets" / "levels" / "maze.json").read_text())


def _scaled(tmp_path: Path, size: float) -> Path:
    level = copy.deepcopy(MAZE)
    level["cell_size"] = size
    level["zones"] = {k: [[[x * size, y * size] for x, y in p] for p in v]
                      for k, v in MAZE["zones"].items()}
    for key in ("guards", "decoys"):
        level[key] = [[x * size, y * size] for x, y in MAZE[key]]
    path = tmp_path / f"cells{size:g}.json"
    path.write_text(json.dumps(level))
    return path


@pytest.mark.parametrize("command", [
    ["validate"], ["sim"], ["sim", "--abstraction", "partition"],
    ["path", "--from", "1e200,1e200", "--to", "3e200,3e200"], ["levels"], ["play"],
])
def test_a_cell_size_of_1e200_is_one_line_in_every_command(tmp_path, capsys, command):
    path = str(_scaled(tmp_path, 1e200))
    args = [command[0], path, *command[1:]]
    assert main(args) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[-1].startswith("stealth: error: ") and "cell_size: must be in" in lines[-1]
    assert not any("Traceback" in line for line in lines)


def test_cell_sizes_and_extents_at_the_limits(tmp_path):
    with pytest.raises(LevelError, match="cell_size: must be in"):
        load_level(_scaled(tmp_path, MIN_CELL_SIZE / 2))
    load_level(_scaled(tmp_path, MIN_CELL_SIZE))
    with pytest.raises(LevelError, match="would span 2e\\+06 world units"):
        load_level(_scaled(tmp_path, MAX_EXTENT / 10))  # 20 cells of 10^5
    huge = {"format": "stealth-level/1", "name": "far", "cell_size": 1e5,
            "outline": [[0, 0], [1e200, 0], [1e200, 1e200], [0, 1e200]], "guards": [[1, 1]]}
    with pytest.raises(LevelError, match="outline: coordinates beyond"):
        parse_level(huge)


def test_a_large_cell_size_in_range_still_runs(tmp_path, capsys):
    assert main(["sim", str(_scaled(tmp_path, 1e4)), "--set", "world.duration=2"]) == 0
