"""Maps drawn the way Tiled users draw them (issue 41): walls marked on the tileset, guards as
tile objects, a guard with a patrol route — each loads with its walls and guards and plays.

``tests/data/tiled_designer`` holds three small hand-written maps, one per way of marking
walls (a tile class in a ``.tsx``, a ``collides`` property in a ``.tsj``, collision shapes in
an embedded tileset), and an excerpt of Tiled's Sticker Knight sandbox; ``tests/data/tiled``
holds a TMX 1.0 automapping rule file of Tiled's examples, byte for byte.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from ai.baselines import ScriptedGuards
from game.config import Config
from game.trial import TrialSpec, make_world, run_trial
from headless.cli import main
from navmesh.errors import LevelError, LevelWarning
from navmesh.level import load_level

ROOT = Path(__file__).resolve().parents[1]
HERE = ROOT / "tests" / "data" / "tiled_designer"
RULES = ROOT / "tests" / "data" / "tiled" / "tiled_examples" / "sewer_automap" / "rule_001.tmx"

BY_CLASS = ["############",
            "#....#.....#",
            "#....#.....#",
            "#....#.....#",
            "#....#.....#",
            "#..........#",
            "#..........#",
            "#....###...#",
            "#..........#",
            "############"]
BY_COLLIDES = ["##########",
               "#........#",
               "#..##....#",
               "#..##....#",  # (7, 3) is a 'wall'-class tile whose collides = false
               "#........#",
               "#....##..#",  # (6, 5) is a crate drawn flipped
               "#........#",
               "##########"]
BY_SHAPES = ["##########",
             "#........#",
             "#........#",  # (2, 2) and (3, 2): a low wall over the top 12 of 32 pixels
             "#........#",
             "#.....#..#",
             "#.....#..#",
             "#........#",
             "##########"]


def _load(name: str):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        level = load_level(HERE / name)
    return level, [str(w.message) for w in caught if issubclass(w.category, LevelWarning)]


def _cells(level) -> list[str]:
    return ["".join("." if w else "#" for w in row) for row in level.occupancy]


def test_walls_by_tile_class_and_guards_as_tile_objects():
    level, notes = _load("by_class.tmx")
    assert notes == []
    assert _cells(level) == BY_CLASS and int((~level.occupancy).sum()) == 47
    assert level.walkable.area == pytest.approx(73.0)
    # tile objects stand on their bottom-left corner: a 32-px guard tile at (64, 96) covers
    # the cell of rows 2..3 in pixels 64..96, so its centre is (2.5, 2.5), not (2.5, 3.5)
    assert level.guards == ((2.5, 2.5), (8.5, 8.5))
    assert level.facing == pytest.approx((math.pi / 2, math.pi))
    assert level.patrols == (((2.5, 1.5), (7.5, 1.5), (7.5, 5.5)), ())
    assert level.player == (10.5, 1.5) and level.tiled


def test_walls_by_a_collides_property_a_false_one_wins_and_flipped_tiles_count():
    level, notes = _load("by_collides.tmj")
    assert notes == []
    assert _cells(level) == BY_COLLIDES and int((~level.occupancy).sum()) == 38
    assert level.cell_of(7.5, 3.5) == (3, 7) and level.occupancy[3, 7]  # collides = false
    assert not level.occupancy[5, 6]  # gid 2 | horizontal flip: still the crate
    # no class on the objects: each takes its tile's ('guard'; 'Guard' on the third object)
    assert level.guards == ((1.5, 6.5), (7.5, 4.5), (2.5, 2.5))
    assert level.facing == (pytest.approx(math.pi / 2), None, None)
    assert level.patrols == (((1.5, 1.5), (8.5, 1.5), (8.5, 6.5)), (), ())


def test_walls_by_collision_shapes_whole_cells_and_exact_obstacles_objects_without_id():
    level, notes = _load("by_shapes.tmx")
    assert notes == []
    # a shape covering 99 % of its tile or more is a wall cell; the 12-px low wall is an
    # exact obstacle: its cells stay walkable (their centres are free) but its area is not
    assert _cells(level) == BY_SHAPES and int((~level.occupancy).sum()) == 34
    assert level.walkable.area == pytest.approx(46 - 2 * 12 / 32)
    assert not level.contains(2.5, 2.2) and not level.contains(3.9, 2.3)
    assert level.contains(2.5, 2.5) and level.contains(4.1, 2.2)
    # the second guard and the player have no id (as TMX 1.0 wrote them): they load
    assert level.guards == ((1.5, 1.5), (8.5, 6.5)) and level.player == (8.5, 1.5)


def test_the_maps_were_empty_boxes_when_only_a_walls_layer_counted(tmp_path):
    """The same map with its tileset's marks taken away is an empty box (with the warning):
    the walls above come from the tileset, not from the layers' names."""
    doc = json.loads((HERE / "props.tsj").read_text())
    for tile in doc["tiles"]:
        tile.pop("properties", None)
        tile.pop("class", None)
    (tmp_path / "props.tsj").write_text(json.dumps(doc))
    (tmp_path / "m.tmj").write_text((HERE / "by_collides.tmj").read_text())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        level = load_level(tmp_path / "m.tmj")
    assert level.occupancy.all() and level.guards == ((2.5, 2.5),)  # its own class 'Guard'
    assert any("the level is an empty box" in str(w.message) for w in caught)


@pytest.mark.parametrize("name", ["by_class.tmx", "by_collides.tmj", "by_shapes.tmx"])
def test_sim_starts_the_guards_a_map_places_and_runs(name, capsys):
    assert main(["sim", str(HERE / name), "--guards", "fsm", "--player", "maxmin", "--json",
                 "--set", "world.duration=8"]) == 0
    out = capsys.readouterr()
    result = json.loads(out.out)
    assert result["config"]["world.spawns"] == "level", result["config"]
    assert set(result["metrics"]) >= {"captured", "coverage"} and "stealth:" not in out.err
    # an explicit rule still wins
    assert main(["sim", str(HERE / name), "--guards", "fsm", "--json",
                 "--set", "world.duration=2", "--set", "world.spawns=random"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["world.spawns"] == "random"


def test_a_json_level_and_a_map_without_guards_keep_the_configured_rule(capsys):
    assert main(["sim", "maze", "--json", "--set", "world.duration=1"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["world.spawns"] == "random"
    assert main(["sim", str(HERE / "sticker_sandbox.tmx"), "--json",
                 "--set", "world.duration=1"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["world.spawns"] == "random"


def test_placed_guards_stand_where_drawn_and_face_their_facing():
    level = load_level(HERE / "by_class.tmx")
    spec = TrialSpec(level=str(HERE / "by_class.tmx"), guards="fsm",
                     overrides=(("world.spawns", "level"),))
    world = make_world(spec, Config.load(spec.settings), level=level)
    assert [world.graph.node_at(*p) for p in level.guards] == [g.node for g in world.guards]
    assert [g.heading for g in world.guards] == pytest.approx([math.pi / 2, math.pi])
    random_spec = TrialSpec(level=spec.level, guards="fsm")
    drawn = make_world(random_spec, Config.load(random_spec.settings), level=level)
    assert [g.heading for g in drawn.guards] != pytest.approx([math.pi / 2, math.pi])


def test_an_fsm_guard_walks_its_patrol_route_in_order():
    level = load_level(HERE / "by_class.tmx")
    # guards that never see the player stay on patrol (seeing it, they chase as always)
    spec = TrialSpec(level=str(HERE / "by_class.tmx"), guards="fsm", player="maxmin",
                     scenario="fixed", overrides=(("world.spawns", "level"),
                                                  ("world.duration", 40),
                                                  ("world.view_range", 0.01)))
    world = make_world(spec, Config.load(spec.settings), level=level)
    route = [world.graph.node_at(*p) for p in level.patrols[0]]
    ai = world.guard_ai
    assert isinstance(ai, ScriptedGuards)
    targets: list[int] = []
    while not world.done and len(targets) < 7:
        world.step()
        gs = ai.guards[0]
        if gs.state == "patrol" and gs.target is not None and (
                not targets or targets[-1] != gs.target):
            targets.append(gs.target)
    assert targets == [route[k % 3] for k in range(7)], (targets, route)


def test_a_tile_object_of_a_known_class_in_a_sticker_knight_map_is_its_rectangle():
    level, notes = _load("sticker_sandbox.tmx")
    assert (level.rows, level.cols) == (45, 79)
    # the 160x192 px door at (2016, 991) stands on its bottom-left corner
    assert level.exits[0].bounds == pytest.approx((63.0, 24.96875, 68.0, 30.96875))
    assert len(notes) == 2 and "no object of class 'guard'" in notes[0]


def test_a_tmx_1_0_rule_file_loads():
    """Tiled's sewer automapping rule: TMX 1.0, objects without id, tilesets without
    tilecount or columns (refused before with "missing key 'id'")."""
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        level = load_level(RULES)
    assert (level.rows, level.cols) == (3, 7)


def test_a_tile_of_100000_collision_shapes_is_one_line_and_exit_2(tmp_path):
    shapes = ",".join('{"id":%d,"x":0,"y":0,"width":1,"height":1}' % i
                      for i in range(1, 100_001))
    (tmp_path / "t.tsj").write_text(
        '{"name":"t","tilewidth":32,"tileheight":32,"tilecount":1,"columns":1,'
        '"tiles":[{"id":0,"objectgroup":{"type":"objectgroup","objects":[' + shapes + ']}}]}')
    doc = json.loads((HERE / "by_collides.tmj").read_text())
    doc["tilesets"] = [{"firstgid": 1, "source": "t.tsj"}]
    (tmp_path / "m.tmj").write_text(json.dumps(doc))
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "headless.cli", "validate",
                           str(tmp_path / "m.tmj")], capture_output=True, text=True, cwd=ROOT,
                          timeout=120)
    assert time.monotonic() - start < 30
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.splitlines() == [
        f"stealth: error: {tmp_path / 'm.tmj'}: tilesets[0] 't.tsj' tile 0: 100000 collision "
        "shapes on one tile, more than the limit of 256"]


@pytest.mark.parametrize("value,message", [
    ("sideways", "property facing: expected degrees or one of"),
])
def test_a_bad_facing_is_one_line_naming_the_guard(tmp_path, value, message):
    text = (HERE / "by_class.tmx").read_text().replace('value="south"', f'value="{value}"')
    (tmp_path / "m.tmx").write_text(text)
    (tmp_path / "dungeon.tsx").write_text((HERE / "dungeon.tsx").read_text())
    with pytest.raises(LevelError, match=r"layer 'Entities' object 1 'north' \(guard\): "
                       + message):
        load_level(tmp_path / "m.tmx")


def test_a_patrol_point_inside_a_wall_is_one_line_naming_the_guard(tmp_path):
    text = (HERE / "by_class.tmx").read_text().replace('points="0,0 160,0 160,128"',
                                                       'points="0,0 80,0"')
    (tmp_path / "m.tmx").write_text(text)
    (tmp_path / "dungeon.tsx").write_text((HERE / "dungeon.tsx").read_text())
    with pytest.raises(LevelError, match=r"object 1 'north' \(guard\): .*inside a wall"):
        load_level(tmp_path / "m.tmx")


def test_one_trial_on_each_map_through_the_python_api():
    for name in ("by_class.tmx", "by_collides.tmj", "by_shapes.tmx"):
        spec = TrialSpec(level=str(HERE / name), guards="pf", player="maxmin",
                         overrides=(("world.spawns", "level"), ("world.duration", 5)))
        row = run_trial(spec)
        assert np.isfinite(row["metrics"]["coverage"]) and row["metrics"]["coverage"] > 0, name


def test_docs_list_the_wall_names_the_loader_reads():
    from navmesh.tiled_classes import WALL_CLASSES, WALL_PROPERTIES

    text = (ROOT / "docs" / "levels.md").read_text(encoding="utf-8")
    classes = ", ".join(f"`{c}`" for c in WALL_CLASSES)
    properties = ", ".join(f"`{p}`" for p in WALL_PROPERTIES)
    assert f"is one of: {classes};" in text and f"named one of: {properties}," in text


def test_a_template_tile_object_counts_its_gid_in_the_template_s_tileset(tmp_path):
    """A template's gid is numbered in the template's own tileset (Sticker Knight's hero.tx
    names ``../objs.tsx`` at firstgid 1): it is moved to where that tileset sits in the map,
    and a tileset the map lacks is added, as Tiled does."""
    for name in ("props.tsj", "dungeon.tsx"):
        (tmp_path / name).write_text((HERE / name).read_text())
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / "crate_guard.tj").write_text(json.dumps({
        "type": "template", "tileset": {"firstgid": 11, "source": "../props.tsj"},
        "object": {"gid": 14, "width": 32, "height": 32, "name": "", "rotation": 0,
                   "visible": True}}))
    (tmp_path / "t" / "dungeon_guard.tx").write_text(
        '<?xml version="1.0"?><template><tileset firstgid="1" source="../dungeon.tsx"/>'
        '<object gid="3" width="32" height="32"/></template>')
    doc = json.loads((HERE / "by_collides.tmj").read_text())
    doc["layers"][1]["objects"] = [
        {"id": 20, "template": "t/crate_guard.tj", "x": 224, "y": 224},
        {"id": 21, "template": "t/dungeon_guard.tx", "x": 160, "y": 128}]
    (tmp_path / "m.tmj").write_text(json.dumps(doc))
    level = load_level(tmp_path / "m.tmj")
    assert level.guards == ((7.5, 6.5), (5.5, 3.5))
    assert _cells(level) == BY_COLLIDES  # the added tileset changes no tile of the map


def test_layers_and_objects_named_for_collision_block(tmp_path):
    """A tile layer named ``Collision`` blocks every tile on it (any tile); a shape without a
    class in an object layer named ``Collisions`` and an object of class ``solid`` block
    their area; a point there blocks nothing."""
    (tmp_path / "props.tsj").write_text((HERE / "props.tsj").read_text())
    doc = json.loads((HERE / "by_collides.tmj").read_text())
    guard = doc["layers"][1]["objects"][0]
    guard["properties"] = [p for p in guard["properties"] if p["name"] != "patrol"]
    floor = [0] * 80
    floor[1 * 10 + 1] = 1  # the floor tile: no wall anywhere else
    doc["layers"].append({"id": 5, "name": "Collision", "type": "tilelayer", "width": 10,
                          "height": 8, "opacity": 1, "visible": True, "x": 0, "y": 0,
                          "data": floor})
    shape = {"height": 32, "width": 32, "name": "", "rotation": 0, "visible": True}
    doc["layers"].append({"id": 6, "name": "Collisions", "type": "objectgroup",
                          "draworder": "topdown", "opacity": 1, "visible": True, "x": 0,
                          "y": 0, "objects": [
                              {**shape, "id": 30, "x": 256, "y": 32},
                              {**shape, "id": 31, "x": 100, "y": 100, "point": True,
                               "width": 0, "height": 0}]})
    doc["layers"][1]["objects"].append({**shape, "id": 32, "x": 128, "y": 192,
                                        "type": "Solid"})
    (tmp_path / "m.tmj").write_text(json.dumps(doc))
    level = load_level(tmp_path / "m.tmj")
    blocked = {(1, 1), (1, 8), (6, 4)}
    for r, row in enumerate(BY_COLLIDES):
        for c, ch in enumerate(row):
            assert level.occupancy[r, c] == (ch == "." and (r, c) not in blocked), (r, c)


def test_a_collision_shape_whose_sides_cross_is_one_line(tmp_path):
    doc = json.loads((HERE / "props.tsj").read_text())
    doc["tiles"][0]["objectgroup"] = {"type": "objectgroup", "objects": [
        {"id": 7, "x": 0, "y": 0, "polygon": [{"x": 0, "y": 0}, {"x": 32, "y": 32},
                                              {"x": 32, "y": 0}, {"x": 0, "y": 32}]}]}
    (tmp_path / "props.tsj").write_text(json.dumps(doc))
    (tmp_path / "m.tmj").write_text((HERE / "by_collides.tmj").read_text())
    with pytest.raises(LevelError, match=r"m.tmj: tileset 'props' tile 1 collision object 7: "
                                         r"collision shape is not a simple polygon"):
        load_level(tmp_path / "m.tmj")


def test_a_zone_kind_named_like_a_wall_class_is_refused():
    from navmesh.level import register_zone_kind

    with pytest.raises(ValueError, match="zone kind 'Solid': a Tiled map could not tell it "
                                         "from the class 'solid'"):
        register_zone_kind("Solid")


def test_a_tileset_describing_too_many_tiles_is_one_line_before_it_is_parsed(tmp_path):
    from navmesh.tiled_tiles import MAX_TILE_ENTRIES

    count = MAX_TILE_ENTRIES + 1
    (tmp_path / "dungeon.tsx").write_text(
        '<?xml version="1.0"?><tileset name="d" tilewidth="32" tileheight="32" '
        f'tilecount="{count}" columns="1">'
        + "".join(f'<tile id="{i}" type="x"/>' for i in range(count)) + "</tileset>")
    (tmp_path / "m.tmx").write_text((HERE / "by_class.tmx").read_text())
    start = time.monotonic()
    with pytest.raises(LevelError, match=r"tilesets\[0\] 'dungeon.tsx': more than 100000 tiles "
                                         r"described in the map's tilesets"):
        load_level(tmp_path / "m.tmx")
    assert time.monotonic() - start < 5


def test_flipped_wall_tiles_flip_their_collision_shapes():
    from shapely.geometry import box

    from navmesh.tiled_tiles import TileWall

    low = TileWall(32.0, 32.0, (box(0, 0, 32, 12),))  # the top 12 pixels
    side = TileWall(32.0, 32.0, (box(0, 0, 8, 32),))  # the left 8 pixels
    H, V, D = 0x80000000, 0x40000000, 0x20000000
    assert low.placed(3, 64, 0)[0].bounds == (64, 0, 96, 12)
    assert low.placed(3 | V, 64, 0)[0].bounds == (64, 20, 96, 32)
    assert low.placed(3 | D, 64, 0)[0].bounds == (64, 0, 76, 32)
    assert side.placed(3 | H, 0, 0)[0].bounds == (24, 0, 32, 32)
    assert side.placed(3, 10, 20, 2.0, 0.5)[0].bounds == (10, 20, 26, 36)
    assert TileWall(32.0, 32.0, ()).placed(3 | H, 0, 0)[0].bounds == (0, 0, 32, 32)


def test_a_room_closed_by_wall_objects_is_blocked_with_a_warning(tmp_path):
    """Solid objects off the tile grid closing a room: the room is unreachable, so it is
    blocked with one warning, as a grid level's pockets are, instead of refusing the map
    ("walkable area is in 2 disconnected pieces")."""
    ring = [(2.25, 3.25, 3.5, 0.25), (2.25, 6.5, 3.5, 0.25),  # x, y, width, height in tiles
            (2.25, 3.25, 0.25, 3.5), (5.5, 3.25, 0.25, 3.5)]
    walls = "".join(f'<object type="solid" x="{x * 32}" y="{y * 32}" width="{w * 32}" '
                    f'height="{h * 32}"/>' for x, y, w, h in ring)
    text = (HERE / "by_shapes.tmx").read_text().replace(" </objectgroup>\n</map>",
                                                        walls + "</objectgroup></map>")
    (tmp_path / "m.tmx").write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        level = load_level(tmp_path / "m.tmx")
    notes = [str(w.message) for w in caught if issubclass(w.category, LevelWarning)]
    assert len(notes) == 1 and "1 walkable pieces (9 tiles in all) walled off" in notes[0], notes
    assert not level.contains(4.0, 5.0) and not level.occupancy[4:6, 3:5].any()
    assert level.occupancy[1, 1:9].all()


def test_the_python_api_starts_placed_guards_as_sim_does():
    from headless.api import build_world, run_one, trial_spec

    path = str(HERE / "by_class.tmx")
    assert dict(trial_spec(path).overrides)["world.spawns"] == "level"
    assert dict(trial_spec(path, overrides={"world.spawns": "random"}).overrides) == {
        "world.spawns": "random"}
    assert trial_spec("maze").overrides == ()
    world = build_world(path, guards="fsm")
    assert [g.heading for g in world.guards] == pytest.approx([math.pi / 2, math.pi])
    assert run_one(path, guards="fsm", overrides={"world.duration": 2})["config"][
        "world.spawns"] == "level"
