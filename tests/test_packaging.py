"""The wheel is a working install: bundled levels and presets found from any folder.

Builds the wheel from a copy of the sources, installs it into a fresh venv (system site
packages visible, so the dependencies need no network) and runs the console script from an
unrelated folder. Takes about a minute; marked ``packaging`` (it runs in CI like the rest).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "README.md", "navmesh", "ai", "game", "headless", "assets")


def _run(args: list, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    done = subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, f"{args}\n{done.stdout}\n{done.stderr}"
    return done


@pytest.mark.packaging
def test_the_installed_wheel_has_the_bundled_levels_and_presets(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy", MPLBACKEND="Agg")
    source = tmp_path / "source"  # a copy, so the build leaves no build/ in the checkout
    source.mkdir()
    for name in SOURCES:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, source / name,
                            ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(ROOT / name, source / name)
    wheels = tmp_path / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", wheels, "."],
         source, env)
    (wheel,) = wheels.glob("stealthfield-*.whl")

    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", "--system-site-packages", venv], tmp_path, env)
    bin_dir = venv / "bin"
    # --ignore-installed: the system site may hold an (editable) stealthfield already
    _run([bin_dir / "python", "-m", "pip", "install", "-q", "--no-deps", "--no-index",
          "--ignore-installed", wheel], tmp_path, env)

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    where = _run([bin_dir / "python", "-c",
                  "import navmesh, headless, navmesh.level as l; "
                  "print(navmesh.__file__); print(headless.__file__); print(l.LEVELS_DIR)"],
                 elsewhere, env).stdout.split()
    for imported in where:  # the installed copy, not a checkout or an editable install
        assert Path(imported).is_relative_to(venv), where

    stealth = bin_dir / "stealth"
    levels = json.loads(_run([stealth, "levels", "--json"], elsewhere, env).stdout)
    assert {row["name"] for row in levels} == {"arkham", "dishonored", "maze", "miami", "tlou"}
    table = _run([stealth, "levels"], elsewhere, env).stdout
    assert "miami" in table
    sim = json.loads(_run([stealth, "sim", "miami", "--guards", "pf", "--player", "maxmin",
                           "--json"], elsewhere, env).stdout)
    assert sim["level"] == "miami" and "captured" in sim["metrics"]
    _run([stealth, "validate", Path(where[2]) / "maze.tmj"], elsewhere, env)
    _run([stealth, "run", "--preset", "smoke", "--out", "X", "--workers", "2"], elsewhere, env)
    _run([stealth, "report", "X"], elsewhere, env)
    assert (elsewhere / "X" / "trials.csv").is_file()
    assert any((elsewhere / "X").rglob("*.md")), sorted((elsewhere / "X").iterdir())
