"""A level's goal in interactive play: pick up every collectible, then reach an exit.

A level may declare ``exits`` (areas) and ``collectibles`` (points) (docs/levels.md). The
player picks a collectible up by walking within ``PICKUP_RADIUS`` of it; standing inside an
exit wins once every collectible is picked up (at once on a level without collectibles).
A level without exits has no goal but surviving the trial's duration. Headless trials do
not use this module, so their metrics are unchanged.

>>> from navmesh.level import parse_level
>>> level = parse_level({"format": "stealth-level/1", "name": "box",
...     "grid": ["#######", "#.....#", "#######"], "guards": [[1.5, 1.5]],
...     "collectibles": [[3.5, 1.5]], "exits": [[[5, 1], [6, 1], [6, 2], [5, 2]]]})
>>> goal = Objectives.of(level)
>>> goal.update((5.5, 1.5)), goal.won     # the exit, but the collectible is still there
((), False)
>>> goal.update((3.4, 1.5)), goal.update((5.5, 1.5)), goal.won
(('collected',), ('escaped',), True)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely

from navmesh.level import Level

__all__ = ["PICKUP_RADIUS", "Objectives"]

#: The player picks a collectible up within this distance (world units) of its centre.
PICKUP_RADIUS = 0.6


@dataclass
class Objectives:
    """What is left to do on one level, updated from the player's position every step."""

    exits: tuple[shapely.Polygon, ...]
    collectibles: np.ndarray
    collected: np.ndarray = field(init=False)
    won: bool = False

    def __post_init__(self) -> None:
        self.collectibles = np.asarray(self.collectibles, dtype=np.float64).reshape(-1, 2)
        self.collected = np.zeros(len(self.collectibles), dtype=bool)
        for area in self.exits:
            shapely.prepare(area)

    @classmethod
    def of(cls, level: Level) -> Objectives:
        """The objectives a level declares."""
        return cls(tuple(level.exits), np.asarray(level.collectibles, dtype=np.float64))

    @property
    def has_goal(self) -> bool:
        """Whether the level has an exit (else the player wins by surviving)."""
        return bool(self.exits)

    @property
    def remaining(self) -> int:
        """Collectibles not picked up yet."""
        return int((~self.collected).sum())

    def update(self, pos: tuple[float, float]) -> tuple[str, ...]:
        """Pick up what is in reach of ``pos`` and check the exits; the events that happened
        now: ``"collected"`` (one per item) and ``"escaped"`` (the game is won)."""
        if self.won:
            return ()
        events: list[str] = []
        if len(self.collectibles):
            d = np.hypot(*(self.collectibles - np.asarray(pos)).T)
            new = (d <= PICKUP_RADIUS) & ~self.collected
            self.collected |= new
            events += ["collected"] * int(new.sum())
        if self.remaining == 0 and any(shapely.contains_xy(a, *pos) for a in self.exits):
            self.won = True
            events.append("escaped")
        return tuple(events)
