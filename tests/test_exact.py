"""game.exact against what it ports: CPython's math.hypot and pymunk's segment query.

Bit-for-bit ``py_hypot`` over a million inputs of every magnitude; ``clear_line`` against
``space.segment_query_first`` on the five bundled levels (random sight lines and the
degenerate ones: through and onto wall endpoints, along walls, from a wall, zero length)
and on random off-grid walls; ``touches_wall`` against a brute-force distance. The timings
print (run with ``-s`` to see them).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pymunk
import pytest
import shapely
from numba import njit

from game.agents import WALL_QUERY, build_space
from game.exact import TOUCH_EPS, WallGrid, clear_line, py_hypot, touches_wall
from navmesh.level import Level, cached_level

LEVELS = ("arkham", "dishonored", "maze", "miami", "tlou")


@njit(error_model="numpy")
def _hypots(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = py_hypot(x[i], y[i])
    return out


@njit(error_model="numpy")
def _clear_lines(segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                 geom: np.ndarray, q: np.ndarray) -> np.ndarray:
    out = np.empty(q.shape[0], dtype=np.bool_)
    for i in range(q.shape[0]):
        out[i] = clear_line(segs, cell_start, cell_items, geom, q[i, 0], q[i, 1], q[i, 2], q[i, 3])
    return out


@njit(error_model="numpy")
def _touches(segs: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray, geom: np.ndarray,
             p: np.ndarray, r: np.ndarray) -> np.ndarray:
    out = np.empty(p.shape[0], dtype=np.bool_)
    for i in range(p.shape[0]):
        out[i] = touches_wall(segs, cell_start, cell_items, geom, p[i, 0], p[i, 1], r[i])
    return out


def _hypot_inputs(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    n = 200_000
    parts = []
    # varied magnitudes, independent exponents, both signs
    for lo, hi in ((-3, 3), (-300, 300), (-320, -300), (290, 308)):
        x = rng.uniform(-1, 1, n) * 10.0 ** rng.uniform(lo, hi, n)
        y = rng.uniform(-1, 1, n) * 10.0 ** rng.uniform(lo, hi, n)
        parts.append((x, y))
    # differences of nearby floats, as positions minus positions
    x, px = rng.uniform(0, 100, (2, n))
    y, py = rng.uniform(0, 100, (2, n))
    parts.append((x - px, y - py))
    xs = x[: n // 4] + rng.uniform(-1e-9, 1e-9, n // 4)
    parts.append((xs - x[: n // 4], y[: n // 4] - py[: n // 4]))
    # equal components, zeros, integers, subnormals
    v = rng.uniform(-100, 100, n // 4)
    parts.append((v, v))
    parts.append((v, -v))
    parts.append((v, np.zeros_like(v)))
    parts.append((np.zeros_like(v), v))
    k = rng.integers(-1000, 1000, (2, n // 4)).astype(float)
    parts.append((k[0], k[1]))
    sub = rng.integers(0, 2**52, (2, n // 4)).astype(np.uint64).view(np.float64)
    parts.append((sub[0], sub[1]))
    parts.append((sub[0], v))
    special = [0.0, -0.0, 5e-324, 2.2250738585072014e-308, 1.0, 1e308, 1.7976931348623157e308]
    sx, sy = np.meshgrid(special, special)
    parts.append((sx.ravel(), sy.ravel()))
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def test_py_hypot_matches_cpython_bit_for_bit() -> None:
    x, y = _hypot_inputs(np.random.default_rng(11))
    assert len(x) >= 1_000_000
    ours = _hypots(x, y)
    theirs = np.fromiter(map(math.hypot, x.tolist(), y.tolist()), dtype=np.float64, count=len(x))
    bad = np.flatnonzero(ours.view(np.int64) != theirs.view(np.int64))
    assert len(bad) == 0, [(x[i], y[i], ours[i], theirs[i]) for i in bad[:5]]
    # not vacuous: libm's hypot (numpy) differs from CPython's on some of these
    with np.errstate(over="ignore"):
        assert (np.hypot(x, y).view(np.int64) != theirs.view(np.int64)).any()


def _reference(space: pymunk.Space, q: np.ndarray) -> np.ndarray:
    query = space.segment_query_first
    return np.fromiter((query((a, b), (c, d), 0.0, WALL_QUERY) is None
                        for a, b, c, d in q.tolist()), dtype=bool, count=len(q))


def _walkable_points(level: Level, rng: np.random.Generator, n: int) -> np.ndarray:
    x0, y0, x1, y1 = level.walkable.bounds
    out = np.empty((0, 2))
    while len(out) < n:
        p = rng.uniform((x0, y0), (x1, y1), (2 * n, 2))
        out = np.vstack([out, p[shapely.contains_xy(level.walkable, p[:, 0], p[:, 1])]])
    return out[:n]


def _random_segments(level: Level, rng: np.random.Generator, n: int) -> np.ndarray:
    a = _walkable_points(level, rng, n)
    ang = rng.uniform(0, 2 * math.pi, n)
    length = rng.uniform(0, 10, n)
    b = a + np.stack([np.cos(ang), np.sin(ang)], axis=1) * length[:, None]
    return np.hstack([a, b])


def _adversarial_segments(segs: np.ndarray, rng: np.random.Generator,
                          bounds: tuple[float, float, float, float]) -> np.ndarray:
    """Sight lines meeting the walls' endpoints, lines and interiors exactly."""
    x0, y0, x1, y1 = bounds
    ends = np.unique(np.vstack([segs[:, :2], segs[:, 2:]]), axis=0)
    n = 4000
    out = []

    def pick(arr: np.ndarray, k: int) -> np.ndarray:
        return arr[rng.integers(0, len(arr), k)]

    free = rng.uniform((x0, y0), (x1, y1), (n, 2))
    e = pick(ends, n)
    out += [np.hstack([free, e]), np.hstack([e, free])]  # ending at / starting from endpoints
    # passing exactly through an endpoint (dyadic steps: exact arithmetic)
    d = rng.integers(-4, 5, (n, 2)) / 4.0
    k, m = rng.integers(0, 9, (2, n, 1)) / 2.0
    out.append(np.hstack([e - k * d, e + m * d]))
    # along walls: collinear with their line, inside, across and beyond their ends
    w = pick(segs, n)
    start, span = w[:, :2], w[:, 2:] - w[:, :2]
    s, t = rng.integers(-8, 25, (2, n, 1)) / 16.0
    out.append(np.hstack([start + s * span, start + t * span]))
    su, tu = rng.uniform(-0.5, 1.5, (2, n, 1))
    out.append(np.hstack([start + su * span, start + tu * span]))
    # starting on a wall, going anywhere near
    on = start + s * span
    out.append(np.hstack([on, on + rng.uniform(-3, 3, (n, 2))]))
    out.append(np.hstack([on + rng.uniform(-3, 3, (n, 2)), on]))
    out.append(np.hstack([on, on + rng.integers(-6, 7, (n, 2)) / 2.0]))
    # zero length: free, on walls, at endpoints
    out += [np.hstack([free, free]), np.hstack([on, on]), np.hstack([e, e])]
    # lattice points (integers and halves, where the walls lie)
    lat = np.round(rng.uniform((x0, y0), (x1, y1), (n, 2)) * 2) / 2
    out.append(np.hstack([lat, lat + rng.integers(-12, 13, (n, 2)) / 2.0]))
    # a hair off an endpoint
    eps = rng.choice([-1e-12, -1e-15, 0.0, 1e-15, 1e-12], (n, 2))
    out.append(np.hstack([e + eps, e + rng.integers(-6, 7, (n, 2)) / 2.0]))
    out.append(np.hstack([e + rng.integers(-6, 7, (n, 2)) / 2.0, e + eps]))
    out.append(np.hstack([np.nextafter(e, e + rng.choice([-1.0, 1.0], (n, 2))),
                          pick(ends, n)]))
    return np.vstack(out)


@pytest.mark.parametrize("name", LEVELS)
def test_clear_line_matches_pymunk_on_levels(name: str) -> None:
    level = cached_level(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    grid = WallGrid.build(level.walls)
    space = build_space(level)
    q = np.vstack([_random_segments(level, rng, 100_000),
                   _adversarial_segments(grid.segs, rng, level.walkable.bounds)])
    ours = _clear_lines(*grid.arrays, q)
    theirs = _reference(space, q)
    bad = np.flatnonzero(ours != theirs)
    assert len(bad) == 0, [(q[i].tolist(), bool(theirs[i])) for i in bad[:5]]
    assert 0.05 < theirs.mean() < 0.95  # both answers well represented


def _space_of(segs: np.ndarray) -> pymunk.Space:
    space = pymunk.Space()
    for ax, ay, bx, by in segs.tolist():
        space.add(pymunk.Segment(space.static_body, (ax, ay), (bx, by), 0.0))
    return space


@pytest.mark.parametrize("count", [0, 1, 2, 60])
def test_clear_line_matches_pymunk_on_random_walls(count: int) -> None:
    """Walls at any angle, off any lattice, some of zero or tiny length; one wall alone
    (a lone leaf is not box-culled by chipmunk's tree)."""
    rng = np.random.default_rng(100 + count)
    segs = rng.uniform(0, 20, (count, 4))
    if count >= 2:
        segs[0, 2:] = segs[0, :2]  # zero length
        segs[1, 2:] = segs[1, :2] + 1e-9
    if count >= 60:
        segs[2:10, 3] = segs[2:10, 1]  # horizontal
        segs[10:20, 2] = segs[10:20, 0]  # vertical
    grid = WallGrid.build([((a, b), (c, d)) for a, b, c, d in segs.tolist()], cell=1.5)
    space = _space_of(segs)
    q = [rng.uniform(-2, 22, (20_000, 4))]
    a = rng.uniform(-2, 22, (20_000, 2))
    q.append(np.hstack([a, a + rng.uniform(-3, 3, (20_000, 2))]))
    if count:
        q.append(_adversarial_segments(segs, rng, (0.0, 0.0, 20.0, 20.0)))
    q_all = np.vstack(q)
    ours = _clear_lines(*grid.arrays, q_all)
    theirs = _reference(space, q_all)
    bad = np.flatnonzero(ours != theirs)
    assert len(bad) == 0, [(q_all[i].tolist(), bool(theirs[i])) for i in bad[:5]]


def test_clear_line_edge_cases() -> None:
    """Chipmunk's tie rules, each against pymunk: a hit must come before alpha 1 (a long
    line crossing one lone wall by one ulp is clear), a line ending on a wall is clear, one
    starting on it (or on a zero-length wall's point) is blocked."""
    up = math.nextafter(5.0, 9.0)
    wall = ((0.0, 5.0), (10.0, 5.0))
    far = ((50.0, 50.0), (51.0, 51.0))
    dot = ((2.0, 2.0), (2.0, 2.0))
    post = ((0.0, 0.0), (0.0, 1.0))
    cases = [
        ([wall], (3.0, -100.0, 3.0, up), True),  # alpha rounds to 1
        ([wall, far], (3.0, -100.0, 3.0, up), True),  # and the box query enters at 1
        ([wall], (3.0, -1.0, 3.0, up), False),
        ([wall, far], (3.0, 0.0, 3.0, 5.0), True),  # ends on the wall
        ([wall, far], (3.0, 5.0, 3.0, 0.0), False),  # starts on it
        ([wall, far], (10.0, 5.0, 12.0, 7.0), False),  # starts on its endpoint
        ([wall, far], (0.0, 7.0, 0.0, 3.0), False),  # through its endpoint
        ([wall, far], (-3.0, 5.0, 13.0, 5.0), True),  # along it
        ([dot, far], (2.0, 2.0, 3.0, 3.0), False),  # from a zero-length wall's point
        ([dot, far], (1.0, 1.0, 3.0, 3.0), True),  # through it
        ([dot, far], (2.0, 2.0, 2.0, 2.0), False),
        ([], (0.0, 0.0, 1.0, 1.0), True),
        # a start 1e-170 off a wall is on it (its distance squared underflows) ...
        ([post], (1e-170, 0.5, -5.0, 0.5), False),
        ([post], (1e-170, 0.5, 5.0, 0.5), False),
        ([post, far], (1e-170, 0.5, 5.0, 0.5), True),  # ... unless the box query culls it
        ([post, far], (2.0**-1000, 0.5, 2.0**80, 0.5), False),  # which a -0 quotient passes
        ([post, far], (2.0**-1000, 0.5, 2.0**60, 0.5), True),
        ([post, far], (-1e20, 0.5, 1e20, 0.5), False),  # far beyond the grid, both ends
        ([post, far], (-1e20, -1e20, 1e20, 1e20), False),  # through its endpoint
        ([post, far], (-1e20, 2.0, 1e20, 2.0), True),
        ([post, far], (-1e20, 2.0, -1e20, 0.5), True),
    ]
    for walls, (ax, ay, bx, by), clear in cases:
        grid = WallGrid.build(walls)
        space = _space_of(grid.segs)
        assert (space.segment_query_first((ax, ay), (bx, by), 0.0, WALL_QUERY) is None) == clear
        assert clear_line(*grid.arrays, ax, ay, bx, by) == clear, (walls, (ax, ay, bx, by))


def test_clear_line_does_not_depend_on_the_cell_size() -> None:
    rng = np.random.default_rng(21)
    segs = rng.uniform(0, 20, (80, 4))
    walls = [((a, b), (c, d)) for a, b, c, d in segs.tolist()]
    q = np.vstack([rng.uniform(-2, 22, (20_000, 4)),
                   _adversarial_segments(segs, rng, (0.0, 0.0, 20.0, 20.0))])
    answers = [_clear_lines(*WallGrid.build(walls, cell=cell).arrays, q)
               for cell in (0.3, 1.0, 2.0, 7.0, 50.0)]
    assert all(np.array_equal(answers[0], other) for other in answers[1:])


@pytest.mark.parametrize("name", ["maze", "dishonored"])
def test_touches_wall_is_conservative_and_tight(name: str) -> None:
    level = cached_level(name)
    rng = np.random.default_rng(7)
    grid = WallGrid.build(level.walls)
    segs = grid.segs
    n = 20_000
    x0, y0, x1, y1 = level.walkable.bounds
    p = rng.uniform((x0 - 2, y0 - 2), (x1 + 2, y1 + 2), (n, 2))
    # many right at the contact distance of some wall
    w = segs[rng.integers(0, len(segs), n // 2)]
    along = w[:, :2] + rng.uniform(-0.2, 1.2, (n // 2, 1)) * (w[:, 2:] - w[:, :2])
    r = rng.uniform(0.05, 1.5, n)
    ang = rng.uniform(0, 2 * math.pi, n // 2)
    gap = r[: n // 2, None] + rng.normal(0, 1e-7, (n // 2, 1))
    p[: n // 2] = along + np.stack([np.cos(ang), np.sin(ang)], 1) * gap
    ours = _touches(*grid.arrays, p, r)
    # brute force over every wall (vectorised point-segment distance)
    a, e = segs[None, :, :2], segs[None, :, 2:] - segs[None, :, :2]
    dist = np.empty(n)
    for lo in range(0, n, 4000):
        rel = p[lo:lo + 4000, None, :] - a
        t = np.clip((rel * e).sum(-1) / (e * e).sum(-1), 0.0, 1.0)
        dist[lo:lo + 4000] = np.linalg.norm(rel - t[..., None] * e, axis=-1).min(axis=1)
    assert not (~ours & (dist < r)).any()  # never misses a contact pymunk could make
    assert not (ours & (dist > r + 2 * TOUCH_EPS)).any()  # and stays tight
    assert np.array_equal(ours, dist <= r + TOUCH_EPS) or (
        np.abs(dist[ours != (dist <= r + TOUCH_EPS)] - r - TOUCH_EPS) < 1e-12).all()


def test_timings() -> None:
    """Per call inside a compiled loop (printed, not asserted)."""
    level = cached_level("dishonored")
    rng = np.random.default_rng(3)
    grid = WallGrid.build(level.walls)
    q = _random_segments(level, rng, 100_000)
    _clear_lines(*grid.arrays, q[:10])
    start = time.perf_counter()
    clear = _clear_lines(*grid.arrays, q)
    per_line = (time.perf_counter() - start) / len(q)
    x, y = rng.uniform(-100, 100, (2, 1_000_000))
    _hypots(x[:10], y[:10])
    start = time.perf_counter()
    _hypots(x, y)
    per_hypot = (time.perf_counter() - start) / len(x)
    print(f"\nclear_line: {per_line * 1e9:.0f} ns/call ({clear.mean():.0%} clear); "
          f"py_hypot: {per_hypot * 1e9:.1f} ns/call")


@pytest.mark.parametrize("name", ["arkham", "miami"])
def test_blocking_wall_names_a_wall_exactly_when_pymunk_reports_a_hit(name: str) -> None:
    from game.exact import blocking_wall, wall_grid

    level = cached_level(name)
    space, grid = build_space(level), wall_grid(level.walls)
    rng = np.random.default_rng(7)
    pts = np.asarray(level.walls, dtype=np.float64).reshape(-1, 2)
    lo, hi = pts.min(axis=0) - 1, pts.max(axis=0) + 1
    for a, b in rng.uniform(lo, hi, size=(2000, 2, 2)).tolist():
        wall = blocking_wall(*grid.arrays, a[0], a[1], b[0], b[1])
        hit = space.segment_query_first(tuple(a), tuple(b), 0.0, WALL_QUERY)
        assert (wall >= 0) == (hit is not None)
        if wall >= 0:  # the named wall itself stops the line
            one = pymunk.Space()
            (wa, wb) = level.walls[wall]
            seg = pymunk.Segment(one.static_body, tuple(wa), tuple(wb), 0.0)
            one.add(seg)
            assert one.segment_query_first(tuple(a), tuple(b), 0.0,
                                           pymunk.ShapeFilter()) is not None


@pytest.mark.parametrize("name", ["dishonored", "tlou"])
def test_compiled_visible_points_equal_the_pymunk_ones(name: str) -> None:
    from game.senses import Senses

    level = cached_level(name)
    space = build_space(level)
    pymunk_senses, compiled = Senses(space, 90.0), Senses(space, 90.0, level.walls)
    pts = np.asarray(level.walls, dtype=np.float64).reshape(-1, 2)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    rng = np.random.default_rng(3)
    points = rng.uniform(lo, hi, size=(3000, 2))
    seen = 0
    for origin, heading in zip(rng.uniform(lo, hi, size=(20, 2)).tolist(),
                               rng.uniform(-math.pi, math.pi, 20).tolist()):
        want = pymunk_senses.visible_points(tuple(origin), heading, points, 9.0)
        got = compiled.visible_points(tuple(origin), heading, points, 9.0)
        assert np.array_equal(want, got)
        seen += int(want.sum())
    assert seen > 100  # the origins saw something: the masks are not trivially empty


@pytest.mark.parametrize("name", ["arkham", "maze"])
def test_compiled_lines_of_sight_need_no_walls_in_the_space(name: str) -> None:
    # the batch engine's worlds keep the walls out of their spaces: their senses answer
    # every perceives() as a space with the walls does
    from game.agents import bodies_space
    from game.senses import Senses

    level = cached_level(name)
    reference = Senses(build_space(level), 90.0)
    compiled = Senses(bodies_space(), 90.0, level.walls, compiled_lines=True)
    pts = np.asarray(level.walls, dtype=np.float64).reshape(-1, 2)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    rng = np.random.default_rng(5)
    blocked = 0
    for a, b in zip(rng.uniform(lo, hi, (2000, 2)).tolist(), rng.uniform(lo, hi, (2000, 2)).tolist()):
        want = reference.perceives(tuple(a), None, tuple(b), 1e9)
        assert compiled.perceives(tuple(a), None, tuple(b), 1e9) == want
        blocked += not want
    assert 100 < blocked < 1990  # both answers occur
    with pytest.raises(ValueError, match="need the walls"):
        Senses(bodies_space(), 90.0, compiled_lines=True)
