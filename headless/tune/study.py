"""``stealth tune SPEC.toml --out DIR``: a resumable Optuna study over the config (SPEC §10).

SPEC.toml is a preset (the design; its ``seeds`` are replaced) plus

* ``[search]`` — ``"key" = {low = , high = , log = false}`` (a float, or an int range when
  both bounds are whole numbers) or ``{choices = [...]}``, each a config key;
* ``[objective]`` — ``maximize = "EXPR"`` or ``minimize = "EXPR"`` (:mod:`headless.tune.expr`),
  optional ``constraints = ["EXPR <= N", ...]``; or ``target = "FILE.csv"`` (minimise the
  distance to a table, :mod:`headless.tune.objective`);
* ``seeds_train = N``, ``seeds_test = M``, optional ``sampler_seed`` (default 0).

Each Optuna trial runs the design on seeds 0…N−1 with its parameters as ``[set]`` values,
through the executors of the sweeps (:mod:`headless.executors`: in-process, a process pool
or Dask). The study lives in Optuna's SQLite storage ``DIR/study.db``: a killed study is
resumed by the same command (the trial that was running is marked failed and asked again).
The TPE sampler is re-seeded before each trial from ``sampler_seed`` and the number of
trials finished so far, so a study gives the same parameters whether it ran at once or
was interrupted and resumed. At the end the best feasible trial is re-evaluated on seeds
N…N+M−1 and ``best.toml`` (a ``--config`` file), ``study.csv``, ``report.md``,
``history.png`` and ``params.png`` are written.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from game.config_file import read_config_file, write_config_file
from game.errors import ConfigError
from game.trial import TrialSpec

from ..errors import SweepError, UserError
from ..engines import engine_tasks, split
from ..executors import InlineExecutor, connect_dask, process_pool, shutdown, terminate
from ..outputs.dirlock import DirectoryLock
from .expr import ExpressionError
from .objective import as_trials
from .spec import TuneSpec, load_tune_spec
from .study_file import STUDY_FILE, check_study_file, study_errors

__all__ = ["MAX_STUDY_TRIALS", "check_study_budget", "cmd_tune", "run_study"]

STUDY_NAME = "stealth-tune"
# --------------------------------------------------------------------------- evaluation
def evaluate(executor: Any, specs: Sequence[TrialSpec], parallelism: int,
             engine: str = "auto") -> list[dict[str, Any]]:
    """Run ``specs`` over ``executor`` on ``engine`` (``world.engine``: the batch engine's
    groups and pymunk's small batches, :func:`headless.engines.engine_tasks`) and return
    their rows as trials, in ``specs``' order; a failed trial raises :class:`SweepError`."""
    tasks = engine_tasks(split(specs, engine), parallelism,
                         inline=isinstance(executor, InlineExecutor))
    futures = [executor.submit(task, part) for task, part in tasks]
    order = {spec.key: i for i, spec in enumerate(specs)}
    rows = sorted((row for future in futures for row in future.result()),
                  key=lambda row: order[row["key"]])
    for row in rows:
        if row.get("error"):
            raise SweepError(f"trial {row['key']} failed: {row['error'].splitlines()[0]}")
    return as_trials(rows)


def _feasible(trial: Any) -> bool:
    return all(v <= 0 for v in trial.user_attrs.get("constraints", []))


def _best(study: Any, direction: str) -> Any:
    from optuna.trial import TrialState

    done = [t for t in study.get_trials(deepcopy=False, states=[TrialState.COMPLETE])
            if _feasible(t) and t.value is not None and math.isfinite(t.value)]
    if not done:
        return None
    sign = -1.0 if direction == "maximize" else 1.0
    return min(done, key=lambda t: (sign * t.value, t.number))


def run_study(spec: TuneSpec, out: Path, trials: int, *, workers: int | None = None,
              scheduler: str | None = None, stream: Any = None) -> Path:
    """Run the study until it has ``trials`` finished trials, then write its outputs."""
    try:
        import optuna
        from optuna.trial import TrialState
    except ImportError:
        raise UserError("stealth tune needs Optuna: pip install 'stealthfield[tune]'") from None
    stream = stream if stream is not None else sys.stderr
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: exists and is not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise SweepError(f"--out {out}: cannot create ({error.strerror or error})") from None
    with DirectoryLock(out, "study"), study_errors(out / STUDY_FILE):
        check_study_file(out / STUDY_FILE)
        return _run_study(optuna, TrialState, spec, out, trials, workers, scheduler, stream)


def _run_study(optuna: Any, TrialState: Any, spec: TuneSpec, out: Path, trials: int,
               workers: int | None, scheduler: str | None, stream: Any) -> Path:
    """:func:`run_study` once the study directory is locked and its file checked."""
    storage = f"sqlite:///{(out / STUDY_FILE).resolve()}"
    study = optuna.create_study(storage=storage, study_name=STUDY_NAME,
                                direction=spec.direction, load_if_exists=True)
    old = study.user_attrs.get("spec")
    if old is None:
        study.set_user_attr("spec", spec.text)
        study.set_user_attr("config_hash", spec.preset.config_hash)
    elif old != spec.text or study.user_attrs.get("config_hash") != spec.preset.config_hash:
        raise UserError(f"--out {out}: holds a study of another spec or config; use another "
                        "--out or delete that directory")
    for stale in study.get_trials(deepcopy=False, states=[TrialState.RUNNING]):
        study.tell(stale.number, state=TrialState.FAIL)  # killed mid-trial: asked again

    client, executor, parallelism = None, None, 1
    try:
        if scheduler:
            client, executor, parallelism = connect_dask(scheduler)
        elif (workers or os.cpu_count() or 1) == 1:
            executor = InlineExecutor()
        else:
            parallelism = workers or os.cpu_count() or 1
            executor = process_pool(parallelism)
        seeds = range(spec.seeds_train)
        failed_in_a_row = 0
        while True:
            finished = study.get_trials(deepcopy=False, states=[TrialState.COMPLETE])
            if len(finished) >= trials:
                break
            sampler = optuna.samplers.TPESampler(seed=spec.sampler_seed * 100_003 + len(finished))
            current = optuna.load_study(study_name=STUDY_NAME, storage=storage, sampler=sampler)
            trial = current.ask()
            values = {p.key: p.suggest(trial) for p in spec.params}
            try:
                rows = evaluate(executor, spec.specs(values, seeds), parallelism,
                                spec.preset.engine)
            except BaseException:
                current.tell(trial, state=TrialState.FAIL)
                raise
            try:
                value, cons, facts = spec.score(rows)
            except ExpressionError as error:  # e.g. a division by a metric that was 0
                current.tell(trial, state=TrialState.FAIL)
                failed_in_a_row = _failed(failed_in_a_row, trial.number, str(error), stream)
                continue
            trial.set_user_attr("constraints", cons)
            for number, amount in enumerate(cons):  # <= 0 holds; TPE prefers feasible trials
                trial.set_constraint(f"c{number}", amount)
            for name, fact in facts.items():
                trial.set_user_attr(name, fact)
            if not math.isfinite(value):
                current.tell(trial, state=TrialState.FAIL)
                failed_in_a_row = _failed(failed_in_a_row, trial.number, "objective is not a "
                                          "number (a metric without trials?)", stream)
                continue
            failed_in_a_row = 0
            current.tell(trial, value)
            stream.write(f"stealth: tune trial {trial.number} ({len(finished) + 1}/{trials}): "
                         f"{value:.6g} {json.dumps(values)}\n")
        best = _best(study, spec.direction)
        test = None
        if best is not None and spec.seeds_test:
            cached = study.user_attrs.get("test")
            if cached and cached.get("trial") == best.number:
                test = cached
            else:
                held = range(spec.seeds_train, spec.seeds_train + spec.seeds_test)
                rows = evaluate(executor, spec.specs(best.params, held), parallelism,
                                spec.preset.engine)
                held_value, held_cons, held_facts = spec.score(rows)
                test = {"trial": best.number, "value": held_value, "constraints": held_cons,
                        **held_facts}
                study.set_user_attr("test", test)
    except KeyboardInterrupt:
        if executor is not None:
            terminate(executor)  # the pool's workers ignore Ctrl-C: end them now
            executor = None
        raise
    finally:
        if executor is not None:
            shutdown(executor)
        if client is not None:
            client.close()
    from .report import write_study_outputs

    write_study_outputs(spec, study, best, test, out)
    return out


MAX_FAILED_IN_A_ROW = 20
"""Trials in a row without an objective value after which a study stops (one line)."""


def _failed(count: int, number: int, why: str, stream: Any) -> int:
    """Report a trial without a value; :class:`UserError` after too many in a row (a study
    whose objective can never be computed would otherwise ask for ever)."""
    stream.write(f"stealth: tune trial {number}: {why}\n")
    if count + 1 >= MAX_FAILED_IN_A_ROW:
        raise UserError(f"{MAX_FAILED_IN_A_ROW} tune trials in a row gave no objective value; "
                        f"the last: {why}")
    return count + 1


MAX_STUDY_TRIALS = 10_000
"""Most Optuna trials one study may ask for (``--trials``): the bundled designer-pf study
(100 trials of 1,200 steps per Optuna trial) fits the step budget 16,000 times."""


def _worst(spec: TuneSpec, key: str, config: Mapping[str, Any], largest: bool) -> Any:
    """The largest (or smallest) value ``key`` takes in the study: its search range's end
    or choice when it is searched, else the design's value."""
    for p in spec.params:
        if p.key == key:
            values = [float(v) for v in (p.choices if p.choices else (p.low, p.high))]
            return max(values) if largest else min(values)
    return config[key]


def check_study_budget(spec: TuneSpec, trials: int) -> None:
    """Refuse a study whose ``trials`` × physics steps exceed the sweeps' budget (:func:`game.budget.check_design_steps`: every Optuna
    trial runs the design on the training seeds, the best one the test seeds); a searched
    ``world.duration`` or ``world.physics_step`` counts at its costliest end."""
    from game.budget import check_design_steps
    from game.config import Config

    preset = spec.preset
    config = Config.load(dict(preset.overrides)).as_dict()
    config["world.duration"] = _worst(spec, "world.duration", config, largest=True)
    config["world.physics_step"] = _worst(spec, "world.physics_step", config, largest=False)
    per_cell = trials * spec.seeds_train + spec.seeds_test
    cells = preset.n_trials // len(preset.seeds)  # level × abstraction × ... × factor levels
    try:  # check_design_steps multiplies by the factor levels itself
        check_design_steps(cells // math.prod(len(v) for _, v in preset.factors) * per_cell,
                           config, preset.factors)
    except ConfigError as error:
        count = f"the study's {per_cell * cells:,} trials"
        raise UserError(f"--trials {trials}: " + str(error).replace(
            "the design's trials", count).replace("use fewer seeds", "use fewer --trials, seeds")
                        ) from None


def cmd_tune(args: argparse.Namespace) -> int:
    """``stealth tune SPEC.toml --out DIR [--trials N] [--workers N] [--config FILE]``."""
    if not 1 <= args.trials <= MAX_STUDY_TRIALS:
        raise UserError(f"--trials: expected a number of trials in [1, {MAX_STUDY_TRIALS}], "
                        f"got {args.trials}")
    if args.workers is not None and args.workers < 1:
        raise UserError(f"--workers: must be at least 1, got {args.workers}")
    from ..outputs.clobber import refuse_inputs_all

    refuse_inputs_all("--out", [Path(args.out) / name for name in (
        "best.toml", "study.csv", "report.md", "history.png", "params.png", "results.lock")],
                      [args.spec, args.config])
    extra = read_config_file(args.config) if args.config else None
    out = Path(args.out)
    from ..store import STORE_NAME

    if (out / STORE_NAME).exists():
        raise UserError(f"--out {out}: holds a results store ({STORE_NAME} of stealth run); "
                        "a study needs a directory of its own")
    spec = load_tune_spec(args.spec, extra)
    check_study_budget(spec, args.trials)
    run_study(spec, out, args.trials, workers=args.workers, scheduler=args.scheduler)
    print(f"stealth: study in {out}: best.toml, study.csv, report.md", file=sys.stderr)
    return 0


