"""``world.engine`` wired in (SPEC §12): a config key that is no part of a trial's identity.

The engines give equal results trial for trial, so the engine stays out of the config hash,
the trial key and the sweep's design; a row says which engine ran it. These tests need no
batch engine: what only the engine can show (its rows equal the reference's) is its own
tests' business.
"""

from __future__ import annotations

import pytest

from game.config import Config
from game.errors import ConfigError
from game.trial import TrialSpec, trial_rngs
from headless.cli import main

SHORT = (("world.duration", 2.0),)


# ------------------------------------------------------------------ the key and its identity
def test_the_engine_is_a_world_key_whose_default_is_the_reference() -> None:
    assert Config.defaults()["world.engine"] == "pymunk"
    assert Config.load(["world.engine=batch"])["world.engine"] == "batch"


def test_an_unknown_engine_is_refused_naming_the_key_and_the_engines() -> None:
    with pytest.raises(ConfigError, match=r"world\.engine = 'gpu': must be one of 'pymunk', 'batch'"):
        Config.load(["world.engine=gpu"])


def test_the_engine_is_out_of_the_config_hash() -> None:
    assert Config.load(["world.engine=batch"]).hash() == Config.defaults().hash() \
        == "c53787ba3cd08da1"
    assert Config.load(["world.engine=pymunk"]).hash() == Config.defaults().hash()
    # still sensitive to everything else
    assert Config.load(["world.engine=batch", "pf.rho=0.9"]).hash() == "6e28a1d79ad34ffd"


def test_the_engine_is_out_of_the_trial_key_and_the_draws() -> None:
    plain = TrialSpec("maze", overrides=SHORT, factors=(("pf.rho", 0.9),))
    for engine in ("batch", "pymunk"):
        over = TrialSpec("maze", overrides=(("world.engine", engine), *SHORT),
                         factors=(("pf.rho", 0.9),))
        assert over.key == plain.key
        factor = TrialSpec("maze", overrides=SHORT,
                           factors=(("pf.rho", 0.9), ("world.engine", engine)))
        assert factor.key == plain.key
        draws = [g.integers(1 << 30) for g in trial_rngs(factor, "maze")]
        assert draws == [g.integers(1 << 30) for g in trial_rngs(plain, "maze")]
    # a design without the engine keeps its keys exactly as before
    assert TrialSpec("maze", overrides=SHORT).key == "maze/grid/pf/maxmin/capture/0/0/world.duration=2.0"


def test_sim_refuses_an_unknown_engine_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "maze", "--set", "world.engine=gpu"]) == 2
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert lines == ["stealth: error: world.engine = 'gpu': must be one of 'pymunk', 'batch'"]
    assert captured.out == ""
