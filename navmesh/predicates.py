"""Whole-mesh numpy forms of the refiner's predicates, to skip its first pass over every triangle.

:class:`navmesh.refine.Refiner` tests one edge or triangle at a time in Python floats. On a
10^5-triangle mesh its first passes (legalising every edge, scanning every triangle for
quality, finding degenerate triangles) are most of its time, yet almost every test fails.
These functions evaluate the same tests for all items at once and return a *superset* of
those that can pass: the caller re-runs the exact scalar test on those only, so the result
does not depend on numpy's rounding (the incircle and dot products here are even computed
in the scalar code's operation order, so they agree to the bit; lengths use ``np.hypot``,
which may differ from ``math.hypot`` in the last bit, hence a relative margin).
"""

from __future__ import annotations

import numpy as np

__all__ = ["degenerate_candidates", "flip_candidates", "quality_candidates", "small_angle_candidates"]

#: relative slack of the supersets against last-bit differences of ``np.hypot``/``np.arctan2``
_MARGIN = 1e-9


def flip_candidates(x: np.ndarray, y: np.ndarray, tri: np.ndarray, nbr: np.ndarray, threshold: float) -> np.ndarray:
    """(T, 3) bool: edge k of t may be flipped (``Refiner._should_flip``'s incircle test passes).

    False only where that test fails for sure: a boundary edge, or the opposite vertex of
    the neighbour not inside the circumcircle by more than ``threshold`` (scaled as the
    scalar ``_incircle``).
    """
    t_count = len(tri)
    u = nbr.ravel()
    t_idx = np.repeat(np.arange(t_count), 3)
    k_idx = np.tile(np.arange(3), t_count)
    inner = u >= 0
    uu = np.where(inner, u, 0)
    # the neighbour's vertex opposite the shared edge: the one not on it
    shared = (nbr[uu] == t_idx[:, None])
    j = np.argmax(shared, axis=1)
    d = tri[uu, j]
    a = tri[t_idx, k_idx]
    b = tri[t_idx, (k_idx + 1) % 3]
    c = tri[t_idx, (k_idx + 2) % 3]
    adx, ady = x[a] - x[d], y[a] - y[d]
    bdx, bdy = x[b] - x[d], y[b] - y[d]
    cdx, cdy = x[c] - x[d], y[c] - y[d]
    ad, bd, cd = adx * adx + ady * ady, bdx * bdx + bdy * bdy, cdx * cdx + cdy * cdy
    det = adx * (bdy * cd - bd * cdy) - ady * (bdx * cd - bd * cdx) + ad * (bdx * cdy - bdy * cdx)
    scale = np.maximum(np.maximum(ad, bd), cd)
    with np.errstate(divide="ignore", invalid="ignore"):
        val = np.where(scale > 0, det / (scale * scale), 0.0)
    maybe = ~(val <= threshold * (1.0 - _MARGIN) - _MARGIN * 1e-12)  # NaN counts as maybe
    return (maybe & inner).reshape(t_count, 3)


def quality_candidates(
    x: np.ndarray, y: np.ndarray, tri: np.ndarray, sin_min: float, max_area: float
) -> np.ndarray:
    """(T,) bool: the triangle may be bad (``Refiner._quality`` < 1); False only where it is not."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    l0 = np.hypot(x[b] - x[c], y[b] - y[c])
    l1 = np.hypot(x[c] - x[a], y[c] - y[a])
    l2 = np.hypot(x[a] - x[b], y[a] - y[b])
    area2 = (x[b] - x[a]) * (y[c] - y[a]) - (y[b] - y[a]) * (x[c] - x[a])
    lmin = np.minimum(np.minimum(l0, l1), l2)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        prod = np.where(lmin > 0, l0 * l1 * l2 / lmin, np.inf)
        if sin_min > 0:
            q = np.where(prod > 0, (area2 / prod) / sin_min, np.inf)
        else:
            q = np.full(len(tri), np.inf)
        if max_area > 0:
            q = np.minimum(q, max_area / (0.5 * area2))
    return ~(q >= 1.0 + 1e-6)  # NaN counts as maybe


def degenerate_candidates(x: np.ndarray, y: np.ndarray, tri: np.ndarray, tol: float) -> np.ndarray:
    """(T,) bool: the triangle may be flat (signed doubled area ≤ tol × its longest edge)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    longest = np.maximum(np.maximum(np.hypot(x[b] - x[c], y[b] - y[c]), np.hypot(x[c] - x[a], y[c] - y[a])),
                         np.hypot(x[a] - x[b], y[a] - y[b]))
    area2 = (x[b] - x[a]) * (y[c] - y[a]) - (y[b] - y[a]) * (x[c] - x[a])
    return ~(area2 > tol * longest * (1.0 + 1e-6) + 1e-300)


def small_angle_candidates(x: np.ndarray, y: np.ndarray, prv: np.ndarray, nxt: np.ndarray, limit: float) -> np.ndarray:
    """(n,) bool per ring vertex: its walkable angle may be below ``limit`` radians.

    ``x``, ``y``: the rings' points laid end to end; ``prv``, ``nxt``: each point's
    neighbours on its ring (:func:`navmesh.rings.ring_neighbours`).
    """
    ux, uy = x[nxt] - x, y[nxt] - y
    wx, wy = x[prv] - x, y[prv] - y
    ang = np.arctan2(ux * wy - uy * wx, ux * wx + uy * wy) % (2.0 * np.pi)
    return ~(ang >= limit * (1.0 + 1e-6)) | (ang > 2.0 * np.pi * (1.0 - 1e-6))
