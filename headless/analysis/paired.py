"""Two results stores compared trial by trial: the difference a setting makes, with CIs.

``python -m headless.paired ARM_DIR CONTROL_DIR [--guards pf]`` pairs the trials of two
stores by (level, abstraction, guards, player, scenario, seed) — the same trial identity
run with and without a setting (e.g. ``paper-roles`` against ``paper``) — and prints a
Markdown table per Table 3 measure and abstraction: both means with 95 % bootstrap CIs and
the paired difference with its CI. Capture measures come from capture trials, the others
from fixed-time trials, as in Table 3; a trial without the event counts as 60 s.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..commands.failure import GuardedParser, guarded, wants_debug
from ..errors import UserError
from .stats import bootstrap_ci
from ..store import STORE_NAME, ResultStore

__all__ = ["MEASURES", "main", "paired_rows", "paired_table", "run"]

#: (Table 3 name, scenario, metric, value of a trial without the event)
MEASURES: tuple[tuple[str, str, str, float | None], ...] = (
    ("CaptureRate", "capture", "captured", None),
    ("CapturesInTime", "fixed", "captures", None),
    ("BacktrackCount", "fixed", "backtracks", None),
    ("FirstDetectTime", "fixed", "first_detect_time", 60.0),
)
_PAIR_KEY = ("level", "abstraction", "guards", "player", "scenario", "seed")


def _load(directory: Path, guards: str | None, across: bool = False,
          ) -> dict[tuple[Any, ...], Mapping[str, Any]]:
    """Trials by pair key (without the guard mode when pairing ``across`` modes)."""
    key = tuple(k for k in _PAIR_KEY if not (across and k == "guards"))
    with ResultStore(directory / STORE_NAME, readonly=True) as store:
        return {tuple(t[k] for k in key): t for t in store.trials()
                if guards is None or t["guards"] == guards}


def _value(trial: Mapping[str, Any], metric: str, missing: float | None,
           directory: Path) -> float:
    """The trial's ``metric``; a store written before the metric existed, or a trial
    without it, is a :class:`~headless.errors.UserError` naming the store."""
    value = trial.get(metric)
    if value is None:
        if missing is None:
            what = ("has no column" if metric not in trial
                    else f"trial {str(trial['key'])[:60]} has no value")
            raise UserError(f"{directory}: {what} for {metric} (a store of another version "
                            "or a failed trial); compare stores of the same version")
        return missing
    return float(value)


def paired_rows(arm: Path, control: Path, guards: str | None = None,
                control_guards: str | None = None) -> list[dict[str, Any]]:
    """Per measure and abstraction (and both together): pairs, means, CIs, difference.

    ``control_guards`` pairs the arm's ``guards`` trials with that mode's in the control.
    """
    if control_guards is not None and guards is None:
        raise UserError("control_guards needs guards")
    across = control_guards is not None
    a = _load(arm, guards, across)
    c = _load(control, control_guards if across else guards, across)
    scenario_at = _PAIR_KEY.index("scenario") - (1 if across else 0)
    keys = sorted(set(a) & set(c))
    if not keys:
        mode = "" if guards is None else f" of guard mode {guards!r}" + (
            f" and {control_guards!r}" if across else "")
        raise UserError(f"{arm} and {control}: no trial{mode} with the same level, "
                        "abstraction, player, scenario and seed in both")
    out = []
    for name, scenario, metric, missing in MEASURES:
        for env in (*sorted({k[1] for k in keys}), "both"):
            ks = [k for k in keys if k[scenario_at] == scenario and env in (k[1], "both")]
            x = np.array([_value(a[k], metric, missing, arm) for k in ks])
            y = np.array([_value(c[k], metric, missing, control) for k in ks])
            label = f"paired/{name}/{env}"
            out.append({"measure": name, "env": env, "pairs": len(ks),
                        "arm": (float(x.mean()) if len(x) else float("nan"),
                                bootstrap_ci(x, label + "/arm")),
                        "control": (float(y.mean()) if len(y) else float("nan"),
                                    bootstrap_ci(y, label + "/control")),
                        "difference": (float((x - y).mean()) if len(x) else float("nan"),
                                       bootstrap_ci(x - y, label + "/difference"))})
    return out


def paired_table(rows: Sequence[Mapping[str, Any]], arm: str = "arm",
                 control: str = "control") -> str:
    """The rows of :func:`paired_rows` with pairs as a Markdown table."""
    def cell(stat: tuple[float, tuple[float, float]], signed: bool = False) -> str:
        mean, (low, high) = stat
        fmt = "{:+.2f}" if signed else "{:.2f}"
        return f"{fmt.format(mean)} [{fmt.format(low)}, {fmt.format(high)}]"

    lines = [f"| measure | env | pairs | {arm} | {control} | difference |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['measure']} | {r['env']} | {r['pairs']} | {cell(r['arm'])} | "
              f"{cell(r['control'])} | {cell(r['difference'], signed=True)} |" for r in rows
              if r["pairs"]]  # a measure of a scenario neither store ran: no row
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m headless.paired``: its exit code; every failure one ``stealth: error:`` line
    (:func:`headless.commands.failure.guarded`, as for ``stealth``)."""
    words = list(sys.argv[1:] if argv is None else argv)
    return guarded(lambda: run(words), wants_debug(words))


def run(argv: Sequence[str], prog: str = "python -m headless.paired") -> int:
    """The analysis of the command line ``argv``, unguarded: :func:`main` guards it, and so
    does ``stealth analyse`` (``prog`` names the command in the help)."""
    parser = GuardedParser(prog=prog, description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("arm", type=Path, help="results directory of the arm")
    parser.add_argument("control", type=Path, help="results directory of the control")
    parser.add_argument("--guards", default=None, help="only trials of this guard mode")
    parser.add_argument("--control-guards", default=None,
                        help="pair with this guard mode's trials of the control (needs --guards)")
    parser.add_argument("--names", nargs=2, default=("arm", "control"),
                        metavar=("ARM", "CONTROL"), help="column titles")
    args = parser.parse_args(argv)
    for directory in (args.arm, args.control):
        if not (directory / STORE_NAME).is_file():
            print(f"stealth: error: {directory}: no {STORE_NAME} here", file=sys.stderr)
            return 2
    if args.control_guards is not None and args.guards is None:
        print("stealth: error: --control-guards needs --guards", file=sys.stderr)
        return 2
    rows = paired_rows(args.arm, args.control, args.guards, args.control_guards)
    sys.stdout.write(paired_table(rows, *args.names))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
