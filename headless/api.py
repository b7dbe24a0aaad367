"""The Python API for notebooks: one trial, a design's rows, a store's rows, a world.

Thin conveniences over the same functions the ``stealth`` command runs (docs/api.md):
:func:`run_one` is ``stealth sim``, :func:`run_design` is ``stealth run`` (into a results
directory, resumable), :func:`load_store` reads a results directory as rows — a pandas
``DataFrame`` when pandas is installed, else a list of dicts — and :func:`build_world` is
the world of one trial, to step by hand.

>>> row = run_one("maze", guards="random", seed=1, overrides={"world.duration": 3.0})
>>> sorted(row["metrics"])[:4]
['avg_guard_player_dist', 'backtracks', 'backtracks_entries', 'backtracks_targets']
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ai import DEFAULT_GUARD_MODE, DEFAULT_PLAYER_POLICY
from ai.stimuli import load_stimulus
from game.trial import TrialSpec, make_world, placed_spawns, run_trial
from game.world import World
from navmesh.level import cached_level

from .errors import UserError
from .presets import Preset, load_preset
from .store import IDENTITY, STORE_NAME, ResultStore

__all__ = ["as_rows", "build_world", "load_store", "run_design", "run_one", "trial_spec"]


def trial_spec(level: str, *, abstraction: str = "grid",
               guards: str = DEFAULT_GUARD_MODE, player: str = DEFAULT_PLAYER_POLICY,
               scenario: str = "capture", seed: int = 0,
               overrides: Mapping[str, Any] | None = None,
               stimuli: Sequence[str] = ()) -> TrialSpec:
    """The :class:`~game.trial.TrialSpec` of these settings (``overrides``: config keys);
    a Tiled map that places guards starts them there unless ``world.spawns`` is given, as in
    ``stealth sim`` (:func:`game.trial.placed_spawns`)."""
    for plugin in stimuli:  # before the level: a plugin may declare its zone kinds
        load_stimulus(plugin)
    return TrialSpec(level, abstraction, guards, player, scenario, seed,
                     overrides=placed_spawns(cached_level(level),
                                             tuple(sorted((overrides or {}).items()))),
                     stimuli=tuple(stimuli))


def run_one(level: str, **settings: Any) -> dict[str, Any]:
    """Run one trial (settings as :func:`trial_spec`) and return its row: identity,
    ``config``, ``metrics`` (SPEC §9), per-node ``visits`` and ``attacks``."""
    return run_trial(trial_spec(level, **settings))


def build_world(level: str, **settings: Any) -> World:
    """The world of one trial (settings as :func:`trial_spec`), not yet stepped:
    ``world.step()`` advances one physics step, ``world.run()`` plays it out."""
    return make_world(trial_spec(level, **settings))


def as_rows(records: Sequence[Mapping[str, Any]]) -> Any:
    """``records`` as a pandas ``DataFrame`` when pandas is installed, else as a list."""
    try:
        import pandas
    except ImportError:
        return [dict(r) for r in records]
    return pandas.DataFrame.from_records([dict(r) for r in records])


def load_store(directory: str | Path) -> Any:
    """The finished trials of a results directory (or its ``results.sqlite``), one row each:
    key, identity, config hash, every metric, ``wall_time`` (:func:`as_rows`)."""
    path = Path(directory)
    if path.is_dir():
        path = path / STORE_NAME
    if not path.is_file():
        raise UserError(f"{directory}: no results store here")
    keep = ("key", *IDENTITY, "config_hash")
    with ResultStore(path, readonly=True) as store:
        records = []
        for trial in store.trials():
            record = {k: trial[k] for k in keep}
            record.update({m.name: trial[m.name] for m in store.metrics})
            record.update(trial["extra_metrics"])
            record["wall_time"] = trial["wall_time"]
            records.append(record)
    return as_rows(records)


def run_design(preset: str | Preset, out: str | Path | None = None, *, workers: int = 1,
               progress: bool = False) -> Any:
    """Run every trial of a design (a bundled preset's name, a preset file or a
    :class:`~headless.presets.Preset`) into ``out`` (default: a new temporary directory)
    and return its rows (:func:`load_store`). Trials already in ``out`` are not run again."""
    from .sweep import run_sweep

    design = load_preset(preset) if isinstance(preset, str) else preset
    directory = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="stealth-"))
    result = run_sweep(design, directory, workers=workers, progress=progress)
    if result.failed:
        raise UserError(f"{result.failed} trials failed, the first: {result.first_error}")
    return load_store(directory)
