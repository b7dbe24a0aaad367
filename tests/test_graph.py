"""The node graph both abstractions share (SPEC §2): positions, adjacency, distances, queries."""

from __future__ import annotations

import numpy as np
import pytest

from navmesh.graph import NodeGraph, build_graph, graph_for
from navmesh.level import load_level


def l_shape() -> NodeGraph:
    """Walkable cells of an L: a 3-cell column (0,0)-(2,0) and a 3-cell row (2,0)-(2,2)."""
    occupancy = np.array([[1, 0, 0], [1, 0, 0], [1, 1, 1]], dtype=bool)
    return NodeGraph.from_grid(occupancy, 2.0)


def test_grid_nodes_positions_and_neighbours() -> None:
    g = l_shape()
    assert g.kind == "grid" and g.n == 5
    # row-major order of walkable cells; positions are cell centres (x = col, y = row), size 2
    assert g.node_cell.tolist() == [[0, 0], [1, 0], [2, 0], [2, 1], [2, 2]]
    assert g.positions.tolist() == [[1, 1], [1, 3], [1, 5], [3, 5], [5, 5]]
    assert [sorted(nb.tolist()) for nb in g.neighbors] == [[1], [0, 2], [1, 3], [2, 4], [3]]
    assert g.degree.tolist() == [1, 2, 2, 2, 1] and g.max_degree == 2
    assert g.mean_edge_length == pytest.approx(2.0)


def test_hop_and_metric_distances_and_paths() -> None:
    g = l_shape()
    assert g.hops_from(0).tolist() == [0, 1, 2, 3, 4]
    assert g.dist_between(0, 4) == pytest.approx(8.0)  # four edges of length 2
    hops, dist = g.hops_from(range(g.n)), g.dist_from(range(g.n))
    assert np.array_equal(hops, hops.T) and np.allclose(dist, dist.T)
    assert g.shortest_path(0, 4) == [0, 1, 2, 3, 4]
    assert g.shortest_path(3, 3) == [3]
    assert g.next_hop(0, 4) == 1
    assert g.step_towards(0, 4, horizon=2.0) == 1  # one cell
    assert g.step_towards(0, 4, horizon=5.0) == 2  # as far as 5 units reach along the path
    assert g.step_towards(0, 4, horizon=0.1) == 1  # always at least one hop


def test_node_at_inside_and_nearest_outside() -> None:
    g = l_shape()
    assert g.node_at(1.2, 4.9) == 2  # inside cell (2, 0)
    assert g.node_at(5.0, 2.0) == 4  # a blocked cell: the nearest node (3 units away)
    assert g.node_at(-3.0, 0.0) == 0  # off the grid: the nearest node
    assert g.node_near(1.2, 4.9, hint=0) == 2


@pytest.mark.parametrize("name", ["maze", "tlou"])
def test_partition_graph_is_the_mesh_dual(name: str) -> None:
    level = load_level(name)
    g = build_graph(level, "partition")
    mesh = g.mesh
    assert g.kind == "partition" and g.n == len(mesh.triangles)
    assert np.allclose(g.positions, mesh.centroids)
    for t, nbs in enumerate(g.neighbors):  # neighbours share an edge, both ways
        for u in nbs:
            assert t in g.neighbors[u]
            assert len(set(mesh.triangles[t]) & set(mesh.triangles[u])) == 2
    assert (g.hops_from(0) < g.n).all()  # one connected piece
    for t in (0, g.n // 2):
        assert g.node_at(*mesh.centroids[t]) == t
        assert g.node_near(*mesh.centroids[t], hint=t) == t


def test_graphs_are_cached_per_process() -> None:
    level = load_level("miami")
    assert graph_for(level, "grid") is graph_for(load_level("miami"), "grid")
    with pytest.raises(ValueError, match="unknown abstraction 'hex'"):
        build_graph(level, "hex")
