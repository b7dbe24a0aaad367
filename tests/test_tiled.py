"""Tiled maps: each layer-data encoding, infinite maps, groups, shapes and errors (SPEC §10).

Every map is written here the way Tiled writes it (all the keys Tiled emits) from a JSON
level, its twin; the two must load to the same walkable area, grid and spawn points.
"""

from __future__ import annotations

import base64
import copy
import gzip
import json
import re
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import Point, Polygon, box

import navmesh.level_fields as level_module
from navmesh.errors import LevelWarning
from navmesh.level import LEVELS_DIR, LevelError, load_level, parse_level, register_zone_kind

ROOT = Path(__file__).resolve().parents[1]
T = 32  # pixels per tile, as in most Tiled maps
MAZE = json.loads((LEVELS_DIR / "maze.json").read_text())


# --------------------------------------------------------------------------- writing maps


class MapWriter:
    """Builds Tiled JSON documents: layers and objects with every key Tiled writes."""

    def __init__(self) -> None:
        self.next_object = 1
        self.next_layer = 1

    def _layer_id(self) -> int:
        self.next_layer += 1
        return self.next_layer - 1

    def obj(self, cls: str, x: float, y: float, w: float = 0, h: float = 0, *,
            rotation: float = 0, key: str = "type", name: str = "", **shape) -> dict:
        o = {"height": h, "id": self.next_object, "name": name, "rotation": rotation,
             key: cls, "visible": True, "width": w, "x": x, "y": y, **shape}
        self.next_object += 1
        return o

    def point(self, cls: str, x: float, y: float, **kw) -> dict:
        return self.obj(cls, x, y, point=True, **kw)

    def polygon(self, cls: str, x: float, y: float, points, **kw) -> dict:
        return self.obj(cls, x, y, polygon=[{"x": px, "y": py} for px, py in points], **kw)

    def objects(self, name: str, objects: list, offset=(0, 0)) -> dict:
        layer = {"draworder": "topdown", "id": self._layer_id(), "name": name,
                 "objects": objects, "opacity": 1, "type": "objectgroup", "visible": True,
                 "x": 0, "y": 0}
        return _with_offset(layer, offset)

    def group(self, name: str, layers: list, offset=(0, 0)) -> dict:
        layer = {"id": self._layer_id(), "layers": layers, "name": name, "opacity": 1,
                 "type": "group", "visible": True, "x": 0, "y": 0}
        return _with_offset(layer, offset)

    def tiles(self, name: str, gids: np.ndarray, *, encoding: str = "csv",
              compression: str = "", chunk: int | None = None, origin=(0, 0),
              offset=(0, 0), cls: str | None = None) -> dict:
        """A tile layer; with ``chunk`` the layer of an infinite map, ``origin`` its tile."""
        rows, cols = gids.shape
        layer: dict = {"id": self._layer_id(), "name": name, "opacity": 1,
                       "type": "tilelayer", "visible": True, "x": 0, "y": 0}
        if cls is not None:
            layer["class"] = cls
        if encoding == "base64":
            layer.update(compression=compression, encoding="base64")
        if chunk is None:
            layer.update(data=_encode(gids, encoding, compression), height=rows, width=cols)
        else:
            x0, y0 = origin
            pad_r, pad_c = -(-rows // chunk) * chunk, -(-cols // chunk) * chunk
            padded = np.zeros((pad_r, pad_c), dtype=np.uint32)
            padded[:rows, :cols] = gids
            layer["chunks"] = [
                {"data": _encode(padded[r:r + chunk, c:c + chunk], encoding, compression),
                 "height": chunk, "width": chunk, "x": x0 + c, "y": y0 + r}
                for r in range(0, pad_r, chunk) for c in range(0, pad_c, chunk)
            ]
            layer.update(height=pad_r, width=pad_c, startx=x0, starty=y0)
        return _with_offset(layer, offset)

    def map(self, width: int, height: int, layers: list, *, infinite: bool = False,
            properties: list | None = None, tile_h: int = T, **extra) -> dict:
        doc = {"compressionlevel": -1, "height": height, "infinite": infinite,
               "layers": layers, "nextlayerid": self.next_layer,
               "nextobjectid": self.next_object, "orientation": "orthogonal",
               "renderorder": "right-down", "tiledversion": "1.10.2", "tileheight": tile_h,
               "tilesets": [{"columns": 1, "firstgid": 1, "image": "walls.png",
                             "imageheight": T, "imagewidth": T, "margin": 0,
                             "name": "walls", "spacing": 0, "tilecount": 1,
                             "tileheight": T, "tilewidth": T}],
               "tilewidth": T, "type": "map", "version": "1.10", "width": width, **extra}
        if properties:
            doc["properties"] = properties
        return doc


def _with_offset(layer: dict, offset) -> dict:
    if offset != (0, 0):  # Tiled writes both keys, and only when the offset is not zero
        layer["offsetx"], layer["offsety"] = offset
    return layer


def _encode(gids: np.ndarray, encoding: str, compression: str):
    flat = [int(g) for g in np.asarray(gids).ravel()]
    if encoding == "csv":
        return flat
    raw = struct.pack(f"<{len(flat)}I", *flat)
    if compression == "zlib":
        raw = zlib.compress(raw)
    elif compression == "gzip":
        raw = gzip.compress(raw)
    elif compression == "zstd":
        import zstd  # pytiled-parser's zstd extra; Tiled writes one zstd frame per layer

        raw = zstd.compress(raw)
    return base64.b64encode(raw).decode("ascii")


def grid_gids(grid: list[str]) -> np.ndarray:
    return np.array([[1 if ch == "#" else 0 for ch in row] for row in grid], dtype=np.uint32)


def spawn_objects(w: MapWriter, level: dict, dx: float = 0, dy: float = 0) -> list:
    """Guards, decoys and axis-aligned rectangular zones of a JSON level, in pixels."""
    objects = []
    for kind, polygons in level.get("zones", {}).items():
        for p in polygons:
            (x0, y0), (x1, y1) = np.min(p, axis=0).tolist(), np.max(p, axis=0).tolist()
            objects.append(w.obj(kind, x0 * T - dx, y0 * T - dy, (x1 - x0) * T, (y1 - y0) * T))
    for key, cls in (("guards", "guard"), ("decoys", "decoy")):
        objects += [w.point(cls, x * T - dx, y * T - dy) for x, y in level.get(key, [])]
    return objects


def write(tmp_path: Path, doc: dict, name: str = "map.tmj") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return path


def assert_same_level(tiled, twin) -> None:
    """Same walkable area, grid, spawn points and zones."""
    assert tiled.walkable.symmetric_difference(twin.walkable).area < 1e-9
    assert tiled.cell_size == twin.cell_size
    assert np.array_equal(tiled.occupancy, twin.occupancy)
    assert_same_points(tiled.guards, twin.guards)
    assert_same_points(tiled.decoys, twin.decoys)
    assert set(tiled.zones) == set(twin.zones)
    for kind, polygons in twin.zones.items():
        assert len(tiled.zones[kind]) == len(polygons)
        for a, b in zip(tiled.zones[kind], polygons):
            assert a.symmetric_difference(b).area < 1e-9
    assert tiled.player == (None if twin.player is None else pytest.approx(twin.player))
    assert len(tiled.exits) == len(twin.exits)
    for a, b in zip(tiled.exits, twin.exits):
        assert a.symmetric_difference(b).area < 1e-9
    assert_same_points(tiled.collectibles, twin.collectibles)


def assert_same_points(a, b) -> None:
    a, b = np.reshape(np.asarray(a, float), (-1, 2)), np.reshape(np.asarray(b, float), (-1, 2))
    assert a.shape == b.shape and np.allclose(a, b, rtol=0, atol=1e-9), (a, b)


# --------------------------------------------------------------------------- equivalence


def test_bundled_maze_tmj_is_maze_json():
    tiled, twin = load_level(LEVELS_DIR / "maze.tmj"), load_level("maze")
    assert tiled.name == "maze" and tiled.path.name == "maze.tmj"
    assert_same_level(tiled, twin)


@pytest.mark.parametrize("encoding,compression", [
    ("csv", ""), ("base64", ""), ("base64", "zlib"), ("base64", "gzip"), ("base64", "zstd"),
])
def test_every_layer_data_encoding(tmp_path, encoding, compression):
    twin = json.loads((LEVELS_DIR / "miami.json").read_text())
    w = MapWriter()
    gids = grid_gids(twin["grid"])
    layers = [w.tiles("walls", gids, encoding=encoding, compression=compression),
              w.objects("spawns", spawn_objects(w, twin))]
    path = write(tmp_path, w.map(gids.shape[1], gids.shape[0], layers))
    assert_same_level(load_level(path), parse_level(twin))


@pytest.mark.parametrize("encoding,compression", [("csv", ""), ("base64", "zlib")])
def test_infinite_map_in_chunks_is_cut_to_its_walls_and_moved_to_the_origin(
        tmp_path, encoding, compression):
    """Chunks start at negative tiles; the level is the walls' bounds, shifted by whole tiles."""
    w = MapWriter()
    gids = grid_gids(MAZE["grid"])
    ox, oy = -21, -5  # tile where the maze's top-left corner lies in the infinite map
    layers = [w.tiles("walls", gids, encoding=encoding, compression=compression, chunk=16,
                      origin=(ox, oy)),
              w.objects("spawns", spawn_objects(w, MAZE, -ox * T, -oy * T))]
    path = write(tmp_path, w.map(30, 20, layers, infinite=True))
    assert_same_level(load_level(path), parse_level(MAZE))


def test_group_offsets_add_up(tmp_path):
    """A walls layer in a group: group (2, 0) tiles + layer (-1, 1) tiles = (1, 1) tiles."""
    w = MapWriter()
    gids = grid_gids(MAZE["grid"])
    shifted = np.zeros_like(gids)
    shifted[:-1, :-1] = gids[1:, 1:]  # drawn one tile up-left of where it ends up
    border = np.zeros_like(gids)
    border[0, :], border[:, 0] = 1, 1  # the top row and left column, drawn in place
    # objects: groups (2, 0) + (1.5, 0) tiles and the layer's (7, -3) px, written undone
    spawns = spawn_objects(w, MAZE, dx=3.5 * T + 7, dy=-3)
    layers = [
        w.group("building", [
            w.tiles("walls", shifted, offset=(-T, T)),
            w.group("people", [w.objects("spawns", spawns, offset=(7, -3))],
                    offset=(1.5 * T, 0)),
        ], offset=(2 * T, 0)),
        w.tiles("Walls", border, encoding="base64", compression="gzip"),
        w.tiles("floor", np.ones_like(gids)),  # not a walls layer: decoration
    ]
    layers[0]["layers"][0]["parallaxx"] = 0.5  # parallax is for rendering only
    path = write(tmp_path, w.map(20, 20, layers))
    assert_same_level(load_level(path), parse_level(MAZE))


def test_a_walls_layer_by_class_and_an_unaligned_offset(tmp_path):
    """Half-tile offsets move the walls off the grid: an outline with obstacle rectangles."""
    w = MapWriter()
    gids = np.zeros((6, 10), dtype=np.uint32)
    gids[2, 3:6] = 1
    gids[4, 7] = 1
    layers = [w.tiles("Tile Layer 1", gids, cls="Walls", offset=(16, 8)),
              w.objects("o", [w.point("guard", 16, 16)])]
    path = write(tmp_path, w.map(10, 6, layers))
    twin = {"format": "stealth-level/1", "name": "map", "outline": [[0, 0], [10, 0], [10, 6],
            [0, 6]], "obstacles": [[[3.5, 2.25], [6.5, 2.25], [6.5, 3.25], [3.5, 3.25]],
                                   [[7.5, 4.25], [8.5, 4.25], [8.5, 5.25], [7.5, 5.25]]],
            "guards": [[0.5, 0.5]]}
    assert_same_level(load_level(path), parse_level(twin))


def test_shapes_rotated_rectangles_polygons_with_an_origin_and_ellipses(tmp_path):
    w = MapWriter()
    objects = [
        # a 2x1-tile rectangle turned 90 degrees clockwise about its top-left corner (6, 2)
        w.obj("obstacle", 6 * T, 2 * T, 2 * T, T, rotation=90),
        w.obj("obstacle", 9 * T, 6 * T, 2 * T, T, rotation=30),
        # polygon points are relative to the object's origin
        w.polygon("obstacle", 2 * T, 7 * T, [(0, 0), (2 * T, 0), (T, 1.5 * T)], rotation=-20),
        w.obj("obstacle", 12 * T, 1 * T, 2 * T, 3 * T, ellipse=True),
        w.obj("dark", 1 * T, 1 * T, 3 * T, 2 * T, ellipse=True, rotation=45),
        w.polygon("concealment", 10 * T, 10 * T, [(0, 0), (3 * T, 0), (3 * T, 2 * T)]),
        w.point("guard", 1.5 * T, 10.5 * T),
        w.obj("guard", 4 * T, 10 * T, T, T),  # any other shape: its centre
        w.obj("decoy", 15 * T, 10 * T, T, 2 * T, rotation=90),  # centre of the turned box
    ]
    path = write(tmp_path, w.map(16, 12, [w.objects("things", objects)]))

    def ellipse(x, y, width, height, rotation=0):
        circle = Point(0, 0).buffer(1, quad_segs=8)  # 32 vertices from angle 0, like Tiled's
        shape = affinity.translate(affinity.scale(circle, width / 2, height / 2),
                                   x + width / 2, y + height / 2)
        return affinity.rotate(shape, rotation, origin=(x, y))  # clockwise on a y-down screen

    ring = lambda g: [list(c) for c in g.exterior.coords[:-1]]  # noqa: E731
    twin = {
        "format": "stealth-level/1", "name": "map",
        "outline": [[0, 0], [16, 0], [16, 12], [0, 12]],
        "obstacles": [
            [[5, 2], [6, 2], [6, 4], [5, 4]],
            ring(affinity.rotate(box(9, 6, 11, 7), 30, origin=(9, 6))),
            ring(affinity.rotate(Polygon([(2, 7), (4, 7), (3, 8.5)]), -20, origin=(2, 7))),
            ring(ellipse(12, 1, 2, 3)),
        ],
        "zones": {"dark": [ring(ellipse(1, 1, 3, 2, 45))],
                  "concealment": [[[10, 10], [13, 10], [13, 12]]]},
        "guards": [[1.5, 10.5], [4.5, 10.5]],
        "decoys": [[14.0, 10.5]],
    }
    assert_same_level(load_level(path), parse_level(twin))


def test_cell_size_property_classes_and_the_added_keys(tmp_path):
    """``cell_size`` scales tiles; ``class`` (Tiled 1.9) or ``type``, any case; new keys."""
    w = MapWriter()
    gids = grid_gids(MAZE["grid"])
    objects = [
        w.point("Guard", 17.5 * T, 1.5 * T, key="class"),
        w.point("GUARD", 9.5 * T, 9.5 * T),
        w.point("player", 1.5 * T, 17.5 * T, name="hero"),
        w.point("collectible", 5.5 * T, 1.5 * T),
        w.obj("exit", 17 * T, 17 * T, 2 * T, 2 * T),
        w.obj("", 3 * T, 3 * T, T, T),  # no class: decoration
        w.obj("", 3 * T, 3 * T, T, T, text={"text": "hello"}),  # a classless text label
    ]
    props = [{"name": "cell_size", "type": "float", "value": 2.0},
             {"name": "name", "type": "string", "value": "big maze"}]
    path = write(tmp_path, w.map(20, 20, [w.tiles("walls", gids), w.objects("o", objects)],
                                 properties=props), name="bigmaze.json")
    twin = {**MAZE, "cell_size": 2.0, "zones": {}, "decoys": [],
            "guards": [[35, 3], [19, 19]], "player": [3, 35], "collectibles": [[11, 3]],
            "exits": [[[34, 34], [38, 34], [38, 38], [34, 38]]]}
    level = load_level(path)  # a .json file whose "type" is "map"
    assert level.name == "big maze"
    assert_same_level(level, parse_level(twin))


def test_zone_kinds_declared_by_a_stimulus(tmp_path, monkeypatch):
    monkeypatch.setattr(level_module, "_zone_kinds", list(level_module.ZONE_KINDS))
    w = MapWriter()
    objects = [w.obj("smoke", 2 * T, 2 * T, 2 * T, 2 * T), w.point("guard", 16, 16)]
    path = write(tmp_path, w.map(6, 6, [w.objects("o", objects)]))
    with pytest.warns(LevelWarning, match=r"object 1 \(smoke\): unknown class 'smoke', "
                                          "treated as decoration"):
        assert "smoke" not in load_level(path).zones
    json_level = {"format": "stealth-level/1", "name": "m", "grid": ["......"] * 6,
                  "zones": {"smoke": [[[2, 2], [4, 2], [4, 4], [2, 4]]]}, "guards": [[0.5, 0.5]]}
    with pytest.raises(LevelError, match="zones.smoke: unknown zone kind"):
        parse_level(json_level)
    register_zone_kind("smoke")
    assert_same_level(load_level(path), parse_level(json_level))
    assert set(parse_level(json_level).zones) == {"dark", "concealment", "smoke"}


# --------------------------------------------------------------------------- level keys


@pytest.mark.parametrize("extra,message", [
    ({"player": [0.5, 1.5]}, r"player: point \(0.5, 1.5\) is inside a wall"),
    ({"player": [30, 1.5]}, r"player: point \(30, 1.5\) is outside the level"),
    ({"player": [1.5]}, "player: expected a point"),
    ({"collectibles": [[1.5, 1.5], [0.2, 0.2]]}, r"collectibles\[1\]: point .* inside a wall"),
    ({"exits": [[[30, 30], [31, 30], [31, 31]]]}, r"exits\[0\]: exit does not overlap"),
    ({"exits": {}}, "exits: expected an array of polygons"),
])
def test_added_level_keys_are_validated(extra, message):
    with pytest.raises(LevelError, match=message):
        parse_level({**MAZE, **extra})


def test_added_level_keys_default_to_nothing():
    level = load_level("maze")
    assert level.player is None and level.exits == () and level.collectibles == ()


# --------------------------------------------------------------------------- errors


def _bad_maps(w: MapWriter) -> list[tuple[str, dict, str]]:
    ok = [w.tiles("walls", grid_gids(MAZE["grid"]))]

    def objs(*objects):
        return ok + [w.objects("things", list(objects))]

    guard = lambda: w.point("guard", 1.5 * T, 1.5 * T)  # noqa: E731
    return [
        ("isometric", {**w.map(20, 20, objs(guard())), "orientation": "isometric"},
         "map: orientation 'isometric' is not supported"),
        ("hexagonal", {**w.map(20, 20, objs(guard())), "orientation": "hexagonal"},
         "map: orientation 'hexagonal' is not supported"),
        ("non-square", w.map(20, 20, objs(guard()), tile_h=16),
         "map: tiles of 32x16 pixels are not supported"),
        ("unknown layer type", w.map(20, 20, [*objs(guard()), {
            "id": 90, "name": "odd", "opacity": 1, "type": "foolayer", "visible": True,
            "x": 0, "y": 0}]), r"layer 'odd': unknown layer type 'foolayer' \(Tiled's layer "
                               r"types are tilelayer, objectgroup, imagelayer, group\)"),
        ("text guard", w.map(20, 20, objs(w.obj("guard", 40, 40, T, T, text={"text": "G"}))),
         r"object \d+ \(guard\): text objects have no shape"),
        ("polyline", w.map(20, 20, objs(guard(), w.obj("obstacle", 40, 40, polyline=[
            {"x": 0, "y": 0}, {"x": 30, "y": 0}]))), "a polyline is not closed"),
        ("point obstacle", w.map(20, 20, objs(guard(), w.point("obstacle", 48, 48))),
         r"\(obstacle\): a point object has no area"),
        ("two players", w.map(20, 20, objs(guard(), w.point("player", 48, 48),
                                           w.point("player", 48, 48))),
         r"\(player\): a second object of class 'player'"),
        ("guard in a wall", w.map(20, 20, objs(guard(), w.point("guard", 16, 16, name="bob"))),
         r"layer 'things' object \d+ 'bob' \(guard\): point \(0.5, 0.5\) is inside a wall"),
        ("obstacle outside", w.map(20, 20, [w.objects("o", [
            guard(), w.obj("obstacle", 2000, 40, T, T)])]),
         r"object \d+ \(obstacle\): obstacle lies entirely outside the outline"),
        ("bad cell_size", w.map(20, 20, objs(guard()), properties=[
            {"name": "cell_size", "type": "string", "value": "big"}]),
         "map property cell_size: expected a number, got 'big'"),
        ("missing key", {k: v for k, v in w.map(20, 20, objs(guard())).items()
                         if k != "tilewidth"}, "map: not a Tiled map .*missing key 'tilewidth'"),
        ("missing template", w.map(20, 20, objs(guard(), {"id": 98, "template": "nowhere.tj",
                                                         "x": 48, "y": 48})),
         "layer 'things' object 98 template: a file the map refers to is missing: .*nowhere.tj"),
        ("tmx template", w.map(20, 20, objs(guard(), {"id": 99, "template": "guard.tx",
                                                     "x": 48, "y": 48})),
         r"object 99 template: .*guard.tx is not an object template \(no <template> holding"),
        ("infinite, empty", w.map(20, 20, [w.objects("o", [guard()])], infinite=True),
         "map: an infinite map without tiles, obstacles or an outline object has no extent"),
    ]


@pytest.mark.parametrize("index", range(15))
def test_bad_maps_are_one_line_errors(tmp_path, index):
    name, doc, message = _bad_maps(MapWriter())[index]
    (tmp_path / "guard.tx").write_text('<?xml version="1.0"?><template/>')
    path = write(tmp_path, doc)
    with pytest.raises(LevelError, match=message) as caught:
        load_level(path)
    assert "\n" not in str(caught.value) and str(caught.value).startswith(f"{path}: "), name


def test_bad_maps_through_the_cli(tmp_path):
    """``validate`` goes on after a bad file: one error line each, exit 2, no traceback."""
    maps = _bad_maps(MapWriter())
    paths = [write(tmp_path, maps[i][1], name=f"bad{i}.tmj") for i in (0, 3, 8, 11)]
    good = LEVELS_DIR / "maze.tmj"
    done = subprocess.run(
        [sys.executable, "-m", "headless.cli", "validate", str(good), *map(str, paths)],
        capture_output=True, text=True, cwd=ROOT, timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert lines[0].startswith(f"{good}: ok"), done.stderr
    lines = lines[1:]
    assert len(lines) == len(paths), done.stderr
    for line, path, i in zip(lines, paths, (0, 3, 8, 11)):
        assert line.startswith(f"stealth: error: {path}: "), line
        assert re.search(maps[i][2], line), (line, maps[i][2])


def test_a_json_file_that_is_not_a_map_is_still_a_level(tmp_path):
    path = tmp_path / "level.json"
    path.write_text(json.dumps({**MAZE, "name": "plain"}))
    assert load_level(path).name == "plain"
    bad = tmp_path / "notmap.tmj"
    bad.write_text("[1, 2]")
    with pytest.raises(LevelError, match="notmap.tmj: map: not a Tiled map"):
        load_level(bad)


def test_walls_cells_of_a_polygon_outline_are_kept_only_where_they_touch_it(tmp_path):
    """With an outline object, wall tiles outside it do not matter."""
    w = MapWriter()
    gids = np.ones((8, 8), dtype=np.uint32)
    gids[2:6, 2:6] = 0
    outline = w.polygon("outline", 2 * T, 2 * T, [(0, 0), (4 * T, 0), (0, 4 * T)])
    path = write(tmp_path, w.map(8, 8, [w.tiles("walls", gids),
                                        w.objects("o", [outline, w.point("guard", 80, 80)])]))
    level = load_level(path)
    assert level.walkable.symmetric_difference(Polygon([(2, 2), (6, 2), (2, 6)])).area < 1e-9
    assert shapely.equals(level.walkable, Polygon([(2, 2), (6, 2), (2, 6)]))


def test_object_templates_in_json_are_read(tmp_path):
    """An instance of a ``.tj`` template carries only its id, position and overrides."""
    (tmp_path / "guard.tj").write_text(json.dumps({"object": {
        "height": 0, "name": "sentry", "point": True, "rotation": 0, "type": "guard",
        "visible": True, "width": 0}, "type": "template"}))
    w = MapWriter()
    objects = [{"id": 7, "template": "guard.tj", "x": 17.5 * T, "y": 1.5 * T},
               {"id": 8, "template": "guard.tj", "x": 9.5 * T, "y": 9.5 * T},
               {"id": 9, "template": "guard.tj", "x": 1.5 * T, "y": 17.5 * T}]
    layers = [w.tiles("walls", grid_gids(MAZE["grid"])), w.objects("o", objects)]
    path = write(tmp_path, w.map(20, 20, layers))
    assert_same_level(load_level(path), parse_level({**MAZE, "zones": {}, "decoys": []}))
