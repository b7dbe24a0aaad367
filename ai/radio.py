"""Guard communication by radio (beyond the paper; docs/ai.md "Beyond the paper").

A guard that detects the player, or finds a corpse, sends a report; after ``delay``
seconds the report reaches every teammate that was within ``range`` (world units) of the
sender when it was sent, and enters the shared information field as a decaying layer at
the reported node, ``−level · falloff^hops`` (``level ← level · decay^dt``), like a noise;
a heard sighting report replaces the older ones, and a new detection by the team drops
them (the shared field's own sighting is fresher), so a report acts as the last known
position once the team has lost sight. A report nobody was in range to hear is lost. While a report is live the team's ``w_I``
is kept at least ``alert_weight`` (0: no floor).

*Missing teammate*: every active guard checks in each AI tick; a guard that stops (taken
down) is reported ``missing_time`` seconds after the first tick it failed to check in, is reported missing at its last node to every active
teammate (the team radio: no range).

One :class:`Radio` stimulus does all of it, so the guard AI never learns about radios.

>>> import numpy as np
>>> from navmesh.graph import NodeGraph
>>> from ai.stimuli import StimulusSet
>>> from ai.view import WorldView
>>> graph = NodeGraph.from_grid(np.ones((1, 9), bool), 1.0)
>>> stimuli = StimulusSet(graph)
>>> radio = stimuli.add(Radio(RadioParams(delay=2.0, range=3.0)))
>>> stimuli.tick(WorldView.at_nodes(graph, [0, 2], 8, t=1.0, seen_by=(0,)), 1.0)
>>> [r.node for r in radio.pending], radio.live
([8], [])
>>> stimuli.tick(WorldView.at_nodes(graph, [0, 2], 8, t=3.0), 1.0)
>>> [(r.kind, r.node, r.reporter) for r in radio.live]
[('sighting', 8, 0)]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .bounds import FRACTION, NON_NEGATIVE, UNIT
from .params import Params
from .stimuli import Corpse, FieldContext, Stimulus
from .view import WorldView


@dataclass(frozen=True)
class RadioParams(Params):
    """The ``[radio]`` config section (``enabled`` is the world's switch)."""

    #: world units between sender and hearer at sending time
    range: float = 12.0
    #: seconds from sending to hearing
    delay: float = 2.0
    #: the report's layer: −level · falloff^hops, level × decay per second
    amplitude: float = 4.0
    falloff: float = 0.8
    decay: float = 0.9
    #: a report is dropped when its level is below this
    threshold: float = 0.1
    #: a guard reports a sighting at most once per this many seconds
    cooldown: float = 5.0
    #: seconds of silence before a taken-down guard is reported missing
    missing_time: float = 10.0
    #: w_I floor while a report is live (0: none)
    alert_weight: float = 0.0

    bounds = {
        "range": NON_NEGATIVE, "delay": NON_NEGATIVE, "amplitude": NON_NEGATIVE,
        "falloff": UNIT, "decay": UNIT, "threshold": NON_NEGATIVE,
        "cooldown": NON_NEGATIVE, "missing_time": NON_NEGATIVE,
        "alert_weight": FRACTION,
    }


@dataclass
class Report:
    """One radio message: what, where, who sent it, when it is heard, by whom."""

    kind: str  # "sighting", "corpse" or "missing"
    node: int
    reporter: int
    sent: float
    due: float
    hearers: tuple[int, ...]
    level: float = 0.0

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "node": self.node, "reporter": self.reporter,
                "sent": round(self.sent, 6), "hearers": list(self.hearers),
                "level": round(self.level, 6)}


class Radio(Stimulus):
    """The team's radio: reports scheduled, delivered after the delay, decaying layers."""

    name = "radio"

    def __init__(self, params: RadioParams | None = None) -> None:
        self.params = params or RadioParams()
        self.pending: list[Report] = []
        self.live: list[Report] = []
        self._last_report: dict[int, float] = {}
        self._last_node: dict[int, int] = {}
        self._silent_since: dict[int, float] = {}
        self._missing_sent: set[int] = set()
        self._corpses_sent: set[int] = set()
        self.ctx: FieldContext | None = None

    def start(self, ctx: FieldContext) -> None:
        self.ctx = ctx

    # ------------------------------------------------------------------ sending
    def _hearers(self, view: WorldView, sender: int, radius: float | None) -> tuple[int, ...]:
        active = _active(view)
        out = []
        for j in range(view.n_guards):
            if j == sender or not active[j]:
                continue
            if radius is not None:
                gap = view.guard_positions[j] - view.guard_positions[sender]
                if float(np.hypot(gap[0], gap[1])) > radius + 1e-9:
                    continue
            out.append(j)
        return tuple(out)

    def send(self, view: WorldView, kind: str, node: int, reporter: int) -> Report:
        """Queue a report now; heard ``delay`` s later by the teammates in range now."""
        p, t = self.params, float(view.t)
        hearers = (self._hearers(view, reporter, p.range) if reporter >= 0
                   else tuple(j for j in range(view.n_guards) if _active(view)[j]))
        report = Report(kind, int(node), int(reporter), t, t + p.delay, hearers)
        self.pending.append(report)
        return report

    def on_tick(self, view: WorldView, dt: float) -> None:
        p, t = self.params, float(view.t)
        active = _active(view)
        # who saw the player: the guards that see it now, else (seen earlier this tick)
        # the active guard nearest to the sighting
        detected: tuple[int, ...] = ()
        if view.seen_by:
            detected, where = tuple(view.seen_by), int(view.player_node)
        elif view.sighting is not None:
            where = int(view.sighting)
            detected = (_nearest_active(view, where),)
        if detected:  # the team's own sighting is fresher than any heard position
            self.live = [r for r in self.live if r.kind != "sighting"]
        for i in detected:
            if i >= 0 and active[i] and t - self._last_report.get(i, -np.inf) >= p.cooldown - 1e-9:
                self._last_report[i] = t
                self.send(view, "sighting", where, i)
        for stimulus in self.ctx.active if self.ctx is not None else ():
            if isinstance(stimulus, Corpse) and stimulus.found and id(stimulus) not in self._corpses_sent:
                self._corpses_sent.add(id(stimulus))
                self.send(view, "corpse", stimulus.node, _nearest_active(view, stimulus.node))
        for j in range(view.n_guards):
            if active[j]:
                self._last_node[j] = int(view.guard_nodes[j])
                self._silent_since.pop(j, None)
                continue
            since = self._silent_since.setdefault(j, t)
            if j not in self._missing_sent and t - since >= p.missing_time - 1e-9:
                self._missing_sent.add(j)
                self.send(view, "missing", self._last_node.get(j, int(view.guard_nodes[j])), -1)
        self._deliver(t)

    def _deliver(self, t: float) -> None:
        due = [r for r in self.pending if r.due <= t + 1e-9]
        self.pending = [r for r in self.pending if r.due > t + 1e-9]
        for report in due:
            if report.hearers:
                report.level = self.params.amplitude
                if report.kind == "sighting":  # the latest position replaces older ones
                    self.live = [r for r in self.live if r.kind != "sighting"]
                self.live.append(report)

    # ------------------------------------------------------------------ the layer
    def decay(self, dt: float) -> None:
        for report in self.live:
            report.level *= self.params.decay ** dt
        self.live = [r for r in self.live if r.level >= self.params.threshold]

    def inject(self, ctx: FieldContext) -> np.ndarray | None:
        if not self.live:
            return None
        total = np.zeros(ctx.n)
        for report in self.live:
            total -= report.level * ctx.falloff(report.node, self.params.falloff)
        return total

    @property
    def information_weight_floor(self) -> float | None:  # type: ignore[override]
        return self.params.alert_weight if self.live and self.params.alert_weight > 0 else None

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": -1,
                "pending": [r.describe() for r in self.pending],
                "live": [r.describe() for r in self.live]}


def _active(view: WorldView) -> np.ndarray:
    if view.guard_active is None:
        return np.ones(view.n_guards, dtype=bool)
    return np.asarray(view.guard_active, dtype=bool)


def _nearest_active(view: WorldView, node: int) -> int:
    """The active guard nearest in hops to ``node`` (lowest index on ties; -1: none)."""
    active = np.flatnonzero(_active(view))
    if not len(active):
        return -1
    hops = np.atleast_1d(view.graph.hops_between(int(node), np.asarray(view.guard_nodes)[active]))
    return int(active[int(np.argmin(hops))])


__all__ = ["Radio", "RadioParams", "Report"]
