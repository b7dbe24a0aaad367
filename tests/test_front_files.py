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
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

from game.front.best import BestResults, better, describe  # noqa: E402
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


GOOD_FILE = {"maze": {"pf": {"outcome": "won", "time": 3, "stars": 1}, "random": WON}}
ODD_VALUES = [{"x": 1}, {}, [], [1, {"a": [None]}], [[[]]], {"outcome": {"x": 1}},
              {"a": {"b": {"c": [1, 2, {"d": "won"}]}}}, None, True, "won", 1.5]


def _places(value: object, path: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """Every path to a value inside a nest of objects (the file itself is ``()``)."""
    here = [path]
    if isinstance(value, dict):
        for key, inner in value.items():
            here += _places(inner, path + (key,))
    return here


def _put(value: object, path: tuple[str, ...], odd: object) -> object:
    """``value`` with ``odd`` at ``path`` (a copy)."""
    if not path:
        return odd
    assert isinstance(value, dict)
    return {**value, path[0]: _put(value[path[0]], path[1:], odd)}


def _check_play_goes_on(path: Path, text: str, err: str, best: BestResults) -> None:
    """One warning at most; if one, the file is set aside whole; what is kept reads as the
    chooser and the end screen read it; a new best is saved."""
    assert "Traceback" not in err and err.count("\n") <= 1
    if err:
        assert "set aside as best.json.corrupt" in err and best.results == {}
        assert (path.parent / "best.json.corrupt").read_text() == text
    for level, modes in best.results.items():
        for mode in modes:
            assert describe(best.best(level, mode)).startswith("best: ")
            better(WON, best.best(level, mode))
    assert best.offer("maze", "greedy", WON)
    assert json.loads(path.read_text())["maze"]["greedy"] == WON


SHAPES = [(place, odd) for place in _places(GOOD_FILE) for odd in ODD_VALUES]
SHAPES += [(place, {"deep": [[{"x": [1]}]] * 3}) for place in _places(GOOD_FILE)]


@pytest.mark.parametrize("place, odd", SHAPES, ids=[f"{'/'.join(p) or 'file'}={json.dumps(o)[:20]}"
                                                    for p, o in SHAPES])
def test_any_json_value_anywhere_in_the_best_file_leaves_play_working(
        place: tuple[str, ...], odd: object, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 42: an object or a list where a word or a number belongs (``{"maze": {"pf":
    {"outcome": {"x": 1}, "time": 3}}}``) raised a TypeError out of the shape check."""
    path = tmp_path / "best.json"
    text = json.dumps(_put(GOOD_FILE, place, odd))
    path.write_text(text)
    best = BestResults(path)
    _check_play_goes_on(path, text, capsys.readouterr().err, best)


_JSON = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
                     | st.text(max_size=5) | st.sampled_from(["won", "caught", "maze", "pf"]),
                     lambda inner: st.lists(inner, max_size=3)
                     | st.dictionaries(st.sampled_from(["maze", "pf", "outcome", "time",
                                                         "stars", "x"]), inner, max_size=4),
                     max_leaves=12)


@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(_JSON)
def test_a_generated_best_file_of_any_shape_leaves_play_working(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], loaded: object) -> None:
    path = tmp_path / "best.json"
    for old in tmp_path.iterdir():
        old.unlink()
    capsys.readouterr()
    text = json.dumps(loaded)
    path.write_text(text)
    best = BestResults(path)
    _check_play_goes_on(path, text, capsys.readouterr().err, best)


@pytest.mark.parametrize("odd", [{"x": 1}, [1, [2]], {"a": {"b": []}}])
def test_the_chooser_draws_over_an_odd_outcome(odd: object, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "best.json").write_text(json.dumps({"maze": {"pf": {"outcome": odd, "time": 3}}}))
    pygame.display.init()
    chooser = LevelChooser(pygame.display.set_mode((800, 700)), ["maze"],
                           best=BestResults(tmp_path / "best.json"))
    assert chooser.run(frames=2) is None
    assert capsys.readouterr().err.count("set aside") == 1


def test_play_and_its_chooser_start_with_the_issues_best_file(tmp_path: Path) -> None:
    """The file of issue 42, through ``stealth play`` (the chooser, 30 frames) and then a
    level (the end screen reads the best result too)."""
    issue = '{"maze": {"pf": {"outcome": {"x": 1}, "time": 3}}}'
    (tmp_path / "best.json").write_text(issue)
    done = _stealth("play", "--frames", "30", data=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and done.stderr.count("set aside") == 1
    assert (tmp_path / "best.json.corrupt").read_text() == issue
    (tmp_path / "best.json").write_text(issue.replace("outcome", "stars"))
    done = _stealth("play", "maze", "--frames", "5", data=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and done.stderr.count("set aside") == 1


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
