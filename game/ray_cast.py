"""Vision cones by vectorised ray casting against the wall segments, apart from the scene they are drawn in."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

__all__ = ["WallBuckets", "vision_cone"]

#: Angular offset of the two rays cast either side of a wall corner.
_CORNER_EPS = 1e-4
#: Side of a wall bucket (level units).
_BUCKET_SIZE = 8.0


class WallBuckets:
    """Wall segments and corners by square bucket, so a cone on a large level only tests
    the walls near its guard (every wall within reach is still tested: same polygon)."""

    def __init__(self, walls: np.ndarray, corners: np.ndarray) -> None:
        lo = np.floor(walls.min(axis=1) / _BUCKET_SIZE).astype(np.int64)
        hi = np.floor(walls.max(axis=1) / _BUCKET_SIZE).astype(np.int64)
        lists: dict[tuple[int, int], list[int]] = {}
        for i, ((x0, y0), (x1, y1)) in enumerate(zip(lo.tolist(), hi.tolist())):
            for bx in range(x0, x1 + 1):
                for by in range(y0, y1 + 1):
                    lists.setdefault((bx, by), []).append(i)
        self.walls = {k: np.asarray(v, dtype=np.int64) for k, v in lists.items()}
        cells = np.floor(corners / _BUCKET_SIZE).astype(np.int64)
        lists = {}
        for i, (bx, by) in enumerate(cells.tolist()):
            lists.setdefault((bx, by), []).append(i)
        self.corners = {k: np.asarray(v, dtype=np.int64) for k, v in lists.items()}
        self._none = np.zeros(0, dtype=np.int64)

    def near(self, pos: Sequence[float], reach: float) -> tuple[np.ndarray, np.ndarray]:
        """Indices (sorted, each once) of the walls and corners in the buckets a disc of
        ``reach`` touches."""
        x0, y0 = (math.floor((float(v) - reach) / _BUCKET_SIZE) for v in pos)
        x1, y1 = (math.floor((float(v) + reach) / _BUCKET_SIZE) for v in pos)
        keys = [(bx, by) for bx in range(x0, x1 + 1) for by in range(y0, y1 + 1)]
        walls = [self.walls[k] for k in keys if k in self.walls]
        corners = [self.corners[k] for k in keys if k in self.corners]
        # a wall spanning two buckets is listed in both: unique; a corner is in one bucket
        return (np.unique(np.concatenate(walls)) if walls else self._none,
                np.sort(np.concatenate(corners)) if corners else self._none)


#: Below this many candidate walls a cone tests them all rather than filtering by distance.
_NEAR_FILTER_MIN = 96


@functools.lru_cache(maxsize=16)
def _ray_offsets(half_fov: float, rays: int) -> np.ndarray:
    """The evenly spaced ray angles relative to the heading (the same for every cone)."""
    offsets = np.linspace(-half_fov, half_fov, rays)
    offsets.flags.writeable = False
    return offsets


def vision_cone(
    wall_start: np.ndarray, wall_delta: np.ndarray, corners: np.ndarray, pos: Sequence[float],
    heading: float, half_fov: float, reach: float, rays: int,
) -> np.ndarray:
    """Visible polygon of a view sector, clipped by wall segments (vectorised ray casting).

    Rays are cast at ``rays`` evenly spaced angles over ``heading ± half_fov`` plus two
    rays grazing every wall corner inside the sector, so the outline follows the walls'
    corners exactly. Returns ``(k, 2)``: the apex ``pos`` then the ray end points in
    increasing angle.
    """
    px, py = float(pos[0]), float(pos[1])
    origin = np.array([px, py])
    a, d = wall_start, wall_delta
    if len(a) > _NEAR_FILTER_MIN:
        # Walls that can matter: closest point within reach (a wall farther away cannot
        # stop a ray before ``reach``, so with few walls testing them all is cheaper).
        rel = origin - wall_start
        dd = np.einsum("ij,ij->i", wall_delta, wall_delta)
        s = np.clip(np.einsum("ij,ij->i", rel, wall_delta) / np.maximum(dd, 1e-18), 0.0, 1.0)
        near = np.hypot(*(wall_start + s[:, None] * wall_delta - origin).T) <= reach + 1e-9
        a, d = wall_start[near], wall_delta[near]

    angles = heading + _ray_offsets(half_fov, rays)
    if len(corners):
        cv = corners - origin
        cd = np.hypot(cv[:, 0], cv[:, 1])
        ca = np.arctan2(cv[:, 1], cv[:, 0])
        off = (ca - heading + math.pi) % (2 * math.pi) - math.pi
        inside = (cd <= reach) & (cd > 1e-9) & (np.abs(off) < half_fov)
        if inside.any():
            base = heading + off[inside]
            extra = np.concatenate([base - _CORNER_EPS, base + _CORNER_EPS])
            extra = extra[np.abs(extra - heading) <= half_fov]
            angles = np.sort(np.concatenate([angles, extra]))
    ux, uy = np.cos(angles), np.sin(angles)
    t = np.full(len(angles), float(reach))
    if len(a):
        # Solve origin + t·u = a + s·d for every (ray, wall).
        denom = ux[:, None] * d[None, :, 1] - uy[:, None] * d[None, :, 0]
        wx, wy = a[:, 0] - px, a[:, 1] - py
        with np.errstate(divide="ignore", invalid="ignore"):
            tt = (wx[None, :] * d[None, :, 1] - wy[None, :] * d[None, :, 0]) / denom
            ss = (wx[None, :] * uy[:, None] - wy[None, :] * ux[:, None]) / denom
        hit = (np.abs(denom) > 1e-12) & (tt > 1e-9) & (ss >= -1e-9) & (ss <= 1 + 1e-9)
        tt = np.where(hit, tt, np.inf)
        t = np.minimum(t, tt.min(axis=1))
    points = np.empty((len(angles) + 1, 2))
    points[0] = origin
    points[1:, 0] = px + t * ux
    points[1:, 1] = py + t * uy
    return points
