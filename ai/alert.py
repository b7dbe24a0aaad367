"""Alert phases of the guard team (beyond the paper; docs/ai.md "Beyond the paper").

One phase per team, derived once per AI tick from what the team knows: detections (a
guard sees the player: ``view.seen_by`` or ``view.sighting``), suspicions (``"suspicion"``
events of graded perception, :mod:`game.awareness`) and the time since each.

``unaware → suspicious → alert → search → caution``: *alert* while the last detection is
at most ``alert_time`` s old, *search* for ``search_time`` s after that, *suspicious* while
the last suspicion is at most ``suspicious_time`` s old (and no alert or search), then the
cool-down floor: *caution* once the team has ever been alert, *unaware* before that, so
caution never returns to unaware.

The phase acts only through the stimulus hooks: :class:`AlertPhases` is a
:class:`~ai.stimuli.Stimulus` whose ``information_weight_floor`` is the phase's floor on
``w_I`` (the adaptive weights of eq. 8 never go below it), and its :attr:`speed_scale`
is the factor the world puts on the guards' speed. Both are bounded (``[0, 1]`` and
``[0.5, 1.5]``).

>>> import numpy as np
>>> from navmesh.graph import NodeGraph
>>> from ai.view import WorldView
>>> graph = NodeGraph.from_grid(np.ones((1, 5), bool), 1.0)
>>> phases = AlertPhases(AlertParams())
>>> phases.on_tick(WorldView.at_nodes(graph, [0], 4, t=1.0, sighting=4), 1.0)
>>> phases.phase, phases.information_weight_floor, phases.speed_scale
('alert', 0.9, 1.25)
>>> phases.on_tick(WorldView.at_nodes(graph, [0], 4, t=5.0), 1.0)
>>> phases.phase
'search'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .bounds import FRACTION, NON_NEGATIVE, Range
from .params import Params
from .stimuli import Stimulus
from .view import Event, WorldView

#: the phases in escalation order
PHASES = ("unaware", "suspicious", "alert", "search", "caution")
_FLOOR = FRACTION
_SPEED = Range(0.5, 1.5)


@dataclass(frozen=True)
class AlertParams(Params):
    """The ``[alert]`` config section (``enabled`` is the world's switch, not a parameter)."""

    #: seconds after the last detection the team stays alert
    alert_time: float = 3.0
    #: then seconds of search before the cool-down
    search_time: float = 20.0
    #: seconds a suspicion keeps the team suspicious
    suspicious_time: float = 8.0
    #: floor on w_I per phase (0 = no floor; the paper's w_I_max is 0.9)
    floor_unaware: float = 0.0
    floor_suspicious: float = 0.6
    floor_alert: float = 0.9
    floor_search: float = 0.7
    floor_caution: float = 0.5
    #: factor on the guards' walking speed per phase
    speed_unaware: float = 1.0
    speed_suspicious: float = 1.0
    speed_alert: float = 1.25
    speed_search: float = 1.1
    speed_caution: float = 1.0

    bounds = {
        "alert_time": NON_NEGATIVE, "search_time": NON_NEGATIVE,
        "suspicious_time": NON_NEGATIVE,
        **{f"floor_{p}": _FLOOR for p in PHASES},
        **{f"speed_{p}": _SPEED for p in PHASES},
    }

    def floor(self, phase: str) -> float:
        """The w_I floor of ``phase``."""
        return float(getattr(self, f"floor_{phase}"))

    def speed(self, phase: str) -> float:
        """The guards' speed factor in ``phase``."""
        return float(getattr(self, f"speed_{phase}"))


class AlertPhases(Stimulus):
    """The team's alert phase as a stimulus: no layer, a weight floor, a speed factor."""

    name = "alert"

    def __init__(self, params: AlertParams | None = None) -> None:
        self.params = params or AlertParams()
        self.phase = "unaware"
        self.last_detection: float | None = None
        self.last_suspicion: float | None = None
        self.ever_alert = False
        self.t = 0.0

    def on_event(self, event: Event) -> None:
        if event.kind == "suspicion":
            self.last_suspicion = float(event.t)

    def on_tick(self, view: WorldView, dt: float) -> None:
        self.t = float(view.t)
        if view.seen_by or view.sighting is not None:
            self.last_detection = self.t
        self.phase = self.phase_at(self.t)
        self.ever_alert = self.ever_alert or self.phase == "alert"

    def phase_at(self, t: float) -> str:
        """The phase at time ``t`` from the last detection and suspicion (see the module)."""
        p = self.params
        if self.last_detection is not None:
            since = t - self.last_detection
            if since <= p.alert_time + 1e-9:
                return "alert"
            if since <= p.alert_time + p.search_time + 1e-9:
                return "search"
        if self.last_suspicion is not None and t - self.last_suspicion <= p.suspicious_time + 1e-9:
            return "suspicious"
        return "caution" if self.ever_alert or self.last_detection is not None else "unaware"

    @property
    def information_weight_floor(self) -> float | None:  # type: ignore[override]
        floor = self.params.floor(self.phase)
        return floor if floor > 0 else None

    @property
    def speed_scale(self) -> float:
        """The factor on the guards' speed in the current phase."""
        return self.params.speed(self.phase)

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "node": -1, "phase": self.phase}


__all__ = ["PHASES", "AlertParams", "AlertPhases"]
