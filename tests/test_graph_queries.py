"""On-demand distances (navmesh/graph.py) against dense all-pairs references from scipy.

Every query of a graph searched per source (``dense=False``) must give exactly what the
dense matrices give (bit for bit), and both must match an independent scipy reference:
exactly for hop counts, to 1e-12 for metric distances. Also the field's per-source
spreads, kernel and candidate sets against their old dense construction.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.sparse.csgraph import shortest_path
from scipy.spatial import Delaunay

from ai.fields import CompositeField, FieldMatrices, candidate_sets
from ai.pf import PotentialFieldGuards
from ai.view import WorldView
from ai.params import PFParams
from navmesh.graph import (
    UNREACHABLE_HOPS,
    NodeGraph,
    build_graph,
    falloff_depth,
    hop_ball_pairs,
)
from navmesh.level import bundled_level_names, load_level


def random_grid(seed: int) -> NodeGraph:
    rng = np.random.default_rng(seed)
    occupancy = rng.random((23, 31)) > 0.3
    return NodeGraph.from_grid(occupancy, 0.7)  # several pieces: unreachable pairs too


def random_partition(seed: int) -> NodeGraph:
    rng = np.random.default_rng(seed)
    points = rng.random((150, 2)) * [20.0, 13.0]
    mesh = Delaunay(points)
    return NodeGraph(
        kind="partition",
        positions=points[mesh.simplices].mean(axis=1),
        neighbors=tuple(np.sort(row[row >= 0]) for row in mesh.neighbors),
    )


def graphs() -> list[tuple[str, NodeGraph]]:
    found = [(f"{name}/{ab}", build_graph(load_level(name), ab))
             for name in bundled_level_names() for ab in ("grid", "partition")]
    found += [(f"random-grid-{s}", random_grid(s)) for s in range(2)]
    found += [(f"random-partition-{s}", random_partition(s)) for s in range(2)]
    return found


GRAPHS = graphs()


@pytest.fixture(params=GRAPHS, ids=[name for name, _ in GRAPHS])
def pair(request: pytest.FixtureRequest) -> tuple[NodeGraph, NodeGraph]:
    graph = request.param[1]
    return dataclasses.replace(graph, dense=True), dataclasses.replace(graph, dense=False)


def test_hops_and_distances_match_scipy_and_each_other(pair: tuple[NodeGraph, NodeGraph]) -> None:
    dense, sparse = pair
    assert dense.dense and not sparse.dense
    ref_hops = shortest_path(dense.adjacency, unweighted=True)
    ref_hops[~np.isfinite(ref_hops)] = UNREACHABLE_HOPS
    ref_dist = shortest_path(dense.adjacency, directed=False)
    sources = np.unique(np.linspace(0, dense.n - 1, 25).astype(int))
    for s in sources:
        for g in (dense, sparse):
            assert np.array_equal(g.hops_from(s), ref_hops[s].astype(np.int32))
            finite = np.isfinite(ref_dist[s])
            assert np.array_equal(np.isfinite(g.dist_from(s)), finite)
            assert np.allclose(g.dist_from(s)[finite], ref_dist[s][finite], rtol=1e-12, atol=0)
            assert np.array_equal(g.reachable_from(s), finite)
        assert np.array_equal(dense.dist_from(s), sparse.dist_from(s))  # bit for bit
        for cut in (0, 2, 7):
            assert np.array_equal(dense.hops_from(s, cut), sparse.hops_from(s, cut))
            assert np.array_equal(sparse.hops_from(s, cut),
                                  np.where(ref_hops[s] <= cut, ref_hops[s], UNREACHABLE_HOPS))
        limit = 3.0 * dense.mean_edge_length
        assert np.array_equal(dense.dist_from(s, limit=limit), sparse.dist_from(s, limit=limit))
    a, b = sources[:-1], sources[1:]
    assert np.array_equal(dense.dist_between(a, b), sparse.dist_between(a, b))
    assert np.array_equal(dense.hops_between(a, b), sparse.hops_between(a, b))


def test_paths_and_steps_are_the_same_on_both_storages(pair: tuple[NodeGraph, NodeGraph]) -> None:
    dense, sparse = pair
    rng = np.random.default_rng(3)
    for a, b in rng.integers(dense.n, size=(40, 2)).tolist():
        if not dense.reachable_from(a)[b]:
            with pytest.raises(ValueError, match="not reachable"):
                sparse.shortest_path(a, b)
            continue
        path = dense.shortest_path(a, b)
        assert path == sparse.shortest_path(a, b)
        for horizon in (0.5, 2.0, 5.0):
            step = dense.step_towards(a, b, horizon)
            assert step == sparse.step_towards(a, b, horizon)
            # the compiled walk is the rule: the farthest node of the path within the
            # horizon (+1e-9), at least one hop
            along = dense.dist_from(a)[path]
            within = np.nonzero(along <= horizon + 1e-9)[0]
            assert step == (a if a == b else path[max(1, int(within[-1]))])


def test_nearest_distances_equal_the_min_over_rows(pair: tuple[NodeGraph, NodeGraph]) -> None:
    dense, sparse = pair
    rng = np.random.default_rng(5)
    for k in (1, 2, 4):
        for _ in range(6):
            srcs = rng.choice(dense.n, size=k, replace=False)
            rows = dense.dist_from(srcs).min(axis=0)  # the old dist[guards].min(axis=0)
            assert np.array_equal(dense.nearest_dist(srcs), rows)
            assert np.array_equal(sparse.nearest_dist(srcs), rows)
            target = int(rng.integers(dense.n))
            want = float(dense.dist_from(srcs)[:, target].min())  # the old metric's indexing
            assert sparse.nearest_dist_to(srcs, target) == want == dense.nearest_dist_to(srcs, target)
            reach = 3 * dense.max_edge_length
            near = sparse.nearest_dist(srcs, around=target, reach=reach)
            close = dense.dist_from(target) <= 3 * dense.max_edge_length
            assert np.array_equal(near[close], rows[close])


def test_nearest_distances_of_many_rows_are_each_rows_own(pair: tuple[NodeGraph, NodeGraph]) -> None:
    # the batch engine's distance samples: one call for every trial whose nodes changed
    dense, sparse = pair
    rng = np.random.default_rng(8)
    srcs = rng.integers(-1, dense.n, size=(30, 4))
    srcs[3] = -1  # a row without a source (every guard out of play)
    targets = rng.integers(dense.n, size=30)
    want = [dense.nearest_dist_to([s for s in row if s >= 0], int(t))
            for row, t in zip(srcs.tolist(), targets.tolist())]
    assert want[3] == np.inf and np.isfinite(want).sum() > 20
    assert dense.nearest_dist_to_rows(srcs, targets).tolist() == want
    assert sparse.nearest_dist_to_rows(srcs, targets).tolist() == want


def test_decisions_on_a_searched_graph_equal_the_dense_ones(pair: tuple[NodeGraph, NodeGraph]) -> None:
    """A large graph's field reads K at a decision's candidates alone (kernel_at) and the
    spreads from their balls: the scores, winners and explanations stay bit for bit."""
    dense, sparse = pair
    rng = np.random.default_rng(9)
    fields = [CompositeField(g) for g in (dense, sparse)]
    for step in range(3):
        guards = rng.choice(dense.n, size=3)
        sighting = int(rng.integers(dense.n)) if step != 1 else None
        extra = -rng.random(dense.n) * (rng.random(dense.n) < 0.1)
        for f in fields:
            f.tick(1.0, guards, sighting)
            f.extra_information = extra
        assert np.array_equal(fields[0].kernel(), fields[1].kernel())
        for node in range(0, dense.n, max(1, dense.n // 25)):
            mates = rng.choice(dense.n, size=2)
            a, b = (f.select(node, np.random.default_rng(node), mates) for f in fields)
            assert np.array_equal(a.scores, b.scores) and a.winner == b.winner
            assert np.array_equal(fields[1].kernel_at(node),
                                  fields[1].kernel()[fields[1].candidates(node)])
    answers = []
    for graph in (dense, sparse):
        guards = PotentialFieldGuards()
        guards.reset(graph, np.random.default_rng(0), 3)
        nodes = np.array([0, graph.n // 2, graph.n - 1])
        view = WorldView(t=0.0, graph=graph, guard_nodes=nodes,
                         guard_positions=graph.positions[nodes], guard_headings=np.zeros(3),
                         player_node=graph.n // 3, player_pos=graph.positions[graph.n // 3],
                         sighting=graph.n // 3)
        guards.tick(view, 1.0)
        answers.append([(guards.decide(i, view), guards.explain(i)) for i in range(3)])
    assert answers[0] == answers[1]


def test_hop_balls_match_the_dense_matrix(pair: tuple[NodeGraph, NodeGraph]) -> None:
    dense, _ = pair
    hops = dense.hops_from(range(dense.n))
    for radius in (0, 1, 3):
        rows, cols, found = hop_ball_pairs(dense, radius)
        want_rows, want_cols = np.nonzero(hops <= radius)
        assert np.array_equal(rows, want_rows) and np.array_equal(cols, want_cols)
        assert np.array_equal(found, hops[rows, cols])


def test_field_precomputation_matches_the_dense_construction(pair: tuple[NodeGraph, NodeGraph]) -> None:
    dense, sparse = pair
    params = PFParams()
    hops = dense.hops_from(range(dense.n))
    reachable = hops < UNREACHABLE_HOPS
    conf = np.where(reachable, params.gamma_C ** hops.astype(np.float64), 0.0)
    info = np.where(reachable, params.gamma_I ** hops.astype(np.float64), 0.0)
    old_kernel = _old_kernel(hops, params.kernel_lambda, params.kernel_radius)
    presence = np.ascontiguousarray(np.asarray(old_kernel @ conf).T)
    dist = dense.dist_from(range(dense.n))
    old_candidates = _old_candidates(dense, dist, params.r_edge_factor)
    for graph in (dense, sparse):
        m = FieldMatrices(graph, params)
        assert (m.kernel != old_kernel).nnz == 0
        assert np.array_equal(m.kernel.indices, old_kernel.indices)
        for s in range(0, graph.n, max(1, graph.n // 40)):
            assert np.array_equal(m.conf_spread(s), conf[s])
            assert np.array_equal(m.info_spread(s), info[s])
            assert np.array_equal(m.candidates[s], old_candidates[s])
            mates = [s, (s * 7 + 3) % graph.n]
            assert np.array_equal(m.deposit(mates), conf[mates].sum(axis=0))
            cands = m.candidates[s]
            assert np.array_equal(m.presence(mates, s), presence[mates][:, cands].sum(axis=0))
    assert all(np.array_equal(a, b) for a, b in
               zip(candidate_sets(sparse, 2.5), old_candidates, strict=True))


def test_spreads_stop_below_the_tolerance() -> None:
    long = NodeGraph.from_grid(np.ones((1, 400), dtype=bool), 1.0, dense=False)
    m = FieldMatrices(long, PFParams())
    depth = falloff_depth(0.8)
    assert 0.8**depth >= 1e-12 > 0.8 ** (depth + 1)
    row = m.conf_spread(0)
    assert row[depth] == 0.8**depth and not row[depth + 1 :].any()
    assert falloff_depth(1.0) is None


def _old_kernel(hops: np.ndarray, lam: float, radius: int):  # type: ignore[no-untyped-def]
    from scipy import sparse

    rows, cols = np.nonzero(hops <= radius)
    weights = lam ** hops[rows, cols].astype(np.float64)
    totals = np.bincount(rows, weights=weights, minlength=len(hops))
    n = len(hops)
    return sparse.csr_matrix((weights / totals[rows], (rows, cols)), shape=(n, n))


def _old_candidates(graph: NodeGraph, dist: np.ndarray, factor: float) -> list[np.ndarray]:
    """The candidate sets as the dense implementation computed them (all sources at once)."""
    neighbours = [np.asarray(nb, dtype=np.intp) for nb in graph.neighbors]
    r_edge = factor * graph.mean_edge_length
    if graph.kind == "grid":
        return neighbours
    coo = graph.adjacency.tocoo()
    u, v, w = coo.row, coo.col, coo.data
    du, dv = dist[:, u], dist[:, v]
    tol = 1e-9 * (1.0 + np.abs(dv))
    with np.errstate(invalid="ignore"):
        frontier = (du < r_edge) & (dv >= r_edge) & (np.abs(du + w - dv) <= tol)
    result = []
    for s, row in enumerate(frontier):
        found = np.unique(v[row]).astype(np.intp)
        result.append(found if len(found) else neighbours[s])
    return result
