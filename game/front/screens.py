"""The game's screens as panels over the map: ready, paused, won / lost, level chooser,
questionnaire.

A :class:`Panel` is a title, a few lines and an optional highlighted choice. It is drawn
along the top edge of the map area (or the right-hand corner, for the small paused panel),
never over the map's centre, where the player and the guards usually are.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import pygame

from .palette import Color, TEXT, TEXT_DIM, WARN

__all__ = ["Panel", "draw_panel"]


@dataclass(frozen=True)
class Panel:
    """A screen's text: ``title`` big, then ``lines``; ``choice`` highlights one line."""

    title: str
    lines: Sequence[str] = ()
    title_color: Color = TEXT
    choice: int | None = None
    #: ``"top"`` (a wide panel under the HUD) or ``"corner"`` (small, top right)
    where: str = "top"
    hint: str = ""
    extra: tuple[str, ...] = field(default_factory=tuple)


_FONTS: dict[int, pygame.font.Font] = {}
#: Rendered lines by (font size, text, colour): a panel shown for many frames renders once.
_TEXTS: dict[tuple[int, str, Color], pygame.Surface] = {}


def _font(size: int) -> pygame.font.Font:
    font = _FONTS.get(size)
    if font is None:
        font = _FONTS[size] = pygame.font.Font(None, size)
    return font


def _render(size: int, text: str, color: Color) -> pygame.Surface:
    key = (size, text, color)
    label = _TEXTS.get(key)
    if label is None:
        if len(_TEXTS) > 256:
            _TEXTS.clear()
        label = _TEXTS[key] = _font(size).render(text, True, color)
    return label


def wrap(text: str, size: int, width: int) -> list[str]:
    """``text`` in lines of at most ``width`` px in the panel font of ``size`` (word wrap;
    a single word wider than that stays whole)."""
    font = _font(size)
    lines: list[str] = []
    current = ""
    for word in text.split(" "):
        candidate = f"{current} {word}" if current else word
        if current and font.size(candidate)[0] > width:
            lines.append(current)
            current = "   " + word  # a continued line is indented
        else:
            current = candidate
    return lines + [current]


def draw_panel(surface: pygame.Surface, area: pygame.Rect, panel: Panel,
               avoid: tuple[float, float] | None = None, column: bool = False) -> pygame.Rect:
    """Draw ``panel`` inside the map ``area``; returns the box drawn.

    A wide panel goes along the top edge, or along the bottom edge when the ``avoid``
    point (the player on screen) is in the upper half, so it never hides the player.
    ``column``: ``area`` is the column beside the map; the panel fills its width from the
    top (``where="bottom-left"``: at its bottom), its lines wrapped to fit."""
    big = 46 if panel.where == "top" else 32
    inner = area.width - 20 - 36
    if column and _font(big).size(panel.title)[0] > inner:
        big = 32
    title = _render(big, panel.title, panel.title_color)
    rows = []
    for i, line in enumerate(panel.lines):
        chosen = panel.choice == i
        text = ("> " if chosen else "  ") + line if panel.choice is not None else line
        for part in wrap(text, 22, inner) if column else [text]:
            rows.append(_render(22, part, WARN if chosen else TEXT))
    if panel.hint:
        for part in wrap(panel.hint, 22, inner) if column else [panel.hint]:
            rows.append(_render(22, part, TEXT_DIM))
    width = max([title.get_width()] + [r.get_width() for r in rows]) + 36
    height = title.get_height() + sum(r.get_height() + 3 for r in rows) + 26
    if column:
        width = area.width - 20
        x = area.left + 10
        y = area.bottom - height - 10 if panel.where == "bottom-left" else area.top + 10
    elif panel.where == "corner":
        x, y = area.right - width - 10, area.top + 10
    elif panel.where == "bottom-left":
        x, y = area.left + 10, area.bottom - height - 10
    else:
        x, y = area.centerx - width // 2, area.top + 10
        if avoid is not None and avoid[1] < area.centery:
            y = area.bottom - height - 10
    box = pygame.Rect(x, y, width, height)
    shade = pygame.Surface(box.size, pygame.SRCALPHA)
    shade.fill((0, 0, 0, 200))
    surface.blit(shade, box.topleft)
    pygame.draw.rect(surface, panel.title_color, box, 2)
    surface.blit(title, (x + 18, y + 10))
    cy = y + 14 + title.get_height()
    for row in rows:
        surface.blit(row, (x + 18, cy))
        cy += row.get_height() + 3
    return box
