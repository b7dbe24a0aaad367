"""Tiled object templates merged into the objects placed from them, read by the map's one reader.

An object placed from a template (``template="guard.tx"`` in TMX, ``"template": "guard.tj"``
in JSON) stores only its id, position and what it overrides; the rest is in the template.
Tiled's rule is applied here, on the decoded map: the object's own attributes win,
properties are merged by name (the object's value wins), and the template's shape is kept
unless the object has its own. pytiled-parser, which would open the template and its
tileset with a plain :func:`open`, then sees ordinary objects and opens nothing. As in
Tiled, a map of either format may use templates of either format (``.tx`` or ``.tj``): a
template in the other format is converted (its attributes, shape and scalar properties;
class-typed properties, which a level never reads, are left out).

Each template and its tileset are read through the map's one reader (``MapFiles``), so a
FIFO, a device or a huge file is refused like any file a map names. A template's tile object
counts its gid in the template's own tileset: as in Tiled, it is moved to that tileset's
place in the map (:class:`MapTilesets`), which gains the tileset if it lacks it, so the
object's tile class and walls are those of its tile. Every placed object counts its
template's size against :data:`navmesh.level_fields.MAX_FILE_BYTES`, so a small map cannot
multiply a large template into unbounded work.
"""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as etree
from pathlib import Path
from typing import Any, Callable, NoReturn

from navmesh.errors import LevelError
from navmesh.level_fields import MAX_FILE_BYTES
from navmesh.tiled_format import is_tiled_xml

__all__ = ["MapTilesets", "Templates"]

_SHAPES = ("ellipse", "point", "polygon", "polyline", "text")
_FLAGS = 0xF0000000  # a gid's flip and rotation flags
_ADDED_FIRST, _ADDED_SPAN, _ADDED_MAX = 0x08000000, 0x00400000, 31
"""Tilesets a map gains from its templates start at _ADDED_FIRST, _ADDED_SPAN gids apart: no
map's own tilesets reach there (a 64 MiB file cannot list 2^27 tiles)."""


class MapTilesets:
    """The map's external tilesets by file, and the first gid of each; ``add(firstgid,
    path)`` puts a template's tileset the map lacks into the map's document."""

    def __init__(self, firstgids: dict[str, int], add: Callable[[int, str], None]) -> None:
        self._firstgids = dict(firstgids)
        self._add = add
        self._added = 0

    def firstgid(self, path: Path, source: str, field: str) -> int:
        """The map's first gid of the tileset file ``path`` (added to the map if needed)."""
        key = os.path.normpath(path)
        if key not in self._firstgids:
            if self._added >= _ADDED_MAX:
                raise LevelError(source, field, f"the map's templates name more than "
                                                f"{_ADDED_MAX} tilesets the map lacks")
            first = _ADDED_FIRST + self._added * _ADDED_SPAN
            self._added += 1
            self._firstgids[key] = first
            self._add(first, key)
        return self._firstgids[key]


class Templates:
    """The templates one map uses: each read and decoded once, merged into each object.

    ``read(path, field)`` is the map's one reader (:meth:`navmesh.tiled_guard.MapFiles.read`);
    ``source`` names the map in errors.
    """

    def __init__(self, read: Callable[[Path, str], bytes], source: str,
                 tilesets: MapTilesets | None = None) -> None:
        self.read = read
        self.source = source
        self.tilesets = tilesets
        self._decoded: dict[Path, Any] = {}
        self._tileset_of: dict[Path, tuple[Path, int]] = {}
        self._expanded = 0

    def _map_gid(self, gid: Any, template: Path, field: str) -> Any:
        """A template's gid in the map's numbering (unchanged without a tileset to map)."""
        if template not in self._tileset_of or self.tilesets is None:
            return gid
        try:
            number = int(gid)
        except (TypeError, ValueError):
            return gid
        if not 0 <= number < 2**32:
            return gid
        path, first = self._tileset_of[template]
        local = (number & ~_FLAGS) - first
        if local < 0:
            return gid
        return (number & _FLAGS) | (self.tilesets.firstgid(path, self.source, field) + local)

    def inline_json(self, obj: dict[str, Any], folder: Path, where: str) -> dict[str, Any]:
        """The JSON object ``obj`` with its template's keys merged in (no ``template`` key)."""
        template = self._load(obj.get("template"), folder, where, xml=False)
        merged = {k: v for k, v in template.items() if k not in ("id", "template")}
        if "gid" in merged and "gid" not in obj:
            merged["gid"] = self._map_gid(merged["gid"], folder / obj["template"],
                                          f"{where} template")
        for key, value in obj.items():
            if key == "template":
                continue
            inherited = merged.get("properties")
            if key == "properties" and isinstance(value, list) and isinstance(inherited, list):
                own = {p.get("name") for p in value if isinstance(p, dict)}
                value = [p for p in inherited
                         if not (isinstance(p, dict) and p.get("name") in own)] + value
            merged[key] = value
        return merged

    def inline_xml(self, obj: Any, folder: Path, where: str) -> Any:
        """A new ``<object>`` element: ``obj`` with its template's attributes and children."""
        template = self._load(obj.get("template"), folder, where, xml=True)
        merged = etree.Element("object", {k: v for k, v in template.attrib.items()
                                          if k not in ("id", "template")})
        if merged.get("gid") is not None and obj.get("gid") is None:
            merged.set("gid", str(self._map_gid(merged.get("gid"), folder / obj.get("template"),
                                                f"{where} template")))
        merged.attrib.update((k, v) for k, v in obj.attrib.items() if k != "template")
        own = {child.tag for child in obj}
        for child in template:  # shared, not copied: nothing downstream changes them
            if child.tag not in own and not (child.tag in _SHAPES and own & set(_SHAPES)):
                merged.append(child)
        for child in obj:
            inherited = template.find(child.tag)
            if child.tag == "properties" and inherited is not None:
                names = {p.get("name") for p in child}
                combined = etree.Element("properties")
                combined.extend(p for p in inherited if p.get("name") not in names)
                combined.extend(child)
                child = combined
            merged.append(child)
        merged.tail = obj.tail
        return merged

    def _load(self, named: Any, folder: Path, where: str, *, xml: bool) -> Any:
        """The template's object (a dict or an element), charging its size to the map."""
        field = f"{where} template"
        if not isinstance(named, str) or not named:
            self._fail(field, f"must name a template file, got {named!r}")
        path = folder / named
        raw = self.read(path, field)
        self._expanded += len(raw)
        if self._expanded > MAX_FILE_BYTES:
            self._fail(field, f"the map's objects expand to more than "
                              f"{MAX_FILE_BYTES // 2**20} MiB of templates")
        if path not in self._decoded:
            self._decoded[path] = self._decode(path, raw, field, xml)
        return self._decoded[path]

    def _note_tileset(self, path: Path, named: str, first: Any) -> None:
        """Remember the tileset (and its first gid there) a template counts its gid in."""
        try:
            self._tileset_of[path] = (path.parent / named, int(first))
        except (TypeError, ValueError):
            pass

    def _decode(self, path: Path, raw: bytes, field: str, xml: bool) -> Any:
        if not raw.strip():
            self._fail(field, f"{path} is empty")
        template = self._decode_format(path, raw, field, is_tiled_xml(raw))
        if is_tiled_xml(raw) == xml:
            return template
        try:
            return _xml_object(template) if xml else _json_object(template)
        except (TypeError, ValueError, AttributeError, KeyError) as exc:
            self._fail(field, f"{path} cannot be converted to the map's format "
                              f"({type(exc).__name__}: {exc})")

    def _decode_format(self, path: Path, raw: bytes, field: str, xml: bool) -> Any:
        if xml:
            try:
                root = etree.fromstring(raw)
            except etree.ParseError as exc:
                self._fail(field, f"{path} is not valid XML ({exc})")
            template = root.find("object") if root.tag == "template" else None
            tileset = root.find("tileset")
            named = tileset.get("source") if tileset is not None else None
            first = tileset.get("firstgid", "1") if tileset is not None else None
            if template is None:
                self._fail(field, f"{path} is not an object template (no <template> holding "
                                  "an <object>)")
        else:
            try:
                doc = json.loads(raw.decode("utf-8-sig"))
            except (UnicodeDecodeError, ValueError, RecursionError) as exc:
                self._fail(field, f"{path} is not valid JSON ({exc})")
            template = doc.get("object") if isinstance(doc, dict) else None
            tileset = doc.get("tileset") if isinstance(doc, dict) else None
            named = tileset.get("source") if isinstance(tileset, dict) else None
            first = tileset.get("firstgid", 1) if isinstance(tileset, dict) else None
            if not isinstance(template, dict):
                self._fail(field, f"{path} is not an object template (no \"object\")")
        if named is not None:
            if not isinstance(named, str):
                self._fail(f"{field}'s tileset", f"source must be a file name, got {named!r}")
            self.read(path.parent / named, f"{field}'s tileset")
            self._note_tileset(path, named, first)
        return template

    def _fail(self, field: str, problem: str) -> NoReturn:
        raise LevelError(self.source, field, problem)


# --------------------------------------------------------------------------- conversion

_NUMBERS: dict[str, Callable[[str], Any]] = {
    "x": float, "y": float, "width": float, "height": float, "rotation": float, "gid": int,
    "id": int}
_SCALARS: dict[str, Callable[[str], Any]] = {"int": int, "float": float,
                                             "bool": lambda v: v == "true"}


def _json_object(element: Any) -> dict[str, Any]:
    """A TMX template's ``<object>`` as the JSON object Tiled would have written."""
    obj: dict[str, Any] = {}
    for key, value in element.attrib.items():
        if key == "visible":
            obj[key] = value != "0"
        else:
            obj[key] = _NUMBERS.get(key, str)(value)
    for child in element:
        if child.tag in ("point", "ellipse"):
            obj[child.tag] = True
        elif child.tag in ("polygon", "polyline"):
            pairs = [p.split(",") for p in (child.get("points") or "").split()]
            obj[child.tag] = [{"x": float(x), "y": float(y)} for x, y in pairs]
        elif child.tag == "text":
            obj["text"] = {**child.attrib, "text": child.text or ""}
        elif child.tag == "properties":
            obj["properties"] = [
                {"name": p.get("name"), "type": p.get("type", "string"),
                 "value": _SCALARS.get(p.get("type", ""), str)(p.get("value", p.text or ""))}
                for p in child if p.get("type") != "class"]
    return obj


def _xml_object(obj: dict[str, Any]) -> Any:
    """A JSON template's object as the TMX ``<object>`` Tiled would have written."""
    element = etree.Element("object")
    for key, value in obj.items():
        if isinstance(value, bool):
            if key == "visible":
                element.set(key, "1" if value else "0")
            elif key in ("point", "ellipse") and value:
                etree.SubElement(element, key)
        elif key in ("polygon", "polyline"):
            points = " ".join(f"{p['x']},{p['y']}" for p in value)
            etree.SubElement(element, key, points=points)
        elif key == "text" and isinstance(value, dict):
            text = etree.SubElement(element, "text", {k: str(v) for k, v in value.items()
                                                      if k != "text"})
            text.text = str(value.get("text", ""))
        elif key == "properties" and isinstance(value, list):
            holder = etree.SubElement(element, "properties")
            for p in value:
                if p.get("type") != "class":
                    shown = str(p.get("value")).lower() if isinstance(p.get("value"), bool) \
                        else str(p.get("value"))
                    etree.SubElement(holder, "property", name=str(p.get("name")),
                                     type=str(p.get("type", "string")), value=shown)
        elif isinstance(value, (int, float, str)):
            element.set(key, str(value))
    return element
