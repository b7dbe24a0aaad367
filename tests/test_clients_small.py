"""What a new user meets first: a headless run, the README's overlay name, a sweep's estimate."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from game.front.display import NOTE
from game.scene import overlay_key
from headless.cli import build_parser, main
from headless.estimate import TRIAL_SECONDS
from navmesh.level import bundled_level_names

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SDL's Linux drivers")
def test_play_without_a_display_says_so_in_one_line_not_sdl_s_error(tmp_path):
    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER", "SDL_AUDIODRIVER",
                        "XDG_RUNTIME_DIR")}
    done = subprocess.run([sys.executable, "-m", "headless.cli", "play", "maze", "--frames", "3"],
                          env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "XDG_RUNTIME_DIR" not in done.stderr and "pygame-ce" not in done.stdout
    assert done.stderr.splitlines()[0] == NOTE, done.stderr


def test_the_readme_s_overlay_names_are_accepted_and_listed_in_help(capsys):
    readme = (ROOT / "README.md").read_text()
    names = re.findall(r"--overlay (\w+)", readme)
    assert names
    with pytest.raises(SystemExit):
        build_parser().parse_args(["play", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    for name in names:
        key = overlay_key(name)
        assert f"{key} ({name})" in help_text or name == key, (name, help_text)


def test_run_prints_an_estimate_before_it_starts(tmp_path, capsys):
    preset = tmp_path / "tiny.toml"
    preset.write_text('description = "two trials"\nlevels = ["maze"]\nabstractions = ["grid"]\n'
                      'guards = ["pf"]\nplayers = ["maxmin"]\nscenarios = ["capture", "fixed"]\n'
                      'seeds = 1\n[set]\n"world.duration" = 6.0\n')
    assert main(["run", "--preset", str(preset), "--out", str(tmp_path / "out"),
                 "--workers", "1"]) == 0
    err = capsys.readouterr().err
    assert re.search(r"^stealth: estimate: about \d+ s for 2 trials on 1 worker ", err, re.M), err


def test_the_estimate_covers_every_bundled_level():
    for level in bundled_level_names():
        for abstraction in ("grid", "partition"):
            for scenario in ("capture", "fixed"):
                assert TRIAL_SECONDS[(level, abstraction, scenario)] > 0
