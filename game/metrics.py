"""The metric registry: every trial metric declared once (SPEC §7, §9).

A :class:`Metric` says what a metric is called, its unit, the scenario(s) Table 3 reports it
for, how it aggregates, its titles in tables and figures, its SQL column type and how the
world computes it from its :class:`Counters`. :meth:`game.world.World.metrics`, the results
store's columns, Table 3, the aggregate figure and the report's README all read
:func:`registered_metrics`, so a new metric is one :func:`register_metric` call (from any
module, no core file edited):

>>> extra = Metric("visited_nodes", lambda world: int(world.m.covered.sum()), kind="int",
...                column="VisitedNodes", definition="nodes any guard entered")
>>> _ = register_metric(extra)
>>> [m.name for m in registered_metrics()][-2:]
['coverage_seen_per_guard', 'visited_nodes']
>>> unregister_metric("visited_nodes")
>>> extra.sql_type, extra.table_columns()[0].name
('INTEGER', 'VisitedNodes')
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:
    from navmesh.graph import NodeGraph

    from .large.distance_worker import DistanceWorker
    from .guard_sight import ViewCover

__all__ = ["AGGREGATES", "BACKTRACK_RULES", "COVERAGE_RULES", "Counters", "DISTANCE_RULES",
           "Measured", "PARTITION_COVERAGE_RULES", "coverage_rule", "node_areas", "Metric", "RECENT_ENTRIES", "TableColumn", "register_metric", "registered_metrics",
           "metric_names", "unregister_metric", "world_metrics"]

#: how a metric's per-trial values become one Table 3 cell: ``mean`` of the values, or
#: ``rate`` = the share of trials where it is true (a mean of 1/0, on a fraction axis)
AGGREGATES = ("mean", "rate")
_SQL_TYPES = {"bool": "INTEGER", "int": "INTEGER", "float": "REAL"}

#: ``metrics.backtracks = "entries"``: the paper's "revisiting recent locations (e.g.
#: within the last N = 5 steps)" (guard-ai-composite-potential-fields.tex, line 328)
RECENT_ENTRIES = 5
#: the values of the ``[metrics]`` keys (SPEC §11), today's definition first (the default)
COVERAGE_RULES = ("visited", "seen", "per_guard", "area", "seen_area", "seen_per_guard")
#: ``metrics.partition_coverage`` (SPEC §12): the partition's own coverage reading, or
#: ``same`` (the default): the one ``metrics.coverage`` names for both abstractions
PARTITION_COVERAGE_RULES = ("same", *COVERAGE_RULES)
BACKTRACK_RULES = ("targets", "entries")
DISTANCE_RULES = ("path", "euclidean")


@dataclass
class Counters:
    """What the world counts during a trial; the metrics are computed from these."""

    captures: int = 0
    capture_time: float | None = None
    first_detect_time: float | None = None
    backtracks: int = 0
    dist_sum: float = 0.0
    dist_samples: int = 0
    #: the other definitions (SPEC §11 ``metrics.*``), counted in every trial: guard entries
    #: into one of that guard's last :data:`RECENT_ENTRIES` entered nodes; straight-line
    #: player-to-nearest-guard distances; per guard, the nodes its centre entered
    entry_backtracks: int = 0
    euclid_sum: float = 0.0
    euclid_samples: int = 0
    guard_covered: list[np.ndarray] = field(default_factory=list)
    recent_entries: list[deque[int]] = field(default_factory=list)
    #: the nodes inside a guard's view at some AI tick (set by the world)
    view_cover: ViewCover | None = None
    #: per guard, the nodes inside that guard's view at some AI tick (made from
    #: ``view_cover`` at the first tick)
    guard_view_covers: list[ViewCover] = field(default_factory=list)
    #: per node: ever entered by a guard; guard entries; HP the player lost there
    covered: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    visits: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    attacks: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.float64))

    #: the nodes of the last distance sample and their distance (nodes change a few times a
    #: second, steps 20 times, so the lookup is cached)
    _dist_key: tuple[int, ...] = ()
    _dist_now: float | None = None
    #: set (the game on a large level): the searches run there, and the samples wait in
    #: ``_dist_runs`` as [search, key, steps] until :meth:`settle` sums them
    distance_worker: DistanceWorker | None = None
    _dist_runs: list[list[Any]] = field(default_factory=list)

    def sample_distance(self, graph: Any, player_node: int, guard_nodes: list[int]) -> None:
        """One physics step's shortest-path distance from the player to the nearest guard."""
        key = (player_node, *guard_nodes)
        if self.distance_worker is not None:
            if not guard_nodes:
                self._dist_key = key
                return
            if key != self._dist_key or not self._dist_runs:
                self._dist_key = key
                search = self.distance_worker.submit(tuple(guard_nodes), player_node)
                self._dist_runs.append([search, key, 0])
            self._dist_runs[-1][2] += 1
            self.dist_samples += 1
            return
        if key != self._dist_key:
            self._dist_key = key
            self._dist_now = (graph.nearest_dist_to(guard_nodes, player_node)
                              if guard_nodes else None)
        if self._dist_now is not None:
            self.dist_sum += self._dist_now
            self.dist_samples += 1

    def cached_distance(self, player_node: int, guard_nodes: list[int]) -> float | None:
        """The last sample's ``graph.nearest_dist_to(guard_nodes, player_node)`` when it was
        taken for exactly these nodes (no worker), else None: a reader of the same distance
        need not search again."""
        if self.distance_worker is None and self._dist_key == (player_node, *guard_nodes):
            return self._dist_now
        return None

    def distances_ready(self) -> bool:
        """Whether :meth:`settle` would not wait: every search handed to the worker is done."""
        return self.distances_pending() == 0

    def distances_pending(self) -> int:
        """How many of the worker's searches are not done yet."""
        return sum(1 for run in self._dist_runs if not run[0].done())

    def settle(self) -> None:
        """Add the worker's distances to ``dist_sum`` — one addition per step, in step
        order, as :meth:`sample_distance` adds them without a worker (the same bits)."""
        worker = self.distance_worker
        if worker is None or not self._dist_runs:
            return
        runs, self._dist_runs = self._dist_runs, []
        for search, key, steps in runs:
            value = worker.value(search, tuple(key[1:]), key[0])
            for _ in range(steps):
                self.dist_sum += value
        # the next sample starts a new run even on the same key (its search is gone)
        self._dist_key = ()

    def mean_distance(self) -> float | None:
        """The mean of the distance samples (None: no guard was ever in play)."""
        self.settle()
        return self.dist_sum / self.dist_samples if self.dist_samples else None

    def observe_view(self, guards: Any) -> None:
        """At an AI tick: the nodes the guards see now count for ``coverage_seen``."""
        if self.view_cover is not None:
            self.view_cover.observe(guards)
            guards = list(guards)
            covers = self.guard_view_covers
            while len(covers) < len(guards):
                covers.append(self.view_cover.fresh())
            for cover, guard in zip(covers, guards):
                cover.observe((guard,))

    def count_capture(self, t: float) -> None:
        """The player lost all HP at time ``t``."""
        self.captures += 1
        if self.capture_time is None:
            self.capture_time = t

    def count_visit(self, node: int, guard: int = 0) -> None:
        """Guard number ``guard``'s centre entered ``node`` (a backtrack by entries when
        ``node`` is among the last :data:`RECENT_ENTRIES` nodes it entered)."""
        self.visits[node] += 1
        self.covered[node] = True
        while len(self.guard_covered) <= guard:
            self.guard_covered.append(np.zeros(len(self.covered), dtype=bool))
            self.recent_entries.append(deque(maxlen=RECENT_ENTRIES))
        self.guard_covered[guard][node] = True
        recent = self.recent_entries[guard]
        if node in recent:
            self.entry_backtracks += 1
        recent.append(node)

    def sample_euclidean(self, player: tuple[float, float],
                         guards: list[tuple[float, float]]) -> None:
        """One physics step's straight-line distance from the player to the nearest guard."""
        if guards:
            px, py = player
            self.euclid_sum += min(math.hypot(x - px, y - py) for x, y in guards)
            self.euclid_samples += 1

    def mean_euclidean(self) -> float | None:
        """The mean of the straight-line samples (None: no guard was ever in play)."""
        return self.euclid_sum / self.euclid_samples if self.euclid_samples else None

    def per_guard_coverage(self) -> float:
        """The sum over guards of the share of nodes each one's centre entered (up to the
        number of guards)."""
        n = len(self.covered)
        return sum(int(c.sum()) for c in self.guard_covered) / n if n else 0.0

    def seen_per_guard_coverage(self) -> float | None:
        """The sum over guards of the share of nodes inside that guard's view at some AI tick
        (up to the number of guards; None: not tracked)."""
        if self.view_cover is None:
            return None
        return float(sum(cover.share() for cover in self.guard_view_covers))

    def seen_coverage(self) -> float | None:
        """The share of nodes inside some guard's view at an AI tick (None: not tracked)."""
        return None if self.view_cover is None else self.view_cover.share()

    def count_arrival(self, history: deque[int], target: int) -> None:
        """A guard reached its decided ``target``: a backtrack if it is among its last
        nodes (``history``, updated here); staying put is not a move."""
        if target == history[-1]:
            return
        if target in history:
            self.backtracks += 1
        history.append(target)

    @classmethod
    def for_nodes(cls, n: int) -> Counters:
        """Fresh counters of a graph with ``n`` nodes."""
        return cls(covered=np.zeros(n, dtype=bool), visits=np.zeros(n, dtype=np.int64),
                   attacks=np.zeros(n, dtype=np.float64))


@dataclass(frozen=True)
class TableColumn:
    """One Table 3 column: a metric over the trials of one scenario."""

    name: str       # CSV-safe column name
    title: str      # column title in Markdown and figures
    scenario: str   # trials it is computed from
    metric: Metric

    @property
    def heading(self) -> str:
        """The Markdown column title (with the unit where the metric asks for it)."""
        return self.title + (f" ({self.metric.unit})" if self.metric.unit_in_title else "")


class Sections(Protocol):
    """Config values read a section at a time (a :class:`game.config.Config` is one)."""

    def section(self, name: str) -> dict[str, Any]: ...


class Measured(Protocol):
    """What a metric reads of a trial: the world's :class:`Counters` (``m``), its node graph
    and its config (the ``[metrics]`` definitions). A :class:`game.world.World` is one; this
    module never imports the world, which reads it.
    """

    @property
    def m(self) -> Counters: ...

    @property
    def graph(self) -> NodeGraph: ...

    @property
    def config(self) -> Sections: ...


@dataclass(frozen=True)
class Metric:
    """One trial metric, declared once.

    ``compute(world)`` reads the world's counters (``world.m``; :class:`Measured` says what a
    metric may read) at the end of a trial and
    returns a JSON value (``None``: it did not happen). ``column``/``title`` name its Table 3
    column (``column=None``: stored and in ``trials.csv`` but not in Table 3). ``censor``: a
    missing value counts as the trial's full duration in Table 3 (times of events).
    """

    name: str
    compute: Callable[[Measured], Any]
    kind: str = "float"                  # bool | int | float
    unit: str = ""                       # unit of the Table 3 value ("" = a count)
    scenarios: tuple[str, ...] = ("fixed",)
    aggregate: str = "mean"
    column: str | None = None
    title: str = ""
    censor: bool = False
    unit_in_title: bool = False
    definition: str = ""                 # the README's one-line definition

    def __post_init__(self) -> None:
        if self.kind not in _SQL_TYPES:
            raise ValueError(f"metric {self.name}: kind must be bool, int or float, got {self.kind!r}")
        if self.aggregate not in AGGREGATES:
            raise ValueError(f"metric {self.name}: aggregate must be one of {', '.join(AGGREGATES)}")
        if not self.name.isidentifier():
            raise ValueError(f"metric {self.name!r}: the name must be an identifier (SQL column)")

    @property
    def sql_type(self) -> str:
        """The SQLite column type of the results store."""
        return _SQL_TYPES[self.kind]

    @property
    def axis_label(self) -> str:
        """The figure's y-axis label."""
        return self.unit or ("fraction" if self.aggregate == "rate" else "count")

    def table_columns(self) -> tuple[TableColumn, ...]:
        """Its Table 3 columns, one per scenario (none without ``column``)."""
        if self.column is None:
            return ()
        title = self.title or self.column
        if len(self.scenarios) == 1:
            return (TableColumn(self.column, title, self.scenarios[0], self),)
        return tuple(TableColumn(f"{self.column}{s.title()}", f"{title} ({s})", s, self)
                     for s in self.scenarios)


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def _visited(w: Measured) -> float:
    return float(w.m.covered.mean()) if w.graph.n else 0.0


def node_areas(graph: NodeGraph) -> np.ndarray:
    """(n,) the walkable area of each node: a partition's triangle areas, a grid's cell
    area."""
    if graph.mesh is not None:
        return np.asarray(graph.mesh.areas, dtype=np.float64)
    return np.full(graph.n, float(graph.cell_size) ** 2)


def _area_share(graph: NodeGraph, nodes: np.ndarray) -> float:
    """The share of the walkable area in the nodes where ``nodes`` (bool, (n,)) is true."""
    areas = node_areas(graph)
    total = float(areas.sum())
    return float(areas[nodes].sum()) / total if total > 0 else 0.0


def _seen_area(w: Measured) -> float | None:
    cover = w.m.view_cover
    return None if cover is None else _area_share(w.graph, cover.seen)


#: every definition of the keyed metrics (SPEC §11), by the value of its ``metrics.*`` key
_COVERAGE: dict[str, Callable[[Measured], float | None]] = {
    "visited": _visited,
    "seen": lambda w: w.m.seen_coverage(),
    "per_guard": lambda w: w.m.per_guard_coverage(),
    "area": lambda w: _area_share(w.graph, w.m.covered),
    "seen_area": _seen_area,
    "seen_per_guard": lambda w: w.m.seen_per_guard_coverage(),
}
_BACKTRACKS: dict[str, Callable[[Measured], int]] = {
    "targets": lambda w: w.m.backtracks,
    "entries": lambda w: w.m.entry_backtracks,
}
_DISTANCE: dict[str, Callable[[Measured], float | None]] = {
    "path": lambda w: w.m.mean_distance(),
    "euclidean": lambda w: w.m.mean_euclidean(),
}


def _keyed(table: dict[str, Callable[[Measured], Any]], key: str) -> Callable[[Measured], Any]:
    """The metric as the world's ``metrics.<key>`` defines it (today's without the key)."""
    first = next(iter(table))
    return lambda w: table[w.config.section("metrics").get(key, first)](w)


def coverage_rule(rules: Mapping[str, Any], abstraction: str) -> str:
    """The coverage reading of a trial on ``abstraction`` under the ``[metrics]`` keys
    ``rules``: ``partition_coverage`` on the partition unless it is ``same``, else
    ``coverage``.

    >>> coverage_rule({"coverage": "seen", "partition_coverage": "area"}, "partition")
    'area'
    >>> coverage_rule({"coverage": "seen", "partition_coverage": "area"}, "grid")
    'seen'
    """
    own = str(rules.get("partition_coverage", "same"))
    if abstraction == "partition" and own != "same":
        return own
    return str(rules.get("coverage", COVERAGE_RULES[0]))


def _coverage(w: Measured) -> float | None:
    return _COVERAGE[coverage_rule(w.config.section("metrics"), w.graph.kind)](w)


_CORE: tuple[Metric, ...] = (
    Metric("captured", lambda w: w.m.captures > 0, kind="bool", scenarios=("capture",),
           aggregate="rate", column="CaptureRate", unit="fraction",
           definition="fraction of trials in which the player lost all HP"),
    Metric("capture_time", lambda w: _round(w.m.capture_time), scenarios=("capture",),
           column="CaptureTime", unit="s", censor=True, unit_in_title=True,
           definition="time of the capture (s); **an uncaptured trial counts as its full "
           "duration (60 s)**, which is what the paper's numbers imply (RandomWalk: 58.18 s at "
           "rate 0.04)"),
    Metric("captures", lambda w: w.m.captures, kind="int", column="CapturesInTime",
           definition="captures in 60 s (the player respawns after each)"),
    Metric("coverage", _coverage,
           column="CoverageRate", unit="fraction",
           definition="by `metrics.coverage` (default `visited`: the fraction of walkable "
           "nodes (cells or triangles) any guard entered, in [0, 1]; on the partition "
           "`metrics.partition_coverage` when it is not `same`); see coverage_*"),
    Metric("avg_guard_player_dist", _keyed(_DISTANCE, "distance"),
           column="AvgGuardPlayerDist", title="AvgGuard–PlayerDist", unit="world units",
           definition="by `metrics.distance` (default `path`: the mean over physics steps of "
           "the shortest-path distance (world units) from the player's node to the closest "
           "guard's node); see dist_*"),
    Metric("first_detect_time", lambda w: _round(w.m.first_detect_time),
           column="FirstDetectTime", unit="s", censor=True, unit_in_title=True,
           definition="time of the first sighting (s); **a trial without one counts as its "
           "full duration** (the paper's RandomWalk 46 ± 23 s implies the same)"),
    Metric("backtracks", _keyed(_BACKTRACKS, "backtracks"), kind="int",
           column="BacktrackCount",
           definition="by `metrics.backtracks` (default `targets`: guard moves to a decided "
           "node among that guard's last 5 nodes); see backtracks_*"),
    # Every definition at once, whatever the keys say (stored and in trials.csv, not in
    # Table 3), so one store answers each of them.
    Metric("coverage_visited", _visited, unit="fraction",
           definition="fraction of walkable nodes any guard's centre entered"),
    Metric("coverage_seen", _COVERAGE["seen"], unit="fraction",
           definition="fraction of walkable nodes inside some active guard's view (range "
           "scaled by the node's zone, cone, clear line) at some AI tick"),
    Metric("coverage_per_guard", _COVERAGE["per_guard"], unit="fraction",
           definition="sum over guards of the fraction of nodes each guard's centre entered "
           "(up to the number of guards)"),
    Metric("backtracks_targets", _BACKTRACKS["targets"], kind="int",
           definition="guard arrivals at a decided target among that guard's last 5 targets"),
    Metric("backtracks_entries", _BACKTRACKS["entries"], kind="int",
           definition="guard entries into a node among the last 5 nodes that guard entered"),
    Metric("dist_path", _DISTANCE["path"], unit="world units",
           definition="mean over physics steps of the shortest-path distance from the "
           "player's node to the closest guard's node"),
    Metric("dist_euclidean", _DISTANCE["euclidean"], unit="world units",
           definition="mean over physics steps of the straight-line distance from the "
           "player to the closest active guard"),
    # SPEC §12's coverage readings (after the older columns, so the stores' order holds)
    Metric("coverage_area", _COVERAGE["area"], unit="fraction",
           definition="share of the walkable area in the nodes any guard's centre entered "
           "(a partition's triangles by their area; on the grid equal to coverage_visited)"),
    Metric("coverage_seen_area", _COVERAGE["seen_area"], unit="fraction",
           definition="share of the walkable area in the nodes inside some active guard's "
           "view at some AI tick"),
    Metric("coverage_seen_per_guard", _COVERAGE["seen_per_guard"], unit="fraction",
           definition="sum over guards of the fraction of nodes inside that guard's view at "
           "some AI tick (up to the number of guards)"),
)

_REGISTRY: dict[str, Metric] = {m.name: m for m in _CORE}


def register_metric(metric: Metric, *, replace: bool = False) -> Metric:
    """Add ``metric`` to every world, store and report of this process; returns it.

    Registering the same name twice is an error unless ``replace`` (e.g. a reloaded module).
    """
    if metric.name in _REGISTRY and not replace:
        raise ValueError(f"metric {metric.name!r} is already registered")
    _REGISTRY[metric.name] = metric
    return metric


def unregister_metric(name: str) -> None:
    """Remove a metric registered with :func:`register_metric` (the core ones stay)."""
    if any(m.name == name for m in _CORE):
        raise ValueError(f"metric {name!r} is a core metric (SPEC §7) and cannot be removed")
    _REGISTRY.pop(name, None)


def registered_metrics() -> tuple[Metric, ...]:
    """Every metric in registration order (the SPEC §7 ones first, then every definition
    of the SPEC §11 keyed ones)."""
    return tuple(_REGISTRY.values())


def metric_names() -> tuple[str, ...]:
    """Names of :func:`registered_metrics`."""
    return tuple(_REGISTRY)


def world_metrics(world: Measured) -> dict[str, Any]:
    """Every registered metric of ``world`` as the SPEC §9 ``metrics`` object."""
    return {m.name: m.compute(world) for m in _REGISTRY.values()}
