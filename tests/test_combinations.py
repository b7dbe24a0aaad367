"""Every guard mode × player policy × abstraction × scenario × level runs through `stealth sim`."""

from __future__ import annotations

import json

import pytest

from ai import GUARD_MODES
from headless.cli import main
from navmesh.level import bundled_level_names

PAPER_POLICIES = ("maxmin", "safetygraph")


@pytest.mark.parametrize("level", bundled_level_names())
@pytest.mark.parametrize("abstraction", ["grid", "partition"])
def test_every_combination_runs(level: str, abstraction: str, capsys: pytest.CaptureFixture) -> None:
    for mode in GUARD_MODES:
        for policy in PAPER_POLICIES:
            for scenario in ("capture", "fixed"):
                code = main(["sim", level, "--guards", mode, "--player", policy,
                             "--abstraction", abstraction, "--scenario", scenario,
                             "--seed", "1", "--set", "world.duration=4", "--json"])
                out = capsys.readouterr().out
                assert code == 0, (mode, policy, scenario)
                document = json.loads(out)
                assert (document["guards"], document["player"]) == (mode, policy)
                metrics = document["metrics"]
                assert 0.0 <= metrics["coverage"] <= 1.0
                assert metrics["backtracks"] >= 0
