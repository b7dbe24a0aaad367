"""The defaults (the dataclasses, and the file for the keys no class holds), overrides, hashing."""

from __future__ import annotations

import tomllib
from dataclasses import fields

import pytest

from ai.params import PlayerParams, Params
from game.config import DEFAULTS_PATH, Config, ConfigError
from game.schema import parameter_sections


def _params_classes() -> set[type]:
    """Every parameter dataclass of the product (ai/, game/): subclasses of ``Params``."""
    import ai.alert, ai.awareness, ai.radio, ai.roles, ai.stimuli, game.actions  # noqa: E401, F401

    found, todo = set(), [Params]
    while todo:
        for sub in todo.pop().__subclasses__():
            todo.append(sub)
            if sub.__module__.split(".")[0] in ("ai", "game"):
                found.add(sub)
    return found


def test_every_parameter_class_is_the_one_source_of_its_sections_defaults() -> None:
    """Each class's field defaults are its section's defaults, and the file writes none."""
    sections = parameter_sections()
    assert {c for classes in sections.values() for c in classes} == _params_classes()
    assert len(_params_classes()) == 10
    with DEFAULTS_PATH.open("rb") as handle:
        tables = tomllib.load(handle)
    defaults = Config.defaults()
    for section, classes in sections.items():
        expected = {f.name: f.default for cls in classes for f in fields(cls)
                    if f.name not in cls.from_world}
        found = defaults.section(section)
        assert found.pop("enabled", False) is False  # the team rules' switch: the file's
        assert found == expected, section
        assert not set(tables.get(section, {})) & {f.name for c in classes for f in fields(c)}


def test_player_section_leaves_the_speeds_to_the_world() -> None:
    section = Config.defaults().section("player")
    assert "guard_speed" not in section and "player_speed" not in section
    assert set(PlayerParams.from_world) == {"guard_speed", "player_speed"}


def test_the_config_hash_is_pinned() -> None:
    """The hash a store's identity holds: the same values as before the defaults moved into
    the dataclasses (measured on the commit before), so every store still resumes."""
    assert Config.defaults().hash() == "c53787ba3cd08da1"
    assert Config.load(["pf.rho=0.9"]).hash() == "6e28a1d79ad34ffd"
    assert Config.load(["metrics.coverage=seen", "awareness.enabled=true"]).hash() \
        == "53837f3c38328917"
    # world.engine (SPEC §12); play: attack_needs_awareness, attack_memory, sneak_factor,
    # gait_sneak; readings (SPEC §12): staleness_weight, separation_weight, safetygraph_hops,
    # metrics.partition_coverage (all out of the hash at their default)
    assert len(Config.defaults().as_dict()) == 155
    assert Config.load(["world.attack_needs_awareness=true"]).hash() != Config.defaults().hash()
    from headless.presets import load_preset

    assert load_preset("paper").config_hash == "7647327243295999"


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
