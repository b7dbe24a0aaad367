"""Published Tiled maps as shipped, TMX beside JSON, and the warnings of foreign maps.

``tests/data/tiled`` holds copies of real maps (Tiled's examples, pytiled-parser's and
arcade's test maps; ``README.md`` there says where each came from, with the licences). Each
must either load — with one warning line per thing it lacks — or be refused in one line.
"""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from headless.cli import main
from navmesh.errors import LevelWarning
from navmesh.level import LEVELS_DIR, LevelError, load_level, parse_level

ROOT = Path(__file__).resolve().parents[1]
HELD = ROOT / "tests" / "data" / "tiled"
MAZE = json.loads((LEVELS_DIR / "maze.json").read_text())
NO_GUARD = "no object of class 'guard'"
EMPTY = "the level is an empty box"

# map -> (rows, cols, the warnings it gives) or the refusal
LOADS = {
    "tiled_examples/desert.tmx": (40, 40, [NO_GUARD, f"{EMPTY} (40x40 tiles)"]),
    "tiled_examples/sewers.tmx": (50, 50, [NO_GUARD, f"{EMPTY} (50x50 tiles)"]),
    "tiled_examples/perspective_walls.tmx": (32, 32, [
        NO_GUARD, "2 walkable cells in 2 pockets walled off from the rest"]),
    "tiled_examples/sewer_automap/rule_001.tmx": (3, 7, [  # TMX 1.0: objects without id
        "object 1 'StinkingAcid' (dmg): unknown class 'DMG', treated as decoration",
        NO_GUARD, f"{EMPTY} (7x3 tiles)"]),
    "pytiled_parser/layer_tests/all_layer_types/map.json": (6, 8, [NO_GUARD, f"{EMPTY} (8x6 tiles)"]),
    "pytiled_parser/layer_tests/b64_zstd/map.tmx": (6, 8, [NO_GUARD, f"{EMPTY} (8x6 tiles)"]),
    "pytiled_parser/layer_tests/infinite_map/map.json": (7, 9, [NO_GUARD, f"{EMPTY} (infinite)"]),
    "pytiled_parser/map_tests/embedded_tileset/map.tmx": (6, 8, [NO_GUARD, f"{EMPTY} (8x6 tiles)"]),
    "arcade/test_objects.json": (20, 20, [
        "object 7 'crate1' (crate): unknown class 'crate', treated as decoration",
        "object 8 'coin1' (coin): unknown class 'coin', treated as decoration",
        NO_GUARD]),  # its two tile objects of a tile with a collision polygon block
}
REFUSED = {
    "tiled_examples/hexagonal-mini.tmx": "map: orientation 'hexagonal' is not supported",
    "tiled_examples/isometric_grass_and_water.tmx": "map: orientation 'isometric' is not supported",
    "pytiled_parser/map_tests/hexagonal/map.tmx": "map: orientation 'hexagonal' is not supported",
}


def test_the_held_set_is_every_map_shipped_there():
    shipped = {p.relative_to(HELD).as_posix() for p in HELD.rglob("*")
               if p.suffix in (".tmx", ".tmj") or p.name in ("map.json", "test_objects.json")}
    assert shipped == set(LOADS) | set(REFUSED)
    for folder in ("tiled_examples", "pytiled_parser", "arcade"):
        assert any((HELD / folder).glob("LICENSE*")) or (HELD / folder / "COPYING").is_file()
    assert all(name in (HELD / "README.md").read_text() for name in (*LOADS, *REFUSED))


@pytest.mark.parametrize("name", sorted(LOADS))
def test_a_published_map_loads_with_one_warning_per_missing_part(name):
    rows, cols, expected = LOADS[name]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        level = load_level(HELD / name)
    notes = [str(w.message) for w in caught if issubclass(w.category, LevelWarning)]
    assert len(notes) == len(expected), notes
    for note, part in zip(notes, expected):
        assert note.startswith(f"{HELD / name}: ") and part in note and "\n" not in note, note
    assert (level.rows, level.cols) == (rows, cols)
    assert level.guards == () and level.occupancy.any()


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_a_map_that_is_not_orthogonal_is_refused_in_one_line(name):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(LevelError, match=REFUSED[name]) as refused:
            load_level(HELD / name)
    assert "\n" not in str(refused.value) and not caught


def test_validate_prints_one_line_per_warning_and_per_refusal():
    paths = [str(HELD / name) for name in sorted(LOADS) + sorted(REFUSED)]
    done = subprocess.run([sys.executable, "-m", "headless.cli", "validate", *paths],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    lines = done.stderr.splitlines()
    for name, (_, _, expected) in LOADS.items():
        mine = [line for line in lines if f"{HELD / name}: " in line]
        assert len(mine) == len(expected) + 1, mine
        for line, part in zip(mine, expected):
            assert line.startswith(f"stealth: warning: {HELD / name}: ") and part in line
        assert mine[-1].startswith(f"{HELD / name}: ok ("), mine
    for name, refusal in REFUSED.items():
        mine = [line for line in lines if f"{HELD / name}: " in line]
        assert len(mine) == 1 and mine[0].startswith(f"stealth: error: {HELD / name}: {refusal}")


@pytest.mark.parametrize("name", ["tiled_examples/desert.tmx", "arcade/test_objects.json",
                                  "tiled_examples/perspective_walls.tmx"])
def test_sim_runs_a_published_map_with_random_guards(name, capsys):
    assert main(["sim", str(HELD / name), "--guards", "pf", "--player", "maxmin", "--json",
                 "--set", "world.duration=10"]) == 0
    out = capsys.readouterr()
    result = json.loads(out.out)
    assert result["config"]["world.guards"] == 3 and "captured" in result["metrics"]
    warned = [line for line in out.err.splitlines() if line.startswith("stealth: warning: ")]
    assert len(warned) == len(LOADS[name][2]), out.err


def test_spawns_level_without_guard_objects_draws_random_spawns(capsys):
    path = str(HELD / "tiled_examples/sewers.tmx")
    common = ["sim", path, "--guards", "pf", "--player", "maxmin", "--json",
              "--set", "world.duration=5"]
    assert main([*common, "--set", "world.spawns=level"]) == 0
    level_spawns = json.loads(capsys.readouterr().out)["metrics"]
    assert main(common) == 0
    assert json.loads(capsys.readouterr().out)["metrics"] == level_spawns


# --------------------------------------------------------------------------- TMX and old JSON


def _maze_tmx(encoding: str) -> str:
    """maze.json as Tiled writes TMX: a walls layer, guard points, no tilecount (Tiled < 1.0)."""
    gids = np.array([[1 if c == "#" else 0 for c in row] for row in MAZE["grid"]])
    rows, cols = gids.shape
    if encoding == "csv":
        data = '<data encoding="csv">\n' + ",\n".join(
            ",".join(map(str, row)) for row in gids) + "\n</data>"
    else:
        import base64
        import zlib
        packed = base64.b64encode(zlib.compress(gids.astype("<u4").tobytes())).decode()
        data = f'<data encoding="base64" compression="zlib">\n   {packed}\n  </data>'
    guards = "\n".join(
        f'  <object id="{i + 1}" type="guard" x="{x * 32}" y="{y * 32}"><point/></object>'
        for i, (x, y) in enumerate(MAZE["guards"]))
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<map version="1.0" orientation="orthogonal"'
            f' width="{cols}" height="{rows}" tilewidth="32" tileheight="32">\n'
            ' <properties><property name="name" value="maze"/></properties>\n'
            ' <tileset firstgid="1" name="walls" tilewidth="32" tileheight="32">\n'
            '  <image source="walls.png"/>\n </tileset>\n'
            f' <layer name="Walls" width="{cols}" height="{rows}">\n  {data}\n </layer>\n'
            f' <objectgroup name="spawns">\n{guards}\n </objectgroup>\n</map>\n')


@pytest.mark.parametrize("encoding", ["csv", "zlib"])
@pytest.mark.parametrize("suffix", [".tmx", ".xml"])
def test_a_tmx_map_loads_to_the_same_level_as_its_json_twin(tmp_path, encoding, suffix):
    path = tmp_path / f"maze{suffix}"  # by suffix, or by its XML content
    path.write_text(_maze_tmx(encoding))
    level, twin = load_level(path), parse_level(MAZE)
    assert level.name == "maze" and level.guards == twin.guards
    assert np.array_equal(level.occupancy, twin.occupancy)
    assert level.walkable.symmetric_difference(twin.walkable).area < 1e-9


def test_an_old_tiled_json_without_type_goes_to_the_tiled_reader(tmp_path):
    doc = {"height": 3, "width": 3, "tilewidth": 16, "tileheight": 16, "orientation": "orthogonal",
           "version": 1, "backgroundcolor": "#000000", "properties": {"name": "old"},
           "tilesets": [{"firstgid": 1, "image": "t.png", "name": "t", "tilewidth": 16,
                         "tileheight": 16}],  # no tilecount: older Tiled did not write it
           "layers": [{"name": "walls", "type": "tilelayer", "width": 3, "height": 3,
                       "x": 0, "y": 0, "opacity": 1, "visible": True,
                       "data": [0, 0, 0, 0, 1, 0, 0, 0, 0]},
                      {"name": "o", "type": "objectgroup", "x": 0, "y": 0, "opacity": 1,
                       "visible": True, "draworder": "topdown", "objects": [
                           {"id": 1, "name": "", "type": "guard", "x": 8, "y": 8, "width": 0,
                            "height": 0, "rotation": 0, "visible": True, "point": True}]}]}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    level = load_level(path)
    assert level.name == "old" and level.guards == ((0.5, 0.5),)
    assert level.occupancy.tolist() == [[True] * 3, [True, False, True], [True] * 3]


def test_the_documented_unknown_key_message_is_the_code_s():
    """docs/levels.md quotes the unknown-key error with the allowed keys of today's code."""
    with pytest.raises(LevelError) as refused:
        parse_level({**MAZE, "walls": []}, "w.json")
    assert f"`{refused.value}`" in (ROOT / "docs" / "levels.md").read_text()


def test_a_staggered_map_is_refused_in_one_line(tmp_path):
    path = tmp_path / "s.tmx"
    path.write_text(_maze_tmx("csv").replace('orientation="orthogonal"',
                                             'orientation="staggered" staggeraxis="y"'))
    with pytest.raises(LevelError, match="map: orientation 'staggered' is not supported"):
        load_level(path)


@pytest.mark.parametrize("name", sorted(LOADS) + sorted(REFUSED))
def test_a_broken_copy_of_a_published_map_is_a_one_line_error(tmp_path, name):
    """Cut short, or with its first line blank: a LevelError (or a level), never a traceback."""
    text = (HELD / name).read_bytes()
    folder = tmp_path / Path(name).parent
    folder.mkdir(parents=True)
    for source in (HELD / name).parent.iterdir():  # the tilesets and templates beside it
        if source.is_file():
            (folder / source.name).write_bytes(source.read_bytes())
    path = tmp_path / name
    for broken in (text[:len(text) // 3], text[:2 * len(text) // 3], b"\n" + text):
        path.write_bytes(broken)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                load_level(path)
            except LevelError as error:
                assert "\n" not in str(error)


def _collision_conventions(path: Path) -> list[str]:
    """What in a map marks walls the ways Tiled users do (issue 41): layers named or of a
    wall class, tiles of such a class, with a collides-style property, or collision shapes."""
    from pytiled_parser import layer as tl

    from navmesh.tiled_classes import WALL_CLASSES, WALL_PROPERTIES
    from navmesh.tiled_read import read_map

    tmap = read_map(path, path.read_bytes(), str(path))
    found = []

    def walk(layers):
        for layer in layers:
            if {layer.name.strip().lower(), (layer.class_ or "").lower()} & set(WALL_CLASSES):
                found.append(f"layer {layer.name}")
            if isinstance(layer, tl.LayerGroup):
                walk(layer.layers or [])
    walk(tmap.layers)
    for tileset in tmap.tilesets.values():
        for tile in (tileset.tiles or {}).values():
            if (tile.class_ or "").lower() in WALL_CLASSES or tile.objects is not None or any(
                    str(k).lower() in WALL_PROPERTIES for k in (tile.properties or {})):
                found.append(f"tileset {tileset.name} tile {tile.id}")
    return found


@pytest.mark.parametrize("name", sorted(LOADS))
def test_no_published_map_with_a_collision_convention_is_an_empty_box(name):
    conventions = _collision_conventions(HELD / name)
    empty = any(EMPTY in part for part in LOADS[name][2])
    assert empty == (not conventions), conventions
    if conventions:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert not load_level(HELD / name).occupancy.all()
