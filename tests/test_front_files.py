"""``stealth play``'s own files and options at their edges (issue 35): a best-results file
of another shape is set aside and play goes on; ``--frames`` ends the chooser too; a
refused ``--record`` game creates nothing; ``--questions`` needs ``--record``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.front.best import BestResults  # noqa: E402
from game.front.chooser import LevelChooser  # noqa: E402
from game.front.render import pygame  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
WON = {"outcome": "won", "time": 5.0, "stars": 1}
DEEP = "[" * 100_000 + "]" * 100_000  # under the 1-MiB limit, beyond Python's recursion

CORRUPT = {
    "array of modes": '{"maze": [1, 2]}',
    "time not a number": '{"maze": {"pf": {"outcome": "won", "time": "abc"}}}',
    "time NaN": '{"maze": {"pf": {"outcome": "won", "time": NaN}}}',
    "time of 400 digits": '{"maze": {"pf": {"outcome": "won", "time": ' + "9" * 400 + "}}}",
    "time negative": '{"maze": {"pf": {"outcome": "won", "time": -3}}}',
    "null": "null",
    "result not an object": '{"maze": {"pf": 3}}',
    "no outcome": '{"maze": {"pf": {"time": 3}}}',
    "outcome with a NUL": '{"maze": {"pf": {"outcome": "\\u0000", "time": 3}}}',
    "negative stars": '{"maze": {"pf": {"outcome": "won", "time": 3, "stars": -1}}}',
    "deep": DEEP,
    "not JSON": "{not json",
    "not UTF-8": b"\xff\xfe{}",
}


def _stealth(*args: str, data: Path, timeout: float = 30) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "STEALTHFIELD_DATA": str(data),
           "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    return subprocess.run([sys.executable, "-m", "headless.cli", *args], env=env, text=True,
                          capture_output=True, timeout=timeout)


@pytest.mark.parametrize("text", CORRUPT.values(), ids=CORRUPT.keys())
def test_a_best_file_of_another_shape_is_set_aside(text: str | bytes, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "best.json"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    best = BestResults(path)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "set aside as best.json.corrupt" in err
    assert best.results == {} and best.best("maze", "pf") is None
    assert (tmp_path / "best.json.corrupt").read_bytes() == (
        text if isinstance(text, bytes) else text.encode())
    assert best.offer("maze", "pf", WON)  # play goes on, and keeps the new best
    assert json.loads(path.read_text()) == {"maze": {"pf": WON}}


def test_an_older_corrupt_file_is_kept(tmp_path: Path) -> None:
    (tmp_path / "best.json.corrupt").write_text("first")
    (tmp_path / "best.json").write_text("null")
    BestResults(tmp_path / "best.json")
    assert (tmp_path / "best.json.corrupt").read_text() == "first"
    assert (tmp_path / "best.json.corrupt-2").read_text() == "null"


def test_the_chooser_draws_from_a_set_aside_file(tmp_path: Path) -> None:
    (tmp_path / "best.json").write_text('{"maze": {"pf": {"outcome": "won", "time": "abc"}}}')
    pygame.display.init()
    chooser = LevelChooser(pygame.display.set_mode((800, 700)), ["maze"],
                           best=BestResults(tmp_path / "best.json"))
    assert chooser.run(frames=2) is None  # drew its cards: "not played yet"


def test_play_starts_with_a_deeply_nested_best_file_and_the_chooser_stops(tmp_path: Path) -> None:
    """``stealth play --frames 30`` without a level: the chooser gives up after 30 frames
    (it waited for a key for ever), saves its frame for ``--screenshot``, and the deep best
    file is set aside on the way."""
    (tmp_path / "best.json").write_text(DEEP)
    shot = tmp_path / "chooser.png"
    done = _stealth("play", "--frames", "30", "--screenshot", str(shot), data=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "set aside" in done.stderr
    assert (tmp_path / "best.json.corrupt").exists() and shot.stat().st_size > 1000


def test_a_refused_recorded_game_creates_nothing(tmp_path: Path) -> None:
    out = tmp_path / "rec"
    done = _stealth("play", "maze", "--frames", "3", "--record", str(out),
                    "--set", "bad.key=1", data=tmp_path)
    assert done.returncode == 2 and done.stderr.startswith("stealth: error: ")
    assert done.stderr.count("\n") == 1 and not out.exists()
    blocked = tmp_path / "file"
    blocked.write_text("x")
    done = _stealth("play", "maze", "--frames", "3", "--record", str(blocked / "rec"), data=tmp_path)
    assert done.returncode == 2 and "cannot create the folder" in done.stderr


def test_questions_need_record(tmp_path: Path) -> None:
    done = _stealth("play", "maze", "--frames", "3", "--questions", data=tmp_path)
    assert done.returncode == 2
    assert done.stderr == ("stealth: error: --questions: the ratings are stored with the "
                           "session: give --record DIR too\n")


@pytest.mark.parametrize("spoil", ["sessions file", "store junk", "store fifo"])
def test_a_record_folder_that_would_lose_the_session_is_refused_first(spoil: str,
                                                                       tmp_path: Path) -> None:
    """Refused before the game (3 frames: no session), not after it is played."""
    out = tmp_path / "rec"
    out.mkdir()
    if spoil == "sessions file":
        (out / "sessions").write_text("")
    elif spoil == "store junk":
        (out / "results.sqlite").write_text("junk")
    else:
        os.mkfifo(out / "results.sqlite")
    done = _stealth("play", "maze", "--frames", "3", "--record", str(out), data=tmp_path)
    assert done.returncode == 2 and done.stderr.startswith(f"stealth: error: --record {out}: ")
    assert done.stderr.count("\n") == 1
