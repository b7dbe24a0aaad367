"""The cached static layer: floor, zones, field overlay, grid/mesh lines, zone and exit
outlines, walls and level decoys, drawn once into a Surface and blitted every frame.

The cache covers the part of the level around what the window shows (the visible world
rectangle plus half a window on every side, clipped to the level), at the current zoom.
It is rebuilt only when the camera leaves it, the zoom changes, the field layer changes
(once per AI tick) or the mesh option is toggled, and a rebuild draws only the rings,
segments, cells and triangles whose bounding boxes meet the region: so the cost of a
frame, and of a rebuild, depends on the window, not on the size of the level.

Drawing order (bottom to top): floor and zone fills, the colour-mapped field, mesh lines,
then zone outlines, exit outlines, walls and decoys, so outlines stay visible over every
overlay.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pygame
import shapely

from game.scene import FieldLayer, StaticScene

from .palette import (
    BACKGROUND, BLOCKED, DECOY, EXIT_EDGE, FLOOR, HALO, MESH, OVERLAY_ALPHA, TEXT_DIM,
    ZONE_EDGE, ZONE_FILL, colors_of,
)

__all__ = ["Region", "StaticLayers"]

_KEY = (255, 0, 255)  # colour key of the line layer (never drawn)
#: Stripes the game composes a large level's new field values in, one per frame.
COMPOSE_STRIPES = 4
#: No grid lines below this many pixels per cell (they would only darken the map).
MIN_CELL_PIXELS = 4.0


@dataclass(frozen=True)
class Region:
    """A cached part of the level: world rectangle ``x0, y0, x1, y1`` at ``scale`` px/unit."""

    x0: float
    y0: float
    x1: float
    y1: float
    scale: float

    def covers(self, x0: float, y0: float, x1: float, y1: float, scale: float) -> bool:
        """Whether the world rectangle, at ``scale``, is inside this region."""
        eps = 1e-6
        return (abs(scale - self.scale) < 1e-9 and x0 >= self.x0 - eps and y0 >= self.y0 - eps
                and x1 <= self.x1 + eps and y1 <= self.y1 + eps)

    @property
    def size(self) -> tuple[int, int]:
        """Pixel size of the region's surface."""
        return (max(1, round((self.x1 - self.x0) * self.scale)),
                max(1, round((self.y1 - self.y0) * self.scale)))


def _bboxes(rings: list[np.ndarray]) -> np.ndarray:
    if not rings:
        return np.zeros((0, 4))
    return np.array([[r[:, 0].min(), r[:, 1].min(), r[:, 0].max(), r[:, 1].max()] for r in rings])


def _meets(boxes: np.ndarray, region: Region) -> np.ndarray:
    if not len(boxes):
        return np.zeros(0, dtype=bool)
    return ((boxes[:, 2] >= region.x0) & (boxes[:, 0] <= region.x1)
            & (boxes[:, 3] >= region.y0) & (boxes[:, 1] <= region.y1))


def _meeting(boxes: np.ndarray, region: Region) -> np.ndarray:
    """Indices of the boxes that meet ``region`` (the loops draw only those)."""
    return np.flatnonzero(_meets(boxes, region))


def _layer_key(layer: FieldLayer | None) -> str | None:
    return None if layer is None else layer.key


class StaticLayers:
    """The static layer of one :class:`StaticScene`, cached by region, field and options."""

    def __init__(self, static: StaticScene, stripes: int = 1) -> None:
        self.static = static
        #: whether new values of a field are composed in stripes (a large level)
        self.striped = int(stripes) > 1
        #: how many stripes the next new field values are composed in (the game sets it
        #: from its frame budget; a compose under way keeps the count it started with)
        self.stripes = max(1, int(stripes))
        #: the seconds the last composition of the whole region took (measured)
        self.compose_cost = 0.0
        outline, *holes = static.floor
        self._outline, self._holes = outline, holes
        self._hole_boxes = _bboxes(holes)
        self._zones = [(kind, ring) for kind, polys in static.zones.items() for ring, *_ in polys]
        self._zone_boxes = _bboxes([ring for _, ring in self._zones])
        self._exits = list(static.exits)
        walls = static.walls.reshape(-1, 2, 2)
        self._walls = walls
        self._wall_boxes = np.concatenate([walls.min(axis=1), walls.max(axis=1)], axis=1) \
            if len(walls) else np.zeros((0, 4))
        self._tris = static.triangles
        self._tri_boxes = (np.concatenate([static.triangles.min(axis=1), static.triangles.max(axis=1)],
                                          axis=1) if static.triangles is not None else np.zeros((0, 4)))
        self.region: Region | None = None
        self._base: pygame.Surface | None = None
        self._lines: pygame.Surface | None = None
        self._mesh: pygame.Surface | None = None
        self._composite: pygame.Surface | None = None
        self._composite_key: tuple[object, bool] | None = None
        #: a composite being built in stripes: (its layer, surface, next stripe, stripes)
        self._next: tuple[FieldLayer | None, pygame.Surface, int, int] | None = None
        self._layer: FieldLayer | None = None
        self._pool: dict[str, pygame.Surface] = {}
        self._outline_shape = shapely.Polygon(outline) if len(outline) >= 3 else None
        self.rebuilds = 0

    # ------------------------------------------------------------------ public
    def surface(self, visible: tuple[float, float, float, float], scale: float,
                layer: FieldLayer | None, show_mesh: bool) -> tuple[pygame.Surface, Region]:
        """The composed static layer covering the ``visible`` world rectangle at ``scale``."""
        if self.region is None or not self.region.covers(*visible, scale):
            self._new_region(visible, scale)
        assert self.region is not None
        key = (id(layer) if layer is not None else None, show_mesh)
        at_once = (self._composite is None or self._composite_key is None
                   or show_mesh != self._composite_key[1]
                   or _layer_key(layer) != _layer_key(self._layer))  # a toggle shows at once
        if at_once or key != self._composite_key or layer is not self._layer:
            self._compose(layer, show_mesh, at_once or not self.striped)
        assert self._composite is not None
        return self._composite, self.region

    @property
    def composing(self) -> bool:
        """Whether a new field layer is still being composed in stripes."""
        return self._next is not None

    def _compose(self, layer: FieldLayer | None, show_mesh: bool, at_once: bool) -> None:
        """Base, field, mesh and line layers into the spare surface — all of it, or the next
        of ``stripes`` stripes — and, once complete, copied into the composite that
        :meth:`surface` returns (the old one is shown until then; with one stripe the
        composite is drawn onto directly).

        New values of the same field (once per AI tick) come in :attr:`stripes` stripes when
        the layers are :attr:`striped` (the game on a large level, where composing the region
        costs a frame ~10 ms; the game sets the count from its frame budget); anything else, and every small level, at once, so a rendered scene
        shows its own layer. The spare is copied, not swapped with the composite: the line
        layer is RLE-encoded for the one surface it is blitted onto, and SDL encodes it again
        for every other (measured: 13 ms at 10^6 cells).
        """
        if at_once or self._next is None or self._next[0] is not layer:
            # without stripes the composite itself is the one surface drawn onto (no copy)
            spare = self._blank("composite-next" if self.striped else "composite")
            self._next = (layer, spare, 0, 1 if at_once else max(1, int(self.stripes)))
        _, spare, stripe, stripes = self._next
        done = stripes if at_once else stripe + 1
        width, height = spare.get_size()
        top = height * stripe // stripes
        started = time.perf_counter()
        spare.set_clip(pygame.Rect(0, top, width, height * done // stripes - top))
        spare.blit(self._base_surface(), (0, 0))
        if layer is not None:
            self._draw_field(spare, layer.norm)
        if show_mesh:
            if self._mesh is None:
                self._mesh = self._keyed(self._draw_mesh)
            spare.blit(self._mesh, (0, 0))
        if self._lines is None:
            self._lines = self._keyed(self._draw_lines)
        spare.blit(self._lines, (0, 0))
        spare.set_clip(None)
        if height * (done - stripe) // stripes:  # the whole region's cost, from this part
            self.compose_cost = (time.perf_counter() - started) * stripes / (done - stripe)
        if done < stripes:
            self._next = (layer, spare, done, stripes)
            return
        composite = self._blank("composite")
        if composite is not spare:
            composite.blit(spare, (0, 0))
        self._composite, self._next = composite, None
        self._composite_key, self._layer = (id(layer) if layer is not None else None, show_mesh), layer

    # ------------------------------------------------------------------ building
    def _new_region(self, visible: tuple[float, float, float, float], scale: float) -> None:
        x0, y0, x1, y1 = visible
        mx, my = (x1 - x0) / 2, (y1 - y0) / 2
        w, h = self.static.width, self.static.height
        self.region = Region(max(0.0, x0 - mx), max(0.0, y0 - my), min(w, x1 + mx),
                             min(h, y1 + my), scale)
        if self.region.x1 <= self.region.x0 or self.region.y1 <= self.region.y0:
            self.region = Region(0.0, 0.0, w, h, scale)
        self._base = self._lines = self._mesh = self._composite = None
        self._next = None
        self.rebuilds += 1

    def _pts(self, points: np.ndarray) -> list[tuple[float, float]]:
        r = self.region
        assert r is not None
        p = (np.asarray(points, dtype=float).reshape(-1, 2) - (r.x0, r.y0)) * r.scale
        return [(float(x), float(y)) for x, y in p]

    def _blank(self, role: str) -> pygame.Surface:
        """The surface of one role (base, composite, line layers) at the region's size,
        reused from the last region when the size is the same (no allocation per rebuild)."""
        assert self.region is not None
        surface = self._pool.get(role)
        if surface is None or surface.get_size() != self.region.size:
            surface = self._pool[role] = pygame.Surface(self.region.size).convert()
        return surface

    def _floor_outline(self, region: Region) -> list[np.ndarray]:
        """The floor's outer ring, clipped to the region when it reaches beyond it (a large
        level's outline is filled over a region-sized surface only, not the whole level)."""
        outline = self._outline
        if self._outline_shape is None or (
                outline[:, 0].min() >= region.x0 and outline[:, 1].min() >= region.y0
                and outline[:, 0].max() <= region.x1 and outline[:, 1].max() <= region.y1):
            return [outline]
        pad = 1.0 / region.scale  # a pixel beyond the region, so no edge shows at its border
        clipped = shapely.clip_by_rect(self._outline_shape, region.x0 - pad, region.y0 - pad,
                                       region.x1 + pad, region.y1 + pad)
        return [np.asarray(p.exterior.coords) for p in shapely.get_parts(clipped)
                if isinstance(p, shapely.Polygon) and not p.is_empty]

    def _keyed(self, draw: Callable[[pygame.Surface], None]) -> pygame.Surface:
        surface = self._blank(draw.__name__)
        surface.set_colorkey(None)
        surface.fill(_KEY)
        draw(surface)
        surface.set_colorkey(_KEY, pygame.RLEACCEL)
        return surface

    def _base_surface(self) -> pygame.Surface:
        if self._base is not None:
            return self._base
        region = self.region
        assert region is not None
        surface = self._blank("base")
        surface.fill(BACKGROUND)
        extent = self._pts(np.array([[0.0, 0.0], [self.static.width, self.static.height]]))
        (ax, ay), (bx, by) = extent
        surface.fill(BLOCKED, pygame.Rect(round(ax), round(ay), round(bx - ax), round(by - ay)))
        for ring in self._floor_outline(region):
            pygame.draw.polygon(surface, FLOOR, self._pts(ring))
        holes = [self._holes[i] for i in _meeting(self._hole_boxes, region)]
        for hole in holes:
            pygame.draw.polygon(surface, BLOCKED, self._pts(hole))
        for i in _meeting(self._zone_boxes, region):
            kind, ring = self._zones[i]
            pygame.draw.polygon(surface, ZONE_FILL.get(kind, FLOOR), self._pts(ring))
        for hole in holes:  # a zone clipped to the floor has the obstacles as its holes
            pygame.draw.polygon(surface, BLOCKED, self._pts(hole))
        self._base = surface
        return surface

    def _draw_lines(self, surface: pygame.Surface) -> None:
        """Zone and exit outlines (with a dark halo), walls, static decoys."""
        region = self.region
        assert region is not None
        s = region.scale
        for i in _meeting(self._zone_boxes, region):
            kind, ring = self._zones[i]
            pts = self._pts(ring)
            pygame.draw.lines(surface, HALO, True, pts, 4)
            pygame.draw.lines(surface, ZONE_EDGE.get(kind, TEXT_DIM), True, pts, 2)
        for ring in self._exits:
            pts = self._pts(ring)
            pygame.draw.lines(surface, HALO, True, pts, 6)
            pygame.draw.lines(surface, EXIT_EDGE, True, pts, 3)
        width = max(2, round(s * 0.12))
        walls = (self._walls[_meeting(self._wall_boxes, region)] - (region.x0, region.y0)) * s
        for pa, pb in walls.tolist():
            pygame.draw.line(surface, (236, 236, 244), pa, pb, width)
        for x, y in self.static.decoys:
            (cx, cy), = self._pts(np.array([[x, y]]))
            r = max(5.0, s * 0.3)
            pygame.draw.polygon(surface, DECOY, [(cx, cy - r), (cx + r, cy), (cx, cy + r), (cx - r, cy)],
                                max(2, round(s * 0.08)))

    def _cells(self) -> tuple[int, int, int, int]:
        r = self.region
        assert r is not None
        cs = self.static.cell_size
        rows, cols = self.static.occupancy.shape
        return (max(0, int(r.y0 // cs)), min(rows, int(np.ceil(r.y1 / cs))),
                max(0, int(r.x0 // cs)), min(cols, int(np.ceil(r.x1 / cs))))

    def _draw_mesh(self, surface: pygame.Surface) -> None:
        region = self.region
        assert region is not None
        if self._tris is not None:
            for tri in ((self._tris[_meeting(self._tri_boxes, region)] - (region.x0, region.y0))
                        * region.scale).tolist():
                pygame.draw.lines(surface, MESH, True, tri, 1)
            return
        cell = self.static.cell_size * region.scale
        if cell < MIN_CELL_PIXELS:
            return
        r0, r1, c0, c1 = self._cells()
        ox, oy = -region.x0 * region.scale, -region.y0 * region.scale
        for r, c in np.argwhere(self.static.occupancy[r0:r1, c0:c1]):
            rect = pygame.Rect(round(ox + (c0 + c) * cell), round(oy + (r0 + r) * cell),
                               round(cell) + 1, round(cell) + 1)
            pygame.draw.rect(surface, MESH, rect, 1)

    def _draw_field(self, surface: pygame.Surface, norm: np.ndarray) -> None:
        """Colour every node's cell (grid) or triangle (partition) by its normalised value."""
        region = self.region
        assert region is not None
        clip = surface.get_clip()
        if self.static.cell_node is not None:
            # One pixel per cell of the region (within the clip's rows), then scaled up.
            r0, r1, c0, c1 = self._cells()
            cs = self.static.cell_size
            r0 = max(r0, int((region.y0 + clip.top / region.scale) // cs))
            r1 = min(r1, int(np.ceil((region.y0 + clip.bottom / region.scale) / cs)))
            cell_node = self.static.cell_node[r0:r1, c0:c1]
            rows, cols = cell_node.shape
            if not rows or not cols:
                return
            image = np.zeros((rows, cols, 4), dtype=np.uint8)
            inside = cell_node >= 0
            image[inside, :3] = colors_of(norm[cell_node[inside]])  # the region's nodes only
            image[inside, 3] = OVERLAY_ALPHA
            small = pygame.image.frombuffer(image.tobytes(), (cols, rows), "RGBA").convert_alpha()
            cell = self.static.cell_size * region.scale
            big = pygame.transform.scale(small, (round(cols * cell), round(rows * cell)))
            (x, y), = self._pts(np.array([[c0 * self.static.cell_size, r0 * self.static.cell_size]]))
            surface.blit(big, (round(x), round(y)))
        elif self._tris is not None:
            layer = pygame.Surface(surface.get_size(), pygame.SRCALPHA).convert_alpha()
            shown = _meeting(self._tri_boxes, Region(
                region.x0 + clip.left / region.scale, region.y0 + clip.top / region.scale,
                region.x0 + clip.right / region.scale, region.y0 + clip.bottom / region.scale,
                region.scale))
            tris = ((self._tris[shown] - (region.x0, region.y0)) * region.scale).tolist()
            for tri, (r, g, b) in zip(tris, colors_of(norm[shown]).tolist()):
                pygame.draw.polygon(layer, (r, g, b, OVERLAY_ALPHA), tri)
            surface.blit(layer, (0, 0))
