"""Scalar plane geometry of the refinement (:mod:`navmesh.refine`), in Python floats.

Orientation, the angle at a corner and the circumcentre, each in one fixed order of
operations (the refinement's results depend on them to the bit).
"""

from __future__ import annotations

import math

__all__ = ["angle_at", "circumcentre", "orient2"]


def orient2(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    """Twice the signed area of (a, b, c): positive when counter-clockwise in the coordinate sense."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def angle_at(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    """Angle at a between rays a→b and a→c, in [0, π]."""
    ux, uy, vx, vy = bx - ax, by - ay, cx - ax, cy - ay
    return abs(math.atan2(ux * vy - uy * vx, ux * vx + uy * vy))


def circumcentre(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> tuple[float, float]:
    bx, by, cx, cy = bx - ax, by - ay, cx - ax, cy - ay
    d = 2.0 * (bx * cy - by * cx)
    if d == 0.0:
        return math.nan, math.nan
    b2, c2 = bx * bx + by * by, cx * cx + cy * cy
    return ax + (cy * b2 - by * c2) / d, ay + (bx * c2 - cx * b2) / d
