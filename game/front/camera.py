"""The camera: which part of the level the window shows, at which zoom.

``zoom = None`` fits the whole level into the window (small levels, the default when it
fits at :data:`MIN_FIT_SCALE` px per world unit or more). Zooming in (mouse wheel, ``+``)
switches to following a point (the player), clamped so the view stays over the level;
zooming out back to the fit scale fits again.

>>> cam = Camera()
>>> cam.scale(fit=10.0), cam.zoom_by(2.0, fit=10.0), cam.scale(fit=10.0)
(10.0, True, 20.0)
>>> cam.zoom_by(0.1, fit=10.0), cam.zoom
(True, None)
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["MAX_SCALE", "MIN_FIT_SCALE", "START_SCALE", "ZOOM_STEP", "Camera"]

#: Levels that fit at this many px per world unit or more start fitted; larger ones start
#: zoomed in to :data:`START_SCALE`, following the player.
MIN_FIT_SCALE = 10.0
START_SCALE = 24.0
MAX_SCALE = 80.0
ZOOM_STEP = 1.25


@dataclass
class Camera:
    """Zoom (px per world unit, None = fit) and the world point at the view's centre."""

    zoom: float | None = None
    center: tuple[float, float] = (0.0, 0.0)

    def scale(self, fit: float) -> float:
        """The px per world unit now, given the scale that fits the level."""
        return fit if self.zoom is None else self.zoom

    def zoom_by(self, factor: float, fit: float) -> bool:
        """Multiply the zoom by ``factor`` (never below fitting, never above MAX_SCALE)."""
        new = min(MAX_SCALE, self.scale(fit) * factor)
        zoom = None if new <= fit * 1.0001 else new
        changed = zoom != self.zoom
        self.zoom = zoom
        return changed

    def follow(self, point: tuple[float, float]) -> None:
        """Centre the view on ``point`` (the renderer clamps it to the level)."""
        self.center = (float(point[0]), float(point[1]))
