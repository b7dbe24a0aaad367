"""Issue 24 class 3: the tuner's expressions and study files end in one line.

Arithmetic is in floats with bounded text and depth (no 370-million-digit integer, no
MemoryError from deep nesting), arithmetic failures are one-line errors (constant parts at
parse time), and a garbage ``study.db``, a full disk and a second ``tune`` on one directory
are refused in one line without a SQLAlchemy traceback.
"""

from __future__ import annotations

import errno
import time
from pathlib import Path

import pytest

from headless.cli import main
from headless.outputs.dirlock import DirectoryLock
from headless.errors import UserError
from headless.tune.expr import ExpressionError, parse_constraint, parse_expression

pytest.importorskip("optuna")

SPEC = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds_train = 1
seeds_test = 0
sampler_seed = 3

[set]
"world.duration" = 1.0

[search]
"world.guard_speed" = {low = 1.5, high = 3.0}

[objective]
maximize = "OBJECTIVE"
"""


def _lookup(name: str, selectors: tuple[str, ...]) -> float:
    return {"captures": 3.0, "backtracks": 0.0}.get(name, 1.0)


def _one_error_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert lines and lines[-1].startswith("stealth: error: "), stderr
    assert "Traceback" not in stderr, stderr
    return lines[-1]


@pytest.mark.parametrize(("text", "words"), [
    ("captures + 9**9**9", "overflow"),
    ("captures + 10**400", "too large"),
    ("captures + 1/0", "division by zero"),
    ("captures * (-8) ** 0.5", "complex"),
    ("max(captures)", "takes 2 to 64 arguments, got 1"),
    ("max(" + ", ".join(["captures"] * 65) + ")", "got 65"),
    ("abs()", "a call without arguments"),
    ("(" * 250 + "captures" + ")" * 250, "not an expression"),
    ("abs(captures, backtracks)", "takes 1 argument, got 2"),
    ("-" * 200_000 + "captures", "longer than"),
    ("-" * 9_000 + "captures", "nested more than"),
    ("-" * 500 + "captures", "nested more than"),
])
def test_a_hostile_expression_is_refused_when_parsed(text: str, words: str) -> None:
    started = time.monotonic()
    with pytest.raises(UserError, match=words) as caught:
        parse_expression(text)
    assert time.monotonic() - started < 5
    assert "\n" not in str(caught.value) and len(str(caught.value)) < 400


@pytest.mark.parametrize(("text", "words"), [
    ("captures / backtracks", "division by zero"),
    ("(-captures) ** 0.5", "complex"),
    ("captures * 1e308 * 10", "overflow"),
    ("captures ** 1e6", "overflow"),
    ("backtracks ** -1", "division by zero"),
])
def test_arithmetic_on_metric_values_fails_in_one_line(text: str, words: str) -> None:
    with pytest.raises(ExpressionError, match=words):
        parse_expression(text).evaluate(_lookup)


def test_ordinary_expressions_keep_their_values() -> None:
    assert parse_expression("captures - 0.05*backtracks").evaluate(_lookup) == 3.0
    assert parse_expression("max(captures, 2) ** 2 + abs(-backtracks)").evaluate(_lookup) == 9.0
    assert parse_expression("-" * 50 + "captures").evaluate(_lookup) == 3.0
    assert parse_constraint("captures ** 2 >= 4").evaluate(_lookup) == -5.0


def _spec(tmp_path: Path, objective: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.replace("OBJECTIVE", objective))
    return path


def _tune(spec: Path, out: Path, trials: int = 1) -> int:
    return main(["tune", str(spec), "--out", str(out), "--trials", str(trials), "--workers", "1"])


def test_a_constant_overflow_is_refused_before_any_trial(tmp_path: Path, capsys) -> None:
    assert _tune(_spec(tmp_path, "captures + 9**9**9"), tmp_path / "out") == 2
    assert "overflow" in _one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "out" / "study.db").exists()


def test_an_objective_that_always_fails_stops_the_study(tmp_path: Path, capsys) -> None:
    # backtracks of a 1 s trial of random guards are 0: the division fails every trial
    assert _tune(_spec(tmp_path, "captures / (backtracks * 0)"), tmp_path / "out", 2) == 2
    err = capsys.readouterr().err
    assert "in a row gave no objective value" in _one_error_line(err)
    assert "division by zero" in err


def test_a_garbage_study_db_is_refused(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "study.db").write_bytes(b"\x00garbage" * 100)
    assert _tune(_spec(tmp_path, "captures"), out) == 2
    assert "not an Optuna study" in _one_error_line(capsys.readouterr().err)
    assert (out / "study.db").read_bytes() == b"\x00garbage" * 100


def test_a_second_tune_on_one_directory_is_refused(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    out.mkdir()
    with DirectoryLock(out, "study"):  # what a running `stealth tune` holds
        assert _tune(_spec(tmp_path, "captures"), out) == 2
    assert "another study is writing" in _one_error_line(capsys.readouterr().err)
    assert not (out / "study.db").exists()


def test_a_full_disk_under_optuna_is_one_line(tmp_path: Path, capsys, monkeypatch) -> None:
    import sqlite3.dbapi2 as dbapi  # what SQLAlchemy's pysqlite dialect connects through

    real = dbapi.connect

    def full(*args, **kwargs):  # every connection SQLAlchemy opens fails as a full disk does
        if "study.db" in str(args[0] if args else kwargs.get("database")):
            raise dbapi.OperationalError("database or disk is full")
        return real(*args, **kwargs)

    monkeypatch.setattr(dbapi, "connect", full)
    assert _tune(_spec(tmp_path, "captures"), tmp_path / "out") == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "study.db" in line and "disk is full" in line


def test_a_full_disk_writing_the_outputs_is_one_line(tmp_path: Path, capsys, monkeypatch) -> None:
    import headless.tune.report as tune_report

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", "best.toml")

    monkeypatch.setattr(tune_report, "write_study_outputs", full)
    assert _tune(_spec(tmp_path, "captures"), tmp_path / "out") == 2
    assert "No space left on device (ENOSPC)" in _one_error_line(capsys.readouterr().err)
