"""Level files: loading, validation and rasterisation (SPEC §8).

A level is one JSON object (``"format": "stealth-level/1"``) whose geometry is given either
as an ``outline`` polygon minus ``obstacles`` or as a ``grid`` of strings (``#`` blocked).
Both forms become the same :class:`Level`: one walkable shapely polygon (one piece, may have
holes) plus a boolean occupancy grid that always starts at the world origin, with x to the
right and y downwards (row r covers ``y in [r, r+1) * cell_size``).

Every problem with a file is reported as a :class:`LevelError` whose message is one line,
``"<file>: <field>: <problem>"``, so the command line can print it and exit cleanly.

>>> level = parse_level({"format": "stealth-level/1", "name": "box",
...                      "grid": ["...", ".#.", "..."], "guards": [[0.5, 0.5]]})
>>> level.rows, level.cols, int(level.occupancy.sum())
(3, 3, 8)
>>> level.contains(1.5, 1.5), level.cell_of(2.2, 0.7)
(False, (0, 2))
"""

from __future__ import annotations

import hashlib
import importlib.resources
import json
import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path
from typing import Any, NoReturn

import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from navmesh.errors import LevelError
from navmesh.files import FileRefused, read_regular
from navmesh.grid_geometry import cells_polygon

__all__ = [
    "FORMAT",
    "MAX_EXTENT",
    "MAX_FILE_BYTES",
    "MIN_CELL_SIZE",
    "MAX_SPOTS",
    "LEVELS_DIR",
    "MAX_CELLS",
    "ZONE_KINDS",
    "Level",
    "LevelError",
    "bundled_level_names",
    "cached_level",
    "load_level",
    "parse_level",
    "register_zone_kind",
    "resolve_level_path",
    "zone_kinds",
]

FORMAT = "stealth-level/1"
"""The only accepted value of a level's ``format`` key."""

MAX_CELLS = 1_000_000
"""Largest allowed occupancy grid (rows x cols); checked before anything is rasterised."""

MAX_EXTENT = 1e6
"""Largest coordinate (and cell size) of a level, in world units; beyond, the geometry's
double precision is lost to the agents' sub-unit moves (the bundled levels span 100)."""

MIN_CELL_SIZE = 1e-3
"""Smallest cell size, in world units (an agent's body must also fit a cell: check_level)."""

MAX_FILE_BYTES = 64 * 2**20
"""Largest level file read (64 MiB; the bundled levels are a few kB)."""

MAX_SPOTS = 1000
"""Most guard, decoy or collectible points a level may list (each is a body in the world)."""

ZONE_KINDS = ("dark", "concealment")
"""The built-in zone kinds; a stimulus may declare more with :func:`register_zone_kind`."""

_zone_kinds: list[str] = list(ZONE_KINDS)


def register_zone_kind(kind: str) -> None:
    """Let levels (JSON and Tiled) declare zones of ``kind``, e.g. from a stimulus plugin.

    Registering a known kind again does nothing. Levels parsed afterwards have the kind as
    a key of ``Level.zones``; levels parsed before keep the kinds they were parsed with.
    """
    if not isinstance(kind, str) or not kind.strip() or kind != kind.strip():
        raise ValueError(f"a zone kind is a non-empty string without spaces around it, got {kind!r}")
    if kind not in _zone_kinds:
        _zone_kinds.append(kind)


def zone_kinds() -> tuple[str, ...]:
    """Zone kinds a level may declare now: the built-in ones, then the registered ones."""
    return tuple(_zone_kinds)


def _bundled_levels_dir() -> Path:
    """``assets/levels`` of a source checkout, else the copy installed as package data.

    The checkout wins so that a worktree on ``PYTHONPATH`` sees its own levels even while an
    editable install of another checkout is on the path; a wheel ships the same folder as
    the data package ``stealthfield_assets`` (pyproject ``package-dir``).
    """
    root = Path(__file__).resolve().parent.parent
    if (root / "pyproject.toml").is_file() and (root / "assets" / "levels").is_dir():
        return root / "assets" / "levels"
    try:
        return Path(str(importlib.resources.files("stealthfield_assets") / "levels"))
    except (ModuleNotFoundError, NotADirectoryError):  # no installed data package to read
        return root / "assets" / "levels"


LEVELS_DIR = _bundled_levels_dir()
"""Folder of the bundled levels (see :func:`_bundled_levels_dir`)."""

_REQUIRED_KEYS = ("format", "name", "guards")
_OPTIONAL_KEYS = (
    "cell_size", "outline", "obstacles", "grid", "zones", "decoys",
    "player", "exits", "collectibles",
)
_ALLOWED_KEYS = _REQUIRED_KEYS + _OPTIONAL_KEYS
_AREA_EPS = 1e-12  # areas at or below this are "zero" (float noise from shapely overlays)
# JSON arrays and numbers; tuples and numpy scalars are accepted from in-memory levels too.
_ARRAY_TYPES = (list, tuple)
_NUMBER_TYPES = (int, float, np.integer, np.floating)

Point = tuple[float, float]


@dataclass(frozen=True, eq=False)
class Level:
    """A validated level: walkable polygon, occupancy grid, zones and spawn points.

    Built by :func:`load_level` / :func:`parse_level`, which guarantee the invariants: the
    walkable area is one polygon, the walkable cells are one 4-connected group, and every
    guard and decoy lies in the walkable area inside a walkable cell. ``walkable`` has no
    collinear vertices; its exterior is counter-clockwise in world coordinates
    (``exterior.is_ccw``; clockwise on a y-down screen) and its holes the other way.
    ``eq=False``: levels compare and hash by identity (numpy and shapely fields have no
    useful ``==``); ``digest`` is the content identity instead: the SHA-256 of the file
    bytes the level was parsed from (``None`` for a level built in memory), the key of the
    per-process caches (:func:`cached_level`, :func:`navmesh.graph.graph_for`).
    """

    name: str
    path: Path | None
    cell_size: float
    walkable: Polygon
    occupancy: np.ndarray
    zones: dict[str, tuple[Polygon, ...]]
    guards: tuple[Point, ...]
    decoys: tuple[Point, ...]
    digest: str | None = None
    player: Point | None = None
    """The player's start in interactive play and with ``world.spawns = "level"``."""
    exits: tuple[Polygon, ...] = ()
    """Areas the player leaves the level through (objectives, issue 16)."""
    collectibles: tuple[Point, ...] = ()
    """Items the player can pick up (objectives, issue 16)."""

    def __post_init__(self) -> None:
        occupancy = np.array(self.occupancy, dtype=bool)  # private copy, then frozen
        if occupancy.ndim != 2:
            raise ValueError(f"occupancy must be 2-D, got shape {occupancy.shape}")
        occupancy.setflags(write=False)
        object.__setattr__(self, "occupancy", occupancy)
        shapely.prepare(self.walkable)  # fast repeated contains() queries

    @property
    def rows(self) -> int:
        """Number of grid rows (y direction)."""
        return int(self.occupancy.shape[0])

    @property
    def cols(self) -> int:
        """Number of grid columns (x direction)."""
        return int(self.occupancy.shape[1])

    @cached_property
    def walls(self) -> np.ndarray:
        """Boundary segments of ``walkable`` (exterior and holes), shape ``(m, 2, 2)``, read-only.

        ``walls[i] = [[x0, y0], [x1, y1]]``; consecutive segments of a ring share endpoints.
        """
        rings = shapely.get_rings(self.walkable)  # exterior first, then the holes
        coords, ring = shapely.get_coordinates(rings, return_index=True)
        same_ring = ring[:-1] == ring[1:]  # each ring repeats its first point at the end
        segments = np.stack([coords[:-1][same_ring], coords[1:][same_ring]], axis=1)
        segments.setflags(write=False)
        return segments

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """Grid cell ``(row, col)`` containing the world point ``(x, y)``.

        Cells are half-open, except that the far right and bottom edges of the grid belong
        to the last column and row. Raises ``ValueError`` for a point outside the grid.
        """
        width, height = self.cols * self.cell_size, self.rows * self.cell_size
        if not (0.0 <= x <= width and 0.0 <= y <= height):
            raise ValueError(
                f"point ({x:g}, {y:g}) is outside the {self.rows}x{self.cols} grid of "
                f"level {self.name!r}"
            )
        row = min(int(y // self.cell_size), self.rows - 1)
        col = min(int(x // self.cell_size), self.cols - 1)
        return row, col

    def cell_center(self, row: int, col: int) -> Point:
        """World coordinates of the centre of cell ``(row, col)``."""
        return ((col + 0.5) * self.cell_size, (row + 0.5) * self.cell_size)

    def contains(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` lies in the walkable area (the boundary counts as inside)."""
        return bool(shapely.intersects_xy(self.walkable, x, y))


# --------------------------------------------------------------------------- loading


def bundled_level_names() -> list[str]:
    """Names of the levels shipped in ``assets/levels`` (file stems, sorted)."""
    return sorted(p.stem for p in LEVELS_DIR.glob("*.json"))


def resolve_level_path(path_or_name: str | Path) -> Path:
    """The file a level argument refers to: an existing file, else a bundled level name.

    A bare name without a folder or ``.json`` suffix (``"miami"``, case-insensitive) that is
    not an existing file is looked up in ``assets/levels``; an unknown bare name raises
    :class:`LevelError` listing the bundled names. Anything else is returned as a path
    (whether it exists is :func:`load_level`'s business).
    """
    path = Path(path_or_name)
    if path.is_file():
        return path
    text = str(path_or_name)
    if _looks_like_name(text):
        bundled = LEVELS_DIR / f"{text.lower()}.json"
        if bundled.is_file():
            return bundled
        names = ", ".join(bundled_level_names()) or "none"
        raise LevelError(text, "file", f"no such file or bundled level (bundled levels: {names})")
    return path


def load_level(path_or_name: str | Path) -> Level:
    """Load and validate a level from a JSON file, a Tiled map or a bundled level name.

    A ``.tmj`` file, or a JSON file whose ``"type"`` is ``"map"``, is a Tiled map, read by
    :mod:`navmesh.tiled` into the same structure. Errors name the file as the caller gave
    it (a bundled level by its file name).
    """
    content = _read_level_file(path_or_name)
    return _parse_content(content)


def cached_level(path_or_name: str | Path) -> Level:
    """:func:`load_level`, memoised per process on the file's resolved path and content.

    The one level cache of the project: the file is read on every call (levels are a few
    kB) and its SHA-256 compared, so an edited file is parsed again — never a stale level —
    while repeated trials on an unchanged file share one :class:`Level` (and, through
    ``Level.digest``, one node graph).
    """
    return _cached_parse(_read_level_file(path_or_name))


def parse_level(
    data: Any, source: str = "<memory>", *, path: Path | None = None, digest: str | None = None
) -> Level:
    """Validate an in-memory level (the decoded JSON object) and build its :class:`Level`.

    ``source`` names the level in error messages; ``path`` and ``digest`` (the content
    identity of the file it came from) are stored on the result.
    """
    src = source
    if not isinstance(data, dict):
        _fail(src, "top-level", f"expected a JSON object, got {_describe(data)}")
    for key in data:
        if key not in _ALLOWED_KEYS:
            _fail(src, str(key), f"unknown key (allowed keys: {', '.join(_ALLOWED_KEYS)})")
    for key in _REQUIRED_KEYS:
        if key not in data:
            _fail(src, key, "missing required key")

    if data["format"] != FORMAT:
        _fail(src, "format", f"expected {FORMAT!r}, got {_describe(data['format'])}")
    name = data["name"]
    if not isinstance(name, str) or not name.strip():
        _fail(src, "name", f"expected a non-empty string, got {_describe(name)}")
    cell_size = _number(data.get("cell_size", 1.0), src, "cell_size")
    if not MIN_CELL_SIZE <= cell_size <= MAX_EXTENT:  # beyond, geometry loses its precision
        _fail(src, "cell_size", f"must be in [{MIN_CELL_SIZE:g}, {MAX_EXTENT:g}] world units, "
                                f"got {cell_size:g}")

    has_outline, has_grid = "outline" in data, "grid" in data
    if has_outline and has_grid:
        _fail(src, "outline/grid", "both 'outline' and 'grid' given; use exactly one geometry form")
    if not has_outline and not has_grid:
        _fail(src, "outline/grid", "no geometry; give either 'outline' (+ 'obstacles') or 'grid'")
    if has_grid:
        if "obstacles" in data:
            _fail(src, "obstacles", "only allowed with 'outline', not with 'grid'")
        occupancy = _parse_grid(data["grid"], src)
        if not max(occupancy.shape) * cell_size <= MAX_EXTENT:
            _fail(src, "cell_size", f"{cell_size:g} is too large: the level would span "
                                    f"{max(occupancy.shape) * cell_size:g} world units, more "
                                    f"than the limit of {MAX_EXTENT:g}")
        _check_connected(occupancy, src, "grid")
        walkable = cells_polygon(occupancy, cell_size)
        outline: Polygon | None = None
    else:
        outline = _parse_polygon(data["outline"], src, "outline")
        if not max(abs(v) for v in outline.bounds) <= MAX_EXTENT:
            _fail(src, "outline", f"coordinates beyond ±{MAX_EXTENT:g} world units")
        walkable, occupancy = _polygon_geometry(outline, data.get("obstacles", []), cell_size, src)

    zones = _parse_zones(data.get("zones", {}), walkable, src)
    level_spots = dict(walkable=walkable, occupancy=occupancy, outline=outline, cell_size=cell_size)
    guards = _parse_spots(data["guards"], src, "guards", required=True, **level_spots)
    decoys = _parse_spots(data.get("decoys", []), src, "decoys", required=False, **level_spots)
    collectibles = _parse_spots(
        data.get("collectibles", []), src, "collectibles", required=False, **level_spots
    )
    player = None
    if "player" in data:
        player = _point(data["player"], src, "player")
        _check_spot(player, src, "player", **level_spots)
    exits = data.get("exits", [])
    if not isinstance(exits, _ARRAY_TYPES):
        _fail(src, "exits", f"expected an array of polygons, got {_describe(exits)}")
    exit_areas = tuple(_polygons_overlapping(
        exits, walkable, src, "exits", "exit does not overlap the walkable area"
    ))
    return Level(
        name=name,
        path=path,
        cell_size=cell_size,
        walkable=walkable,
        occupancy=occupancy,
        zones=zones,
        guards=guards,
        decoys=decoys,
        digest=digest,
        player=player,
        exits=exit_areas,
        collectibles=collectibles,
    )


# --------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class _LevelFile:
    """A level file's bytes; equal (and hashed) by resolved path and SHA-256 of the bytes only."""

    resolved: str
    digest: str
    raw: bytes = field(compare=False, repr=False)
    path: Path = field(compare=False)
    source: str = field(compare=False)


def _read_level_file(path_or_name: str | Path) -> _LevelFile:
    path = resolve_level_path(path_or_name)
    source = str(path_or_name) if path == Path(path_or_name) else path.name
    raw = _read_bytes(path, source)
    return _LevelFile(str(path.resolve()), hashlib.sha256(raw).hexdigest(), raw, path, source)


def _parse_content(content: _LevelFile) -> Level:
    data = _decode_json(content.raw, content.source)
    if content.path.suffix.lower() == ".tmj" or (isinstance(data, dict) and data.get("type") == "map"):
        from navmesh.tiled import load_tiled  # lazy: imports this module and pytiled-parser

        return load_tiled(content.path, content.source, content.digest)
    return parse_level(data, content.source, path=content.path, digest=content.digest)


_cached_parse = lru_cache(maxsize=32)(_parse_content)


def _read_bytes(path: Path, src: str) -> bytes:
    """Read a level file (a regular file of at most :data:`MAX_FILE_BYTES`); every failure
    becomes a one-line LevelError."""
    try:
        return read_regular(path, MAX_FILE_BYTES)
    except FileRefused as refused:
        _fail(src, "file", str(refused))
    except FileNotFoundError:
        _fail(src, "file", "no such file")
    except IsADirectoryError:
        _fail(src, "file", "is a directory, not a level file")
    except PermissionError:
        _fail(src, "file", "permission denied")
    except OSError as exc:
        _fail(src, "file", f"cannot read ({exc.strerror or exc})")


def _decode_json(raw: bytes, src: str) -> Any:
    """Decode a level file's bytes; every failure becomes a one-line LevelError."""
    if not raw.strip():
        _fail(src, "file", "is empty")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _fail(src, "file", f"not UTF-8 text (invalid byte at offset {exc.start})")
    try:
        # NaN/Infinity literals decode to floats and are rejected with their field name later.
        return json.loads(text, object_pairs_hook=_no_duplicate_keys)
    except _DuplicateKey as exc:
        _fail(src, exc.key, "duplicate key")
    except json.JSONDecodeError as exc:
        _fail(src, "json", f"not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}")
    except (ValueError, RecursionError) as exc:  # e.g. an integer with too many digits
        _fail(src, "json", f"not valid JSON: {exc}")


class _DuplicateKey(Exception):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    obj: dict[str, Any] = {}
    for key, value in pairs:
        if key in obj:
            raise _DuplicateKey(key)
        obj[key] = value
    return obj


# --------------------------------------------------------------------------- values


def _fail(src: str, field: str, problem: str) -> NoReturn:
    raise LevelError(src, field, problem)


def _one_line(text: str) -> str:
    return " ".join(str(text).splitlines())


def _looks_like_name(text: str) -> bool:
    """A bare level name: no folder separator and no ``.json`` suffix."""
    has_folder = "/" in text or "\\" in text
    return bool(text) and not has_folder and not text.lower().endswith(".json")


def _describe(value: Any) -> str:
    """JSON type and a short repr of a value, for "expected X, got Y" messages."""
    if isinstance(value, bool):
        kind = "a boolean"
    elif isinstance(value, _NUMBER_TYPES):
        kind = "a number"
    elif isinstance(value, str):
        kind = "a string"
    elif isinstance(value, _ARRAY_TYPES):
        return f"an array of {len(value)} items"
    elif isinstance(value, dict):
        return "an object"
    elif value is None:
        return "null"
    else:
        kind = type(value).__name__
    try:
        text = repr(value) if isinstance(value, float) else json.dumps(value)
    except (TypeError, ValueError):  # not a JSON value (in-memory levels only)
        text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{kind} ({text})"


def _number(value: Any, src: str, field: str) -> float:
    """A finite JSON number (booleans are not numbers)."""
    if isinstance(value, bool) or not isinstance(value, _NUMBER_TYPES):
        _fail(src, field, f"expected a number, got {_describe(value)}")
    try:
        number = float(value)
    except OverflowError:
        _fail(src, field, "number is too large")
    if not math.isfinite(number):
        shown = "NaN" if math.isnan(number) else ("Infinity" if number > 0 else "-Infinity")
        _fail(src, field, f"non-finite number {shown} (NaN and Infinity are not allowed)")
    return number


def _point(value: Any, src: str, field: str) -> Point:
    """An ``[x, y]`` pair of finite numbers."""
    if not isinstance(value, _ARRAY_TYPES) or len(value) != 2:
        _fail(src, field, f"expected a point [x, y], got {_describe(value)}")
    return (_number(value[0], src, f"{field}[0]"), _number(value[1], src, f"{field}[1]"))


def _polygons_overlapping(
    values: Any, region: Polygon, src: str, field: str, problem: str
) -> list[Polygon]:
    """Each of ``values`` parsed as a polygon that must overlap ``region`` (else ``problem``)."""
    parsed = []
    shapely.prepare(region)
    for i, raw in enumerate(values):
        polygon = _parse_polygon(raw, src, f"{field}[{i}]")
        # Inside the region the overlap is the polygon itself, whose area _parse_polygon
        # checked: the (prepared) containment test spares most levels an intersection each.
        if not region.contains(polygon) and region.intersection(polygon).area <= _AREA_EPS:
            _fail(src, f"{field}[{i}]", problem)
        parsed.append(polygon)
    return parsed


def _parse_polygon(value: Any, src: str, field: str) -> Polygon:
    """A simple polygon from a list of points (closing point optional)."""
    if not isinstance(value, _ARRAY_TYPES):
        _fail(src, field, f"expected a polygon (an array of [x, y] points), got {_describe(value)}")
    points = [_point(p, src, f"{field}[{i}]") for i, p in enumerate(value)]
    ring = [p for i, p in enumerate(points) if i == 0 or p != points[i - 1]]
    if len(ring) > 1 and ring[0] == ring[-1]:
        ring.pop()
    distinct = len(set(ring))
    if distinct < 3:
        _fail(src, field, f"polygon needs at least 3 distinct points, got {distinct}")
    xy = np.asarray(ring) - ring[0]  # ring[1] != ring[0], so collinear <=> all crosses vanish
    xy /= max(float(np.abs(xy).max()), 1.0)  # scale-free tolerance, no overflow
    cross = xy[1, 0] * xy[2:, 1] - xy[1, 1] * xy[2:, 0]
    if np.abs(cross).max() <= 1e-12:
        _fail(src, field, "polygon has zero area (all its points are collinear)")
    polygon = Polygon(ring)
    if not polygon.is_valid:
        _fail(src, field, f"polygon is not simple: {shapely.is_valid_reason(polygon)}")
    if polygon.area <= _AREA_EPS:
        _fail(src, field, "polygon has zero area")
    return polygon


def _parse_grid(value: Any, src: str) -> np.ndarray:
    """Occupancy (True = walkable) from a list of equal-length strings, ``#`` blocked."""
    if not isinstance(value, _ARRAY_TYPES):
        _fail(src, "grid", f"expected an array of strings, got {_describe(value)}")
    if not value:
        _fail(src, "grid", "grid is empty (no rows)")
    for i, row in enumerate(value):
        if not isinstance(row, str):
            _fail(src, f"grid[{i}]", f"expected a string, got {_describe(row)}")
    cols = len(value[0])
    if cols == 0:
        _fail(src, "grid[0]", "row is empty")
    for i, row in enumerate(value):
        if len(row) != cols:
            _fail(src, f"grid[{i}]", f"row has {len(row)} cells, expected {cols} like grid[0]")
    _check_size(len(value), cols, src, "grid")
    chars = np.array(list(value), dtype=f"<U{cols}").view("<U1").reshape(len(value), cols)
    return chars != "#"


def _check_size(rows: int, cols: int, src: str, field: str) -> None:
    cells = rows * cols
    if cells > MAX_CELLS:
        _fail(src, field, f"grid of {rows}x{cols} = {cells} cells exceeds the limit of {MAX_CELLS}")


# --------------------------------------------------------------------------- geometry


def _single_piece(geometry: BaseGeometry, src: str, field: str) -> Polygon:
    """The one polygon of ``geometry``, tidied (no collinear vertices, exterior CCW)."""
    parts = shapely.get_parts(geometry)
    pieces = [g for g in parts if isinstance(g, Polygon) and g.area > _AREA_EPS]
    if not pieces:
        _fail(src, field, "nothing is walkable")
    if len(pieces) > 1:
        areas = ", ".join(f"{g.area:g}" for g in sorted(pieces, key=lambda g: -g.area)[:5])
        _fail(src, field, f"walkable area is in {len(pieces)} disconnected pieces (areas {areas})")
    polygon = shapely.simplify(pieces[0], 0.0)  # drops collinear vertices, keeps topology
    return orient(polygon, sign=1.0)


def _polygon_geometry(
    outline: Polygon, obstacles_value: Any, cell_size: float, src: str
) -> tuple[Polygon, np.ndarray]:
    """Walkable polygon (outline minus obstacles) and its rasterised occupancy."""
    minx, miny, maxx, maxy = outline.bounds
    if minx < 0 or miny < 0:
        x, y = next((x, y) for x, y in outline.exterior.coords if x < 0 or y < 0)
        _fail(
            src,
            "outline",
            f"point ({x:g}, {y:g}) has a negative coordinate; the grid starts at the origin, "
            "so outline coordinates must be >= 0",
        )
    height, width = maxy / cell_size, maxx / cell_size
    if not (math.isfinite(height) and math.isfinite(width)):  # e.g. a subnormal cell_size
        _fail(src, "outline", f"the level spans more than {MAX_CELLS} cells at this cell_size")
    rows, cols = math.ceil(height - 1e-9), math.ceil(width - 1e-9)
    _check_size(rows, cols, src, "outline")

    if not isinstance(obstacles_value, _ARRAY_TYPES):
        _fail(src, "obstacles", f"expected an array of polygons, got {_describe(obstacles_value)}")
    obstacles = _polygons_overlapping(
        obstacles_value, outline, src, "obstacles", "obstacle lies entirely outside the outline"
    )
    field = "obstacles" if obstacles else "outline"
    walkable = outline.difference(shapely.unary_union(obstacles)) if obstacles else outline
    if walkable.area <= _AREA_EPS:
        _fail(src, field, "obstacles cover the whole outline; nothing is walkable")
    walkable = _single_piece(walkable, src, field)

    ys, xs = (np.mgrid[0:rows, 0:cols] + 0.5) * cell_size
    shapely.prepare(walkable)  # same answers; a million cell centres ~10x faster
    occupancy = shapely.contains_xy(walkable, xs, ys)
    _check_connected(occupancy, src, field)
    return walkable, occupancy


def _check_connected(occupancy: np.ndarray, src: str, field: str) -> None:
    """At least one walkable cell, and all of them one 4-connected group."""
    labels, count = ndimage.label(occupancy)  # default structure: 4-neighbourhood
    if count == 0:
        _fail(src, field, "no walkable cell (no cell centre lies in the walkable area)")
    if count > 1:
        sizes = np.bincount(labels.ravel())[1:]
        smallest = int(np.argmin(sizes)) + 1
        rows, cols = np.nonzero(labels == smallest)
        _fail(
            src,
            field,
            f"walkable cells form {count} disconnected groups (4-neighbourhood); e.g. the "
            f"{sizes[smallest - 1]} cell(s) around row {rows[0]}, col {cols[0]} are cut off",
        )


# --------------------------------------------------------------------------- zones, spots


def _parse_zones(value: Any, walkable: Polygon, src: str) -> dict[str, tuple[Polygon, ...]]:
    if not isinstance(value, dict):
        _fail(src, "zones", f"expected an object of zone kind -> polygons, got {_describe(value)}")
    kinds = zone_kinds()
    zones: dict[str, tuple[Polygon, ...]] = {kind: () for kind in kinds}
    for kind, polygons in value.items():
        field = f"zones.{kind}"
        if kind not in kinds:
            _fail(src, field, f"unknown zone kind (known kinds: {', '.join(kinds)})")
        if not isinstance(polygons, _ARRAY_TYPES):
            _fail(src, field, f"expected an array of polygons, got {_describe(polygons)}")
        zones[kind] = tuple(_polygons_overlapping(
            polygons, walkable, src, field, "zone does not overlap the walkable area"
        ))
    return zones


def _parse_spots(
    value: Any,
    src: str,
    field: str,
    *,
    required: bool,
    walkable: Polygon,
    occupancy: np.ndarray,
    outline: Polygon | None,
    cell_size: float,
) -> tuple[Point, ...]:
    """Guard, decoy or collectible points: each checked by :func:`_check_spot`."""
    if not isinstance(value, _ARRAY_TYPES):
        _fail(src, field, f"expected an array of [x, y] points, got {_describe(value)}")
    if required and not value:
        _fail(src, field, "needs at least one point")
    if len(value) > MAX_SPOTS:
        _fail(src, field, f"{len(value)} points, more than the limit of {MAX_SPOTS}")
    points = tuple(_point(p, src, f"{field}[{i}]") for i, p in enumerate(value))
    level = dict(walkable=walkable, occupancy=occupancy, outline=outline, cell_size=cell_size)
    for i, point in enumerate(points):
        _check_spot(point, src, f"{field}[{i}]", **level)
    return points


def _check_spot(
    point: Point,
    src: str,
    field: str,
    *,
    walkable: Polygon,
    occupancy: np.ndarray,
    outline: Polygon | None,
    cell_size: float,
) -> None:
    """A spawn point must lie in the walkable area and in a walkable grid cell."""
    x, y = point
    rows, cols = occupancy.shape
    where = f"point ({x:g}, {y:g})"
    in_grid = 0 <= x <= cols * cell_size and 0 <= y <= rows * cell_size
    in_level = in_grid if outline is None else bool(shapely.intersects_xy(outline, x, y))
    if not in_level:
        _fail(src, field, f"{where} is outside the level")
    if not shapely.intersects_xy(walkable, x, y):
        _fail(src, field, f"{where} is inside a wall")
    row = min(int(y // cell_size), rows - 1)
    col = min(int(x // cell_size), cols - 1)
    if not occupancy[row, col]:
        _fail(
            src,
            field,
            f"{where} is in grid cell (row {row}, col {col}), which is not walkable "
            "(its centre is inside a wall); move the point into a walkable cell",
        )
