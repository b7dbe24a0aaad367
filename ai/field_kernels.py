"""A potential-field decision's scores, compiled (numba), loaded at first use by
:meth:`ai.fields.CompositeField.select` on a graph with dense tables: the same IEEE
operations in the same order as the Python loop they replace, so the same bits and the
same tie draw."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def dense_scores(kernel: np.ndarray, candidates: np.ndarray, table: np.ndarray,
                 teammates: np.ndarray, scale: float, recent: np.ndarray, hit: float,
                 miss: float, revisit: bool, personal: np.ndarray, eps: float
                 ) -> tuple[np.ndarray, np.ndarray, bool]:
    """Per candidate c: ``K[c]``, plus ``scale`` × the teammates' presence at c summed left
    to right (when there are teammates and ``scale`` is not 0), plus ``hit`` if c is among
    ``recent`` else ``miss`` (when ``revisit``), plus ``personal[c]`` (when given); then
    the candidates within ``eps`` of the least score. Returns (scores, tied, ok); ``ok`` is
    False when a score is NaN (the caller takes its array path then)."""
    k = candidates.shape[0]
    scores = np.empty(k)
    presence = teammates.shape[0] > 0 and scale != 0.0
    for j in range(k):
        c = candidates[j]
        x = kernel[c]
        if presence:
            total = table[c, teammates[0]]
            for t in range(1, teammates.shape[0]):
                total += table[c, teammates[t]]
            x += scale * total
        if revisit:
            found = False
            for r in recent:
                if r == c:
                    found = True
                    break
            x += hit if found else miss
        if personal.shape[0] > 0:
            x += personal[c]
        if np.isnan(x):
            return scores, candidates[:0].copy(), False
        scores[j] = x
    low = scores[0]
    for j in range(1, k):
        if scores[j] < low:
            low = scores[j]
    count = 0
    tied = np.empty(k, dtype=candidates.dtype)
    for j in range(k):
        if scores[j] - low < eps:
            tied[count] = candidates[j]
            count += 1
    return scores, tied[:count].copy(), True


__all__ = ["dense_scores"]
