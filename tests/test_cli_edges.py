"""The command line's newer edges (issue 35): seeds of any length, switches in ``--set``,
an empty table in ``--config``, ``sim --from`` on an older store and on a trial that ran
with a plugin stimulus. Each mistake is one ``stealth: error:`` line, exit 2."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import pytest

from headless.cli import main

ROOT = Path(__file__).resolve().parent.parent
PRESET = """levels = ["maze"]
abstractions = ["grid"]
guards = ["pf"]
players = ["maxmin"]
scenarios = ["capture"]
seeds = 1
{extra}
[set]
"world.duration" = 3.0
"""


def _one_line(capsys: pytest.CaptureFixture[str], *words: str) -> str:
    err = capsys.readouterr().err
    assert err.startswith("stealth: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err and all(w in err for w in words), err
    return err


@pytest.mark.parametrize("digits", [20, 280, 309, 400, 4300, 4301, 20_000])
def test_a_seed_of_any_length_is_one_line(digits: int, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "maze", "--seed", "7" * digits]) == 2
    err = _one_line(capsys, "--seed", "9223372036854775807")
    assert len(err) < 200  # the digits are not echoed


def test_a_whole_number_beyond_floats_is_out_of_range_not_an_overflow(
        capsys: pytest.CaptureFixture[str]) -> None:
    from ai.bounds import Range

    assert Range(0, 10, integer=True).problem(10**400) == "must be a whole number in [0, 10]"
    assert Range(0, integer=True).problem(10**400) is None  # [0, inf) holds it
    assert main(["sim", "maze", "--set", "world.duration=1", "--set",
                 "pf.kernel_radius=" + "7" * 400]) == 0  # in range; the kernel stops at the diameter
    capsys.readouterr()


@pytest.mark.parametrize("word", ["yes", "no", "1", "0", "TRUE", "False"])
def test_set_switches_take_the_words_its_message_names(word: str,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "maze", "--set", "world.duration=1", "--set", f"stimuli.raining={word}"]) == 0
    capsys.readouterr()
    assert main(["sim", "maze", "--set", "stimuli.raining=maybe"]) == 2
    _one_line(capsys, "expected true or false (or yes / no, 1 / 0), got 'maybe'")


@pytest.mark.parametrize("text", ["[metrics]\ncoverage = {}\n", "[world]\n", 'world = {}\n'])
def test_an_empty_table_in_a_config_file_is_refused(text: str, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "c.toml"
    config.write_text(text)
    assert main(["sim", "maze", "--config", str(config)]) == 2
    _one_line(capsys, "an empty table sets nothing")


def _run(tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str = "") -> tuple[Path, str]:
    preset = tmp_path / "p.toml"
    preset.write_text(PRESET.format(extra=extra))
    out = tmp_path / "out"
    assert main(["run", "--preset", str(preset), "--out", str(out), "--workers", "1"]) == 0
    capsys.readouterr()
    with sqlite3.connect(out / "results.sqlite") as db:
        return out, db.execute("SELECT key FROM trials").fetchone()[0]


def test_sim_from_compares_only_the_columns_an_older_store_has(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, key = _run(tmp_path, capsys)
    with sqlite3.connect(out / "results.sqlite") as db:  # the store of a version before them
        db.execute("ALTER TABLE trials DROP COLUMN dist_euclidean")
        db.execute("ALTER TABLE trials DROP COLUMN coverage_seen")
    assert main(["sim", "--from", str(out), "--trial", key]) == 0
    assert "metrics identical to the stored row" in capsys.readouterr().err
    with sqlite3.connect(out / "results.sqlite") as db:  # a real difference is still seen
        db.execute("UPDATE trials SET coverage = coverage + 0.5")
    assert main(["sim", "--from", str(out), "--trial", key]) == 1
    assert "differs from the stored row in coverage\n" in capsys.readouterr().err


def test_a_trial_with_a_plugin_stimulus_reruns_when_it_is_given_again(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    shutil.copy(ROOT / "examples" / "tripwire.py", tmp_path / "tripwire.py")
    out, key = _run(tmp_path, capsys, 'stimuli = ["tripwire.py:Tripwire"]')
    assert "stimuli=" in key
    assert main(["sim", "--from", str(out), "--trial", key]) == 2  # never run from the store
    _one_line(capsys, "it ran with the plugin stimuli", "--stimulus", "never runs code")
    monkeypatch.chdir(tmp_path)  # the same file, named relative to here
    assert main(["sim", "--from", "out", "--trial", key, "--stimulus", "tripwire.py:Tripwire"]) == 0
    assert "metrics identical to the stored row" in capsys.readouterr().err
    assert main(["sim", "--from", "out", "--trial", key, "--stimulus", "tripwire.py:Nope"]) == 2
    _one_line(capsys, "(given: tripwire.py:Nope)")
    assert main(["replay", "out", "--stimulus", "tripwire.py:Tripwire"]) == 2
    _one_line(capsys, "replay --stimulus: only with --trial")


def test_a_plugin_given_for_a_trial_without_one_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, key = _run(tmp_path, capsys)
    plugin = str(ROOT / "examples" / "tripwire.py") + ":Tripwire"
    assert main(["sim", "--from", str(out), "--trial", key, "--stimulus", plugin]) == 2
    _one_line(capsys, "it ran without plugin stimuli; drop --stimulus")


def test_a_plugin_path_that_is_not_a_file_says_so(tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    import os

    os.mkfifo(tmp_path / "pipe.py")
    assert main(["sim", "maze", "--stimulus", f"{tmp_path}/pipe.py:X"]) == 2
    _one_line(capsys, "not a regular file")
