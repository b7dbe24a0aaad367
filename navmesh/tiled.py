"""Tiled maps as levels (SPEC §10 "Tiled maps").

A Tiled map — JSON (``.tmj``, or a ``.json`` that is one, see :mod:`navmesh.tiled_format`)
or TMX (XML, ``.tmx``), with JSON or TSX tilesets — is read with pytiled-parser and converted into the level structure of SPEC §8, which
:func:`navmesh.level.parse_level` then validates: both formats share every check, and a
validation error is reported against the Tiled layer or object it came from.

Conventions (documented for level designers in ``docs/levels.md``):

* one tile is one world unit, or ``cell_size`` units if the map has that number property;
  the grid is the map's tile grid;
* the classes of layers and objects, and what each becomes, are those of
  :mod:`navmesh.tiled_classes` (points: a point object, or the centre of any other shape;
  areas: rectangle, polygon, ellipse as a 32-gon, rotation honoured);
* blocked: the non-zero tiles of the walls layers, the tiles of any layer that the tileset
  marks as walls (:mod:`navmesh.tiled_tiles`: a tile class, a ``collides``-style property,
  collision shapes), the obstacle objects, objects of a wall class (``wall``, ``solid``,
  ``collision``, ...), shapes without a class in an object layer named or of such a class,
  and tile objects of wall tiles; the outline is the map's bounds unless an outline object
  is given (an infinite map is cut to the bounds of its walls and obstacles, shifted by
  whole tiles so that they start at the origin);
* a tile object is its rectangle, whose origin is its bottom-left corner (Tiled's rule for
  tile objects), and takes its tile's class when it has none of its own;
* a guard object's properties ``facing`` (degrees clockwise from +x, or a compass word) and
  ``patrol`` (a reference to a polyline, polygon or point object, or "x,y x,y ..." in tiles)
  become the level's ``facing`` and ``patrols``.

Object classes are matched on the object's ``class`` (Tiled >= 1.9) or legacy ``type``,
case-insensitively; objects without a class are decoration and ignored, and so is an
object of a class Stealthfield does not know, with one :class:`~navmesh.errors.LevelWarning`
each (a published map has classes of its own game; a typo'd guard is named in that line).
A map without any object of a class that has a ``when_missing`` reason (guards: they take
the world's random spawns) warns with it. A map without walls, obstacles or an outline
warns that it is an empty box (an infinite one is cut to the bounds of all its tiles).
Layer offsets count (those of enclosing groups added up); parallax, visibility and opacity
are rendering matters and are ignored.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

import numpy as np
import pytiled_parser
import shapely
from scipy import ndimage
from pytiled_parser import layer as tl
from pytiled_parser import tiled_object as to
from pytiled_parser.common_types import Size
from shapely import affinity
from shapely.geometry import Polygon, box

from navmesh.errors import LevelError, LevelWarning
from navmesh.level_fields import MAX_LEVEL_VERTICES, zone_kinds
from navmesh.level_format import Level, parse_level
from navmesh.tiled_classes import (GUARD, OBSTACLE, OUTLINE, WALL_CLASSES, WALLS, TiledClass,
                                   object_classes)
from navmesh.tiled_guard import MapFiles, check_map_cells
from navmesh.tiled_read import read_map
from navmesh.tiled_tiles import TileRules, TileWall

__all__ = ["ELLIPSE_SIDES", "MAX_TILE_PIXELS", "load_tiled", "tiled_level_data"]

ELLIPSE_SIDES = 32
"""An ellipse object becomes this regular-angle polygon inscribed in it."""

MAX_TILE_PIXELS = 2**16
"""Widest tile read, in pixels. Objects are placed in pixels and a tile is a cell, so an
object one pixel wide is 1/65536 of a cell here, an area the level's checks still tell from
zero; with wider tiles an ordinary map's objects shrink to specks refused as "zero area"."""


@dataclass
class _Collected:
    """What the layers hold, in map pixels (offsets applied), before conversion."""

    classes: dict[str, TiledClass]
    """The object classes known when the map is read, by name (zone kinds included)."""
    rules: TileRules
    """What each tile of the map's tilesets is (its class; whether it is a wall)."""
    tile: float
    """The map's tile size in pixels."""
    walls: list[tuple[str, np.ndarray, np.ndarray, float, float]] = field(default_factory=list)
    """(layer, tile columns, tile rows, offset x px, offset y px) of each walls layer."""
    shapes: dict[str, list[tuple[str, Any]]] = field(default_factory=dict)
    """class -> [(object description, shapely geometry in pixels)]."""
    tile_offsets: list[tuple[float, float]] = field(default_factory=list)
    """The pixel offset of the layer of each entry of ``tile_boxes``."""
    tile_boxes: list[tuple[float, float, float, float]] = field(default_factory=list)
    """Tile bounds (x0, y0, x1, y1 in columns and rows) of the non-zero tiles of each tile
    layer: an infinite map's extent when it has no walls, obstacles or outline."""
    guards: list[tuple[to.TiledObject, float, float, str]] = field(default_factory=list)
    """Each guard object with its layer's offset and its description, in the guards' order."""
    by_id: dict[int, tuple[to.TiledObject, float, float]] = field(default_factory=dict)
    """Every object by id, with its layer's offset (what a ``patrol`` property refers to)."""
    corners: int = 0
    """Corners of the obstacles made from collision shapes so far (bounded)."""


def load_tiled(path: Path, source: str, digest: str | None = None,
               raw: bytes | None = None) -> Level:
    """Read a Tiled map and validate it as a level; errors name the Tiled layer or object.

    ``raw`` is the map's bytes if the caller has read them (else they are read here, bounded);
    ``digest`` is their content identity (see :func:`navmesh.level.cached_level`).
    The map's :class:`~navmesh.errors.LevelWarning` lines are issued only if it loads: a
    refused map is its one error line.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", LevelWarning)
        data, origins = tiled_level_data(path, source, raw)
        try:
            level = parse_level(data, source, path=path, digest=digest, require_guards=False,
                                tiled=True)
        except LevelError as exc:
            raise LevelError(source, _origin(exc.field, origins), exc.problem) from None
    for note in caught:
        warnings.warn_explicit(note.message, note.category, note.filename, note.lineno)
    return level


def tiled_level_data(path: Path, source: str, raw: bytes | None = None
                     ) -> tuple[dict[str, Any], dict[str, str]]:
    """The SPEC §8 level structure of a Tiled map, and where each of its entries came from.

    The second value maps a field of the structure (``"guards[1]"``, ``"obstacles[0]"``,
    ``"grid"``, ...) to the Tiled layer or object it was made from.
    """
    if raw is None:
        raw = MapFiles(source).read(path, "map")
    tmap = _read_map(path, raw, source)
    if tmap.orientation != "orthogonal":
        _fail(source, "map", f"orientation {tmap.orientation!r} is not supported; "
                             "only orthogonal maps are")
    tile_w, tile_h = tmap.tile_size.width, tmap.tile_size.height
    if tile_w != tile_h or tile_w <= 0:
        _fail(source, "map", f"tiles of {tile_w}x{tile_h} pixels are not supported; "
                             "tiles must be square")
    if tile_w > MAX_TILE_PIXELS:
        _fail(source, "map", f"tiles {tile_w} pixels wide are not supported; tiles are at "
                             f"most {MAX_TILE_PIXELS} pixels wide")
    cell_size = _cell_size(tmap, source)
    tile = float(tile_w)
    rules = TileRules(tmap.tilesets or {}, lambda obj, where: _collision_shape(obj, where, source))
    found = _Collected({c.name: c for c in object_classes(zone_kinds())}, rules, tile)
    _collect(tmap.layers, "", 0.0, 0.0, found, source)
    for cls in found.classes.values():
        objects = found.shapes.get(cls.name, [])
        if cls.single and len(objects) > 1:
            _fail(source, objects[1][0], f"a second object of class {cls.name!r}; "
                                         "a map has at most one")
    _warn_of_missing_parts(found, tmap, source)

    # Bounds in tiles: the map's, or for an infinite map those of its content.
    outline_objects = found.shapes.get(OUTLINE.name, [])
    if not tmap.infinite:
        x0, y0, x1, y1 = 0, 0, int(tmap.map_size.width), int(tmap.map_size.height)
    else:
        x0, y0, x1, y1 = _content_bounds(found, outline_objects, tile, source)
    shift = (x0 * tile, y0 * tile)  # pixels; whole tiles so the grid stays the tile grid
    scale = cell_size / tile

    def world(geometry: Any) -> Any:
        return shapely.transform(geometry, lambda xy: (xy - shift) * scale)

    data: dict[str, Any] = {"format": "stealth-level/1", "name": _name(tmap, path, source)}
    data["cell_size"] = cell_size
    origins: dict[str, str] = {}
    aligned = all(ox % tile == 0 and oy % tile == 0 for _, _, _, ox, oy in found.walls)
    obstacle_objects = found.shapes.get(OBSTACLE.name, [])
    walls_origin = ", ".join(f"layer {name!r}" for name, *_ in found.walls) or "map"
    if aligned and not obstacle_objects and not outline_objects:
        data["grid"] = _grid(found, (x0, y0, x1, y1), tile, source)
        origins["grid"] = walls_origin
    else:
        if outline_objects:
            where, outline = outline_objects[0]
        else:
            where, outline = "map bounds", box(x0 * tile, y0 * tile, x1 * tile, y1 * tile)
        data[OUTLINE.field] = _ring(world(outline))
        origins[OUTLINE.field] = where
        obstacles = [*obstacle_objects, *_wall_rectangles(found, outline, tile)]
        obstacles += [("map", piece) for piece in _walled_off(outline, obstacles, tile, source)]
        data[OBSTACLE.field] = [_ring(world(geometry)) for _, geometry in obstacles]
        origins.update((f"{OBSTACLE.field}[{i}]", where) for i, (where, _) in enumerate(obstacles))
        if not obstacles:
            origins[OBSTACLE.field] = walls_origin

    for cls in found.classes.values():  # the rest: points, exits, zones
        if cls in (OBSTACLE, OUTLINE):
            continue
        objects = found.shapes.get(cls.name, [])
        convert = _ring if cls.is_area else _xy
        values = [convert(world(geometry)) for _, geometry in objects]
        if cls.single:
            if values:
                _put(data, cls.field, values[0])
                origins[cls.field] = objects[0][0]
            continue
        _put(data, cls.field, values)
        origins[cls.field] = f"objects of class {cls.name!r}"
        origins.update((f"{cls.field}[{i}]", where) for i, (where, _) in enumerate(objects))
    _guard_properties(found, data, origins, world, tile, source)
    return data, origins


def _guard_properties(found: _Collected, data: dict[str, Any], origins: dict[str, str],
                      world: Any, tile: float, src: str) -> None:
    """``facing`` and ``patrols`` from the guard objects' properties (only when one has them)."""
    facing = [_facing(obj, where, src) for obj, _, _, where in found.guards]
    routes = [_patrol(obj, where, found, tile, src) for obj, _, _, where in found.guards]
    if any(f is not None for f in facing):
        data["facing"] = facing
        origins.update((f"facing[{i}]", g[3]) for i, g in enumerate(found.guards))
    if any(routes):
        data["patrols"] = [[_xy(world(shapely.Point(p))) for p in route] for route in routes]
        origins.update((f"patrols[{i}]", g[3]) for i, g in enumerate(found.guards))


_COMPASS = {"east": 0.0, "e": 0.0, "right": 0.0, "south": 90.0, "s": 90.0, "down": 90.0,
            "west": 180.0, "w": 180.0, "left": 180.0, "north": 270.0, "n": 270.0, "up": 270.0}


def _property(obj: to.TiledObject, name: str) -> Any:
    """The object's custom property ``name`` (any case), or None."""
    for key, value in (obj.properties or {}).items():
        if str(key).strip().lower() == name:
            return value
    return None


def _facing(obj: to.TiledObject, where: str, src: str) -> float | None:
    """A guard's ``facing`` property in degrees clockwise on the screen from +x, or None."""
    value = _property(obj, "facing")
    if value is None or value == "":
        return None
    if isinstance(value, str):
        word = value.strip().lower()
        if word in _COMPASS:
            return _COMPASS[word]
        try:
            value = float(word)
        except ValueError:
            _fail(src, where, f"property facing: expected degrees or one of "
                              f"{', '.join(sorted(set(_COMPASS)))}, got {value!r}")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        _fail(src, where, f"property facing: expected a number of degrees, got {value!r}")
    _finite(src, where, "property facing", _float(value))
    return float(value)


def _patrol(obj: to.TiledObject, where: str, found: _Collected, tile: float, src: str
            ) -> list[tuple[float, float]]:
    """A guard's ``patrol`` route in map pixels: the points of the object it refers to (an
    object property, or an id), or a string of "x,y" pairs in tiles; [] for none."""
    value = _property(obj, "patrol")
    if value is None or value == "" or value == 0:
        return []
    if isinstance(value, int) and not isinstance(value, bool) or (
            isinstance(value, str) and value.strip().isdigit()):
        ref = int(value)
        if ref == 0:
            return []
        if ref not in found.by_id:
            _fail(src, where, f"property patrol: no object with id {ref}")
        target, ox, oy = found.by_id[ref]
        return _route_points(target, ox, oy, f"object {ref}", src)
    if isinstance(value, str):
        pairs = value.replace(";", " ").split()
        try:
            points = [tuple(float(v) * tile for v in pair.split(",")) for pair in pairs]
        except ValueError:
            points = []
        if not points or any(len(p) != 2 for p in points):
            _fail(src, where, f"property patrol: expected an object or \"x,y x,y ...\" in "
                              f"tiles, got {value!r}")
        _finite(src, where, "property patrol", *(v for p in points for v in p))
        return [(p[0], p[1]) for p in points]
    _fail(src, where, f"property patrol: expected an object or \"x,y x,y ...\" in tiles, "
                      f"got {value!r}")


def _route_points(obj: to.TiledObject, ox: float, oy: float, where: str, src: str
                  ) -> list[tuple[float, float]]:
    """The points of a route object in map pixels: a polyline's or polygon's corners in
    order (rotation honoured), a point, or the centre of any other shape."""
    x, y = _float(obj.coordinates.x) + ox, _float(obj.coordinates.y) + oy
    _finite(src, where, "position", x, y)
    if isinstance(obj, (to.Polyline, to.Polygon)):
        local = np.array([(_float(p.x), _float(p.y)) for p in obj.points]).reshape(-1, 2)
        _finite(src, where, "points", *local.ravel())
        theta = math.radians(_float(obj.rotation))
        if theta:
            cos, sin = math.cos(theta), math.sin(theta)
            local = local @ np.array([[cos, sin], [-sin, cos]])
        return [(float(px + x), float(py + y)) for px, py in local]
    if isinstance(obj, to.Point):
        return [(x, y)]
    centre = _object_geometry(obj, ox, oy, where, src, want_area=False)
    return [(float(centre.x), float(centre.y))]


def _put(data: dict[str, Any], field_name: str, value: Any) -> None:
    """Set a field of the level structure; ``"zones.KIND"`` is ``data["zones"]["KIND"]``."""
    *parents, key = field_name.split(".")
    for parent in parents:
        data = data.setdefault(parent, {})
    data[key] = value


# --------------------------------------------------------------------------- reading


def _read_map(path: Path, raw: bytes, source: str) -> pytiled_parser.TiledMap:
    """Read with :func:`navmesh.tiled_read.read_map`; any failure becomes a one-line LevelError.

    The reader signals malformed input with whatever its code happens to raise (KeyError for
    a missing key, TypeError, ValueError, RecursionError for layers nested too deep, ...),
    so everything it raises is caught here and reported with
    its type: the map is user input and must never end in a traceback. The files it names
    and its layers' data are bounded first (:mod:`navmesh.tiled_guard`).
    """
    try:
        return read_map(path, raw, source)
    except LevelError:
        raise
    except KeyError as exc:
        _fail(source, "map", f"not a Tiled map Stealthfield can read: missing key {exc}")
    except RecursionError:
        _fail(source, "map", "not a Tiled map Stealthfield can read: nested too deeply "
                             "(RecursionError)")
    except Exception as exc:  # noqa: BLE001 - third-party reader, see the docstring
        _fail(source, "map", f"not a Tiled map Stealthfield can read: "
                             f"{type(exc).__name__}: {exc}")


def _cell_size(tmap: pytiled_parser.TiledMap, source: str) -> float:
    value = (tmap.properties or {}).get("cell_size", 1.0)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        _fail(source, "map property cell_size", f"expected a number, got {value!r}")
    if not (math.isfinite(_float(value)) and value > 0):
        _fail(source, "map property cell_size", f"must be a finite number > 0, got {value!r}")
    return float(value)


def _name(tmap: pytiled_parser.TiledMap, path: Path, source: str) -> str:
    """The map's string property ``name``, else the file's stem."""
    value = (tmap.properties or {}).get("name", path.stem)
    if not isinstance(value, str):
        _fail(source, "map property name", f"expected a string, got {value!r}")
    return value


def _class_of(thing: Any) -> str:
    return (getattr(thing, "class_", None) or "").strip().lower()


def _collect(
    layers: list[tl.Layer], parent: str, ox: float, oy: float, found: _Collected, src: str
) -> None:
    """Walk the layer tree, adding up group offsets, into ``found``."""
    for layer in layers:
        name = f"{parent}{layer.name}"
        lx, ly = ox + float(layer.offset.x), oy + float(layer.offset.y)
        if isinstance(layer, tl.LayerGroup):
            _collect(layer.layers or [], f"{name}/", lx, ly, found, src)
        elif isinstance(layer, tl.TileLayer):
            is_walls = bool(set(WALL_CLASSES) & {layer.name.strip().lower(), _class_of(layer)})
            cols, rows, gids = _nonzero_tiles(layer, name, src, required=is_walls)
            if is_walls:
                found.walls.append((name, cols, rows, lx, ly))
            elif cols.size:
                _collect_wall_tiles(name, cols, rows, gids, lx, ly, found, src)
            if cols.size:
                found.tile_boxes.append((float(cols.min()), float(rows.min()),
                                         float(cols.max() + 1), float(rows.max() + 1)))
                found.tile_offsets.append((lx, ly))
        elif isinstance(layer, tl.ObjectLayer):
            walls = set(WALL_CLASSES) & {layer.name.strip().lower(), _class_of(layer)}
            for obj in layer.tiled_objects:
                _collect_object(obj, name, lx, ly, found, src, collision_layer=bool(walls))
        # image layers are pictures only


def _nonzero_tiles(layer: tl.TileLayer, name: str, src: str, *, required: bool
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tile columns, rows (layer coordinates) and gids (flip flags kept) of the layer's
    non-zero tiles; a layer without tile data is an error if ``required`` (a walls layer),
    else has none."""
    blocks: list[tuple[float, float, list[list[int]]]] = (
        [(0, 0, layer.data)] if layer.data is not None else [])
    blocks += [(c.coordinates.x, c.coordinates.y, c.data) for c in layer.chunks or []]
    cols, rows, gids = [], [], []
    for x0, y0, data in blocks:
        for r, row in enumerate(data):
            values = np.asarray(row, dtype=np.int64)
            c = np.flatnonzero(values)
            cols.append(c + int(x0))
            rows.append(np.full(c.size, r + int(y0)))
            gids.append(values[c])
    if not cols:
        if required:
            _fail(src, f"layer {name!r}", "walls layer has no tile data")
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(cols), np.concatenate(rows), np.concatenate(gids)


def _collect_wall_tiles(name: str, cols: np.ndarray, rows: np.ndarray, gids: np.ndarray,
                        ox: float, oy: float, found: _Collected, src: str) -> None:
    """The layer's tiles that its tileset marks as walls: whole cells when the tile is
    blocked whole and one cell in size, else obstacles (its collision shapes, or its
    rectangle when it is larger than a cell), drawn as Tiled draws tiles: bottom-left on
    the cell."""
    unique, inverse = np.unique(gids, return_inverse=True)
    walls: list[TileWall | None] = [found.rules.wall(int(g)) for g in unique]
    tile = found.tile
    cell = np.array([w is not None and w.full and (w.width, w.height) == (tile, tile)
                     for w in walls], dtype=bool)[inverse]
    other = np.array([w is not None for w in walls], dtype=bool)[inverse] & ~cell
    if cell.any():
        found.walls.append((name, cols[cell], rows[cell], ox, oy))
    for i in np.flatnonzero(other):
        wall = walls[int(inverse[i])]
        assert wall is not None
        c, r, gid = int(cols[i]), int(rows[i]), int(gids[i])
        where = f"layer {name!r} tile at row {r}, column {c}"
        for polygon in wall.placed(gid, c * tile + ox, (r + 1) * tile + oy - wall.height):
            _add_obstacle(found, where, polygon, src)


def _add_obstacle(found: _Collected, where: str, polygon: Polygon, src: str) -> None:
    """An obstacle made from a tile's collision shape, bounded in corners before the level's
    own checks (a large map of small shapes must not build without end)."""
    found.corners += len(polygon.exterior.coords) - 1
    if found.corners > MAX_LEVEL_VERTICES:
        _fail(src, where, f"the wall tiles' collision shapes have more than "
                          f"{MAX_LEVEL_VERTICES} corners in all")
    found.shapes.setdefault(OBSTACLE.name, []).append((where, polygon))


def _collision_shape(obj: to.TiledObject, where: str, src: str) -> Polygon | None:
    """A tile's collision object as a polygon in tile pixels; None for one without area."""
    if not isinstance(obj, (to.Rectangle, to.Ellipse, to.Polygon)):
        return None
    if not isinstance(obj, to.Polygon) and (_float(obj.size.width) <= 0
                                            or _float(obj.size.height) <= 0):
        return None
    described = f"{where} collision object {obj.id}"
    geometry = _object_geometry(obj, 0.0, 0.0, described, src, want_area=True)
    if not geometry.is_valid:
        _fail(src, described, "collision shape is not a simple polygon (its sides cross)")
    return geometry


def _describe_object(obj: to.TiledObject, layer: str, cls: str) -> str:
    named = f" {obj.name!r}" if obj.name else ""
    return f"layer {layer!r} object {obj.id}{named} ({cls})"


def _collect_object(
    obj: to.TiledObject, layer: str, ox: float, oy: float, found: _Collected, src: str, *,
    collision_layer: bool = False
) -> None:
    found.by_id.setdefault(int(obj.id), (obj, ox, oy))
    cls = _class_of(obj)
    wall: TileWall | None = None
    gid = 0
    if isinstance(obj, to.Tile):
        gid = obj.gid
        _tile_object_size(obj, found)
        cls = cls or found.rules.class_of(obj.gid)  # Tiled: an object takes its tile's class
        wall = found.rules.wall(obj.gid)
    if (cls in WALL_CLASSES and cls != OBSTACLE.name) or (
            not cls and (wall is not None or collision_layer)):
        _collect_wall_object(obj, layer, ox, oy, found, src, wall, gid)
        return
    if not cls:
        return  # decoration
    where = _describe_object(obj, layer, cls)
    if cls not in found.classes:
        known = ", ".join(found.classes)
        _warn(src, where, f"unknown class {obj.class_!r}, treated as decoration (known "
                          f"classes: {known})")
        return
    geometry = _object_geometry(obj, ox, oy, where, src, want_area=found.classes[cls].is_area)
    found.shapes.setdefault(cls, []).append((where, geometry))
    if cls == GUARD.name:
        found.guards.append((obj, ox, oy, where))


def _tile_object_size(obj: to.Tile, found: _Collected) -> None:
    """A tile object written without a size (older Tiled) has its tile's."""
    if _float(obj.size.width) <= 0 or _float(obj.size.height) <= 0:
        size = found.rules.size_of(obj.gid)
        if size is not None:
            obj.size = Size(*size)


def _collect_wall_object(obj: to.TiledObject, layer: str, ox: float, oy: float,
                         found: _Collected, src: str, wall: TileWall | None, gid: int
                         ) -> None:
    """An object that blocks: of a wall class, in a collision layer, or a wall tile placed
    as a tile object (its collision shapes scaled to the object, or its rectangle)."""
    if isinstance(obj, (to.Point, to.Polyline, to.Text)):
        return  # no area: nothing to block
    where = _describe_object(obj, layer, OBSTACLE.name)
    if wall is None or wall.full:
        _add_obstacle(found, where, _object_geometry(obj, ox, oy, where, src, want_area=True),
                      src)
        return
    w, h = _float(obj.size.width), _float(obj.size.height)
    x, y = _float(obj.coordinates.x) + ox, _float(obj.coordinates.y) + oy
    _finite(src, where, "position and size", x, y, w, h, _float(obj.rotation))
    if w <= 0 or h <= 0:
        _fail(src, where, f"shape of {w:g}x{h:g} pixels has no area")
    for polygon in wall.placed(gid, x, y - h, w / wall.width, h / wall.height):
        if obj.rotation:
            polygon = affinity.rotate(polygon, _float(obj.rotation), origin=(x, y))
        _add_obstacle(found, where, polygon, src)


def _object_geometry(
    obj: to.TiledObject, ox: float, oy: float, where: str, src: str, *, want_area: bool
) -> Any:
    """The object's shape in map pixels: a polygon, or a point for a point object."""
    if isinstance(obj, to.Text):
        _fail(src, where, "text objects have no shape; use a point, rectangle, polygon or "
                          "ellipse object")
    if isinstance(obj, to.Polyline):
        _fail(src, where, "a polyline is not closed; use a polygon object")
    x, y = _float(obj.coordinates.x) + ox, _float(obj.coordinates.y) + oy
    _finite(src, where, "position", x, y)
    if isinstance(obj, to.Point):
        if want_area:
            _fail(src, where, "a point object has no area; use a rectangle, polygon or ellipse")
        return shapely.Point(x, y)
    w, h = _float(obj.size.width), _float(obj.size.height)
    _finite(src, where, "size and rotation", w, h, _float(obj.rotation))
    if isinstance(obj, to.Polygon):
        local = np.array([(_float(p.x), _float(p.y)) for p in obj.points]).reshape(-1, 2)
        _finite(src, where, "points", *local.ravel())
    elif isinstance(obj, to.Ellipse):
        angles = 2.0 * np.pi * np.arange(ELLIPSE_SIDES) / ELLIPSE_SIDES
        local = np.column_stack([w / 2 * (1 + np.cos(angles)), h / 2 * (1 + np.sin(angles))])
    elif isinstance(obj, to.Rectangle):
        local = np.array([(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)])
    elif isinstance(obj, to.Tile):  # drawn upwards from its origin, the bottom-left corner
        local = np.array([(0.0, -h), (w, -h), (w, 0.0), (0.0, 0.0)])
    else:  # pragma: no cover - pytiled-parser has no other object kinds
        _fail(src, where, f"unsupported object kind {type(obj).__name__}")
    if not isinstance(obj, to.Polygon) and (w <= 0 or h <= 0):
        if want_area:
            _fail(src, where, f"shape of {w:g}x{h:g} pixels has no area")
        return shapely.Point(x, y)  # a zero-size rectangle is how older Tiled wrote points
    if len(local) < 3:
        _fail(src, where, f"polygon needs at least 3 points, got {len(local)}")
    theta = math.radians(_float(obj.rotation))  # degrees clockwise on screen, about (x, y)
    cos, sin = math.cos(theta), math.sin(theta)
    if theta:
        local = local @ np.array([[cos, sin], [-sin, cos]])
    corners = local + (x, y)
    _finite(src, where, "corners (position + size)", *corners.ravel())
    polygon = Polygon(corners)
    if not want_area:
        if not polygon.is_valid or polygon.area <= 0:
            _fail(src, where, "shape is not a simple polygon, so it has no centre")
        return polygon.centroid
    return polygon


# --------------------------------------------------------------------------- converting


def _warn_of_missing_parts(found: _Collected, tmap: pytiled_parser.TiledMap, src: str) -> None:
    """One warning line for each class with a ``when_missing`` reason that the map has no
    object of (guards), and one for a map that is an empty box."""
    for cls in found.classes.values():
        if cls.when_missing and not found.shapes.get(cls.name):
            _warn(src, "map", f"no object of class {cls.name!r}: {cls.when_missing}")
    walls = any(c.size for _, c, _, _, _ in found.walls)
    if not walls and not found.shapes.get(OBSTACLE.name) and not found.shapes.get(OUTLINE.name):
        size = ("infinite" if tmap.infinite
                else f"{int(tmap.map_size.width)}x{int(tmap.map_size.height)} tiles")
        _warn(src, "map", f"no walls, obstacles or outline: the level is an empty box "
                          f"({size}); blocked cells are the tiles of a tile layer named or of "
                          f"class {WALLS.name!r}, tiles the tileset marks as walls (a class "
                          f"such as 'wall', a 'collides' property, collision shapes) and "
                          f"objects of class {OBSTACLE.name!r}, an object of class "
                          f"{OUTLINE.name!r} is the boundary")


def _wall_tiles(found: _Collected, tile: float) -> tuple[np.ndarray, np.ndarray]:
    """Tile-aligned wall cells of all walls layers (their offsets are whole tiles)."""
    cols = [c + int(ox // tile) for _, c, _, ox, _ in found.walls]
    rows = [r + int(oy // tile) for _, _, r, _, oy in found.walls]
    return np.concatenate(cols or [np.zeros(0, int)]), np.concatenate(rows or [np.zeros(0, int)])


def _content_bounds(
    found: _Collected, outline_objects: list[tuple[str, Any]], tile: float, src: str
) -> tuple[int, int, int, int]:
    """Whole-tile bounds of an infinite map: its outline, else its walls and obstacles."""
    if outline_objects:
        minx, miny, maxx, maxy = outline_objects[0][1].bounds
    else:
        boxes = [g.bounds for _, g in found.shapes.get(OBSTACLE.name, [])]
        for _, c, r, ox, oy in found.walls:
            if c.size:
                boxes.append((c.min() * tile + ox, r.min() * tile + oy,
                              (c.max() + 1) * tile + ox, (r.max() + 1) * tile + oy))
        if not boxes:  # an empty box: the extent of all its tiles
            boxes = [(c0 * tile + ox, r0 * tile + oy, c1 * tile + ox, r1 * tile + oy)
                     for (c0, r0, c1, r1), (ox, oy) in zip(found.tile_boxes, found.tile_offsets)]
        if not boxes:
            _fail(src, "map", "an infinite map without tiles, obstacles or an outline object "
                              "has no extent")
        minx, miny = min(b[0] for b in boxes), min(b[1] for b in boxes)
        maxx, maxy = max(b[2] for b in boxes), max(b[3] for b in boxes)
    return (math.floor(minx / tile), math.floor(miny / tile),
            math.ceil(maxx / tile), math.ceil(maxy / tile))


def _grid(found: _Collected, bounds: tuple[int, int, int, int], tile: float, src: str
          ) -> list[str]:
    """Grid strings over ``bounds`` (tiles): ``#`` where any walls layer has a tile."""
    x0, y0, x1, y1 = bounds
    if x1 <= x0 or y1 <= y0:
        _fail(src, "map", f"map of {x1 - x0}x{y1 - y0} tiles is empty")
    check_map_cells(x1 - x0, y1 - y0, src)
    blocked = np.zeros((y1 - y0, x1 - x0), dtype=bool)
    cols, rows = _wall_tiles(found, tile)
    inside = (cols >= x0) & (cols < x1) & (rows >= y0) & (rows < y1)
    blocked[rows[inside] - y0, cols[inside] - x0] = True
    _block_pockets(blocked, src)
    return ["".join(row) for row in np.where(blocked, "#", ".").tolist()]


def _block_pockets(blocked: np.ndarray, src: str) -> None:
    """Walkable cells walled off from the largest 4-connected group become blocked, with one
    warning: a published map's closed rooms and wall interiors are unreachable anyway, and
    a level must be one piece."""
    labels, count = ndimage.label(~blocked)
    if count <= 1:
        return
    sizes = np.bincount(labels.ravel())[1:]
    keep = 1 + int(np.argmax(sizes))
    pockets = (labels > 0) & (labels != keep)
    row, col = np.argwhere(pockets)[0]
    _warn(src, "map", f"{int(pockets.sum())} walkable cells in {count - 1} pockets walled off "
                      f"from the rest (the first at row {row}, col {col}) are treated as blocked")
    blocked[pockets] = True


def _walled_off(outline: Polygon, obstacles: list[tuple[str, Any]], tile: float, src: str
                ) -> list[Polygon]:
    """Walkable pieces cut off from the largest by the obstacles, which become blocked too,
    with one warning, as a grid level's pockets are: a designer's closed room or wall
    interior is unreachable anyway, and a level must be one piece."""
    if not obstacles:
        return []
    walkable = outline.difference(shapely.union_all([g for _, g in obstacles]))
    pieces = sorted(shapely.get_parts(walkable), key=lambda p: p.area, reverse=True)
    pieces = [p for p in pieces if isinstance(p, Polygon) and p.area > 0]
    if len(pieces) <= 1:
        return []
    cut = pieces[1:]
    area = sum(p.area for p in cut) / tile**2
    x, y = cut[0].representative_point().coords[0]
    _warn(src, "map", f"{len(cut)} walkable pieces ({area:.3g} tiles in all) walled off from "
                      f"the rest (the first around tile ({x / tile:.3g}, {y / tile:.3g})) are "
                      "treated as blocked")
    return [Polygon(p.exterior) for p in cut]


def _wall_rectangles(
    found: _Collected, outline: Polygon, tile: float
) -> list[tuple[str, Polygon]]:
    """Each walls layer's tiles as rectangles (runs along a row), those touching the outline."""
    rectangles = []
    for name, cols, rows, ox, oy in found.walls:
        if not cols.size:
            continue
        order = np.lexsort((cols, rows))
        c, r = cols[order], rows[order]
        starts = np.flatnonzero(np.r_[True, (np.diff(c) != 1) | (np.diff(r) != 0)])
        ends = np.r_[starts[1:], c.size] - 1
        for s, e in zip(starts, ends):
            rect = box(c[s] * tile + ox, r[s] * tile + oy,
                       (c[e] + 1) * tile + ox, (r[s] + 1) * tile + oy)
            if outline.intersection(rect).area > 0:
                rectangles.append((f"layer {name!r}", rect))
    return rectangles


def _ring(polygon: Polygon) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in polygon.exterior.coords[:-1]]


def _xy(point: Any) -> list[float]:
    return [float(point.x), float(point.y)]


def _origin(fld: str, origins: dict[str, str]) -> str:
    """The Tiled layer or object behind a field of the converted structure."""
    best = max((k for k in origins if fld == k or fld.startswith(k + "[")
                or fld.startswith(k + ".")), key=len, default=None)
    return origins[best] if best is not None else fld


def _float(value: Any) -> float:
    """A number of the map as a float; an integer beyond a float's range is infinite (a JSON
    map may hold 10^400), which :func:`_finite` then refuses."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def _finite(src: str, where: str, what: str, *values: float) -> None:
    """A Tiled object's numbers must be finite (a TMX ``x="nan"`` or a JSON ``NaN``)."""
    bad = next((v for v in values if not math.isfinite(v)), None)
    if bad is not None:
        _fail(src, where, f"{what} must be finite numbers, got {bad:g}")


def _fail(src: str, fld: str, problem: str) -> NoReturn:
    raise LevelError(src, fld, problem)


def _warn(src: str, fld: str, problem: str) -> None:
    warnings.warn(LevelWarning(src, fld, problem), stacklevel=3)
