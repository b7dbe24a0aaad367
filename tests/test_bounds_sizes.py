"""Issue 11 class 5: special files and absurd sizes are refused with one line, at once.

A level (or preset, or trace) is read only from a regular file of bounded size; a design,
a worker count and a level's spawn lists are bounded before anything is allocated or started.
"""

from __future__ import annotations

import concurrent.futures as cf
import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from headless.cli import main
from headless.errors import PresetError
from headless.presets import load_preset
from navmesh.errors import LevelError
from navmesh.level import load_level, parse_level

ROOT = Path(__file__).resolve().parent.parent
MAZE = ROOT / "assets" / "levels" / "maze.json"

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX special files")


def _limited(memory: int = 1536 * 2**20) -> None:
    """preexec_fn: a child that tries to exhaust memory fails fast instead of the machine."""
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))


def _stealth(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    path = os.environ.get("PYTHONPATH", "")
    env = {**os.environ, "PYTHONPATH": str(ROOT) + (os.pathsep + path if path else "")}
    return subprocess.run([sys.executable, "-m", "headless.cli", *args], env=env,
                          capture_output=True, text=True, timeout=timeout,
                          preexec_fn=_limited)


def _one_error_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), stderr
    assert "Traceback" not in stderr
    return lines[0]


def test_a_fifo_as_a_level_is_refused_without_waiting_for_a_writer(tmp_path: Path) -> None:
    fifo = tmp_path / "level.json"
    os.mkfifo(fifo)
    try:
        done = _stealth("validate", str(fifo), timeout=20)
    except subprocess.TimeoutExpired:
        pytest.fail("validate waited on the FIFO")
    assert done.returncode == 2
    assert "FIFO" in _one_error_line(done.stderr) and str(fifo) in done.stderr


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null"])
def test_a_device_as_a_level_is_refused(device: str) -> None:
    if not Path(device).exists():
        pytest.skip(f"no {device}")
    try:
        done = _stealth("validate", device, timeout=20)
    except subprocess.TimeoutExpired:
        pytest.fail(f"validate kept reading {device}")
    assert done.returncode == 2
    assert "character device" in _one_error_line(done.stderr)


def test_a_level_file_over_the_size_limit_is_refused_unread(tmp_path: Path) -> None:
    big = tmp_path / "big.json"
    with big.open("wb") as handle:  # sparse: 65 MiB that take no disk
        handle.truncate(65 * 2**20)
    with pytest.raises(LevelError, match="larger than the limit of 64 MiB"):
        load_level(big)


def test_a_preset_or_trace_that_is_a_fifo_is_refused(tmp_path: Path) -> None:
    fifo = tmp_path / "preset.toml"
    os.mkfifo(fifo)
    commands = [("run", "--preset", str(fifo), "--out", str(tmp_path / "out")),
                ("replay", str(fifo), "--level", "maze", "--frames", "1")]
    for command in commands:
        try:
            done = _stealth(*command, timeout=20)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{command[0]} waited on the FIFO")
        assert done.returncode == 2 and "FIFO" in _one_error_line(done.stderr), command
    assert not (tmp_path / "out").exists()


def test_a_hundred_million_seeds_are_refused_before_any_allocation(tmp_path: Path) -> None:
    preset = tmp_path / "huge.toml"
    preset.write_text('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["pf"]\n'
                      'players = ["maxmin"]\nscenarios = ["fixed"]\nseeds = 100000000\n')
    done = _stealth("run", "--preset", str(preset), "--out", str(tmp_path / "out"))
    assert done.returncode == 2
    assert "limit" in _one_error_line(done.stderr) and "seeds" in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_design_with_too_many_trials_is_refused(tmp_path: Path) -> None:
    preset = tmp_path / "wide.toml"
    preset.write_text('levels = ["maze", "miami"]\nabstractions = ["grid", "partition"]\n'
                      'guards = ["pf", "cheat", "random"]\nplayers = ["maxmin"]\n'
                      'scenarios = ["capture", "fixed"]\nseeds = 200000\n')
    with pytest.raises(PresetError, match="4800000 trials, more than the limit"):
        load_preset(str(preset))


def test_a_thousand_workers_are_refused_before_a_pool_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    def no_pool(*args: object, **kwargs: object) -> None:
        raise AssertionError("a process pool was started")

    monkeypatch.setattr(cf, "ProcessPoolExecutor", no_pool)
    preset = tmp_path / "tiny.toml"
    preset.write_text('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["random"]\n'
                      'players = ["maxmin"]\nscenarios = ["fixed"]\nseeds = 1\n'
                      '[set]\n"world.duration" = 2.0\n')
    for command in (["run", "--preset", str(preset), "--out", str(tmp_path / "out")],
                    ["mechanics", "--seeds", "2", "--level", "maze", "--out",
                     str(tmp_path / "mech")]):
        assert main([*command, "--workers", "1000"]) == 2
        assert "--workers" in _one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "out").exists() and not (tmp_path / "mech").exists()


@pytest.mark.parametrize("field", ["guards", "decoys", "collectibles"])
def test_a_level_with_too_many_spawn_points_is_refused(field: str) -> None:
    data = json.loads(MAZE.read_text())
    data[field] = [data["guards"][0]] * 1001
    with pytest.raises(LevelError, match=f"{field}: 1001 points, more than the limit of 1000"):
        parse_level(data, "many.json")
