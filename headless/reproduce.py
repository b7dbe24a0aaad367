"""Any stored trial, again: ``stealth sim --from DIR --trial KEY`` (and ``replay --trial``).

A row of ``DIR/results.sqlite`` holds the whole identity of its trial — level file, mode,
policy, scenario, seed, root seed, ``[set]`` overrides and factor values — so the
:class:`~game.trial.TrialSpec` is rebuilt from it alone (the preset need not exist any
more) and, trials being pure functions of their spec, re-running it gives the stored
metrics bit for bit. The rebuilt spec's key must equal the stored key, or the store was
written by code whose identity differs, and that is said rather than run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from game.trial import TrialSpec

from .errors import UserError
from .store import STORE_NAME, ResultStore, StoredTrial, stored_value

__all__ = ["cmd_sim_from", "same_metrics", "stored_spec", "stored_trial"]


def stored_trial(directory: str | Path, key: str) -> StoredTrial:
    """The finished trial ``key`` of a results directory (one-line error when absent)."""
    path = Path(directory) / STORE_NAME
    if not path.is_file():
        raise UserError(f"{directory}: no {STORE_NAME} here (a results directory of `stealth run`)")
    with ResultStore(path, readonly=True) as store:
        for trial in store.trials():
            if trial["key"] == key:
                return trial
    raise UserError(f"--trial {key}: no finished trial with this key in {path} "
                    "(the keys are the key column of trials.csv)")


def spec_of(trial: StoredTrial) -> TrialSpec:
    """The identity of a stored trial."""
    spec = TrialSpec(
        level=trial["level_ref"], abstraction=trial["abstraction"], guards=trial["guards"],
        player=trial["player"], scenario=trial["scenario"], seed=int(trial["seed"]),
        overrides=tuple(sorted(trial["overrides"].items())),
        root_seed=int(trial["root_seed"]),
        factors=tuple(sorted(trial.get("factors", {}).items())),
    )
    if spec.key != trial["key"]:
        raise UserError(f"--trial {trial['key']}: the stored row rebuilds as {spec.key}; "
                        "the store was written by another version of the trial identity")
    return spec


def stored_spec(directory: str | Path, key: str) -> TrialSpec:
    """The :class:`TrialSpec` of the stored trial ``key`` of ``directory``."""
    return spec_of(stored_trial(directory, key))


def same_metrics(trial: StoredTrial, metrics: dict[str, Any]) -> list[str]:
    """Names of the metrics whose re-run value differs from the stored one (none: identical)."""
    stored = {**trial.get("extra_metrics", {}), **trial}
    return [name for name, value in metrics.items()
            if name in stored and stored_value(stored[name]) != stored_value(value)]


def cmd_sim_from(args: argparse.Namespace) -> int:
    """``stealth sim --from DIR --trial KEY``: re-run one stored trial, print its metrics.

    Exit code 1 (and a line on stderr) if any metric differs from the stored row.
    """
    from game.trial import run_trial, sim_document

    if args.from_dir is None or args.trial is None:
        raise UserError("sim: --from DIR and --trial KEY go together")
    if args.level is not None or args.set or args.config or args.stimulus:
        raise UserError("sim --from: the stored trial says what runs; drop LEVEL, --set, "
                        "--config and --stimulus")
    trial = stored_trial(args.from_dir, args.trial)
    spec = spec_of(trial)
    if args.trace:
        from .outputs.clobber import level_file, open_output, plugin_files

        handle = open_output("--trace", args.trace, [
            Path(args.from_dir) / STORE_NAME, level_file(spec.level),
            *plugin_files(spec.stimuli)])
        with handle:
            row = run_trial(spec, trace=handle, explain=args.explain)
    else:
        row = run_trial(spec)
    document = sim_document(row)
    document["key"] = spec.key
    if spec.factors:
        document["factors"] = dict(spec.factors)
    if args.json:
        import json

        json.dump(document, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(f"{spec.key}")
        for key, value in document["metrics"].items():
            print(f"  {key:<22} {value}")
    differ = same_metrics(trial, row["metrics"])
    if differ:
        print(f"stealth: the re-run differs from the stored row in {', '.join(differ)}",
              file=sys.stderr)
        return 1
    print("stealth: metrics identical to the stored row", file=sys.stderr)
    return 0
