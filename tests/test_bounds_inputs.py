"""Issue 24 class 5: other inputs end in one line.

``--config`` naming a FIFO or a 3 MB file, a key given twice in a ``--config`` or a preset,
a plugin calling ``sys.exit(3)`` at import or whose ``done`` raises, ``mechanics`` with 10^9
seeds, a 280-digit ``--seed`` and Ctrl-C during start-up: one ``stealth: error:`` line (or
``stealth: interrupted``, exit 130), never a traceback or a silent exit.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from headless.cli import main

ROOT = Path(__file__).resolve().parent.parent
BASE = ('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["random"]\nplayers = ["maxmin"]\n'
        'scenarios = ["fixed"]\nseeds = 1\n')


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("stealth: error: "), err
    return err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX FIFOs")
def test_a_config_fifo_is_refused_without_blocking(tmp_path: Path, capsys) -> None:
    os.mkfifo(tmp_path / "fifo")
    started = time.monotonic()
    assert main(["sim", "maze", "--config", str(tmp_path / "fifo")]) == 2
    assert "FIFO" in _one_line(capsys) and time.monotonic() - started < 10


def test_a_huge_config_is_refused_unread(tmp_path: Path, capsys) -> None:
    (tmp_path / "big.toml").write_bytes(b"#" * 3_000_000)
    assert main(["sim", "maze", "--config", str(tmp_path / "big.toml")]) == 2
    assert "larger than the limit" in _one_line(capsys)


@pytest.mark.parametrize(("where", "text"), [
    ("config", '"world.view_range" = 6\n[world]\nview_range = 5\n'),
    ("preset", BASE + '[set]\n"world.view_range" = 6\n[set.world]\nview_range = 5\n'),
    ("preset", BASE + '[factors]\n"pf.rho" = [0.9]\n[factors.pf]\nrho = [0.8]\n'),
    ("preset", BASE + '[set]\n"pf.rho" = 0.9\n[factors.pf]\nrho = [0.8, 0.85]\n'),
])
def test_a_key_given_twice_is_refused(tmp_path: Path, capsys, where: str, text: str) -> None:
    path = tmp_path / "x.toml"
    path.write_text(text)
    argv = (["sim", "maze", "--config", str(path)] if where == "config"
            else ["run", "--preset", str(path), "--out", str(tmp_path / "out"), "--workers", "1"])
    assert main(argv) == 2
    line = _one_line(capsys)
    assert "given twice" in line or "is also in [set]" in line
    assert not (tmp_path / "out").exists()


def test_plugins_that_exit_or_raise_in_done_are_one_line(tmp_path: Path, capsys) -> None:
    (tmp_path / "ex.py").write_text("import sys\nsys.exit(3)\n")
    (tmp_path / "dn.py").write_text(
        "from ai.stimuli import Stimulus\n"
        "class D(Stimulus):\n    name = 'd'\n    @property\n    def done(self):\n"
        "        raise RuntimeError('boom')\n"
        "class M(Stimulus):\n    name = 'm'\n    def done(self):\n        return False\n")
    for spec, words in ((f"{tmp_path / 'ex.py'}:X", "called sys.exit(3)"),
                        (f"{tmp_path / 'dn.py'}:D", "done raised RuntimeError: boom"),
                        (f"{tmp_path / 'dn.py'}:M", "done must be a bool, got method")):
        assert main(["sim", "maze", "--set", "world.duration=1", "--stimulus", spec]) == 2
        assert words in _one_line(capsys)


def test_mechanics_seeds_and_a_long_seed(capsys) -> None:
    assert main(["mechanics", "--seeds", str(10**9)]) == 2
    assert "at most 10000" in _one_line(capsys)
    assert main(["sim", "maze", "--seed", "7" * 280]) == 2
    line = _one_line(capsys)
    assert "280 digits" in line and len(line) < 200


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_during_start_up_is_one_line() -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    warm = subprocess.run([sys.executable, "-c", "import site"], env=env)  # Python's own start
    assert warm.returncode == 0
    for delay in (0.35, 0.6, 1.0):  # a 3,600-s trial on maze takes ~6 s on a quiet machine
        process = subprocess.Popen([sys.executable, "-m", "headless.cli", "sim", "maze",
                                    "--set", "world.duration=3600"], env=env, cwd=ROOT,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(delay)
        process.send_signal(signal.SIGINT)
        err = process.communicate(timeout=30)[1]
        assert "Traceback" not in err, err
        assert err.strip().splitlines()[-1:] == ["stealth: interrupted"], (delay, err)


@pytest.mark.parametrize(("grid", "zones", "words"), [
    (["###", "#.#", "###"], {"dark": [[[1, 1], [2, 1], [2, 2], [1, 2]]],
                             "concealment": [[[1, 1], [2, 1], [2, 2], [1, 2]]]}, "walkable cells"),
    (None, {"dark": [[[7, 7], [12, 7], [12, 12], [7, 12]]]}, "need a concealment zone"),
    (None, {}, "need a dark and a concealment zone"),
])
def test_mechanics_on_a_level_it_cannot_measure(tmp_path: Path, capsys, grid, zones,
                                                words: str) -> None:
    import json

    data = json.loads((ROOT / "assets" / "levels" / "maze.json").read_text())
    data["zones"] = zones
    if grid is not None:
        data.update(grid=grid, guards=[[1.5, 1.5]], decoys=[])
    (tmp_path / "level.json").write_text(json.dumps(data))
    started = time.monotonic()
    assert main(["mechanics", "--level", str(tmp_path / "level.json"), "--seeds", "2",
                 "--workers", "1", "--out", str(tmp_path / "out")]) == 2
    assert words in _one_line(capsys) and time.monotonic() - started < 30
    assert not (tmp_path / "out").exists()
