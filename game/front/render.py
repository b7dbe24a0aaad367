"""The pygame adapter: draws a :class:`~game.scene.Scene` into a window (or any Surface).

The static background (floor, zones, walls, optional grid or navmesh lines and the
colour-mapped field overlay) is composed once into a cached Surface and rebuilt only when
the window is resized, the overlay's field changes (once per AI tick) or a display option
is toggled; every frame then blits it and draws only what moves: cones, agents, plans, HUD.

Field colours come from one diverging colour map on ``FieldLayer.norm`` in [-1, 1]:
warm (yellow, red) for negative values, which attract the guards (they move to the
least K), cold (blue) for positive values, which repel them, neutral grey for 0.
"""

from __future__ import annotations

import time

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import numpy as np
import pygame

from game.scene import GuardDrawing, Scene, StaticScene

Color = tuple[int, int, int]

# ---------------------------------------------------------------------------- palette
BACKGROUND: Color = (16, 17, 22)
BLOCKED: Color = (30, 32, 40)
FLOOR: Color = (86, 90, 100)
ZONE_FILL: dict[str, Color] = {"dark": (44, 46, 70), "concealment": (58, 104, 62)}
ZONE_EDGE: dict[str, Color] = {"dark": (120, 120, 200), "concealment": (120, 210, 120)}
WALL: Color = (236, 236, 244)
MESH: Color = (130, 134, 150)
DECOY: Color = (200, 130, 255)
MARKER: Color = (255, 160, 230)
CONE = (255, 232, 130, 78)
CONE_EDGE: Color = (255, 232, 130)
CONE_SEEING = (255, 60, 50, 110)
CONE_SEEING_EDGE: Color = (255, 90, 80)
GUARD: Color = (240, 140, 40)
GUARD_ALERT: Color = (235, 60, 50)
GUARD_DOWN: Color = (110, 110, 120)
PLAYER: Color = (80, 210, 255)
PLAYER_SPRINT: Color = (160, 240, 255)
ATTACK_RING: Color = (140, 70, 60)
TEXT: Color = (230, 232, 240)
TEXT_DIM: Color = (150, 154, 168)
GOOD: Color = (110, 220, 120)
BAD: Color = (255, 90, 80)
WARN: Color = (255, 200, 80)
PLAN_COLORS: tuple[Color, ...] = (
    (255, 170, 60), (240, 90, 220), (80, 230, 200), (250, 250, 110), (150, 160, 255),
)
OVERLAY_ALPHA = 215
_KEY: Color = (255, 0, 255)  # colour key of the cached line layers (never drawn)

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


def init_pygame() -> None:
    """Initialise only what the front end uses (display, fonts): no audio device needed."""
    pygame.display.init()
    pygame.font.init()


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
    #: a large centred banner (game over, end of trace)
    banner: str | None = None
    banner_sub: str = ""
    #: extra HUD items on the first row
    info: Sequence[str] = field(default_factory=tuple)
    #: the second HUD row shows the overlay legend (play) or nothing (replay)
    legend: bool = True


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


class Renderer:
    """Draws scenes of one :class:`StaticScene` onto a Surface of a given size.

    Usage (needs a pygame display)::

        renderer = Renderer(builder.static, (900, 700))
        renderer.draw(screen, builder.from_world(world, "K"), DrawOptions(show_plans=True))
    """

    HUD_HEIGHT = 50
    HELP_LINE = 18
    MARGIN = 8

    def __init__(self, static: StaticScene, size: tuple[int, int]) -> None:
        self.static = static
        self.font = pygame.font.Font(None, 22)
        self.small = pygame.font.Font(None, 18)
        self.big = pygame.font.Font(None, 56)
        self._text_cache: dict[tuple[str, int, Color], pygame.Surface] = {}
        self._help_key: tuple[int, tuple[str, ...]] | None = None
        self._help_lines: list[str] = []
        self._base: pygame.Surface | None = None
        self._composite: pygame.Surface | None = None
        self._composite_key: tuple[object, bool] | None = None
        self._composite_layer: object = None
        self._legend_bar: tuple[tuple[int, float, float], pygame.Surface] | None = None
        self._help_count = 2
        self.layout = self._layout(size, self._help_count)
        self._prepare()

    # ------------------------------------------------------------------ geometry
    def _layout(self, size: tuple[int, int], help_lines: int) -> Layout:
        w, h = max(size[0], 200), max(size[1], 200)
        hud, helph = self.HUD_HEIGHT, help_lines * self.HELP_LINE + 6
        avail_w = w - 2 * self.MARGIN
        avail_h = h - hud - helph - 2 * self.MARGIN
        s = max(1e-3, min(avail_w / self.static.width, avail_h / self.static.height))
        ox = (w - s * self.static.width) / 2
        oy = hud + self.MARGIN + (avail_h - s * self.static.height) / 2
        return Layout((w, h), hud, helph, s, (ox, oy))

    def resize(self, size: tuple[int, int]) -> None:
        """Adopt a new window size (recomputes the transform and the cached layers)."""
        self.layout = self._layout(size, self._help_count)
        self._help_key = None
        self._prepare()

    def _prepare(self) -> None:
        s, (ox, oy) = self.layout.scale, self.layout.origin
        self._base = None
        self._composite_key = None
        self._mesh_layer: pygame.Surface | None = None
        self._top_layer: pygame.Surface | None = None
        self._field_layer: pygame.Surface | None = None
        self._tri_polys: list[list[tuple[float, float]]] = []
        if self.static.triangles is not None:
            pts = self.static.triangles * s + (ox, oy)
            self._tri_polys = [[(float(x), float(y)) for x, y in tri] for tri in pts]
        walls = self.static.walls * s + (ox, oy)
        self._wall_lines = [((float(a[0]), float(a[1])), (float(b[0]), float(b[1]))) for a, b in walls]

    def to_screen(self, x: float, y: float) -> tuple[float, float]:
        """World point → window pixel."""
        s, (ox, oy) = self.layout.scale, self.layout.origin
        return (ox + x * s, oy + y * s)

    def to_world(self, px: float, py: float) -> tuple[float, float]:
        """Window pixel → world point."""
        s, (ox, oy) = self.layout.scale, self.layout.origin
        return ((px - ox) / s, (py - oy) / s)

    def _pts(self, points: np.ndarray) -> list[tuple[float, float]]:
        s, (ox, oy) = self.layout.scale, self.layout.origin
        return [(ox + x * s, oy + y * s) for x, y in np.asarray(points, dtype=float).reshape(-1, 2)]

    # ------------------------------------------------------------------ cached layers
    def _base_surface(self) -> pygame.Surface:
        """Floor and zones: depends on the window size only."""
        if self._base is not None:
            return self._base
        surface = pygame.Surface(self.layout.size).convert()
        surface.fill(BACKGROUND)
        world = pygame.Rect(
            round(self.layout.origin[0]), round(self.layout.origin[1]),
            round(self.static.width * self.layout.scale), round(self.static.height * self.layout.scale),
        )
        surface.fill(BLOCKED, world)
        outline, *holes = self.static.floor
        pygame.draw.polygon(surface, FLOOR, self._pts(outline))
        for hole in holes:
            pygame.draw.polygon(surface, BLOCKED, self._pts(hole))
        for kind, polygons in self.static.zones.items():
            for exterior, *_ in polygons:
                pygame.draw.polygon(surface, ZONE_FILL.get(kind, FLOOR), self._pts(exterior))
        for hole in holes:  # a zone clipped to the floor has the obstacles as its holes
            pygame.draw.polygon(surface, BLOCKED, self._pts(hole))
        self._base = surface
        return surface

    def _lines_layer(self, draw: Callable[[pygame.Surface], None]) -> pygame.Surface:
        """A window-sized colour-keyed layer (fast sparse blits) holding what ``draw`` draws."""
        surface = pygame.Surface(self.layout.size).convert()
        surface.fill(_KEY)
        draw(surface)
        surface.set_colorkey(_KEY, pygame.RLEACCEL)
        return surface

    def _draw_top(self, surface: pygame.Surface) -> None:
        """Zone outlines, walls and static decoys: drawn over the field overlay."""
        for kind, polygons in self.static.zones.items():
            for exterior, *_ in polygons:
                pygame.draw.lines(surface, ZONE_EDGE.get(kind, TEXT_DIM), True, self._pts(exterior), 1)
        wall_width = max(2, round(self.layout.scale * 0.12))
        for a, b in self._wall_lines:
            pygame.draw.line(surface, WALL, a, b, wall_width)
        width = max(1, round(self.layout.scale * 0.08))
        for x, y in self.static.decoys:
            self._diamond(surface, self.to_screen(x, y), max(4, self.layout.scale * 0.3), DECOY, width)

    def _composite_surface(self, scene: Scene, options: DrawOptions) -> pygame.Surface:
        """Base + field overlay + grid/mesh lines + zone outlines + walls + static decoys.

        Rebuilt only when the field layer (once per AI tick), the mesh option or the window
        size changes; the line layers themselves are drawn once per window size.
        """
        layer = scene.layer
        key = (id(layer) if layer is not None else None, options.show_mesh)
        if self._composite is not None and key == self._composite_key and self._composite_layer is layer:
            return self._composite
        base = self._base_surface()
        surface = self._composite
        if surface is None or surface.get_size() != base.get_size():
            surface = pygame.Surface(base.get_size()).convert()
        surface.blit(base, (0, 0))
        if layer is not None:
            self._draw_field(surface, layer.norm)
        if options.show_mesh:
            if self._mesh_layer is None:
                self._mesh_layer = self._lines_layer(self._draw_mesh)
            surface.blit(self._mesh_layer, (0, 0))
        if self._top_layer is None:
            self._top_layer = self._lines_layer(self._draw_top)
        surface.blit(self._top_layer, (0, 0))
        self._composite, self._composite_key, self._composite_layer = surface, key, layer
        return surface

    def _draw_field(self, surface: pygame.Surface, norm: np.ndarray) -> None:
        """Colour every node's cell (grid) or triangle (partition) by its normalised value."""
        rgb = colors_of(norm)
        s, (ox, oy) = self.layout.scale, self.layout.origin
        if self.static.cell_node is not None:
            # One pixel per cell, then scaled up: the whole overlay is two blits.
            cell_node = self.static.cell_node
            rows, cols = cell_node.shape
            image = np.zeros((rows, cols, 4), dtype=np.uint8)
            inside = cell_node >= 0
            image[inside, :3] = rgb[cell_node[inside]]
            image[inside, 3] = OVERLAY_ALPHA
            # convert_alpha: a display-format surface blits ~30x faster than raw RGBA.
            small = pygame.image.frombuffer(image.tobytes(), (cols, rows), "RGBA").convert_alpha()
            cell = self.static.cell_size * s
            big = pygame.transform.scale(small, (round(cols * cell), round(rows * cell)))
            surface.blit(big, (round(ox), round(oy)))
        elif self._tri_polys:
            if self._field_layer is None:
                self._field_layer = pygame.Surface(self.layout.size, pygame.SRCALPHA).convert_alpha()
            layer = self._field_layer
            layer.fill((0, 0, 0, 0))
            for poly, (r, g, b) in zip(self._tri_polys, rgb.tolist()):
                pygame.draw.polygon(layer, (r, g, b, OVERLAY_ALPHA), poly)
            surface.blit(layer, (0, 0))

    def _draw_mesh(self, surface: pygame.Surface) -> None:
        if self._tri_polys:
            for poly in self._tri_polys:
                pygame.draw.lines(surface, MESH, True, poly, 1)
            return
        s, (ox, oy) = self.layout.scale, self.layout.origin
        cell = self.static.cell_size * s
        for r, c in np.argwhere(self.static.occupancy):
            rect = pygame.Rect(round(ox + c * cell), round(oy + r * cell), round(cell) + 1, round(cell) + 1)
            pygame.draw.rect(surface, MESH, rect, 1)

    # ------------------------------------------------------------------ the frame
    def draw(self, surface: pygame.Surface, scene: Scene, options: DrawOptions | None = None) -> None:
        """Draw one frame of ``scene`` onto ``surface`` (the window's size)."""
        options = options or DrawOptions()
        if surface.get_size() != self.layout.size:
            self.resize(surface.get_size())
        self._wrap_help(options.help)
        surface.blit(self._composite_surface(scene, options), (0, 0))
        s = self.layout.scale
        for x, y in scene.markers:
            self._diamond(surface, self.to_screen(x, y), max(4, s * 0.3), MARKER, 0)
        for guard in scene.guards:
            self._draw_cone(surface, guard)
        if options.show_plans:
            for i, guard in enumerate(scene.guards):
                self._draw_plan(surface, guard, PLAN_COLORS[i % len(PLAN_COLORS)])
        for guard in scene.guards:
            self._draw_guard(surface, guard, scene)
        if options.show_plans:
            for i, guard in enumerate(scene.guards):
                self._draw_target(surface, guard, PLAN_COLORS[i % len(PLAN_COLORS)])
        self._draw_player(surface, scene)
        self._draw_hud(surface, scene, options)
        self._draw_help(surface)
        if options.banner:
            self._draw_banner(surface, options.banner, options.banner_sub)
        elif options.paused:
            self._draw_banner(surface, "PAUSED", "Space to continue")

    def _draw_cone(self, surface: pygame.Surface, guard: GuardDrawing) -> None:
        if not guard.active or len(guard.cone) < 3:
            return
        pts = np.asarray(self._pts(guard.cone))
        lo = np.floor(pts.min(axis=0)).astype(int)
        hi = np.ceil(pts.max(axis=0)).astype(int) + 1
        size = (max(1, hi[0] - lo[0]), max(1, hi[1] - lo[1]))
        layer = pygame.Surface(size, pygame.SRCALPHA)
        local = [(float(x), float(y)) for x, y in pts - lo]
        pygame.draw.polygon(layer, CONE_SEEING if guard.sees_player else CONE, local)
        surface.blit(layer, (int(lo[0]), int(lo[1])))
        edge = CONE_SEEING_EDGE if guard.sees_player else CONE_EDGE
        pygame.draw.lines(surface, edge, True, [tuple(p) for p in pts.tolist()], 1)

    def _draw_plan(self, surface: pygame.Surface, guard: GuardDrawing, color: Color) -> None:
        if not guard.active:
            return
        s = self.layout.scale
        if len(guard.path):
            pts = [self.to_screen(*guard.pos)] + self._pts(guard.path)
            pygame.draw.lines(surface, color, False, pts, max(2, round(s * 0.08)))
        for x, y in guard.candidates:
            pygame.draw.circle(surface, color, self.to_screen(x, y), max(3, s * 0.15), 1)
        if guard.chosen is not None:
            pygame.draw.circle(surface, color, self.to_screen(*guard.chosen), max(3, s * 0.15))

    def _draw_target(self, surface: pygame.Surface, guard: GuardDrawing, color: Color) -> None:
        """A square frame around the target node, larger than a body so it shows around one."""
        if guard.active and guard.target is not None:
            cx, cy = self.to_screen(*guard.target)
            half = max(6, self.layout.scale * 0.45)
            pygame.draw.rect(surface, color, pygame.Rect(cx - half, cy - half, 2 * half, 2 * half), 2)

    def _draw_guard(self, surface: pygame.Surface, guard: GuardDrawing, scene: Scene) -> None:
        s = self.layout.scale
        center = self.to_screen(*guard.pos)
        radius = max(4.0, scene.agent_radius * s)
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
        if guard.state:
            text = f"{guard.state} · {guard.role}" if guard.role else guard.state
            label = self._text(text, self.small, TEXT)
            surface.blit(label, (center[0] - label.get_width() / 2, center[1] + radius + 1))
        if guard.awareness is not None:  # graded perception: a meter above the guard
            frac = max(0.0, min(1.0, guard.awareness))
            meter = pygame.Rect(round(center[0] - radius), round(center[1] - radius - 7),
                                round(2 * radius), 4)
            pygame.draw.rect(surface, (40, 40, 40), meter)
            pygame.draw.rect(surface, BAD if frac >= 1.0 else WARN,
                             (meter.x, meter.y, round(meter.w * frac), meter.h))

    def _draw_player(self, surface: pygame.Surface, scene: Scene) -> None:
        s = self.layout.scale
        p = scene.player
        center = self.to_screen(*p.pos)
        radius = max(4.0, scene.agent_radius * s)
        color = PLAYER_SPRINT if p.sprinting else PLAYER
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
        self._row(surface, bar.right + 10, y, items)
        if options.message:
            label = self._text(options.message, self.font, options.message_color)
            surface.blit(label, (w - label.get_width() - 10, y))
        if options.legend:
            self._draw_legend(surface, scene, 10, y + 22)

    def _draw_legend(self, surface: pygame.Surface, scene: Scene, x: int, y: int) -> None:
        layer = scene.layer
        if scene.overlay == "none":
            self._row(surface, x, y, [("overlay: none", TEXT_DIM)])
            return
        if layer is None:
            self._row(surface, x, y, [(f"overlay {scene.overlay}: {scene.field_note}", WARN)])
            return
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
        self._row(surface, x, y, [("warm attracts guards · cold repels", TEXT_DIM)])

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
            self._prepare()

    def _draw_help(self, surface: pygame.Surface) -> None:
        y = self.layout.size[1] - self.layout.help_height + 3
        for line in self._help_lines:
            surface.blit(self._text(line, self.small, TEXT_DIM), (10, y))
            y += self.HELP_LINE

    def _draw_banner(self, surface: pygame.Surface, title: str, sub: str) -> None:
        w, h = self.layout.size
        big = self._text(title, self.big, TEXT)
        small = self._text(sub, self.font, TEXT) if sub else None
        bw = max(big.get_width(), small.get_width() if small else 0) + 40
        bh = big.get_height() + (small.get_height() + 8 if small else 0) + 24
        box = pygame.Surface((bw, bh), pygame.SRCALPHA)
        box.fill((0, 0, 0, 170))
        x, y = (w - bw) // 2, (h - bh) // 2
        surface.blit(box, (x, y))
        surface.blit(big, ((w - big.get_width()) // 2, y + 12))
        if small:
            surface.blit(small, ((w - small.get_width()) // 2, y + 16 + big.get_height()))


class FrameLoop:
    """The frame loop play and replay share: ``frame(elapsed)`` until Esc or ``frames``.

    Subclasses set ``running``, ``lockstep`` and ``clock`` and implement ``frame``. In
    lockstep (tests, ``--frames``) every frame advances one fixed step; otherwise the clock
    paces the loop at 60 frames per second and passes the real elapsed time.
    """

    running: bool
    lockstep: bool
    clock: pygame.time.Clock
    screen: pygame.Surface
    renderer: Renderer

    def handle_window(self, event: pygame.event.Event) -> bool:
        """Close and resize events, the same in every window; True when ``event`` was one."""
        if event.type == pygame.QUIT:
            self.running = False
            return True
        if event.type == pygame.VIDEORESIZE:
            self.screen = pygame.display.get_surface() or self.screen
            self.renderer.resize(self.screen.get_size())
            return True
        return False

    def frame(self, elapsed: float) -> None:  # pragma: no cover - implemented by subclasses
        raise NotImplementedError

    def run(self, frames: int | None = None) -> list[float]:
        """Loop until Esc / window close (or ``frames`` frames); return each frame's seconds."""
        times: list[float] = []
        elapsed = 0.0
        while self.running and (frames is None or len(times) < frames):
            start = time.perf_counter()
            self.frame(elapsed)
            times.append(time.perf_counter() - start)
            elapsed = 0.0 if self.lockstep else self.clock.tick(60) / 1000.0
        return times


def default_window_size(static: StaticScene) -> tuple[int, int]:
    """A window that shows the level at a comfortable scale (at least 960 px wide)."""
    s = max(14.0, min(40.0, min(1100 / static.width, 640 / static.height)))
    return (max(960, round(static.width * s) + 2 * Renderer.MARGIN),
            round(static.height * s) + Renderer.HUD_HEIGHT + 2 * Renderer.MARGIN + 3 * Renderer.HELP_LINE + 6)


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
