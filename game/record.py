"""Played sessions as data: a human game turned into a trial row like :func:`game.trial.run_trial`'s.

``stealth play --record DIR`` keeps a :class:`Recording` of every game played: the trace
(one JSON line per AI tick, :func:`game.trace.attach_trace`), and at the end a row with the
trial's identity (``player = "human"``), config hash, every registered metric, the per-node
heatmaps, the objective's outcome and the optional questionnaire ratings (both as extra
metrics). The command line (``headless``) writes the rows into a results store, so
``stealth report DIR`` puts the human sessions next to the policies played on the same
level and seed (:func:`policy_row` runs those with the same interactive world).

The front end never imports ``headless``: this module, below both, only builds rows.
"""

from __future__ import annotations

import io
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Any

from .config import Config
from .trace import TraceWriter, attach_trace
from .trial import TrialSpec, identity_row, make_world
from .world import World

__all__ = ["HUMAN", "QUESTIONS", "Recording", "policy_row", "trial_row"]

#: The ``player`` of a recorded session.
HUMAN = "human"

#: The post-game questionnaire: ``(metric name, question)``, each answered 1–5.
QUESTIONS: tuple[tuple[str, str], ...] = (
    ("rating_challenge", "How challenging was it? (1 easy - 5 very hard)"),
    ("rating_fairness", "How fair did it feel? (1 unfair - 5 fair)"),
    ("rating_naturalness", "How natural were the guards? (1 robotic - 5 human-like)"),
)


def trial_row(world: World, spec: TrialSpec, config: Config, *, key: str,
              extra: Mapping[str, Any] | None = None, wall_time: float = 0.0) -> dict[str, Any]:
    """The store row of a finished (or abandoned) ``world`` played as ``spec``.

    Same fields as :func:`game.trial.run_trial`'s row plus ``key`` and ``level_ref``;
    ``extra`` values are added to the metrics (the store keeps them as extra metrics).
    """
    return {
        **identity_row(spec, world.level.name, key=key),
        "config_hash": config.hash(),
        "metrics": {**world.metrics(), **dict(extra or {})},
        "visits": world.m.visits.tolist(),
        "attacks": [round(a, 6) for a in world.m.attacks.tolist()],
        "wall_time": wall_time,
    }


def policy_row(spec: TrialSpec, config: Config) -> dict[str, Any]:
    """Run ``spec`` (a player policy) in the interactive world a session is played in
    (same physics step, spawns and config) and return its row: the session's comparison."""
    started = time.perf_counter()
    world = make_world(spec, config, interactive=True)
    world.run()
    return trial_row(world, spec, config, key=spec.key + "/interactive",
                     wall_time=time.perf_counter() - started)


@dataclass
class Recording:
    """One recorded session: the trace lines so far, then its row (:meth:`finish`)."""

    spec: TrialSpec
    config: Config
    started: str = field(default_factory=lambda: datetime.now(timezone.utc).strftime(
        "%Y%m%dT%H%M%S%fZ"))
    trace: io.StringIO = field(default_factory=io.StringIO)
    _clock: float = field(default_factory=time.perf_counter)
    _writer: TraceWriter | None = None

    def attach(self, world: World) -> None:
        """Trace ``world`` from now on (its t = 0 line at once)."""
        self._writer = attach_trace(world, self.trace)

    @property
    def key(self) -> str:
        """The session's store key: the trial key plus when it started (sessions never clash)."""
        return f"{self.spec.key}/session={self.started}"

    def finish(self, world: World, outcome: Mapping[str, Any],
               ratings: Mapping[str, int] | None = None) -> dict[str, Any]:
        """The session's row: metrics, heatmaps, ``outcome`` (won, collected) and ``ratings``.

        The trace gets its final line (the moment the game ended, between two AI ticks as a
        capture usually is, with the outcome), so a replay runs to the true end."""
        if self._writer is not None:
            self._writer.finish(world, str(outcome.get("outcome", "")))
            self._writer = None
        extra = {**outcome, **dict(ratings or {})}
        return trial_row(world, self.spec, self.config, key=self.key, extra=extra,
                         wall_time=time.perf_counter() - self._clock)

    def trace_lines(self) -> Sequence[str]:
        """The trace as JSON lines (``stealth replay`` reads them)."""
        return self.trace.getvalue().splitlines()
