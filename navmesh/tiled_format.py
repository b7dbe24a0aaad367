"""Which level files are Tiled maps: decided by suffix, then by content (no pytiled import).

A ``.tmj`` or ``.tmx`` file is a Tiled map; so is any file whose first non-blank character
is ``<`` (TMX is XML, a Stealthfield level is JSON), and any JSON object that is not a
Stealthfield level (no ``"format"`` key) and has ``"type": "map"`` or the keys every Tiled
map has (older Tiled wrote no ``"type"``).

>>> is_tiled_json({"tilewidth": 32, "layers": [], "orientation": "orthogonal"})
True
>>> is_tiled_json({"format": "stealth-level/1", "name": "box", "grid": ["."]})
False
>>> is_tiled_xml(b'  <?xml version="1.0"?><map/>'), is_tiled_xml(b'{"format": 1}')
(True, False)
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["TILED_SUFFIXES", "is_tiled_json", "is_tiled_suffix", "is_tiled_xml"]

TILED_SUFFIXES = (".tmj", ".tmx")
"""File suffixes that always mean a Tiled map (JSON and XML)."""

_TILED_MAP_KEYS = ("tilewidth", "tileheight", "layers", "orientation")


def is_tiled_suffix(path: Path) -> bool:
    """Whether the file's suffix alone says it is a Tiled map."""
    return path.suffix.lower() in TILED_SUFFIXES


def is_tiled_xml(raw: bytes) -> bool:
    """Whether the bytes look like XML (a TMX map) rather than JSON."""
    return raw.lstrip(b"\xef\xbb\xbf \t\r\n")[:1] == b"<"


def is_tiled_json(data: Any) -> bool:
    """Whether a decoded JSON value is a Tiled map rather than a Stealthfield level."""
    if not isinstance(data, dict) or "format" in data:
        return False
    return data.get("type") == "map" or any(key in data for key in _TILED_MAP_KEYS)
