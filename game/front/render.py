"""The pygame adapter: draws a :class:`~game.scene.Scene` into a window (or any Surface).

The static background (floor, zones, field overlay, lines, walls) comes from the cached
:class:`~game.front.layers.StaticLayers`; every frame blits it and draws only what moves:
cones, agents, plans, noise rings, HUD. A :class:`~game.front.camera.Camera` says what part
of the level the window shows: the whole level (small levels) or a zoomed view that
follows the player, with a :class:`~game.front.minimap.Minimap` in the corner.

Drawing order keeps everything readable over every overlay: cones (light fill, white
outline on a dark halo, colours outside the colour map), plans, bodies, plan targets, the
player, then every text label last on a dark box, so no marker hides one. What the caller
adds to a frame besides the scene is a :class:`DrawOptions`; where HUD, map and help lines
go in the window is the renderer's :class:`Layout`.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
# The window's own framebuffer (X11: MIT-SHM), not SDL's default of a texture drawn by
# OpenGL: without a GPU (Mesa llvmpipe, Xvfb, virtual machines) that path cost 8 ms of CPU
# and 15-30 ms of wall time per flip of a 1280x860 window; the framebuffer flip 0.4 ms.
os.environ.setdefault("SDL_FRAMEBUFFER_ACCELERATION", "0")

import numpy as np
import pygame

from game.scene import GuardDrawing, Scene, StaticScene

from .display import choose_video_driver
from .camera import MIN_FIT_SCALE, START_SCALE, Camera
from .cones import draw_cones
from .labels import place_labels
from .layers import StaticLayers
from .minimap import Minimap
from .marks import (
    awareness_fill, draw_awareness_mark, draw_phase_ring, draw_player_halo, mark_font,
)
from .palette import (
    ATTACK_RING, BACKGROUND, BAD, EXIT_EDGE, COLLECTIBLE,
    GOOD, GUARD, GUARD_ALERT, GUARD_DOWN, HALO, MARKER, PLAN_COLORS, PLAYER, PLAYER_SPRINT,
    TEXT, TEXT_DIM, WARN, Color, colormap_lut, colors_of,
)
from .screens import Panel, draw_panel


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
    #: width of the column kept free right of the map for a screen (ready, menu, ...)
    side: int = 0

    @property
    def world_rect(self) -> pygame.Rect:
        """Screen rectangle of the world extent."""
        return pygame.Rect(0, self.hud_height, self.size[0] - self.side,
                           self.size[1] - self.hud_height - self.help_height)

    @property
    def side_rect(self) -> pygame.Rect:
        """The column beside the map where a screen goes (empty without one)."""
        area = self.world_rect
        return pygame.Rect(area.right, area.top, self.side, area.height)


def init_pygame() -> None:
    """Initialise only what the front end uses (display, fonts): no audio device needed;
    headless without a display (:mod:`game.front.display`)."""
    choose_video_driver()
    pygame.display.init()
    pygame.font.init()


class Renderer:
    """Draws scenes of one :class:`StaticScene` onto a Surface of a given size.

    Usage (needs a pygame display)::

        renderer = Renderer(builder.static, (900, 700))
        renderer.draw(screen, builder.from_world(world, "K"), DrawOptions(show_plans=True))
    """

    HUD_HEIGHT = 50
    HELP_LINE = 18
    MARGIN = 8
    #: a screen (ready, pause menu, game over, questionnaire) goes in a column this wide
    #: right of the map in a window at least SIDE_FROM px wide, never over the map
    SIDE_COLUMN = 300
    SIDE_FROM = 960

    def __init__(self, static: StaticScene, size: tuple[int, int],
                 camera: Camera | None = None, compose_stripes: int = 1) -> None:
        self.static = static
        self.font = pygame.font.Font(None, 22)
        self.small = pygame.font.Font(None, 18)
        self.big = pygame.font.Font(None, 56)
        self._text_cache: dict[tuple[str, int, Color], pygame.Surface] = {}
        self._help_key: tuple[int, tuple[str, ...]] | None = None
        self._help_lines: list[str] = []
        self._legend_bar: tuple[tuple[int, float, float], pygame.Surface] | None = None
        self._help_count = 2
        self._side = 0
        #: where the HUD's texts went in the last frame (its row, legend, message)
        self.hud_boxes: list[pygame.Rect] = []
        #: the box the last screen (panel) was drawn in, if any
        self.panel_box: pygame.Rect | None = None
        self.layers = StaticLayers(static, compose_stripes)
        self.minimap = Minimap(static)
        self.camera = camera or Camera()
        self._size = (max(size[0], 200), max(size[1], 200))
        if self.camera.zoom is None and self.fit_scale() < MIN_FIT_SCALE:
            self.camera.zoom = START_SCALE  # a large level: start zoomed in, following
        self.layout = self._layout(self._size, self._help_count)

    # ------------------------------------------------------------------ geometry
    def _area(self, size: tuple[int, int], help_lines: int) -> tuple[int, int, int, int]:
        w, h = size
        hud, helph = self.HUD_HEIGHT, help_lines * self.HELP_LINE + 6
        return w, h, hud, helph

    def fit_scale(self, size: tuple[int, int] | None = None) -> float:
        """The px per world unit that shows the whole level in the window."""
        w, h, hud, helph = self._area(size or self._size, self._help_count)
        avail_w = w - self._side - 2 * self.MARGIN
        avail_h = h - hud - helph - 2 * self.MARGIN
        return max(1e-3, min(avail_w / self.static.width, avail_h / self.static.height))

    def _layout(self, size: tuple[int, int], help_lines: int) -> Layout:
        w, h, hud, helph = self._area(size, help_lines)
        fit = self.fit_scale(size)
        s = self.camera.scale(fit)
        avail_h = h - hud - helph - 2 * self.MARGIN
        mw = w - self._side  # the map's width
        if self.camera.zoom is None:
            ox = (mw - s * self.static.width) / 2
            oy = hud + self.MARGIN + (avail_h - s * self.static.height) / 2
        else:
            view_w, view_h = mw / s, (h - hud - helph) / s
            cx, cy = self.camera.center
            cx = _clamp(cx, view_w / 2, self.static.width - view_w / 2)
            cy = _clamp(cy, view_h / 2, self.static.height - view_h / 2)
            ox = mw / 2 - cx * s
            oy = hud + (h - hud - helph) / 2 - cy * s
        return Layout((w, h), hud, helph, s, (round(ox), round(oy)), self._side)

    def resize(self, size: tuple[int, int]) -> None:
        """Adopt a new window size (recomputes the transform; the cache follows)."""
        self._size = (max(size[0], 200), max(size[1], 200))
        self.layout = self._layout(self._size, self._help_count)
        self._help_key = None

    def refresh_view(self) -> None:
        """Recompute the transform after the camera moved or zoomed."""
        self.layout = self._layout(self._size, self._help_count)

    def visible(self) -> tuple[float, float, float, float]:
        """The world rectangle the map area shows now, clipped to the level."""
        rect = self.layout.world_rect
        x0, y0 = self.to_world(rect.left, rect.top)
        x1, y1 = self.to_world(rect.right, rect.bottom)
        return (max(0.0, x0), max(0.0, y0), min(self.static.width, x1), min(self.static.height, y1))

    @property
    def zoomed(self) -> bool:
        """Whether the window shows only part of the level (then the minimap is drawn)."""
        x0, y0, x1, y1 = self.visible()
        return x0 > 1e-6 or y0 > 1e-6 or x1 < self.static.width - 1e-6 or y1 < self.static.height - 1e-6

    def to_screen(self, x: float, y: float) -> tuple[float, float]:
        """World point → window pixel."""
        s, (ox, oy) = self.layout.scale, self.layout.origin
        return (ox + x * s, oy + y * s)

    def to_world(self, px: float, py: float) -> tuple[float, float]:
        """Window pixel → world point."""
        s, (ox, oy) = self.layout.scale, self.layout.origin
        return ((px - ox) / s, (py - oy) / s)

    def _pts(self, points: np.ndarray) -> list[list[float]]:
        s, (ox, oy) = self.layout.scale, self.layout.origin
        pts = np.asarray(points, dtype=float).reshape(-1, 2) * s + (ox, oy)
        return pts.tolist()

    # ------------------------------------------------------------------ the frame
    def draw(self, surface: pygame.Surface, scene: Scene, options: DrawOptions | None = None) -> None:
        """Draw one frame of ``scene`` onto ``surface`` (the window's size)."""
        options = options or DrawOptions()
        if surface.get_size() != self.layout.size:
            self.resize(surface.get_size())
        side = (self.SIDE_COLUMN if options.panel is not None
                and surface.get_width() >= self.SIDE_FROM else 0)
        if side != self._side:  # a screen came or went: the map makes room beside it
            self._side = side
            self.layout = self._layout(self._size, self._help_count)
        self._wrap_help(options.help)
        area = self.layout.world_rect
        static, region = self.layers.surface(self.visible(), self.layout.scale, scene.layer,
                                             options.show_mesh)
        sx, sy = self.to_screen(region.x0, region.y0)
        placed = static.get_rect(topleft=(round(sx), round(sy)))
        if placed.contains(area):  # the map is covered: clear only the HUD and help bands
            surface.fill(BACKGROUND, (0, 0, surface.get_width(), area.top))
            surface.fill(BACKGROUND, (0, area.bottom, surface.get_width(),
                                      surface.get_height() - area.bottom))
        else:
            surface.fill(BACKGROUND)
        surface.set_clip(area)
        surface.blit(static, placed)
        s = self.layout.scale
        for x, y in scene.markers:
            self._diamond(surface, self.to_screen(x, y), max(6, s * 0.35), MARKER, 0)
        for x, y in options.collectibles:
            self._collectible(surface, self.to_screen(x, y), max(6.0, s * 0.35))
        draw_cones(surface, scene.guards, self.layout.scale, self.layout.origin, self.layout.world_rect)
        for ring in self.static.exits:
            x, y = self.to_screen(float(ring[:, 0].min()), float(ring[:, 1].min()))
            label = self._text("EXIT", self.small, EXIT_EDGE)
            surface.blit(label, (round(x) + 4, round(y) + 3))
        if options.effects is not None:
            options.effects(surface, self)
        if options.show_plans:
            for i, guard in enumerate(scene.guards):
                self._draw_plan(surface, guard, PLAN_COLORS[i % len(PLAN_COLORS)])
        for guard in scene.guards:
            self._draw_guard(surface, guard, scene)
        if options.show_plans:
            for i, guard in enumerate(scene.guards):
                self._draw_target(surface, guard, PLAN_COLORS[i % len(PLAN_COLORS)])
        self._draw_labels(surface, scene)
        self._draw_player(surface, scene)  # last: never lost under guards, cones or labels
        if self.zoomed:
            self.minimap.draw(surface, area.bottomright, scene, self.visible())
        surface.set_clip(None)
        self._draw_hud(surface, scene, options)
        self._draw_help(surface)
        player = self.to_screen(*scene.player.pos)
        self.panel_box = None
        if options.panel is not None and self._side:
            column = self.layout.side_rect
            surface.fill(BACKGROUND, column)
            self.panel_box = draw_panel(surface, column, options.panel, column=True)
        elif options.panel is not None:
            self.panel_box = draw_panel(surface, area, options.panel, avoid=player)
        elif options.banner:
            draw_panel(surface, area, Panel(options.banner, (options.banner_sub,)), avoid=player)
        if options.paused:  # over any screen: a paused ready screen must not look frozen
            where = "corner" if options.panel is None else "bottom-left"
            if self._side:  # below the screen, in its column
                draw_panel(surface, self.layout.side_rect, Panel(
                    "PAUSED", ("Space to continue",), BAD, where="bottom-left"), column=True)
            else:
                draw_panel(surface, area, Panel("PAUSED", ("Space to continue",), BAD, where=where))

    def _draw_plan(self, surface: pygame.Surface, guard: GuardDrawing, color: Color) -> None:
        if not guard.active:
            return
        s = self.layout.scale
        width = max(2, round(s * 0.1))
        if len(guard.path):
            pts = [list(self.to_screen(*guard.pos))] + self._pts(guard.path)
            pygame.draw.lines(surface, HALO, False, pts, width + 2)
            pygame.draw.lines(surface, color, False, pts, width)
        r = max(6.0, s * 0.28)
        for x, y in guard.candidates:
            c = self.to_screen(x, y)
            pygame.draw.circle(surface, HALO, c, r + 1, 4)
            pygame.draw.circle(surface, color, c, r, 2)
        if guard.chosen is not None:
            c = self.to_screen(*guard.chosen)
            pygame.draw.circle(surface, HALO, c, r + 1)
            pygame.draw.circle(surface, color, c, r)

    def _draw_target(self, surface: pygame.Surface, guard: GuardDrawing, color: Color) -> None:
        """A square frame around the target node, larger than a body so it shows around one."""
        if guard.active and guard.target is not None:
            cx, cy = self.to_screen(*guard.target)
            half = max(9, self.layout.scale * 0.55)
            box = pygame.Rect(cx - half, cy - half, 2 * half, 2 * half)
            pygame.draw.rect(surface, HALO, box.inflate(4, 4), 5)
            pygame.draw.rect(surface, color, box, 3)

    def _draw_guard(self, surface: pygame.Surface, guard: GuardDrawing, scene: Scene) -> None:
        s = self.layout.scale
        center = self.to_screen(*guard.pos)
        radius = max(5.0, scene.agent_radius * s)
        if not guard.active:
            d = radius * 0.8
            cx, cy = center
            pygame.draw.line(surface, GUARD_DOWN, (cx - d, cy - d), (cx + d, cy + d), 3)
            pygame.draw.line(surface, GUARD_DOWN, (cx - d, cy + d), (cx + d, cy - d), 3)
            return
        if scene.attack_range > 0:
            pygame.draw.circle(surface, ATTACK_RING, center, scene.attack_range * s, 1)
        alert = guard.sees_player or guard.state in ("alert", "chase", "investigate")
        pygame.draw.circle(surface, GUARD_ALERT if alert else GUARD, center, radius)
        pygame.draw.circle(surface, (20, 20, 20), center, radius, 1)
        hx, hy = np.cos(guard.heading), np.sin(guard.heading)
        tip = (center[0] + hx * radius * 1.7, center[1] + hy * radius * 1.7)
        pygame.draw.line(surface, (20, 20, 20), center, tip, 2)
        draw_phase_ring(surface, center, radius, scene.phase)
        fill = awareness_fill(guard.sees_player, guard.awareness, guard.state)
        if fill is not None:
            draw_awareness_mark(surface, mark_font(), self._text, center, radius, fill)

    def _draw_labels(self, surface: pygame.Surface, scene: Scene) -> None:
        """The behaviour labels on dark boxes, drawn after every marker and placed by
        :func:`~game.front.labels.place_labels` so that no two overlap and none covers a
        guard or the player."""
        radius = max(5.0, scene.agent_radius * self.layout.scale)
        shown = [g for g in scene.guards if g.state]
        if not shown:
            return
        texts = [self._text(f"{g.state} · {g.role}" if g.role else g.state, self.small, TEXT)
                 for g in shown]
        # the awareness mark sits above a guard: a label keeps clear of it too
        anchors = [(*self.to_screen(*g.pos), radius + 30) for g in shown]
        px, py = self.to_screen(*scene.player.pos)
        pr = radius + 4  # the red "seen" ring
        spots = place_labels(anchors, [(t.get_width() + 6, t.get_height() + 2) for t in texts],
                             avoid=[(px - pr, py - pr, 2 * pr, 2 * pr)])
        for label, (x, y) in zip(texts, spots):
            box = pygame.Rect(round(x), round(y), label.get_width() + 6, label.get_height() + 2)
            pygame.draw.rect(surface, HALO, box)
            surface.blit(label, (box.x + 3, box.y + 1))

    def _draw_player(self, surface: pygame.Surface, scene: Scene) -> None:
        s = self.layout.scale
        p = scene.player
        center = self.to_screen(*p.pos)
        radius = max(5.0, scene.agent_radius * s)
        color = PLAYER_SPRINT if p.sprinting else PLAYER
        draw_player_halo(surface, center, radius)
        # a double outline (dark, then light) stands out on floor, cones, guards and markers
        pygame.draw.circle(surface, (0, 0, 0), center, radius + 5, 2)
        pygame.draw.circle(surface, (255, 255, 255), center, radius + 3, 2)
        if p.concealed:
            pygame.draw.circle(surface, color, center, radius, 2)
        else:
            pygame.draw.circle(surface, color, center, radius)
            pygame.draw.circle(surface, (10, 30, 40), center, radius, 1)
        if scene.detected:
            pygame.draw.circle(surface, BAD, center, radius + 4, 2)
        hx, hy = np.cos(p.heading), np.sin(p.heading)
        tip = (center[0] + hx * radius * 1.6, center[1] + hy * radius * 1.6)
        pygame.draw.line(surface, color, center, tip, 2)

    @staticmethod
    def _diamond(surface: pygame.Surface, c: tuple[float, float], r: float, color: Color, width: int) -> None:
        x, y = c
        pygame.draw.polygon(surface, color, [(x, y - r), (x + r, y), (x, y + r), (x - r, y)], width)

    @staticmethod
    def _collectible(surface: pygame.Surface, c: tuple[float, float], r: float) -> None:
        x, y = c
        star = [(x + r * np.cos(a) * (1 if k % 2 == 0 else 0.45), y + r * np.sin(a) * (1 if k % 2 == 0 else 0.45))
                for k, a in enumerate(np.linspace(-np.pi / 2, 1.5 * np.pi, 10, endpoint=False))]
        pygame.draw.polygon(surface, HALO, star, 4)
        pygame.draw.polygon(surface, COLLECTIBLE, star)

    # ------------------------------------------------------------------ text
    def _text(self, text: str, font: pygame.font.Font, color: Color) -> pygame.Surface:
        key = (text, id(font), color)
        cached = self._text_cache.get(key)
        if cached is None:
            if len(self._text_cache) > 512:
                self._text_cache.clear()
            cached = font.render(text, True, color)
            self._text_cache[key] = cached
        return cached

    def _row(self, surface: pygame.Surface, x: int, y: int, items: Sequence[tuple[str, Color]]) -> int:
        for text, color in items:
            if not text:
                continue
            label = self._text(text, self.font, color)
            surface.blit(label, (x, y))
            x += label.get_width() + 18
        return x

    def _draw_hud(self, surface: pygame.Surface, scene: Scene, options: DrawOptions) -> None:
        w = self.layout.size[0]
        x, y = 10, 6
        p = scene.player
        bar = pygame.Rect(x, y + 1, 90, 13)
        pygame.draw.rect(surface, (60, 20, 20), bar)
        frac = 0.0 if p.hp_max <= 0 else max(0.0, min(1.0, p.hp / p.hp_max))
        pygame.draw.rect(surface, GOOD if frac > 0.34 else BAD, (bar.x, bar.y, round(bar.w * frac), bar.h))
        pygame.draw.rect(surface, TEXT_DIM, bar, 1)
        if scene.attackers:
            state, color = f"UNDER ATTACK ({scene.attackers})", BAD
        elif scene.detected:
            state, color = f"SEEN by {len(scene.seen_by)}", BAD
        elif any(g.state in ("alert", "chase", "investigate") for g in scene.guards):
            state, color = "HIDDEN (guards alert)", WARN
        else:
            state, color = "HIDDEN", GOOD
        items: list[tuple[str, Color]] = [
            (f"HP {max(p.hp, 0.0):.1f}/{p.hp_max:g}", TEXT),
            (state, color),
            (f"t {scene.t:5.1f} / {scene.duration:g} s", TEXT),
            (f"{scene.mode} · {scene.abstraction}" if scene.mode == "replay"
             else f"guards {scene.mode} · {scene.abstraction}", TEXT),
        ]
        if scene.phase:
            items.append((f"team {scene.phase}", BAD if scene.phase == "alert" else
                          WARN if scene.phase in ("suspicious", "search") else TEXT))
        if scene.captures and scene.status == "playing":
            items.append((f"captures {scene.captures}", WARN))
        if scene.rain is not None:
            items.append((f"rain {'on' if scene.rain else 'off'}", TEXT))
        if p.concealed:
            items.append(("concealed", GOOD))
        if p.sprinting:
            items.append(("sprinting", WARN))
        items += [(text, TEXT_DIM) for text in options.info]
        end = self._row(surface, bar.right + 10, y, items)
        self.hud_boxes = [pygame.Rect(10, y, end - 18 - 10, 20)]
        legend_end = 10
        if options.legend:
            legend_end = self._draw_legend(surface, scene, 10, y + 22)
            self.hud_boxes.append(pygame.Rect(10, y + 22, legend_end - 10, 20))
        if options.message:
            # right of the first row; on the second when the row reaches it (a narrow window)
            label = self._text(options.message, self.font, options.message_color)
            mx = w - label.get_width() - 10
            my = y if mx >= end else y + 22
            if my != y and mx < legend_end + 8:  # both rows full: shorten it
                mx = legend_end + 8
                label = label.subsurface((0, 0, max(1, w - 10 - mx), label.get_height()))
            surface.blit(label, (mx, my))
            self.hud_boxes.append(pygame.Rect(mx, my, label.get_width(), label.get_height()))

    def _draw_legend(self, surface: pygame.Surface, scene: Scene, x: int, y: int) -> int:
        """The overlay's legend from ``x``; returns where it ends."""
        layer = scene.layer
        if scene.overlay == "none":
            return self._row(surface, x, y, [("overlay: none", TEXT_DIM)]) - 18
        if layer is None:
            return self._row(surface, x, y, [(f"overlay {scene.overlay}: {scene.field_note}", WARN)]) - 18
        x = self._row(surface, x, y, [(layer.label, TEXT)]) - 8
        lo = self._text(f"{layer.vmin:.3g}", self.font, TEXT)
        surface.blit(lo, (x, y))
        x += lo.get_width() + 6
        width = 180
        surface.blit(self._bar(width, layer.vmin, layer.vmax), (x, y + 1))
        pygame.draw.rect(surface, TEXT_DIM, (x - 1, y, width + 2, 15), 1)
        if layer.vmin < 0 < layer.vmax:  # where 0 lies on the bar
            zx = x + round(width * (0 - layer.vmin) / (layer.vmax - layer.vmin))
            pygame.draw.line(surface, TEXT, (zx, y - 2), (zx, y + 16), 1)
        x += width + 6
        hi = self._text(f"{layer.vmax:.3g}", self.font, TEXT)
        surface.blit(hi, (x, y))
        x += hi.get_width() + 18
        return self._row(surface, x, y, [("warm attracts guards · cold repels", TEXT_DIM)]) - 18

    def _bar(self, width: int, vmin: float, vmax: float) -> pygame.Surface:
        """A colour bar from vmin to vmax (on the symmetric scale of the map), cached."""
        key = (width, vmin, vmax)
        if self._legend_bar is not None and self._legend_bar[0] == key:
            return self._legend_bar[1]
        scale = max(abs(vmin), abs(vmax))
        values = np.linspace(vmin, vmax, width)
        norm = values / scale if scale > 1e-12 else np.zeros(width)
        rgb = colors_of(norm)
        image = np.repeat(rgb[:, None, :], 13, axis=1)  # (width, height, 3) for surfarray
        bar = pygame.surfarray.make_surface(image).convert()
        self._legend_bar = (key, bar)
        return bar

    def _wrap_help(self, items: Sequence[str]) -> None:
        key = (self.layout.size[0], tuple(items))
        if key == self._help_key:
            return
        lines: list[str] = []
        current = ""
        limit = self.layout.size[0] - 20
        for item in items:
            candidate = f"{current}  ·  {item}" if current else item
            if current and self.small.size(candidate)[0] > limit:
                lines.append(current)
                current = item
            else:
                current = candidate
        if current:
            lines.append(current)
        self._help_key = key
        self._help_lines = lines
        if len(lines) != self._help_count:
            self._help_count = len(lines)
            self.layout = self._layout(self.layout.size, self._help_count)

    def _draw_help(self, surface: pygame.Surface) -> None:
        y = self.layout.size[1] - self.layout.help_height + 3
        for line in self._help_lines:
            surface.blit(self._text(line, self.small, TEXT_DIM), (10, y))
            y += self.HELP_LINE


def _clamp(value: float, lo: float, hi: float) -> float:
    """``value`` within [lo, hi] (the middle when the range is empty)."""
    return (lo + hi) / 2 if lo > hi else min(max(value, lo), hi)


#: The largest window :func:`default_window_size` opens (a larger level gets the camera).
MAX_WINDOW = (1280, 860)


def default_window_size(static: StaticScene) -> tuple[int, int]:
    """A window that shows the level at a comfortable scale (at least 960 px wide, at most
    :data:`MAX_WINDOW`: a level that does not fit is shown through the camera)."""
    s = max(14.0, min(40.0, min(1100 / static.width, 640 / static.height)))
    chrome = Renderer.HUD_HEIGHT + 2 * Renderer.MARGIN + 3 * Renderer.HELP_LINE + 6
    return (min(MAX_WINDOW[0], max(960, round(static.width * s) + 2 * Renderer.MARGIN)),
            min(MAX_WINDOW[1], round(static.height * s) + chrome))


def save_screenshot(surface: pygame.Surface, path: str) -> None:
    """Save ``surface`` as PNG (folders created); raises OSError with the reason."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    try:
        pygame.image.save(surface, path)
    except pygame.error as error:
        raise OSError(str(error)) from None


__all__ = [
    "DrawOptions", "Layout", "Renderer", "colormap_lut", "colors_of", "default_window_size",
    "init_pygame", "save_screenshot",
]
