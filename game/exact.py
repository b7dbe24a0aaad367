"""Bit-exact compiled ports of what the reference engine computes with CPython and pymunk.

The batch engine must reproduce the reference engine's trials exactly, so its compiled
loops cannot use libm's ``hypot`` (it differs from CPython's ``math.hypot`` in the last
bit for ~0.3 % of inputs) nor a textbook segment intersection (pymunk's line-of-sight
query has its own rounding and tie rules). This module holds the two ports:

* :func:`py_hypot`: CPython 3.11's ``math.hypot`` of two floats (``vector_norm`` in
  Modules/mathmodule.c: power-of-two scaling, Veltkamp-Dekker squaring with
  ``T27 = 2**27 + 1``, compensated summation, one differential correction of the root).
* :func:`clear_line`: ``space.segment_query_first(a, b, 0.0, WALL_QUERY) is None`` for a
  level's walls (Chipmunk 7 as bundled with pymunk: the bounding-box-tree culling
  ``cpBBSegmentQuery``, then ``cpShapeSegmentQuery`` of a radius-0 segment shape), with
  the walls bucketed in a :class:`WallGrid`. :func:`touches_wall` is the conservative
  contact test that decides when a body must go back to pymunk.

The wall queries take finite coordinates; :func:`py_hypot` takes any float.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from numba import njit

#: Veltkamp-Dekker split constant of CPython 3.11's vector_norm: ldexp(1.0, 27) + 1.0
_T27 = 134217729.0
#: CPFLOAT_MIN (DBL_MIN): cpvnormalize divides by length + DBL_MIN
_DBL_MIN = 2.2250738585072014e-308
#: 2**-1000: a gap this small against a segment's extent may underflow in cpBBSegmentQuery
_TINY = 2.0**-1000
#: how far around its own box a wall is bucketed (covers the cell arithmetic's rounding and
#: a box query passing a box this close through a quotient underflowing to -0)
GRID_MARGIN = 0.25
#: slack of :func:`touches_wall` over the body radius
TOUCH_EPS = 1e-6


@njit(cache=True, error_model="numpy")
def py_hypot(x: float, y: float) -> float:
    """``math.hypot(x, y)`` of CPython 3.11, bit for bit (finite or not)."""
    ax = abs(x)
    ay = abs(y)
    mx = 0.0
    if ax > mx:
        mx = ax
    if ay > mx:
        mx = ay
    if math.isinf(mx):
        return mx
    if math.isnan(ax) or math.isnan(ay):
        return math.nan
    if mx == 0.0:
        return mx
    max_e = math.frexp(mx)[1]
    if max_e >= -1023:
        scale = math.ldexp(1.0, -max_e)
        csum = 1.0
        frac1 = 0.0
        frac2 = 0.0
        frac3 = 0.0
        for i in range(2):
            v = ax if i == 0 else ay
            v = v * scale  # lossless scaling
            t = v * _T27
            hi = t - (t - v)
            lo = v - hi
            v = hi * hi
            oldcsum = csum
            csum += v
            frac1 += (oldcsum - csum) + v
            v = 2.0 * hi * lo
            oldcsum = csum
            csum += v
            frac2 += (oldcsum - csum) + v
            frac3 += lo * lo
        h = math.sqrt(csum - 1.0 + (frac1 + frac2 + frac3))
        t = h * _T27
        hi = t - (t - h)
        lo = h - hi
        v = -hi * hi
        oldcsum = csum
        csum += v
        frac1 += (oldcsum - csum) + v
        v = -2.0 * hi * lo
        oldcsum = csum
        csum += v
        frac2 += (oldcsum - csum) + v
        v = -lo * lo
        oldcsum = csum
        csum += v
        frac3 += (oldcsum - csum) + v
        v = csum - 1.0 + (frac1 + frac2 + frac3)
        h += v / (2.0 * h)  # differential correction
        return h / scale
    # subnormal max: ldexp(1.0, -max_e) would overflow, so divide by max instead
    csum = 1.0
    frac1 = 0.0
    for i in range(2):
        v = ax if i == 0 else ay
        v /= mx
        v = v * v
        oldcsum = csum
        csum += v
        frac1 += (oldcsum - csum) + v
    return mx * math.sqrt(csum - 1.0 + frac1)


# --- Chipmunk's inline helpers, with their exact comparison semantics ----------------------


@njit(cache=True, error_model="numpy", inline="always")
def _cpfmin(a: float, b: float) -> float:
    return a if a < b else b


@njit(cache=True, error_model="numpy", inline="always")
def _cpfmax(a: float, b: float) -> float:
    return a if a > b else b


@njit(cache=True, error_model="numpy", inline="always")
def _bb_segment_query(l: float, b: float, r: float, t: float,
                      ax: float, ay: float, bx: float, by: float) -> float:
    """cpBBSegmentQuery: the fraction along a->b where it enters the box, or inf."""
    dx = bx - ax
    dy = by - ay
    tmin = -math.inf
    tmax = math.inf
    if dx == 0.0:
        if ax < l or r < ax:
            return math.inf
    else:
        t1 = (l - ax) / dx
        t2 = (r - ax) / dx
        tmin = _cpfmax(tmin, _cpfmin(t1, t2))
        tmax = _cpfmin(tmax, _cpfmax(t1, t2))
    if dy == 0.0:
        if ay < b or t < ay:
            return math.inf
    else:
        t1 = (b - ay) / dy
        t2 = (t - ay) / dy
        tmin = _cpfmax(tmin, _cpfmin(t1, t2))
        tmax = _cpfmin(tmax, _cpfmax(t1, t2))
    if tmin <= tmax and 0.0 <= tmax and tmin <= 1.0:
        return _cpfmax(tmin, 0.0)
    return math.inf


@njit(cache=True, error_model="numpy", inline="always")
def _wall_hits(segs: np.ndarray, w: int, root_leaf: bool,
               ax: float, ay: float, bx: float, by: float) -> bool:
    """Whether wall ``w`` makes cpSpaceSegmentQueryFirst(a, b, 0) report a shape.

    The tree's culling (``t < t_exit`` with t_exit = 1 until a hit; a lone root leaf is
    not tested), cpShapeSegmentQuery (point query of ``a``, else the segment query) and
    the ``alpha < 1`` of SegmentQueryFirst.
    """
    wax = segs[w, 0]
    way = segs[w, 1]
    wbx = segs[w, 2]
    wby = segs[w, 3]
    if not root_leaf:
        # cpSegmentShapeCacheData's box (radius 0)
        if wax < wbx:
            bl = wax
            br = wbx
        else:
            bl = wbx
            br = wax
        if way < wby:
            bb = way
            bt = wby
        else:
            bb = wby
            bt = way
        # boxes apart by more than the segment's extent times 2**-1000: the box query
        # fails too (it can pass for a closer box, when a quotient underflows to -0)
        sx = abs(bx - ax) * _TINY
        sy = abs(by - ay) * _TINY
        if (min(ax, bx) - br > sx or bl - max(ax, bx) > sx
                or min(ay, by) - bt > sy or bb - max(ay, by) > sy):
            return False
        if not (_bb_segment_query(bl - 0.0, bb - 0.0, br + 0.0, bt + 0.0, ax, ay, bx, by) < 1.0):
            return False
    # cpSegmentShapePointQuery of a (cpClosetPointOnSegment); a hit at distance <= 0
    ex = wax - wbx
    ey = way - wby
    tc = (ex * (ax - wbx) + ey * (ay - wby)) / (ex * ex + ey * ey)
    tc = _cpfmax(0.0, _cpfmin(tc, 1.0))
    cx = wbx + ex * tc
    cy = wby + ey * tc
    px = ax - cx
    py = ay - cy
    if math.sqrt(px * px + py * py) - 0.0 <= 0.0:
        return True
    # cpSegmentShapeSegmentQuery with r = 0; n = cpvrperp(cpvnormalize(b - a))
    vx = wbx - wax
    vy = wby - way
    inv = 1.0 / (math.sqrt(vx * vx + vy * vy) + _DBL_MIN)
    ux = vx * inv
    uy = vy * inv
    nx = uy
    ny = -ux
    d = (wax - ax) * nx + (way - ay) * ny
    if d > 0.0:
        fnx = -nx
        fny = -ny
    else:
        fnx = nx
        fny = ny
    offx = fnx * 0.0 - ax
    offy = fny * 0.0 - ay
    sax = wax + offx
    say = way + offy
    sbx = wbx + offx
    sby = wby + offy
    ddx = bx - ax
    ddy = by - ay
    if (ddx * say - ddy * sax) * (ddx * sby - ddy * sbx) <= 0.0:
        d_offset = d + (-0.0 if d > 0.0 else 0.0)
        ad = -d_offset
        bd = (ddx * nx + ddy * ny) - d_offset
        if ad * bd < 0.0:
            return ad / (ad - bd) < 1.0
    return False


@njit(cache=True, error_model="numpy", inline="always")
def cell_range(lo: float, hi: float, origin: float, cell: float, n: int) -> tuple[int, int]:
    """The clamped cell indices covering [lo, hi] along one axis (clamped as floats: a huge
    coordinate must not overflow the integer)."""
    f0 = math.floor((lo - origin) / cell)
    f1 = math.floor((hi - origin) / cell)
    i0 = 0 if not f0 > 0.0 else (n - 1 if f0 > n - 1 else int(f0))
    i1 = n - 1 if not f1 < n - 1 else (0 if f1 < 0.0 else int(f1))
    return i0, i1


@njit(cache=True, error_model="numpy")
def blocking_wall(segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                  geom: np.ndarray, ax: float, ay: float, bx: float, by: float) -> int:
    """A wall (its row in ``segs``) that makes ``space.segment_query_first((ax, ay),
    (bx, by), 0.0, WALL_QUERY)`` report a hit, or -1 when it reports none (the line is
    clear). Which of several blocking walls is named is unspecified (not pymunk's nearest).

    ``segs``, ``cell_start``, ``cell_items`` and ``geom`` are a :class:`WallGrid`'s; the
    walls of the cells under the segment's box are tested (a wall met twice is harmless).
    """
    nwalls = segs.shape[0]
    if nwalls == 0:
        return -1
    if nwalls == 1:  # the tree's root is the wall's leaf: no box culling
        return 0 if _wall_hits(segs, 0, True, ax, ay, bx, by) else -1
    x0 = geom[0]
    y0 = geom[1]
    cell = geom[2]
    ncx = int(geom[3])
    ncy = int(geom[4])
    lox = ax if ax < bx else bx
    hix = bx if ax < bx else ax
    loy = ay if ay < by else by
    hiy = by if ay < by else ay
    if hix < x0 or hiy < y0 or lox > x0 + ncx * cell or loy > y0 + ncy * cell:
        return -1  # beyond every wall's margin
    i0, i1 = cell_range(lox, hix, x0, cell, ncx)
    j0, j1 = cell_range(loy, hiy, y0, cell, ncy)
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            c = j * ncx + i
            for k in range(cell_start[c], cell_start[c + 1]):
                if _wall_hits(segs, cell_items[k], False, ax, ay, bx, by):
                    return cell_items[k]
    return -1


@njit(cache=True, error_model="numpy")
def clear_line(segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
               geom: np.ndarray, ax: float, ay: float, bx: float, by: float) -> bool:
    """``space.segment_query_first((ax, ay), (bx, by), 0.0, WALL_QUERY) is None``
    (:func:`blocking_wall` finds no wall)."""
    return blocking_wall(segs, cell_start, cell_items, geom, ax, ay, bx, by) < 0


@njit(cache=True, error_model="numpy")
def touches_wall(segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                 geom: np.ndarray, x: float, y: float, r: float) -> bool:
    """Some wall comes within ``r + TOUCH_EPS`` of (x, y): pymunk may make a contact.

    Conservative (pymunk collides a circle and a segment at distance < r): False only
    when no wall can touch the body.
    """
    if segs.shape[0] == 0:
        return False
    x0 = geom[0]
    y0 = geom[1]
    cell = geom[2]
    ncx = int(geom[3])
    ncy = int(geom[4])
    reach = r + TOUCH_EPS
    if (x + reach < x0 or y + reach < y0 or x - reach > x0 + ncx * cell
            or y - reach > y0 + ncy * cell):
        return False
    i0, i1 = cell_range(x - reach, x + reach, x0, cell, ncx)
    j0, j1 = cell_range(y - reach, y + reach, y0, cell, ncy)
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            c = j * ncx + i
            for k in range(cell_start[c], cell_start[c + 1]):
                w = cell_items[k]
                if _segment_distance(segs[w, 0], segs[w, 1], segs[w, 2], segs[w, 3],
                                     x, y) <= reach:
                    return True
    return False


@njit(cache=True, error_model="numpy", inline="always")
def _segment_distance(ax: float, ay: float, bx: float, by: float, x: float, y: float) -> float:
    """Distance from (x, y) to the segment a-b (a point when a == b)."""
    ex = bx - ax
    ey = by - ay
    ll = ex * ex + ey * ey
    t = 0.0
    if ll > 0.0:
        t = ((x - ax) * ex + (y - ay) * ey) / ll
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
    dx = x - (ax + ex * t)
    dy = y - (ay + ey * t)
    return math.sqrt(dx * dx + dy * dy)


class WallGrid:
    """A level's walls bucketed in square cells, as arrays the compiled queries take.

    ``segs`` (W, 4): each wall's ``ax, ay, bx, by``; ``cell_start`` (ncells + 1,) and
    ``cell_items`` (K,): CSR lists of the walls whose box, grown by :data:`GRID_MARGIN`,
    meets each cell (cell ``j * ncx + i`` covers ``[x0 + i*cell, x0 + (i+1)*cell)`` by the
    same in y); ``geom``: ``[x0, y0, cell, ncx, ncy]``. Memory grows with the walls' boxes
    (a level's walls are axis-aligned: their length), never walls x walls or cells x walls.
    """

    def __init__(self, segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                 geom: np.ndarray) -> None:
        self.segs, self.cell_start, self.cell_items, self.geom = segs, cell_start, cell_items, geom

    @property
    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(segs, cell_start, cell_items, geom)``, the queries' first four arguments."""
        return self.segs, self.cell_start, self.cell_items, self.geom

    @classmethod
    def build(cls, walls: Sequence[tuple[tuple[float, float], tuple[float, float]]] | np.ndarray,
              cell: float = 2.0) -> WallGrid:
        """Bucket ``walls`` (``((ax, ay), (bx, by))`` each, or a level's ``(m, 2, 2)`` array)
        in cells of side ``cell``."""
        segs = np.array([[float(a[0]), float(a[1]), float(b[0]), float(b[1])]
                         for a, b in walls], dtype=np.float64).reshape(-1, 4)
        nwalls = len(segs)
        if nwalls == 0:
            geom = np.array([0.0, 0.0, float(cell), 1.0, 1.0])
            return cls(segs, np.zeros(2, dtype=np.int64), np.zeros(0, dtype=np.int64), geom)
        m = GRID_MARGIN
        x0 = float(np.minimum(segs[:, 0], segs[:, 2]).min()) - m
        y0 = float(np.minimum(segs[:, 1], segs[:, 3]).min()) - m
        x1 = float(np.maximum(segs[:, 0], segs[:, 2]).max()) + m
        y1 = float(np.maximum(segs[:, 1], segs[:, 3]).max()) + m
        # keep the cell count linear in the walls for sparse, sprawling levels
        cap = max(4096, 64 * nwalls)
        cell = max(float(cell), math.sqrt((x1 - x0) * (y1 - y0) / cap))
        ncx = int(math.floor((x1 - x0) / cell)) + 1
        ncy = int(math.floor((y1 - y0) / cell)) + 1
        # a wall goes in every cell its box (plus the margin) meets: chipmunk tests a wall
        # only when the sight line enters its box, so one of those cells lies on the line
        cells: list[np.ndarray] = []
        owners: list[np.ndarray] = []
        for w, (ax, ay, bx, by) in enumerate(segs):
            i0 = max(int(math.floor((min(ax, bx) - m - x0) / cell)), 0)
            i1 = min(int(math.floor((max(ax, bx) + m - x0) / cell)), ncx - 1)
            j0 = max(int(math.floor((min(ay, by) - m - y0) / cell)), 0)
            j1 = min(int(math.floor((max(ay, by) + m - y0) / cell)), ncy - 1)
            gi, gj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
            cells.append((gj * ncx + gi).ravel())
            owners.append(np.full(gi.size, w, dtype=np.int64))
        flat_cells = np.concatenate(cells).astype(np.int64)
        flat_walls = np.concatenate(owners)
        order = np.lexsort((flat_walls, flat_cells))
        cell_items = flat_walls[order]
        counts = np.bincount(flat_cells, minlength=ncx * ncy)
        cell_start = np.zeros(ncx * ncy + 1, dtype=np.int64)
        np.cumsum(counts, out=cell_start[1:])
        geom = np.array([x0, y0, cell, float(ncx), float(ncy)], dtype=np.float64)
        return cls(np.ascontiguousarray(segs), cell_start, np.ascontiguousarray(cell_items), geom)


def wall_grid(walls: np.ndarray) -> WallGrid:
    """The :class:`WallGrid` of ``walls`` (``(m, 2, 2)`` or ``(m, 4)``), built once per set
    of walls: every trial of a level shares it (read-only)."""
    segs = np.ascontiguousarray(np.asarray(walls, dtype=np.float64).reshape(-1, 4))
    return _wall_grid(segs.tobytes())


@lru_cache(maxsize=16)
def _wall_grid(data: bytes) -> WallGrid:
    segs = np.frombuffer(data, dtype=np.float64).reshape(-1, 4)
    grid = WallGrid.build([((a, b), (c, d)) for a, b, c, d in segs.tolist()])
    for array in grid.arrays:
        array.flags.writeable = False
    return grid


def forget_stale_cache(module_file: str) -> None:
    """numba's on-disk cache of a module is keyed on that file alone, yet kernels that call
    this module's functions compile them in: when this file changed since the module
    ``module_file`` was cached, drop that module's cached kernels (call at its import)."""
    here = Path(module_file)
    cache = here.parent / "__pycache__"
    stamp = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
    mark = cache / f"{here.stem}.exact-{stamp}"
    if mark.exists():
        return
    try:
        for old in cache.glob(f"{here.stem}.*"):
            old.unlink()
        cache.mkdir(exist_ok=True)
        mark.touch()
    except OSError:  # a read-only install: its cache was made with the files it ships
        pass


__all__ = ["GRID_MARGIN", "TOUCH_EPS", "WallGrid", "blocking_wall", "cell_range", "clear_line",
           "forget_stale_cache", "py_hypot", "touches_wall", "wall_grid"]
