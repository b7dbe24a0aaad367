"""``stealth sim``: one trial run in the command line's process, its metrics (or a stored trial again)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from typing import Any

from ..errors import UsageError, UserError
from .output import _emit_json

__all__ = ["cmd_sim"]


# ---------------------------------------------------------------------- sim
def _overrides(items: Sequence[str], level: Any, base: Mapping[str, Any] | None = None
               ) -> tuple[tuple[str, Any], ...]:
    """The ``--config`` file's settings (``base``) overridden by the ``--set`` pairs, every
    key and value checked now, also against the level (one-line ConfigError before any
    file is written)."""
    from game.config import Config, parse_overrides
    from game.schema import check_level

    settings = {**(base or {}), **dict(parse_overrides(items))}
    check_level(Config.load(settings), level)
    return tuple(settings.items())


def cmd_sim(args: argparse.Namespace) -> int:
    from ai.stimuli import load_stimulus
    from game.config_file import read_config_file
    from game.trial import TrialSpec, run_trial, sim_document
    from navmesh.level import load_level

    if args.from_dir is not None or args.trial is not None:
        from ..reproduce import cmd_sim_from

        return cmd_sim_from(args)
    if args.level is None:
        raise UsageError("sim: a LEVEL is required (or --from DIR --trial KEY)")
    for plugin in args.stimulus:  # before the level: a plugin may declare its zone kinds
        load_stimulus(plugin)  # a bad plugin fails here with its one-line message
    level = load_level(args.level)  # a bad level fails here with its one-line message
    spec = TrialSpec(
        level=args.level,
        abstraction=args.abstraction,
        guards=args.guards,
        player=args.player,
        scenario=args.scenario,
        seed=args.seed,
        overrides=_overrides(args.set, level,
                             read_config_file(args.config) if args.config else {}),
        stimuli=tuple(args.stimulus),
    )
    if args.trace:
        from navmesh.level import resolve_level_path

        from ..outputs.clobber import refuse_inputs

        plugins = [p.rpartition(":")[0] for p in args.stimulus if ":" in p]
        refuse_inputs("--trace", args.trace, [resolve_level_path(args.level), *plugins])
        try:
            handle = open(args.trace, "w", encoding="utf-8")
        except OSError as error:
            raise UserError(f"--trace {args.trace}: cannot write ({error.strerror})") from None
        try:
            with handle:
                row = run_trial(spec, trace=handle, explain=args.explain)
        except OSError as error:  # the disk filled up, the device refused: name the file
            raise OSError(error.errno, error.strerror, args.trace) from error
    elif args.explain:
        row = run_trial(spec, trace=sys.stderr, explain=True)
    else:
        row = run_trial(spec)
    document = sim_document(row)
    if args.json:
        _emit_json(document)
    else:
        print(f"{document['level']} {document['abstraction']} guards={document['guards']} "
              f"player={document['player']} scenario={document['scenario']} seed={document['seed']}")
        for key, value in document["metrics"].items():
            print(f"  {key:<22} {value}")
    return 0
