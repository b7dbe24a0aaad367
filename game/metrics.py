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
['backtracks', 'visited_nodes']
>>> unregister_metric("visited_nodes")
>>> extra.sql_type, extra.table_columns()[0].name
('INTEGER', 'VisitedNodes')
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .large.distance_worker import DistanceWorker
    from .world import World

__all__ = ["AGGREGATES", "Counters", "Metric", "TableColumn", "register_metric",
           "registered_metrics", "metric_names", "unregister_metric", "world_metrics"]

#: how a metric's per-trial values become one Table 3 cell: ``mean`` of the values, or
#: ``rate`` = the share of trials where it is true (a mean of 1/0, on a fraction axis)
AGGREGATES = ("mean", "rate")
_SQL_TYPES = {"bool": "INTEGER", "int": "INTEGER", "float": "REAL"}


@dataclass
class Counters:
    """What the world counts during a trial; the metrics are computed from these."""

    captures: int = 0
    capture_time: float | None = None
    first_detect_time: float | None = None
    backtracks: int = 0
    dist_sum: float = 0.0
    dist_samples: int = 0
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

    def count_capture(self, t: float) -> None:
        """The player lost all HP at time ``t``."""
        self.captures += 1
        if self.capture_time is None:
            self.capture_time = t

    def count_visit(self, node: int) -> None:
        """A guard's centre entered ``node``."""
        self.visits[node] += 1
        self.covered[node] = True

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


@dataclass(frozen=True)
class Metric:
    """One trial metric, declared once.

    ``compute(world)`` reads the world's counters (``world.m``) at the end of a trial and
    returns a JSON value (``None``: it did not happen). ``column``/``title`` name its Table 3
    column (``column=None``: stored and in ``trials.csv`` but not in Table 3). ``censor``: a
    missing value counts as the trial's full duration in Table 3 (times of events).
    """

    name: str
    compute: Callable[[World], Any]
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
    Metric("coverage", lambda w: float(w.m.covered.mean()) if w.graph.n else 0.0,
           column="CoverageRate", unit="fraction",
           definition="fraction of walkable nodes (cells or triangles) any guard entered, in "
           "[0, 1]"),
    Metric("avg_guard_player_dist",
           lambda w: w.m.mean_distance(),
           column="AvgGuardPlayerDist", title="AvgGuard–PlayerDist", unit="world units",
           definition="mean over physics steps of the shortest-path distance (world units) "
           "from the player's node to the closest guard's node"),
    Metric("first_detect_time", lambda w: _round(w.m.first_detect_time),
           column="FirstDetectTime", unit="s", censor=True, unit_in_title=True,
           definition="time of the first sighting (s); **a trial without one counts as its "
           "full duration** (the paper's RandomWalk 46 ± 23 s implies the same)"),
    Metric("backtracks", lambda w: w.m.backtracks, kind="int", column="BacktrackCount",
           definition="guard moves to a node among that guard's last 5 nodes"),
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
    """Every metric in registration order (the SPEC §7 ones first)."""
    return tuple(_REGISTRY.values())


def metric_names() -> tuple[str, ...]:
    """Names of :func:`registered_metrics`."""
    return tuple(_REGISTRY)


def world_metrics(world: World) -> dict[str, Any]:
    """Every registered metric of ``world`` as the SPEC §9 ``metrics`` object."""
    return {m.name: m.compute(world) for m in _REGISTRY.values()}
