"""Issue 24 class 4: the analyses' entry points go through the CLI's error handling.

``python -m headless.held_out`` / ``robustness`` / ``paired`` / ``beside_paper`` on a file
that is not a store, an empty store, a store with no trials table or without a report end in
one ``stealth: error:`` line and exit 2 (:func:`headless.commands.failure.guarded`), never a
sqlite3 / FileNotFoundError / ZeroDivisionError traceback.
"""

from __future__ import annotations

import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from headless.presets import load_preset
from headless.sweep import run_sweep

ROOT = Path(__file__).resolve().parent.parent

PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["random"]
players = ["maxmin"]
scenarios = ["fixed"]
seeds = 2

[set]
"world.duration" = 1.0
"""


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A finished store without a report, and three directories that are no store."""
    base = tmp_path_factory.mktemp("stores")
    (base / "p.toml").write_text(PRESET)
    run_sweep(load_preset(str(base / "p.toml")), base / "store", workers=1, progress=False)
    garbage, empty, tables, none = (base / n for n in ("garbage", "empty", "tables", "none"))
    for folder in (garbage, empty, tables, none):
        folder.mkdir()
    (garbage / "results.sqlite").write_bytes(os.urandom(4096))
    (empty / "results.sqlite").write_bytes(b"")
    sqlite3.connect(tables / "results.sqlite").execute("CREATE TABLE other (x)").connection.close()
    return {"store": base / "store", "garbage": garbage, "empty": empty, "tables": tables,
            "none": none}


def _run(module: str, *args: Path | str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", f"headless.{module}", *map(str, args)],
                          capture_output=True, text=True, timeout=60, env=env, cwd=ROOT)


# paired and held_out on a finished store give a correct result (tested below), not an error
CASES = [(m, k) for m in ("held_out", "robustness", "beside_paper", "paired")
         for k in ("store", "garbage", "empty", "tables", "none")
         if not (k == "store" and m in ("paired", "held_out"))]


@pytest.mark.parametrize(("module", "kind"), CASES)
def test_an_analysis_on_a_bad_input_is_one_line(module: str, kind: str,
                                                 stores: dict[str, Path]) -> None:
    folder = stores[kind]
    args = (folder, stores["store"]) if module == "paired" else (folder,)
    before = (folder / "results.sqlite").read_bytes() if (folder / "results.sqlite").is_file() else None
    done = _run(module, *args)
    assert done.returncode == 2, (done.stdout, done.stderr)
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), done.stderr
    after = (folder / "results.sqlite").read_bytes() if (folder / "results.sqlite").is_file() else None
    assert before == after  # nothing written into what was read


def test_held_out_on_a_store_without_capture_cells(stores: dict[str, Path]) -> None:
    done = _run("held_out", stores["store"])  # fixed-time trials only: no capture-rate cells
    assert done.returncode == 0, done.stderr
    assert "Capture-rate cells within ±0.10: – (no cells)" in done.stdout


def test_paired_on_two_stores_and_a_bad_option(stores: dict[str, Path]) -> None:
    done = _run("paired", stores["store"], stores["store"])
    assert done.returncode == 0 and "FirstDetectTime" in done.stdout, done.stderr
    done = _run("paired", stores["store"], stores["store"], "--no-such-option")
    assert done.returncode == 2
    assert done.stderr.strip().startswith("stealth: error: unrecognized arguments"), done.stderr
