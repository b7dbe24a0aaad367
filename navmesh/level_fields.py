"""A level's fields read from JSON values (SPEC §8): numbers, points, polygons, the grid,
zones and spots, each failing with a one-line :class:`LevelError` that names its field;
the zone kinds a level may declare; the size limits."""

from __future__ import annotations

import json
import math
from typing import Any, NoReturn

import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from navmesh.errors import LevelError
from navmesh.names import name_problem
from navmesh.tiled_classes import BUILT_IN, WALL_CLASSES

__all__ = ["MAX_CELLS", "MAX_LEVEL_VERTICES", "MAX_POLYGON_VERTICES", "MAX_SPOTS", "ZONE_KINDS", "register_zone_kind", "zone_kinds"]

MAX_FILE_BYTES = 64 * 2**20
"""Largest level file read (64 MiB; the bundled levels are a few kB)."""

MAX_EXTENT = 1e6
"""Largest coordinate (and cell size) of a level, in world units; beyond, the geometry's
double precision is lost to the agents' sub-unit moves (the bundled levels span 100)."""

MIN_CELL_SIZE = 1e-3
"""Smallest cell size, in world units (an agent's body must also fit a cell: check_level)."""

MAX_CELLS = 1_000_000
"""Largest allowed occupancy grid (rows x cols); checked before anything is rasterised."""

MAX_SPOTS = 1000
"""Most guard, decoy or collectible points a level may list (each is a body in the world)."""

MAX_POLYGON_VERTICES = 10_000
"""Most points of one polygon (the outline, an obstacle, a zone).  Beyond, the navmesh's
build (GEOS's constrained Delaunay of a 10^5-point hole: minutes; the refinement of a
many-cornered round room) outgrows the 30 s a level may take: ``stealth levels`` on a
regular polygon of 10^4 points takes 7 s, of 2 × 10^4 points 15-20 s (docs/hostile-inputs.md)."""

MAX_LEVEL_VERTICES = 200_000
"""Most points of the outline and the obstacles together (a 1000×1000-cell building of
rooms has 86,000)."""

ZONE_KINDS = ("dark", "concealment")
"""The built-in zone kinds; a stimulus may declare more with :func:`register_zone_kind`."""

_zone_kinds: list[str] = list(ZONE_KINDS)


def register_zone_kind(kind: str) -> None:
    """Let levels (JSON and Tiled) declare zones of ``kind``, e.g. from a stimulus plugin.

    Registering a known kind again does nothing. Levels parsed afterwards have the kind as
    a key of ``Level.zones``; levels parsed before keep the kinds they were parsed with.
    A kind is a word (:func:`navmesh.names.name_problem`), because it is a Tiled class and
    a key of ``zones``; a Tiled map matches classes case-insensitively, so a kind named like
    a built-in Tiled class (``guard``, ``walls``, ...), a wall class (``solid``, ...) or
    like another kind in another case is refused (``ValueError``): a map's guard spawns or
    walls would silently become zones.
    """
    problem = name_problem(kind)
    if problem is not None:
        raise ValueError(f"a zone kind {problem}")
    taken = ([c.name for c in BUILT_IN] + list(WALL_CLASSES)
             + [k for k in _zone_kinds if k != kind])
    clash = next((name for name in taken if name.lower() == kind.lower()), None)
    if clash is not None:
        raise ValueError(f"zone kind {kind!r}: a Tiled map could not tell it from the class "
                         f"{clash!r} (classes match in any case); choose another name")
    if kind not in _zone_kinds:
        _zone_kinds.append(kind)


def zone_kinds() -> tuple[str, ...]:
    """Zone kinds a level may declare now: the built-in ones, then the registered ones."""
    return tuple(_zone_kinds)


_AREA_EPS = 1e-12  # areas at or below this are "zero" (float noise from shapely overlays)
# JSON arrays and numbers; tuples and numpy scalars are accepted from in-memory levels too.
_ARRAY_TYPES = (list, tuple)
_NUMBER_TYPES = (int, float, np.integer, np.floating)

Point = tuple[float, float]


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
    if len(value) > MAX_POLYGON_VERTICES + 1:  # before reading a point (+1: a closing point)
        _fail(src, field, f"polygon of {len(value)} points, more than the limit of {MAX_POLYGON_VERTICES}")
    points = [_point(p, src, f"{field}[{i}]") for i, p in enumerate(value)]
    ring = [p for i, p in enumerate(points) if i == 0 or p != points[i - 1]]
    if len(ring) > 1 and ring[0] == ring[-1]:
        ring.pop()
    if len(ring) > MAX_POLYGON_VERTICES:
        _fail(src, field, f"polygon of {len(ring)} points, more than the limit of {MAX_POLYGON_VERTICES}")
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
    corners = len(outline.exterior.coords) - 1 + sum(len(o) for o in obstacles_value if isinstance(o, _ARRAY_TYPES))
    if corners > MAX_LEVEL_VERTICES:
        _fail(src, "obstacles", f"outline and obstacles have {corners} points in all, more than the limit "
                                f"of {MAX_LEVEL_VERTICES}")
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
