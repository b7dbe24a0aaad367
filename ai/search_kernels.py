"""Compiled searches of the player policies (numba), loaded at first use by
:mod:`ai.players`: the same float operations in the same order as the Python they replace,
so a compiled plan is the plan, bit for bit."""

from __future__ import annotations

import heapq

import numpy as np
from numba import njit

from navmesh.path_kernels import tree_path


@njit(cache=True)
def astar(start: int, goal: int, indptr: np.ndarray, indices: np.ndarray,
          lengths: np.ndarray, penalty: np.ndarray, heuristic: np.ndarray) -> np.ndarray:
    """The nodes of the A* path ``start`` → ``goal`` (``SafetyGraphPlayer.astar``'s rule:
    entering v costs ``lengths[e] * penalty[v]``, open-list ties first in, first out);
    ``[start]`` when the goal is unreachable."""
    n = heuristic.shape[0]
    cost = np.full(n, np.inf)
    parent = np.full(n, -1, dtype=np.int64)
    closed = np.zeros(n, dtype=np.bool_)
    cost[start] = 0.0
    open_list = [(heuristic[start], np.int64(0), np.int64(start))]
    counter = 1
    while len(open_list) > 0:
        _, _, u = heapq.heappop(open_list)
        if u == goal:
            return tree_path(parent, start, goal)
        if closed[u]:
            continue
        closed[u] = True
        base = cost[u]
        for e in range(indptr[u], indptr[u + 1]):
            v = np.int64(indices[e])
            if closed[v]:
                continue
            g = base + lengths[e] * penalty[v]
            if g < cost[v]:
                cost[v] = g
                parent[v] = u
                heapq.heappush(open_list, (g + heuristic[v], np.int64(counter), v))
                counter += 1
    result = np.empty(1, dtype=np.int64)
    result[0] = start
    return result


@njit(cache=True)
def maxmin_firsts(nearest: np.ndarray, paths: np.ndarray, closing: np.ndarray,
                  eps: float) -> np.ndarray:
    """The first moves, sorted, of MaxMin's best sequences (``MaxMinPlayer.decide``'s
    rule): each row of ``paths`` scores ``min_k (nearest[paths[k]] − closing[k])``; the
    best score within ``eps`` wins, then the largest value at the sequence's end within
    ``eps``."""
    m, depth = paths.shape
    score = np.empty(m)
    final = np.empty(m)
    for i in range(m):
        low = np.inf
        for k in range(depth):
            value = nearest[paths[i, k]] - closing[k]
            if value < low:
                low = value
        score[i] = low
        final[i] = nearest[paths[i, depth - 1]] - closing[depth - 1]
    top = score.max() - eps
    far = -np.inf
    for i in range(m):
        if score[i] >= top and final[i] > far:
            far = final[i]
    far -= eps
    firsts = np.empty(m, dtype=np.int64)
    count = 0
    for i in range(m):
        if score[i] >= top and final[i] >= far:
            firsts[count] = paths[i, 0]
            count += 1
    return np.unique(firsts[:count])


__all__ = ["astar", "maxmin_firsts"]
