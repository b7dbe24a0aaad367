"""Perception: the one vision / range / line-of-sight test of the world.

Every question "can this guard perceive that point" goes through :meth:`Senses.perceives`:
a guard seeing the player (range × the zone's view scale, the cone, a clear line), the
nodes a guard could see now (the player start rule), a guard in attack range (range, a
clear line unless ``world.attack_needs_line_of_sight`` is off) and the take-down's "is the
player inside this guard's cone" (the cone alone). The cone test runs before the ray is
cast, because the ray is the costly part (MEASURED.md).
"""

from __future__ import annotations

import math

import numpy as np
import pymunk

from .agents import WALL_QUERY

#: Ranges are compared with this slack so a distance of exactly the range counts as inside
#: whatever the last bit of the float sum of positions.
RANGE_EPS = 1e-9

Point = tuple[float, float]


class Senses:
    """Range, cone and line-of-sight tests against one pymunk space's walls.

    >>> senses = Senses(pymunk.Space(), fov_deg=90.0)
    >>> senses.perceives((0.0, 0.0), 0.0, (2.0, 1.0), reach=3.0)   # in range, in the cone
    True
    >>> senses.perceives((0.0, 0.0), math.pi, (2.0, 1.0), reach=3.0)  # behind it
    False
    >>> senses.perceives((0.0, 0.0), None, (2.0, 1.0), reach=2.0)   # no cone: range only
    False
    """

    def __init__(self, space: pymunk.Space, fov_deg: float,
                 walls: np.ndarray | None = None, *, compiled_lines: bool = False) -> None:
        self.space = space
        self.cos_half_fov = math.cos(math.radians(float(fov_deg)) / 2)
        #: the space's walls as (m, 2, 2) ends, when the caller has them: the many-point
        #: :meth:`visible_points` then runs compiled (the same query, bit for bit)
        self.walls = None if walls is None else np.asarray(walls, dtype=np.float64)
        #: lines of sight by the compiled port of pymunk's query (``game.exact``) over
        #: ``walls``, for a space that does not hold them (the batch engine's worlds)
        self.compiled_lines = compiled_lines
        if compiled_lines and self.walls is None:
            raise ValueError("compiled lines of sight need the walls")

    def clear_line(self, a: Point, b: Point) -> bool:
        """No wall between ``a`` and ``b``."""
        if self.compiled_lines:
            from .exact import clear_line, wall_grid

            assert self.walls is not None
            return bool(clear_line(*wall_grid(self.walls).arrays, float(a[0]), float(a[1]),
                                   float(b[0]), float(b[1])))
        return self.space.segment_query_first(a, b, 0.0, WALL_QUERY) is None

    def in_cone(self, origin: Point, heading: float, target: Point) -> bool:
        """``target`` lies inside the view cone around ``heading`` (any distance; a target
        at the origin itself counts as inside)."""
        dx, dy = target[0] - origin[0], target[1] - origin[1]
        return self._in_cone(dx, dy, math.sqrt(dx * dx + dy * dy), heading)

    def _in_cone(self, dx: float, dy: float, d: float, heading: float) -> bool:
        return d <= 1e-9 or dx * math.cos(heading) + dy * math.sin(heading) >= self.cos_half_fov * d

    def perceives(self, origin: Point, heading: float | None, target: Point, reach: float,
                  *, line_of_sight: bool = True) -> bool:
        """``target`` within ``reach`` of ``origin`` (``RANGE_EPS`` slack), inside the cone
        around ``heading`` (``None``: no cone) and, with ``line_of_sight``, no wall between."""
        dx, dy = target[0] - origin[0], target[1] - origin[1]
        d2 = dx * dx + dy * dy
        limit = reach + RANGE_EPS
        if d2 > limit * limit:
            return False
        if heading is not None and not self._in_cone(dx, dy, math.sqrt(d2), heading):
            return False
        return not line_of_sight or self.clear_line(origin, target)

    def visible_points(self, origin: Point, heading: float, points: np.ndarray,
                       reach: float) -> np.ndarray:
        """Mask of the ``points`` (k, 2) that :meth:`perceives` from ``origin``.

        With the walls known (``walls``), a compiled loop repeats :meth:`perceives` over the
        points (:func:`game.sight_kernels.visible`: its operations in its order, pymunk's
        query by its exact port); else a vectorised distance bound (with slack, so it only
        ever keeps more) picks the candidates and each gets the one test.
        """
        if self.walls is not None:
            from .exact import wall_grid
            from .sight_kernels import visible

            pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
            return visible(float(origin[0]), float(origin[1]), math.cos(heading),
                           math.sin(heading), pts, float(reach), self.cos_half_fov,
                           *wall_grid(self.walls).arrays)
        delta = points - origin
        near = np.flatnonzero(np.hypot(delta[:, 0], delta[:, 1]) <= reach + 1e-6)
        mask = np.zeros(len(points), dtype=bool)
        for k in near:
            mask[k] = self.perceives(origin, heading, (float(points[k, 0]), float(points[k, 1])),
                                     reach)
        return mask


__all__ = ["RANGE_EPS", "Senses"]
