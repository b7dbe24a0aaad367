"""The per-step fast paths give exactly what the plain computations give.

Trials must stay bit-identical when a cache or a numpy rewrite replaces a slower
computation, so each fast path is compared here, by ``==`` on floats, with the
computation it replaces, on the bundled levels and on random inputs.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from navmesh.clearance import PATH_CACHE_SIZE, Clearance, clearance_for
from navmesh.level import load_level

BUNDLED = ["arkham", "dishonored", "maze", "miami", "tlou"]


def _walkable_points(level, n: int, rng: np.random.Generator) -> np.ndarray:
    minx, miny, maxx, maxy = level.walkable.bounds
    p = rng.uniform([minx, miny], [maxx, maxy], size=(8 * n, 2))
    return p[shapely.contains_xy(level.walkable, p[:, 0], p[:, 1])][:n]


@pytest.mark.parametrize("name", BUNDLED)
def test_cached_body_paths_equal_fresh_searches(name: str) -> None:
    """Clearance.path (cached) == Clearance._path (searched) on node points and random
    points, asked twice; every answer is a new list of new tuples."""
    from navmesh.graph import graph_for

    level = load_level(name)
    body = clearance_for(level, 0.3)
    rng = np.random.default_rng(7)
    nodes = graph_for(level, "partition", 0.3).positions
    points = [tuple(p) for p in nodes[rng.choice(len(nodes), 12, replace=False)].tolist()]
    points += [tuple(p) for p in _walkable_points(level, 12, rng).tolist()]
    for _ in range(2):
        for a in points:
            for b in points[::3]:
                first = body.path(a, b)
                again = body.path(a, b)
                assert first == again == body._path(a[0], a[1], b[0], b[1])
                assert all(p is not q for p, q in zip(first, again))


def test_path_cache_is_bounded_and_skips_signed_zeros(monkeypatch: pytest.MonkeyPatch) -> None:
    """Beyond PATH_CACHE_SIZE the least recently used pair goes; a key with a zero
    coordinate is never stored (-0.0 and 0.0 are one dict key but not one waypoint)."""
    import navmesh.clearance

    assert PATH_CACHE_SIZE >= 4096
    monkeypatch.setattr(navmesh.clearance, "PATH_CACHE_SIZE", 8)
    body = Clearance(load_level("maze"), 0.3)
    xs = [float(x) for x in np.linspace(2.0, 3.0, 12)]
    for x in xs:
        body.path((x, 2.5), (2.5, 2.5))
    body.path((xs[5], 2.5), (2.5, 2.5))  # used again: now the most recent
    body.path((2.6, 2.5), (2.5, 2.5))
    assert len(body._paths) == 8
    assert list(body._paths)[-2:] == [(xs[5], 2.5, 2.5, 2.5), (2.6, 2.5, 2.5, 2.5)]
    assert (xs[4], 2.5, 2.5, 2.5) not in body._paths
    size = len(body._paths)
    body.path((0.0, 2.5), (2.5, 2.5))
    assert len(body._paths) == size


def _scipy_presence(m, teammates, node: int) -> np.ndarray:
    """FieldMatrices.presence as it was: one scipy CSR product per call."""
    block = m.kernel[m.candidates[node]]
    spreads = np.stack([m.conf_spread(int(t)) for t in teammates])
    smoothed = np.asarray(block @ spreads.T)
    return np.ascontiguousarray(smoothed.T).sum(axis=0)


@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_presence_equals_the_scipy_product_on_the_bundled_levels(abstraction: str) -> None:
    """Every other node of every bundled level, with 1 to 4 random teammates, bit for bit."""
    from ai.fields import FieldMatrices
    from ai.params import PFParams
    from navmesh.graph import graph_for

    rng = np.random.default_rng(11)
    for name in BUNDLED:
        graph = graph_for(load_level(name), abstraction, 0.3)
        m = FieldMatrices(graph, PFParams())
        rows_only = FieldMatrices(graph, PFParams())
        rows_only.__dict__["presence_table"] = None  # the large-graph path, per-row sums
        assert m.presence_table is not None  # bundled graphs are dense: the table path
        for node in range(rng.integers(2), graph.n, 2):
            mates = rng.integers(graph.n, size=int(rng.integers(1, 5)))
            expected = _scipy_presence(m, mates, node)
            assert np.array_equal(m.presence(mates, node), expected)
            assert np.array_equal(rows_only.presence(mates, node), expected)


def test_presence_equals_the_scipy_product_on_random_inputs() -> None:
    """Random kernel weights (any row width, empty rows, unsorted columns) and random
    spread values spanning many magnitudes, so any change of summation order would show."""
    from ai.fields import FieldMatrices
    from ai.params import PFParams
    from navmesh.graph import NodeGraph
    from scipy import sparse

    rng = np.random.default_rng(5)
    for trial in range(30):
        occupancy = rng.random((9, 13)) > 0.25
        graph = NodeGraph.from_grid(occupancy, 1.0)
        m = FieldMatrices(graph, PFParams(kernel_radius=int(rng.integers(0, 5))))
        n = graph.n
        dense = (rng.random((n, n)) < rng.uniform(0.02, 0.5)) * rng.lognormal(0, 3, (n, n))
        dense[rng.random(n) < 0.1] = 0.0  # some empty rows
        csr = sparse.csr_matrix(dense)
        for r in range(n):  # rows in no particular column order, as a COO build may leave them
            lo, hi = csr.indptr[r], csr.indptr[r + 1]
            order = lo + rng.permutation(hi - lo)
            csr.indices[lo:hi], csr.data[lo:hi] = csr.indices[order], csr.data[order]
        csr.has_sorted_indices = False
        m.kernel = csr
        rows = {t: rng.lognormal(0, 4, n) * (rng.random(n) < 0.8) for t in range(n)}
        m.conf_spread = rows.__getitem__  # type: ignore[method-assign,assignment]
        m._spread_row = lambda which, t: rows[t]  # type: ignore[method-assign,assignment]
        rows_only = FieldMatrices(graph, PFParams())
        rows_only.kernel, rows_only.candidates = csr, m.candidates
        rows_only.conf_spread = rows.__getitem__  # type: ignore[method-assign,assignment]
        rows_only.conf_spread_at = lambda t, at: rows[t][at]  # type: ignore[method-assign,assignment]
        rows_only.__dict__["presence_table"] = None
        for node in rng.integers(n, size=20):
            mates = rng.integers(n, size=int(rng.integers(1, 6)))
            expected = _scipy_presence(m, mates, int(node))
            assert np.array_equal(m.presence(mates, int(node)), expected)  # the dense table
            assert np.array_equal(rows_only.presence(mates, int(node)), expected)  # per row


@pytest.mark.parametrize("penalty", [0.7, 0.0])
def test_dense_select_equals_the_array_select(penalty: float) -> None:
    """CompositeField's Python-float decision on a dense graph == its array decision: the
    same winner, the same score bits (signs of zero included), the same ties and draws."""
    from ai.fields import CompositeField
    from ai.params import PFParams
    from navmesh.graph import NodeGraph

    rng = np.random.default_rng(11)
    for trial in range(12):
        graph = NodeGraph.from_grid(rng.random((8, 11)) > 0.2, 1.0)
        params = PFParams(revisit_penalty=penalty, teammate_presence=float(rng.uniform(0, 2)),
                          tie_eps=float(rng.choice([1e-9, 0.05, 0.5])))
        field = CompositeField(graph, params)
        for _ in range(3):
            field.tick(float(rng.uniform(0, 2)), rng.integers(graph.n, size=3),
                       int(rng.integers(graph.n)) if rng.random() < 0.5 else None)
        assert field.matrices.spreads.tables
        for _ in range(25):
            node = int(rng.integers(graph.n))
            cands = field.matrices.candidates[node]
            if not len(cands):
                continue
            mates = rng.integers(graph.n, size=int(rng.integers(0, 4)))
            recent = [int(x) for x in rng.choice(cands, size=min(len(cands), 2))] + [node]
            personal = rng.normal(size=graph.n) if rng.random() < 0.3 else None
            seed = int(rng.integers(2**31))
            a_rng, b_rng = np.random.default_rng(seed), np.random.default_rng(seed)
            a = field._select_dense(cands, a_rng, mates, recent, personal)
            b = field._select_arrays(node, cands, b_rng, mates, recent, personal)
            assert a is not None and a.winner == b.winner
            assert np.array_equal(a.scores, b.scores)
            assert np.array_equal(np.signbit(a.scores), np.signbit(b.scores))
            assert np.array_equal(a.tied, b.tied) and a.tied.dtype == b.tied.dtype
            assert a_rng.integers(2**62) == b_rng.integers(2**62)
