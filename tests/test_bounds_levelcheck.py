"""Issue 24 class 3: one level check shared by every command.

``validate`` refused a level whose walkable area a body cannot cross (a 1e-9-wide corridor
between two rooms) while ``sim``, ``run`` and ``play`` simulated it. The body check is now
:func:`navmesh.clearance.check_body`, called by ``validate`` and by
:func:`game.schema.check_level`, which every command and the world run.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from game.config import Config
from game.schema import check_level
from headless.cli import main
from navmesh.errors import LevelError
from navmesh.level import bundled_level_names, load_level

LO, HI = 1.5 - 5e-10, 1.5 + 5e-10
CORRIDOR = {"format": "stealth-level/1", "name": "corridor",
            "outline": [[0, 0], [4, 0], [4, LO], [6, LO], [6, 0], [10, 0], [10, 3], [6, 3],
                        [6, HI], [4, HI], [4, 3], [0, 3]],
            "guards": [[1, 1], [8, 1]]}
MESSAGE = "walkable area: an agent of radius 0.3 cannot reach the whole level: it is in 2 pieces"


@pytest.fixture
def corridor(tmp_path: Path) -> Path:
    path = tmp_path / "corridor.json"
    path.write_text(json.dumps(CORRIDOR))
    return path


def _preset(tmp_path: Path, level: Path) -> Path:
    path = tmp_path / "p.toml"
    path.write_text(f'levels = ["{level}"]\nabstractions = ["grid"]\nguards = ["random"]\n'
                    'players = ["maxmin"]\nscenarios = ["capture"]\nseeds = 1\n')
    return path


@pytest.mark.parametrize("command", ["validate", "sim", "sim-partition", "run", "play"])
def test_every_command_refuses_what_validate_refuses(corridor, tmp_path, capsys, command):
    args = {"validate": ["validate", str(corridor)], "sim": ["sim", str(corridor)],
            "sim-partition": ["sim", str(corridor), "--abstraction", "partition"],
            "run": ["run", "--preset", str(_preset(tmp_path, corridor)),
                    "--out", str(tmp_path / "out")],
            "play": ["play", str(corridor)]}[command]
    assert main(args) == 2
    lines = [line for line in capsys.readouterr().err.strip().splitlines()
             if not line.startswith("pygame")]
    assert len(lines) == 1 and lines[0].startswith("stealth: error: ") and MESSAGE in lines[0]
    assert not (tmp_path / "out").exists()


def test_the_world_check_is_the_validate_check(corridor):
    with pytest.raises(LevelError, match=MESSAGE):
        check_level(Config.defaults(), load_level(corridor))
    wide = {**CORRIDOR, "outline": [[x, 1.0 if y == LO else 2.0 if y == HI else y]
                                    for x, y in CORRIDOR["outline"]]}
    path = corridor.with_name("wide.json")
    path.write_text(json.dumps(wide))
    check_level(Config.defaults(), load_level(path))  # a one-unit corridor is passable


@pytest.mark.parametrize("name", bundled_level_names())
def test_the_bundled_levels_pass_the_shared_check(name):
    check_level(Config.defaults(), load_level(name))
