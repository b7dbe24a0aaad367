"""Compiled walks over a shortest-path tree (numba), loaded at first use by
:meth:`navmesh.graph.NodeGraph.step_towards`: the guards' baselines ask for one step of a
path per decision, and following the predecessors node by node in Python cost more than
the search it reads."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def tree_path(pred: np.ndarray, a: int, b: int) -> np.ndarray:
    """The nodes from ``a`` to ``b`` (both included) along the predecessors ``pred`` of a
    search from ``a``; empty when ``b`` is not reached (a predecessor < 0 on the way)."""
    length = 1
    v = b
    while v != a:
        v = pred[v]
        if v < 0:
            return np.empty(0, dtype=np.int64)
        length += 1
    path = np.empty(length, dtype=np.int64)
    v = b
    for k in range(length - 1, -1, -1):
        path[k] = v
        if k > 0:
            v = pred[v]
    return path


@njit(cache=True)
def step_towards(pred: np.ndarray, dist: np.ndarray, a: int, b: int, horizon: float) -> int:
    """The farthest node on the tree's path a→b (``pred``: predecessors of a search from
    a, ``dist``: its distances) within ``horizon`` of a, at least one hop; -1 when b is not
    reachable. ``NodeGraph.step_towards``'s rule: ``dist ≤ horizon + 1e-9``."""
    if a == b:
        return a
    path = tree_path(pred, a, b)
    if path.shape[0] == 0:
        return -1
    length = path.shape[0]
    bound = horizon + 1e-9
    last = 0
    for k in range(length):
        if dist[path[k]] <= bound:
            last = k
    return path[max(1, last)]


__all__ = ["step_towards", "tree_path"]
