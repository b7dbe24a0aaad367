"""Any stored trial, again: ``stealth sim --from DIR --trial KEY`` (and ``replay --trial``).

A row of ``DIR/results.sqlite`` holds the whole identity of its trial — level file, mode,
policy, scenario, seed, root seed, ``[set]`` overrides and factor values — so the
:class:`~game.trial.TrialSpec` is rebuilt from it alone (the preset need not exist any
more) and, trials being pure functions of their spec, re-running it gives the stored
metrics bit for bit. The rebuilt spec's key must equal the stored key, or the store was
written by code whose identity differs, and that is said rather than run.

A trial that ran with plugin stimuli (``--stimulus FILE.py:NAME``) names them in its key,
but a store never makes code run by naming it: they must be given again (``--stimulus``,
the same plugins in the same order; a path may be relative where the key's is absolute),
and a missing one is said in one line. Metrics that an
older store has no column for are not compared.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from game.trial import TrialSpec

from .errors import UserError
from .store import STORE_NAME, ResultStore, StoredTrial, stored_value

__all__ = ["cmd_sim_from", "same_metrics", "stored_spec", "stored_trial"]


def stored_trial(directory: str | Path, key: str) -> StoredTrial:
    """The finished trial ``key`` of a results directory (one-line error when absent);
    the metrics of a store older than their columns are left out, not given as None."""
    path = Path(directory) / STORE_NAME
    if not path.is_file():
        raise UserError(f"{directory}: no {STORE_NAME} here (a results directory of `stealth run`)")
    with ResultStore(path, readonly=True) as store:
        for trial in store.trials():
            if trial["key"] == key:
                for metric in store.metrics:
                    if metric.name not in store.metric_names:  # the file never had it
                        del trial[metric.name]
                return trial
    raise UserError(f"--trial {key}: no finished trial with this key in {path} "
                    "(the keys are the key column of trials.csv)")


def spec_of(trial: StoredTrial, stimuli: Sequence[str] = ()) -> TrialSpec:
    """The identity of a stored trial, with the plugin ``stimuli`` the user gave again."""
    spec = TrialSpec(
        level=trial["level_ref"], abstraction=trial["abstraction"], guards=trial["guards"],
        player=trial["player"], scenario=trial["scenario"], seed=int(trial["seed"]),
        overrides=tuple(sorted(trial["overrides"].items())),
        root_seed=int(trial["root_seed"]),
        stimuli=tuple(stimuli),
        factors=tuple(sorted(trial.get("factors", {}).items())),
    )
    if spec.key != trial["key"]:
        recorded = _recorded_stimuli(trial["key"], spec)
        if stimuli and replace(spec, stimuli=()).key == trial["key"]:
            raise UserError(f"--trial {trial['key']}: it ran without plugin stimuli; "
                            "drop --stimulus")
        if recorded is not None and len(recorded) == len(stimuli) and all(
                _same_plugin(g, r) for g, r in zip(stimuli, recorded)):
            return replace(spec, stimuli=recorded)  # the same files, named another way
        if recorded is not None:
            given = " ".join(stimuli) or "none"
            raise UserError(f"--trial {trial['key']}: it ran with the plugin stimuli "
                            f"{' '.join(recorded)} (given: {given}); give them again, "
                            f"{' '.join('--stimulus ' + r for r in recorded)} (a stored "
                            "trial never runs code its store names)")
        raise UserError(f"--trial {trial['key']}: the stored row rebuilds as {spec.key}; "
                        "the store was written by another version of the trial identity")
    return spec


def _same_plugin(given: str, recorded: str) -> bool:
    """Whether two plugin references name the same thing: equal, or ``FILE.py:NAME`` with
    the same NAME and the same file (a preset stores its plugins' paths made absolute)."""
    if given == recorded:
        return True
    (a, sep_a, name_a), (b, sep_b, name_b) = given.rpartition(":"), recorded.rpartition(":")
    if not (sep_a and sep_b and a.endswith(".py") and b.endswith(".py") and name_a == name_b):
        return False
    return Path(a).expanduser().resolve() == Path(b).expanduser().resolve()


def _recorded_stimuli(key: str, spec: TrialSpec) -> tuple[str, ...] | None:
    """The plugin stimuli stored ``key`` names (None when it names none, or the rest of
    it does not match ``spec``): the part between ``spec``'s key without stimuli and its
    factors (:attr:`game.trial.TrialSpec.key`)."""
    plain = replace(spec, stimuli=()).key
    cut = len(replace(spec, stimuli=(), factors=()).key)
    head, tail, mark = plain[:cut], plain[cut:], "/stimuli="
    if not (key.startswith(head + mark) and key.endswith(tail)) or len(key) <= len(plain) + len(mark):
        return None
    recorded = tuple(key[cut + len(mark):len(key) - len(tail)].split("+"))
    return recorded if replace(spec, stimuli=recorded).key == key else None


def stored_spec(directory: str | Path, key: str, stimuli: Sequence[str] = ()) -> TrialSpec:
    """The :class:`TrialSpec` of the stored trial ``key`` of ``directory`` (its plugin
    ``stimuli`` given again by the user)."""
    return spec_of(stored_trial(directory, key), stimuli)


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
    if args.level is not None or args.set or args.config:
        raise UserError("sim --from: the stored trial says what runs; drop LEVEL, --set "
                        "and --config")
    trial = stored_trial(args.from_dir, args.trial)
    spec = spec_of(trial, args.stimulus)  # plugin stimuli: only those the user gives again
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
