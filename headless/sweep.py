"""Sweeps: a preset expanded to trials, mapped over an executor, resumable (``stealth run``).

The sweep expands a :class:`~headless.presets.Preset` to :class:`~game.trial.TrialSpec`
objects in a fixed order (seeds outermost, so a half-finished sweep is a balanced design
with fewer seeds), skips the trials already in the store, and maps
:func:`~headless.executors.run_batch` (a few trials per task, to amortise pickling) over a
``concurrent.futures`` executor from :mod:`headless.executors`: in-process for
``--workers 1``, a process pool, or a Dask cluster's ``Client.get_executor()``. The main
process is the only writer of the store and commits each trial as soon as it arrives, so
a killed sweep is resumed by running the same command again; :mod:`headless.progress`
draws the bar.

The engine (``world.engine``, :mod:`headless.engines`) assigns the pending trials before
anything is written: ``batch`` refuses a trial it does not cover (one line, exit 2),
``auto`` (the default) runs the covered ones on the batch engine and the rest on pymunk,
and the first line says which. A batch-engine task is
:func:`~headless.executors.run_engine_batch` over up to ``game.batch.MAX_BATCH`` trials that
share level, abstraction, overrides and factors (:func:`headless.engines.batch_tasks`).
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import os
import shlex
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any

from game.config import parse_overrides
from game.config_file import read_config_file
from game.trial import TrialSpec
from navmesh.level import zone_kinds

from .outputs.dirlock import DirectoryLock
from .errors import SweepError
from .engines import Split, engine_tasks, split
from .estimate import MEASURED_DURATION, duration_text, estimate_seconds
from .executors import (
    InlineExecutor,
    check_workers,
    connect_dask,
    process_pool,
    shutdown,
    terminate,
)
from .outputs.filenames import output_path
from .growth import design_change, design_trials, grown_design
from .presets import Preset, load_preset
from .progress import Progress
from .store import STORE_NAME, ResultStore

__all__ = ["SweepResult", "cmd_run", "run_sweep"]



@dataclass
class SweepResult:
    """What one ``stealth run`` did."""

    total: int
    skipped: int
    finished: int = 0
    failed: int = 0
    elapsed: float = 0.0
    interrupted: bool = False
    aborted: str | None = None
    first_error: str | None = None
    store: Path = field(default_factory=Path)

    @property
    def rate(self) -> float:
        """Trials (finished or failed) per second of wall time in this run."""
        ran = self.finished + self.failed
        return ran / self.elapsed if self.elapsed > 0 else 0.0

    def summary(self) -> str:
        """The one-line summary printed at the end of a sweep."""
        text = (f"{self.finished} finished, {self.failed} failed, {self.skipped} skipped "
                f"(already in the store) of {self.total} trials in {self.elapsed:.1f} s "
                f"({self.rate:.1f} trials/s) -> {self.store}")
        if self.first_error:
            text += f"; first error: {self.first_error}"
        return text


def _pending(specs: list[TrialSpec], store_path: Path) -> list[TrialSpec]:
    """The ``specs`` not yet finished in the store at ``store_path`` (read only: nothing is
    written), all of them when there is no store yet."""
    if not store_path.is_file():
        return specs
    with ResultStore(store_path, readonly=True) as store:
        done = store.done_keys() if store.meta() else set()
    return [s for s in specs if s.key not in done]


def level_digests(preset: Preset) -> dict[str, str]:
    """The SHA-256 of every level file of the design (``Level.digest``), by level reference."""
    from navmesh.level import cached_level

    return {ref: cached_level(ref).digest or "" for ref in preset.levels}


def _check_levels(store_path: Path, stored: str | None, current: dict[str, str],
                  preset: Preset) -> None:
    """Refuse to resume when a level file changed since the store's trials ran on it.

    A store from before level digests were kept has none: it resumes, and gets them.
    """
    if stored is None:
        return
    old = json.loads(stored)
    names = dict(zip(preset.levels, preset.level_names))
    for ref, digest in current.items():
        if ref in old and old[ref] != digest:
            raise SweepError(
                f"{store_path}: level {names.get(ref, ref)!r} ({ref}) changed since its trials "
                f"ran (sha256 {old[ref][:12]} then, {digest[:12]} now); restore the file or "
                "use another --out")


def _check_store(store_path: Path, preset: Preset, digests: dict[str, str]) -> None:
    """Refuse to resume into a store that holds a different design, configuration or levels."""
    if not store_path.is_file():
        return
    try:
        with ResultStore(store_path, readonly=True) as store:
            meta = store.meta()
    except Exception as error:
        raise SweepError(f"{store_path}: not a readable results store ({error})") from None
    old = meta.get("design")
    change = design_change(json.loads(old), preset.design()) if old is not None else None
    if change is not None:
        raise SweepError(
            f"{store_path}: holds results of a different design (preset "
            f"{meta.get('preset_name', '?')!r}; {change} differ, and only seeds and factor "
            "levels may grow); use another --out or delete that directory")
    old_hash = meta.get("config_hash")
    if old_hash is not None and old_hash != preset.config_hash:
        raise SweepError(
            f"{store_path}: its trials ran with config {old_hash}, the current config is "
            f"{preset.config_hash} (a default or the preset's [set] changed); "
            "use another --out")
    _check_levels(store_path, meta.get("level_digests"), digests, preset)


def run_sweep(
    preset: Preset,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    stream: IO[str] | None = None,
) -> SweepResult:
    """Run every trial of ``preset`` that is not yet in ``out/results.sqlite``.

    ``workers=1`` runs in this process; otherwise a process pool of ``workers`` (default:
    the number of CPUs); with ``scheduler`` a Dask cluster at that address. Ctrl-C does not
    raise: the result comes back with ``interrupted=True`` after the running tasks' trials
    are committed. Problems found before anything is written raise :class:`UserError`.
    """
    stream = stream if stream is not None else sys.stderr
    out = Path(out)
    workers = check_workers(workers or os.cpu_count() or 1)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {out}: exists and is not a directory")
    from .tune.study_file import STUDY_FILE

    if (out / STUDY_FILE).exists():  # the converse of tune's refusal of a results store
        raise SweepError(f"--out {out}: holds a study ({STUDY_FILE} of stealth tune); a "
                         "results store needs a directory of its own")
    store_path = out / STORE_NAME
    digests = level_digests(preset)
    _check_store(store_path, preset, digests)
    # before anything is written: the batch engine refuses a trial it does not cover
    engines = split(_pending(preset.specs(), store_path), preset.engine)
    client: Any = None
    executor: cf.Executor | None = None
    lock: DirectoryLock | None = None
    store: ResultStore | None = None
    try:
        if scheduler:
            client, executor, parallelism = connect_dask(scheduler)
        elif workers == 1:
            executor, parallelism = InlineExecutor(), 1
        else:
            parallelism = workers  # the pool is started below, once there is work
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise SweepError(f"--out {out}: cannot create ({error.strerror or error})") from None
        lock = DirectoryLock(out)
        if progress:
            factors = "".join(f" x {len(levels)} {key}" for key, levels in preset.factors)
            stream.write(f"stealth: preset {preset.name}: {preset.n_trials} trials "
                         f"({len(preset.levels)} levels x {len(preset.abstractions)} "
                         f"abstractions x {len(preset.guards)} guard modes x "
                         f"{len(preset.players)} player policies x {len(preset.scenarios)} "
                         f"scenarios{factors} x {len(preset.seeds)} seeds) -> {out}"
                         f" ({engines.describe()})\n")
        store = ResultStore(store_path)
        now = datetime.now(timezone.utc).isoformat(timespec="seconds")
        old_design = store.get_meta("design")
        design = (grown_design(json.loads(old_design), preset.design()) if old_design
                  else preset.design())
        meta = {
            "preset_name": preset.name, "preset_source": preset.source,
            "preset_toml": preset.text, "design": json.dumps(design),
            "config_hash": preset.config_hash, "total_trials": str(design_trials(design)),
            "config": json.dumps(dict(preset.config), sort_keys=True),
            "level_digests": json.dumps(digests, sort_keys=True),
            # what a report needs of the plugins, as data: it never imports them
            "zone_kinds": json.dumps(list(zone_kinds())),
            "updated_at": now,
        }
        if store.get_meta("created_at") is None:
            meta["created_at"] = now
        store.set_meta(meta)

        specs = preset.specs()
        done = store.done_keys()
        todo = [s for s in specs if s.key not in done]
        result = SweepResult(total=len(specs), skipped=len(specs) - len(todo), store=store_path)
        if not todo:
            return result
        if result.skipped and progress:
            stream.write(f"resuming: {result.skipped} of {len(specs)} trials already in "
                         f"{store_path}, {len(todo)} to run\n")
        todo_keys = {s.key for s in todo}
        engines.batch = [s for s in engines.batch if s.key in todo_keys]
        engines.pymunk = [s for s in engines.pymunk if s.key in todo_keys]
        if progress:
            _write_estimate(stream, preset, engines, parallelism)
        if executor is None:
            executor = process_pool(workers)
        inline = isinstance(executor, InlineExecutor)
        in_flight = 1 if inline else 2 * parallelism
        tasks = engine_tasks(engines, parallelism, inline=inline)
        bar = Progress(len(todo), stream, enabled=progress)
        started = time.monotonic()
        try:
            _drive(executor, tasks, in_flight, store, preset, result, bar)
        finally:
            result.elapsed = time.monotonic() - started
            bar.close()
        return result
    finally:
        if executor is not None:
            shutdown(executor)
        if client is not None:
            client.close()
        if store is not None:
            store.close()
        if lock is not None:
            lock.close()


def _write_estimate(stream: IO[str], preset: Preset, engines: Split, workers: int) -> None:
    """One line: the expected wall time of the trials to run (:mod:`headless.estimate`)."""
    names = dict(zip(preset.levels, preset.level_names))

    def cells(specs: list[TrialSpec]) -> Iterator[tuple[str, str, str]]:
        return ((names.get(s.level, s.level), s.abstraction, s.scenario) for s in specs)

    seconds = estimate_seconds(cells(engines.pymunk), workers,
                               float(preset.config.get("world.duration", MEASURED_DURATION)),
                               cells(engines.batch))
    count = len(engines.pymunk) + len(engines.batch)
    stream.write(f"stealth: estimate: about {duration_text(seconds)} for {count} trials on "
                 f"{workers} worker{'s' if workers != 1 else ''} (per-trial times measured "
                 "on 2 vCPUs; the ETA below then uses the real rate)\n")


def _record(rows: Iterable[dict[str, Any]], store: ResultStore, result: SweepResult,
            bar: Progress) -> None:
    finished = failed = 0
    for row in rows:
        if row.get("error"):
            failed += 1
            if result.first_error is None:
                result.first_error = f"{row['key']}: {row['error'].splitlines()[0]}"
        else:
            finished += 1
        store.add(row)
    result.finished += finished
    result.failed += failed
    bar.update(finished + failed, failed)


class _TaskError(Exception):
    """A task raised as a whole (not a trial): the sweep stops, the store keeps its rows."""

    def __init__(self, error: BaseException) -> None:
        super().__init__(str(error))
        self.error = error


def _drive(executor: cf.Executor,
           tasks: Iterator[tuple[Callable[..., list[dict[str, Any]]], list[TrialSpec]]],
           in_flight: int, store: ResultStore, preset: Preset, result: SweepResult,
           bar: Progress) -> None:
    """Keep at most ``in_flight`` tasks submitted (each a function over its trials:
    ``run_batch``, or ``run_engine_batch`` on the batch engine); commit every result as it
    arrives."""
    pending: dict[cf.Future[Any], list[TrialSpec]] = {}
    names = dict(zip(preset.levels, preset.level_names))  # for the rows of failed trials

    def collect(future: cf.Future[Any]) -> None:
        pending.pop(future)
        error = future.exception()
        if error is not None:
            # a task never raises for a failing trial, so this is the machinery: a
            # worker process died, the cluster cannot import the project, pickling failed.
            raise _TaskError(error)
        _record(future.result(), store, result, bar)

    try:
        exhausted = False
        while True:
            while not exhausted and len(pending) < in_flight:
                item = next(tasks, None)
                if item is None:
                    exhausted = True
                    break
                task, batch = item
                pending[executor.submit(task, batch, names)] = batch
            if not pending:
                break
            done, _ = cf.wait(list(pending), timeout=1.0, return_when=cf.FIRST_COMPLETED)
            for future in done:
                collect(future)
            bar.update(0)
    except KeyboardInterrupt:
        result.interrupted = True
        for future in pending:
            future.cancel()
        _drain(pending, collect, executor)
    except _TaskError as failure:
        error = failure.error
        what = "a worker process died" if isinstance(error, cf.BrokenExecutor) else "a task failed"
        text = " ".join(f"{type(error).__name__}: {error}".split())
        result.aborted = f"{what} ({text[:300]}); the trials finished so far are kept"
        for future in list(pending):
            if not future.cancel() and future.done() and future.exception() is None:
                collect(future)  # finished before the failure was seen: keep it
        if isinstance(executor, cf.ProcessPoolExecutor):
            executor.shutdown(wait=False, cancel_futures=True)
    else:
        if isinstance(executor, cf.ProcessPoolExecutor):
            executor.shutdown(wait=True)


def _drain(pending: dict[cf.Future[Any], list[TrialSpec]],
           collect: Callable[[cf.Future[Any]], None], executor: cf.Executor,
           timeout: float = 10.0) -> None:
    """After Ctrl-C: commit what the running tasks finish (a second Ctrl-C stops at once)."""
    try:
        running = [f for f in pending if not f.cancelled()]
        done, _ = cf.wait(running, timeout=timeout)
        for future in done:
            if future in pending and not future.cancelled():
                try:
                    collect(future)
                except _TaskError:
                    pass
    except KeyboardInterrupt:
        pass
    finally:
        terminate(executor)  # our own pool's workers, still busy after the wait


# =========================================================================== command
def _resume_command(args: argparse.Namespace, out: Path) -> str:
    words = ["stealth", "run", "--preset", args.preset, "--out", str(out)]
    if args.seeds is not None:
        words += ["--seeds", str(args.seeds)]
    if args.config:
        words += ["--config", args.config]
    for item in getattr(args, "set", None) or ():
        words += ["--set", item]
    if args.workers:
        words += ["--workers", str(args.workers)]
    if args.scheduler:
        words += ["--scheduler", args.scheduler]
    return " ".join(shlex.quote(w) for w in words)


def cmd_run(args: argparse.Namespace) -> int:
    """``stealth run``: validate the preset, run the missing trials, print a summary line.

    Exit codes: 0 all done, 1 some trial failed or a worker died, 2 a user error (nothing
    written; raised as a :class:`~navmesh.errors.StealthError` for the CLI to print), 130
    interrupted (the store keeps every committed trial; rerun to resume).
    """
    if args.workers is not None:
        check_workers(args.workers)
    extra = {**(read_config_file(args.config) if args.config else {}),
             **dict(parse_overrides(getattr(args, "set", None) or ()))}
    preset = load_preset(args.preset, extra or None)
    if args.seeds is not None:
        preset = preset.with_seeds(args.seeds)
    out = Path(args.out) if args.out else output_path("results", preset.name)
    stderr = sys.stderr
    result = run_sweep(preset, out, workers=args.workers, scheduler=args.scheduler)
    if result.interrupted:
        stderr.write(f"stealth: interrupted: {result.finished + result.failed} trials were "
                     f"committed in this run, {result.skipped + result.finished} of "
                     f"{result.total} are in {result.store}; resume with: "
                     f"{_resume_command(args, out)}\n")
        return 130
    if result.aborted:
        stderr.write(f"stealth: error: {result.aborted}; resume with: "
                     f"{_resume_command(args, out)}\n")
        return 1
    if result.finished == 0 and result.failed == 0:
        stderr.write(f"stealth: nothing to do: all {result.total} trials are in "
                     f"{result.store}\n")
        return 0
    stderr.write(f"stealth: {result.summary()}\n")
    if result.failed:
        stderr.write("stealth: failed trials are kept with their error text and are retried "
                     f"by the next run; `stealth report {out}` lists them in failed.csv\n")
        return 1
    return 0
