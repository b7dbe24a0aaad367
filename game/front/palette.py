"""The front end's colours and its one diverging colour map for field overlays.

Field colours come from one diverging colour map on ``FieldLayer.norm`` in [-1, 1]:
warm (yellow, red) for negative values, which attract the guards (they move to the
least K), cold (blue) for positive values, which repel them, neutral grey for 0. Everything
drawn over a field (cones, zone and exit outlines, labels) uses colours outside that map
(white, green, violet, cyan) on a dark halo, so it stays readable over every overlay.

>>> colors_of(np.array([-1.0, 0.0, 1.0])).tolist()
[[255, 240, 120], [63, 64, 75], [175, 235, 255]]
"""

from __future__ import annotations

import numpy as np

Color = tuple[int, int, int]
RGBA = tuple[int, int, int, int]

BACKGROUND: Color = (16, 17, 22)
BLOCKED: Color = (30, 32, 40)
FLOOR: Color = (86, 90, 100)
ZONE_FILL: dict[str, Color] = {"dark": (44, 46, 70), "concealment": (58, 104, 62)}
ZONE_EDGE: dict[str, Color] = {"dark": (170, 150, 255), "concealment": (120, 240, 120)}
EXIT_EDGE: Color = (60, 255, 140)
COLLECTIBLE: Color = (255, 215, 0)
WALL: Color = (236, 236, 244)
MESH: Color = (130, 134, 150)
DECOY: Color = (200, 130, 255)
MARKER: Color = (255, 160, 230)
HALO: Color = (8, 8, 12)
#: cones: a light fill and a white outline on a dark halo (none of the colour map's hues)
CONE: RGBA = (255, 255, 255, 72)
CONE_EDGE: Color = (250, 250, 250)
CONE_SEEING: RGBA = (255, 40, 120, 90)
CONE_SEEING_EDGE: Color = (255, 70, 160)
GUARD: Color = (240, 140, 40)
GUARD_ALERT: Color = (235, 60, 50)
GUARD_DOWN: Color = (110, 110, 120)
PLAYER: Color = (80, 210, 255)
PLAYER_SPRINT: Color = (160, 240, 255)
ATTACK_RING: Color = (140, 70, 60)
NOISE: Color = (120, 255, 230)
RAIN: RGBA = (170, 200, 255, 120)
TEXT: Color = (230, 232, 240)
TEXT_DIM: Color = (150, 154, 168)
GOOD: Color = (110, 220, 120)
BAD: Color = (255, 90, 80)
WARN: Color = (255, 200, 80)
PLAN_COLORS: tuple[Color, ...] = (
    (255, 170, 60), (240, 90, 220), (80, 230, 200), (250, 250, 110), (150, 160, 255),
)
OVERLAY_ALPHA = 215

# Diverging colour map stops on [-1, 1] (attractive warm, repulsive cold).
_STOPS = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
_STOP_COLORS = np.array(
    [[255, 240, 120], [235, 80, 40], [64, 64, 74], [50, 110, 225], [175, 235, 255]], dtype=float
)
LUT_SIZE = 256


def colormap_lut(size: int = LUT_SIZE) -> np.ndarray:
    """The diverging colour map as ``(size, 3)`` uint8, index 0 = -1, last = +1."""
    x = np.linspace(-1.0, 1.0, size)
    return np.stack([np.interp(x, _STOPS, _STOP_COLORS[:, k]) for k in range(3)], axis=1).astype(
        np.uint8
    )


_LUT = colormap_lut()


def colors_of(norm: np.ndarray) -> np.ndarray:
    """Colours ``(n, 3)`` uint8 of normalised values in [-1, 1]."""
    idx = np.clip(np.rint((np.asarray(norm) + 1.0) * 0.5 * (LUT_SIZE - 1)), 0, LUT_SIZE - 1)
    return _LUT[idx.astype(np.intp)]
