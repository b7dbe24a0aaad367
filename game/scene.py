"""What there is to draw: a renderer-independent picture of a world (SPEC §1, STYLE).

The simulation core never imports pygame. This module turns a :class:`~game.world.World`
(or a replayed trace) into plain data — numpy arrays, tuples and strings — that any
front end can draw: the pygame adapter in :mod:`game.front.render` is one, a PNG exporter
with matplotlib could be another.

* :class:`StaticScene` — what never moves: floor rings, walls, zones (clipped to the
  walkable area), static decoys, the grid cells or the navmesh triangles, node positions.
* :class:`Scene` — one frame: guards (with their vision cones clipped by walls, their
  plans), the player, HP, detection state and an optional :class:`FieldLayer`.
* :func:`~game.ray_cast.vision_cone` — the exact visible part of a guard's view sector: rays cast
  against the wall segments with numpy, including rays grazing every wall corner, so the
  polygon ends exactly where the walls block the guard's line of sight (the same segment
  test :meth:`World.sees` does with pymunk).

>>> from navmesh.level import parse_level
>>> from navmesh.graph import build_graph
>>> level = parse_level({"format": "stealth-level/1", "name": "box",
...                      "grid": ["#####", "#...#", "#####"], "guards": [[1.5, 1.5]]})
>>> builder = SceneBuilder(level, build_graph(level, "grid"), view_range=8.0, fov_deg=90.0)
>>> cone = builder.cone((1.5, 1.5), 0.0, 8.0)
>>> float(cone[:, 0].max())  # the ray straight ahead stops at the wall x = 4
4.0
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from navmesh.graph import NodeGraph
from navmesh.level import Level

from .large.background import lowest_priority
from .large.policy import bucket_walls
from .overlays import (OVERLAY_ALIASES, OVERLAYS, Overlay, overlay_key, overlay_label,
                       register_overlay, unregister_overlay)
from .ray_cast import WallBuckets, vision_cone

if TYPE_CHECKING:
    from .world import World

Point = tuple[float, float]

#: Rays per radian of field of view (about one every 1.6°), before the corner rays.
RAYS_PER_RADIAN = 36.0


# ---------------------------------------------------------------------------- static part


@dataclass(frozen=True, eq=False)
class StaticScene:
    """The parts of a level that never move, in world units (x right, y down)."""

    name: str
    #: world extent drawn: x in [0, width], y in [0, height]
    width: float
    height: float
    cell_size: float
    #: walkable area as rings: ``floor[0]`` the outline, the rest holes (obstacles)
    floor: tuple[np.ndarray, ...]
    #: wall segments ``(m, 2, 2)``
    walls: np.ndarray
    #: per zone kind, polygons clipped to the walkable area, each as (exterior, *holes) rings
    zones: Mapping[str, tuple[tuple[np.ndarray, ...], ...]]
    #: static decoy points ``(k, 2)``
    decoys: np.ndarray
    #: ``"grid"`` or ``"partition"``
    kind: str
    #: node positions ``(n, 2)``
    nodes: np.ndarray
    #: grid: walkable mask ``(rows, cols)``
    occupancy: np.ndarray
    #: grid: node index per cell ``(rows, cols)``, -1 blocked; None on a partition
    cell_node: np.ndarray | None
    #: partition: triangle corners ``(T, 3, 2)`` (node t is triangle t); None on a grid
    triangles: np.ndarray | None
    #: exit areas' outer rings (objectives, game.objectives)
    exits: tuple[np.ndarray, ...] = ()
    #: collectible points ``(k, 2)``
    collectibles: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    @classmethod
    def from_level(cls, level: Level, graph: NodeGraph) -> StaticScene:
        """Collect what is drawn of ``level`` in the abstraction of ``graph``."""
        _, _, maxx, maxy = level.walkable.bounds
        width = max(maxx, level.cols * level.cell_size)
        height = max(maxy, level.rows * level.cell_size)
        floor = _rings(level.walkable)[0]
        zones = {}
        for kind, polygons in level.zones.items():
            clipped = [level.walkable.intersection(p) for p in polygons]
            zones[kind] = tuple(r for g in clipped for r in _rings(g))
        triangles = None
        if graph.mesh is not None:
            triangles = np.asarray(graph.mesh.vertices)[np.asarray(graph.mesh.triangles)]
        decoys = np.asarray(level.decoys, dtype=np.float64).reshape(-1, 2)
        return cls(
            name=level.name, width=float(width), height=float(height),
            cell_size=float(level.cell_size), floor=floor,
            walls=np.asarray(level.walls, dtype=np.float64), zones=zones, decoys=decoys,
            kind=graph.kind, nodes=np.asarray(graph.positions, dtype=np.float64),
            occupancy=np.asarray(level.occupancy, dtype=bool),
            cell_node=None if graph.cell_node is None else np.asarray(graph.cell_node),
            triangles=triangles,
            exits=tuple(np.asarray(a.exterior.coords, dtype=np.float64)[:-1, :2] for a in level.exits),
            collectibles=np.asarray(level.collectibles, dtype=np.float64).reshape(-1, 2),
        )


def _rings(geometry: BaseGeometry) -> list[tuple[np.ndarray, ...]]:
    """Every polygon of ``geometry`` as (exterior, *holes) coordinate arrays (no closing point)."""
    polygons = [g for g in shapely.get_parts(geometry) if isinstance(g, Polygon) and not g.is_empty]
    out = []
    for polygon in polygons:
        rings = [np.asarray(polygon.exterior.coords, dtype=np.float64)[:-1, :2]]
        rings += [np.asarray(r.coords, dtype=np.float64)[:-1, :2] for r in polygon.interiors]
        out.append(tuple(rings))
    return out


# ---------------------------------------------------------------------------- dynamic part


@dataclass(frozen=True, eq=False)
class GuardDrawing:
    """One guard as drawn: body, cone, behaviour label and (optionally) its plan."""

    pos: Point
    heading: float
    active: bool
    sees_player: bool
    state: str
    #: visible part of the view sector, ``(k, 2)``, apex first; empty when inactive
    cone: np.ndarray
    #: position of the target node (None unless plans are requested)
    target: Point | None = None
    #: remaining waypoints ``(k, 2)`` (empty unless plans are requested)
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    #: candidate node positions of the last decision ``(c, 2)`` (PF only, with plans)
    candidates: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    #: position of the chosen candidate (PF only, with plans)
    chosen: Point | None = None
    #: awareness as a fraction of the detection threshold (graded perception on), else None
    awareness: float | None = None
    #: coordinated role ("" when roles are off or the guard has none)
    role: str = ""


@dataclass(frozen=True)
class PlayerDrawing:
    """The player as drawn."""

    pos: Point
    heading: float
    hp: float
    hp_max: float
    sprinting: bool = False
    concealed: bool = False


@dataclass(frozen=True, eq=False)
class FieldLayer:
    """A per-node field ready for a colour map.

    ``norm = values / max|values|`` lies in [-1, 1] (0 where the field is 0): negative
    values attract the guards (they move to the least K), positive ones repel them.
    """

    key: str
    label: str
    values: np.ndarray
    vmin: float
    vmax: float
    norm: np.ndarray

    @classmethod
    def from_values(cls, key: str, values: np.ndarray, label: str | None = None) -> FieldLayer:
        """Normalise ``values`` symmetrically around 0."""
        values = np.asarray(values, dtype=np.float64)
        vmin = float(values.min()) if len(values) else 0.0
        vmax = float(values.max()) if len(values) else 0.0
        scale = max(abs(vmin), abs(vmax))
        norm = values / scale if scale > 1e-12 else np.zeros_like(values)
        return cls(key, label or overlay_label(key), values, vmin, vmax, norm)


@dataclass(frozen=True, eq=False)
class Scene:
    """One frame of the game: everything a front end needs to draw it."""

    static: StaticScene
    t: float
    duration: float
    guards: tuple[GuardDrawing, ...]
    player: PlayerDrawing
    seen_by: tuple[int, ...] = ()
    attackers: int = 0
    #: ``"playing"``, ``"captured"`` or ``"survived"``
    status: str = "playing"
    mode: str = ""
    abstraction: str = ""
    #: the requested overlay key (``"none"`` for none)
    overlay: str = "none"
    #: the field of the requested overlay; None when off or when the mode has no fields
    layer: FieldLayer | None = None
    #: why ``layer`` is None although an overlay is requested (e.g. mode without fields)
    field_note: str = ""
    #: guard reach now (shorter while the player stands in concealment)
    reach: float = 0.0
    attack_range: float = 0.0
    agent_radius: float = 0.3
    #: dynamic decoys or other stimulus markers ``(k, 2)`` (thrown decoys, corpses, ...)
    markers: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    rain: bool | None = None
    events: tuple[str, ...] = ()
    captures: int = 0
    #: the guard team's alert phase ("" when alert phases are off)
    phase: str = ""

    @property
    def detected(self) -> bool:
        """Whether any guard sees the player in this frame."""
        return bool(self.seen_by)


# ---------------------------------------------------------------------------- building


class SceneBuilder:
    """Builds :class:`Scene` frames for one level and abstraction (static part cached).

    Field layers are cached by the identity of the source arrays (the AI hands out
    immutable snapshots that change once per AI tick), so a renderer can cache its
    colour-mapped image by the identity of the layer. With ``background_fields`` a new
    layer is computed on a worker thread from the AI's :meth:`~ai.view.GuardAI.fields_later`
    (numpy and scipy release the GIL) while frames keep the previous one: on a level of
    10^6 cells the whole-level P, K and normalisation of one tick take tens of ms, which
    the game spends beside the frames rather than in one of them. Only what is drawn
    lags, by the few frames the worker takes; the simulation does not wait for it.
    """

    def __init__(
        self, level: Level, graph: NodeGraph, *, view_range: float, fov_deg: float,
        rays_per_radian: float = RAYS_PER_RADIAN, background_fields: bool = False,
    ) -> None:
        self.level, self.graph = level, graph
        self.static = StaticScene.from_level(level, graph)
        self.view_range = float(view_range)
        self.half_fov = math.radians(float(fov_deg)) / 2.0
        self.rays = max(3, math.ceil(2.0 * self.half_fov * rays_per_radian) + 1)
        walls = self.static.walls
        self._a = walls[:, 0].copy()
        self._d = walls[:, 1] - walls[:, 0]
        corners = np.unique(walls.reshape(-1, 2), axis=0)
        self._corners = corners
        self._buckets = WallBuckets(walls, corners) if bucket_walls(len(walls)) else None
        self._layers: dict[str, tuple[tuple[int, ...], tuple[Any, ...], FieldLayer]] = {}
        self._background = (ThreadPoolExecutor(1, "field-layer", initializer=lowest_priority)
                            if background_fields else None)
        #: background: per overlay, the identity and (layer, note) last shown
        self._shown: dict[str, tuple[Hashable, tuple[FieldLayer | None, str]]] = {}
        self._pending: tuple[str, Hashable, Future[tuple[FieldLayer | None, str]]] | None = None

    # ------------------------------------------------------------------ cones
    def cone(self, pos: Point, heading: float, reach: float) -> np.ndarray:
        """The visible part of the view sector at ``pos`` facing ``heading``, ``(k, 2)``.

        The first point is the apex; the rest run counter-clockwise in angle (y down: from
        ``heading - fov/2`` to ``heading + fov/2``).
        """
        if self._buckets is not None:  # a large level: only the walls near the guard
            walls, corners = self._buckets.near(pos, reach)
            return vision_cone(self._a[walls], self._d[walls], self._corners[corners], pos,
                               heading, self.half_fov, reach, self.rays)
        return vision_cone(self._a, self._d, self._corners, pos, heading, self.half_fov,
                           reach, self.rays)

    # ------------------------------------------------------------------ fields
    def field_layer(self, key: str, fields: Mapping[str, np.ndarray]) -> FieldLayer | None:
        """The layer of overlay ``key`` from a guard AI's ``fields()`` dict (None if absent)."""
        overlay = OVERLAYS.get(key)
        if overlay is None:
            return None
        sources = tuple(fields.get(name) for name in overlay.fields)
        if sources[0] is None:
            return None
        ids = tuple(id(s) for s in sources)
        cached = self._layers.get(key)
        if cached is not None and cached[0] == ids:
            return cached[2]
        values, label = overlay.layer_values(sources)
        layer = FieldLayer.from_values(key, values, label)
        self._layers[key] = (ids, sources, layer)  # keep the sources alive: ids stay unique
        return layer

    def _layer_and_note(self, overlay: str, fields: Mapping[str, np.ndarray],
                        mode: str) -> tuple[FieldLayer | None, str]:
        """The layer of ``overlay`` from ``fields``, or None and the reason why not."""
        if not fields:
            return None, f"no fields in mode {mode}"
        layer = self.field_layer(overlay, fields)
        return layer, "" if layer is not None else f"field {overlay} not available"

    def _layer_later(self, overlay: str, guard_ai: Any) -> tuple[FieldLayer | None, str]:
        """The newest finished layer of ``overlay``; a newer state is handed to the worker
        (one job at a time: a state that changes meanwhile is taken when it is free)."""
        assert self._background is not None
        identity, compute = guard_ai.fields_later()
        pending = self._pending
        if pending is not None and pending[2].done():
            self._shown[pending[0]] = (pending[1], pending[2].result())
            self._pending = pending = None
        shown = self._shown.get(overlay)
        if (shown is None or shown[0] != identity) and pending is None:
            mode = guard_ai.mode
            job = self._background.submit(lambda: self._layer_and_note(overlay, compute(), mode))
            self._pending = (overlay, identity, job)
        return shown[1] if shown is not None else (None, "")

    def settle(self) -> bool:
        """Wait for the layer being computed on the worker (if any); whether there was one."""
        pending, self._pending = self._pending, None
        if pending is None:
            return False
        self._shown[pending[0]] = (pending[1], pending[2].result())
        return True

    # ------------------------------------------------------------------ from a world
    def from_world(self, world: World, overlay: str = "none", plans: bool = False) -> Scene:
        """The frame of ``world`` now, with the ``overlay`` field and optionally the plans."""
        concealed = _concealed(world.zones, world.player.node)
        reach = world.view_range * float(world.view_scale_at[world.player.node])
        seen = set(world.seen_by)
        positions = self.graph.positions
        guard_ai = world.guard_ai
        team_top, team_guards = world.team.trace_fields(world)
        guards = []
        for i, g in enumerate(world.guards):
            cone = self.cone(g.pos, g.heading, reach) if g.active else np.zeros((0, 2))
            extra: dict[str, Any] = dict(team_guards[i])
            if plans and g.active:
                extra["target"] = (float(positions[g.target][0]), float(positions[g.target][1]))
                extra["path"] = np.asarray(list(g.waypoints), dtype=np.float64).reshape(-1, 2)
                record = guard_ai.explain(i)
                if record and record.get("candidates"):
                    nodes = [c["node"] for c in record["candidates"]]
                    extra["candidates"] = positions[nodes]
                    won = positions[int(record["winner"])]
                    extra["chosen"] = (float(won[0]), float(won[1]))
            guards.append(GuardDrawing(
                pos=g.pos, heading=g.heading, active=g.active, sees_player=i in seen,
                state=str(guard_ai.state_name(i)) if g.active else "down", cone=cone, **extra,
            ))
        field_layer, note = None, ""
        if overlay != "none" and self._background is not None:
            field_layer, note = self._layer_later(overlay, guard_ai)
        elif overlay != "none":
            field_layer, note = self._layer_and_note(overlay, guard_ai.fields(), guard_ai.mode)
        if world.done:
            status = "captured" if (world.end_on_capture and world.m.captures) else "survived"
        else:
            status = "playing"
        return Scene(
            static=self.static,
            t=world.t,
            duration=world.total_steps * world.dt,
            guards=tuple(guards),
            player=PlayerDrawing(
                pos=world.player.pos, heading=world.player.heading, hp=world.hp,
                hp_max=world.hp_max, sprinting=bool(world.sprinting), concealed=concealed,
            ),
            seen_by=tuple(world.seen_by),
            attackers=int(world.attackers),
            status=status,
            mode=guard_ai.mode,
            abstraction=world.graph.kind,
            overlay=overlay,
            layer=field_layer,
            field_note=note,
            reach=reach,
            attack_range=world.attack_range,
            agent_radius=world.radius,
            markers=np.asarray(world.stimulus_points(), dtype=np.float64).reshape(-1, 2),
            rain=world.raining,
            events=tuple(e.kind for e in world.tick_events),
            captures=world.m.captures,
            phase=str(team_top.get("phase", "")),
        )


def _concealed(zones: Mapping[str, np.ndarray], node: int) -> bool:
    mask = zones.get("concealment")
    return bool(mask is not None and 0 <= node < len(mask) and mask[node])


__all__ = [
    "OVERLAYS", "OVERLAY_ALIASES", "FieldLayer", "GuardDrawing", "Overlay", "PlayerDrawing",
    "Scene", "SceneBuilder", "StaticScene", "overlay_key", "overlay_label", "register_overlay",
    "unregister_overlay", "vision_cone",
]
