"""The Tiled classes a map may use, and what each becomes in a level (SPEC §10 "Tiled maps").

One :class:`TiledClass` per class: its name (matched, case-insensitively, on an object's
``class`` or legacy ``type``, or on a tile layer's name or class), what it becomes, the
level field it fills and a one-line description. The loader (:mod:`navmesh.tiled`), its
warnings and ``docs/levels.md``'s class table (:func:`markdown_table`, kept current by a
test) read them here. The built-in classes are constants; every zone kind of
:func:`navmesh.level_fields.zone_kinds` — built in, or registered by a stimulus with
``register_zone_kind`` — is a class of its own name, so there is no second list of kinds.

>>> [c.name for c in object_classes(("dark",))]
['guard', 'decoy', 'collectible', 'player', 'obstacle', 'outline', 'exit', 'dark']
>>> PLAYER.single, PLAYER.is_area, zone_class("dark").field
(True, False, 'zones.dark')
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

__all__ = ["AREA", "AREAS", "BUILT_IN", "WALL_CLASSES", "WALL_PROPERTIES", "COLLECTIBLE", "DECOY", "EXIT", "GUARD", "OBSTACLE",
           "OUTLINE", "PLAYER", "POINT", "POINTS", "TILES", "WALLS", "TiledClass",
           "markdown_table", "object_classes", "tiled_classes", "zone_class"]

POINTS = "points"
"""Each object is a point (a point object, or the centre of any other shape) of a list field."""
POINT = "point"
"""The one object of its class (at most one per map) is the point of a field."""
AREAS = "areas"
"""Each object is a polygon (rectangle, polygon, ellipse as a 32-gon) of a list field."""
AREA = "area"
"""The one object of its class (at most one per map) is the polygon of a field."""
TILES = "tiles"
"""A tile layer (by its name or its class), whose non-zero tiles are blocked."""

_POINT_SHAPE, _AREA_SHAPE = "point, or the centre of any shape", "rectangle, polygon, ellipse"
_SHAPES = {POINTS: _POINT_SHAPE, POINT: _POINT_SHAPE, AREAS: _AREA_SHAPE, AREA: _AREA_SHAPE,
           TILES: "tile layer, by its name or its class"}


@dataclass(frozen=True)
class TiledClass:
    """A class a Tiled map's layers or objects may have, and what it becomes in the level."""

    name: str
    """The class, lower case."""
    becomes: str
    """One of :data:`POINTS`, :data:`POINT`, :data:`AREAS`, :data:`AREA`, :data:`TILES`."""
    field: str
    """The SPEC §8 level field it fills (``"zones.dark"`` for a zone kind); "" for the walls
    layers, which become the ``grid`` or, beside an obstacle or outline object, obstacles."""
    description: str
    """What it is in the level, one line (docs and messages)."""
    when_missing: str = ""
    """Why a map without any object of the class still loads (its warning); "" means no
    warning."""

    @property
    def single(self) -> bool:
        """Whether a map may hold at most one object of the class."""
        return self.becomes in (POINT, AREA)

    @property
    def is_area(self) -> bool:
        """Whether its objects must have an area (else each is a point)."""
        return self.becomes in (AREAS, AREA)


WALLS = TiledClass("walls", TILES, "", "its non-zero tiles are blocked; there may be several")
GUARD = TiledClass("guard", POINTS, "guards", "a guard spawn",
                   when_missing="the guards start at random nodes "
                                "(as with world.spawns = \"random\")")
DECOY = TiledClass("decoy", POINTS, "decoys", "a decoy the player can activate")
COLLECTIBLE = TiledClass("collectible", POINTS, "collectibles",
                         "an item the player can pick up")
PLAYER = TiledClass("player", POINT, "player", "the player's start")
OBSTACLE = TiledClass("obstacle", AREAS, "obstacles", "a blocked area, on or off the grid")
OUTLINE = TiledClass("outline", AREA, "outline",
                     "the level's boundary instead of the map's bounds")
EXIT = TiledClass("exit", AREAS, "exits", "an exit area")

BUILT_IN = (WALLS, GUARD, DECOY, COLLECTIBLE, PLAYER, OBSTACLE, OUTLINE, EXIT)
"""The classes that are not zone kinds, in the order messages and docs list them."""

WALL_CLASSES = (WALLS.name, "wall", "solid", "collision", "collisions", "collider",
                "colliders", "blocked", OBSTACLE.name, "obstacles")
"""Classes (and layer names) Tiled users mark walls with (:mod:`navmesh.tiled_tiles`): a
tileset tile of one of these classes is a wall tile; a tile layer named or of one of them is
a walls layer (every non-zero tile blocked); an object of one of them (or without a class in
an object layer named or of one of them) is a blocked area."""

WALL_PROPERTIES = ("collides", "collide", "collision", "collidable", "solid", "blocked",
                   "blocks", "wall", "obstacle")
"""Boolean tile properties (any case) that make a tile a wall when true and none when false."""


def zone_class(kind: str) -> TiledClass:
    """The class of a zone kind: each of its objects is a zone of that kind."""
    return TiledClass(kind, AREAS, f"zones.{kind}", f"a zone of kind `{kind}`")


def tiled_classes(kinds: Iterable[str]) -> tuple[TiledClass, ...]:
    """Every class: the built-in ones, then one per zone kind (``kinds``: the kinds known
    now are :func:`~navmesh.level_fields.zone_kinds`)."""
    return BUILT_IN + tuple(zone_class(k) for k in kinds)


def object_classes(kinds: Iterable[str]) -> tuple[TiledClass, ...]:
    """The classes an object may have (all but the tile layers')."""
    return tuple(c for c in tiled_classes(kinds) if c.becomes != TILES)


def markdown_table(kinds: Iterable[str]) -> str:
    """The class table of ``docs/levels.md`` (``kinds``: the built-in zone kinds): each class
    with its shape and what it becomes; the last row stands for the kinds a stimulus
    registers."""
    lines = ["| class | shape | becomes |", "|---|---|---|"]
    for c in tiled_classes(kinds):
        notes = [c.description + (f" (`{c.field}`)" if c.field else "")]
        if c.single:
            notes.append("at most one")
        if c.when_missing:
            notes.append(f"without any, {c.when_missing}")
        lines.append(f"| `{c.name}` | {_SHAPES[c.becomes]} | {'; '.join(notes)} |")
    lines.append(f"| a kind a stimulus registered (`register_zone_kind`) | {_SHAPES[AREAS]} | "
                 "a zone of that kind (`zones.KIND`) |")
    return "\n".join(lines) + "\n"
