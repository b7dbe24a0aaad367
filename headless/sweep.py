"""Sweeps: a preset expanded to trials, mapped over an executor, resumable (``stealth run``).

A **preset** is a TOML file (``headless/presets/NAME.toml`` or the user's own) naming the
levels, abstractions, guard modes, player policies, scenarios and seeds of a full factorial
design, an optional ``root_seed`` and an optional ``[set]`` table of config overrides. It is
validated completely before anything runs or is written.

The sweep expands the preset to :class:`~game.trial.TrialSpec` objects in a fixed order
(seeds outermost, so a half-finished sweep is a balanced design with fewer seeds), skips the
trials already in the store, and maps :func:`run_batch` (a few trials per task, to amortise
pickling) over a ``concurrent.futures`` executor: a ``ProcessPoolExecutor``, an in-process
executor for ``--workers 1``, or a Dask cluster's ``Client.get_executor()``. The main
process is the only writer of the store and commits each trial as soon as it arrives, so
a killed sweep is resumed by running the same command again.

>>> preset = load_preset("smoke")  # doctest: +SKIP
>>> len(preset.specs())            # doctest: +SKIP
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import os
import shlex
import signal
import sys
import time
import tomllib
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any

from game.trial import TrialSpec, run_trial

from .cli import UserError
from .store import STORE_NAME, ResultStore

__all__ = [
    "PRESETS_DIR",
    "Preset",
    "Progress",
    "SweepResult",
    "bundled_preset_names",
    "cmd_run",
    "load_preset",
    "parse_preset",
    "run_batch",
    "run_one",
    "run_sweep",
]

PRESETS_DIR = Path(__file__).resolve().parent / "presets"
"""Folder of the bundled presets."""

_LIST_FIELDS = ("levels", "abstractions", "guards", "players", "scenarios")
_ALLOWED_KEYS = (*_LIST_FIELDS, "seeds", "root_seed", "set", "description")
_MAX_BATCH = 8  # trials per task: ~0.3-0.5 s of work, pickling overhead negligible


# =========================================================================== presets
@dataclass(frozen=True)
class Preset:
    """A validated experiment design (see the module docstring and docs/experiments.md)."""

    name: str
    source: str
    text: str
    levels: tuple[str, ...]
    level_names: tuple[str, ...]
    abstractions: tuple[str, ...]
    guards: tuple[str, ...]
    players: tuple[str, ...]
    scenarios: tuple[str, ...]
    seeds: tuple[int, ...]
    root_seed: int = 0
    overrides: tuple[tuple[str, Any], ...] = ()
    description: str = ""
    config_hash: str = ""
    #: every config value the sweep's trials run with (defaults + the preset's [set])
    config: Mapping[str, Any] = field(default_factory=dict)

    @property
    def n_trials(self) -> int:
        """Number of trials of the full design."""
        n = len(self.seeds)
        for name in _LIST_FIELDS:
            n *= len(getattr(self, name))
        return n

    def specs(self) -> list[TrialSpec]:
        """Every trial of the design, in the sweep's deterministic order (seeds outermost)."""
        return [
            TrialSpec(level=level, abstraction=abstraction, guards=guards, player=player,
                      scenario=scenario, seed=seed, overrides=self.overrides,
                      root_seed=self.root_seed)
            for seed in self.seeds
            for level in self.levels
            for abstraction in self.abstractions
            for guards in self.guards
            for player in self.players
            for scenario in self.scenarios
        ]

    def design(self) -> dict[str, Any]:
        """The design as JSON-able data (stored in the results' ``meta`` table)."""
        return {
            "levels": list(self.levels),
            "level_names": list(self.level_names),
            "abstractions": list(self.abstractions),
            "guards": list(self.guards),
            "players": list(self.players),
            "scenarios": list(self.scenarios),
            "seeds": list(self.seeds),
            "root_seed": self.root_seed,
            "set": {k: v for k, v in self.overrides},
        }


def bundled_preset_names() -> list[str]:
    """Names of the presets shipped in ``headless/presets`` (sorted)."""
    return sorted(p.stem for p in PRESETS_DIR.glob("*.toml"))


def _preset_path(name_or_path: str) -> tuple[Path, str]:
    """The file a ``--preset`` argument means and how to name it in messages."""
    path = Path(name_or_path)
    if path.is_file():
        return path, str(name_or_path)
    bare = "/" not in name_or_path and "\\" not in name_or_path and not name_or_path.endswith(
        ".toml")
    if bare:
        bundled = PRESETS_DIR / f"{name_or_path}.toml"
        if bundled.is_file():
            return bundled, f"presets/{bundled.name}"
        names = ", ".join(bundled_preset_names()) or "none"
        raise UserError(f"--preset {name_or_path}: no such file or bundled preset "
                        f"(bundled presets: {names})")
    if path.is_dir():
        raise UserError(f"{name_or_path}: is a directory, not a preset file")
    raise UserError(f"{name_or_path}: no such preset file")


def load_preset(name_or_path: str) -> Preset:
    """Load and fully validate a bundled preset (by name) or a preset file (by path).

    Every problem raises :class:`~headless.cli.UserError` with one line naming the file and
    the field: unknown keys, modes, policies, abstractions or scenarios, levels that do not
    load, empty lists or no seeds, bad ``[set]`` overrides.
    """
    path, src = _preset_path(name_or_path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"{src}: file: cannot read ({error})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"{src}: toml: not valid TOML ({error})") from None
    return parse_preset(data, src, name=path.stem, text=text, base=path.resolve().parent)


def _fail(src: str, field: str, problem: str) -> UserError:
    return UserError(f"{src}: {field}: {' '.join(problem.splitlines())}")


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            flat.update(_flatten(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


def _names(data: Mapping[str, Any], key: str, src: str, allowed: Sequence[str] | None) -> list[str]:
    """A non-empty list of distinct strings, each in ``allowed`` when given."""
    if key not in data:
        raise _fail(src, key, "missing required key")
    value = data[key]
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(src, key, f"expected a list of names, got {value!r}")
    if not value:
        raise _fail(src, key, "empty list: the design would have no trials")
    seen = set()
    for v in value:
        if allowed is not None and v not in allowed:
            raise _fail(src, key, f"unknown value {v!r} (choose from {', '.join(allowed)})")
        if v in seen:
            raise _fail(src, key, f"{v!r} is listed twice")
        seen.add(v)
    return list(value)


def _seeds(data: Mapping[str, Any], src: str) -> tuple[int, ...]:
    if "seeds" not in data:
        raise _fail(src, "seeds", "missing required key (a count, or a list of seeds)")
    value = data["seeds"]
    if isinstance(value, int) and not isinstance(value, bool):
        if value <= 0:
            raise _fail(src, "seeds", f"must be at least 1, got {value}: the design would "
                                      "have no trials")
        return tuple(range(value))
    if isinstance(value, list):
        if not value:
            raise _fail(src, "seeds", "empty list: the design would have no trials")
        if not all(isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in value):
            raise _fail(src, "seeds", f"expected whole numbers >= 0, got {value!r}")
        if len(set(value)) != len(value):
            raise _fail(src, "seeds", "a seed is listed twice")
        return tuple(value)
    raise _fail(src, "seeds", f"expected a count or a list of seeds, got {value!r}")


def _level_ref(name: str, base: Path | None) -> str:
    """A bundled name stays a name; a path is made absolute (relative to the preset file)."""
    bare = "/" not in name and "\\" not in name and not name.lower().endswith(".json")
    if bare:
        return name
    path = Path(name).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    return str(path.resolve())


def parse_preset(
    data: Mapping[str, Any],
    src: str = "<preset>",
    *,
    name: str = "preset",
    text: str = "",
    base: Path | None = None,
) -> Preset:
    """Validate decoded preset data (see :func:`load_preset`); relative level paths are
    resolved against ``base`` (the preset file's folder)."""
    from ai import GUARD_MODES, PLAYER_POLICIES, make_guard_ai, make_player_policy
    from game.config import Config, ConfigError
    from game.world import SCENARIOS
    from navmesh.graph import ABSTRACTIONS, graph_for
    from navmesh.level import LevelError, load_level

    for key in data:
        if key not in _ALLOWED_KEYS:
            raise _fail(src, str(key), f"unknown key (allowed keys: {', '.join(_ALLOWED_KEYS)})")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise _fail(src, "description", "expected a string")
    abstractions = _names(data, "abstractions", src, ABSTRACTIONS)
    guards = _names(data, "guards", src, list(GUARD_MODES))
    players = _names(data, "players", src, list(PLAYER_POLICIES))
    scenarios = _names(data, "scenarios", src, SCENARIOS)
    seeds = _seeds(data, src)
    root_seed = data.get("root_seed", 0)
    if isinstance(root_seed, bool) or not isinstance(root_seed, int) or root_seed < 0:
        raise _fail(src, "root_seed", f"expected a whole number >= 0, got {root_seed!r}")

    overrides_table = data.get("set", {})
    if not isinstance(overrides_table, Mapping):
        raise _fail(src, "set", "expected a table of config overrides (dotted keys)")
    flat = _flatten(overrides_table)
    try:
        config = Config.load(flat)
    except ConfigError as error:
        raise _fail(src, "set", str(error)) from None
    # The values as the config coerced them (10 -> 10.0 for a float key), so equal settings
    # written differently give equal trial keys.
    overrides = tuple((key, config[key]) for key in sorted(flat))

    for mode in guards:
        try:
            make_guard_ai(mode, config.section(mode))
        except Exception as error:  # a mode that is listed but cannot be built
            raise _fail(src, "guards", f"{mode}: cannot be loaded "
                                       f"({type(error).__name__}: {error})") from None
    for policy in players:
        try:
            make_player_policy(policy, config.section("player"))
        except Exception as error:
            raise _fail(src, "players", f"{policy}: cannot be loaded "
                                        f"({type(error).__name__}: {error})") from None

    level_names = _names(data, "levels", src, None)
    refs: list[str] = []
    names: list[str] = []
    for level_name in level_names:
        ref = _level_ref(level_name, base)
        try:
            level = load_level(ref)
        except LevelError as error:
            raise _fail(src, "levels", str(error)) from None
        if level.name in names:
            raise _fail(src, "levels", f"two levels are named {level.name!r}")
        for abstraction in abstractions:
            try:
                graph_for(level, abstraction)
            except Exception as error:
                raise _fail(src, "abstractions", f"{abstraction}: cannot build the graph of "
                            f"level {level.name!r} ({type(error).__name__}: {error})") from None
        refs.append(ref)
        names.append(level.name)

    return Preset(
        name=name, source=src, text=text, levels=tuple(refs), level_names=tuple(names),
        abstractions=tuple(abstractions), guards=tuple(guards), players=tuple(players),
        scenarios=tuple(scenarios), seeds=seeds, root_seed=root_seed, overrides=overrides,
        description=description, config_hash=config.hash(), config=config.as_dict(),
    )


# =========================================================================== workers
def run_one(spec: TrialSpec) -> dict[str, Any]:
    """Run one trial; a trial that raises becomes a row with ``error`` (the traceback)."""
    try:
        row = run_trial(spec)
    except Exception as error:
        row = {
            "level": spec.level, "abstraction": spec.abstraction, "guards": spec.guards,
            "player": spec.player, "scenario": spec.scenario, "seed": spec.seed,
            "root_seed": spec.root_seed, "overrides": dict(spec.overrides),
            "error": f"{type(error).__name__}: {error}\n{traceback.format_exc(limit=-8)}"[:8000],
        }
    row["key"] = spec.key
    row["level_ref"] = spec.level
    return row


def run_batch(specs: Sequence[TrialSpec]) -> list[dict[str, Any]]:
    """Run a few trials in one task (top-level and picklable: any executor can map it)."""
    return [run_one(spec) for spec in specs]


def _ignore_sigint() -> None:
    """Pool worker initializer: Ctrl-C is the main process's business."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class _InlineExecutor(cf.Executor):
    """``--workers 1``: run each task at submit time in this process (easy to debug)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        future: cf.Future[Any] = cf.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as error:
            future.set_exception(error)
        return future


# =========================================================================== progress
def _duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "--:--"
    seconds = round(seconds)
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m:02d}:{s:02d}"


class Progress:
    """A dependency-free progress bar on a stream (stderr).

    On a terminal it redraws one line with ``\\r``; otherwise (a log file, CI) it prints a
    plain line at most every ``interval`` seconds.
    """

    def __init__(self, total: int, stream: IO[str] | None = None, *, enabled: bool = True,
                 interval: float = 5.0) -> None:
        self.total = total
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = 0.1 if self.tty else interval
        self.started = time.monotonic()
        self.last = -math.inf
        self.done = 0
        self.failed = 0

    def line(self) -> str:
        """The current progress text, e.g. ``[#####.....] 50/100 50% 12.3 trials/s ETA 00:04``."""
        elapsed = time.monotonic() - self.started
        rate = self.done / elapsed if elapsed > 0 else 0.0
        eta = (self.total - self.done) / rate if rate > 0 else math.inf
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(frac * 24) + "." * (24 - int(frac * 24))
        failed = f" {self.failed} failed" if self.failed else ""
        return (f"[{bar}] {self.done}/{self.total} {100 * frac:3.0f}% "
                f"{rate:5.1f} trials/s ETA {_duration(eta)}{failed}")

    def update(self, done: int, failed: int = 0, *, force: bool = False) -> None:
        """Record ``done`` (and ``failed``) more trials and redraw if it is time to."""
        self.done += done
        self.failed += failed
        now = time.monotonic()
        if not self.enabled or (not force and now - self.last < self.interval):
            return
        self.last = now
        if self.tty:
            self.stream.write("\r" + self.line() + "\x1b[K")
        else:
            self.stream.write(self.line() + "\n")
        self.stream.flush()

    def close(self) -> None:
        """Draw the final state (and end the redrawn line on a terminal)."""
        if self.enabled:
            self.update(0, force=True)
            if self.tty:
                self.stream.write("\n")
                self.stream.flush()


# =========================================================================== the sweep
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


def _batches(specs: Sequence[TrialSpec], size: int) -> Iterator[list[TrialSpec]]:
    for i in range(0, len(specs), size):
        yield list(specs[i:i + size])


def _check_store(store_path: Path, preset: Preset) -> None:
    """Refuse to resume into a store that holds a different design or configuration."""
    if not store_path.is_file():
        return
    try:
        with ResultStore(store_path, readonly=True) as store:
            meta = store.meta()
    except Exception as error:
        raise UserError(f"{store_path}: not a readable results store ({error})") from None
    old = meta.get("design")
    if old is not None and json.loads(old) != preset.design():
        raise UserError(
            f"{store_path}: holds results of a different design (preset "
            f"{meta.get('preset_name', '?')!r}); use another --out or delete that directory")
    old_hash = meta.get("config_hash")
    if old_hash is not None and old_hash != preset.config_hash:
        raise UserError(
            f"{store_path}: its trials ran with config {old_hash}, the current config is "
            f"{preset.config_hash} (game/defaults.toml or the preset's [set] changed); "
            "use another --out")


def _connect(scheduler: str) -> tuple[Any, cf.Executor, int]:
    """A Dask client, its ``concurrent.futures`` executor and its number of threads."""
    try:
        import distributed
    except ImportError:
        raise UserError("--scheduler needs Dask: install the cluster extra "
                        "(pip install 'stealthfield[cluster]')") from None
    try:
        client = distributed.Client(scheduler, timeout="10s")
    except Exception as error:
        raise UserError(f"--scheduler {scheduler}: cannot connect "
                        f"({type(error).__name__}: {error})") from None
    threads = sum(client.nthreads().values()) or 1
    return client, client.get_executor(), threads


def _lock(out: Path) -> Any:
    """An exclusive lock on the results directory (one writing sweep at a time)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX: no lock
        return None
    handle = open(out / "results.lock", "w")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.close()
        raise UserError(f"{out}: another sweep is writing to this directory") from None
    handle.write(str(os.getpid()))
    handle.flush()
    return handle


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
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise UserError(f"--workers: must be at least 1, got {workers}")
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: exists and is not a directory")
    store_path = out / STORE_NAME
    _check_store(store_path, preset)
    client: Any = None
    executor: cf.Executor | None = None
    lock: Any = None
    store: ResultStore | None = None
    try:
        if scheduler:
            client, executor, parallelism = _connect(scheduler)
        elif workers == 1:
            executor, parallelism = _InlineExecutor(), 1
        else:
            parallelism = workers  # the pool is started below, once there is work
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise UserError(f"--out {out}: cannot create ({error.strerror or error})") from None
        lock = _lock(out)
        if progress:
            stream.write(f"stealth: preset {preset.name}: {preset.n_trials} trials "
                         f"({len(preset.levels)} levels x {len(preset.abstractions)} "
                         f"abstractions x {len(preset.guards)} guard modes x "
                         f"{len(preset.players)} player policies x {len(preset.scenarios)} "
                         f"scenarios x {len(preset.seeds)} seeds) -> {out}\n")
        store = ResultStore(store_path)
        now = datetime.now(timezone.utc).isoformat(timespec="seconds")
        meta = {
            "preset_name": preset.name, "preset_source": preset.source,
            "preset_toml": preset.text, "design": json.dumps(preset.design()),
            "config_hash": preset.config_hash, "total_trials": str(preset.n_trials),
            "config": json.dumps(dict(preset.config), sort_keys=True),
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
        if executor is None:
            executor = cf.ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint)
        inline = isinstance(executor, _InlineExecutor)
        size = 1 if inline else max(1, min(_MAX_BATCH, math.ceil(len(todo) / (parallelism * 8))))
        in_flight = 1 if inline else 2 * parallelism
        bar = Progress(len(todo), stream, enabled=progress)
        started = time.monotonic()
        try:
            _drive(executor, _batches(todo, size), in_flight, store, preset, result, bar)
        finally:
            result.elapsed = time.monotonic() - started
            bar.close()
        return result
    finally:
        if isinstance(executor, cf.ProcessPoolExecutor):
            executor.shutdown(wait=False, cancel_futures=True)  # no-op after a clean finish
        elif executor is not None:
            executor.shutdown(wait=False)
        if client is not None:
            client.close()
        if store is not None:
            store.close()
        if lock is not None:
            lock.close()


def _record(rows: Iterable[dict[str, Any]], store: ResultStore, preset: Preset,
            result: SweepResult, bar: Progress) -> None:
    names = dict(zip(preset.levels, preset.level_names))
    finished = failed = 0
    for row in rows:
        if row.get("error"):
            row["level"] = names.get(row["level_ref"], row["level"])
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


def _drive(executor: cf.Executor, batches: Iterator[list[TrialSpec]], in_flight: int,
           store: ResultStore, preset: Preset, result: SweepResult, bar: Progress) -> None:
    """Keep at most ``in_flight`` tasks submitted; commit every result as it arrives."""
    pending: dict[cf.Future[Any], list[TrialSpec]] = {}

    def collect(future: cf.Future[Any]) -> None:
        pending.pop(future)
        error = future.exception()
        if error is not None:
            # run_batch never raises for a failing trial, so this is the machinery: a
            # worker process died, the cluster cannot import the project, pickling failed.
            raise _TaskError(error)
        _record(future.result(), store, preset, result, bar)

    try:
        exhausted = False
        while True:
            while not exhausted and len(pending) < in_flight:
                batch = next(batches, None)
                if batch is None:
                    exhausted = True
                    break
                pending[executor.submit(run_batch, batch)] = batch
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
        if isinstance(executor, cf.ProcessPoolExecutor):
            processes = list((getattr(executor, "_processes", None) or {}).values())
            executor.shutdown(wait=False, cancel_futures=True)
            for process in processes:  # our own pool's workers, still busy after the wait
                if process.is_alive():
                    process.terminate()


# =========================================================================== command
def _resume_command(args: argparse.Namespace, out: Path) -> str:
    words = ["stealth", "run", "--preset", args.preset, "--out", str(out)]
    if args.workers:
        words += ["--workers", str(args.workers)]
    if args.scheduler:
        words += ["--scheduler", args.scheduler]
    return " ".join(shlex.quote(w) for w in words)


def cmd_run(args: argparse.Namespace) -> int:
    """``stealth run``: validate the preset, run the missing trials, print a summary line.

    Exit codes: 0 all done, 1 some trial failed or a worker died, 2 a user error (nothing
    written), 130 interrupted (the store keeps every committed trial; rerun to resume).
    """
    try:
        return _cmd_run(args)
    except UserError as error:
        return user_error(error)


def user_error(error: BaseException) -> int:
    """Print a user error as ``stealth: error: ...`` and return exit code 2.

    The commands handle their own :class:`UserError` because under ``python -m
    headless.cli`` the entry point's ``UserError`` is ``__main__.UserError``, a different
    class from the ``headless.cli.UserError`` raised here.
    """
    print(f"stealth: error: {' '.join(str(error).splitlines())}", file=sys.stderr)
    return 2


def _cmd_run(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        raise UserError(f"--workers: must be at least 1, got {args.workers}")
    preset = load_preset(args.preset)
    out = Path(args.out) if args.out else Path("results") / preset.name
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
