"""Whether a level fits this machine: its graph's memory and its navmesh's work, estimated
before building anything.

``stealth validate`` and ``stealth levels`` call :func:`check_fits` first, so a level too
big to run is refused in one line that says how big it is, never with a MemoryError.
:func:`check_mesh_work` bounds the partition's geometry work the same way (its navmesh's
triangulation and its trials' eroded path area): every build of a level's partition graph
(:func:`navmesh.graph.build_graph`, so ``levels``, ``path``, ``sim``, ``run``, ``play``,
``replay``) checks it before triangulating.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import shapely

from .distances import ROW_CACHE_BYTES, keeps_dense

if TYPE_CHECKING:
    from shapely.geometry import Polygon

    from .level import Level

__all__ = ["BYTES_PER_NODE", "MAX_MESH_CORNERS", "MAX_MESH_HOLE_WORK", "MAX_PATH_HOLE_WORK",
           "available_bytes",
           "check_fits", "check_mesh_work", "dense_bytes", "estimate_bytes", "walkable_size"]

#: Corners of the walkable polygon the partition navmesh triangulates at most: the polygon
#: form's ``MAX_LEVEL_VERTICES``, for every form (the grid form's traced polygon had no
#: bound). The rest of the build (rings, refinement, locator) is about linear in them.
MAX_MESH_CORNERS = 200_000
#: holes × corners the partition navmesh triangulates at most. GEOS's constrained Delaunay
#: joins the holes to the outline one by one, each join costing about the corners joined
#: so far: measured 6–8 ns × holes × corners (grids of pillars and of plus-shaped holes,
#: the 1000×1000 building: 1.0 × 10^9, 6.7 s), so about 10 s at the limit.
MAX_MESH_HOLE_WORK = 1_500_000_000
#: holes × outline corners at most: a partition trial also erodes the walkable area by the
#: body's radius (:attr:`navmesh.clearance.Clearance.path_area`), and GEOS's buffer then
#: tests every hole against the outline it may lie in, corner by corner: measured
#: 50–75 ns × holes × outline corners (a toothed outline of 1.7 × 10^5 corners above
#: 7,396 pillars: minutes), so 10–15 s at the limit. A grid of pillars in a box or the
#: 1000×1000 building (outline of 4 corners) is far below it.
MAX_PATH_HOLE_WORK = 200_000_000


def walkable_size(polygon: Polygon) -> tuple[int, int]:
    """(holes, corners) of a walkable polygon (closing points not counted), without a
    Python loop over its rings (a grid of pillars has 250,000)."""
    holes = int(shapely.get_num_interior_rings(polygon))
    return holes, int(shapely.get_num_coordinates(polygon)) - (holes + 1)


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
    triangulation's triangle count). Bytes: per node, plus the dense matrices when
    :func:`~navmesh.distances.keeps_dense` says the graph keeps them, plus the bounded row caches.
    """
    cells = int(level.occupancy.sum())
    vertices = int(shapely.get_num_coordinates(level.walkable))  # closing points included
    nodes = max(cells, 2 * vertices)
    dense = dense_bytes(nodes) if keeps_dense(nodes) else 0
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


def check_mesh_work(level: Level, source: str | None = None) -> None:
    """Raise a one-line :class:`~navmesh.level.LevelError` if the level's partition navmesh
    would take too long to triangulate: more than :data:`MAX_MESH_CORNERS` corners, or more
    than :data:`MAX_MESH_HOLE_WORK` holes × corners; or its trials' eroded path area too
    long to compute: more than :data:`MAX_PATH_HOLE_WORK` holes × outline corners.
    ``source`` names the level (default: its file name, as
    :func:`navmesh.clearance.check_body` does). The grid abstraction builds neither and has
    no such limit.
    """
    from .errors import LevelError

    holes, corners = walkable_size(level.walkable)
    src = source or (level.path.name if level.path is not None else level.name)
    if corners > MAX_MESH_CORNERS:
        raise LevelError(
            src, "walkable area",
            f"{corners} corners ({holes} holes) for the partition navmesh, more than the "
            f"limit of {MAX_MESH_CORNERS} (the grid abstraction has no such limit)")
    if holes * corners > MAX_MESH_HOLE_WORK:
        raise LevelError(
            src, "walkable area",
            f"{holes} holes x {corners} corners = {holes * corners:.3g} for the partition "
            f"navmesh, more than the limit of {MAX_MESH_HOLE_WORK:.3g} (its triangulation "
            f"time grows with holes x corners; the grid abstraction has no such limit)")
    outline = int(shapely.get_num_coordinates(level.walkable.exterior)) - 1
    if holes * outline > MAX_PATH_HOLE_WORK:
        raise LevelError(
            src, "walkable area",
            f"{holes} holes x {outline} outline corners = {holes * outline:.3g} for the "
            f"partition's path area (the walkable area eroded by a body), more than the limit "
            f"of {MAX_PATH_HOLE_WORK:.3g} (its time grows with holes x outline corners; the "
            f"grid abstraction has no such limit)")
