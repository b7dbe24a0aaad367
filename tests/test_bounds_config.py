"""Issue 11, class 2: every config value is checked against its one declared bound.

Out-of-range values, NaN, infinities and fractions for whole-number keys end with one line
``stealth: error: <key> = <value>: must be ...`` (exit 2) from ``stealth sim``, and a preset
with such a ``[set]`` creates no results directory. The bounds are declared once per key.
"""

from __future__ import annotations

import math
from dataclasses import fields
from pathlib import Path

import pytest

from ai.params import FSMParams, PFParams, PlayerParams, StalenessParams
from ai.stimuli import StimulusParams
from game.action_params import ActionParams
from game.config import Config
from game.errors import ConfigError
from headless.cli import main

ROOT = Path(__file__).resolve().parent.parent

#: (override, what the error line must also name: the allowed range)
BAD_SETS = [
    ("stimuli.noise_decay=1.5", "(0, 1]"),            # a decay rate above 1: traceback before
    ("pf.rho=1.5", "(0, 1]"),
    ("world.guard_speed=0", "(0, inf)"),               # zero / negative speeds
    ("world.player_speed=-1", "(0, inf)"),
    ("world.physics_step=0", "(0, 0.05]"),             # ZeroDivisionError before
    ("pf.kernel_radius=-1", "[0, inf)"),
    ("pf.tie_eps=0", "(0, inf)"),                      # numpy "high <= 0" before
    ("world.guards=-1", "[0, inf)"),
    ("world.player_hp=-1", "(0, inf)"),                # silently accepted before
    ("world.duration=-5", "(0, inf)"),
    ("world.view_range=-3", "[0, inf)"),
    ("world.fov_deg=400", "[0, 360]"),
    ("stimuli.throw_cooldown=-1", "[0, inf)"),
    ("scenario.capture.view_range_scale=-0.5", "[0, inf)"),
    ("zones.dark_confidence_decay=0", "(0, 1]"),
    ("world.view_range=nan", "finite"),
    ("world.attack_range=inf", "finite"),
    ("world.agent_radius=0.8", "half the cell size"),  # wider than a corridor
    ("pf.w_I_max=0.1", "w_I_base"),                    # a rule between two keys
]


def one_error_line(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    """Run the CLI in-process; it must exit 2 with exactly one ``stealth: error:`` line."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stealth: error: "), err
    return lines[0]


@pytest.mark.parametrize(("override", "allowed"), BAD_SETS)
def test_sim_refuses_an_out_of_range_set_in_one_line(
        capsys: pytest.CaptureFixture[str], tmp_path: Path, override: str, allowed: str) -> None:
    trace = tmp_path / "trace.jsonl"
    line = one_error_line(capsys, ["sim", "maze", "--set", "world.duration=1", "--set", override,
                                   "--trace", str(trace)])
    key, value = override.split("=")
    section, name = key.rsplit(".", 1)
    assert allowed in line, line
    if "w_I_base" in line:  # a rule between keys names the section and both keys
        assert f"{section}:" in line and name in line, line
    else:  # "<key> = <value>: ..." with the value as the key holds it
        shown = line.split(f"{key} = ", 1)[1].split(":", 1)[0]
        assert math.isclose(float(shown), float(value)) or shown == value == "nan", line
    assert not trace.exists()  # refused before the trace file was opened


@pytest.mark.parametrize("seed", ["-1", "9223372036854775808"])
def test_a_seed_outside_its_range_is_one_line(capsys: pytest.CaptureFixture[str], seed: str) -> None:
    line = one_error_line(capsys, ["sim", "maze", "--seed", seed, "--set", "world.duration=1"])
    assert "--seed" in line and seed in line and "[0, 9223372036854775807]" in line, line


PRESET = """
levels = ["maze"]
abstractions = ["grid"]
guards = ["random"]
players = ["evade"]
scenarios = ["capture"]
seeds = 1

[set]
"world.duration" = 1.0
{line}
"""


@pytest.mark.parametrize(("line", "key", "allowed"), [
    ('"pf.rho" = nan', "pf.rho = nan", "(0, 1]"),                 # TOML nan passed before
    ('"world.fov_deg" = inf', "world.fov_deg = inf", "[0, 360]"),
    ('"world.guard_speed" = -1.0', "world.guard_speed = -1.0", "(0, inf)"),
    ('"world.guards" = 2.5', "world.guards = 2.5", "whole number"),
    ('"world.ai_tick" = -1.0', "world.ai_tick = -1.0", "(0, inf)"),
    ('"world.agent_radius" = 0.6', "world.agent_radius = 0.6", "half the cell size"),
    ('"stimuli.noise_decay" = 2.0', "stimuli.noise_decay = 2.0", "(0, 1]"),
])
def test_a_preset_with_a_bad_set_writes_nothing(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                                line: str, key: str, allowed: str) -> None:
    preset = tmp_path / "bad.toml"
    preset.write_text(PRESET.format(line=line), encoding="utf-8")
    out = tmp_path / "results"
    error = one_error_line(capsys, ["run", "--preset", str(preset), "--out", str(out),
                                    "--workers", "1"])
    assert "bad.toml: set:" in error and key in error and allowed in error, error
    assert not out.exists()


def test_every_key_declares_a_bound_its_default_satisfies() -> None:
    from ai.bounds import Range
    from game.config import check_value
    from game.schema import bound_of

    defaults = Config.defaults().as_dict()
    for key, default in defaults.items():
        bound = bound_of(key)
        assert bound.problem(default) is None, key
        value = check_value(key, default)
        assert value == default and type(value) is type(default), key
        if isinstance(bound, Range):
            assert bound.integer == isinstance(default, int), key


@pytest.mark.parametrize("cls", [PFParams, FSMParams, StalenessParams, PlayerParams,
                                 StimulusParams, ActionParams])
def test_every_parameter_field_declares_one_bound(cls: type) -> None:
    from ai.bounds import Range

    names = {f.name for f in fields(cls)}
    assert set(cls.bounds) == names
    for f in fields(cls):
        bound = cls.bounds[f.name]
        if isinstance(bound, Range):
            assert bound.integer == (f.type == "int"), f.name


def test_the_config_key_and_the_parameter_share_one_declaration() -> None:
    from game.schema import bound_of

    assert bound_of("pf.rho") is PFParams.bounds["rho"]
    assert bound_of("world.guard_speed") is PlayerParams.bounds["guard_speed"]
    assert bound_of("stimuli.throw_radius") is ActionParams.bounds["throw_radius"]


def test_check_value_is_the_public_check_of_one_value() -> None:
    from game.config import check_value

    assert check_value("world.guards", 2.0) == 2 and isinstance(check_value("world.guards", 2.0), int)
    assert check_value("world.view_range", 6) == 6.0
    assert check_value("world.spawns", "level") == "level"
    for key, value in [("pf.rho", math.nan), ("world.view_range", math.inf),
                       ("world.guards", 2.5), ("world.spawns", "everywhere"),
                       ("world.attack_needs_line_of_sight", 1), ("pf.kernel_radius", True)]:
        with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
            check_value(key, value)
    with pytest.raises(ConfigError, match="unknown config key"):
        check_value("world.viewrange", 6.0)


def test_docs_list_every_bound() -> None:
    from game.schema import markdown_table

    text = (ROOT / "docs" / "config.md").read_text(encoding="utf-8")
    assert markdown_table(Config.defaults().as_dict()) in text
