"""The ``stealth`` command line (SPEC §9).

A user's mistake — a broken level, an unknown mode, a point inside a wall, a bad override —
ends with one line ``stealth: error: ...`` on stderr and exit code 2, never a traceback.
With ``--json`` stdout carries exactly one JSON document; logs go to stderr.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from typing import Any

from ai import GUARD_MODES, PLAYER_POLICIES

EXIT_USER_ERROR = 2


class UserError(Exception):
    """A problem with what the user asked for; printed as one line, exit code 2."""


def _user_errors() -> tuple[type[BaseException], ...]:
    from ai.stimuli import StimulusError
    from game.config import ConfigError
    from navmesh.level import LevelError
    from navmesh.mesh import OutsideError

    return (UserError, LevelError, ConfigError, OutsideError, StimulusError)


def _point(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y (two numbers), got {text!r}") from None
    if not all(abs(v) < float("inf") for v in (x, y)):
        raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r}")
    return (x, y)


def _emit_json(document: Any) -> None:
    json.dump(document, sys.stdout, indent=2)
    sys.stdout.write("\n")


# ---------------------------------------------------------------------- levels / validate
def level_stats(level: Any) -> dict[str, Any]:
    """Paper Table 1 for one level: navmesh triangles and areas, grid size and counts."""
    from navmesh.graph import graph_for

    mesh = graph_for(level, "partition").mesh
    walkable = int(level.occupancy.sum())
    return {
        "name": level.name,
        "triangles": int(len(mesh.triangles)),
        "min_area": round(float(mesh.areas.min()), 4),
        "max_area": round(float(mesh.areas.max()), 4),
        "avg_area": round(float(mesh.areas.mean()), 4),
        "rows": level.rows,
        "cols": level.cols,
        "walkable": walkable,
        "blocked": int(level.occupancy.size - walkable),
    }


def cmd_levels(args: argparse.Namespace) -> int:
    from navmesh.level import bundled_level_names, load_level

    from navmesh.graph import check_fits

    names = args.level or bundled_level_names()
    levels = [load_level(name) for name in names]
    for name, level in zip(names, levels, strict=True):
        check_fits(level, str(name))  # refuse before building what cannot fit
    rows = [level_stats(level) for level in levels]
    if args.json:
        _emit_json(rows)
        return 0
    header = f"{'level':<12}{'tris':>6}{'min area':>10}{'max area':>10}{'avg area':>10}" \
             f"{'rows':>6}{'cols':>6}{'walkable':>10}{'blocked':>9}"
    print(header)
    for r in rows:
        total = r["walkable"] + r["blocked"]
        print(
            f"{r['name']:<12}{r['triangles']:>6}{r['min_area']:>10.4f}{r['max_area']:>10.4f}"
            f"{r['avg_area']:>10.4f}{r['rows']:>6}{r['cols']:>6}"
            f"{r['walkable']:>5} ({100 * r['walkable'] / total:2.0f}%)"
            f"{r['blocked']:>4} ({100 * r['blocked'] / total:2.0f}%)"
        )
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    from navmesh.graph import check_fits
    from navmesh.level import LevelError, load_level

    failed = 0
    for name in args.level:
        try:
            level = load_level(name)
            check_fits(level, str(name))
        except LevelError as error:
            print(f"stealth: error: {error}", file=sys.stderr)
            failed += 1
        else:
            print(f"{name}: ok ({level.name}, {level.rows}x{level.cols}, "
                  f"{int(level.occupancy.sum())} walkable cells)", file=sys.stderr)
    return EXIT_USER_ERROR if failed else 0


# ---------------------------------------------------------------------- path
def cmd_path(args: argparse.Namespace) -> int:
    from navmesh.graph import graph_for
    from navmesh.level import load_level

    level = load_level(args.level)
    mesh = graph_for(level, "partition").mesh
    path = mesh.find_path(args.from_, args.to)
    document = {"points": [[float(x), float(y)] for x, y in path.points],
                "length": float(path.length)}
    if args.json:
        _emit_json(document)
    else:
        print(f"length {document['length']:.4f} through {len(path.points)} points")
        for x, y in document["points"]:
            print(f"  {x:.4f},{y:.4f}")
    return 0


# ---------------------------------------------------------------------- sim
def _overrides(items: Sequence[str]) -> tuple[tuple[str, Any], ...]:
    """The ``--set`` pairs, every key and value checked now (one-line ConfigError)."""
    from game.config import Config, parse_overrides

    Config.load(items)
    return tuple(parse_overrides(items))


def cmd_sim(args: argparse.Namespace) -> int:
    from ai.stimuli import load_stimulus
    from game.trial import TrialSpec, run_trial, sim_document
    from navmesh.level import load_level

    load_level(args.level)  # a bad level fails here with its one-line message
    for plugin in args.stimulus:
        load_stimulus(plugin)  # a bad plugin fails here with its one-line message
    spec = TrialSpec(
        level=args.level,
        abstraction=args.abstraction,
        guards=args.guards,
        player=args.player,
        scenario=args.scenario,
        seed=args.seed,
        overrides=_overrides(args.set),
        stimuli=tuple(args.stimulus),
    )
    if args.trace:
        try:
            handle = open(args.trace, "w", encoding="utf-8")
        except OSError as error:
            raise UserError(f"--trace {args.trace}: cannot write ({error.strerror})") from None
        with handle:
            row = run_trial(spec, trace=handle, explain=args.explain)
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


# ---------------------------------------------------------------------- parser
def _optional_command(module: str, name: str) -> Callable[[argparse.Namespace], int]:
    """A command implemented in another module, imported only when it runs."""

    def run(args: argparse.Namespace) -> int:
        from importlib import import_module

        return int(getattr(import_module(module), name)(args))

    return run


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="stealth", description="Stealthfield: guards driven by composite potential fields."
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("levels", help="paper Table 1 figures of levels")
    p.add_argument("level", nargs="*", help="level files or bundled names (default: all bundled)")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")
    p.set_defaults(func=cmd_levels)

    p = sub.add_parser("validate", help="check level files")
    p.add_argument("level", nargs="+")
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("path", help="navmesh (funnel) path between two points")
    p.add_argument("level")
    p.add_argument("--from", dest="from_", type=_point, required=True, metavar="X,Y")
    p.add_argument("--to", type=_point, required=True, metavar="X,Y")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_path)

    p = sub.add_parser("sim", help="run one trial and print its metrics")
    p.add_argument("level")
    p.add_argument("--guards", choices=sorted(GUARD_MODES), default="pf")
    p.add_argument("--player", choices=sorted(PLAYER_POLICIES), default="maxmin")
    p.add_argument("--abstraction", choices=["grid", "partition"], default="grid")
    p.add_argument("--scenario", choices=["capture", "fixed"], default="capture")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config value, e.g. --set world.view_range=6")
    p.add_argument("--json", action="store_true")
    p.add_argument("--trace", metavar="FILE", help="write every AI tick as a JSON line")
    p.add_argument("--explain", action="store_true",
                   help="add the first guard's decision explained to each trace line "
                        "(to stderr when no --trace)")
    p.add_argument("--stimulus", action="append", default=[], metavar="FILE.py:NAME",
                   help="add a stimulus (a Stimulus subclass or factory in FILE.py, or an "
                        "installed stealthfield.stimuli entry point); repeatable")
    p.set_defaults(func=cmd_sim)

    p = sub.add_parser("mechanics", help="measured effects of the stealth mechanics (docs/mechanics.md)")
    p.add_argument("--seeds", type=int, default=30, help="paired seeds per mechanic (default 30)")
    p.add_argument("--out", default="results/mechanics", help="directory for mechanics.md and .csv")
    p.add_argument("--workers", type=int, default=None, help="worker processes (1 = in-process)")
    p.add_argument("--level", default="miami", help="level (default miami)")
    p.add_argument("--abstraction", choices=["grid", "partition"], default="grid")
    p.set_defaults(func=_optional_command("headless.mechanics", "cmd_mechanics"))

    p = sub.add_parser("run", help="run a sweep (resumable, parallel)")
    p.add_argument("--preset", default="smoke", help="preset name or TOML file")
    p.add_argument("--out", default=None, help="results directory (default: results/PRESET)")
    p.add_argument("--workers", type=int, default=None, help="worker processes (1 = in-process)")
    p.add_argument("--scheduler", default=None, help="Dask scheduler address (cluster extra)")
    p.set_defaults(func=_optional_command("headless.sweep", "cmd_run"))

    p = sub.add_parser("report", help="tables, CSVs and figures of a results directory")
    p.add_argument("dir")
    p.set_defaults(func=_optional_command("headless.report", "cmd_report"))

    p = sub.add_parser("play", help="play a level interactively")
    p.add_argument("level")
    p.add_argument("--guards", choices=sorted(GUARD_MODES), default="pf")
    p.add_argument("--abstraction", choices=["grid", "partition"], default="grid")
    p.add_argument("--autopilot", choices=sorted(PLAYER_POLICIES), default=None)
    p.add_argument("--frames", type=int, default=None, help="stop after N frames")
    p.add_argument("--screenshot", default=None, help="save the last frame as PNG")
    p.add_argument("--overlay", default="none", help="initial field overlay")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--scenario", choices=["capture", "fixed"], default="capture",
                   help="capture: game over at HP 0 (default); fixed: respawn, play 60 s")
    p.add_argument("--mesh", action="store_true", help="start with the grid / navmesh shown")
    p.add_argument("--plans", action="store_true", help="start with the guards' plans shown")
    p.set_defaults(func=_optional_command("game.front.play", "cmd_play"))

    p = sub.add_parser("replay", help="replay a trace written by stealth sim --trace")
    p.add_argument("trace")
    p.add_argument("--level", default=None, help="level of the trace (default: from the trace)")
    p.add_argument("--frames", type=int, default=None)
    p.add_argument("--screenshot", default=None)
    p.add_argument("--abstraction", choices=["grid", "partition"], default=None,
                   help="graph the trace's node numbers refer to (default: detected)")
    p.add_argument("--scenario", choices=["capture", "fixed"], default="capture",
                   help="scenario of the trace (sets the guards' view range drawn)")
    p.add_argument("--speed", type=float, default=1.0, help="playback speed (default 1)")
    p.add_argument("--mesh", action="store_true", help="start with the grid / navmesh shown")
    p.add_argument("--plans", action="store_true", help="start with the guards' targets shown")
    p.set_defaults(func=_optional_command("game.front.replay", "cmd_replay"))
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except _user_errors() as error:
        print(f"stealth: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("stealth: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    # Run through the package module so `python -m headless.cli` and the installed script
    # share one UserError class (other modules import it from headless.cli).
    from headless.cli import main as _main

    sys.exit(_main())
