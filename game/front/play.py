"""``stealth play``: the interactive game (pygame-ce window, keyboard and mouse).

The world is built like a headless trial (:func:`game.trial.make_world`) with the
interactive physics step (1/60 s), the level's own guard spawns (SPEC §6) and, by default,
the capture scenario: the game is over when the player's HP reaches 0 (or after the
trial's duration, 60 s by default: the player survived). Enter restarts, 1–5 restart with
another guard mode on the same level and seed.

With a real display the game runs in real time. With ``--frames N`` or under
``SDL_VIDEODRIVER=dummy`` it runs in lockstep: exactly one physics step per frame, as
fast as the machine allows (``N`` frames = ``N/60`` s of game time), so tests, benchmarks
and screenshots are reproducible.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from game.front.render import (
    BAD,
    GOOD,
    WARN,
    DrawOptions,
    FrameLoop,
    Renderer,
    default_window_size,
    init_pygame,
    pygame,
    save_screenshot,
)
from game.errors import FrontError
from game.front.keys import KEY_HELP, MODE_ORDER
from game.scene import OVERLAYS, Scene, SceneBuilder, overlay_key
from game.world import World

#: Guard modes on the number keys, in the order of SPEC §9.
MODE_KEYS: dict[int, str] = {pygame.K_1 + i: mode for i, mode in enumerate(MODE_ORDER)}

#: Stealth mechanics: the World method each input calls, and the label of its messages.
MECHANICS: dict[str, tuple[Callable[..., Any], str]] = {
    "throw_decoy": (World.throw_decoy, "throw decoy"),
    "activate_decoy": (World.activate_decoy, "activate decoy"),
    "take_down": (World.take_down, "take down"),
    "toggle_rain": (World.toggle_rain, "rain"),
}

_MOVE_KEYS: tuple[tuple[int, float, float], ...] = (
    (pygame.K_w, 0.0, -1.0), (pygame.K_UP, 0.0, -1.0),
    (pygame.K_s, 0.0, 1.0), (pygame.K_DOWN, 0.0, 1.0),
    (pygame.K_a, -1.0, 0.0), (pygame.K_LEFT, -1.0, 0.0),
    (pygame.K_d, 1.0, 0.0), (pygame.K_RIGHT, 1.0, 0.0),
)

#: At most this many physics steps per frame in real time (a slow frame slows the game).
MAX_STEPS_PER_FRAME = 6
MESSAGE_SECONDS = 2.5


@dataclass(frozen=True)
class PlaySettings:
    """Everything that defines a game; the world is rebuilt from it on restart."""

    level: str
    guards: str = "pf"
    abstraction: str = "grid"
    scenario: str = "capture"
    seed: int = 0
    overrides: tuple[str, ...] = ()
    autopilot: str | None = None
    overlay: str = "none"
    show_mesh: bool = False
    show_plans: bool = False
    #: plugin stimuli, ``"FILE.py:NAME"`` or entry-point names (``--stimulus``)
    stimuli: tuple[str, ...] = ()


class PlayGame(FrameLoop):
    """One game window: world, scene builder, renderer and the input handling.

    ``lockstep=True`` advances exactly one physics step per :meth:`frame`; otherwise the
    world follows the wall clock.

    Usage (opens a window)::

        game = PlayGame(PlaySettings("miami", autopilot="maxmin", overlay="K"), lockstep=True)
        times = game.run(frames=120)
    """

    def __init__(
        self, settings: PlaySettings, *, lockstep: bool = True,
        size: tuple[int, int] | None = None, screen: pygame.Surface | None = None,
    ) -> None:
        from game.config import Config

        init_pygame()
        self.settings = settings
        self.lockstep = lockstep
        self.config = Config.load({"world.spawns": "level"}).with_overrides(settings.overrides)
        self.autopilot = settings.autopilot
        self.overlay = overlay_key(settings.overlay)
        self.show_mesh, self.show_plans = settings.show_mesh, settings.show_plans
        self.paused = False
        self.running = True
        self.message, self.message_color, self._message_until = "", WARN, 0.0
        self.world = self._build_world(settings.guards)
        self.level = self.world.level
        self.builder = SceneBuilder(
            self.level, self.world.graph, view_range=self.world.view_range,
            fov_deg=float(self.config["world.fov_deg"]),
        )
        size = size or default_window_size(self.builder.static)
        if screen is None:
            pygame.display.set_caption(f"Stealthfield — {self.level.name}")
            screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        self.screen = screen
        self.renderer = Renderer(self.builder.static, self.screen.get_size())
        self.clock = pygame.time.Clock()
        self._accumulator = 0.0
        self.scene: Scene | None = None
        _freeze_heap()

    # ------------------------------------------------------------------ world
    def _build_world(self, mode: str) -> World:
        from game.trial import TrialSpec, make_world

        self.mode = mode
        spec = TrialSpec(
            level=self.settings.level, abstraction=self.settings.abstraction, guards=mode,
            player=self.autopilot or "evade", scenario=self.settings.scenario,
            seed=self.settings.seed, stimuli=self.settings.stimuli,
        )
        world = make_world(spec, self.config, interactive=True)
        if self.autopilot is None:
            world.player_input = (0.0, 0.0)  # the keyboard drives; the policy never runs
        return world

    def restart(self, mode: str | None = None) -> None:
        """A fresh world on the same level and seed (optionally with another guard mode)."""
        self.world = self._build_world(mode or self.mode)
        _freeze_heap()
        self.paused = False
        self._accumulator = 0.0
        self.flash(f"restarted: guards {self.mode}", GOOD)

    def flash(self, text: str, color: tuple[int, int, int] = WARN) -> None:
        """Show a short message in the HUD for a few seconds."""
        self.message, self.message_color = text, color
        self._message_until = time.monotonic() + MESSAGE_SECONDS

    # ------------------------------------------------------------------ input
    def help_items(self) -> list[str]:
        """The help line: every key of :data:`game.front.keys.KEY_HELP`, shortly."""
        return [f"{keys} {what.split(' (')[0]}" for keys, what in KEY_HELP]

    def _mechanic(self, method: str, *args: float) -> None:
        action, label = MECHANICS[method]
        if self.world.done:
            return
        try:
            result = action(self.world, *args)
        except (ValueError, RuntimeError) as error:
            self.flash(f"{label}: {error}", BAD)
            return
        if isinstance(result, str):  # a refusal is a str that is false (game.world.Refused)
            self.flash(f"{label}: {result}", GOOD if result else BAD)
        elif result is None or result:
            self.flash(f"{label}: done", GOOD)
        else:
            self.flash(f"{label}: not possible now", BAD)

    def handle(self, event: pygame.event.Event) -> None:
        """React to one pygame event."""
        if self.handle_window(event):
            return
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
            x, y = self.renderer.to_world(*event.pos)
            static = self.builder.static
            if 0 <= x <= static.width and 0 <= y <= static.height:
                self._mechanic("throw_decoy", x, y)
        elif event.type == pygame.KEYDOWN:
            self._key(event.key)

    def _key(self, key: int) -> None:
        if key == pygame.K_ESCAPE:
            self.running = False
        elif key == pygame.K_SPACE:
            self.paused = not self.paused
        elif key in (pygame.K_o, pygame.K_TAB):
            keys = list(OVERLAYS)
            self.overlay = keys[(keys.index(self.overlay) + 1) % len(keys)]
        elif key == pygame.K_m:
            self.show_mesh = not self.show_mesh
        elif key == pygame.K_g:
            self.show_plans = not self.show_plans
        elif key in (pygame.K_RETURN, pygame.K_KP_ENTER):
            self.restart()
        elif key in MODE_KEYS:
            self.restart(MODE_KEYS[key])
        elif key == pygame.K_e:
            self._mechanic("activate_decoy")
        elif key == pygame.K_f:
            self._mechanic("take_down")
        elif key == pygame.K_r:
            self._mechanic("toggle_rain")

    def _steer(self) -> None:
        """Keyboard → ``world.player_input`` and ``world.sprinting``."""
        pressed = pygame.key.get_pressed()
        vx = vy = 0.0
        for key, dx, dy in _MOVE_KEYS:
            if pressed[key]:
                vx, vy = vx + dx, vy + dy
        vx, vy = max(-1.0, min(1.0, vx)), max(-1.0, min(1.0, vy))
        if self.autopilot is not None:
            if not (vx or vy):
                return
            self.autopilot = None  # a movement key takes over from the autopilot
            self.flash("manual control", GOOD)
        norm = (vx * vx + vy * vy) ** 0.5
        self.world.player_input = (vx / norm, vy / norm) if norm else (0.0, 0.0)
        mods = pygame.key.get_mods()
        self.world.sprinting = bool(mods & pygame.KMOD_SHIFT)

    # ------------------------------------------------------------------ frames
    def update(self, elapsed: float) -> None:
        """Advance the world: one step in lockstep, else ``elapsed`` seconds of game time."""
        if self.paused or self.world.done:
            self._accumulator = 0.0
            return
        self._steer()
        if self.lockstep:
            self.world.step()
            return
        self._accumulator = min(self._accumulator + elapsed, MAX_STEPS_PER_FRAME * self.world.dt)
        while self._accumulator >= self.world.dt and not self.world.done:
            self.world.step()
            self._accumulator -= self.world.dt

    def options(self) -> DrawOptions:
        """Display options and HUD texts for this frame."""
        banner, sub = None, ""
        world = self.world
        if world.done:
            if world.end_on_capture and world.m.captures:
                banner = "CAUGHT"
                sub = f"after {world.m.capture_time:.1f} s · Enter restart · 1-5 other guards · Esc quit"
            else:
                banner = "SURVIVED" if not world.m.captures else "TIME UP"
                caught = f"caught {world.m.captures}× · " if world.m.captures else ""
                sub = f"{caught}{world.t:.0f} s · Enter restart · 1-5 other guards · Esc quit"
        message = self.message if time.monotonic() < self._message_until else ""
        info = [f"autopilot {self.autopilot}"] if self.autopilot else []
        return DrawOptions(
            show_mesh=self.show_mesh, show_plans=self.show_plans, paused=self.paused,
            help=self.help_items(), message=message, message_color=self.message_color,
            banner=banner, banner_sub=sub, info=info,
        )

    def draw(self) -> Scene:
        """Build the scene of the world now and draw it to the window."""
        scene = self.builder.from_world(self.world, self.overlay, plans=self.show_plans)
        self.renderer.draw(self.screen, scene, self.options())
        self.scene = scene
        return scene

    def frame(self, elapsed: float = 0.0) -> None:
        """One frame: events, world update, drawing, display flip."""
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return
        self.update(elapsed)
        self.draw()
        pygame.display.flip()

    def close(self) -> None:
        """Give the frozen heap back to the garbage collector (the window stays to the caller)."""
        gc.unfreeze()



def _freeze_heap() -> None:
    """Move everything built so far (level, graph, world) out of the garbage collector's view.

    Otherwise every full collection rescans those long-lived objects and costs a frame
    several milliseconds (measured: p99 frame time 9.8 ms → 4 ms on dishonored).
    """
    gc.unfreeze()  # a restart's old world becomes collectable again
    gc.collect()
    gc.freeze()


# ---------------------------------------------------------------------------- command line


def lockstep_wanted(frames: int | None) -> bool:
    """Lockstep (one physics step per frame) with --frames or without a real display."""
    return frames is not None or pygame.display.get_driver() in ("dummy", "offscreen")


def open_display() -> None:
    """Initialise the display or fail with a one-line user error."""
    try:
        init_pygame()
    except pygame.error as error:
        raise FrontError(
            f"cannot open a window ({error}); for a headless run set SDL_VIDEODRIVER=dummy"
        ) from None


def finish(surface: pygame.Surface, screenshot: str | None, times: Sequence[float]) -> None:
    """Save the screenshot (if asked) and report the frame count and times on stderr."""
    if screenshot:
        try:
            save_screenshot(surface, screenshot)
        except OSError as error:
            raise FrontError(f"--screenshot {screenshot}: cannot write ({error})") from None
    if times:
        ordered = sorted(times)
        median = ordered[len(ordered) // 2] * 1000
        p99 = ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))] * 1000
        shot = f", screenshot {screenshot}" if screenshot else ""
        print(f"{len(times)} frames, median {median:.2f} ms, p99 {p99:.2f} ms{shot}", file=sys.stderr)


def cmd_play(args: argparse.Namespace) -> int:
    """``stealth play LEVEL``: see the module docstring and docs/play.md."""
    from ai.stimuli import load_stimulus
    from navmesh.level import load_level

    for plugin in args.stimulus:  # before the level: a plugin may declare its zone kinds
        load_stimulus(plugin)  # a bad plugin fails here with its one-line message
    load_level(args.level)  # a bad level fails here with its one-line message
    try:
        overlay = overlay_key(args.overlay)
    except ValueError as error:
        raise FrontError(f"--overlay: {error}") from None
    if args.frames is not None and args.frames < 1:
        raise FrontError(f"--frames: expected a positive number of frames, got {args.frames}")
    from game.config import Config

    Config.load({"world.spawns": "level"}).with_overrides(args.set)  # bad --set: one line
    settings = PlaySettings(
        level=args.level, guards=args.guards, abstraction=args.abstraction,
        scenario=args.scenario, seed=args.seed,
        overrides=tuple(args.set), autopilot=args.autopilot, overlay=overlay,
        show_mesh=args.mesh, show_plans=args.plans, stimuli=tuple(args.stimulus),
    )
    open_display()
    game = PlayGame(settings, lockstep=lockstep_wanted(args.frames))
    try:
        times = game.run(args.frames)
        finish(game.screen, args.screenshot, times)
    finally:
        game.close()
        pygame.display.quit()
    return 0


__all__ = ["MECHANICS", "MODE_KEYS", "PlayGame", "PlaySettings", "cmd_play"]

