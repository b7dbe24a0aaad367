"""What a guard knows and what phase the team is in, drawn on the guard; and a halo that
makes the player stand out on every floor and overlay.

* :func:`draw_awareness_mark` — a "?" over a guard whose box fills with its graded
  awareness (``[awareness]`` on) or that investigates, turning into a red "!" while it sees
  the player (awareness at the threshold).
* :func:`draw_phase_ring` — a ring round every guard in the team's alert phase colour
  (``[alert]`` on): suspicious amber, alert red, search orange, caution pale.
* :func:`draw_player_halo` — a white ring on a dark one under the player's disc.
"""

from __future__ import annotations

from collections.abc import Callable

import pygame

from .palette import BAD, HALO, WARN, Color

__all__ = ["PHASE_COLORS", "awareness_fill", "draw_awareness_mark", "draw_phase_ring",
           "draw_player_halo", "mark_font"]

PHASE_COLORS: dict[str, Color] = {
    "suspicious": WARN, "alert": BAD, "search": (255, 140, 40), "caution": (250, 235, 190),
}
_QUESTIONING = ("investigate", "search", "return")


def awareness_fill(sees_player: bool, awareness: float | None, state: str) -> float | None:
    """How full a guard's mark is (1 = "!"), or None when it shows no mark.

    >>> awareness_fill(True, None, "chase"), awareness_fill(False, 0.4, "patrol")
    (1.0, 0.4)
    >>> awareness_fill(False, None, "investigate"), awareness_fill(False, 0.0, "patrol")
    (0.5, None)
    """
    if sees_player:
        return 1.0
    if awareness is not None and awareness > 0.0:
        return min(1.0, awareness)
    if state in _QUESTIONING:
        return 0.5
    return None


_FONTS: dict[int, pygame.font.Font] = {}


def mark_font() -> pygame.font.Font:
    """The mark's glyph font (made once, after pygame's font module is up)."""
    if 26 not in _FONTS:
        _FONTS[26] = pygame.font.Font(None, 26)
    return _FONTS[26]


def draw_awareness_mark(surface: pygame.Surface, font: pygame.font.Font,
                        text: Callable[[str, pygame.font.Font, Color], pygame.Surface],
                        center: tuple[float, float], radius: float, fill: float) -> None:
    """The mark above a guard at ``center``: a box filled to ``fill`` from the bottom, with
    "?" (filling) or "!" (full) on it."""
    w, h = 18, 24
    box = pygame.Rect(round(center[0] - w / 2), round(center[1] - radius - h - 6), w, h)
    pygame.draw.rect(surface, HALO, box.inflate(4, 4), border_radius=4)
    level = round(h * fill)
    color = BAD if fill >= 1.0 else WARN
    if level:
        pygame.draw.rect(surface, color, (box.x, box.bottom - level, w, level), border_radius=3)
    glyph = text("!" if fill >= 1.0 else "?", font, (250, 250, 250))
    surface.blit(glyph, (box.centerx - glyph.get_width() // 2, box.centery - glyph.get_height() // 2))


def draw_phase_ring(surface: pygame.Surface, center: tuple[float, float], radius: float,
                    phase: str) -> None:
    """A ring in the phase's colour round a guard (nothing while unaware)."""
    color = PHASE_COLORS.get(phase)
    if color is not None:
        pygame.draw.circle(surface, HALO, center, radius + 5, 4)
        pygame.draw.circle(surface, color, center, radius + 4, 2)


def draw_player_halo(surface: pygame.Surface, center: tuple[float, float], radius: float) -> None:
    """A white ring on a dark ring round the player: visible on light and dark floors."""
    pygame.draw.circle(surface, HALO, center, radius + 6, 3)
    pygame.draw.circle(surface, (255, 255, 255), center, radius + 4, 2)
