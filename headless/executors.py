"""Executors a sweep maps its trials over: in-process, a process pool, a Dask cluster.

The unit of work is :func:`run_batch` — a few :class:`~game.trial.TrialSpec` in, their rows
out — a pure, top-level, picklable function, so every ``concurrent.futures.Executor`` runs
it alike (Mesa's batch runner); on the batch engine (``world.engine = "batch"``) it is
:func:`run_engine_batch`, up to ``game.batch.MAX_BATCH`` trials of one level, abstraction,
``[set]`` and factor combination advanced together. A failing trial never raises: it
becomes a row with an ``error`` text (on the batch engine a batch that raises makes every
one of its trials such a row), so only the machinery itself (a dead worker, a cluster that
cannot import the project) makes a task fail. To add an executor, return any
``concurrent.futures`` executor from a function here and pick it in
:func:`headless.sweep.run_sweep`.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from game.trial import TrialSpec, identity_row, run_trial

from .errors import SweepError, UserError

__all__ = [
    "MAX_WORKERS_PER_CPU", "InlineExecutor", "check_workers", "connect_dask", "process_pool",
    "run_batch", "run_engine_batch", "run_one", "shutdown", "terminate",
]


def _error_text(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}\n{traceback.format_exc(limit=-8)}"[:8000]


def run_one(spec: TrialSpec, level_name: str | None = None) -> dict[str, Any]:
    """Run one trial; a trial that raises becomes a row with ``error`` (the traceback) and
    the identity of :func:`~game.trial.identity_row`, ``level`` being ``level_name`` (the
    level's name, which a failed trial may not have read)."""
    try:
        return run_trial(spec)
    except Exception as error:
        return {**identity_row(spec, level_name), "error": _error_text(error)}


def run_batch(specs: Sequence[TrialSpec], level_names: Mapping[str, str] | None = None
              ) -> list[dict[str, Any]]:
    """Run a few trials in one task (top-level and picklable: any executor can map it);
    ``level_names``: the level's name of each level reference, for the rows of failures."""
    names = level_names or {}
    return [run_one(spec, names.get(spec.level)) for spec in specs]


def run_engine_batch(specs: Sequence[TrialSpec], level_names: Mapping[str, str] | None = None
                     ) -> list[dict[str, Any]]:
    """Run trials that share level, abstraction, overrides and factors on the batch engine
    (:func:`game.batch.run_trials`: one row per spec, in order, each a
    :func:`~game.trial.run_trial` row); top-level and picklable like :func:`run_batch`.

    A batch that raises, or answers with rows that are not its specs' (another count,
    another key), becomes an error row for each of its specs (``engine`` batch), so a
    rerun retries them, as it retries a failed trial.
    """
    names = level_names or {}
    try:
        from game.batch import run_trials

        rows = list(run_trials(specs))
        keys = [row.get("key") for row in rows]
        if keys != [spec.key for spec in specs]:
            raise RuntimeError(f"the batch engine answered {len(rows)} rows for {len(specs)} "
                               "trials, or not in their order")
        return rows
    except Exception as error:
        text = _error_text(error)
        return [{**identity_row(spec, names.get(spec.level)), "error": text, "engine": "batch"}
                for spec in specs]


class InlineExecutor(cf.Executor):
    """``--workers 1``: run each task at submit time in this process (easy to debug)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        future: cf.Future[Any] = cf.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as error:
            future.set_exception(error)
        return future


MAX_WORKERS_PER_CPU = 4
"""``--workers`` may ask for at most this many processes per CPU."""


def check_workers(workers: int) -> int:
    """``workers`` if it is a sensible number of local processes, else a one-line UserError.

    >>> check_workers(1)
    1
    """
    limit = MAX_WORKERS_PER_CPU * (os.cpu_count() or 1)
    if workers < 1:
        raise UserError(f"--workers: must be at least 1, got {workers}")
    if workers > limit:
        raise UserError(f"--workers: {workers} is more than {MAX_WORKERS_PER_CPU} per CPU "
                        f"({os.cpu_count() or 1} CPUs here, at most {limit})")
    return workers


def _die_with(parent: int) -> None:
    """Pool worker initializer: Ctrl-C is the main process's business, and the worker ends
    when its parent does (killed or not), so no orphan keeps running trials or files open.

    On Linux the kernel sends SIGKILL at the parent's death (``prctl(PR_SET_PDEATHSIG)``);
    everywhere a daemon thread also polls :func:`os.getppid` and exits once the worker has
    been re-parented.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no usable libc: the watchdog
            pass
    if multiprocessing.get_start_method() != "fork":
        parent = os.getppid()  # forkserver/spawn: the server, which ends with the main process
    if os.getppid() != parent:  # the parent died before the death signal was armed
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watchdog",
                     daemon=True).start()


_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _watch_parent(parent: int, interval: float = 0.5) -> None:
    """End this process as soon as ``parent`` is no longer its parent."""
    while os.getppid() == parent:
        time.sleep(interval)
    os._exit(1)


def process_pool(workers: int) -> cf.ProcessPoolExecutor:
    """A pool of ``workers`` processes that leave Ctrl-C to the main process and die with it."""
    return cf.ProcessPoolExecutor(max_workers=check_workers(workers), initializer=_die_with,
                                  initargs=(os.getpid(),))


def connect_dask(scheduler: str) -> tuple[Any, cf.Executor, int]:
    """A Dask client, its ``concurrent.futures`` executor and its number of threads."""
    try:
        import distributed
    except ImportError:
        raise SweepError("--scheduler needs Dask: install the cluster extra "
                         "(pip install 'stealthfield[cluster]')") from None
    try:
        client = distributed.Client(scheduler, timeout="10s")
    except Exception as error:
        raise SweepError(f"--scheduler {scheduler}: cannot connect "
                         f"({type(error).__name__}: {error})") from None
    threads = sum(client.nthreads().values()) or 1
    return client, client.get_executor(), threads


def shutdown(executor: cf.Executor) -> None:
    """Stop an executor without waiting; a process pool drops its queued tasks too."""
    if isinstance(executor, cf.ProcessPoolExecutor):
        executor.shutdown(wait=False, cancel_futures=True)  # no-op after a clean finish
    else:
        executor.shutdown(wait=False)


def terminate(executor: cf.Executor) -> None:
    """Stop at once: shut down, and end a process pool's workers that are still busy."""
    if isinstance(executor, cf.ProcessPoolExecutor):
        processes = list((executor._processes or {}).values())  # noqa: SLF001 (our own pool)
        executor.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            if process.is_alive():
                process.terminate()
    else:
        executor.shutdown(wait=False)
