"""What a frame is drawn with besides the scene (:class:`DrawOptions`) and where it goes (:class:`Layout`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pygame

from .palette import WARN, Color
from .screens import Panel

if TYPE_CHECKING:
    from .render import Renderer

__all__ = ["DrawOptions", "Layout"]


@dataclass
class DrawOptions:
    """What the caller (play or replay) adds to a frame besides the scene."""

    show_mesh: bool = False
    show_plans: bool = False
    paused: bool = False
    #: help-line items, e.g. ``["WASD move", "Space pause"]``
    help: Sequence[str] = ()
    #: short status text shown in the HUD (last action, speed, ...)
    message: str = ""
    message_color: Color = WARN
    #: a banner panel at the top of the map (end of trace)
    banner: str | None = None
    banner_sub: str = ""
    #: extra HUD items on the first row
    info: Sequence[str] = field(default_factory=tuple)
    #: the second HUD row shows the overlay legend (play) or nothing (replay)
    legend: bool = True
    #: a screen over the map (ready, won / lost, level chooser); wins over ``banner``
    panel: Panel | None = None
    #: collectibles still to pick up ``(k, 2)``
    collectibles: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    #: extra drawing after the cones (noise rings, rain): ``effects(surface, renderer)``
    effects: Callable[[pygame.Surface, Renderer], None] | None = None


@dataclass(frozen=True)
class Layout:
    """Where things go in a window of ``size``: HUD bar, world rectangle, help lines."""

    size: tuple[int, int]
    hud_height: int
    help_height: int
    scale: float
    origin: tuple[float, float]

    @property
    def world_rect(self) -> pygame.Rect:
        """Screen rectangle of the world extent."""
        return pygame.Rect(0, self.hud_height, self.size[0], self.size[1] - self.hud_height - self.help_height)
