"""The level format (SPEC §8): :class:`Level`, its validation and rasterisation.

Reading files and choosing their format is :mod:`navmesh.level`, which re-exports
everything here; a reader of another format (:mod:`navmesh.tiled`) builds on this module.

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

import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon

from navmesh.errors import LevelError
from navmesh.grid_geometry import cells_polygon
from navmesh.level_fields import (
    _ARRAY_TYPES,
    MAX_CELLS,
    MAX_EXTENT,
    MIN_CELL_SIZE,
    MAX_SPOTS,
    ZONE_KINDS,
    Point,
    _check_connected,
    _check_spot,
    _describe,
    _fail,
    _number,
    _parse_grid,
    _parse_polygon,
    _parse_spots,
    _parse_zones,
    _point,
    _polygon_geometry,
    _polygons_overlapping,
    register_zone_kind,
    zone_kinds,
)

__all__ = [
    "FORMAT",
    "MAX_SPOTS",
    "MAX_CELLS",
    "ZONE_KINDS",
    "Level",
    "LevelError",
    "parse_level",
    "register_zone_kind",
    "zone_kinds",
]

FORMAT = "stealth-level/1"
"""The only accepted value of a level's ``format`` key."""

_REQUIRED_KEYS = ("format", "name", "guards")
_OPTIONAL_KEYS = (
    "cell_size", "outline", "obstacles", "grid", "zones", "decoys",
    "player", "exits", "collectibles", "facing", "patrols",
)
_ALLOWED_KEYS = _REQUIRED_KEYS + _OPTIONAL_KEYS
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
    facing: tuple[float | None, ...] = ()
    """Each guard's heading at its spawn point, in radians (0 = +x, π/2 = +y, down on the
    screen), ``None`` where the level gives none; empty when it gives none at all. Used with
    ``world.spawns = "level"``."""
    patrols: tuple[tuple[Point, ...], ...] = ()
    """Each guard's patrol route (walkable points, in order; empty for a guard without one);
    empty when the level gives none at all."""
    tiled: bool = False
    """Whether the level was read from a Tiled map: guards a designer placed there start
    where they stand in ``stealth sim`` unless ``world.spawns`` is set (JSON levels and
    presets keep the configured rule)."""

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


def parse_level(
    data: Any, source: str = "<memory>", *, path: Path | None = None, digest: str | None = None,
    require_guards: bool = True, tiled: bool = False,
) -> Level:
    """Validate an in-memory level (the decoded JSON object) and build its :class:`Level`.

    ``source`` names the level in error messages; ``path`` and ``digest`` (the content
    identity of the file it came from) are stored on the result. ``require_guards=False``
    accepts an empty ``guards`` list (a Tiled map without guard objects: its guards spawn
    at random nodes, :func:`game.spawns.guard_spawn_nodes`).
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
    guards = _parse_spots(data["guards"], src, "guards", required=require_guards, **level_spots)
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
    facing = _parse_facing(data.get("facing"), len(guards), src)
    patrols = _parse_patrols(data.get("patrols"), len(guards), src, level_spots)
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
        facing=facing,
        patrols=patrols,
        tiled=tiled,
    )


def _parse_facing(value: Any, guards: int, src: str) -> tuple[float | None, ...]:
    """``facing``: one entry per guard, degrees clockwise on the screen from +x (0 = east,
    90 = south) or null; kept in radians."""
    if value is None:
        return ()
    if not isinstance(value, _ARRAY_TYPES) or len(value) != guards:
        _fail(src, "facing", f"expected an array of {guards} numbers or nulls (one per guard), "
                             f"got {_describe(value)}")
    return tuple(None if v is None else math.radians(_number(v, src, f"facing[{i}]"))
                 for i, v in enumerate(value))


def _parse_patrols(value: Any, guards: int, src: str, level_spots: dict[str, Any]
                   ) -> tuple[tuple[Point, ...], ...]:
    """``patrols``: one route per guard, each an array of walkable points (may be empty)."""
    if value is None:
        return ()
    if not isinstance(value, _ARRAY_TYPES) or len(value) != guards:
        _fail(src, "patrols", f"expected an array of {guards} routes (one per guard), got "
                              f"{_describe(value)}")
    return tuple(_parse_spots(route, src, f"patrols[{i}]", required=False, **level_spots)
                 for i, route in enumerate(value))
