"""Issue 24 class 6: memory over many trials in one process stays bounded.

Every per-process cache is bounded: the field matrices of one graph are kept for at most
:data:`ai.field_matrices.MATRICES_PER_GRAPH` parameter sets (a tuner varying ``pf.kernel_lambda``
per trial grew ~0.9 MB a trial before), each with byte-bounded row caches. The measurement
over 2,000 trials is ``benchmarks/memory.py``.
"""

from __future__ import annotations

import ai.field_matrices as fields
from ai.field_matrices import MATRICES_PER_GRAPH, field_matrices
from ai.params import PFParams
from navmesh.graph import graph_for
from navmesh.level import load_level


def test_field_matrices_per_graph_are_bounded_and_reused():
    graph = graph_for(load_level("maze"), "grid")
    first = field_matrices(graph, PFParams(kernel_lambda=0.5))
    for i in range(3 * MATRICES_PER_GRAPH):
        field_matrices(graph, PFParams(kernel_lambda=0.6 + i / 100))
        assert len(fields._MATRIX_CACHE[graph]) <= MATRICES_PER_GRAPH
    again = field_matrices(graph, PFParams(kernel_lambda=0.5))
    assert again is not first  # dropped long ago, built again
    assert field_matrices(graph, PFParams(kernel_lambda=0.5)) is again  # and kept while used
    recent = PFParams(kernel_lambda=0.6 + (3 * MATRICES_PER_GRAPH - 1) / 100)
    kept = field_matrices(graph, recent)
    assert field_matrices(graph, recent) is kept
