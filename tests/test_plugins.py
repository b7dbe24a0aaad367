"""A user stimulus with its own zone kind, everywhere: a Tiled level, a preset, play, mechanics.

The plugin is ``examples/tripwire.py`` (zone kind ``alarm``) and the level
``examples/alarm_maze.tmj`` (the bundled maze drawn in Tiled, with four alarm zones).
"""

from __future__ import annotations

import csv
import json
import os
import shutil

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

from pathlib import Path

import numpy as np
import pygame
import pytest

import navmesh.level_fields as level_module
from navmesh.errors import LevelWarning
from ai.errors import StimulusError
from ai.stimuli import Measure, Stimulus, load_stimulus
from game.front.play import PlayGame, PlaySettings
from game.trial import TrialSpec, make_world, run_trial
from headless.cli import main
from headless.errors import PresetError
from headless.presets import load_preset
from headless.analysis.report import write_report
from headless.sweep import run_sweep
from navmesh.errors import LevelError
from navmesh.level import load_level

ROOT = Path(__file__).resolve().parents[1]
PLUGIN_FILE = ROOT / "examples" / "tripwire.py"
PLUGIN = f"{PLUGIN_FILE}:Tripwire"
LEVEL = ROOT / "examples" / "alarm_maze.tmj"


@pytest.fixture(autouse=True)
def fresh_zone_kinds(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test starts with the built-in zone kinds only (the registry is per process)."""
    monkeypatch.setattr(level_module, "_zone_kinds", list(level_module.ZONE_KINDS))


def tripwire(world) -> Stimulus:
    return next(s for s in world.stimuli.active if s.name == "tripwire")


# ---------------------------------------------------------------------------- the level


def test_loading_the_plugin_lets_levels_use_its_zone_kind() -> None:
    with pytest.warns(LevelWarning, match=r"\(alarm\): unknown class 'alarm', treated as "
                                          "decoration"):
        assert "alarm" not in load_level(LEVEL).zones  # a Tiled map: decoration, warned
    load_stimulus(PLUGIN)
    assert "alarm" in level_module.zone_kinds()
    level = load_level(LEVEL)
    assert len(level.zones["alarm"]) == 4
    # the maze itself is unchanged: the same walkable area as the bundled maze
    assert level.walkable.symmetric_difference(load_level("maze").walkable).area < 1e-9


def test_cli_without_the_plugin_names_the_object_and_with_it_validates(capsys) -> None:
    assert main(["validate", str(LEVEL)]) == 0
    assert ("stealth: warning: " in capsys.readouterr().err.split("(alarm): unknown class 'alarm'")[0])
    assert main(["validate", str(LEVEL), "--stimulus", PLUGIN]) == 0


def test_the_zone_is_what_the_stimulus_does() -> None:
    """A player in an alarm zone trips the bell: guards on alert, drawn to the spot."""
    spec = TrialSpec(str(LEVEL), seed=0, stimuli=(PLUGIN,))
    world = make_world(spec)
    wire = tripwire(world)
    assert wire.wired.sum() > 0 and wire.wired[world.player.node]  # starts in a zone
    while world.t < 2.0:
        world.step()
    assert wire.ringing and wire.node >= 0
    assert world.guard_ai.state_name(0) == "alert"
    assert wire.inject(world.stimuli.ctx)[wire.node] == pytest.approx(-6.0)


def test_a_level_without_alarm_zones_leaves_the_plugin_silent() -> None:
    row = run_trial(TrialSpec("maze", seed=0, stimuli=(PLUGIN,)))
    plain = run_trial(TrialSpec("maze", seed=0))
    assert row["metrics"] == plain["metrics"]


# ---------------------------------------------------------------------------- declarations


def test_bad_declarations_are_one_line_errors(tmp_path: Path) -> None:
    plugin = tmp_path / "bad.py"
    plugin.write_text(
        "from ai.stimuli import Stimulus\n"
        "class Kinds(Stimulus):\n    zone_kinds = 'alarm'\n"
        "class Spaces(Stimulus):\n    zone_kinds = (' alarm',)\n"
        "class Meas(Stimulus):\n    measure = 'captured'\n"
    )
    for name, message in (("Kinds", "zone_kinds must be a tuple of strings"),
                          ("Spaces", "zone_kinds: a zone kind must be a word"),
                          ("Meas", "measure must be an ai.stimuli.Measure")):
        with pytest.raises(StimulusError, match=message):
            load_stimulus(f"{plugin}:{name}")
    with pytest.raises(StimulusError, match="the direction must be"):
        Measure(metrics=(("captured", 5),))
    assert Stimulus.zone_kinds == () and Stimulus.measure == Measure()


# ---------------------------------------------------------------------------- a preset


def test_a_preset_with_stimuli_runs_reports_and_keys_its_trials(tmp_path: Path) -> None:
    shutil.copy(PLUGIN_FILE, tmp_path / "tripwire.py")
    shutil.copy(LEVEL, tmp_path / "alarm_maze.tmj")
    preset_file = tmp_path / "alarm.toml"
    preset_file.write_text(
        'description = "tripwire"\nlevels = ["alarm_maze.tmj"]\nabstractions = ["grid"]\n'
        'guards = ["pf"]\nplayers = ["maxmin"]\nscenarios = ["capture"]\nseeds = 2\n'
        'stimuli = ["tripwire.py:Tripwire"]\n'
    )
    preset = load_preset(str(preset_file))
    absolute = f"{(tmp_path / 'tripwire.py').resolve()}:Tripwire"
    assert preset.stimuli == (absolute,)
    assert preset.design()["stimuli"] == [absolute]
    assert all(s.stimuli == (absolute,) and s.key.endswith("stimuli=" + absolute)
               for s in preset.specs())
    result = run_sweep(preset, tmp_path / "out", workers=1, progress=False)
    assert result.finished == 2 and result.failed == 0
    level_module._zone_kinds[:] = list(level_module.ZONE_KINDS)  # as a fresh `stealth report`
    write_report(tmp_path / "out", figures=False)  # loads the design's plugin first
    stored = {int(r["seed"]): r for r in csv.DictReader(open(tmp_path / "out" / "trials.csv"))}
    for spec in preset.specs():  # the stored trials are those with the tripwire
        with_it = run_trial(spec)["metrics"]["first_detect_time"]
        assert float(stored[spec.seed]["first_detect_time"]) == pytest.approx(with_it)
    plain = run_trial(TrialSpec(preset.levels[0], seed=0))["metrics"]["first_detect_time"]
    assert plain != run_trial(preset.specs()[0])["metrics"]["first_detect_time"]


def test_preset_stimuli_errors_are_one_line(tmp_path: Path) -> None:
    preset_file = tmp_path / "p.toml"
    base = ('levels = ["maze"]\nabstractions = ["grid"]\nguards = ["pf"]\n'
            'players = ["maxmin"]\nscenarios = ["capture"]\nseeds = 1\n')
    preset_file.write_text(base + 'stimuli = ["nowhere.py:X"]\n')
    with pytest.raises(PresetError, match=r"p.toml: stimuli: .*no such file"):
        load_preset(str(preset_file))
    preset_file.write_text(base + 'stimuli = "x"\n')
    with pytest.raises(PresetError, match=r"p.toml: stimuli: expected a list"):
        load_preset(str(preset_file))


# ---------------------------------------------------------------------------- play


def test_play_with_the_plugin_on_its_tiled_level() -> None:
    pygame.display.init()
    pygame.font.init()
    try:
        load_stimulus(PLUGIN)  # as `stealth play --stimulus` does before the level
        runs = {}
        for stimuli in ((PLUGIN,), ()):
            game = PlayGame(PlaySettings(str(LEVEL), autopilot="maxmin", stimuli=stimuli),
                            lockstep=True, size=(640, 520))
            try:
                game.run(frames=150)  # 2.5 s of game time
                runs[stimuli] = [game.world.guard_ai.state_name(i)
                                 for i in range(len(game.world.guards))]
                if stimuli:
                    assert tripwire(game.world).ringing
                    assert game.world.stimulus_points().shape == (1, 2)  # the bell is drawn
            finally:
                game.close()
        assert runs[(PLUGIN,)] == ["alert"] * 3
        assert "alert" not in runs[()]
    finally:
        pygame.display.quit()


def test_play_cli_takes_the_stimulus(tmp_path: Path, capsys) -> None:
    shot = tmp_path / "play.png"
    code = main(["play", str(LEVEL), "--stimulus", PLUGIN, "--frames", "20",
                 "--autopilot", "maxmin", "--screenshot", str(shot)])
    assert code == 0 and shot.stat().st_size > 0
    level_module._zone_kinds[:] = list(level_module.ZONE_KINDS)  # a fresh process
    assert main(["play", str(LEVEL), "--frames", "5"]) == 0  # the alarms are decoration
    assert "unknown class 'alarm', treated as decoration" in capsys.readouterr().err


# ---------------------------------------------------------------------------- mechanics


def test_mechanics_measures_the_plugin_against_a_paired_control(tmp_path: Path, capsys) -> None:
    out = tmp_path / "mech"
    code = main(["mechanics", "--level", str(LEVEL), "--stimulus", PLUGIN, "--seeds", "4",
                 "--workers", "1", "--out", str(out)])
    assert code == 0
    captured = capsys.readouterr()
    table = captured.out
    assert "4/4 100%" in captured.err and "jobs/s" in captured.err  # progress on stderr
    assert "tripwire: first_detect_time, s (censored at 60)" in table
    rows = list(csv.DictReader(open(out / "mechanics.csv")))
    by = {r["measure"]: r for r in rows}
    detect = by["tripwire: first_detect_time, s (censored at 60)"]
    assert int(detect["n"]) == 4 and detect["intended"] == "down"
    assert float(detect["on"]) < float(detect["control"])  # the bell gets the player seen
    trials = list(csv.DictReader(open(out / "mechanics_trials.csv")))
    assert {t["arm"] for t in trials} == {"on", "control"}
    # the control arm is the plain trial of the same seed
    control = [t for t in trials if t["arm"] == "control" and t["measure"] == detect["measure"]]
    plain = run_trial(TrialSpec(str(LEVEL), seed=int(control[0]["seed"])))
    assert float(control[0]["value"]) == (plain["metrics"]["first_detect_time"] or 60.0)


def test_a_default_measure_has_no_intended_direction(tmp_path: Path, capsys) -> None:
    from headless.mechanics.stimulus_effect import plugin_measures

    bell = f"{ROOT / 'examples' / 'alarm_bell.py'}:AlarmBell"
    measure, expected = plugin_measures(bell)
    assert measure == Measure() and set(expected.values()) == {0}
    plugin = tmp_path / "typo.py"
    plugin.write_text("from ai.stimuli import Measure, Stimulus\n"
                      "class Typo(Stimulus):\n    measure = Measure(metrics=(('catpured', 1),))\n")
    assert main(["mechanics", "--stimulus", f"{plugin}:Typo", "--seeds", "2"]) == 2
    assert "measure: unknown metric 'catpured'" in capsys.readouterr().err


def test_plugin_jobs_do_not_depend_on_the_worker_count() -> None:
    from headless.mechanics.run import run_jobs
    from headless.mechanics.stimulus_effect import run_plugin_job

    jobs = [(PLUGIN, str(LEVEL), "grid", s) for s in range(2)]
    inline, _ = run_jobs(run_plugin_job, jobs, 1, progress=False)
    pooled, _ = run_jobs(run_plugin_job, jobs, 2, progress=False)
    assert inline == pooled
    assert np.isfinite([r[3] for r in inline]).all()
    json.dumps(inline)
