"""``stealth play`` on the command line: argument checks, display, frame report (the window: play.py)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from game.errors import FrontError
from game.front.play import PlayGame
from game.front.play_settings import PlaySettings, SessionSink
from game.front.render import init_pygame, pygame, save_screenshot
from game.scene import overlay_key


__all__ = ["cmd_play", "finish", "lockstep_wanted", "open_display"]


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


def cmd_play(args: argparse.Namespace, on_session: SessionSink | None = None) -> int:
    """``stealth play [LEVEL]``: see the module docstring and docs/play.md.

    Without a level a chooser lists the bundled levels. ``on_session`` receives every
    finished session's row and trace (the command line stores them for ``--record``).
    """
    from ai.stimuli import load_stimulus
    from navmesh.level import load_level

    for plugin in args.stimulus:  # before the level: a plugin may declare its zone kinds
        load_stimulus(plugin)  # a bad plugin fails here with its one-line message
    loaded = load_level(args.level) if args.level is not None else None  # a bad level: one line
    try:
        overlay = overlay_key(args.overlay)
    except ValueError as error:
        raise FrontError(f"--overlay: {error}") from None
    if args.frames is not None and args.frames < 1:
        raise FrontError(f"--frames: expected a positive number of frames, got {args.frames}")
    from game.config import ENGINE_KEY, Config

    config = Config.for_play(args.set)  # bad --set: one line
    if config[ENGINE_KEY] == "batch":  # a game is one trial in real time: the reference's
        raise FrontError('world.engine = "batch" does not cover stealth play (one game in real '
                         'time); leave world.engine at "auto" or set "pymunk"')
    if loaded is not None:
        from game.schema import check_level

        check_level(config, loaded)  # the world's own check, before a window or a note opens
    open_display()
    level = args.level
    if level is None:
        from game.front.chooser import LevelChooser, play_levels

        pygame.display.set_caption("Stealthfield")
        chooser = LevelChooser(pygame.display.set_mode((960, 780)), play_levels(),
                               mode=args.guards)
        level = chooser.run(args.frames)  # --frames: no choice within N frames ends play
        if level is None:
            try:
                finish(chooser.screen, args.screenshot, [])  # --screenshot: the chooser's frame
            finally:
                pygame.display.quit()
            return 0
        args.guards = chooser.mode
    settings = PlaySettings(
        level=level, guards=args.guards, abstraction=args.abstraction,
        scenario=args.scenario, seed=args.seed,
        overrides=tuple(args.set), autopilot=args.autopilot, overlay=overlay,
        show_mesh=args.mesh, show_plans=args.plans, stimuli=tuple(args.stimulus),
        record=on_session is not None, questions=bool(getattr(args, "questions", False)),
    )
    game = PlayGame(settings, lockstep=lockstep_wanted(args.frames), on_session=on_session)
    try:
        times = game.run(args.frames)
        finish(game.screen, args.screenshot, times)
    finally:
        game.close()
        pygame.display.quit()
    return 0
