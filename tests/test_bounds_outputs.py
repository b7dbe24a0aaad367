"""Issue 24 class 1: nothing lost — an output is never an input of its command, nor a store.

Every command that writes a file refuses, in one line and before anything is opened, an
output that is one of its inputs (the store ``sim --from`` reads, the level, ``--config``, a
plugin, a preset or tune spec) or an existing SQLite store; every input stays intact.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

from headless.presets import load_preset
from headless.store import ResultStore
from headless.sweep import run_sweep

ROOT = Path(__file__).resolve().parent.parent
PRESET = """
levels = ["level.json"]
abstractions = ["grid"]
guards = ["random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds = 1

[set]
"world.duration" = 1.0
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("outputs")
    (base / "level.json").write_bytes((ROOT / "assets" / "levels" / "maze.json").read_bytes())
    (base / "p.toml").write_text(PRESET)
    (base / "c.toml").write_text('"world.duration" = 1.0\n')
    (base / "plug.py").write_text("from ai.stimuli import Stimulus\nclass P(Stimulus):\n"
                                  "    name = 'p'\n")
    (base / "tune.toml").write_text(PRESET.replace("seeds = 1", "seeds_train = 1\nseeds_test = 0")
                                    + '[search]\n"world.guard_speed" = {low = 1.5, high = 3.0}\n'
                                      '[objective]\nmaximize = "captures"\n')
    run_sweep(load_preset(str(base / "p.toml")), base / "store", workers=1, progress=False)
    (base / "hard.link").hardlink_to(base / "level.json")
    return base


def _key(folder: Path) -> str:
    with ResultStore(folder / "store" / "results.sqlite", readonly=True) as store:
        return next(iter(store.trials()))["key"]


def _digests(folder: Path) -> dict[str, str]:
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.rglob("*"))
            if p.is_file() and "results.sqlite-" not in p.name and p.name != "results.lock"}


CASES = [
    ("sim --from store --trial KEY --trace store/results.sqlite", "is an input"),
    ("sim maze --trace store/results.sqlite", "is a results store"),
    ("sim level.json --trace hard.link", "is an input"),
    ("sim maze --config c.toml --trace c.toml", "is an input"),
    ("sim maze --stimulus plug.py:P --trace plug.py", "is an input"),
    ("play level.json --frames 1 --screenshot level.json", "is an input"),
    ("play maze --frames 1 --screenshot store/results.sqlite", "is a results store"),
    ("replay store --trial KEY --screenshot store/results.sqlite", "is an input"),
    ("mechanics --level level.json --seeds 2 --out store", "is a results store"),
    ("tune tune.toml --out . --workers 1 --trials 1", "is an input"),
]


@pytest.mark.parametrize(("command", "words"), CASES)
def test_an_output_onto_an_input_or_a_store_is_refused(folder: Path, command: str,
                                                       words: str) -> None:
    if command.startswith("mechanics"):  # its outputs are fixed names: make one a store
        (folder / "store" / "mechanics.csv").write_bytes(
            (folder / "store" / "results.sqlite").read_bytes()[:4096])
    if command.startswith("tune"):  # tune's --out holds best.toml: make that the spec
        (folder / "best.toml").unlink(missing_ok=True)
        (folder / "best.toml").hardlink_to(folder / "tune.toml")
    before = _digests(folder)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg",
           "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    done = subprocess.run([sys.executable, "-m", "headless.cli",
                           *command.replace("KEY", _key(folder)).split()],
                          capture_output=True, text=True, timeout=60, env=env, cwd=folder)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: ") and words in lines[0], \
        done.stderr
    assert _digests(folder) == before  # every input and store intact


def test_an_analysis_figure_onto_its_store_is_refused(folder: Path) -> None:
    before = _digests(folder)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    for module, args in (("held_out", ["store", "--figure", "store/results.sqlite"]),
                         ("robustness", ["store", "--write", "store/results.sqlite"])):
        done = subprocess.run([sys.executable, "-m", f"headless.{module}", *args],
                              capture_output=True, text=True, timeout=60, env=env, cwd=folder)
        assert done.returncode == 2 and "writing it would destroy it" in done.stderr, done.stderr
    assert _digests(folder) == before
