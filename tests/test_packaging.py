"""The wheel is a working install: bundled levels and presets found from any folder.

Builds the wheel from a copy of the sources, installs it into a fresh venv and runs the
console script from an unrelated folder. The venv sees the dependencies of the environment
running the test through a ``.pth`` file listing that environment's site-packages (so no
network is needed, and it works whether the test runs in a venv or in the machine's own
Python: ``--system-site-packages`` would expose the base interpreter's packages, not a venv's).
Takes about a minute; marked ``packaging`` (it runs in CI like the rest).
"""

from __future__ import annotations

import json
import os
import shutil
import site
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


def _see_our_packages(python: Path, cwd: Path, env: dict) -> None:
    """Put this environment's site-packages on the venv's path, after the venv's own.

    Plain directory lines of a ``.pth`` file are appended to ``sys.path``, but the ``.pth``
    files inside those directories are not run, so an editable install of stealthfield here
    does not leak into the venv: its import finder is never installed there.
    """
    venv_site = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                          cwd, env).stdout.strip())
    ours = list(site.getsitepackages())
    if site.ENABLE_USER_SITE:
        ours.append(site.getusersitepackages())
    ours = [p for p in ours if Path(p).is_dir()]
    (venv_site / "zz_outer_environment.pth").write_text("".join(f"{p}\n" for p in ours))


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
    _run([sys.executable, "-m", "venv", venv], tmp_path, env)
    bin_dir = venv / "bin"
    _see_our_packages(bin_dir / "python", tmp_path, env)
    # --ignore-installed: our site may hold an (editable) stealthfield already
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
