"""Read a Tiled map's header, layers, properties and tilesets — TMX (XML) or JSON.

Tilesets (embedded, ``.tsx``, ``.tsj``) are read for what a level needs of them — tile
classes, properties and collision shapes, which mark walls — by
:func:`navmesh.tiled_tiles.read_tilesets` through the map's one bounded reader; their images
are never opened, and a tileset written by an older Tiled without ``tilecount`` or
``columns`` still loads. The header keys newer Tiled added
(``infinite``, ``nextlayerid``, ``renderorder``, ``tiledversion``, ...) default as Tiled
does. The map's bytes come from the caller (read once, bounded); the decoded document is
checked and its object templates merged in by :func:`navmesh.tiled_guard.guard_map`, then
its layers are parsed by pytiled-parser's own layer readers (every data encoding and
compression, chunks, groups), which then open no file. A map that is not orthogonal is
refused before anything else is checked (once its text is decoded: a JSON map must be
UTF-8, as Tiled writes it), so an isometric, staggered or hexagonal map gets that one line
whatever else it holds.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as etree
from pathlib import Path
from typing import Any, NoReturn

from pytiled_parser import TiledMap
from pytiled_parser.common_types import Size
from pytiled_parser.parsers.json.layer import parse as parse_json_layer
from pytiled_parser.parsers.json.properties import parse as parse_json_properties
from pytiled_parser.parsers.tmx.layer import parse as parse_tmx_layer
from pytiled_parser.parsers.tmx.properties import parse as parse_tmx_properties

from navmesh.errors import LevelError
from navmesh.tiled_format import is_tiled_xml
from navmesh.tiled_guard import guard_map
from navmesh.tiled_tiles import read_tilesets

__all__ = ["ORTHOGONAL", "read_map"]

ORTHOGONAL = "orthogonal"
"""The one map orientation a level can come from (its grid is the tile grid)."""

_ENCODING = "utf-8"
_LAYER_TAGS = ("layer", "objectgroup", "imagelayer", "group")


def read_map(path: Path, raw: bytes, source: str) -> TiledMap:
    """The map at ``path``, whose bytes are ``raw``, with its tilesets; a map that is
    not orthogonal or fails :func:`~navmesh.tiled_guard.guard_map` raises
    :class:`LevelError` (``source`` names it). Malformed input raises whatever the XML,
    JSON or layer readers raise (the caller turns it into one line)."""
    if is_tiled_xml(raw):
        return _read_tmx(path, raw, source)
    return _read_json(path, raw, source)


def _read_tmx(path: Path, raw: bytes, source: str) -> TiledMap:
    root = etree.fromstring(raw)
    if root.tag != "map":
        raise ValueError(f"the XML's root element is <{root.tag}>, not <map>")
    attrib = root.attrib
    _check_orientation(attrib.get("orientation", ORTHOGONAL), source)
    files = guard_map(root, path.parent, source)
    tmap = _tiled_map(
        path, attrib,
        infinite=bool(int(attrib.get("infinite", "0"))),
        layers=[parse_tmx_layer(e, _ENCODING, path.parent) for e in root if e.tag in _LAYER_TAGS],
        size=(_whole(attrib, "width", source), _whole(attrib, "height", source)),
        tile=(_whole(attrib, "tilewidth", source), _whole(attrib, "tileheight", source)),
    )
    properties = root.find("./properties")
    if properties is not None:
        tmap.properties = parse_tmx_properties(properties)
    tmap.tilesets = read_tilesets(root, path.parent, files.read, source)
    return tmap


def _read_json(path: Path, raw: bytes, source: str) -> TiledMap:
    data = json.loads(_utf8(raw, source))
    if not isinstance(data, dict):
        raise ValueError("the JSON is not an object")
    _check_orientation(data.get("orientation", ORTHOGONAL), source)
    files = guard_map(data, path.parent, source)
    layers = data.get("layers") or []
    tmap = _tiled_map(
        path, data,
        infinite=bool(data.get("infinite", False)),
        layers=[parse_json_layer(layer, _ENCODING, path.parent) for layer in layers],
        size=(_whole(data, "width", source), _whole(data, "height", source)),
        tile=(_whole(data, "tilewidth", source), _whole(data, "tileheight", source)),
    )
    properties = data.get("properties")
    if isinstance(properties, dict):  # Tiled < 1.2 wrote {"name": value}
        tmap.properties = dict(properties)
    elif properties:
        tmap.properties = parse_json_properties(properties)
    tmap.tilesets = read_tilesets(data, path.parent, files.read, source)
    return tmap


def _utf8(raw: bytes, source: str) -> str:
    """A JSON map's text. Tiled writes UTF-8 (a byte order mark allowed); anything else is
    refused in one line — UTF-16 above all, whose NUL bytes UTF-8 would otherwise accept (a
    UTF-16 TMX with a byte order mark comes here too: it does not start with ``<``)."""
    problem = "not UTF-8 text (invalid byte at offset {}); Tiled writes maps in UTF-8"
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _refuse(source, problem.format(exc.start))
    if b"\0" in raw:  # never in JSON text; every other byte of UTF-16
        _refuse(source, problem.format(raw.index(b"\0")))
    return text


def _tiled_map(path: Path, header: Any, *, infinite: bool, layers: list, size: tuple[int, int],
               tile: tuple[int, int]) -> TiledMap:
    next_layer = header.get("nextlayerid")
    return TiledMap(
        map_file=path,
        infinite=infinite,
        layers=layers,
        map_size=Size(*size),
        next_layer_id=int(next_layer) if next_layer is not None else None,
        next_object_id=int(header.get("nextobjectid", 1)),
        orientation=str(header.get("orientation", ORTHOGONAL)),
        render_order=str(header.get("renderorder", "right-down")),
        tiled_version=str(header.get("tiledversion", "")),
        tile_size=Size(*tile),
        tilesets={},
        version=str(header.get("version", "")),
    )


def _whole(header: Any, key: str, source: str) -> int:
    """A header size in tiles or pixels: a whole number (a TMX attribute is its digits); a
    missing key raises :class:`KeyError` like every other."""
    value = header[key]
    digits = value.strip().lstrip("+-") if isinstance(value, str) else ""
    if digits.isascii() and digits.isdigit():
        return int(value)
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    _refuse(source, f"{key} must be a whole number, got {value!r}")


def _check_orientation(orientation: Any, source: str) -> None:
    if orientation != ORTHOGONAL:
        _refuse(source, f"orientation {orientation!r} is not supported; only orthogonal maps "
                        "are (isometric, staggered and hexagonal maps have no square tile grid)")


def _refuse(source: str, problem: str) -> NoReturn:
    raise LevelError(source, "map", problem)
