"""The names of the two abstractions (SPEC §2): a grid of cells or a navmesh partition.

Apart from :mod:`navmesh.graph`, which builds either one, so the command line can offer
the names without importing numpy, scipy or shapely.
"""

from __future__ import annotations

__all__ = ["ABSTRACTIONS"]

#: Every abstraction's name, in the order commands list them.
ABSTRACTIONS: tuple[str, ...] = ("grid", "partition")
