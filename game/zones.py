"""The level's zones on a node graph: which nodes are dark or concealed and what that does.

:class:`ZoneMap` is what the world and the replay viewer share: per zone kind a node mask
(a node is in a zone when its position is), the zone rules of the ``[zones]`` config
section (:class:`ai.stimuli.Zone`) and, per node, the factor on the guards' view range while
the player stands there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely

from ai.stimuli import Zone, zone_view_scale, zones_from_config
from navmesh.graph import NodeGraph
from navmesh.level import Level


def zone_masks(level: Level, graph: NodeGraph) -> dict[str, np.ndarray]:
    """Per zone kind of the level, the nodes whose position lies in one of its polygons."""
    masks = {}
    x, y = graph.positions[:, 0], graph.positions[:, 1]
    for kind, polygons in level.zones.items():
        mask = np.zeros(graph.n, dtype=bool)
        for polygon in polygons:
            mask |= shapely.intersects_xy(polygon, x, y)
        masks[kind] = mask
    return masks


@dataclass(frozen=True)
class ZoneMap:
    """Zone masks, rules and per-node view scale of one level on one graph."""

    masks: dict[str, np.ndarray]
    rules: dict[str, Zone]
    view_scale: np.ndarray

    @classmethod
    def build(cls, level: Level, graph: NodeGraph, config: Any) -> ZoneMap:
        """From the level's polygons and the config's ``[zones]`` section."""
        masks = zone_masks(level, graph)
        rules = zones_from_config(config.section("zones"))
        return cls(masks, rules, zone_view_scale(rules, masks, graph.n))

    def mask(self, kind: str) -> np.ndarray:
        """The nodes of zone ``kind`` (all false if the level has none)."""
        found = self.masks.get(kind)
        return found if found is not None else np.zeros(len(self.view_scale), dtype=bool)


__all__ = ["ZoneMap", "zone_masks"]
