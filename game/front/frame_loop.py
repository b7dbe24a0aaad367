"""The frame loop play and replay share (pacing, idle sleep, zoom and window events), apart from drawing."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pygame

from .camera import ZOOM_STEP, Camera

if TYPE_CHECKING:
    from .render import Renderer

__all__ = ["IDLE_WAIT_MS", "FrameLoop"]


#: How long an idle frame loop blocks waiting for input (so it still redraws twice a second).
IDLE_WAIT_MS = 500


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
    camera: Camera
    #: the wall time the last frame of :meth:`run` measured and no frame has used yet: the
    #: next ``run`` starts with it, so a loop of ``run(N)`` calls loses no time between them
    _carried: float = 0.0

    def focus(self) -> tuple[float, float]:
        """The world point a zoomed camera follows (the player)."""
        raise NotImplementedError  # pragma: no cover - implemented by subclasses

    def zoom(self, factor: float) -> None:
        """Zoom the camera in (factor > 1) or out, centred on :meth:`focus`."""
        self.camera.follow(self.focus())
        self.camera.zoom_by(factor, self.renderer.fit_scale())
        self.renderer.refresh_view()

    def follow(self) -> None:
        """Keep a zoomed camera on :meth:`focus` (called every frame before drawing)."""
        if self.camera.zoom is not None:
            self.camera.follow(self.focus())
            self.renderer.refresh_view()

    def zoom_input(self, event: pygame.event.Event) -> float | None:
        """The zoom factor ``event`` asks for (mouse wheel, + / -), None for any other."""
        if event.type == pygame.MOUSEWHEEL and event.y:
            return ZOOM_STEP if event.y > 0 else 1 / ZOOM_STEP
        if event.type == pygame.KEYDOWN:
            if event.key in (pygame.K_EQUALS, pygame.K_PLUS, pygame.K_KP_PLUS):
                return ZOOM_STEP
            if event.key in (pygame.K_MINUS, pygame.K_KP_MINUS):
                return 1 / ZOOM_STEP
        return None

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

    def idle(self) -> bool:
        """Whether nothing moves without input (paused, ready screen): the loop then sleeps."""
        return False

    def run(self, frames: int | None = None) -> list[float]:
        """Loop until Esc / window close (or ``frames`` frames); return each frame's seconds.

        ``cpu_times`` gets each frame's CPU seconds of this process (on a loaded machine the
        wall time also counts waiting for a core; the benchmark reports both)."""
        times: list[float] = []
        self.cpu_times: list[float] = []
        elapsed = 0.0 if self.lockstep else self._carried
        while self.running and (frames is None or len(times) < frames):
            start, cpu = time.perf_counter(), time.process_time()
            self.frame(elapsed)
            times.append(time.perf_counter() - start)
            self.cpu_times.append(time.process_time() - cpu)
            if self.lockstep:
                elapsed = 0.0
            elif self.idle():
                # Sleep until an input arrives (at most IDLE_WAIT_MS): an idle game uses
                # almost no CPU. The event goes back on the queue for the next frame.
                event = pygame.event.wait(IDLE_WAIT_MS)
                if event.type != pygame.NOEVENT:
                    pygame.event.post(event)
                self.clock.tick()
                elapsed = 0.0
            else:
                elapsed = self.clock.tick(60) / 1000.0
        self._carried = elapsed
        return times
