"""Bounds on a Tiled map, checked on the decoded map before pytiled-parser reads it (SPEC §10).

pytiled-parser opens every file a map names (object templates and their tilesets) with a
plain :func:`open`, inflates every compressed layer whole and takes tile data of any length,
so a FIFO named as a template's tileset blocks for ever, ``/dev/zero`` is read until memory
runs out, a 12 KB zstd layer can inflate to 400 MB and a layer of 380 values for 400 tiles
loads silently. :func:`guard_map` walks the decoded map (JSON or TMX) first, with the same
rules as every other input:

* each file the map names — external tilesets, object templates, a template's tileset — is
  read by one :class:`MapFiles`, through :func:`navmesh.files.read_regular` (a regular file
  of at most 64 MiB; all of them together at most 64 MiB and :data:`MAX_NAMED_FILES`
  files); templates are merged into their objects (:mod:`navmesh.tiled_templates`), so
  pytiled-parser opens nothing;
* each layer's or chunk's data holds exactly width × height gids, each in [0, 2^32): base64
  is inflated by :func:`navmesh.files.inflate_bounded` against width × height × 4 bytes;
  TMX's old ``<tile gid="…"/>`` form is rewritten as the CSV it means;
* sizes meet the cell limit and chunk coordinates and layer offsets lie within ±2^31; a
  layer or chunk of no tiles is dropped (pytiled-parser would divide by its zero width), and
  a JSON object gets the keys every Tiled writes (``name``, ``visible``, ...) if it lacks them;
* an object without an ``id`` (TMX 1.0 and JSON maps of Tiled < 1.0 wrote none) gets the next
  free one, in document order, as Tiled itself does when it opens such a map;
* a JSON layer of a type Tiled does not write is one line naming the layer and the types
  there are (pytiled-parser raised a ``RuntimeError``).

A map that passes is one pytiled-parser reads in bounded time and memory.
"""

from __future__ import annotations

import base64
import binascii
import math
import os
import xml.etree.ElementTree as etree
from pathlib import Path
from typing import Any, NoReturn

from navmesh.errors import LevelError
from navmesh.files import FileRefused, inflate_bounded, read_regular
from navmesh.level_fields import MAX_CELLS, MAX_FILE_BYTES
from navmesh.tiled_templates import MapTilesets, Templates

__all__ = ["LAYER_TYPES", "MAX_CHUNK_CELLS", "MAX_COORDINATE", "MAX_NAMED_FILES", "MapFiles",
           "check_map_cells", "guard_map"]

LAYER_TYPES = ("tilelayer", "objectgroup", "imagelayer", "group")
"""The layer types of a JSON map (TMX's elements of the same meaning: ``layer``,
``objectgroup``, ``imagelayer``, ``group``; other TMX elements are not layers)."""

MAX_CHUNK_CELLS = 4 * MAX_CELLS
"""Tiles an infinite map's chunks may hold together (its content must still fit in
:data:`navmesh.level.MAX_CELLS` cells; empty chunks around it are allowed)."""

MAX_NAMED_FILES = 1000
"""Distinct files (tilesets, templates) one map may name."""

MAX_COORDINATE = 2**31
"""Bound of a chunk's tile coordinates and a layer's pixel offsets (Tiled's are 32-bit)."""

_OBJECT_DEFAULTS = {"name": "", "visible": True, "rotation": 0, "width": 0, "height": 0}
_GID_END = 2**32  # a gid is an unsigned 32-bit number (flip flags in its top bits)


class MapFiles:
    """The one reader of the files a map names: each read once, through
    :func:`navmesh.files.read_regular`, and all of them bounded together."""

    def __init__(self, source: str) -> None:
        self.source = source
        self._read: dict[str, bytes] = {}
        self._total = 0

    def read(self, path: Path, where: str) -> bytes:
        """The bytes of ``path``, a file the map names at ``where``; any problem is one
        :class:`LevelError` naming the file."""
        key = os.path.normpath(path)  # a string operation: no file is touched
        if key in self._read:
            return self._read[key]
        if len(self._read) >= MAX_NAMED_FILES:
            _fail(self.source, where, f"the map names more than {MAX_NAMED_FILES} files")
        try:
            raw = read_regular(path, MAX_FILE_BYTES)
        except FileRefused as refused:
            _fail(self.source, where, f"{path} {refused}")
        except FileNotFoundError:
            _fail(self.source, where, f"a file the map refers to is missing: {path}")
        except OSError as exc:
            _fail(self.source, where, f"cannot read {path} ({exc.strerror or exc})")
        except ValueError as exc:  # a NUL byte in the name
            _fail(self.source, where, f"cannot read {str(path)!r} ({exc})")
        self._total += len(raw)
        if self._total > MAX_FILE_BYTES:
            _fail(self.source, where, f"the files the map names hold more than "
                                      f"{MAX_FILE_BYTES // 2**20} MiB together")
        self._read[key] = raw
        return raw


def guard_map(doc: Any, folder: Path, source: str) -> MapFiles:
    """Check (and normalise in place) a decoded map: a JSON ``dict`` or a TMX root element.

    Raises one :class:`LevelError` for a named file that is not a bounded regular file, a
    layer whose data is not width × height valid gids, or a size beyond the limits. Returns
    the map's reader, which holds every file it named (its tilesets are read from it again).
    """
    files = MapFiles(source)
    templates = Templates(files.read, source, _map_tilesets(doc, folder))
    if isinstance(doc, dict):
        _guard_json(doc, folder, files, templates)
    else:
        _guard_xml(doc, folder, files, templates)
    return files


def _map_tilesets(doc: Any, folder: Path) -> MapTilesets:
    """The map's external tilesets by file, for templates' tile objects; a tileset a template
    names and the map lacks is added to the map's document (as Tiled adds it)."""
    entries = (_list(doc.get("tilesets")) if isinstance(doc, dict)
               else doc.findall("tileset"))
    firstgids: dict[str, int] = {}
    for entry in entries:
        if not isinstance(entry, dict) and isinstance(doc, dict):
            continue
        named, first = entry.get("source"), _number(entry.get("firstgid", 1))
        if isinstance(named, str) and named and first is not None and math.isfinite(first):
            firstgids.setdefault(os.path.normpath(folder / named), int(first))

    def add(first: int, path: str) -> None:
        relative = os.path.relpath(path, folder)
        if isinstance(doc, dict):
            doc.setdefault("tilesets", []).append({"firstgid": first, "source": relative})
        else:
            etree.SubElement(doc, "tileset", firstgid=str(first), source=relative)

    return MapTilesets(firstgids, add)


class ObjectIds:
    """Ids for objects written without one, as Tiled gives them when it opens such a map:
    the map's ``nextobjectid`` onwards, never one an object of the map already has."""

    def __init__(self, next_id: Any, taken: list[Any]) -> None:
        given = _number(next_id)
        used = [n for n in map(_number, taken) if n is not None and math.isfinite(n)]
        self.next = max(int(given) if given is not None and math.isfinite(given) else 1,
                        int(max(used, default=0)) + 1, 1)

    def take(self) -> int:
        value, self.next = self.next, self.next + 1
        return value


def check_map_cells(width: int, height: int, source: str, what: str = "map") -> None:
    """The cell limit applied to a map's size in tiles before anything of that size exists."""
    if width < 0 or height < 0:
        _fail(source, what, f"map of {width}x{height} tiles has a negative size")
    if width * height > MAX_CELLS:
        _fail(source, what, f"map of {width}x{height} = {width * height} tiles exceeds the "
                            f"limit of {MAX_CELLS} cells")


class _ChunkTally:
    """The tiles of an infinite map's chunks, counted against :data:`MAX_CHUNK_CELLS`."""

    def __init__(self) -> None:
        self.cells = 0

    def add(self, width: int, height: int, x: Any, y: Any, source: str, where: str) -> None:
        check_map_cells(width, height, source, where)
        _check_coordinates(source, where, "chunk position", x, y, integer=True)
        self.cells += width * height
        if self.cells > MAX_CHUNK_CELLS:
            _fail(source, where, f"chunks of more than {MAX_CHUNK_CELLS} tiles in all")


def _check_coordinates(source: str, where: str, what: str, *values: Any,
                      integer: bool = False) -> None:
    """Finite numbers within ±:data:`MAX_COORDINATE` (whole ones if ``integer``)."""
    for value in values:
        number = _number(value)
        if (number is None or not math.isfinite(number) or abs(number) > MAX_COORDINATE
                or (integer and number != int(number))):
            kind = "whole numbers" if integer else "finite numbers"
            _fail(source, where, f"{what} must be {kind} within ±{MAX_COORDINATE}, got "
                                 f"{value!r}")


def _check_gids(gids: list[Any], width: int, height: int, source: str, where: str) -> None:
    """``gids`` (CSV or a JSON list) must be exactly width × height integers in [0, 2^32)."""
    if len(gids) != width * height:
        _fail(source, where, f"tile data holds {len(gids)} gids, expected {width * height} "
                             f"(one per tile of {width}x{height})")
    for i, gid in enumerate(gids):
        if isinstance(gid, bool) or not isinstance(gid, int) or not 0 <= gid < _GID_END:
            _fail(source, where, f"the gid of the tile at row {i // width}, column "
                                 f"{i % width} is {gid!r}, not a whole number in [0, 2^32)")


def _check_encoded(data: Any, compression: str, tiles: int, source: str, where: str) -> None:
    """Base64 tile data (optionally compressed) must hold exactly ``tiles`` 4-byte gids."""
    if not isinstance(data, str):
        _fail(source, where, f"base64 tile data must be a string, got {type(data).__name__}")
    expected = 4 * tiles
    try:
        raw = base64.b64decode(data, validate=False)
    except (binascii.Error, ValueError) as exc:
        _fail(source, where, f"tile data is not valid base64 ({exc})")
    if compression:
        try:
            raw = inflate_bounded(raw, compression, expected)
        except FileRefused as refused:
            _fail(source, where, f"tile data {refused} ({expected} bytes for the layer's "
                                 f"{tiles} tiles)")
    if len(raw) != expected:
        _fail(source, where, f"tile data is {len(raw)} bytes, expected {expected} "
                             f"(4 per tile for {tiles} tiles)")


# --------------------------------------------------------------------------- JSON maps


def _guard_json(doc: dict[str, Any], folder: Path, files: MapFiles, templates: Templates
                ) -> None:
    source = files.source
    size = _size(doc)
    if size is not None and not doc.get("infinite"):
        check_map_cells(*size, source)
    for i, tileset in enumerate(_list(doc.get("tilesets"))):
        if isinstance(tileset, dict) and isinstance(tileset.get("source"), str):
            files.read(folder / tileset["source"], f"tilesets[{i}].source")
    chunks = _ChunkTally()
    layers = list(_json_layers(_list(doc.get("layers")), ""))
    ids = ObjectIds(doc.get("nextobjectid"),
                    [o.get("id") for _, layer in layers for o in _list(layer.get("objects"))
                     if isinstance(o, dict) and o.get("id") is not None])
    for name, layer in layers:
        where = f"layer {name!r}"
        if layer.get("type") not in LAYER_TYPES:
            _fail(source, where, f"unknown layer type {layer.get('type')!r} (Tiled's layer "
                                 f"types are {', '.join(LAYER_TYPES)})")
        _check_coordinates(source, where, "offset", layer.get("offsetx", 0),
                          layer.get("offsety", 0))
        if layer.get("type") == "tilelayer":
            _guard_json_tiles(layer, where, source, chunks)
        objects = _list(layer.get("objects"))
        for i, obj in enumerate(objects):
            if isinstance(obj, dict) and obj.get("id") is None:
                obj["id"] = ids.take()
            if isinstance(obj, dict) and "template" in obj:
                objects[i] = obj = templates.inline_json(obj, folder,
                                                         f"{where} object {obj.get('id')}")
            if isinstance(obj, dict):  # keys every Tiled writes, which older ones left out
                for key, value in _OBJECT_DEFAULTS.items():
                    obj.setdefault(key, value)


def _guard_json_tiles(layer: dict[str, Any], where: str, source: str,
                      chunks: _ChunkTally) -> None:
    encoding = layer.get("encoding")
    if encoding == "csv":  # Tiled's default, sometimes written out: data is a list
        del layer["encoding"]
        encoding = None
    elif encoding not in (None, "base64"):
        _fail(source, where, f"unknown encoding {encoding!r} (csv or base64)")
    compression = layer.setdefault("compression", "") if encoding else ""

    def check(data: Any, width: int, height: int) -> None:
        if encoding:
            _check_encoded(data, str(compression or ""), width * height, source, where)
        elif isinstance(data, list):
            _check_gids(data, width, height, source, where)
        else:
            _fail(source, where, f"tile data must be a list of gids, got {type(data).__name__}")

    if layer.get("data") is not None:
        size = _required_size(layer, source, where)
        check_map_cells(*size, source, where)
        check(layer["data"], *size)
        if 0 in size:  # no tiles: pytiled-parser would divide by the width
            del layer["data"]
    kept = []
    for chunk in _list(layer.get("chunks")):
        if isinstance(chunk, dict):
            size = _required_size(chunk, source, f"{where} chunk")
            chunks.add(*size, chunk.get("x"), chunk.get("y"), source, where)
            check(chunk.get("data"), *size)
            if 0 in size:
                continue
        kept.append(chunk)
    if "chunks" in layer and isinstance(layer["chunks"], list):
        layer["chunks"] = kept


def _json_layers(layers: list[Any], parent: str) -> Any:
    for layer in layers:
        if not isinstance(layer, dict):
            continue
        name = f"{parent}{layer.get('name', '')}"
        yield name, layer
        if layer.get("type") == "group":
            yield from _json_layers(_list(layer.get("layers")), f"{name}/")


def _list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else []


def _size(thing: dict[str, Any]) -> tuple[int, int] | None:
    """``(width, height)`` when both are integers; anything else is pytiled-parser's to report."""
    width, height = thing.get("width"), thing.get("height")
    if any(isinstance(v, bool) or not isinstance(v, int) for v in (width, height)):
        return None
    return int(width), int(height)  # type: ignore[arg-type]


def _required_size(thing: dict[str, Any], source: str, where: str) -> tuple[int, int]:
    size = _size(thing)
    if size is None:
        _fail(source, where, f"width and height must be whole numbers, got "
                             f"{thing.get('width')!r} and {thing.get('height')!r}")
    return size


# --------------------------------------------------------------------------- TMX maps


def _guard_xml(root: Any, folder: Path, files: MapFiles, templates: Templates) -> None:
    source = files.source
    size = _xml_size(root)
    if size is not None and root.get("infinite", "0") != "1":
        check_map_cells(*size, source)
    for i, tileset in enumerate(root.iter("tileset")):
        if tileset.get("source"):
            files.read(folder / tileset.get("source"), f"tilesets[{i}].source")
    chunks = _ChunkTally()
    layers = list(_xml_layers(root, ""))
    ids = ObjectIds(root.get("nextobjectid"),
                    [o.get("id") for _, layer in layers for o in layer
                     if o.tag == "object" and o.get("id") is not None])
    for name, layer in layers:
        where = f"layer {name!r}"
        _check_coordinates(source, where, "offset", layer.get("offsetx", 0),
                          layer.get("offsety", 0))
        if layer.tag == "layer":
            _guard_xml_tiles(layer, where, source, chunks)
        for i, obj in enumerate(list(layer)):
            if obj.tag == "object" and obj.get("id") is None:
                obj.set("id", str(ids.take()))
            if obj.tag == "object" and obj.get("template") is not None:
                layer[i] = templates.inline_xml(obj, folder, f"{where} object {obj.get('id')}")


def _guard_xml_tiles(layer: Any, where: str, source: str, chunks: _ChunkTally) -> None:
    data = layer.find("data")
    if data is None:
        return
    encoding = data.get("encoding") or "csv"
    if encoding not in ("csv", "base64"):
        _fail(source, where, f"unknown encoding {encoding!r} (csv, base64 or none)")
    compression = data.get("compression") or ""
    if encoding == "csv" and compression:
        _fail(source, where, f"compression {compression!r} needs base64 encoding")

    def check(element: Any, width: int, height: int) -> None:
        if encoding == "base64":
            _check_encoded((element.text or "").strip(), compression, width * height, source,
                          where)
            return
        tiles = element.findall("tile")
        if tiles:  # the old XML form: one <tile gid="..."/> per tile, read as its CSV
            element.text = ",".join(tile.get("gid", "0") for tile in tiles)
            for tile in tiles:
                element.remove(tile)
        text = (element.text or "").strip()
        values = [v.strip() for v in text.split(",")] if text else []
        _check_gids([_whole(v) for v in values], width, height, source, where)

    found = data.findall("chunk")
    if not found:
        size = _xml_required(layer, source, where)
        check_map_cells(*size, source, where)
        check(data, *size)
        if 0 in size:  # no tiles: pytiled-parser would divide by the width
            layer.remove(data)
    for chunk in found:
        size = _xml_required(chunk, source, f"{where} chunk")
        chunks.add(*size, chunk.get("x"), chunk.get("y"), source, where)
        check(chunk, *size)
        if 0 in size:
            data.remove(chunk)
    if found and data.find("chunk") is None:
        layer.remove(data)


def _xml_layers(parent: Any, prefix: str) -> Any:
    for layer in parent:
        if layer.tag not in ("layer", "objectgroup", "imagelayer", "group"):
            continue
        name = f"{prefix}{layer.get('name', '')}"
        yield name, layer
        if layer.tag == "group":
            yield from _xml_layers(layer, f"{name}/")


def _xml_size(element: Any) -> tuple[int, int] | None:
    try:
        return int(element.get("width")), int(element.get("height"))
    except (TypeError, ValueError):
        return None


def _xml_required(element: Any, source: str, where: str) -> tuple[int, int]:
    size = _xml_size(element)
    if size is None:
        _fail(source, where, f"width and height must be whole numbers, got "
                             f"{element.get('width')!r} and {element.get('height')!r}")
    return size


def _whole(text: str) -> Any:
    try:
        return int(text)
    except ValueError:
        return text


def _number(value: Any) -> float | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return float(value) if not isinstance(value, int) or abs(value) < 2**63 else math.inf
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return None
    return None


def _fail(source: str, where: str, problem: str) -> NoReturn:
    raise LevelError(source, where, problem)
