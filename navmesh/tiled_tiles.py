"""Walls the way Tiled users mark them: on the tileset (SPEC §10 "Tiled maps", issue 41).

A Tiled user rarely names a tile layer after its walls: wall tiles are marked on the tileset, in one
of three ways, and every tile layer painted with them (and every tile object placed from
them) is walls:

* the tile's class (Tiled >= 1.9; ``type`` before) is one of
  :data:`navmesh.tiled_classes.WALL_CLASSES`;
* the tile has a boolean custom property named one of
  :data:`navmesh.tiled_classes.WALL_PROPERTIES` set to true
  (``collides = true``); the same property set to **false** makes the tile no wall whatever
  its class or shapes say, so a designer can switch one tile off;
* the tile has collision shapes (Tiled's collision editor: an object group on the tile).

A wall tile's blocked area is its collision shapes when it has any, else the whole tile.
Shapes that cover at least :data:`FULL_COVER` of the tile make it a whole wall cell (Tiled
users draw a tile-sized rectangle a pixel short); smaller ones are exact obstacles.

Tilesets — embedded, ``.tsx`` or ``.tsj``, whatever the map's format — are parsed by
pytiled-parser's own tileset readers, on a copy holding only what a level reads (tile ids,
classes, properties, collision shapes, image sizes), so wang sets, terrains, animations and
images are never looked at and a tileset of an older Tiled (no ``tilecount``, ``columns``,
object ids, or Tiled < 1.2's JSON ``tiles`` object) still reads. Each tileset file comes from
the map's one bounded reader; a tile's collision shapes are bounded
(:data:`MAX_TILE_SHAPES` per tile, :data:`MAX_TILESET_SHAPES` in all) before anything is
parsed, so a tileset of 100,000 shapes on one tile is one line, not minutes of work.

>>> "wall" in WALL_CLASSES, "collides" in WALL_PROPERTIES
(True, True)
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as etree
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, NoReturn, cast

import numpy as np
import shapely
from pytiled_parser import Tileset
from pytiled_parser import tiled_object as to
from pytiled_parser.parsers.json.tileset import parse as parse_json_tileset
from pytiled_parser.parsers.tmx.tileset import parse as parse_tmx_tileset
from shapely.geometry import Polygon, box

from navmesh.errors import LevelError
from navmesh.tiled_classes import WALL_CLASSES, WALL_PROPERTIES
from navmesh.tiled_format import is_tiled_xml

__all__ = ["FLIP_MASK", "FULL_COVER", "MAX_SHAPE_POINTS", "MAX_TILESET_SHAPES", "MAX_TILE_ENTRIES",
           "MAX_TILE_SHAPES", "TileRules", "TileWall", "read_tilesets"]


FULL_COVER = 0.99
"""Collision shapes covering at least this share of their tile make it a whole wall cell."""

MAX_TILE_SHAPES = 256
"""Collision shapes one tile may hold (Tiled users draw one to a handful)."""

MAX_TILESET_SHAPES = 50_000
"""Collision shapes all tilesets of a map may hold together."""

MAX_SHAPE_POINTS = 10_000
"""Polygon corners one tile's collision shapes may hold together."""

MAX_TILE_ENTRIES = 100_000
"""Tiles described one by one (a class, properties, shapes, an image) in all of a map's
tilesets: a 64 MiB tileset of a million bare entries would otherwise cost seconds and a
gigabyte to parse, for nothing a level reads."""

FLIP_MASK = 0x0FFFFFFF
"""A gid without Tiled's flip and rotation flags (its top four bits)."""

_H, _V, _D = 0x80000000, 0x40000000, 0x20000000  # horizontal, vertical, diagonal flips
_KEEP_TILE = ("objectgroup", "properties", "image")


@dataclass(frozen=True)
class TileWall:
    """A wall tile: its size in pixels and its blocked area."""

    width: float
    height: float
    shapes: tuple[Polygon, ...]
    """The blocked area in tile pixels (origin at the tile's top-left); empty: the whole tile."""

    @property
    def full(self) -> bool:
        """Whether the whole tile is blocked."""
        return not self.shapes

    def placed(self, gid: int, x0: float, y0: float, sx: float = 1.0, sy: float = 1.0
               ) -> list[Polygon]:
        """The blocked area of the tile drawn with its top-left at ``(x0, y0)`` and scaled by
        ``(sx, sy)``, its flip flags (in ``gid``) applied as Tiled draws them (diagonal
        first, then horizontal, then vertical)."""
        w, h = self.width, self.height
        if self.full:
            return [box(x0, y0, x0 + w * sx, y0 + h * sy)]

        def move(xy: Any) -> Any:
            x, y = xy[:, 0].copy(), xy[:, 1].copy()
            if gid & _D:  # within the tile's footprint (a non-square tile keeps its size)
                x, y = y * (w / h), x * (h / w)
            if gid & _H:
                x = w - x
            if gid & _V:
                y = h - y
            return np.column_stack([x0 + x * sx, y0 + y * sy])

        return [shapely.transform(shape, move) for shape in self.shapes]


class TileRules:
    """What each tile of a map's tilesets is: its class, and whether (and where) it is a wall.

    ``shape(obj, where)`` turns a collision object into a polygon in tile pixels, or ``None``
    for one that has no area (a point, a polyline); it is the loader's own object reader.
    """

    def __init__(self, tilesets: dict[int, Tileset],
                 shape: Callable[[to.TiledObject, str], Polygon | None]) -> None:
        self._sets = sorted(tilesets.items())
        self._shape = shape
        self._walls: dict[int, TileWall | None] = {}

    def _tile(self, gid: int) -> tuple[Tileset | None, Any]:
        gid &= FLIP_MASK
        found = None
        for first, tileset in self._sets:
            if first <= gid:
                found = tileset
        if found is None:
            return None, None
        return found, (found.tiles or {}).get(gid - found.firstgid)

    def class_of(self, gid: int) -> str:
        """The tile's class (lower case), "" for none or an unknown gid."""
        _, tile = self._tile(gid)
        return (getattr(tile, "class_", None) or "").strip().lower()

    def size_of(self, gid: int) -> tuple[float, float] | None:
        """The tile's size in pixels (its own image's in an image collection)."""
        tileset, tile = self._tile(gid)
        if tileset is None:
            return None
        if tile is not None and tile.width and tile.height:
            return float(tile.width), float(tile.height)
        return float(tileset.tile_width), float(tileset.tile_height)

    def wall(self, gid: int) -> TileWall | None:
        """The tile as a wall, or ``None`` if it is none (flip flags ignored)."""
        gid &= FLIP_MASK
        if gid not in self._walls:
            self._walls[gid] = self._wall(gid)
        return self._walls[gid]

    def _wall(self, gid: int) -> TileWall | None:
        tileset, tile = self._tile(gid)
        if tileset is None or tile is None:
            return None
        marked = _property_mark(tile.properties or {})
        if marked is False:
            return None
        w, h = self.size_of(gid) or (0.0, 0.0)
        if w <= 0 or h <= 0:
            return None
        where = f"tileset {tileset.name!r} tile {tile.id}"
        shapes = []
        if tile.objects is not None:
            for obj in getattr(tile.objects, "tiled_objects", []):
                polygon = self._shape(obj, where)
                if polygon is not None and polygon.area > 0:
                    shapes.append(polygon)
        if not shapes:
            return TileWall(w, h, ()) if marked or self.class_of(gid) in WALL_CLASSES else None
        covered = shapely.union_all(shapes).intersection(box(0, 0, w, h)).area
        if covered >= FULL_COVER * w * h:
            return TileWall(w, h, ())
        return TileWall(w, h, tuple(shapes))


def _property_mark(properties: dict[str, Any]) -> bool | None:
    """True or False when a wall property says so (false wins), else None."""
    marks = []
    for name, value in properties.items():
        if str(name).strip().lower() in WALL_PROPERTIES:
            if isinstance(value, str) and value.strip().lower() in ("true", "false"):
                value = value.strip().lower() == "true"
            if isinstance(value, bool):
                marks.append(value)
    if not marks:
        return None
    return all(marks)


# --------------------------------------------------------------------------- reading


def read_tilesets(doc: Any, folder: Path, read: Callable[[Path, str], bytes], source: str
                  ) -> dict[int, Tileset]:
    """The map's tilesets by first gid, parsed by pytiled-parser from what a level reads of
    them; ``doc`` is the decoded map (a JSON dict or the TMX root), ``read`` its one
    bounded reader. Any problem is one :class:`LevelError` naming the tileset."""
    entries = (doc.get("tilesets") if isinstance(doc, dict) else doc.findall("tileset")) or []
    tilesets: dict[int, Tileset] = {}
    budget = _Budget(source)
    for i, entry in enumerate(entries if isinstance(entries, list) else []):
        where = f"tilesets[{i}]"
        xml_entry = not isinstance(entry, dict)
        if not xml_entry and not isinstance(entry, dict):
            continue
        try:
            first = int(entry.get("firstgid", 1))
        except (TypeError, ValueError):
            _fail(source, where, f"firstgid must be a whole number, got {entry.get('firstgid')!r}")
        named = entry.get("source")
        body: Any = entry
        base = folder
        if named:
            path = folder / str(named)
            where = f"{where} {str(named)!r}"
            raw = read(path, f"{where}.source")
            body = _decode(raw, path, source, where)
            base = path.parent
        try:
            if isinstance(body, dict):
                tilesets[first] = parse_json_tileset(cast(Any, _json_copy(body, budget, where)), first,
                                                     "utf-8", base)
            else:
                tilesets[first] = parse_tmx_tileset(_xml_copy(body, budget, where), first,
                                                    "utf-8", base)
        except LevelError:
            raise
        except Exception as exc:  # noqa: BLE001 - third-party reader: user input, one line
            _fail(source, where, f"not a tileset Stealthfield can read: "
                                 f"{type(exc).__name__}: {exc}")
    return tilesets


class _Budget:
    """Collision shapes counted per tile and in all, before pytiled-parser sees them."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.total = 0
        self.tiles = 0

    def count_tiles(self, tiles: int, where: str) -> None:
        self.tiles += tiles
        if self.tiles > MAX_TILE_ENTRIES:
            _fail(self.source, where, f"more than {MAX_TILE_ENTRIES} tiles described in the "
                                      "map's tilesets")

    def charge(self, shapes: int, points: int, where: str) -> None:
        if shapes > MAX_TILE_SHAPES:
            _fail(self.source, where, f"{shapes} collision shapes on one tile, more than the "
                                      f"limit of {MAX_TILE_SHAPES}")
        if points > MAX_SHAPE_POINTS:
            _fail(self.source, where, f"collision shapes of {points} corners on one tile, more "
                                      f"than the limit of {MAX_SHAPE_POINTS}")
        self.total += shapes
        if self.total > MAX_TILESET_SHAPES:
            _fail(self.source, where, f"more than {MAX_TILESET_SHAPES} collision shapes in "
                                      "the map's tilesets")


def _decode(raw: bytes, path: Path, source: str, where: str) -> Any:
    # counted on the bytes before they are parsed (a 64 MiB tileset of bare tiles takes a
    # gigabyte as a tree): an upper bound of the tiles (and, in JSON, objects) it describes
    entries = (sum(raw.count(b"<tile" + end) for end in (b" ", b">", b"/", b"\n", b"\t"))
               if is_tiled_xml(raw) else raw.count(b'"id"'))
    if entries > MAX_TILE_ENTRIES + MAX_TILESET_SHAPES:
        _fail(source, where, f"more than {MAX_TILE_ENTRIES} tiles described in the map's "
                             "tilesets")
    try:
        if is_tiled_xml(raw):
            root = etree.fromstring(raw)
            if root.tag != "tileset":
                _fail(source, where, f"{path} is not a tileset (root element <{root.tag}>)")
            return root
        doc = json.loads(raw.decode("utf-8-sig"))
    except LevelError:
        raise
    except (etree.ParseError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        _fail(source, where, f"{path} is not a tileset Stealthfield can read ({exc})")
    if not isinstance(doc, dict):
        _fail(source, where, f"{path} is not a tileset (not a JSON object)")
    return doc


def _xml_copy(tileset: Any, budget: _Budget, where: str) -> Any:
    """A ``<tileset>`` holding what a level reads, with the defaults older Tiled left out."""
    a = tileset.attrib
    tiles = tileset.findall("tile")
    budget.count_tiles(len(tiles), where)
    copy = etree.Element("tileset", {
        "name": a.get("name", ""), "tilewidth": a.get("tilewidth", "0"),
        "tileheight": a.get("tileheight", "0"), "tilecount": a.get("tilecount", str(len(tiles))),
        "columns": a.get("columns", "0")})
    for tile in tiles:
        kept = etree.SubElement(copy, "tile", {k: v for k, v in tile.attrib.items()
                                              if k in ("id", "type", "class", "width",
                                                       "height")})
        for child in tile:
            if child.tag not in _KEEP_TILE:
                continue
            if child.tag == "image":
                child = etree.Element("image", {
                    "source": child.get("source", ""),
                    "width": child.get("width", tile.get("width", a.get("tilewidth", "0"))),
                    "height": child.get("height",
                                        tile.get("height", a.get("tileheight", "0")))})
            if child.tag == "objectgroup":
                objects = child.findall("object")
                budget.charge(len(objects), sum(_xml_corners(o) for o in objects),
                              f"{where} tile {tile.get('id')}")
                for n, obj in enumerate(objects, start=1):
                    obj.attrib.setdefault("id", str(n))
            kept.append(child)
    return copy


def _xml_corners(obj: Any) -> int:
    polygon = obj.find("polygon")
    return len((polygon.get("points") or "").split()) if polygon is not None else 4


def _json_copy(tileset: dict[str, Any], budget: _Budget, where: str) -> dict[str, Any]:
    """A JSON tileset holding what a level reads, with the defaults older Tiled left out
    (Tiled < 1.2 wrote ``tiles`` as an object by id and ``tileproperties`` beside it)."""
    tiles = tileset.get("tiles") or []
    if isinstance(tiles, dict):
        tiles = [{**(t if isinstance(t, dict) else {}), "id": int(k)} for k, t in tiles.items()]
    legacy = tileset.get("tileproperties")
    if isinstance(legacy, dict):
        by_id = {t.get("id"): t for t in tiles if isinstance(t, dict)}
        for key, props in legacy.items():
            tile = by_id.setdefault(int(key), {"id": int(key)})
            tile.setdefault("properties", props)
        tiles = list(by_id.values())
    kept_tiles = []
    budget.count_tiles(len(tiles) if isinstance(tiles, list) else 0, where)
    for tile in tiles if isinstance(tiles, list) else []:
        if not isinstance(tile, dict):
            continue
        kept = {k: v for k, v in tile.items()
                if k in ("id", "type", "class", "properties", "image", "imagewidth",
                         "imageheight", "width", "height")}
        group = tile.get("objectgroup")
        if isinstance(group, dict):
            objects = [o for o in group.get("objects") or [] if isinstance(o, dict)]
            budget.charge(len(objects), sum(len(o.get("polygon") or [None] * 4)
                                            for o in objects), f"{where} tile {tile.get('id')}")
            for n, obj in enumerate(objects, start=1):
                for key, value in (("id", n), ("name", ""), ("visible", True), ("rotation", 0),
                                   ("width", 0), ("height", 0)):
                    obj.setdefault(key, value)
            kept["objectgroup"] = {"name": group.get("name", ""), "opacity": 1,
                                   "draworder": group.get("draworder", "topdown"),
                                   "visible": True, "type": "objectgroup",
                                   "x": 0, "y": 0, "objects": objects}
        kept_tiles.append(kept)
    return {"name": tileset.get("name", ""), "tilewidth": tileset.get("tilewidth", 0),
            "tileheight": tileset.get("tileheight", 0),
            "tilecount": tileset.get("tilecount", len(kept_tiles)),
            "columns": tileset.get("columns", 0), "spacing": 0, "margin": 0,
            "tiles": kept_tiles}


def _fail(source: str, where: str, problem: str) -> NoReturn:
    raise LevelError(source, where, problem)
