"""The distance metric's searches in a worker process, for the game on a large level.

The metric ``mean_distance`` samples, every physics step, the shortest-path distance from
the player to the nearest guard (:meth:`game.metrics.Counters.sample_distance`). On a graph
too large for dense tables that is a multi-source search over the whole graph whenever a
guard changes node — about 150 ms at 10^6 cells, three times a second — and scipy's search
holds the GIL, so a thread would stall the frames just the same. The game therefore hands
each new (player node, guard nodes) key to one worker process, which rebuilds the graph
from its nodes and edges once and answers with :meth:`~navmesh.graph.NodeGraph.nearest_dist_to`
itself: the same code on the same graph, so the same bits. The values are only summed when
the metrics are read (:meth:`Counters.settle`), in step order, so the metric is identical
to the one computed in the frame; only when it is computed changes. If the worker cannot
start or dies, the remaining keys are computed in this process.
"""

from __future__ import annotations

import multiprocessing
import os
import shutil
import tempfile
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

import numpy as np

from navmesh.graph import Neighbours, NodeGraph

from .background import lowest_priority

__all__ = ["DistanceWorker"]

_GRAPH: NodeGraph | None = None


def _load(path: str) -> None:
    """Worker initialiser: the searched (never dense) graph of the same nodes and edges, at
    the lowest priority (the frames, and the display server, come first)."""
    global _GRAPH
    lowest_priority()
    try:
        saved = np.load(path)
    except OSError:  # the game closed before this worker started: nothing left to do
        return
    with saved:
        _GRAPH = NodeGraph(kind=str(saved["kind"]), positions=saved["positions"],
                           neighbors=Neighbours(saved["indptr"], saved["indices"]),
                           cell_size=float(saved["cell_size"]), dense=False)


def _nearest(guard_nodes: tuple[int, ...], player_node: int) -> float:
    assert _GRAPH is not None
    return _GRAPH.nearest_dist_to(list(guard_nodes), player_node)


class DistanceWorker:
    """One worker process answering ``nearest_dist_to(guards, player)`` on ``graph``."""

    def __init__(self, graph: NodeGraph) -> None:
        self.graph = graph
        # The graph goes by a file, not through the start-up pipe: a worker that died while
        # reading tens of MB from it would leave this process blocked writing them.
        self._folder = ""
        self._pool: ProcessPoolExecutor | None = None
        try:
            self._folder = tempfile.mkdtemp(prefix="stealth-distances-")
            path = os.path.join(self._folder, "graph.npz")
            neighbors = graph.neighbors
            np.savez(path, kind=graph.kind, positions=np.asarray(graph.positions),
                     indptr=np.asarray(neighbors.indptr), indices=np.asarray(neighbors.indices),  # type: ignore[attr-defined]
                     cell_size=float(graph.cell_size))
        except OSError:  # no room for the file (a full disk): the searches run here
            self.close()
            return
        # spawn, not fork: the game process holds a display connection and threads
        self._pool = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"),
                                         initializer=_load, initargs=(path,))

    def submit(self, guard_nodes: tuple[int, ...], player_node: int) -> Future[float]:
        """The distance, computed in the worker (or here, if the worker is gone)."""
        if self._pool is not None:
            try:
                return self._pool.submit(_nearest, tuple(guard_nodes), int(player_node))
            except (RuntimeError, OSError):  # broken, shut down or not startable: here from now on
                self.close()
        done: Future[float] = Future()
        done.set_result(self.graph.nearest_dist_to(list(guard_nodes), int(player_node)))
        return done

    def value(self, found: Future[float], guard_nodes: tuple[int, ...], player_node: int) -> float:
        """The result of ``found``; computed here if the worker failed to give it."""
        try:
            return float(found.result())
        except Exception:  # noqa: BLE001 — a lost worker costs time, never the metric
            return float(self.graph.nearest_dist_to(list(guard_nodes), int(player_node)))

    def close(self) -> None:
        """Stop the worker (pending searches are dropped)."""
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = None
        if self._folder:
            shutil.rmtree(self._folder, ignore_errors=True)

    def __getstate__(self) -> dict[str, Any]:
        raise TypeError("a DistanceWorker belongs to one process")
