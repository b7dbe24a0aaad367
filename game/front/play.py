"""``stealth play``: the interactive game (pygame-ce window, keyboard and mouse).

The world is built like a headless trial (:func:`game.trial.make_world`) with the
interactive physics step (1/60 s), play's own defaults (the ``[play.*]`` tables of
game/defaults.toml, :func:`game.config.play_defaults`: the level's own guard spawns (SPEC §6),
guards that hurt only a player they noticed, the awareness marker, a take-down reach beyond
the attack range; ``--set`` overrides them) and, by default,
the capture scenario: the game is over when the player's HP reaches 0 (or after the
trial's duration, 60 s by default: the player survived). Enter restarts, 1–5 restart with
another guard mode on the same level and seed.

With a real display the game runs in real time: the world advances in fixed 1/60-s steps,
as many a frame as the wall clock says (catch-up, at most :data:`MAX_CATCH_UP` s a frame),
and a frame that had to run more than :data:`SKIP_DRAW_STEPS` steps skips its drawing
(never two frames in a row), so slow drawing costs pictures, not game time. With ``--frames N`` or under
``SDL_VIDEODRIVER=dummy`` it runs in lockstep: exactly one physics step per frame, as
fast as the machine allows (``N`` frames = ``N/60`` s of game time), so tests, benchmarks
and screenshots are reproducible.
"""

from __future__ import annotations

import dataclasses
import gc
import math
import sys
import time
from collections.abc import Callable
from typing import Any

from game.large.distance_worker import DistanceWorker
from game.front.camera import Camera
from game.front.effects import NoiseRings, draw_rain
from game.front.frame_loop import FrameLoop
from game.front.layers import COMPOSE_STRIPES
from game.front.palette import BAD, GOOD, NOISE, TEXT, WARN
from game.front.play_settings import PlaySettings, SessionSink
from game.front.render import (
    DrawOptions,
    Renderer,
    default_window_size,
    init_pygame,
    pygame,
)
from game.front.keys import key_help, mode_on_key
from game.front.screens import Panel
from game.front.sound import SoundBoard
from game.front.work_ahead import WorkAhead
from game.front.best import BestResults
from game.large.policy import SizePolicy
from game.objectives import Objectives
from game.record import HUMAN, QUESTIONS, Recording
from game.scene import OVERLAYS, Scene, SceneBuilder, overlay_key
from game.trial import TrialSpec
from game.world import World


#: Stealth mechanics: the World method each input calls, the label of its messages and the
#: sound of its success ("" : the sound board hears it in the world: take-down, rain).
MECHANICS: dict[str, tuple[Callable[..., Any], str, str]] = {
    "throw_decoy": (World.throw_decoy, "throw decoy", "throw"),
    "activate_decoy": (World.activate_decoy, "activate decoy", "decoy_on"),
    "take_down": (World.take_down, "take down", ""),
    "toggle_rain": (World.toggle_rain, "rain", ""),
}

#: The pause menu (Esc): its entries, in order.
MENU = ("Resume", "Restart", "Volume", "Controls", "Quit")

_MOVE_KEYS: tuple[tuple[int, float, float], ...] = (
    (pygame.K_w, 0.0, -1.0), (pygame.K_UP, 0.0, -1.0),
    (pygame.K_s, 0.0, 1.0), (pygame.K_DOWN, 0.0, 1.0),
    (pygame.K_a, -1.0, 0.0), (pygame.K_LEFT, -1.0, 0.0),
    (pygame.K_d, 1.0, 0.0), (pygame.K_RIGHT, 1.0, 0.0),
)

#: The most game time one frame catches up in real time (s): a longer stall (the window
#: dragged, the machine suspended) is lost rather than replayed in one burst.
MAX_CATCH_UP = 0.5
#: A frame that ran more steps than this skips its drawing (never two in a row).
SKIP_DRAW_STEPS = 2
MESSAGE_SECONDS = 2.5
#: game seconds the landing cross of a throw stays drawn
LANDED_SECONDS = 1.0
#: above this many nodes the aim shows the range only (the landing search is one pass
#: over every node: too slow for every mouse move on a 10^6-cell level)
AIM_CROSS_MAX_NODES = 50_000




class PlayGame(FrameLoop):
    """One game window: world, scene builder, renderer and the input handling.

    ``lockstep=True`` advances exactly one physics step per :meth:`frame`; otherwise the
    world follows the wall clock. A game starts on the ready screen (``state == "ready"``):
    the clock starts with the player's first move (at once with an autopilot). It ends
    ``"over"`` (won, caught or time up), after the questionnaire (``"questions"``) when asked.

    Usage (opens a window)::

        game = PlayGame(PlaySettings("miami", autopilot="maxmin", overlay="K"), lockstep=True)
        times = game.run(frames=120)
    """

    def __init__(
        self, settings: PlaySettings, *, lockstep: bool = True,
        size: tuple[int, int] | None = None, screen: pygame.Surface | None = None,
        on_session: SessionSink | None = None,
    ) -> None:
        from game.config import Config

        init_pygame()
        self.settings = settings
        self.lockstep = lockstep
        self.on_session = on_session
        self.config = Config.for_play(settings.overrides)  # [play.*], then --set
        self.autopilot = settings.autopilot
        self.overlay = overlay_key(settings.overlay)
        self.show_mesh, self.show_plans = settings.show_mesh, settings.show_plans
        self.paused = False
        #: the pause menu's highlighted entry (None: closed); ``controls``: its key list shown
        self.menu: int | None = None
        self.controls = False
        self._paused_before_menu = False
        self.running = True
        self.message, self.message_color, self._message_until = "", WARN, 0.0
        self.camera = Camera()
        self.clock = pygame.time.Clock()
        self.sessions: list[dict[str, Any]] = []
        self._size, self._screen = size, screen
        self._distances: DistanceWorker | None = None
        #: the game ended, recording, before the distance searches were done: store then
        self._store_when_ready = False
        self.sound = SoundBoard()
        #: the frame's extra work, sized by its measured budget (see :meth:`frame`)
        self.work = WorkAhead()
        self.best = BestResults()
        #: frames whose drawing was skipped to catch up (real time only), and whether the
        #: last one was
        self.skipped_draws, self._skipped_last = 0, False
        #: the last throw's landing point and game time (its cross is drawn a moment)
        self.landed: tuple[float, float, float] | None = None
        self._aim_key: tuple[int, int, int] | None = None
        self._aim_point: tuple[float, float] | None = None
        self._load(settings.level, settings.guards)
        _freeze_heap()

    def _load(self, level: str, mode: str) -> None:
        """(Re)build world, scene builder and renderer for ``level`` (a new level or the first)."""
        self.settings = dataclasses.replace(self.settings, level=level)
        self.world = self._build_world(mode)
        self.level = self.world.level
        policy = SizePolicy.of(self.world.graph)
        self.builder = SceneBuilder(
            self.level, self.world.graph, view_range=self.world.view_range,
            fov_deg=float(self.config["world.fov_deg"]),
            background_fields=policy.background_fields,
        )
        if self._screen is None:
            pygame.display.set_caption(f"Stealthfield — {self.level.name}")
            size = self._size or default_window_size(self.builder.static)
            self._screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        self.screen = self._screen
        self.camera = Camera()
        stripes = COMPOSE_STRIPES if policy.striped_compose else 1
        self.renderer = Renderer(self.builder.static, self.screen.get_size(), self.camera,
                                 compose_stripes=stripes)
        self.scene: Scene | None = None

    # ------------------------------------------------------------------ world
    def _build_world(self, mode: str) -> World:
        from game.trial import make_world

        self.mode = mode
        spec = TrialSpec(
            level=self.settings.level, abstraction=self.settings.abstraction, guards=mode,
            player=self.autopilot or "evade", scenario=self.settings.scenario,
            seed=self.settings.seed, stimuli=self.settings.stimuli,
        )
        world = make_world(spec, self.config, interactive=True)
        if SizePolicy.of(world.graph).distance_worker:
            if self._distances is None or self._distances.graph is not world.graph:
                self._close_distances()
                self._distances = DistanceWorker(world.graph)
            world.m.distance_worker = self._distances
        if self.autopilot is None:
            world.player_input = (0.0, 0.0)  # the keyboard drives; the policy never runs
        self.goal = Objectives.of(world.level)
        self.rings = NoiseRings()
        if hasattr(self, "sound"):
            self.sound.reset()
        self.state = "ready" if self.autopilot is None else "playing"
        self.outcome = ""
        self.answers: dict[str, int] = {}
        self._accumulator = 0.0
        self.recording: Recording | None = None
        if self.settings.record:
            identity = dataclasses.replace(spec, player=HUMAN, overrides=self.identity_overrides())
            self.recording = Recording(identity, self.config)
            self.recording.attach(world)
        return world

    def identity_overrides(self) -> tuple[tuple[str, Any], ...]:
        """The config changes a session is played with (its trial identity's overrides):
        play's own defaults (``[play.*]``), then the keys of ``--set``."""
        from game.config import parse_overrides, play_defaults

        keys = dict.fromkeys([*play_defaults(), *(k for k, _ in parse_overrides(self.settings.overrides))])
        return tuple((k, self.config[k]) for k in keys)

    def restart(self, mode: str | None = None) -> None:
        """A fresh world on the same level and seed (optionally with another guard mode)."""
        self._close_session("restarted")
        self.world = self._build_world(mode or self.mode)
        _freeze_heap()
        self.paused = False
        self.flash(f"restarted: guards {self.mode}", GOOD)

    def next_level(self, step: int = 1) -> None:
        """Load the next (``step=-1``: previous) level of the playlist, same guards and seed."""
        from game.front.chooser import play_levels

        names = list(self.settings.playlist) or play_levels()
        current = self.settings.level
        k = names.index(current) if current in names else -1
        self._close_session("left")
        self._load(names[(k + step) % len(names)], self.mode)
        _freeze_heap()
        self.flash(f"level {self.level.name}", GOOD)

    def flash(self, text: str, color: tuple[int, int, int] = WARN) -> None:
        """Show a short message in the HUD for a few seconds."""
        self.message, self.message_color = text, color
        self._message_until = time.monotonic() + MESSAGE_SECONDS

    # ------------------------------------------------------------------ sessions
    def _result(self) -> dict[str, Any]:
        return {"won": self.outcome == "won", "outcome": self.outcome or "quit",
                "collected": int(self.goal.collected.sum()),
                "collectibles": int(len(self.goal.collected))}

    def _close_session(self, why: str) -> None:
        """Store the session of the current world once (a game left before its first move is
        not a session)."""
        if self.recording is None or self.world.step_index == 0:
            self.recording = None
            return
        if not self.outcome:
            self.outcome = why
        self._store_when_ready = False
        pending = self.world.m.distances_pending()
        if pending:
            print(f"stealth: storing the session once the distance metric's last {pending} "
                  "search(es) are done ...", file=sys.stderr, flush=True)
        row = self.recording.finish(self.world, self._result(), self.answers)
        self.sessions.append(row)
        if self.on_session is not None:
            self.on_session(row, self.recording.trace_lines())
        self.recording = None

    def _game_over(self) -> None:
        if self.goal.won:
            self.outcome = "won"
        elif self.world.end_on_capture and self.world.m.captures:
            self.outcome = "caught"
        else:
            self.outcome = "survived" if not self.goal.has_goal else "time up"
        self.sound.game_over(self.outcome)
        if self.autopilot is None:  # the player's own game: keep it if it is the best yet
            result = {"outcome": self.outcome, "time": round(self.world.t, 2),
                      "stars": int(self.goal.collected.sum())}
            if self.best.offer(self.level.name, self.mode, result):
                self.flash("a new best result", GOOD)
        if self.recording is not None and self.settings.questions:
            self.state = "questions"
        elif self.world.m.distances_ready():
            self.state = "over"
            self._close_session(self.outcome)
        else:  # a large level: stored once the distance metric's searches are done (update)
            self.state, self._store_when_ready = "over", True

    # ------------------------------------------------------------------ input
    def help_items(self) -> list[str]:
        """The help line: every key of :func:`game.front.keys.key_help`, shortly."""
        return [f"{keys} {what.split(' (')[0]}" for keys, what in key_help()]

    def _mechanic(self, method: str, *args: float) -> bool:
        """Do a mechanic; its message and sound; returns whether it was done."""
        action, label, sound = MECHANICS[method]
        if self.world.done or self.state != "playing":
            return False
        try:
            result = action(self.world, *args)
        except (ValueError, RuntimeError) as error:
            self.flash(f"{label}: {error}", BAD)
            self.sound.play("denied")
            return False
        done = bool(result) if isinstance(result, str) else result is None or bool(result)
        if isinstance(result, str):  # a refusal is a str that is false (game.world.Refused)
            self.flash(f"{label}: {result}", GOOD if result else BAD)
        elif done:
            self.flash(f"{label}: done", GOOD)
        else:
            self.flash(f"{label}: not possible now", BAD)
        if not done:
            self.sound.play("denied")
        elif sound:
            self.sound.play(sound)
        return done

    def handle(self, event: pygame.event.Event) -> None:
        """React to one pygame event."""
        if self.handle_window(event):
            return
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
            x, y = self.renderer.to_world(*event.pos)
            static = self.builder.static
            if 0 <= x <= static.width and 0 <= y <= static.height:
                point = landing_point(self.world, x, y)
                if self._mechanic("throw_decoy", x, y):
                    self.landed = (*point, self.world.t)
        elif (factor := self.zoom_input(event)) is not None:
            self.zoom(factor)
        elif event.type == pygame.KEYDOWN:
            self._key(event.key)

    def open_menu(self) -> None:
        """Esc: the pause menu, the game paused under it."""
        if self.menu is None:
            self._paused_before_menu = self.paused
        self.menu, self.controls, self.paused = 0, False, True

    def close_menu(self) -> None:
        """Resume: the menu closed, the game as paused as it was before."""
        self.menu, self.controls, self.paused = None, False, self._paused_before_menu

    def _menu_key(self, key: int) -> None:
        """Keys while the pause menu is open: Up / Down choose, Enter takes, Left / Right
        set the volume, Esc resumes (or leaves the controls list), Q quits."""
        assert self.menu is not None
        if self.controls:
            if key in (pygame.K_ESCAPE, pygame.K_RETURN, pygame.K_KP_ENTER, pygame.K_BACKSPACE):
                self.controls = False
            return
        entry = MENU[self.menu]
        if key == pygame.K_ESCAPE:
            self.close_menu()
        elif key in (pygame.K_UP, pygame.K_w, pygame.K_DOWN, pygame.K_s):
            step = -1 if key in (pygame.K_UP, pygame.K_w) else 1
            self.menu = (self.menu + step) % len(MENU)
        elif key in (pygame.K_LEFT, pygame.K_a, pygame.K_RIGHT, pygame.K_d) and entry == "Volume":
            self.sound.change_volume(0.1 if key in (pygame.K_RIGHT, pygame.K_d) else -0.1)
            self.sound.play("step")  # hear the new volume
        elif key in (pygame.K_RETURN, pygame.K_KP_ENTER):
            if entry == "Resume":
                self.close_menu()
            elif entry == "Restart":
                self.close_menu()
                self.restart()
            elif entry == "Volume":
                self.flash("sound off" if self.sound.toggle_mute() else "sound on", GOOD)
            elif entry == "Controls":
                self.controls = True
            else:
                self.running = False

    def _key(self, key: int) -> None:
        if self.state == "questions":
            self._answer(key)
            return
        if key == pygame.K_q:
            self.running = False
        elif self.menu is not None:
            self._menu_key(key)
        elif key == pygame.K_ESCAPE:
            self.open_menu()
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
        elif key == pygame.K_n:
            self.next_level()
        elif key == pygame.K_b:
            self.next_level(-1)
        elif pygame.K_1 <= key <= pygame.K_9 and (mode := mode_on_key(key - pygame.K_0)):
            self.restart(mode)
        elif key == pygame.K_e:
            self._mechanic("activate_decoy")
        elif key == pygame.K_f:
            self._mechanic("take_down")
        elif key == pygame.K_r:
            self._mechanic("toggle_rain")
        elif key == pygame.K_v:
            self.flash("sound off" if self.sound.toggle_mute() else "sound on", GOOD)
        elif key in (pygame.K_LEFTBRACKET, pygame.K_RIGHTBRACKET):
            step = 0.1 if key == pygame.K_RIGHTBRACKET else -0.1
            self.flash(f"volume {round(100 * self.sound.change_volume(step))} %", GOOD)

    def _answer(self, key: int) -> None:
        """Questionnaire keys: 1-5 rate the current question, Esc / Enter skip the rest."""
        if pygame.K_1 <= key <= pygame.K_5:
            name = QUESTIONS[len(self.answers)][0]
            self.answers[name] = key - pygame.K_0
            if len(self.answers) < len(QUESTIONS):
                return
        elif key not in (pygame.K_ESCAPE, pygame.K_RETURN, pygame.K_KP_ENTER):
            return
        self.state = "over"
        self._close_session(self.outcome)
        self.flash("session recorded", GOOD)

    def _steer(self) -> None:
        """Keyboard → ``world.player_input`` and ``world.sprinting``; the first move starts."""
        pressed = pygame.key.get_pressed()
        vx = vy = 0.0
        for key, dx, dy in _MOVE_KEYS:
            if pressed[key]:
                vx, vy = vx + dx, vy + dy
        vx, vy = max(-1.0, min(1.0, vx)), max(-1.0, min(1.0, vy))
        if (vx or vy) and self.state == "ready":
            self.state = "playing"
        if self.autopilot is not None:
            if not (vx or vy):
                return
            self.autopilot = None  # a movement key takes over from the autopilot
            self.flash("manual control", GOOD)
        norm = (vx * vx + vy * vy) ** 0.5
        self.world.player_input = (vx / norm, vy / norm) if norm else (0.0, 0.0)
        mods = pygame.key.get_mods()
        self.world.sprinting = bool(mods & pygame.KMOD_SHIFT)
        self.world.sneaking = not self.world.sprinting and bool(
            mods & pygame.KMOD_CTRL or pressed[pygame.K_c])

    # ------------------------------------------------------------------ frames
    def focus(self) -> tuple[float, float]:
        """The camera follows the player."""
        return self.world.player.pos

    def idle(self) -> bool:
        """Paused, on the ready screen or after the game: nothing moves without a key."""
        return self.paused or self.state != "playing"

    def start(self) -> None:
        """Leave the ready screen now (what the first move does)."""
        if self.state == "ready":
            self.state = "playing"

    def _step(self) -> None:
        damage = self.world.health.damage_steps
        self.world.step()
        if self.world.health.damage_steps > damage and time.monotonic() >= self._message_until - 2.0:
            hp = math.floor(max(0.0, self.world.hp) * 10) / 10  # as the HUD will show it
            self.flash(f"hit! HP {hp:.1f}", BAD)  # the cue (its sound: SoundBoard)
        events = self.goal.update(self.world.player.pos)
        if "collected" in events:
            self.flash(f"picked up ({self.goal.remaining} left)", GOOD)
            self.sound.play("pickup")
        if "escaped" in events:
            self.world.stop()

    def update(self, elapsed: float) -> int:
        """Advance the world: one step in lockstep, else ``elapsed`` seconds of game time in
        fixed steps (what is left of a step waits for the next frame); returns the steps run."""
        if self.paused or self.state in ("over", "questions"):
            self._accumulator = 0.0
            if self._store_when_ready and self.world.m.distances_ready():
                self._store_when_ready = False
                self._close_session(self.outcome)
                self.flash("session recorded", GOOD)
            return 0
        self._steer()
        if self.state == "ready":
            return 0
        steps = 0
        if self.lockstep:
            self._step()
            steps = 1
        else:
            self._accumulator = min(self._accumulator + elapsed, MAX_CATCH_UP)
            dt = self.world.dt
            while self._accumulator >= dt - 1e-9 and not self.world.done:
                self._step()
                steps += 1
                self._accumulator -= dt
        self.rings.observe(self.world)
        if self.world.done:
            self._game_over()
        return steps

    def panel(self) -> Panel | None:
        """The screen over the map now (ready, questionnaire, game over), if any."""
        return play_panel(self)

    def options(self) -> DrawOptions:
        """Display options and HUD texts for this frame."""
        message = self.message if time.monotonic() < self._message_until else ""
        info = [f"autopilot {self.autopilot}"] if self.autopilot else []
        if self.goal.has_goal:
            info.append(f"stars {int(self.goal.collected.sum())}/{len(self.goal.collected)}"
                        if len(self.goal.collected) else "goal: exit")
        if self.recording is not None:
            info.append("REC")
        return DrawOptions(
            show_mesh=self.show_mesh, show_plans=self.show_plans,
            paused=self.paused and self.menu is None,  # the menu says PAUSED itself
            help=self.help_items(), message=message, message_color=self.message_color,
            info=info, panel=self.panel(),
            collectibles=self.goal.collectibles[~self.goal.collected],
            effects=self._effects,
        )

    def aim(self) -> tuple[list[tuple[float, float]], tuple[float, float] | None] | None:
        """While a throw is ready and the pointer is over the map: the throw's range (the
        diamond of ``stimuli.throw_radius`` cells around the player's cell, world points)
        and where a click there would land (None on a very large level)."""
        world = self.world
        if (self.state != "playing" or self.paused or world.done
                or world.t < world.next_throw - 1e-9 or not pygame.mouse.get_focused()):
            return None
        mx, my = pygame.mouse.get_pos()
        if not self.renderer.layout.world_rect.collidepoint(mx, my):
            return None
        cs = world.level.cell_size
        reach = (world.action_params.throw_radius + 0.5) * cs
        px, py = world.player.pos
        cx, cy = (math.floor(px / cs) + 0.5) * cs, (math.floor(py / cs) + 0.5) * cs
        diamond = [(cx, cy - reach), (cx + reach, cy), (cx, cy + reach), (cx - reach, cy)]
        if world.graph.n > AIM_CROSS_MAX_NODES:
            return diamond, None
        key = (world.player.node, mx, my)
        if key != self._aim_key:
            self._aim_key = key
            self._aim_point = landing_point(world, *self.renderer.to_world(mx, my))
        return diamond, self._aim_point

    def _effects(self, surface: pygame.Surface, renderer: Renderer) -> None:
        if self.world.raining:
            draw_rain(surface, renderer.layout.world_rect, self.world.t)
        self.rings.draw(surface, renderer.to_screen, renderer.layout.scale, self.world.t)
        aim = self.aim()
        if aim is not None:
            diamond, point = aim
            (x0, y0), (x1, y1) = renderer.to_screen(0, 0), renderer.to_screen(
                self.builder.static.width, self.builder.static.height)
            clip = surface.get_clip()
            surface.set_clip(clip.clip(pygame.Rect(round(x0), round(y0), round(x1 - x0),
                                                   round(y1 - y0))))  # the level only
            corners = [renderer.to_screen(*p) for p in diamond]
            pygame.draw.polygon(surface, (0, 0, 0), corners, 4)
            pygame.draw.polygon(surface, NOISE, corners, 2)
            surface.set_clip(clip)
            if point is not None:
                _cross(surface, renderer.to_screen(*point), 7, NOISE)
        if self.landed is not None and self.world.t - self.landed[2] < LANDED_SECONDS:
            _cross(surface, renderer.to_screen(self.landed[0], self.landed[1]), 9, TEXT)

    def draw(self) -> Scene:
        """Build the scene of the world now and draw it to the window."""
        scene = self.builder.from_world(self.world, self.overlay, plans=self.show_plans)
        self.follow()
        self.renderer.draw(self.screen, scene, self.options())
        self.scene = scene
        return scene

    def frame(self, elapsed: float = 0.0) -> None:
        """One frame: events, world update, drawing, display flip, then work ahead.

        The frame's fixed part (all but the work ahead) is timed into :attr:`work`'s budget
        (:class:`~game.front.frame_budget.FrameBudget`), which says how long the guard AI
        may then work ahead (:meth:`~ai.view.GuardAI.prepare`: on a large level the spreads
        of the nodes the guards stand on and head for are searched there, a ring at a time,
        instead of inside the next tick or decision) and how many frames a large level's
        new field values are composed over. It changes no result, only when work is done.
        """
        start = time.perf_counter()
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return
        steps = self.update(elapsed)
        if steps > SKIP_DRAW_STEPS and not self._skipped_last and not self.lockstep:
            # behind the wall clock: this frame's time goes to the simulation, not a picture
            self.skipped_draws += 1
            self._skipped_last = True
            self.work.after_frame(self.world, time.perf_counter() - start, self.idle())
            return
        self._skipped_last = False
        self.work.before_draw(self.renderer.layers)
        scene = self.draw()
        if self.state == "playing" and not self.paused:
            self.sound.observe(self.world, scene.detected, scene.phase,
                               [g.awareness for g in scene.guards])
        pygame.display.flip()
        self.work.after_frame(self.world, time.perf_counter() - start, self.idle())

    def settle_view(self) -> None:
        """Draw the current moment until the picture shows all of it — on a large level the
        overlay of the current field, computed beside the frames and composed in stripes —
        without stepping the world: what a screenshot of this moment should show."""
        for _ in range(100):
            self.draw()
            waited = self.builder.settle()
            if not waited and not self.renderer.layers.composing:
                self.draw()
                return

    def close(self) -> None:
        """Store the session still open (if recording) and give the frozen heap back."""
        self._close_session("quit")
        self._close_distances()
        self.sound.close()
        gc.unfreeze()

    def _close_distances(self) -> None:
        if self._distances is not None:
            self._distances.close()
            self._distances = None



# ------------------------------------------------------------ screens over the map
def play_panel(game: PlayGame) -> Panel | None:
    """The screen over the map now (pause menu, ready, questionnaire, game over), if any."""
    if game.menu is not None:
        return menu_panel(game)
    goal = game.goal
    if game.state == "ready":
        if goal.has_goal:
            task = (f"Pick up the {len(goal.collected)} stars, then reach" if len(goal.collected)
                    else "Reach") + " the green exit without being caught"
        else:
            task = f"Survive {game.world.total_steps * game.world.dt:g} s without being caught"
        return Panel(f"{game.level.name}: ready", (task, "The clock starts on your first move (WASD / arrows)"),
                     GOOD, hint="N next level · B previous · Esc menu · Q quit")
    if game.state == "questions":  # the result stays in view, each answer beside its question
        k = len(game.answers)
        title, color = _OUTCOME_TITLES.get(game.outcome, (game.outcome.upper(), WARN))
        lines = [f"at {game.world.t:.1f} s. Your view, 1 to 5:"] + [
            f"{q}: {game.answers[name]}" if name in game.answers else q for name, q in QUESTIONS]
        return Panel(title, lines, color, choice=k + 1,
                     hint="press 1-5 for the marked question · Enter skip")
    if game.state == "over":
        return over_panel(game)
    return None


def menu_panel(game: PlayGame) -> Panel:
    """The pause menu (Esc), or its list of controls."""
    if game.controls:
        return Panel("Controls", [f"{keys}: {what}" for keys, what in key_help()], WARN,
                     hint="Esc / Enter back")
    volume = "muted" if game.sound.muted else f"{round(100 * game.sound.volume)} %"
    lines = [f"Volume {volume}  (Left / Right, Enter mute)" if entry == "Volume" else entry
             for entry in MENU]
    return Panel("PAUSED", lines, WARN, choice=game.menu,
                 hint="Up / Down choose · Enter select · Esc resume · Q quit")


_OUTCOME_TITLES = {"won": ("ESCAPED", GOOD), "caught": ("CAUGHT", BAD),
                   "survived": ("SURVIVED", GOOD), "time up": ("TIME UP", WARN)}


def over_panel(game: PlayGame) -> Panel:
    """The game-over screen: the outcome and the session's metrics (once they are ready)."""
    title, color = _OUTCOME_TITLES.get(game.outcome, (game.outcome.upper(), WARN))
    hint = "Enter restart · N next level · 1-5 other guards · Esc menu · Q quit"
    pending = game.world.m.distances_pending()
    if pending:  # a large level: the metrics wait for the worker; the window does not
        return Panel(title, [f"time {game.world.t:.1f} s · the metrics follow in a moment "
                             f"({pending} distance searches to go)"], color, hint=hint)
    m = game.world.metrics()
    seen = m["first_detect_time"]
    lines = [f"time {game.world.t:.1f} s · captures {m['captures']} · first seen "
             + ("never" if seen is None else f"at {seen:.1f} s")]
    lines.append(f"mean guard distance {m['avg_guard_player_dist']:.1f} · guard coverage "
                 f"{100 * m['coverage']:.0f} %"
                 + (f" · stars {int(game.goal.collected.sum())}/{len(game.goal.collected)}"
                    if len(game.goal.collected) else ""))
    return Panel(title, lines, color, hint=hint)


def landing_point(world: World, x: float, y: float) -> tuple[float, float]:
    """Where a decoy thrown at (x, y) is seen to land: the clicked point when it lands in
    the node there (a walkable point within the throw's range), else the position of the
    node it lands on (:func:`game.actions.landing_node`: the nearest within range)."""
    from game.actions import node_containing

    node = world.landing_node(x, y)
    if node == node_containing(world, x, y):
        return (float(x), float(y))
    px, py = world.graph.positions[node]
    return (float(px), float(py))


def _cross(surface: pygame.Surface, center: tuple[float, float], r: float,
           color: tuple[int, int, int]) -> None:
    x, y = center
    for dx, dy in ((r, r), (r, -r)):
        pygame.draw.line(surface, (0, 0, 0), (x - dx, y - dy), (x + dx, y + dy), 4)
        pygame.draw.line(surface, color, (x - dx, y - dy), (x + dx, y + dy), 2)


def _freeze_heap() -> None:
    """Move everything built so far (level, graph, world) out of the garbage collector's view.

    Otherwise every full collection rescans those long-lived objects and costs a frame
    several milliseconds (measured: p99 frame time 9.8 ms → 4 ms on dishonored).
    """
    gc.unfreeze()  # a restart's old world becomes collectable again
    gc.collect()
    gc.freeze()


__all__ = ["MECHANICS", "PlayGame", "PlaySettings"]
