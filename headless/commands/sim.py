"""``stealth sim``: one trial, its metrics printed (SPEC §9), optionally its trace.

The level and the config are loaded and checked once, here, and handed to the trial. A Tiled
map that places guards (objects of class ``guard``) runs with ``world.spawns = "level"`` unless
``world.spawns`` is given: the designer put them there (its guards' ``facing`` and ``patrol``
properties apply with it). With
``--set world.engine=batch`` the trial runs on the batch engine
(``game.batch.run_trials([spec])[0]``, the same row), refused in one line when that engine
does not cover it or a trace is asked for (it writes none).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from typing import Any

from ai.stimuli import load_stimulus
from game.config import ENGINE_KEY, Config, parse_overrides
from game.config_file import read_config_file
from game.trial import TrialSpec, make_world, placed_spawns, run_trial, sim_document
from navmesh.level import load_level, resolve_level_path

from ..engines import BATCH, check_covered, refusal
from ..outputs.clobber import open_output, plugin_files
from .failure import UsageError
from .levels import emit_json

__all__ = ["cmd_sim"]


def _settings(items: Sequence[str], base: Mapping[str, Any] | None = None
              ) -> tuple[tuple[str, Any], ...]:
    """The ``--config`` file's settings (``base``) overridden by the ``--set`` pairs, as the
    trial's identity keeps them (the ``--set`` values as typed; checked by ``Config.load``)."""
    return tuple({**(base or {}), **dict(parse_overrides(items))}.items())


def cmd_sim(args: argparse.Namespace) -> int:
    """``stealth sim``: the level and the config are loaded and checked once, here, and the
    trial runs on them — its world is built (checking the config against the level) before
    a ``--trace`` file is opened, so a mistake leaves no file behind."""
    if args.from_dir is not None or args.trial is not None:
        from ..reproduce import cmd_sim_from

        return cmd_sim_from(args)
    if args.level is None:
        raise UsageError("sim: a LEVEL is required (or --from DIR --trial KEY)")
    for plugin in args.stimulus:  # before the level: a plugin may declare its zone kinds
        load_stimulus(plugin)  # a bad plugin fails here with its one-line message
    level = load_level(args.level)  # a bad level fails here with its one-line message
    overrides = placed_spawns(level, _settings(
        args.set, read_config_file(args.config) if args.config else {}))
    spec = TrialSpec(
        level=args.level,
        abstraction=args.abstraction,
        guards=args.guards,
        player=args.player,
        scenario=args.scenario,
        seed=args.seed,
        overrides=overrides,
        stimuli=tuple(args.stimulus),
    )
    config = Config.load(spec.settings)  # every key and value checked: one-line ConfigError
    batch = config[ENGINE_KEY] == BATCH
    if batch and (args.trace or args.explain):
        raise refusal(f"{'--trace' if args.trace else '--explain'} (it writes no traces)")
    if batch:
        check_covered([spec])
    world = make_world(spec, config, level=level)  # checks the config against the level
    if batch:  # the world above only checked the config: the batch engine runs the trial
        from game.batch import run_trials

        row = run_trials([spec])[0]
    elif args.trace:
        handle = open_output("--trace", args.trace, [resolve_level_path(args.level), args.config,
                                                     *plugin_files(args.stimulus)])
        try:
            with handle:
                row = run_trial(spec, trace=handle, explain=args.explain, world=world)
        except OSError as error:  # the disk filled up, the device refused: name the file
            raise OSError(error.errno, error.strerror, args.trace) from error
    elif args.explain:
        row = run_trial(spec, trace=sys.stderr, explain=True, world=world)
    else:
        row = run_trial(spec, world=world)
    document = sim_document(row)
    if args.json:
        emit_json(document)
    else:
        print(f"{document['level']} {document['abstraction']} guards={document['guards']} "
              f"player={document['player']} scenario={document['scenario']} seed={document['seed']}")
        for key, value in document["metrics"].items():
            print(f"  {key:<22} {value}")
    return 0
