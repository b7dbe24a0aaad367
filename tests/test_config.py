"""The defaults file, overrides, hashing, and that the TOML agrees with the AI's dataclasses."""

from __future__ import annotations

from dataclasses import fields

import pytest

from ai.params import FSMParams, PFParams, PlayerParams, StalenessParams
from game.config import Config, ConfigError


@pytest.mark.parametrize(
    ("section", "params"),
    [("pf", PFParams), ("fsm", FSMParams), ("staleness", StalenessParams)],
)
def test_toml_defaults_equal_the_paper_defaults_in_code(section: str, params: type) -> None:
    """One source of truth in spirit: the TOML file and the dataclasses never drift apart."""
    assert Config.defaults().section(section) == {f.name: f.default for f in fields(params)}


def test_player_section_matches_player_params() -> None:
    expected = {f.name: f.default for f in fields(PlayerParams)}
    section = Config.defaults().section("player")
    for key in ("guard_speed", "player_speed"):  # come from [world] and the scenario
        expected.pop(key)
    assert section == expected


def test_paper_table2_values() -> None:
    pf = Config.defaults().section("pf")
    assert (pf["I0"], pf["C0"], pf["gamma_I"], pf["gamma_C"], pf["rho"]) == (5.0, 1.0, 0.9, 0.8, 0.95)
    assert (pf["kernel_lambda"], pf["kernel_radius"]) == (0.8, 3)
    assert (pf["w_I_base"], pf["w_C_patrol"], pf["w_N_patrol"], pf["w_I_max"]) == (0.4, 0.5, 0.1, 0.9)
    assert pf["weight_decay"] == 0.05


def test_overrides_are_typed_and_checked() -> None:
    cfg = Config.load(["world.view_range=6", "world.guards=2", "world.attack_needs_line_of_sight=false"])
    assert cfg["world.view_range"] == 6.0 and isinstance(cfg["world.view_range"], float)
    assert cfg["world.guards"] == 2 and cfg["world.attack_needs_line_of_sight"] is False
    with pytest.raises(ConfigError, match="unknown config key"):
        Config.load(["world.viewrange=6"])
    with pytest.raises(ConfigError, match="expected a number"):
        Config.load(["world.view_range=far"])
    with pytest.raises(ConfigError, match="expected a whole number"):
        Config.load(["world.guards=2.5"])
    with pytest.raises(ConfigError, match="finite"):
        Config.load(["pf.rho=nan"])
    with pytest.raises(ConfigError, match="key=value"):
        Config.load(["pf.rho"])


def test_hash_is_stable_and_sensitive() -> None:
    assert Config.defaults().hash() == Config.load([]).hash()
    assert Config.load(["pf.rho=0.9"]).hash() != Config.defaults().hash()
    assert Config.load(["pf.rho=0.95"]).hash() == Config.defaults().hash()
