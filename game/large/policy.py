"""What the game does differently on a large level, decided once from the graph's storage.

On a graph that keeps dense distances (every bundled level) everything is computed in the
frame. On one that searches per source (:mod:`navmesh.distances`), the front end computes
the whole-field overlay on a background thread, composes new field values over a few frames
and hands the distance metric's searches to a worker process (:mod:`game.large.distance_worker`).
The vision cones of a level with many wall segments test each ray against the walls of the
cells it crosses (:class:`game.ray_cast.WallBuckets`) instead of against all of them
(:func:`bucket_walls`). None of it changes a value, only when it is computed.
"""

from __future__ import annotations

from dataclasses import dataclass

from navmesh.graph import NodeGraph

__all__ = ["BUCKET_MIN_WALLS", "SizePolicy", "bucket_walls"]

#: Levels with more wall segments than this bucket them for the vision cones.
BUCKET_MIN_WALLS = 2000


def bucket_walls(n_walls: int) -> bool:
    """Whether the cones of a level with ``n_walls`` wall segments bucket them by cell.

    >>> bucket_walls(2000), bucket_walls(2001)
    (False, True)
    """
    return n_walls > BUCKET_MIN_WALLS


@dataclass(frozen=True)
class SizePolicy:
    """The large-level choices of the front end, read from the graph in one place.

    >>> import numpy as np
    >>> SizePolicy.of(NodeGraph.from_grid(np.ones((2, 2), bool), 1.0)).large
    False
    """

    #: the graph searches per source instead of keeping dense tables
    large: bool

    @classmethod
    def of(cls, graph: NodeGraph) -> SizePolicy:
        """The policy of a level whose node graph is ``graph``."""
        return cls(large=not graph.dense)

    @property
    def background_fields(self) -> bool:
        """Compute the whole-field overlay beside the frames (:class:`game.scene.SceneBuilder`)."""
        return self.large

    @property
    def striped_compose(self) -> bool:
        """Compose new field values over a few frames (``game/front/layers.py``)."""
        return self.large

    @property
    def distance_worker(self) -> bool:
        """Run the distance metric's searches in a worker process (:mod:`game.large.distance_worker`)."""
        return self.large
