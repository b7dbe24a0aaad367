"""Real time in ``stealth play`` (issue 42): the world advances in fixed steps, as many a
frame as the wall clock says, and a slow frame costs a picture, never game time. The wall
clock is a fake one here (each ``tick`` says how long the frame took), so nothing is timed."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.front.play import MAX_CATCH_UP, PlayGame, PlaySettings  # noqa: E402


class FakeClock:
    """``pygame.time.Clock``'s ``tick`` as the loop calls it: each frame took ``ms``."""

    def __init__(self, ms: list[int]) -> None:
        self.ms, self.calls = ms, 0

    def tick(self, framerate: int = 0) -> int:
        self.calls += 1
        return self.ms[(self.calls - 1) % len(self.ms)]


def _game() -> PlayGame:
    game = PlayGame(PlaySettings("maze", overrides=("world.player_hp=1000",)), lockstep=False,
                    size=(960, 640))
    game.start()
    return game


def _count_draws(game: PlayGame) -> list[int]:
    drawn = [0]
    draw = game.draw

    def counted():  # type: ignore[no-untyped-def]
        drawn[0] += 1
        return draw()

    game.draw = counted  # type: ignore[method-assign]
    return drawn


@pytest.mark.parametrize("ms", [150, 50, 100])
def test_game_time_keeps_pace_with_slow_frames_and_drops_pictures(ms: int) -> None:
    """Frames of ``ms`` wall ms (6.7 to 20 frames a second): after 40 of them the game is
    40 × ``ms`` ms on, within one step (it was capped at 6 steps a frame: 0.67 game s per
    wall s at 150 ms); every other frame skips its drawing, never two in a row."""
    game = _game()
    try:
        game.clock = FakeClock([ms])  # type: ignore[assignment]
        drawn = _count_draws(game)
        game.run(frames=41)  # the first frame has no elapsed time yet
        assert game.world.t == pytest.approx(40 * ms / 1000, abs=game.world.dt + 1e-9)
        assert drawn[0] == 21 and game.skipped_draws == 20
    finally:
        game.close()


def test_frames_at_sixty_a_second_draw_every_frame_at_one_step_each() -> None:
    game = _game()
    try:
        game.clock = FakeClock([17, 17, 16])  # 50 ms every 3 frames: 60 frames a second
        drawn = _count_draws(game)
        game.run(frames=61)
        assert game.world.step_index == 60 and drawn[0] == 61 and game.skipped_draws == 0
    finally:
        game.close()


def test_a_stall_longer_than_the_catch_up_limit_is_not_replayed() -> None:
    game = _game()
    try:
        game.clock = FakeClock([3000])  # the window dragged for 3 s
        game.run(frames=2)
        assert game.world.t == pytest.approx(MAX_CATCH_UP, abs=game.world.dt + 1e-9)
    finally:
        game.close()


def test_a_loop_of_short_runs_loses_no_time_between_them() -> None:
    """``run(10)`` four times is ``run(40)``: the wall time the last frame of one run measured
    goes to the next run's first frame (a benchmark's loop lost one frame in 30: 0.965)."""
    game = _game()
    try:
        game.clock = FakeClock([20])
        for _ in range(4):
            game.run(frames=10)
        assert game.world.t == pytest.approx(39 * 0.020, abs=game.world.dt + 1e-9)
    finally:
        game.close()
