"""The composite potential field against numbers worked out by hand (paper Table 2 defaults).

Graphs: a 1×5 corridor (nodes 0..4 left to right), a full 3×3 grid, a 3×3 ring (centre
blocked) and small hand-built partition-like graphs.
"""

from __future__ import annotations

import numpy as np
import pytest

from ai.fields import CompositeField, candidate_sets, field_matrices
from ai.params import PFParams
from navmesh.graph import NodeGraph


def corridor(length: int = 5) -> NodeGraph:
    return NodeGraph.from_grid(np.ones((1, length), dtype=bool), 1.0)


def partition_graph(points: list[tuple[float, float]], edges: list[tuple[int, int]]) -> NodeGraph:
    """A partition-kind graph with the given node positions and undirected edges."""
    neighbours: list[list[int]] = [[] for _ in points]
    for a, b in edges:
        neighbours[a].append(b)
        neighbours[b].append(a)
    return NodeGraph(
        kind="partition",
        positions=np.array(points, dtype=np.float64),
        neighbors=tuple(np.array(sorted(nb), dtype=np.int64) for nb in neighbours),
    )


# ---------------------------------------------------------------------------- I


def test_sighting_sets_information_from_the_player_node() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [4], sighting_node=0)
    # −I0 γ_I^d = −5 · 0.9^d
    assert field.information == pytest.approx([-5.0, -4.5, -4.05, -3.645, -3.2805])


def test_information_decays_by_rho_without_sighting() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [4], sighting_node=0)
    field.tick(1.0, [4], sighting_node=None)
    assert field.information == pytest.approx([-4.75, -4.275, -3.8475, -3.46275, -3.116475])
    field.tick(1.0, [4], sighting_node=None)
    assert field.information[0] == pytest.approx(-4.5125)


def test_new_sighting_resets_information() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [], sighting_node=0)
    field.tick(1.0, [], sighting_node=4)  # old trace at 0 is gone, not added to
    assert field.information == pytest.approx([-3.2805, -3.645, -4.05, -4.5, -5.0])


def test_information_decay_scales_with_fractional_ticks() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [], sighting_node=0)
    field.tick(0.5, [], sighting_node=None)
    # 0.95 ** 0.5 = 0.974679434480896
    assert field.information[0] == pytest.approx(-5 * 0.974679434480896)
    field.tick(0.5, [], sighting_node=None)
    assert field.information[0] == pytest.approx(-4.75)  # two half ticks = one whole


# ---------------------------------------------------------------------------- C


def test_confidence_deposit_and_decay() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [2], sighting_node=None)
    # C0 γ_C^d = 0.8^d around the guard
    assert field.confidence == pytest.approx([0.64, 0.8, 1.0, 0.8, 0.64])
    field.tick(1.0, [2], sighting_node=None)
    # 0.95 · previous + deposit
    assert field.confidence == pytest.approx([1.248, 1.56, 1.95, 1.56, 1.248])


def test_confidence_sums_over_guards() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [0, 4], sighting_node=None)
    assert field.confidence == pytest.approx([1.4096, 1.312, 1.28, 1.312, 1.4096])


def test_dark_node_decays_confidence_faster() -> None:
    field = CompositeField(corridor())
    field.set_confidence_decay([4], 0.80)
    field.tick(1.0, [2], sighting_node=None)
    field.tick(1.0, [2], sighting_node=None)
    # node 4: 0.80 · 0.64 + 0.64; the others as without the override
    assert field.confidence == pytest.approx([1.248, 1.56, 1.95, 1.56, 1.152])
    mask = np.array([True, False, False, False, False])
    field.set_confidence_decay(mask, 0.5)
    assert field.confidence_decay.tolist() == [0.5, 0.95, 0.95, 0.95, 0.8]


def test_confidence_decay_scales_with_fractional_ticks() -> None:
    field = CompositeField(corridor())
    field.set_confidence_decay([4], 0.80)
    field.tick(1.0, [2], sighting_node=None)
    field.tick(0.25, [], sighting_node=None)
    assert field.confidence[0] == pytest.approx(0.64 * 0.95**0.25)
    assert field.confidence[4] == pytest.approx(0.64 * 0.80**0.25)


def test_state_arrays_are_read_only_snapshots() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [2], sighting_node=None)
    before = field.confidence
    with pytest.raises(ValueError):
        before[0] = 3.0
    field.tick(1.0, [2], sighting_node=None)
    assert before == pytest.approx([0.64, 0.8, 1.0, 0.8, 0.64])  # the old snapshot is kept


# ---------------------------------------------------------------------------- N


def test_connectivity_is_max_degree_minus_degree() -> None:
    assert CompositeField(corridor()).connectivity.tolist() == [1, 0, 0, 0, 1]
    full = NodeGraph.from_grid(np.ones((3, 3), dtype=bool), 1.0)
    assert CompositeField(full).connectivity.tolist() == [2, 1, 2, 1, 0, 1, 2, 1, 2]


# ---------------------------------------------------------------------------- weights


def test_weight_schedule() -> None:
    field = CompositeField(corridor())
    assert field.weights == pytest.approx((0.4, 0.5, 0.1))
    field.tick(1.0, [], sighting_node=2)
    # w_I_max, and 1 − 0.9 split 5 : 1
    assert field.weights == pytest.approx((0.9, 0.1 * 5 / 6, 0.1 / 6))
    field.tick(1.0, [], sighting_node=None)
    assert field.weights == pytest.approx((0.85, 0.125, 0.025))
    field.tick(0.5, [], sighting_node=None)
    assert field.weights == pytest.approx((0.825, 0.145833333, 0.0291666667))
    for _ in range(20):
        field.tick(1.0, [], sighting_node=None)
    assert field.weights == pytest.approx((0.4, 0.5, 0.1))  # floored at w_I_base
    field.tick(1.0, [], sighting_node=0)
    assert field.w_I == 0.9


def test_weights_reach_base_after_ten_seconds() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [], sighting_node=0)
    for _ in range(9):
        field.tick(1.0, [], sighting_node=None)
    assert field.w_I == pytest.approx(0.45)
    field.tick(1.0, [], sighting_node=None)
    assert field.w_I == pytest.approx(0.4)


# ---------------------------------------------------------------------------- P and K


def test_potential_is_the_weighted_sum() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [4], sighting_node=0)
    # 0.9 I + C / 12 + N / 60 with C = 0.8^(4 − n), N = [1, 0, 0, 0, 1]
    assert field.potential() == pytest.approx(
        [-4.4492, -4.0073333333, -3.5916666667, -3.2138333333, -2.85245]
    )


def test_kernel_matrix_rows_by_hand() -> None:
    kmat = field_matrices(corridor(), PFParams()).kernel.toarray()
    assert kmat[0] == pytest.approx(np.array([1, 0.8, 0.64, 0.512, 0]) / 2.952)
    assert kmat[1] == pytest.approx(np.array([0.8, 1, 0.8, 0.64, 0.512]) / 3.752)
    assert kmat[2] == pytest.approx(np.array([0.64, 0.8, 1, 0.8, 0.64]) / 3.88)
    assert kmat.sum(axis=1) == pytest.approx(np.ones(5))
    narrow = field_matrices(corridor(), PFParams(kernel_radius=1)).kernel.toarray()
    assert narrow[2] == pytest.approx(np.array([0, 0.8, 1, 0.8, 0]) / 2.6)


def test_kernel_smooths_the_potential() -> None:
    field = CompositeField(corridor())
    field.extra_information = np.array([-1.0, 0, 0, 0, 0])
    # P = 0.4 · I_extra + 0.1 · N with N = [1, 0, 0, 0, 1]
    assert field.potential() == pytest.approx([-0.3, 0, 0, 0, 0.1])
    expected = [
        -0.3 / 2.952,
        (-0.3 * 0.8 + 0.1 * 0.512) / 3.752,
        (-0.3 * 0.64 + 0.1 * 0.64) / 3.88,
        (-0.3 * 0.512 + 0.1 * 0.8) / 3.752,
        0.1 / 2.952,
    ]
    assert field.kernel() == pytest.approx(expected)


def test_extra_information_is_added_to_information() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [], sighting_node=0)
    before = field.potential().copy()
    layer = np.array([0.0, 0.0, 0.0, -1.0, -2.0])
    field.extra_information = layer
    assert field.potential() - before == pytest.approx(0.9 * layer)
    with pytest.raises(ValueError):
        field.extra_information = np.zeros(3)
    with pytest.raises(ValueError):
        field.extra_information[0] = 1.0  # read-only: assign a new array instead


# ---------------------------------------------------------------------------- candidates


def test_grid_candidates_are_the_four_neighbours() -> None:
    ring = NodeGraph.from_grid(np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]], dtype=bool), 1.0)
    # nodes row-major: (0,0)=0 (0,1)=1 (0,2)=2 (1,0)=3 (1,2)=4 (2,0)=5 (2,1)=6 (2,2)=7
    candidates = candidate_sets(ring, 2.5)
    assert sorted(candidates[0].tolist()) == [1, 3]
    assert sorted(candidates[1].tolist()) == [0, 2]
    assert sorted(candidates[4].tolist()) == [2, 7]
    full = NodeGraph.from_grid(np.ones((3, 3), dtype=bool), 1.0)
    assert sorted(candidate_sets(full, 2.5)[4].tolist()) == [1, 3, 5, 7]


def test_partition_candidates_are_the_r_edge_frontier() -> None:
    # a path 0–1–2–3–4–5 along x (unit edges) with a branch 2–6 up; mean edge 1, R = 2.5
    graph = partition_graph(
        [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0), (2, 1)],
        [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (2, 6)],
    )
    candidates = candidate_sets(graph, 2.5)
    assert sorted(candidates[0].tolist()) == [3, 6]  # both at distance 3, first ≥ 2.5
    assert sorted(candidates[2].tolist()) == [5]  # 0 and 6 are dead ends inside R
    assert sorted(candidates[6].tolist()) == [0, 4]
    # R = 1.5: node 2 (distance 2) is the first on the way; 6 lies beyond it, 3 too
    assert candidate_sets(graph, 1.5)[0].tolist() == [2]
    assert sorted(candidate_sets(graph, 1.5)[3].tolist()) == [1, 5, 6]


def test_partition_candidates_fall_back_to_neighbours() -> None:
    # a triangle of unit edges: everything lies within R = 2.5
    graph = partition_graph([(0, 0), (1, 0), (0.5, 0.866)], [(0, 1), (1, 2), (0, 2)])
    candidates = candidate_sets(graph, 2.5)
    assert sorted(candidates[0].tolist()) == [1, 2]


def test_partition_candidates_use_metric_lengths() -> None:
    # 0 –(1)– 1 –(4)– 2 –(1)– 3: mean edge 2, R = 5 → from 0, node 2 (dist 5) is the first ≥ R
    graph = partition_graph([(0, 0), (1, 0), (5, 0), (6, 0)], [(0, 1), (1, 2), (2, 3)])
    assert candidate_sets(graph, 2.5)[0].tolist() == [2]
    assert candidate_sets(graph, 2.5)[3].tolist() == [1]


# ---------------------------------------------------------------------------- choice and ties


def test_choose_takes_the_least_kernel_value() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [4], sighting_node=0)
    choice = field.select(2, np.random.default_rng(0))
    kernel = field.kernel()
    assert choice.winner == 1
    assert kernel[1] < kernel[3]
    assert choice.tied.tolist() == [1]


def test_ties_are_broken_by_the_generator_not_list_order() -> None:
    field = CompositeField(corridor())
    field.tick(1.0, [2], sighting_node=None)  # symmetric: K(1) == K(3)
    kernel = field.kernel()
    assert abs(kernel[1] - kernel[3]) < 1e-9
    picks = {seed: field.choose(2, np.random.default_rng(seed)) for seed in range(20)}
    assert set(picks.values()) == {1, 3}
    for seed, pick in picks.items():
        assert field.choose(2, np.random.default_rng(seed)) == pick
    assert sorted(field.select(2, np.random.default_rng(0)).tied.tolist()) == [1, 3]


def test_matrices_are_cached_per_graph_and_parameters() -> None:
    graph = corridor()
    assert CompositeField(graph).matrices is CompositeField(graph).matrices
    assert (
        CompositeField(graph, PFParams(gamma_C=0.5)).matrices is not CompositeField(graph).matrices
    )
    assert CompositeField(corridor()).matrices is not CompositeField(graph).matrices


def test_params_reject_unknown_and_bad_values() -> None:
    assert PFParams.from_mapping({"rho": 0.9, "kernel_radius": 2}).kernel_radius == 2
    with pytest.raises(ValueError, match="roh"):
        PFParams.from_mapping({"roh": 0.9})
    with pytest.raises(ValueError, match="rho"):
        PFParams.from_mapping({"rho": 1.5})
    with pytest.raises(ValueError, match="kernel_radius"):
        PFParams.from_mapping({"kernel_radius": 2.5})
