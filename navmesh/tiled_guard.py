"""Bounds on a Tiled JSON map, checked before pytiled-parser reads it (SPEC §8, §10).

pytiled-parser opens every file a map names (external tilesets, object templates and their
tilesets) with a plain :func:`open` and inflates every compressed layer whole, so a FIFO
named as a tileset blocks for ever, ``/dev/zero`` is read until memory runs out and a
12 KB zstd layer can inflate to 400 MB. :func:`guard_json_map` walks the map first with the
same rules as every other input: each named file through :func:`navmesh.files.read_regular`,
each layer's data through :func:`navmesh.files.inflate_bounded` against the size its tiles
take (width × height × 4 bytes), and the map's own size against the cell limit — so a map
that passes is one pytiled-parser reads in bounded time and memory.
"""

from __future__ import annotations

import base64
import binascii
import json
from pathlib import Path
from typing import Any, NoReturn

from navmesh.files import FileRefused, inflate_bounded, read_regular
from navmesh.errors import LevelError
from navmesh.level_fields import MAX_CELLS, MAX_FILE_BYTES

__all__ = ["MAX_CHUNK_CELLS", "check_map_cells", "guard_json_map"]

MAX_CHUNK_CELLS = 4 * MAX_CELLS
"""Tiles an infinite map's chunks may hold together (its content must still fit in
:data:`navmesh.level.MAX_CELLS` cells; empty chunks around it are allowed)."""


def guard_json_map(path: Path, source: str) -> None:
    """Refuse, with one :class:`LevelError`, a map naming a file that is not a bounded regular
    file, a layer whose data inflates past its tiles, or a map beyond the cell limit."""
    raw = _named_file(path, source, "map")
    if raw.lstrip()[:1] == b"<":
        _guard_xml_map(raw, path.parent, source)
        return
    doc = _json_bytes(raw)
    if not isinstance(doc, dict):
        return  # pytiled-parser's own error names what is wrong
    if not doc.get("infinite"):
        size = _size(doc)
        if size is not None:
            check_map_cells(*size, source)
    for i, tileset in enumerate(_list(doc.get("tilesets"))):
        if isinstance(tileset, dict) and isinstance(tileset.get("source"), str):
            _named_file(path.parent / tileset["source"], source, f"tilesets[{i}].source")
    chunk_cells = [0]
    for name, layer in _layers(_list(doc.get("layers")), ""):
        _guard_layer(layer, name, path.parent, source, chunk_cells)


def check_map_cells(width: int, height: int, source: str, what: str = "map") -> None:
    """The cell limit applied to a map's size in tiles before anything of that size exists."""
    if width < 0 or height < 0:
        _fail(source, what, f"map of {width}x{height} tiles has a negative size")
    if width * height > MAX_CELLS:
        _fail(source, what, f"map of {width}x{height} = {width * height} tiles exceeds the "
                            f"limit of {MAX_CELLS} cells")


def _guard_layer(layer: dict[str, Any], name: str, folder: Path, source: str,
                 chunk_cells: list[int]) -> None:
    where = f"layer {name!r}"
    if layer.get("type") == "tilelayer":
        compression = layer.get("compression") or ""
        encoded = layer.get("encoding") == "base64"
        if "data" in layer:
            size = _size(layer)
            if size is not None:
                check_map_cells(*size, source, where)
                _guard_data(layer["data"], encoded, compression, size[0] * size[1], where,
                            source)
        for chunk in _list(layer.get("chunks")):
            if not isinstance(chunk, dict):
                continue
            size = _size(chunk)
            if size is not None:
                check_map_cells(*size, source, where)
                width, height = size
                chunk_cells[0] += width * height
                if chunk_cells[0] > MAX_CHUNK_CELLS:
                    _fail(source, where, f"chunks of more than {MAX_CHUNK_CELLS} tiles "
                                         "in all")
                _guard_data(chunk.get("data"), encoded, compression, width * height,
                            where, source)
    for obj in _list(layer.get("objects")):
        if isinstance(obj, dict) and isinstance(obj.get("template"), str):
            _template(folder / obj["template"], source, f"{where} object {obj.get('id')}")


def _guard_data(data: Any, encoded: bool, compression: str, tiles: int, where: str,
                source: str) -> None:
    """Base64 tile data (optionally compressed) must hold exactly ``tiles`` 4-byte gids."""
    if not encoded or not isinstance(data, str):
        return  # a JSON list, bounded by the file's size
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


def _template(path: Path, source: str, where: str) -> None:
    """An object template (``.tj``) and the tileset it names, if any."""
    doc = _json(path, source, f"{where} template")
    if isinstance(doc, dict) and isinstance(doc.get("tileset"), dict):
        named = doc["tileset"].get("source")
        if isinstance(named, str):
            _named_file(path.parent / named, source, f"{where} template's tileset")


def _named_file(path: Path, source: str, where: str) -> bytes:
    try:
        return read_regular(path, MAX_FILE_BYTES)
    except FileRefused as refused:
        _fail(source, where, f"{path} {refused}")
    except FileNotFoundError:
        _fail(source, "map", f"a file the map refers to is missing: {path}")
    except OSError as exc:
        _fail(source, where, f"cannot read {path} ({exc.strerror or exc})")


def _guard_xml_map(raw: bytes, folder: Path, source: str) -> None:
    """The same bounds for a TMX map: its size, every file it names (tilesets, templates,
    images are not read) and every layer's or chunk's encoded data."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(raw)
    except ET.ParseError:
        return  # the reader reports the broken XML in one line
    size = _xml_size(root)
    if size is not None and root.get("infinite", "0") != "1":
        check_map_cells(*size, source)
    for i, tileset in enumerate(root.iter("tileset")):
        named = tileset.get("source")
        if named:
            _named_file(folder / named, source, f"tilesets[{i}].source")
    for obj in root.iter("object"):
        named = obj.get("template")
        if named:
            _named_file(folder / named, source, f"object {obj.get('id')} template")
    chunk_cells = 0
    for layer in root.iter("layer"):
        where = f"layer {layer.get('name', '')!r}"
        data = layer.find("data")
        if data is None:
            continue
        encoded = data.get("encoding") == "base64"
        compression = data.get("compression") or ""
        chunks = data.findall("chunk")
        if not chunks and size is not None:
            _guard_data((data.text or "").strip(), encoded, compression,
                        _layer_tiles(layer, size, source, where), where, source)
        for chunk in chunks:
            csize = _xml_size(chunk)
            if csize is None:
                continue
            check_map_cells(*csize, source, where)
            chunk_cells += csize[0] * csize[1]
            if chunk_cells > MAX_CHUNK_CELLS:
                _fail(source, where, f"chunks of more than {MAX_CHUNK_CELLS} tiles in all")
            _guard_data((chunk.text or "").strip(), encoded, compression,
                        csize[0] * csize[1], where, source)


def _layer_tiles(layer: Any, size: tuple[int, int], source: str, where: str) -> int:
    own = _xml_size(layer) or size
    check_map_cells(*own, source, where)
    return own[0] * own[1]


def _xml_size(element: Any) -> tuple[int, int] | None:
    try:
        return int(element.get("width")), int(element.get("height"))
    except (TypeError, ValueError):
        return None


def _json_bytes(raw: bytes) -> Any:
    try:
        return json.loads(raw)
    except (ValueError, RecursionError):
        return None


def _json(path: Path, source: str, where: str) -> Any:
    raw = _named_file(path, source, where)
    try:
        return json.loads(raw)
    except (ValueError, RecursionError):
        return None  # XML (TSX/TX) or broken: pytiled-parser reports it, the file is bounded


def _layers(layers: list[Any], parent: str) -> Any:
    for layer in layers:
        if not isinstance(layer, dict):
            continue
        name = f"{parent}{layer.get('name', '')}"
        yield name, layer
        if layer.get("type") == "group":
            yield from _layers(_list(layer.get("layers")), f"{name}/")


def _list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else []


def _size(thing: dict[str, Any]) -> tuple[int, int] | None:
    """``(width, height)`` when both are integers; anything else is pytiled-parser's to report."""
    width, height = thing.get("width"), thing.get("height")
    if any(isinstance(v, bool) or not isinstance(v, int) for v in (width, height)):
        return None
    return int(width), int(height)  # type: ignore[arg-type]


def _fail(source: str, where: str, problem: str) -> NoReturn:
    raise LevelError(source, where, problem)
