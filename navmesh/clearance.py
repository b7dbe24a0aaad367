"""Body clearance: where a disc of the agent radius fits in a level's walkable area.

Agents are discs of radius r, not points. :class:`Clearance` answers the questions the
graph, the paths and ``stealth validate`` ask about that body: which grid moves are clear
(the disc swept along the centre-to-centre segment stays in the walkable area), the
walkable area eroded by r (Recast's agent-radius erosion) with its own navmesh for paths,
the nearest point a body centre may occupy, and where passages are narrower than the body.

>>> from shapely import box
>>> from navmesh.level import parse_level
>>> level = parse_level({"format": "stealth-level/1", "name": "thin",
...     "outline": [[0, 0], [4, 0], [4, 2], [0, 2]],
...     "obstacles": [[[1.95, 0], [2.05, 0], [2.05, 1.2], [1.95, 1.2]]],
...     "guards": [[0.5, 0.5]]})
>>> body = Clearance(level, 0.3)
>>> bool(level.occupancy[0, 1] and level.occupancy[0, 2]), bool(body.right_clear[0, 1])
(True, False)
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING

import numpy as np
import shapely
from shapely.geometry import Point, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.ops import nearest_points

from navmesh.query import find_path

if TYPE_CHECKING:
    from navmesh.level import Level
    from navmesh.mesh import NavMesh

__all__ = ["DEFAULT_AGENT_RADIUS", "PATH_MARGIN", "BodyReport", "Clearance", "check_body",
           "clearance_for"]

#: ``world.agent_radius`` of game/defaults.toml (tests/test_bounds_geometry.py checks they
#: agree): the body graphs are built for when a caller has no config at hand.
DEFAULT_AGENT_RADIUS = 0.3
#: Paths keep this much more than the radius from walls, so a body following one exactly
#: never touches a wall (pymunk would push it back by its collision slop).
PATH_MARGIN = 0.01
#: Pieces and narrow spots smaller than this (area, world units²) are numerical dust.
_AREA_EPS = 1e-4
#: Body-wide paths one :class:`Clearance` remembers (least recently used dropped first).
#: Bodies stop exactly on the node points they walk to, so a trial asks for the same few
#: thousand (start, goal) pairs over and over (94 % repeats on the paper's levels).
PATH_CACHE_SIZE = 16384


@dataclass(frozen=True)
class BodyReport:
    """What ``stealth validate`` says about a level for one body radius.

    ``narrow``: a point near every passage narrower than the body's diameter (warnings);
    ``pieces``: the areas of the eroded walkable area's pieces, largest first — more than
    one means a body cannot reach the whole level (an error).
    """

    radius: float
    narrow: tuple[tuple[float, float], ...]
    pieces: tuple[float, ...]
    piece_points: tuple[tuple[float, float], ...] = field(default=())

    @property
    def connected(self) -> bool:
        """Whether one body can reach every part of the eroded walkable area."""
        return len(self.pieces) <= 1


class Clearance:
    """A level seen by a disc body of ``radius``: clear grid moves, eroded area and mesh."""

    def __init__(self, level: Level, radius: float) -> None:
        self.level, self.radius = level, float(radius)
        self._report: BodyReport | None = None
        self._paths: OrderedDict[tuple[float, float, float, float], tuple[tuple[float, float], ...]] = (
            OrderedDict())

    @cached_property
    def right_clear(self) -> np.ndarray:
        """(rows, cols): whether the body moves clear from each cell to the one on its right."""
        return self._clear_grid_moves(0, 1)

    @cached_property
    def down_clear(self) -> np.ndarray:
        """(rows, cols): whether the body moves clear from each cell to the one below it."""
        return self._clear_grid_moves(1, 0)

    def _clear_grid_moves(self, dr: int, dc: int) -> np.ndarray:
        # computed on first use: validate's report() needs no grid moves
        occ, size = self.level.occupancy, self.level.cell_size
        rows, cols = occ.shape
        mask = np.zeros((rows, cols), dtype=bool)
        mask[:rows - dr, :cols - dc] = occ[:rows - dr, :cols - dc] & occ[dr:, dc:]
        r, c = np.nonzero(mask)
        if r.size:
            a = (np.column_stack([c, r]) + 0.5) * size
            b = (np.column_stack([c + dc, r + dr]) + 0.5) * size
            mask[r, c] = self.clear_moves(a, b)
        return mask

    # ------------------------------------------------------------------ swept-disc test
    @cached_property
    def _walls(self) -> shapely.STRtree:
        segments = shapely.linestrings(np.asarray(self.level.walls, dtype=np.float64))
        return shapely.STRtree(segments)

    def clear_moves(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Whether the disc swept from each ``a[i]`` to ``b[i]`` stays in the walkable area.

        Both ends must be walkable points; then the sweep is clear exactly when no wall
        comes closer to the segment than the radius (a wall crossing it has distance 0).
        """
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        inside = shapely.intersects_xy(self.level.walkable, a[:, 0], a[:, 1]) & \
            shapely.intersects_xy(self.level.walkable, b[:, 0], b[:, 1])
        moves = shapely.linestrings(np.stack([a, b], axis=1))
        hit, _ = self._walls.query(moves, predicate="dwithin", distance=self.radius * (1 - 1e-9))
        clear = inside.copy()
        clear[hit] = False
        return clear

    def clear_move(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """:meth:`clear_moves` for one segment."""
        return bool(self.clear_moves(np.array([a]), np.array([b]))[0])

    # ------------------------------------------------------------------ grid
    @cached_property
    def grid_cells(self) -> np.ndarray:
        """Walkable cells a body can stand on and move between: the largest group of cells
        joined by clear moves (a cell with no clear move, or cut off, is left out)."""
        occ = self.level.occupancy
        rows, cols = occ.shape
        index = np.arange(rows * cols).reshape(rows, cols)
        r1, c1 = np.nonzero(self.right_clear)
        r2, c2 = np.nonzero(self.down_clear)
        src = np.concatenate([index[r1, c1], index[r2, c2]])
        dst = np.concatenate([index[r1, c1 + 1], index[r2 + 1, c2]])
        if src.size == 0:  # no clear move at all: keep the level's cells (one-cell levels)
            return occ.copy()
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        graph = coo_matrix((np.ones(src.size), (src, dst)), shape=(rows * cols, rows * cols))
        _, labels = connected_components(graph, directed=False)
        joined = np.zeros(rows * cols, dtype=bool)
        joined[src] = joined[dst] = True
        sizes = np.bincount(labels[joined], minlength=labels.max() + 1)
        return (labels == int(np.argmax(sizes))).reshape(rows, cols) & joined.reshape(rows, cols)

    # ------------------------------------------------------------------ eroded area, paths
    def eroded(self, radius: float) -> BaseGeometry:
        """The walkable area eroded by ``radius`` (mitre joins: never closer than it to a wall)."""
        return self.level.walkable.buffer(-radius, join_style="mitre")

    @cached_property
    def path_area(self) -> Polygon:
        """Where paths run: the largest piece of the area eroded by radius + PATH_MARGIN."""
        pieces = [g for g in shapely.get_parts(self.eroded(self.radius + PATH_MARGIN))
                  if isinstance(g, Polygon) and g.area > _AREA_EPS]
        if not pieces:
            return Polygon()
        from shapely.geometry.polygon import orient

        piece = max(pieces, key=lambda g: g.area)
        piece = orient(shapely.simplify(piece, 0.0), sign=1.0)
        shapely.prepare(piece)
        return piece

    @cached_property
    def _snap_area(self) -> BaseGeometry:
        inner = self.path_area.buffer(-1e-6, join_style="mitre")
        return inner if not inner.is_empty else self.path_area

    @cached_property
    def path_mesh(self) -> NavMesh | None:
        """The navmesh of :attr:`path_area` (None when no body fits anywhere)."""
        from navmesh.mesh import NavMesh

        if self.path_area.is_empty:
            return None
        try:
            return NavMesh.build(self.path_area)
        except shapely.errors.GEOSException:  # GEOS's constrained Delaunay gives up on a few
            return NavMesh.build(self.path_area, method="earcut", min_angle=20.0)

    def snap(self, x: float, y: float) -> tuple[float, float]:
        """(x, y) itself when a body centre may stand there; else the nearest point that may."""
        if self.path_area.is_empty or shapely.intersects_xy(self.path_area, x, y):
            return (float(x), float(y))
        _, near = nearest_points(Point(x, y), self._snap_area)
        return (float(near.x), float(near.y))

    def path(self, start: tuple[float, float], goal: tuple[float, float]) -> list[tuple[float, float]]:
        """Waypoints (start excluded) of a path a body can follow from ``start`` to ``goal``.

        Both ends are snapped into :attr:`path_area` first; the path runs on its mesh, so
        every corner keeps radius + PATH_MARGIN from the walls. Empty if there is none.
        A pure function of the two points, so answers are remembered per (start, goal)
        (:data:`PATH_CACHE_SIZE`); each call returns a new list of new tuples, as a fresh
        search would (callers compare waypoints by identity).
        """
        key = (float(start[0]), float(start[1]), float(goal[0]), float(goal[1]))
        paths = self._paths
        found = paths.get(key)
        if found is None:
            found = tuple(self._path(key[0], key[1], key[2], key[3]))
            if 0.0 not in key:  # -0.0 == 0.0 as a key, but its sign would reach the waypoints
                paths[key] = found
                if len(paths) > PATH_CACHE_SIZE:
                    paths.popitem(last=False)
        else:
            paths.move_to_end(key)
        return [(x, y) for x, y in found]

    def _path(self, sx: float, sy: float, gx: float, gy: float) -> list[tuple[float, float]]:
        """:meth:`path` searched on the mesh (no cache)."""
        mesh = self.path_mesh
        if mesh is None:
            return []
        a, b = self.snap(sx, sy), self.snap(gx, gy)
        try:
            points = find_path(mesh, a, b).points
        except ValueError:  # OutsideError (a snapped point on a dust piece), no corridor
            return []
        out = [(float(x), float(y)) for x, y in points[1:]]
        if a != (sx, sy):
            out.insert(0, a)  # step out of the wall's reach first
        return out

    # ------------------------------------------------------------------ validation
    def report(self) -> BodyReport:
        """Narrow passages (warnings) and the pieces of the eroded area (error if several);
        a walkable area of many holes is checked group by group (:mod:`navmesh.body_report`).
        Computed once per :class:`Clearance` (every command checks it, every trial too)."""
        if self._report is None:
            self._report = self._compute_report()
        return self._report

    def _compute_report(self) -> BodyReport:
        from navmesh.body_report import LOCAL_MIN_HOLES, exact_parts, local_parts

        r, walkable = self.radius, self.level.walkable
        if isinstance(walkable, Polygon) and len(walkable.interiors) > LOCAL_MIN_HOLES:
            narrow, pieces = local_parts(walkable, r)
        else:
            narrow, pieces = exact_parts(walkable, r)
            pieces.sort(key=lambda g: -g.area)
        points = tuple((round(float(g.representative_point().x), 1),
                        round(float(g.representative_point().y), 1)) for g in pieces)
        return BodyReport(r, tuple(sorted(set(narrow))), tuple(g.area for g in pieces), points)


def check_body(level: Level, radius: float, source: str | None = None) -> BodyReport:
    """The level check every command shares (``validate``, ``sim``, ``run``, ``play``, the
    world): a body of ``radius`` must reach the whole walkable area, else a one-line
    :class:`~navmesh.errors.LevelError`. Returns the report (its narrow spots are warnings)."""
    from navmesh.errors import LevelError

    report = clearance_for(level, radius).report()
    if not report.connected:
        where = ", ".join(f"({x:.1f}, {y:.1f})" for x, y in report.piece_points[:4])
        src = source or (level.path.name if level.path is not None else level.name)
        raise LevelError(src, "walkable area",
                         f"an agent of radius {radius:g} cannot reach the whole level: it is "
                         f"in {len(report.pieces)} pieces for its body (near {where})")
    return report


@dataclass(frozen=True)
class _Key:
    """A level's content identity and a radius; carries (but is not keyed on) the level."""

    digest: str
    radius: float
    level: Level = field(compare=False, repr=False)


@lru_cache(maxsize=32)
def _cached(key: _Key) -> Clearance:
    return Clearance(key.level, key.radius)


def clearance_for(level: Level, radius: float) -> Clearance:
    """The :class:`Clearance` of a level and radius, cached per process on the level's
    content (``Level.digest``); levels built in memory are not cached."""
    if level.digest is not None:
        return _cached(_Key(level.digest, float(radius), level))
    return Clearance(level, radius)
