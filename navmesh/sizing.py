"""Whether a level fits this machine: its graph's memory, estimated before building it.

``stealth validate`` and ``stealth levels`` call :func:`check_fits` first, so a level too
big to run is refused in one line that says how big it is, never with a MemoryError.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .graph import DENSE_MAX_NODES, ROW_CACHE_BYTES

if TYPE_CHECKING:
    from .level import Level

__all__ = ["BYTES_PER_NODE", "available_bytes", "check_fits", "dense_bytes", "estimate_bytes"]


def dense_bytes(n_nodes: int) -> int:
    """Bytes of the dense all-pairs matrices of an n-node graph (int32 hops and predecessors,
    float64 distances)."""
    return 16 * n_nodes * n_nodes


#: Bytes a graph needs per node beyond dense matrices, measured with margin: CSR adjacency
#: and neighbour lists, the radius-3 kernel, candidate sets, per-node world arrays.
BYTES_PER_NODE = 4096


def estimate_bytes(level: Level) -> tuple[int, int]:
    """(nodes, bytes) a level needs to run, from its size alone, before building anything.

    Nodes: the larger of the walkable cells and twice the walkable polygon's vertices (a
    triangulation's triangle count). Bytes: per node, plus the dense matrices below
    :data:`DENSE_MAX_NODES`, plus the bounded row caches.
    """
    cells = int(level.occupancy.sum())
    vertices = len(level.walkable.exterior.coords) + sum(len(r.coords) for r in level.walkable.interiors)
    nodes = max(cells, 2 * vertices)
    dense = dense_bytes(nodes) if nodes <= DENSE_MAX_NODES else 0
    return nodes, nodes * BYTES_PER_NODE + dense + 2 * ROW_CACHE_BYTES


def available_bytes() -> int | None:
    """Memory the machine can still give (``MemAvailable``), None where unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def check_fits(level: Level, source: str) -> None:
    """Raise a one-line :class:`~navmesh.level.LevelError` if the level cannot run here."""
    from .errors import LevelError

    nodes, need = estimate_bytes(level)
    have = available_bytes()
    if have is not None and need > have:
        raise LevelError(
            source, "size",
            f"{level.rows}x{level.cols} cells, about {nodes} nodes: needs about "
            f"{need / 2**30:.1f} GB to run, {have / 2**30:.1f} GB available",
        )
