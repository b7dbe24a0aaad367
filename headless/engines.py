"""The engine a headless command runs its trials on (``world.engine``, SPEC §12).

``pymunk`` is the reference (:func:`game.trial.run_trial`, one world per trial); ``batch``
advances the trials of one level, abstraction, ``[set]`` and factor combination in lockstep
(:func:`game.batch.run_trials`). Asked for explicitly, a trial the batch engine does not
cover (:func:`game.batch.uncovered`) is refused before anything runs or is written, in one
line naming what to use instead (:func:`check_covered`). ``auto`` (the default) runs the
trials the batch engine covers on it and the rest on pymunk (:func:`split`); sweeps and
studies take their tasks from :func:`engine_tasks`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any

from game.config import ENGINE_KEY, Config
from game.trial import TrialSpec

from .errors import UserError

__all__ = ["AUTO", "BATCH", "PYMUNK", "Split", "batch_tasks", "check_covered", "engine_tasks",
           "refusal", "split"]

PYMUNK = "pymunk"
BATCH = "batch"
AUTO = "auto"

#: a pymunk task holds at most this many trials (a batch task: game.batch.MAX_BATCH)
PYMUNK_TASK = 8


def refusal(what: str) -> UserError:
    """The one-line error for a trial the batch engine does not cover (``what`` names it)."""
    from game.batch import refusal_text

    return UserError(refusal_text(what))


def check_covered(specs: Iterable[TrialSpec]) -> None:
    """Raise :func:`refusal` for the first of ``specs`` the batch engine does not cover.

    Each spec is asked with its own config (its ``[set]`` and factors, the engine batch),
    built once per combination.
    """
    for spec, what in _coverage(specs):
        if what is not None:
            raise refusal(what)


def _coverage(specs: Iterable[TrialSpec]) -> Iterator[tuple[TrialSpec, str | None]]:
    """Each spec with what of it the batch engine does not cover (None: all of it), asked
    once per level, abstraction, guard mode, player, stimuli and config."""
    from game.batch import uncovered

    configs: dict[Any, Config] = {}
    answers: dict[Any, str | None] = {}
    for spec in specs:
        key = (spec.overrides, spec.factors)
        config = configs.get(key)
        if config is None:
            config = configs[key] = Config.load({**spec.settings, ENGINE_KEY: BATCH})
        where = (key, spec.level, spec.abstraction, spec.guards, spec.player, spec.stimuli)
        if where not in answers:
            answers[where] = uncovered(spec, config)
        yield spec, answers[where]


class Split:
    """The trials of a run as ``engine`` assigns them: ``batch`` and ``pymunk`` lists (in
    the run's order) and, under ``auto``, why the first trial left to pymunk is."""

    def __init__(self, specs: Sequence[TrialSpec], engine: str) -> None:
        self.engine = engine
        self.batch: list[TrialSpec] = []
        self.pymunk: list[TrialSpec] = []
        self.why: str | None = None
        if engine == PYMUNK:
            self.pymunk = list(specs)
        elif engine == BATCH:
            check_covered(specs)
            self.batch = list(specs)
        elif engine == AUTO:
            for spec, what in _coverage(specs):
                (self.batch if what is None else self.pymunk).append(spec)
                if what is not None and self.why is None:
                    self.why = what
        else:
            raise UserError(f"world.engine: expected one of auto, pymunk, batch, got {engine!r}")

    def describe(self) -> str:
        """What the sweep's first line says of its engines, e.g. ``engine batch`` or
        ``engine auto: batch 900, pymunk 100 (plugin stimuli (x))``."""
        if self.engine != AUTO:
            return f"engine {self.engine}"
        if not self.pymunk:
            return "engine auto: batch"
        if not self.batch:
            return f"engine auto: pymunk (the batch engine does not cover {self.why})"
        return (f"engine auto: batch for {len(self.batch)} trials, pymunk for "
                f"{len(self.pymunk)} (the batch engine does not cover {self.why})")


def split(specs: Sequence[TrialSpec], engine: str) -> Split:
    """``specs`` assigned to the engines ``engine`` asks for (``batch`` refuses a trial it
    does not cover, :func:`check_covered`)."""
    return Split(specs, engine)


def _batch_group(spec: TrialSpec) -> tuple[Any, ...]:
    """What the trials of one batch share (game.batch.run_trials): level, abstraction,
    overrides, factors (and root seed and stimuli, which every trial of a design shares)."""
    return (spec.level, spec.abstraction, spec.overrides, spec.factors, spec.root_seed,
            spec.stimuli)


def batch_tasks(specs: Sequence[TrialSpec], workers: int, max_batch: int
                ) -> list[list[TrialSpec]]:
    """The batch engine's tasks: ``specs`` grouped by level, abstraction, overrides and
    factors (seeds, guard modes, player policies and scenarios vary inside a group), each
    group cut into near-equal tasks of at most ``max_batch`` trials, and smaller ones when
    there are fewer trials than ``max_batch`` x ``workers``, so every worker gets work.

    Every spec is in exactly one task, in the sweep's order within its group; the tasks
    take the groups in turn (the first task of each, then the second, ...), so an
    interrupted sweep has run every group's first seeds.

    >>> specs = [TrialSpec(level, seed=seed) for seed in range(3) for level in ("a", "b")]
    >>> [[(s.level, s.seed) for s in task] for task in batch_tasks(specs, 1, 2)]
    [[('a', 0), ('a', 1)], [('b', 0), ('b', 1)], [('a', 2)], [('b', 2)]]
    """
    if max_batch < 1 or workers < 1:
        raise ValueError(f"batch_tasks: workers {workers} and max_batch {max_batch} must be >= 1")
    groups: dict[tuple[Any, ...], list[TrialSpec]] = {}
    for spec in specs:
        groups.setdefault(_batch_group(spec), []).append(spec)
    size = max(1, min(max_batch, math.ceil(len(specs) / workers)))
    cut = []
    for group in groups.values():
        per = math.ceil(len(group) / math.ceil(len(group) / size))  # near-equal parts
        cut.append([group[i:i + per] for i in range(0, len(group), per)])
    return [parts[i] for i in range(max((len(p) for p in cut), default=0))
            for parts in cut if i < len(parts)]


def engine_tasks(parts: Split, workers: int, *, inline: bool = False
                 ) -> Iterator[tuple[Callable[..., list[dict[str, Any]]], list[TrialSpec]]]:
    """The tasks of a run, ``(function, specs)`` for an executor: the batch engine's groups
    first (:func:`batch_tasks`, up to ``game.batch.MAX_BATCH`` trials each),
    then the pymunk trials in small batches (one each when ``inline``)."""
    from .executors import run_batch, run_engine_batch

    if parts.batch:
        from game.batch import MAX_BATCH

        for task in batch_tasks(parts.batch, workers, MAX_BATCH):
            yield run_engine_batch, task
    todo = parts.pymunk
    size = 1 if inline else max(1, min(PYMUNK_TASK, math.ceil(len(todo) / (workers * 8))))
    for start in range(0, len(todo), size):
        yield run_batch, todo[start:start + size]
