"""The ``stealth`` command line (SPEC §9).

A user's mistake — a broken level, an unknown mode, a point inside a wall, a bad override,
a bad option — ends with one line ``stealth: error: ...`` on stderr and exit code 2, never a
traceback: every layer raises a subclass of :class:`~navmesh.errors.StealthError` and
:func:`main` prints it. With ``--json`` stdout carries exactly one JSON document; logs go to
stderr. The heavy commands live in their own modules and are imported only when they run
(one small ``_cmd_*`` function each), so ``stealth --help`` needs no pygame.
"""

from __future__ import annotations

import os
import signal
import sys


def _quiet_interrupt(signum: int, frame: object) -> None:
    """Ctrl-C while ``stealth`` is still importing: one line and exit 130, no traceback."""
    os.write(2, b"stealth: interrupted\n")
    os._exit(130)


if __name__ == "__main__" or os.path.basename(sys.argv[0]) == "stealth":  # not as a library
    signal.signal(signal.SIGINT, _quiet_interrupt)

import argparse  # noqa: E402 - after the start-up handler above
from collections.abc import Callable, Iterable, Iterator, Sequence  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from .commands.failure import EXIT_USER_ERROR, GuardedParser, UsageError, guarded, os_error_line, wants_debug  # noqa: E402

__all__ = ["ANALYSES", "EXIT_USER_ERROR", "UsageError", "build_parser", "main", "os_error_line"]


def _point(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y (two numbers), got {text!r}") from None
    if not all(abs(v) < float("inf") for v in (x, y)):
        raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r}")
    return (x, y)


def _seed(text: str) -> int:
    """A ``--seed``: a whole number inside the declared seed range (``game.schema.SEED``)."""
    from game.schema import SEED

    unit = "digits" if text.isdigit() else "characters"
    shown = text if len(text) <= 30 else f"{text[:12]}…({len(text)} {unit})"
    try:
        value = int(text)  # beyond 4,300 digits a ValueError too (Python's own limit)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number in {SEED.describe()}, got {shown!r}") from None
    problem = SEED.problem(value)
    if problem is not None:
        raise argparse.ArgumentTypeError(f"{shown} {problem}")
    return value


# ---------------------------------------------------------------------- presets
def cmd_presets(args: argparse.Namespace) -> int:
    """``stealth presets``: the bundled presets and their descriptions."""
    from .commands.levels import emit_json
    from .presets import bundled_presets

    listed = bundled_presets()
    if args.json:
        emit_json([{"name": name, "description": text} for name, text in listed])
        return 0
    width = max((len(name) for name, _ in listed), default=0)
    for name, text in listed:
        print(f"{name:<{width}}  {text}")
    return 0


# ---------------------------------------------------------------------- lazy commands
def _cmd_sim(args: argparse.Namespace) -> int:
    from .commands.sim import cmd_sim

    return cmd_sim(args)


def _cmd_levels(args: argparse.Namespace) -> int:
    from .commands.levels import cmd_levels

    return cmd_levels(args)


def _cmd_validate(args: argparse.Namespace) -> int:
    from .commands.levels import cmd_validate

    return cmd_validate(args)


def _cmd_path(args: argparse.Namespace) -> int:
    from .commands.levels import cmd_path

    return cmd_path(args)


def _cmd_run(args: argparse.Namespace) -> int:
    from .sweep import cmd_run

    return cmd_run(args)


def _cmd_report(args: argparse.Namespace) -> int:
    from .analysis.report import cmd_report

    return cmd_report(args)


def _cmd_mechanics(args: argparse.Namespace) -> int:
    if args.stimulus:
        from .mechanics.stimulus_effect import cmd_stimulus_effect

        return cmd_stimulus_effect(args)
    from .mechanics.run import cmd_mechanics

    return cmd_mechanics(args)


def _cmd_play(args: argparse.Namespace) -> int:
    from game.config_file import read_config_file
    from game.front.play_command import cmd_play

    from .outputs.clobber import level_file, plugin_files, refuse_inputs, refuse_inputs_all

    if args.questions and args.record is None:
        raise UsageError("--questions: the ratings are stored with the session: give --record DIR too")
    inputs = [level_file(args.level), args.config, *plugin_files(args.stimulus)]
    refuse_inputs_all("--screenshot", [args.screenshot] if args.screenshot else [], inputs)
    if args.record:
        refuse_inputs("--record", args.record, inputs, folder=True)
    if args.config:  # the file's overrides first, so --set still wins
        args.set = [f"{k}={v}" for k, v in read_config_file(args.config).items()] + args.set
    if args.record is None:
        return cmd_play(args)
    from .sessions.record import SessionStore

    sink = SessionStore(args.record, args.set)
    code = cmd_play(args, on_session=sink)
    print(f"stealth: recorded {len(sink.stored)} session(s) into {args.record}", file=sys.stderr)
    return code


def _cmd_replay(args: argparse.Namespace) -> int:
    from game.front.replay import cmd_replay, replay_trial

    from .outputs.clobber import level_file, refuse_inputs
    from .store import STORE_NAME

    if args.screenshot:
        refuse_inputs("--screenshot", args.screenshot, [
            args.trace, Path(args.trace) / STORE_NAME, level_file(args.level)])
    if args.stimulus and args.trial is None:
        raise UsageError("replay --stimulus: only with --trial KEY (a trace is replayed as written)")
    if args.trial is not None:
        from .reproduce import stored_spec, stored_trial
        from .sessions.record import session_trace

        if stored_trial(args.trace, args.trial)["player"] == "human":  # a played session:
            args.trace = str(session_trace(args.trace, args.trial))  # its recorded trace
            return cmd_replay(args)
        return replay_trial(stored_spec(args.trace, args.trial, args.stimulus), args)
    return cmd_replay(args)


def _cmd_tune(args: argparse.Namespace) -> int:
    from .tune.study import cmd_tune

    return cmd_tune(args)


#: ``stealth analyse NAME``: each analysis and its module, whose ``run`` takes the arguments
#: of ``python -m headless.NAME`` (NAME with ``_`` for ``-``), which keeps working.
ANALYSES: dict[str, str] = {
    "beside-paper": "headless.analysis.beside_paper",
    "held-out": "headless.analysis.held_out",
    "robustness": "headless.analysis.robustness",
    "paired": "headless.analysis.paired",
    "engines": "headless.analysis.engines",
}


def _cmd_analyse(args: argparse.Namespace) -> int:
    from importlib import import_module

    analysis = import_module(ANALYSES[args.analysis])
    return int(analysis.run(args.words, prog=f"stealth analyse {args.analysis}"))


# ---------------------------------------------------------------------- parser
_Parser = GuardedParser


class _Help(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Help that shows every option's default and keeps the epilog's line breaks.

    A default that is "nothing" (None, False, an empty list) is not printed: flags are off
    by default, and an option whose absence means something says so in its own help.
    """

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if action.default is None or action.default is False or action.default == []:
            return action.help
        return super()._get_help_string(action)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("stealthfield")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "unknown (not installed)"


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked (the lookup scans
    the installed packages, which every other command would pay for)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 default: str = argparse.SUPPRESS, help: str | None = None) -> None:
        super().__init__(option_strings, dest, nargs=0, default=default, help=help)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: object, option_string: str | None = None) -> None:
        print(f"stealth {_version()}")
        parser.exit()


class _Registered:
    """The names of a registry (guard modes, player policies) as argparse ``choices``, read
    when a value is checked or the help is printed: building the parser imports no
    controller code, and a mode registered later is still accepted."""

    def __init__(self, names: Callable[[], Iterable[str]]) -> None:
        self._names = names

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._names()))

    def __contains__(self, name: object) -> bool:
        return name in list(self._names())


def _guard_modes() -> list[str]:
    from ai import GUARD_MODES

    return list(GUARD_MODES)


def _player_policies() -> list[str]:
    from ai import PLAYER_POLICIES

    return list(PLAYER_POLICIES)


#: ``stealth play``'s epilog, replaced by the key table when its help is printed.
_KEYS = "keys:\n"


class _PlayHelp(_Help):
    """``stealth play --help``: the epilog lists the keys (:mod:`game.front.keys`, read only
    when the help is printed)."""

    def add_text(self, text: str | None) -> None:
        if text == _KEYS:
            from game.front.keys import key_table

            text = _KEYS + key_table()
        super().add_text(text)


def build_parser() -> argparse.ArgumentParser:
    """The ``stealth`` parser; its choices come from the registries and name constants.

    Light: it imports the modules of names only (no numpy, pymunk, scipy or shapely); a
    command imports what it needs when it runs, and the registries are read when a value
    is checked (tests/test_cli.py counts the modules).
    """
    from game.overlays import OVERLAYS
    from game.scenarios import SCENARIOS
    from navmesh.abstractions import ABSTRACTIONS

    modes, policies = _Registered(_guard_modes), _Registered(_player_policies)
    abstractions, scenarios = list(ABSTRACTIONS), list(SCENARIOS)
    parser = _Parser(
        prog="stealth", description="Stealthfield: guards driven by composite potential fields.",
        formatter_class=_Help,
    )
    parser.add_argument("--version", action=_Version, help="show program's version number and exit")
    parser.add_argument("--debug", action="store_true",
                        help="on an error, print the traceback before the one-line message")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def command(name: str, text: str, formatter: type[_Help] = _Help,
                **kwargs: Any) -> argparse.ArgumentParser:
        p = sub.add_parser(name, help=text, description=text, formatter_class=formatter, **kwargs)
        p.add_argument("--debug", action="store_true",
                       help="on an error, print the traceback before the one-line message")
        return p

    def add_json(p: argparse.ArgumentParser) -> None:
        p.add_argument("--json", action="store_true",
                       help="print one JSON document on stdout (logs go to stderr)")

    def add_stimulus(p: argparse.ArgumentParser, text: str) -> None:
        p.add_argument("--stimulus", action="append", default=[], metavar="FILE.py:NAME",
                       help=f"{text} (a Stimulus subclass or factory in FILE.py, or an "
                            "installed stealthfield.stimuli entry point); repeatable "
                            "(default: none)")

    def add_set(p: argparse.ArgumentParser) -> None:
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a config value (game/defaults.toml key), e.g. "
                            "--set world.view_range=6; repeatable (default: none)")

    def add_config(p: argparse.ArgumentParser) -> None:
        p.add_argument("--config", default=None, metavar="FILE.toml",
                       help="a TOML of config overrides in the dotted-key form of a preset's "
                            "[set], e.g. the best.toml of stealth tune (default: none)")

    p = command("levels", "paper Table 1 figures of levels")
    p.add_argument("level", nargs="*", default=[],
                   help="level files or bundled names (default: every bundled level)")
    add_json(p)
    p.set_defaults(func=_cmd_levels)

    p = command("validate", "check level files: exit 0, or one error line per bad file and exit 2")
    p.add_argument("level", nargs="+", help="level files or bundled names")
    add_stimulus(p, "load a plugin stimulus first, so its zone kinds are known")
    p.set_defaults(func=_cmd_validate)

    p = command("path", "navmesh (funnel) path between two points")
    p.add_argument("level", help="level file or bundled name")
    p.add_argument("--from", dest="from_", type=_point, required=True, metavar="X,Y",
                   help="start point in world units (required)")
    p.add_argument("--to", type=_point, required=True, metavar="X,Y",
                   help="goal point in world units (required)")
    add_json(p)
    p.set_defaults(func=_cmd_path)

    p = command("sim", "run one trial and print its metrics")
    p.add_argument("level", nargs="?", default=None,
                   help="level file or bundled name (not with --from)")
    p.add_argument("--from", dest="from_dir", default=None, metavar="DIR",
                   help="re-run a stored trial of the results directory DIR (with --trial)")
    p.add_argument("--trial", default=None, metavar="KEY",
                   help="key of the stored trial to re-run (the key column of trials.csv)")
    add_config(p)
    p.add_argument("--guards", choices=modes, metavar="MODE", default="pf",
                   help="guard mode: %(choices)s")
    p.add_argument("--player", choices=policies, metavar="POLICY", default="maxmin",
                   help="player policy: %(choices)s")
    p.add_argument("--abstraction", choices=abstractions, default="grid",
                   help="node graph the AI runs on")
    p.add_argument("--scenario", choices=scenarios, default="capture",
                   help="capture: ends at HP 0; fixed: respawn, always the full duration")
    p.add_argument("--seed", type=_seed, default=0, help="trial seed")
    add_set(p)
    add_json(p)
    p.add_argument("--trace", metavar="FILE", default=None,
                   help="write every AI tick as a JSON line to FILE (default: no trace)")
    p.add_argument("--explain", action="store_true",
                   help="add the first guard's decision explained to each trace line "
                        "(to stderr when no --trace)")
    add_stimulus(p, "add a stimulus (with --from: one the stored trial ran with, given again)")
    p.set_defaults(func=_cmd_sim)

    p = command("mechanics", "measured effects of the stealth mechanics (docs/mechanics.md)")
    p.add_argument("--seeds", type=int, default=30, help="paired seeds per mechanic")
    p.add_argument("--out", default="results/mechanics", help="directory for mechanics.md and .csv")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes, 1 = in-process (default: one per CPU)")
    p.add_argument("--level", default="miami", help="level file or bundled name")
    p.add_argument("--abstraction", choices=abstractions, default="grid",
                   help="node graph the AI runs on")
    add_stimulus(p, "measure this plugin stimulus against a paired control instead of the "
                    "built-in mechanics")
    p.set_defaults(func=_cmd_mechanics)

    p = command("presets", "list the bundled presets with their descriptions")
    add_json(p)
    p.set_defaults(func=cmd_presets)

    p = command("run", "run a sweep (resumable, parallel)")
    p.add_argument("--preset", default="smoke",
                   help="bundled preset name (see `stealth presets`) or a preset TOML file")
    p.add_argument("--out", default=None, help="results directory (default: results/PRESET)")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes, 1 = in-process (default: one per CPU)")
    p.add_argument("--scheduler", default=None,
                   help="address of a Dask scheduler to run the trials on, cluster extra (default: local processes)")
    p.add_argument("--seeds", type=int, default=None, metavar="N",
                   help="run seeds 0..N-1 instead of the preset's (more seeds grow a stored "
                        "design: only the missing trials run)")
    add_config(p)
    add_set(p)  # after --config's, as the preset's [set] is: e.g. --set world.engine=batch
    p.set_defaults(func=_cmd_run)

    p = command("tune", "search a parameter space with Optuna (resumable study)")
    p.add_argument("spec", metavar="SPEC.toml",
                   help="the design (a preset) with [search], [objective], seeds_train, "
                        "seeds_test (docs/experiments.md)")
    p.add_argument("--out", required=True, help="study directory (resumed when it exists)")
    p.add_argument("--trials", type=int, default=20,
                   help="Optuna trials the study should have in total")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes, 1 = in-process (default: one per CPU)")
    p.add_argument("--scheduler", default=None,
                   help="address of a Dask scheduler to run the trials on (default: local processes)")
    add_config(p)
    p.set_defaults(func=_cmd_tune)

    p = command("report", "tables, CSVs and figures of a results directory")
    p.add_argument("dir", help="results directory written by stealth run")
    p.set_defaults(func=_cmd_report)

    p = command("analyse", "analyses of results directories and reports (docs/experiments.md)")
    p.add_argument("analysis", choices=list(ANALYSES), metavar="NAME",
                   help="the analysis: %(choices)s")
    p.add_argument("words", nargs=argparse.REMAINDER, metavar="...",
                   help="its arguments, as for python -m headless.NAME (see stealth analyse "
                        "NAME --help)")
    p.set_defaults(func=_cmd_analyse)

    p = command("play", "play a level interactively", _PlayHelp, epilog=_KEYS)
    p.add_argument("level", nargs="?", default=None,
                   help="level file or bundled name (default: choose one in the window)")
    p.add_argument("--guards", choices=modes, metavar="MODE", default="pf",
                   help="guard mode: %(choices)s")
    p.add_argument("--abstraction", choices=abstractions, default="grid",
                   help="node graph the AI runs on")
    p.add_argument("--autopilot", choices=policies, metavar="POLICY", default=None,
                   help="let a player policy play (%(choices)s); a movement key takes over "
                        "(default: you play)")
    p.add_argument("--frames", type=int, default=None,
                   help="stop after N frames, one physics step each (default: play until Esc); "
                   "without a level the chooser, too, ends after N frames unless a level is chosen")
    p.add_argument("--screenshot", default=None, metavar="FILE.png",
                   help="save the last frame as PNG (default: none)")
    p.add_argument("--overlay", default="none",
                   help="initial field overlay, by key or name: " + ", ".join(
                       key if o is None else f"{key} ({o.aliases[0]})" if o.aliases else key
                       for key, o in OVERLAYS.items()))
    p.add_argument("--seed", type=_seed, default=0, help="seed of the guards' decisions")
    add_set(p)
    add_config(p)
    p.add_argument("--scenario", choices=scenarios, default="capture",
                   help="capture: game over at HP 0; fixed: respawn, play the full duration")
    p.add_argument("--mesh", action="store_true", help="start with the grid / navmesh shown")
    p.add_argument("--plans", action="store_true", help="start with the guards' plans shown")
    add_stimulus(p, "add a stimulus to the game")
    p.add_argument("--record", default=None, metavar="DIR",
                   help="store every game as a trial (player human) in the results store DIR")
    p.add_argument("--questions", action="store_true",
                   help="with --record (refused without it): ask three 1-5 ratings after each game")
    p.set_defaults(func=_cmd_play)

    p = command("replay", "replay a trace written by stealth sim --trace, or a stored trial")
    p.add_argument("trace", help="trace file (JSON lines), or a results directory with --trial")
    p.add_argument("--trial", default=None, metavar="KEY",
                   help="re-simulate and show the stored trial KEY of the results directory")
    p.add_argument("--level", default=None, help="level of the trace (default: the one the trace names)")
    p.add_argument("--frames", type=int, default=None,
                   help="stop after N frames (default: until Esc)")
    p.add_argument("--screenshot", default=None, metavar="FILE.png",
                   help="save the last frame as PNG (default: none)")
    p.add_argument("--abstraction", choices=abstractions, default=None,
                   help="graph the trace's node numbers refer to (default: detected)")
    p.add_argument("--scenario", choices=scenarios, default="capture",
                   help="scenario of the trace (sets the guards' view range drawn)")
    p.add_argument("--speed", type=float, default=1.0, help="playback speed factor")
    p.add_argument("--mesh", action="store_true", help="start with the grid / navmesh shown")
    p.add_argument("--plans", action="store_true", help="start with the guards' targets shown")
    add_stimulus(p, "with --trial: a plugin stimulus the stored trial ran with, given again")
    p.set_defaults(func=_cmd_replay)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one ``stealth`` command; returns its exit code (2 for any user error).

    Failures become one line in :func:`headless.commands.failure.guarded` (a user's mistake, an
    OSError naming its file, a file that is not a results store, Ctrl-C — also during the
    imports of start-up, which happen inside it). ``--debug`` anywhere before ``--`` also
    prints the traceback.
    """
    from .outputs import warning_lines

    words = list(sys.argv[1:] if argv is None else argv)
    warning_lines.install()

    def body() -> int:
        if signal.getsignal(signal.SIGINT) is _quiet_interrupt:  # imported: Ctrl-C is ours now
            signal.signal(signal.SIGINT, signal.default_int_handler)
        args = build_parser().parse_args(words)
        return int(args.func(args))

    return guarded(body, wants_debug(words))


if __name__ == "__main__":
    sys.exit(main())
