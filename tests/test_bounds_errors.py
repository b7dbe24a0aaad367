"""Issue 11 class 7: every OSError and every plugin error is one ``stealth: error:`` line.

The CLI's top-level handler maps an OSError to ``FILE: what happened (ERRNO)``; the stimulus
set calls plugin code through :mod:`ai.plugin_call`, which names the plugin and the method
and checks what it returns; ``--debug`` adds the traceback.
"""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from headless.cli import main
from headless.sweep import run_sweep
from headless.presets import load_preset

ROOT = Path(__file__).resolve().parent.parent
MAZE = ROOT / "assets" / "levels" / "maze.json"

PLUGINS = """
import numpy as np
from ai.stimuli import Stimulus

class Raises(Stimulus):
    name = "raises"
    def inject(self, ctx):
        raise RuntimeError("kaboom")

class Nan(Stimulus):
    name = "nan"
    def inject(self, ctx):
        return np.full(ctx.n, np.nan)

class Shape(Stimulus):
    name = "shape"
    def inject(self, ctx):
        return np.zeros(3)

class TickRaises(Stimulus):
    name = "tick"
    def on_tick(self, view, dt):
        raise KeyError("x")

class BadFloor(Stimulus):
    name = "floor"
    information_weight_floor = float("nan")
"""


def _env(**extra: str) -> dict[str, str]:
    path = os.environ.get("PYTHONPATH", "")
    return {**os.environ, "PYTHONPATH": str(ROOT) + (os.pathsep + path if path else ""),
            **extra}


def _one_error_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), stderr
    return lines[0]


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
def test_a_full_disk_under_the_trace_is_one_line_naming_the_file(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["sim", "maze", "--set", "world.duration=2", "--trace", "/dev/full"]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "/dev/full" in line and "ENOSPC" in line


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("store")
    preset = folder / "tiny.toml"
    preset.write_text('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["random"]\n'
                      'players = ["maxmin"]\nscenarios = ["fixed"]\nseeds = 1\n'
                      '[set]\n"world.duration" = 2.0\n')
    out = folder / "out"
    run_sweep(load_preset(str(preset)), out, workers=1, progress=False)
    return out


def test_a_directory_where_the_report_writes_a_file_is_one_line(
    results: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    (results / "table.md").mkdir(exist_ok=True)
    try:
        assert main(["report", str(results)]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert "table.md" in line and "is a directory; it names a file" in line
    finally:
        (results / "table.md").rmdir()


def test_a_read_only_results_directory_is_one_line(
    results: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    # root ignores permission bits, so the read-only file system is what the kernel would say
    real_open = Path.open

    def read_only(self: Path, mode: str = "r", *args: object, **kwargs: object):  # type: ignore[no-untyped-def]
        if any(c in mode for c in "wax+") and results in self.parents:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))
        return real_open(self, mode, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Path, "open", read_only)
    assert main(["report", str(results)]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert str(results) in line and "EROFS" in line


def test_mechanics_into_a_directory_it_cannot_create_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["mechanics", "--seeds", "2", "--workers", "1", "--level", "maze",
                 "--out", str(blocker / "out")]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert "ENOTDIR" in line or "EEXIST" in line


@pytest.mark.parametrize("reader", ["true", "head -c 10"])
def test_a_closed_pipe_is_one_line_and_no_exception_at_exit(reader: str) -> None:
    # ``true`` closes the pipe before the first write; ``head`` after 10 bytes of an output
    # far larger than the pipe's buffer
    levels = " ".join(["maze"] * (1 if reader == "true" else 600))
    done = subprocess.run(f"{sys.executable} -m headless.cli levels --json {levels} | {reader}",
                          shell=True, env=_env(), capture_output=True, text=True, timeout=120)
    assert len(done.stdout) == (0 if reader == "true" else 10)
    assert "EPIPE" in _one_error_line(done.stderr)
    assert "Exception ignored" not in done.stderr


def test_non_ascii_names_under_an_ascii_locale(tmp_path: Path) -> None:
    folder = tmp_path / "é"
    folder.mkdir()
    level = folder / "lévél.json"
    data = json.loads(MAZE.read_text())
    data["name"] = "Lévél"
    level.write_text(json.dumps(data), encoding="utf-8")
    ascii_env = _env(LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0",
                     PYTHONIOENCODING="")
    for command in (["levels", str(level)], ["validate", str(level)],
                    ["validate", str(folder / "nope.json")]):
        done = subprocess.run([sys.executable, "-m", "headless.cli", *command], env=ascii_env,
                              capture_output=True, timeout=120)
        err = done.stderr.decode("ascii", "replace")
        assert "Traceback" not in err, (command, err)
        assert done.returncode == (2 if "nope.json" in command[-1] else 0), (command, err)
    assert b"L\\xe9v\\xe9l" in subprocess.run(
        [sys.executable, "-m", "headless.cli", "levels", str(level)], env=ascii_env,
        capture_output=True, timeout=120).stdout


@pytest.fixture()
def plugins(tmp_path: Path) -> Path:
    path = tmp_path / "plugins.py"
    path.write_text(PLUGINS)
    return path


@pytest.mark.parametrize(("name", "method", "says"), [
    ("Raises", "inject()", "RuntimeError: kaboom"),
    ("Nan", "inject()", "NaN"),
    ("Shape", "inject()", "shape"),
    ("TickRaises", "on_tick()", "KeyError"),
    ("BadFloor", "information_weight_floor", "[0, 1]"),
])
def test_a_broken_stimulus_plugin_is_one_line_naming_it_and_the_method(
    plugins: Path, name: str, method: str, says: str, capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["sim", "maze", "--guards", "pf", "--set", "world.duration=3",
            "--stimulus", f"{plugins}:{name}"]
    assert main(argv) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert f"({name} in {plugins})" in line and method in line and says in line


def test_debug_shows_the_traceback_then_the_one_line(
    plugins: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["sim", "maze", "--guards", "pf", "--set", "world.duration=3",
            "--stimulus", f"{plugins}:Raises"]
    assert main([*argv, "--debug"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("Traceback") and any("kaboom" in e for e in err[:-1])
    assert err[-1].startswith("stealth: error: stimulus 'raises'")
    assert main(["--debug", "sim", "maze", "--frob"]) == 2  # argparse: the same one-line form
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "stealth: error: unrecognized arguments: --frob"
